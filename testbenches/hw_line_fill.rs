//! LineFill against the AXI memory model (`hw::sim::axi_memory`): random fills of
//! random blocks into random lines, through a memory with latency, random extra
//! latency and random pauses on both channels. Every line reported filled must
//! hold its block's bytes as the memory has them, in the order the fills were
//! taken; every burst must be one INCR burst of a whole block at the block's
//! address; several bursts must be in flight at once (the latency is covered);
//! a burst answered with an error sets `error`.

use crate::common::xsim::{compare, Recorder, XsimRun};
use crate::common::xsim_tb::{self, Simulator};
use crate::common::{lint_top, rng, settle};
use photon_fpga::hw::export::verilog::export_block;
use photon_fpga::hw::memory::line_fill::{LineFill, MAX_FILLS};
use photon_fpga::hw::sim::axi_memory::{AxiBurst, AxiMemory, AxiTiming};
use rand::Rng;
use rust_hdl::prelude::*;
use std::collections::{HashMap, VecDeque};

/// One run: `fills` random fills of `block_bytes`-byte blocks with `D`-bit beats;
/// whether `error` rose, and with `record` the run's stimulus and responses for a
/// cross-simulation of the exported Verilog.
fn run<const D: usize>(
    block_bytes: u64,
    fills: usize,
    timing: AxiTiming,
    fault: Option<u64>,
    record: bool,
) -> (bool, Option<XsimRun>) {
    let beat_bytes = (D / 8) as u64;
    let beats = block_bytes / beat_bytes;
    let blocks = 200u64;
    let lines = 64u64;
    let base = 4 * block_bytes;
    let mut r = rng(timing.seed + 100);
    // The image: `base` bytes of nothing, then `blocks` blocks of random words.
    let words: Vec<u64> = (0..(base + blocks * block_bytes) / 4)
        .map(|_| r.gen::<u32>() as u64)
        .collect();
    let mut memory = AxiMemory::from_words(&words, 4, timing);
    let byte = |a: u64| (words[(a / 4) as usize] >> (8 * (a % 4))) & 0xff;
    if let Some(b) = fault {
        memory.fail_at(base + b * block_bytes);
    }
    let mut uut = LineFill::<D>::new(base, block_bytes, D as u64 / 8);
    let mut recorder = record.then(Recorder::default);
    uut.connect_all();
    check_all(&uut).expect("LineFill checks");
    let mut ram: HashMap<u64, u64> = HashMap::new();
    let mut asked: VecDeque<(u64, u64)> = VecDeque::new();
    let (mut sent, mut done, mut most_in_flight) = (0usize, 0usize, 0usize);
    let mut next = (r.gen_range(0..blocks), r.gen_range(0..lines));
    uut.reset.next = true;
    settle(&mut uut);
    uut.clock.next = true.into();
    settle(&mut uut);
    uut.clock.next = false.into();
    uut.reset.next = false;
    for cycle in 0..200_000 {
        let out = memory.drive();
        uut.m_axi.arready.next = out.arready;
        uut.m_axi.rvalid.next = out.rvalid;
        uut.m_axi.rdata.next = out.rdata.into();
        uut.m_axi.rlast.next = out.rlast;
        uut.m_axi.rresp.next = (out.rresp as u64).into();
        let offer = sent < fills && r.gen_bool(0.7);
        uut.fill_valid.next = offer;
        uut.fill_block.next = next.0.into();
        uut.fill_line.next = next.1.into();
        settle(&mut uut);
        if let Some(rec) = recorder.as_mut() {
            rec.sample(&uut, cycle);
        }
        let ar = uut.m_axi.arvalid.val().then(|| AxiBurst {
            addr: uut.m_axi.araddr.val().to_u64(),
            len: uut.m_axi.arlen.val().to_u64() as u8,
            size: uut.m_axi.arsize.val().to_u64() as u8,
            burst: uut.m_axi.arburst.val().to_u64() as u8,
        });
        if uut.filled_valid.val() {
            let line = uut.filled_line.val().to_u64();
            let (block, want_line) = asked.pop_front().expect("a fill was asked for");
            assert_eq!(
                line, want_line,
                "cycle {cycle}: lines fill in the order asked"
            );
            for beat in 0..beats {
                let at = base + block * block_bytes + beat * beat_bytes;
                let want = (0..beat_bytes).fold(0u64, |w, i| w | (byte(at + i) << (8 * i)));
                assert_eq!(
                    ram.get(&(line * beats + beat)).copied(),
                    Some(want),
                    "line {line} beat {beat}"
                );
            }
            done += 1;
        }
        // This cycle's write lands at the edge, after the line reported now (the
        // next fill of the same line may start writing it in this very cycle).
        if uut.write_enable.val() {
            ram.insert(
                uut.write_index.val().to_u64(),
                uut.write_data.val().to_u64(),
            );
        }
        if offer && uut.fill_ready.val() {
            asked.push_back(next);
            sent += 1;
            next = (r.gen_range(0..blocks), r.gen_range(0..lines));
        }
        let rready = uut.m_axi.rready.val();
        memory.edge(ar, rready);
        most_in_flight = most_in_flight.max(memory.in_flight());
        uut.clock.next = true.into();
        settle(&mut uut);
        uut.clock.next = false.into();
        if uut.error.val() || (done == fills && memory.in_flight() == 0) {
            break;
        }
    }
    let run = recorder.map(Recorder::finish);
    if uut.error.val() {
        return (true, run);
    }
    assert_eq!(done, fills, "every fill finished");
    for b in &memory.bursts {
        assert_eq!(
            (b.len as u64 + 1, 1u64 << b.size, b.burst),
            (beats, beat_bytes, 1),
            "{b:?}"
        );
        assert!(
            b.addr >= base && (b.addr - base).is_multiple_of(block_bytes),
            "{b:?}"
        );
    }
    assert!(
        timing.latency < 8 || most_in_flight >= MAX_FILLS / 2,
        "the latency is covered by several bursts in flight ({most_in_flight})"
    );
    (false, run)
}

