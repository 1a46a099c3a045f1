//! OfferQueue against a model of its rule, with a taker that says a cycle late
//! whether it took the offer: random upstream beats (valid held until they go in),
//! random verdicts and random resets, then a tail that takes every offer. The
//! model keeps the beats in the order they came in, and which one was offered
//! last; every cycle the queue's offer must be the oldest beat in it that was not
//! offered in the previous cycle (none if there is none) — or, built persistent,
//! the beat offered in the previous cycle again if it had been refused before —
//! and `inbound.ready` must be high exactly while it holds fewer than three beats.
//! The taker takes a beat at most once; every beat that went in must be taken
//! unless a reset dropped it. The offer and `inbound.ready` must not follow this
//! cycle's inputs (they are registered), with every beat taken the queue must
//! offer one a cycle, and the exported Verilog must pass the linters.

use crate::common::{clock_cycle, lint_top, rng, settle};
use photon_fpga::hw::export::verilog::export_block;
use photon_fpga::hw::primitives::offer_queue::OfferQueue;
use photon_fpga::hw::primitives::stream::ResultBeat;
use rand::Rng;
use rust_hdl::prelude::*;
use std::collections::{HashMap, HashSet};

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
/// then, then cycles that take every offer until the queue is empty; returns the
/// beats taken.
fn run(
    persistent: bool,
    cycles: usize,
    p_valid: f64,
    p_take: f64,
    p_reset: f64,
    seed: u64,
) -> usize {
    let mut r = rng(seed);
    let mut uut = if persistent {
        OfferQueue::<ResultBeat>::persistent()
    } else {
        OfferQueue::<ResultBeat>::new()
    };
    uut.connect_all();
    check_all(&uut).expect("OfferQueue checks");
    uut.reset.next = true;
    clock_cycle(&mut uut, |u| &mut u.clock);
    uut.reset.next = false;
    // The model: the beats in, oldest first; the serial offered last cycle,
    // whether the taker took it and whether it was still in after that cycle's
    // verdict; the cycle of each beat's first refusal.
    let mut held: Vec<ResultBeat> = Vec::new();
    let mut last: Option<(u64, bool)> = None;
    let mut last_kept = false;
    let mut refused: HashMap<u64, usize> = HashMap::new();
    let mut serial = 0u64;
    let mut upstream: Option<ResultBeat> = None;
    let mut taken_serials = HashSet::new();
    let (mut entered, mut dropped) = (0usize, 0usize);
    let mut c = 0;
    while c < cycles || !held.is_empty() || upstream.is_some() || last.is_some() {
        assert!(c < cycles + 20, "the queue does not drain");
        let tail = c >= cycles;
        let reset = !tail && r.gen_bool(p_reset);
        if !tail && upstream.is_none() && r.gen_bool(p_valid) {
            upstream = Some(beat(&mut r, serial));
            serial += 1;
        }
        // The verdict on last cycle's offer: a beat taken leaves the queue now.
        let taken = last.is_some_and(|(_, t)| t);
        match last {
            Some((s, true)) => held.retain(|b| b.address.to_u64() != s),
            Some((s, false)) => {
                refused.entry(s).or_insert(c);
            }
            None => {}
        }
        uut.reset.next = reset;
        uut.taken.next = taken;
        uut.inbound.valid.next = upstream.is_some();
        uut.inbound.data.next = upstream.unwrap_or_default();
        settle(&mut uut);
        let now = outputs(&uut);
        // The model's offer: persistent, the beat offered last cycle again if
        // it had been refused before that offer was chosen and was still in;
        // else the oldest beat not offered last cycle.
        let again = last
            .filter(|&(s, _)| {
                persistent && last_kept && refused.get(&s).is_some_and(|&k| k + 2 <= c)
            })
            .map(|(s, _)| s);
        let want = match again {
            Some(s) => Some(s),
            None => held
                .iter()
                .find(|b| last.is_none_or(|(s, _)| b.address.to_u64() != s))
                .map(|b| b.address.to_u64()),
        };
        assert_eq!(
            now.1.map(|b| b.address.to_u64()),
            want,
            "cycle {c}: the offer"
        );
        if let Some(b) = now.1 {
            let s = b.address.to_u64();
            let in_queue = held.iter().find(|h| h.address.to_u64() == s);
            assert!(
                in_queue.is_none_or(|h| *h == b),
                "cycle {c}: beat {s} changed"
            );
        }
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
            dropped += held.len();
            held.clear();
            upstream = None;
            last = None;
            last_kept = false;
        } else {
            // The taker takes a beat at most once: a beat offered again in the
            // cycle after it was taken is refused, as the crossbar does.
            last = now.1.map(|b| {
                let s = b.address.to_u64();
                let t = !taken_serials.contains(&s) && (tail || r.gen_bool(p_take));
                if t {
                    taken_serials.insert(s);
                }
                (s, t)
            });
            last_kept = now
                .1
                .is_some_and(|b| held.iter().any(|h| h.address == b.address));
            if now.0 {
                if let Some(b) = upstream.take() {
                    held.push(b);
                    entered += 1;
                }
            }
        }
        clock_cycle(&mut uut, |u| &mut u.clock);
        c += 1;
    }
    assert_eq!(taken_serials.len() + dropped, entered, "beats lost");
    taken_serials.len()
}

const STIMULI: [(f64, f64, f64); 6] = [
    (1.0, 1.0, 0.0),
    (0.7, 0.5, 0.01),
    (0.3, 0.9, 0.0),
    (1.0, 0.2, 0.02),
    (0.5, 0.5, 0.05),
    (0.9, 0.7, 0.0),
];

#[test]
fn offers_the_oldest_beat_not_waiting_for_its_verdict() {
    for (i, (pv, pt, pz)) in STIMULI.into_iter().enumerate() {
        assert!(run(false, 3000, pv, pt, pz, 60 + i as u64) > 200);
    }
}

#[test]
fn persistent_offers_a_refused_beat_every_cycle_until_taken() {
    for (i, (pv, pt, pz)) in STIMULI.into_iter().enumerate() {
        assert!(run(true, 3000, pv, pt, pz, 70 + i as u64) > 200);
    }
}

#[test]
fn a_beat_a_cycle() {
    // Nothing refused: one beat a cycle after the first cycle, in which the
    // first beat goes in (the tail takes the last one).
    for persistent in [false, true] {
        assert_eq!(run(persistent, 500, 1.0, 1.0, 0.0, 3), 500);
    }
}

#[test]
#[cfg_attr(
    not(all(has_yosys, has_verilator, has_iverilog)),
    ignore = "needs yosys, verilator and iverilog"
)]
fn exported_verilog_lints() {
    for q in [OfferQueue::<ResultBeat>::new(), OfferQueue::persistent()] {
        let e = export_block(q).unwrap();
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("top.v"), &e.verilog).unwrap();
        lint_top(dir.path());
    }
}
