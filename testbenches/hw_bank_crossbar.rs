//! BankCrossbar against an independent cycle model, with one port per bank, two
//! shared ports and two split ports (even requesters on the first, odd on the
//! second), and with `ready` registered (a cycle late): random requests (random
//! banks, a hot bank, withdrawn and changed requests while waiting), memories
//! that answer junk in every cycle after a row was not read, and random resets.
//! Every cycle each requester's `ready` (or, late, the previous cycle's), each
//! bank port's enable and row (the previous cycle's grant) and each answer must
//! be the model's (per bank port: the lowest asking requester above the last one
//! it granted, else the lowest; the second port among those the first left
//! waiting, or among the odd ones); every granted read's answer must arrive three
//! cycles later, exactly once, with its tag and the word at its bank's row;
//! nothing arrives that was not asked for. The exported Verilog passes yosys,
//! Verilator lint and Icarus, and replays a recorded run cycle for cycle in both
//! simulators.

use crate::common::xsim::{compare, Recorder, XsimRun};
use crate::common::xsim_tb::{self, Simulator};
use crate::common::{clock_cycle, lint_top, rng, settle};
use photon_fpga::hw::config::bank_config::BankPorts;
use photon_fpga::hw::export::verilog::export_block;
use photon_fpga::hw::primitives::bank_bus::BankPort;
use photon_fpga::hw::primitives::offer_queue::OfferQueue;
use photon_fpga::hw::primitives::stream::ResultBeat;
use photon_fpga::hw::store::bank_crossbar::BankCrossbar;
use rand::Rng;
use rust_hdl::prelude::*;
use std::collections::VecDeque;

/// One crossbar shape and its stimulus.
#[derive(Clone, Copy, Debug)]
struct Shape {
    requesters: usize,
    banks: usize,
    ports: BankPorts,
    rows: usize,
    word_bits: u32,
    tag_bits: u32,
    p_valid: f64,
    /// Share of requests that go to bank 0 (a hot bank).
    p_hot: f64,
    cycles: usize,
    seed: u64,
    /// `ready` registered (`BankCrossbar::with_late_ready`).
    late: bool,
}

const SHAPES: [Shape; 11] = [
    Shape {
        requesters: 1,
        banks: 1,
        ports: BankPorts::One,
        rows: 16,
        word_bits: 64,
        tag_bits: 4,
        p_valid: 0.7,
        p_hot: 0.0,
        cycles: 600,
        seed: 1,
        late: false,
    },
    Shape {
        requesters: 4,
        banks: 2,
        ports: BankPorts::One,
        rows: 32,
        word_bits: 32,
        tag_bits: 4,
        p_valid: 0.8,
        p_hot: 0.3,
        cycles: 1500,
        seed: 2,
        late: false,
    },
    Shape {
        requesters: 3,
        banks: 16,
        ports: BankPorts::Shared,
        rows: 64,
        word_bits: 36,
        tag_bits: 8,
        p_valid: 0.9,
        p_hot: 0.1,
        cycles: 1500,
        seed: 3,
        late: false,
    },
    Shape {
        requesters: 8,
        banks: 8,
        ports: BankPorts::One,
        rows: 64,
        word_bits: 32,
        tag_bits: 4,
        p_valid: 0.9,
        p_hot: 0.2,
        cycles: 1500,
        seed: 4,
        late: false,
    },
    Shape {
        requesters: 16,
        banks: 4,
        ports: BankPorts::Shared,
        rows: 16,
        word_bits: 20,
        tag_bits: 5,
        p_valid: 0.6,
        p_hot: 0.5,
        cycles: 1000,
        seed: 5,
        late: false,
    },
    Shape {
        requesters: 2,
        banks: 1,
        ports: BankPorts::Split,
        rows: 16,
        word_bits: 32,
        tag_bits: 4,
        p_valid: 0.9,
        p_hot: 0.0,
        cycles: 800,
        seed: 6,
        late: false,
    },
    Shape {
        requesters: 8,
        banks: 16,
        ports: BankPorts::Split,
        rows: 32,
        word_bits: 32,
        tag_bits: 5,
        p_valid: 0.9,
        p_hot: 0.2,
        cycles: 1500,
        seed: 7,
        late: false,
    },
    Shape {
        requesters: 6,
        banks: 4,
        ports: BankPorts::Split,
        rows: 16,
        word_bits: 24,
        tag_bits: 6,
        p_valid: 0.7,
        p_hot: 0.5,
        cycles: 1000,
        seed: 8,
        late: false,
    },
    Shape {
        requesters: 4,
        banks: 16,
        ports: BankPorts::Split,
        rows: 32,
        word_bits: 33,
        tag_bits: 4,
        p_valid: 0.9,
        p_hot: 0.3,
        cycles: 1500,
        seed: 9,
        late: true,
    },
    Shape {
        requesters: 5,
        banks: 4,
        ports: BankPorts::Shared,
        rows: 16,
        word_bits: 32,
        tag_bits: 4,
        p_valid: 0.8,
        p_hot: 0.4,
        cycles: 1500,
        seed: 10,
        late: true,
    },
    Shape {
        requesters: 3,
        banks: 2,
        ports: BankPorts::One,
        rows: 16,
        word_bits: 16,
        tag_bits: 3,
        p_valid: 0.9,
        p_hot: 0.5,
        cycles: 1000,
        seed: 11,
        late: true,
    },
];

