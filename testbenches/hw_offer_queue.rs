//! OfferQueue against a model of its rule, with a taker that says a cycle late
//! whether it took the offer: random upstream beats (valid held until they go in),
//! random verdicts and random resets. The model keeps the beats in the order they
//! came in, and which one was offered last; every cycle the queue's offer must be
//! the oldest beat in it that was not offered in the previous cycle (none if there
//! is none), and `inbound.ready` must be high exactly while it holds fewer than
//! three beats. Every beat must be taken once. The offer and `inbound.ready` must
//! not follow this cycle's inputs (they are registered), and with every beat
//! taken the queue must offer one a cycle.

use crate::common::{clock_cycle, rng, settle};
use photon_fpga::hw::primitives::offer_queue::OfferQueue;
use photon_fpga::hw::primitives::stream::ResultBeat;
use rand::Rng;
use rust_hdl::prelude::*;

fn beat(r: &mut impl Rng, serial: u64) -> ResultBeat {
    ResultBeat {
        header: r.gen(),
        last: r.gen(),
        id: r.gen_range(0..1u64 << 16).into(),
        count: r.gen_range(0..=255u64).into(),
        visited: r.gen_range(0..=u32::MAX as u64).into(),
        address: serial.into(),
        distance: r.gen_range(0..=u32::MAX as u64).into(),
        pair: r.gen(),
        address2: r.gen_range(0..1u64 << 24).into(),
        distance2: r.gen_range(0..=u32::MAX as u64).into(),
    }
}

/// The queue's outputs: `inbound.ready`, and the offered beat if any.
fn outputs(q: &OfferQueue<ResultBeat>) -> (bool, Option<ResultBeat>) {
    (
        q.inbound.ready.val(),
        q.offer_valid.val().then(|| q.offer.val()),
    )
}

/// `cycles` cycles with upstream valid / take probabilities and a reset now and
/// then; returns the beats taken.
fn run(cycles: usize, p_valid: f64, p_take: f64, p_reset: f64, seed: u64) -> usize {
    let mut r = rng(seed);
    let mut uut = OfferQueue::<ResultBeat>::new();
    uut.connect_all();
    check_all(&uut).expect("OfferQueue checks");
    uut.reset.next = true;
    clock_cycle(&mut uut, |u| &mut u.clock);
    uut.reset.next = false;
    // The model: the beats in, oldest first, and the serial offered last cycle
    // and whether the taker took it.
    let mut held: Vec<ResultBeat> = Vec::new();
    let mut last: Option<(u64, bool)> = None;
    let mut serial = 0u64;
    let mut upstream: Option<ResultBeat> = None;
    let mut taken_serials = std::collections::HashSet::new();
    for c in 0..cycles {
        let reset = r.gen_bool(p_reset);
        if upstream.is_none() && r.gen_bool(p_valid) {
            upstream = Some(beat(&mut r, serial));
            serial += 1;
        }
        // The verdict on last cycle's offer leaves the queue now.
        let taken = last.is_some_and(|(_, t)| t);
        if let Some((s, true)) = last {
            held.retain(|b| b.address.to_u64() != s);
        }
        uut.reset.next = reset;
        uut.taken.next = taken;
        uut.inbound.valid.next = upstream.is_some();
        uut.inbound.data.next = upstream.unwrap_or_default();
        settle(&mut uut);
        let now = outputs(&uut);
        // The model's offer: the oldest beat not offered last cycle.
        let want = held
            .iter()
            .find(|b| last.is_none_or(|(s, _)| b.address.to_u64() != s))
            .copied();
        assert_eq!(now.1, want, "cycle {c}: the offer");
        assert_eq!(
            now.0,
            held.len() + usize::from(taken) < 3,
            "cycle {c}: ready"
        );
        // Registered: other inputs this cycle change no output.
        uut.taken.next = !taken;
        uut.inbound.valid.next = !uut.inbound.valid.val();
        uut.inbound.data.next = beat(&mut r, 1 << 23);
        settle(&mut uut);
        assert_eq!(outputs(&uut), now, "cycle {c}: an output follows an input");
        uut.taken.next = taken;
        uut.inbound.valid.next = upstream.is_some();
        uut.inbound.data.next = upstream.unwrap_or_default();
        settle(&mut uut);
        if reset {
            held.clear();
            upstream = None;
            last = None;
        } else {
            last = now.1.map(|b| {
                let t = r.gen_bool(p_take);
                if t {
                    assert!(
                        taken_serials.insert(b.address.to_u64()),
                        "cycle {c}: beat {} taken twice",
                        b.address.to_u64()
                    );
                }
                (b.address.to_u64(), t)
            });
            if now.0 {
                if let Some(b) = upstream.take() {
                    held.push(b);
                }
            }
        }
        clock_cycle(&mut uut, |u| &mut u.clock);
    }
    taken_serials.len()
}

#[test]
fn offers_the_oldest_beat_not_waiting_for_its_verdict() {
    for (i, (pv, pt, pz)) in [
        (1.0, 1.0, 0.0),
        (0.7, 0.5, 0.01),
        (0.3, 0.9, 0.0),
        (1.0, 0.2, 0.02),
        (0.5, 0.5, 0.05),
        (0.9, 0.7, 0.0),
    ]
    .into_iter()
    .enumerate()
    {
        assert!(run(3000, pv, pt, pz, 60 + i as u64) > 200);
    }
}

#[test]
fn a_beat_a_cycle() {
    // Nothing refused: one beat a cycle after the first cycle, in which the
    // first beat goes in.
    assert_eq!(run(500, 1.0, 1.0, 0.0, 3), 499);
}
