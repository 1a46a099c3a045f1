//! PacketMerge against a stream scoreboard: N sources, each with a queue of
//! numbered packets of random length (a header, then zero or more photon beats,
//! `last` on the final one) offered at random (each beat held until it is taken, as
//! a valid/ready source must), and a sink that is ready at random. Checked every
//! cycle from the block's documented behaviour: at most one source is ready, only
//! while the sink is; a beat leaves only when a source's beat is taken, with that
//! beat's data; once a packet's first beat left, its source keeps the output until
//! its `last` (nothing else leaves in between); a new packet is chosen round-robin
//! among the offering sources (the lowest above the last served, else the lowest).
//! At the end every beat left exactly once, each source's packets in order and
//! whole.

use photon_fpga::hw::primitives::stream::ResultBeat;
use photon_fpga::hw::top::packet_merge::PacketMerge;
use rand::Rng;
use rand_pcg::Pcg64;
use rust_hdl::prelude::*;
use std::collections::VecDeque;

use crate::common::{clock_cycle, settle};

/// Beat `b` of packet `p` (of `len` beats) from source `s`: the fields name it.
fn packet_beat(s: usize, p: u64, b: u64, len: u64) -> ResultBeat {
    ResultBeat {
        header: b == 0,
        last: b + 1 == len,
        id: ((s as u64) << 24 | p).into(),
        count: (len - 1).into(),
        visited: b.into(),
        address: (p * 3 + b).into(),
        distance: (s as u64 * 1000 + b).into(),
        pair: b % 2 == 1,
        address2: (b * 5).into(),
        distance2: p.into(),
    }
}

fn packets(r: &mut Pcg64, s: usize, count: u64) -> Vec<Vec<ResultBeat>> {
    (0..count)
        .map(|p| {
            let len = match r.gen_range(0..4) {
                0 => 1,
                1 => 2,
                _ => r.gen_range(1..12),
            };
            (0..len).map(|b| packet_beat(s, p, b, len)).collect()
        })
        .collect()
}

fn merge_against_scoreboard(
    n: usize,
    r_out: usize,
    per_source: u64,
    p_valid: f64,
    p_ready: f64,
    seed: u64,
) {
    let mut uut = PacketMerge::grouped(n, r_out);
    uut.connect_all();
    check_all(&uut).expect("PacketMerge checks");
    let g = n / r_out;
    let what = format!("n = {n}, r = {r_out}");
    let mut r = crate::common::rng(seed);
    let sent: Vec<Vec<Vec<ResultBeat>>> = (0..n).map(|s| packets(&mut r, s, per_source)).collect();
    let mut queues: Vec<VecDeque<ResultBeat>> = sent
        .iter()
        .map(|ps| ps.iter().flatten().copied().collect())
        .collect();
    let total: usize = queues.iter().map(|q| q.len()).sum();
    let mut offering = vec![false; n];
    // Per output: the beats that left (with their source), the source of the packet
    // in progress, and of the last beat that left.
    let mut merged: Vec<Vec<(usize, ResultBeat)>> = vec![Vec::new(); r_out];
    let mut locked: Vec<Option<usize>> = vec![None; r_out];
    let mut last: Vec<Option<usize>> = vec![None; r_out];

    uut.reset.next = true;
    clock_cycle(&mut uut, |u| &mut u.clock);
    uut.reset.next = false;
    settle(&mut uut);

    let mut cycles = 0;
    while merged.iter().map(|m| m.len()).sum::<usize>() < total {
        cycles += 1;
        assert!(cycles < 100 * total, "{what}: stuck");
        for s in 0..n {
            offering[s] = !queues[s].is_empty() && (offering[s] || r.gen_bool(p_valid));
            uut.sources[s].valid.next = offering[s];
            uut.sources[s].data.next = if offering[s] {
                queues[s][0]
            } else {
                packet_beat(s, 0xBAD, 0, 1)
            };
        }
        let sink_ready: Vec<bool> = (0..r_out).map(|_| r.gen_bool(p_ready)).collect();
        for (o, &rd) in sink_ready.iter().enumerate() {
            uut.merged[o].ready.next = rd;
        }
        settle(&mut uut);

        // Who the model lets through each output: the locked source, else round
        // robin within the output's group.
        let readies: Vec<bool> = (0..n).map(|s| uut.sources[s].ready.val()).collect();
        let mut taken = vec![];
        for o in 0..r_out {
            let group = o * g..(o + 1) * g;
            let lowest_from =
                |from: usize| (from.max(group.start)..group.end).find(|&i| offering[i]);
            let pick = match locked[o] {
                Some(s) => Some(s),
                None => last[o]
                    .and_then(|l| lowest_from(l + 1))
                    .or_else(|| lowest_from(0)),
            };
            for s in group.clone() {
                assert!(
                    !readies[s] || (sink_ready[o] && pick == Some(s)),
                    "{what} cycle {cycles}: source {s} ready (output {o}: sink {}, pick \
                     {pick:?}, locked {:?}, offering {offering:?})",
                    sink_ready[o],
                    locked[o]
                );
            }
            let out_valid = uut.merged[o].valid.val();
            assert_eq!(
                out_valid,
                pick.is_some_and(|s| offering[s]),
                "{what} cycle {cycles}: output {o} valid (pick {pick:?}, offering {offering:?})"
            );
            let here: Vec<usize> = group.filter(|&s| offering[s] && readies[s]).collect();
            if out_valid {
                let s = pick.unwrap();
                assert_eq!(
                    uut.merged[o].data.val(),
                    queues[s][0],
                    "{what} cycle {cycles}: data"
                );
            }
            if out_valid && sink_ready[o] {
                assert_eq!(here, vec![pick.unwrap()], "{what} cycle {cycles}: taken");
            } else {
                assert!(
                    here.is_empty(),
                    "{what} cycle {cycles}: taken {here:?} unsent"
                );
            }
            taken.extend(here.into_iter().map(|s| (o, s)));
        }
        for &(o, s) in &taken {
            let b = queues[s].pop_front().unwrap();
            merged[o].push((s, uut.merged[o].data.val()));
            assert_eq!(merged[o].last().unwrap().1, b);
            offering[s] = false;
            locked[o] = if b.last { None } else { Some(s) };
            last[o] = Some(s);
        }
        uut.clock.next = true.into();
        settle(&mut uut);
        uut.clock.next = false.into();
        settle(&mut uut);
    }

    // Each output's stream, cut at `last`: whole packets from one source of its
    // group each, and per source the packets it sent, in order.
    let mut got: Vec<Vec<Vec<ResultBeat>>> = vec![Vec::new(); n];
    for (o, out) in merged.iter().enumerate() {
        let mut current: Vec<ResultBeat> = Vec::new();
        let mut from: Option<usize> = None;
        for &(s, b) in out {
            assert!(s / g == o, "{what}: source {s} left on output {o}");
            assert!(
                from.is_none_or(|f| f == s),
                "{what}: a packet split by another source"
            );
            from = Some(s);
            current.push(b);
            if b.last {
                got[s].push(std::mem::take(&mut current));
                from = None;
            }
        }
        assert!(current.is_empty());
    }
    assert_eq!(
        got, sent,
        "{what}: packets lost, duplicated, reordered or split"
    );
}