/// A granted read: when its answer is due, its tag and its word.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Due {
    cycle: usize,
    tag: u64,
    word: u64,
}

/// Port `k` (port `k % ports` of bank `k / ports`) of the crossbar.
fn port(uut: &mut BankCrossbar, k: usize, ports: usize) -> &mut BankPort {
    if k.is_multiple_of(ports) {
        &mut uut.banks[k / ports]
    } else {
        &mut uut.second[k / ports]
    }
}

/// The crossbar of shape `s`.
fn crossbar(s: &Shape) -> BankCrossbar {
    let (d, b, p, w, t) = (s.requesters, s.banks, s.ports, s.word_bits, s.tag_bits);
    if s.late {
        BankCrossbar::with_late_ready(d, b, p, w, t)
    } else {
        BankCrossbar::new(d, b, p, w, t)
    }
}

/// Run `s` against the model; the recording of the run if `record`.
fn run_against_model(s: &Shape, record: bool) -> Option<XsimRun> {
    let (d, b) = (s.requesters, s.banks);
    let ports = s.ports.ports();
    let np = b * ports;
    let mut uut = crossbar(s);
    uut.connect_all();
    check_all(&uut).expect("BankCrossbar checks");
    let mut r = rng(s.seed);
    let word_mask = u64::MAX >> (64 - s.word_bits);
    let mem: Vec<Vec<u64>> = (0..b)
        .map(|_| (0..s.rows).map(|_| r.gen::<u64>() & word_mask).collect())
        .collect();
    let mut recorder = record.then(Recorder::default);
    // The model, per bank port (port p of bank j at j * ports + p): its last
    // grant, the row it granted (registered at the port) and its memory's
    // registered row (None: not read); per requester its offered request and its
    // reads due.
    let mut last: Vec<Option<usize>> = vec![None; np];
    let mut port_row: Vec<Option<usize>> = vec![None; np];
    let mut bram_row: Vec<Option<usize>> = vec![None; np];
    let mut offer: Vec<Option<(usize, usize, u64)>> = vec![None; d];
    let mut due: Vec<VecDeque<Due>> = vec![VecDeque::new(); d];
    let mut next_tag = vec![0u64; d];
    let mut won_before = vec![false; d];
    // With repeats masked: the request granted in the previous cycle, and
    // whether the request on offer is that one again.
    let masked = s.late && BankCrossbar::masks_repeats(d, s.ports);
    let mut granted_before: Vec<Option<(usize, usize, u64)>> = vec![None; d];
    let mut repeat = vec![false; d];
    let (mut granted, mut answered, mut reset_drops) = (0usize, 0usize, 0usize);
    let tail = 4;
    for c in 0..s.cycles + tail {
        let reset = c < 2 || (c > 10 && r.gen_range(0..300) == 0);
        for i in 0..d {
            // A waiting request stays, is withdrawn or changes, at random; none
            // in the tail.
            repeat[i] = false;
            if c >= s.cycles {
                offer[i] = None;
            } else if masked && granted_before[i].is_some() && r.gen_bool(0.5) {
                // Offered again in the cycle after its grant, as a requester
                // that does not yet know it was taken does.
                offer[i] = granted_before[i];
                repeat[i] = true;
            } else if offer[i].is_none() || r.gen_bool(0.2) {
                offer[i] = r.gen_bool(s.p_valid).then(|| {
                    let bank = if r.gen_bool(s.p_hot) {
                        0
                    } else {
                        r.gen_range(0..b)
                    };
                    let tag = next_tag[i];
                    next_tag[i] = (tag + 1) & ((1 << s.tag_bits) - 1);
                    (bank, r.gen_range(0..s.rows), tag)
                });
            }
            let (bank, row, tag) = offer[i].unwrap_or((r.gen_range(0..b), 0, 0));
            uut.clients[i].valid.next = offer[i].is_some();
            uut.clients[i].bank.next = (bank as u64).into();
            uut.clients[i].row.next = (row as u64).into();
            uut.clients[i].tag.next = tag.into();
        }
        // A memory answers its last row, junk after a cycle without a read.
        for (k, row) in bram_row.iter().enumerate() {
            let w = match row {
                Some(row) => mem[k / ports][*row],
                None => r.gen::<u64>(),
            };
            port(&mut uut, k, ports).word.next = w.into();
        }
        uut.reset.next = reset;
        settle(&mut uut);
        if let Some(rec) = recorder.as_mut() {
            rec.sample(&uut, c as u64);
        }
        // The model's grants.
        // The second port serves those the first left waiting; split ports,
        // the even requesters on the first and the odd ones on the second.
        let mut winner: Vec<Option<usize>> = vec![None; np];
        for k in 0..np {
            let (j, first) = (k / ports, k.is_multiple_of(ports));
            let split = s.ports == BankPorts::Split;
            let asking: Vec<usize> = (0..d)
                .filter(|&i| !reset && offer[i].is_some_and(|o| o.0 == j))
                .filter(|&i| !(repeat[i] && won_before[i]))
                .filter(|&i| first || winner[k - 1] != Some(i))
                .filter(|&i| !split || i % 2 == k % 2)
                .collect();
            winner[k] = asking
                .iter()
                .copied()
                .find(|&i| last[k].is_none_or(|l| i > l))
                .or(asking.first().copied());
        }
        // `ready`: granted now, or (late) granted in the previous cycle.
        for (i, o) in offer.iter().enumerate() {
            let won = o.is_some_and(|o| (0..ports).any(|p| winner[o.0 * ports + p] == Some(i)));
            let want = if s.late { won_before[i] } else { won };
            assert_eq!(
                uut.clients[i].ready.val(),
                want,
                "{s:?}: cycle {c}, ready {i}"
            );
            won_before[i] = won;
        }
        for (k, want) in port_row.iter().enumerate() {
            let bp = port(&mut uut, k, ports);
            assert_eq!(bp.enable.val(), want.is_some(), "cycle {c}, port {k}");
            // The row only counts while the port is enabled (a stream's data
            // while it is not valid).
            if let Some(row) = want {
                assert_eq!(bp.row.val().to_u64(), *row as u64, "cycle {c}, port {k}");
            }
        }
        // The answers due now.
        for (i, due) in due.iter_mut().enumerate() {
            let want = due.front().filter(|x| x.cycle == c).copied();
            assert_eq!(
                uut.answers[i].valid.val(),
                want.is_some(),
                "{s:?}: cycle {c}, requester {i}: answer expected {want:?}"
            );
            if let Some(x) = want {
                assert_eq!(uut.answers[i].tag.val().to_u64(), x.tag, "cycle {c}");
                assert_eq!(uut.answers[i].word.val().to_u64(), x.word, "cycle {c}");
                due.pop_front();
                answered += 1;
            }
            // A reset drops the reads granted in the last two cycles (due
            // in the next two).
            while reset && due.front().is_some_and(|x| x.cycle <= c + 2) {
                due.pop_front();
                reset_drops += 1;
            }
        }
        // The edge: grants move, the ports register their granted rows and the
        // memories the rows at their ports.
        for k in 0..np {
            bram_row[k] = port_row[k];
            port_row[k] = winner[k].map(|i| offer[i].unwrap().1);
        }
        granted_before = vec![None; d];
        for (i, rep) in repeat.iter().enumerate() {
            if *rep {
                offer[i] = None;
            }
        }
        for k in 0..np {
            if let Some(i) = winner[k] {
                granted_before[i] = offer[i];
                let (j, row, tag) = offer[i].unwrap();
                due[i].push_back(Due {
                    cycle: c + BankCrossbar::LATENCY,
                    tag,
                    word: mem[j][row],
                });
                last[k] = Some(i);
                offer[i] = None;
                granted += 1;
            }
        }
        clock_cycle(&mut uut, |u| &mut u.clock);
    }
    assert!(due.iter().all(VecDeque::is_empty), "{s:?}: answers missing");
    assert_eq!(granted, answered + reset_drops);
    assert!(
        granted > s.cycles / 4,
        "{s:?}: only {granted} reads granted"
    );
    recorder.map(Recorder::finish)
}

