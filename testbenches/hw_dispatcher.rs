//! Dispatcher against a stream scoreboard: a source that offers numbered beats at
//! random (holding each until it is taken), sinks that are ready at random, `hold`
//! at random. Checked every cycle from the block's documented behaviour: the input
//! is ready iff some sink is ready and `hold` is low; a beat that moves goes to
//! exactly one sink, one that is ready, with the input's data, chosen round-robin
//! (the lowest ready sink above the last one served, else the lowest ready sink);
//! no sink sees a beat in a cycle no beat moves. At the end every beat arrived
//! exactly once and in order.

use photon_fpga::hw::primitives::stream::QueryBeat;
use photon_fpga::hw::top::dispatcher::Dispatcher;
use rand::Rng;
use rust_hdl::prelude::*;

use crate::common::settle;

fn beat(n: u64) -> QueryBeat {
    // Every field carries the beat's number, so a mixed-up field shows.
    QueryBeat {
        id: (0xC000_0000 | n).into(),
        x: (n & 0xFFFF).into(),
        y: ((n * 7) & 0xFFFF).into(),
        z: ((n * 13) & 0xFFFF).into(),
        radius: (n * 31).into(),
        k: (n & 0xFF).into(),
    }
}

fn dispatcher_against_scoreboard(n: usize, beats: u64, p_valid: f64, p_ready: f64, seed: u64) {
    let mut uut = Dispatcher::<QueryBeat>::new(n);
    uut.connect_all();
    check_all(&uut).expect("Dispatcher checks");
    let mut r = crate::common::rng(seed);
    let mut sent = 0u64;
    let mut offering = false;
    // What each sink took, and in which order overall.
    let mut received: Vec<(usize, QueryBeat)> = Vec::new();
    let mut last: Option<usize> = None;
    let mut cycles = 0;
    while received.len() < beats as usize {
        cycles += 1;
        assert!(
            cycles < 200 * beats as usize,
            "n = {n}: stuck after {sent} beats"
        );
        offering = sent < beats && (offering || r.gen_bool(p_valid));
        let hold = r.gen_bool(0.15);
        let ready: Vec<bool> = (0..n).map(|_| r.gen_bool(p_ready)).collect();
        uut.inbound.valid.next = offering;
        uut.inbound.data.next = if offering { beat(sent) } else { beat(0xBAD) };
        uut.hold.next = hold;
        for (i, &rd) in ready.iter().enumerate() {
            uut.sinks[i].ready.next = rd;
        }
        settle(&mut uut);
        let any_ready = ready.iter().any(|&b| b);
        assert_eq!(
            uut.inbound.ready.val(),
            any_ready && !hold,
            "n = {n} cycle {cycles}: inbound ready (sinks {ready:?}, hold {hold})"
        );
        let fire = offering && uut.inbound.ready.val();
        // The model's pick: round robin among the ready sinks.
        let lowest_from = |from: usize| (from..n).find(|&i| ready[i]);
        let pick = last
            .and_then(|l| lowest_from(l + 1))
            .or_else(|| lowest_from(0));
        let valid: Vec<bool> = (0..n).map(|i| uut.sinks[i].valid.val()).collect();
        let want: Vec<bool> = (0..n).map(|i| fire && pick == Some(i)).collect();
        assert_eq!(
            valid, want,
            "n = {n} cycle {cycles}: sink valids (ready {ready:?}, last {last:?}, fire {fire})"
        );
        for i in 0..n {
            if valid[i] && ready[i] {
                received.push((i, uut.sinks[i].data.val()));
            }
        }
        if fire {
            sent += 1;
            last = pick;
        }
        uut.clock.next = true.into();
        settle(&mut uut);
        uut.clock.next = false.into();
        settle(&mut uut);
    }
    assert_eq!(sent, beats);
    let got: Vec<QueryBeat> = received.iter().map(|&(_, b)| b).collect();
    let want: Vec<QueryBeat> = (0..beats).map(beat).collect();
    assert_eq!(got, want, "n = {n}: beats lost, duplicated or reordered");
    // Every sink was used (round robin spreads the beats).
    for i in 0..n {
        assert!(
            received.iter().any(|&(s, _)| s == i),
            "n = {n}: sink {i} never got a beat"
        );
    }
}

#[test]
fn dispatcher_against_a_stream_scoreboard() {
    for (n, p_valid, p_ready, seed) in [
        (1usize, 0.7, 0.5, 91u64),
        (2, 0.9, 0.6, 92),
        (3, 0.5, 0.3, 93),
        (5, 1.0, 0.9, 94),
        (12, 0.8, 0.15, 95),
        (32, 0.9, 0.5, 96),
    ] {
        dispatcher_against_scoreboard(n, 1500, p_valid, p_ready, seed);
    }
}