#[test]
fn fills_arrive_whole_and_in_order_through_a_slow_paused_memory() {
    for (seed, latency) in [(1u64, 22u64), (2, 3), (3, 60)] {
        let timing = AxiTiming {
            latency,
            extra_latency: 10,
            ar_pause: 0.3,
            r_pause: 0.3,
            beat_interval: seed,
            sustained_bytes: 0.0,
            seed,
        };
        assert!(!run::<32>(64, 300, timing, None, false).0);
        assert!(!run::<64>(64, 300, timing, None, false).0);
    }
    // A prompt memory, 16-byte beats' worth of blocks of 128 bytes.
    assert!(!run::<64>(128, 200, AxiTiming::fixed(22), None, false).0);
}

#[test]
fn an_error_response_sets_error() {
    let timing = AxiTiming::fixed(5);
    // Block 7 answers SLVERR; 400 random fills of 200 blocks reach it.
    assert!(run::<32>(64, 400, timing, Some(7), false).0);
}

#[test]
#[cfg_attr(
    not(all(has_yosys, has_verilator, has_iverilog)),
    ignore = "needs yosys, verilator and iverilog"
)]
fn exported_verilog_lints_and_replays_cycle_for_cycle() {
    let timing = AxiTiming {
        latency: 9,
        extra_latency: 6,
        ar_pause: 0.3,
        r_pause: 0.3,
        beat_interval: 1,
        sustained_bytes: 0.0,
        seed: 5,
    };
    let (failed, run) = run::<64>(64, 120, timing, None, true);
    assert!(!failed);
    let run = run.expect("recorded");
    // The same block as the run's: 64-byte blocks from byte 4 x 64.
    let e = export_block(LineFill::<64>::new(256, 64, 8)).unwrap();
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("top.v"), &e.verilog).unwrap();
    lint_top(dir.path());
    assert_eq!(run.ports, e.ports);
    for sim in [Simulator::Icarus, Simulator::Verilator] {
        assert!(sim.available(), "{} is not installed", sim.name());
        let sd = dir.path().join(sim.name());
        xsim_tb::build(sim, &sd, &e.verilog, &run.ports, run.cycles).unwrap();
        let got = xsim_tb::replay(sim, &sd, "line_fill", &run).unwrap();
        if let Err(m) = compare(&run.responses, &got) {
            panic!("LineFill under {}: {m}", sim.name());
        }
    }
}