#[test]
fn every_read_returns_to_its_requester_once_round_robin_per_bank() {
    for s in &SHAPES {
        run_against_model(s, false);
    }
}

#[test]
#[cfg_attr(
    not(all(has_yosys, has_verilator, has_iverilog)),
    ignore = "needs yosys, verilator and iverilog"
)]
fn exported_verilog_lints_and_replays_cycle_for_cycle() {
    for s in [&SHAPES[1], &SHAPES[3], &SHAPES[4], &SHAPES[6], &SHAPES[9]] {
        let e = export_block(crossbar(s)).unwrap();
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("top.v"), &e.verilog).unwrap();
        lint_top(dir.path());
        let run = run_against_model(s, true).unwrap();
        assert_eq!(run.ports, e.ports);
        for sim in [Simulator::Icarus, Simulator::Verilator] {
            assert!(sim.available(), "{} is not installed", sim.name());
            let sd = dir.path().join(sim.name());
            xsim_tb::build(sim, &sd, &e.verilog, &run.ports, run.cycles).unwrap();
            let got = xsim_tb::replay(sim, &sd, "crossbar", &run).unwrap();
            if let Err(m) = compare(&run.responses, &got) {
                panic!("{s:?} under {}: {m}", sim.name());
            }
        }
    }
}