#[test]
fn packet_merge_against_a_stream_scoreboard() {
    for (n, p_valid, p_ready, seed) in [
        (1usize, 0.6, 0.6, 101u64),
        (2, 0.9, 0.7, 102),
        (3, 0.4, 0.5, 103),
        (5, 1.0, 1.0, 104),
        (8, 0.7, 0.3, 105),
    ] {
        merge_against_scoreboard(n, 1, 120, p_valid, p_ready, seed);
    }
}

/// Several outputs, each merging its own group: no beat crosses groups, and each
/// output keeps the packet lock and the round robin of its group.
#[test]
fn grouped_merge_against_a_stream_scoreboard() {
    for (n, r_out, p_valid, p_ready, seed) in [
        (2usize, 2usize, 0.8, 0.6, 201u64),
        (4, 2, 0.6, 0.5, 202),
        (8, 4, 1.0, 1.0, 203),
        (16, 4, 0.7, 0.4, 204),
        (6, 3, 0.5, 0.9, 205),
        // The D = 32 banked core's eight result streams.
        (32, 8, 0.7, 0.5, 206),
    ] {
        merge_against_scoreboard(n, r_out, 80, p_valid, p_ready, seed);
    }
}

/// A source that pauses inside its packet keeps the output: the others wait.
#[test]
fn a_paused_packet_keeps_the_merge() {
    let mut uut = PacketMerge::new(2);
    uut.connect_all();
    check_all(&uut).unwrap();
    let a: Vec<ResultBeat> = (0..3).map(|b| packet_beat(0, 1, b, 3)).collect();
    let b = packet_beat(1, 2, 0, 1);
    let tick = |uut: &mut PacketMerge| {
        uut.clock.next = true.into();
        settle(uut);
        uut.clock.next = false.into();
        settle(uut);
    };
    uut.merged[0].ready.next = true;
    // Source 0's header leaves; then it pauses while source 1 offers a packet.
    uut.sources[0].valid.next = true;
    uut.sources[0].data.next = a[0];
    uut.sources[1].valid.next = false;
    settle(&mut uut);
    assert!(uut.sources[0].ready.val() && uut.merged[0].data.val() == a[0]);
    tick(&mut uut);
    uut.sources[0].valid.next = false;
    uut.sources[1].valid.next = true;
    uut.sources[1].data.next = b;
    for _ in 0..3 {
        settle(&mut uut);
        assert!(!uut.merged[0].valid.val() && !uut.sources[1].ready.val());
        tick(&mut uut);
    }
    for beat in &a[1..] {
        uut.sources[0].valid.next = true;
        uut.sources[0].data.next = *beat;
        settle(&mut uut);
        assert!(uut.merged[0].valid.val() && uut.merged[0].data.val() == *beat);
        assert!(!uut.sources[1].ready.val());
        tick(&mut uut);
    }
    uut.sources[0].valid.next = false;
    settle(&mut uut);
    assert!(
        uut.merged[0].valid.val() && uut.merged[0].data.val() == b && uut.sources[1].ready.val()
    );
}
