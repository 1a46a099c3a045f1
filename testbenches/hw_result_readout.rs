//! ResultReadout against a scoreboard: six queries finish at random times with
//! random found lists (0..=K photons), the bench answers the sequencer's reads as
//! the port does (header and id of `index`, the photons of `entry` once
//! `reading`), frees a query on `done` and stalls the result stream at random.
//! Every packet must be its query's header and photons in list order, one or two
//! a beat, `last` on the final beat; every finished query is read out exactly
//! once, and a new selection is the lowest finished query.

use photon_fpga::hw::config::core_config::CoreConfig;
use photon_fpga::hw::modules::result_readout::ResultReadout;
use rand::Rng;
use rust_hdl::prelude::*;

use crate::common::{clock_cycle, rng, settle};

const QUERIES: usize = 6;
const K: usize = 10;

#[derive(Clone, Debug, PartialEq)]
struct Packet {
    id: u64,
    visited: u64,
    found: Vec<(u64, u64)>,
}

fn cycle(uut: &mut ResultReadout) {
    clock_cycle(uut, |u| &mut u.clock);
}

fn run(per_beat: usize, pipelined: bool, seed: u64) {
    let cfg = CoreConfig {
        k: K,
        queries_per_port: QUERIES,
        pipelined,
        ..CoreConfig::paper()
    };
    let mut uut = ResultReadout::new(&cfg, per_beat);
    uut.connect_all();
    check_all(&uut).unwrap();
    let mut r = rng(seed);
    let mut finished: [Option<Packet>; QUERIES] = Default::default();
    let mut expected = Vec::new();
    let mut received = Vec::new();
    // The packet being received: header fields and photons so far.
    let mut open: Option<(Packet, u64)> = None;
    let mut next_id = 100u64;
    uut.reset.next = true;
    cycle(&mut uut);
    uut.reset.next = false;
    for step in 0..6000 {
        // A free query finishes now and then (not while it is being read out).
        let q = r.gen_range(0..QUERIES);
        if step < 5000 && finished[q].is_none() && r.gen_bool(0.2) {
            let n = r.gen_range(0..=K);
            let p = Packet {
                id: next_id,
                visited: r.gen_range(1..4000),
                found: (0..n)
                    .map(|_| (r.gen_range(1..1024), r.gen_range(0..4096)))
                    .collect(),
            };
            next_id += 1;
            expected.push(p.clone());
            finished[q] = Some(p);
        }
        let mask: u64 = (0..QUERIES)
            .filter(|&i| finished[i].is_some())
            .map(|i| 1u64 << i)
            .sum();
        let idle = uut.select.val().to_u64() == 0;
        uut.finished.next = mask.into();
        uut.result.ready.next = r.gen_bool(0.6);
        settle(&mut uut);
        // Answer the reads of the selected query.
        let index = uut.index.val().to_u64() as usize;
        let sel = finished[index].clone().unwrap_or(Packet {
            id: 0,
            visited: 0,
            found: vec![],
        });
        uut.count.next = (sel.found.len() as u64).into();
        uut.visited.next = sel.visited.into();
        uut.id.next = sel.id.into();
        let entry = uut.entry.val().to_u64() as usize * per_beat;
        let reading = uut.reading.val().to_u64() != 0;
        let photon = |i: usize| sel.found.get(i).copied().unwrap_or((0, 0));
        let (a, d) = if reading { photon(entry) } else { (0, 0) };
        let two = reading && per_beat == 2 && uut.left.val().to_u64() > 1;
        let (a2, d2) = if two { photon(entry + 1) } else { (0, 0) };
        uut.address.next = a.into();
        uut.distance.next = d.into();
        uut.pair.next = two;
        uut.address2.next = a2.into();
        uut.distance2.next = d2.into();
        settle(&mut uut);
        if uut.result.valid.val() && uut.result.ready.val() {
            let b = uut.result.data.val();
            match open.take() {
                None => {
                    assert!(b.header, "step {step}: a packet starts with its header");
                    let count = b.count.to_u64();
                    assert_eq!(b.last, count == 0, "step {step}: last of the header");
                    let p = Packet {
                        id: b.id.to_u64(),
                        visited: b.visited.to_u64(),
                        found: vec![],
                    };
                    if b.last {
                        received.push(p);
                    } else {
                        open = Some((p, count));
                    }
                }
                Some((mut p, count)) => {
                    assert!(!b.header, "step {step}: entry beat");
                    p.found.push((b.address.to_u64(), b.distance.to_u64()));
                    assert_eq!(b.pair, per_beat == 2 && p.found.len() < count as usize);
                    if b.pair {
                        p.found.push((b.address2.to_u64(), b.distance2.to_u64()));
                    }
                    assert_eq!(b.last, p.found.len() == count as usize, "step {step}");
                    if b.last {
                        received.push(p);
                    } else {
                        open = Some((p, count));
                    }
                }
            }
        }
        let done = uut.done.val();
        let select = uut.select.val().to_u64();
        cycle(&mut uut);
        if done {
            assert_eq!(select.count_ones(), 1);
            finished[select.trailing_zeros() as usize] = None;
        }
        // A selection out of idle is the lowest finished query.
        if idle && uut.select.val().to_u64() != 0 {
            assert_eq!(
                uut.select.val().to_u64(),
                mask & mask.wrapping_neg(),
                "step {step}"
            );
        }
    }
    assert!(open.is_none() && finished.iter().all(|f| f.is_none()));
    // Every finished query once, with its own header and photons.
    received.sort_by_key(|p| p.id);
    assert_eq!(received.len(), expected.len());
    assert_eq!(received, expected);
}

#[test]
fn one_photon_a_beat_with_random_stalls() {
    run(1, true, 41);
    run(1, false, 42);
}

#[test]
fn two_photons_a_beat_with_random_stalls() {
    run(2, true, 43);
    run(2, false, 44);
}