/// Three requesters' OfferQueues and a crossbar with a late `ready`, one bank
/// with one port: the setting in which a refused read that asks every other
/// cycle can be passed over forever.
#[derive(LogicBlock)]
struct ThreeOnOnePort {
    clock: Signal<In, Clock>,
    reset: Signal<In, bool>,
    valid: Vec<Signal<In, bool>>,
    data: Vec<Signal<In, ResultBeat>>,
    queues: Vec<OfferQueue<ResultBeat>>,
    crossbar: BankCrossbar,
}

impl Logic for ThreeOnOnePort {
    fn update(&mut self) {
        self.crossbar.clock.next = self.clock.val();
        self.crossbar.reset.next = self.reset.val();
        self.crossbar.banks[0].word.next = 0.into();
        for (i, q) in self.queues.iter_mut().enumerate() {
            q.clock.next = self.clock.val();
            q.reset.next = self.reset.val();
            q.inbound.valid.next = self.valid[i].val();
            q.inbound.data.next = self.data[i].val();
            q.taken.next = self.crossbar.clients[i].ready.val();
            let c = &mut self.crossbar.clients[i];
            c.valid.next = q.offer_valid.val();
            c.bank.next = 0.into();
            c.row.next = q.offer.val().address;
            c.tag.next = (q.offer.val().id.to_u64() & 0xff).into();
        }
    }
}

/// The longest any of requester 0's reads waits from entering its queue to its
/// grant, and its reads granted, while requesters 1 and 2 always have reads for
/// the same bank and requester 0 has one at a time (a slot's next read waits
/// for the last), entering `delay` cycles after its last grant was told.
fn longest_wait(persistent: bool, delay: usize, cycles: usize) -> (usize, usize) {
    let queue = || {
        if persistent {
            OfferQueue::persistent()
        } else {
            OfferQueue::new()
        }
    };
    let mut uut = ThreeOnOnePort {
        clock: Default::default(),
        reset: Default::default(),
        valid: (0..3).map(|_| Default::default()).collect(),
        data: (0..3).map(|_| Default::default()).collect(),
        queues: (0..3).map(|_| queue()).collect(),
        crossbar: BankCrossbar::with_late_ready(3, 1, BankPorts::One, 16, 8),
    };
    // (A harness in plain Rust: its blocks are checked by their own tests.)
    uut.connect_all();
    uut.reset.next = true;
    clock_cycle(&mut uut, |u| &mut u.clock);
    uut.reset.next = false;
    let mut serial = [0u64; 3];
    let (mut entered, mut longest, mut granted) = (None::<usize>, 0, 0);
    let mut told = 0;
    for c in 0..cycles {
        // Requester 0's next read enters once its last one was granted.
        let mine_free = entered.is_none() && c >= told + delay;
        for (i, s) in serial.iter().enumerate() {
            let beat = ResultBeat {
                id: (s & 0xff).into(),
                address: (*s).into(),
                ..Default::default()
            };
            uut.valid[i].next = i > 0 || mine_free;
            uut.data[i].next = beat;
        }
        settle(&mut uut);
        if mine_free && uut.queues[0].inbound.ready.val() {
            entered = Some(c);
        }
        for (q, s) in uut.queues.iter().zip(serial.iter_mut()).skip(1) {
            if q.inbound.ready.val() {
                *s += 1;
            }
        }
        // `ready` (late) says requester 0's read was granted in the last cycle.
        if let Some(e) = entered.filter(|&e| e < c && uut.crossbar.clients[0].ready.val()) {
            longest = longest.max(c - 1 - e);
            granted += 1;
            entered = None;
            told = c;
            serial[0] += 1;
        }
        clock_cycle(&mut uut, |u| &mut u.clock);
    }
    (longest, granted)
}

#[test]
fn a_refused_read_is_granted_within_a_round_of_three() {
    // Each delay puts requester 0's reads at another phase of the others'
    // turns.
    for delay in 0..4 {
        let (longest, granted) = longest_wait(true, delay, 2000);
        assert!(
            granted > 100,
            "delay {delay}: requester 0 got {granted} reads"
        );
        assert!(
            longest <= 8,
            "delay {delay}: a read of requester 0 waited {longest} cycles"
        );
    }
}
