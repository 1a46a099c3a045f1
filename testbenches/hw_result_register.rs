//! ResultRegister (the SearchPort's result skid buffer) against a FIFO model: random
//! valid on the upstream side and random ready downstream, in both the registered
//! and the bypass build. Checked: every beat arrives once and in order (no loss, no
//! duplicate), the AXI-stream rule (a presented beat stays put until taken), full
//! throughput with no stalls, and that registered outputs change only at clock edges.

use photon_fpga::hw::primitives::register_slice::ResultRegister;
use photon_fpga::hw::primitives::stream::ResultBeat;
use rand::Rng;
use rust_hdl::prelude::*;

/// One result beat: (header, last, id, count, visited, address, dist).
type Beat = (bool, bool, u64, u64, u64, u64, u64);

fn random_beat(r: &mut impl Rng, n: u64) -> Beat {
    (
        r.gen(),
        r.gen(),
        n,
        r.gen_range(0..=255),
        r.gen_range(0..=u32::MAX as u64),
        r.gen_range(0..1 << 24),
        r.gen_range(0..=u32::MAX as u64),
    )
}

struct Bench {
    uut: ResultRegister,
}

impl Bench {
    fn new(bypass: bool) -> Self {
        let mut uut = ResultRegister::new(bypass);
        uut.connect_all();
        check_all(&uut).expect("ResultRegister checks");
        let mut b = Bench { uut };
        b.uut.reset.next = true;
        b.tick();
        b.uut.reset.next = false;
        b.settle();
        b
    }
    fn settle(&mut self) {
        crate::common::settle(&mut self.uut);
    }
    fn tick(&mut self) {
        self.uut.clock.next = true.into();
        self.settle();
        self.uut.clock.next = false.into();
        self.settle();
    }
    fn drive(&mut self, valid: bool, b: &Beat) {
        let u = &mut self.uut;
        u.inbound.valid.next = valid;
        u.inbound.data.next = ResultBeat {
            header: b.0,
            last: b.1,
            id: b.2.into(),
            count: b.3.into(),
            visited: b.4.into(),
            address: b.5.into(),
            distance: b.6.into(),
            pair: false,
            address2: 0.into(),
            distance2: 0.into(),
        };
    }
    fn out_beat(&self) -> Beat {
        let o = self.uut.outbound.data.val();
        (
            o.header,
            o.last,
            o.id.to_u64(),
            o.count.to_u64(),
            o.visited.to_u64(),
            o.address.to_u64(),
            o.distance.to_u64(),
        )
    }
}

/// Stream `n` beats with the given valid / ready probabilities; returns the cycles.
fn stream(bypass: bool, n: u64, p_valid: f64, p_ready: f64, seed: u64) -> usize {
    let mut r = crate::common::rng(seed);
    let mut bench = Bench::new(bypass);
    let beats: Vec<Beat> = (0..n).map(|i| random_beat(&mut r, i)).collect();
    let mut sent = 0usize;
    let mut received: Vec<Beat> = Vec::new();
    // The beat presented downstream while it was stalled must still be there.
    let mut stalled: Option<Beat> = None;
    let mut cycles = 0;
    // A beat offered upstream stays offered until taken (the source obeys the rule too).
    let mut offering = false;
    while received.len() < n as usize {
        cycles += 1;
        assert!(
            cycles < 100 * n as usize + 100,
            "stream stuck: sent {sent}, received {}",
            received.len()
        );
        offering = sent < n as usize && (offering || r.gen_bool(p_valid));
        let beat = beats.get(sent).copied().unwrap_or_default();
        let driven = offering;
        bench.drive(driven, &beat);
        bench.uut.outbound.ready.next = r.gen_bool(p_ready);
        bench.settle();
        if bench.uut.outbound.valid.val() {
            let b = bench.out_beat();
            if let Some(s) = stalled {
                assert_eq!(b, s, "a stalled beat changed before it was taken");
            }
            if bench.uut.outbound.ready.val() {
                received.push(b);
                stalled = None;
            } else {
                stalled = Some(b);
            }
        }
        if offering && bench.uut.inbound.ready.val() {
            sent += 1;
            offering = false;
        }
        // Registered outputs must not follow the inputs within a cycle.
        if !bypass {
            let before = (bench.uut.outbound.valid.val(), bench.out_beat());
            bench.drive(!driven, &random_beat(&mut r, 999));
            bench.settle();
            assert_eq!((bench.uut.outbound.valid.val(), bench.out_beat()), before);
            bench.drive(driven, &beat);
            bench.settle();
        }
        bench.tick();
    }
    assert_eq!(received, beats, "beats lost, duplicated or reordered");
    cycles
}

#[test]
fn random_stalls_registered_and_bypass() {
    for bypass in [false, true] {
        for (i, (pv, pr)) in [(1.0, 1.0), (0.7, 0.5), (0.3, 0.9), (1.0, 0.2), (0.5, 0.5)]
            .into_iter()
            .enumerate()
        {
            stream(bypass, 400, pv, pr, 10 + i as u64);
        }
    }
}

#[test]
fn full_throughput() {
    // One beat per cycle with no stalls; the register adds one cycle of latency.
    let n = 200;
    assert_eq!(stream(true, n, 1.0, 1.0, 1), n as usize);
    assert_eq!(stream(false, n, 1.0, 1.0, 1), n as usize + 1);
}

#[test]
fn in_ready_is_registered() {
    // in_ready must not depend on out_ready within a cycle in the registered build.
    let mut bench = Bench::new(false);
    let mut r = crate::common::rng(7);
    for _ in 0..300 {
        bench.drive(r.gen_bool(0.8), &random_beat(&mut r, 1));
        bench.uut.outbound.ready.next = r.gen_bool(0.3);
        bench.settle();
        let ready = bench.uut.inbound.ready.val();
        bench.uut.outbound.ready.next = !bench.uut.outbound.ready.val();
        bench.settle();
        assert_eq!(bench.uut.inbound.ready.val(), ready);
        bench.tick();
    }
}
