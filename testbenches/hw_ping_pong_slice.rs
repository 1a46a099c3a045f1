//! PingPongSlice against the skid-buffer RegisterSlice it stands in for, and
//! against a FIFO model: both slices get the same random upstream beats (valid
//! held until taken), the same random downstream ready and random resets; every
//! cycle their `inbound.ready`, `outbound.valid` and offered beat must be equal,
//! and every beat must arrive once and in order. Also checked: `inbound.ready` and
//! the outputs are registered (they do not follow this cycle's inputs).

use photon_fpga::hw::primitives::ping_pong_slice::PingPongSlice;
use photon_fpga::hw::primitives::register_slice::RegisterSlice;
use photon_fpga::hw::primitives::stream::ResultBeat;
use rand::Rng;
use rust_hdl::prelude::*;
use std::collections::VecDeque;

#[derive(LogicBlock)]
struct Pair {
    clock: Signal<In, Clock>,
    reset: Signal<In, bool>,
    valid: Signal<In, bool>,
    data: Signal<In, ResultBeat>,
    ready: Signal<In, bool>,
    skid: RegisterSlice<ResultBeat>,
    ping: PingPongSlice<ResultBeat>,
}

impl Logic for Pair {
    #[hdl_gen]
    fn update(&mut self) {
        self.skid.clock.next = self.clock.val();
        self.ping.clock.next = self.clock.val();
        self.skid.reset.next = self.reset.val();
        self.ping.reset.next = self.reset.val();
        self.skid.inbound.valid.next = self.valid.val();
        self.ping.inbound.valid.next = self.valid.val();
        self.skid.inbound.data.next = self.data.val();
        self.ping.inbound.data.next = self.data.val();
        self.skid.outbound.ready.next = self.ready.val();
        self.ping.outbound.ready.next = self.ready.val();
    }
}

fn beat(r: &mut impl Rng, id: u64) -> ResultBeat {
    ResultBeat {
        header: r.gen(),
        last: r.gen(),
        id: id.into(),
        count: r.gen_range(0..=255u64).into(),
        visited: r.gen_range(0..=u32::MAX as u64).into(),
        address: r.gen_range(0..1u64 << 24).into(),
        distance: r.gen_range(0..=u32::MAX as u64).into(),
        pair: r.gen(),
        address2: r.gen_range(0..1u64 << 24).into(),
        distance2: r.gen_range(0..=u32::MAX as u64).into(),
    }
}

/// The ping-pong slice's outputs (ready, valid, the beat if valid).
fn ping(p: &Pair) -> (bool, bool, Option<ResultBeat>) {
    let o = &p.ping.outbound;
    (
        p.ping.inbound.ready.val(),
        o.valid.val(),
        o.valid.val().then(|| o.data.val()),
    )
}

/// `cycles` cycles with upstream valid / downstream ready probabilities and a
/// reset now and then; returns the beats delivered.
fn run(cycles: usize, p_valid: f64, p_ready: f64, p_reset: f64, seed: u64) -> usize {
    let mut r = crate::common::rng(seed);
    let mut uut = Pair {
        clock: Default::default(),
        reset: Default::default(),
        valid: Default::default(),
        data: Default::default(),
        ready: Default::default(),
        skid: RegisterSlice::new(false),
        ping: PingPongSlice::new(),
    };
    uut.connect_all();
    check_all(&uut).expect("PingPongSlice checks");
    uut.reset.next = true;
    crate::common::clock_cycle(&mut uut, |u| &mut u.clock);
    uut.reset.next = false;
    let mut model: VecDeque<ResultBeat> = VecDeque::new();
    let mut next_id = 0u64;
    let mut offering: Option<ResultBeat> = None;
    let mut delivered = 0;
    for _ in 0..cycles {
        let reset = r.gen_bool(p_reset);
        if offering.is_none() && r.gen_bool(p_valid) {
            offering = Some(beat(&mut r, next_id));
            next_id += 1;
        }
        uut.reset.next = reset;
        uut.valid.next = offering.is_some();
        uut.data.next = offering.unwrap_or_default();
        uut.ready.next = r.gen_bool(p_ready);
        crate::common::settle(&mut uut);
        let skid = (
            uut.skid.inbound.ready.val(),
            uut.skid.outbound.valid.val(),
            uut.skid
                .outbound
                .valid
                .val()
                .then(|| uut.skid.outbound.data.val()),
        );
        let now = ping(&uut);
        assert_eq!(now, skid, "the slices differ");
        assert_eq!(now.2, model.front().copied(), "not the model's oldest beat");
        // Registered: flipping this cycle's inputs changes none of the outputs.
        uut.valid.next = !uut.valid.val();
        uut.data.next = beat(&mut r, 999);
        uut.ready.next = !uut.ready.val();
        crate::common::settle(&mut uut);
        assert_eq!(ping(&uut), now, "an output follows an input");
        uut.valid.next = offering.is_some();
        uut.data.next = offering.unwrap_or_default();
        uut.ready.next = !uut.ready.val();
        crate::common::settle(&mut uut);
        if reset {
            model.clear();
            offering = None;
        } else {
            if now.1 && uut.ready.val() {
                model.pop_front();
                delivered += 1;
            }
            if now.0 {
                if let Some(b) = offering.take() {
                    model.push_back(b);
                }
            }
        }
        crate::common::clock_cycle(&mut uut, |u| &mut u.clock);
    }
    delivered
}

#[test]
fn equals_the_skid_buffer_under_random_stalls_and_resets() {
    for (i, (pv, pr, pz)) in [
        (1.0, 1.0, 0.0),
        (0.7, 0.5, 0.01),
        (0.3, 0.9, 0.0),
        (1.0, 0.2, 0.02),
        (0.5, 0.5, 0.05),
    ]
    .into_iter()
    .enumerate()
    {
        assert!(run(2000, pv, pr, pz, 40 + i as u64) > 100);
    }
}

#[test]
fn a_beat_a_cycle() {
    // Nothing stalls: one beat per cycle after the first cycle's latency.
    assert_eq!(run(500, 1.0, 1.0, 0.0, 3), 499);
}
