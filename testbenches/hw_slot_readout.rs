//! SlotReadout against a packet model: query slots loaded with an id, found photons
//! appended and overwritten at random list entries, searches ended with a count and
//! a read count, and a sink that is ready at random; a slot is loaded again as soon
//! as the block frees it. From the block's documented behaviour (and `ResultBeat`'s):
//! each ended search leaves as one packet, a header (the low `id_bits` of the id, the
//! count, the reads; `last` iff the count is zero), then the photons of list entries
//! 0..count in order, two a beat (`pair` on a beat with two), `last` on the final
//! beat, the id on every beat; a beat stays put while the sink stalls; `freed` names
//! the slot (one-hot) once per packet, no later than the cycle its last beat leaves,
//! after which the slot's memories may be written again without changing the packet.

use photon_fpga::hw::barrel::slot_readout::SlotReadout;
use photon_fpga::hw::config::controller::Controller;
use photon_fpga::hw::config::core_config::{low_mask, CoreConfig, BARREL_SLOTS};
use photon_fpga::hw::config::metric::Metric;
use photon_fpga::hw::primitives::stream::ResultBeat;
use rand::seq::SliceRandom;
use rand::Rng;
use rust_hdl::prelude::*;
use std::collections::HashMap;

use crate::common::{clock_cycle, settle};

/// A slot's life: free, running a search (its id and found list so far), or
/// finished until the block frees it.
#[derive(Clone, Debug, PartialEq)]
enum Slot {
    Free,
    Running { id: u64, found: Vec<(u64, u64)> },
    Finished { id: u64 },
}

/// The beats of one packet, as the documentation lays them out.
fn packet(id: u64, visited: u64, found: &[(u64, u64)]) -> Vec<ResultBeat> {
    let mut beats = vec![ResultBeat {
        header: true,
        last: found.is_empty(),
        id: id.into(),
        count: (found.len() as u64).into(),
        visited: visited.into(),
        ..Default::default()
    }];
    for (j, two) in found.chunks(2).enumerate() {
        beats.push(ResultBeat {
            header: false,
            last: 2 * j + two.len() == found.len(),
            id: id.into(),
            address: two[0].0.into(),
            distance: two[0].1.into(),
            pair: two.len() == 2,
            address2: two.get(1).map_or(0, |p| p.0).into(),
            distance2: two.get(1).map_or(0, |p| p.1).into(),
            ..Default::default()
        });
    }
    beats
}

/// The fields a beat means (a header's id, count and reads; a photon beat's id,
/// photons and pair flag): the rest are not compared.
fn meaningful(b: &ResultBeat) -> ResultBeat {
    if b.header {
        ResultBeat {
            header: true,
            last: b.last,
            id: b.id,
            count: b.count,
            visited: b.visited,
            ..Default::default()
        }
    } else {
        ResultBeat {
            header: false,
            last: b.last,
            id: b.id,
            address: b.address,
            distance: b.distance,
            pair: b.pair,
            address2: if b.pair { b.address2 } else { 0.into() },
            distance2: if b.pair { b.distance2 } else { 0.into() },
            ..Default::default()
        }
    }
}

fn readout_against_model(cfg: CoreConfig, searches: usize, p_ready: f64, seed: u64) {
    cfg.validate().expect("config");
    let (q, k) = (cfg.queries_per_port, cfg.k);
    let id_mask = low_mask(cfg.id_bits());
    let mut uut = SlotReadout::new(&cfg);
    uut.connect_all();
    check_all(&uut).expect("SlotReadout checks");
    let mut r = crate::common::rng(seed);
    let mut slots = vec![Slot::Free; q];
    // Packets ended and not yet (wholly) out, by id: their beats, the slot, whether
    // the slot was freed.
    let mut pending: HashMap<u64, (Vec<ResultBeat>, usize, bool)> = HashMap::new();
    // The packet leaving now and the beats of it that left.
    let mut current: Option<(u64, usize)> = None;
    let mut stalled: Option<ResultBeat> = None;
    let (mut started, mut ended, mut packets_out, mut beats_out) = (0usize, 0usize, 0, 0);
    let mut next_id = 0u64;

    uut.reset.next = true;
    clock_cycle(&mut uut, |u| &mut u.clock);
    uut.reset.next = false;

    let mut cycle = 0;
    while packets_out < searches {
        cycle += 1;
        assert!(
            cycle < 400 * searches,
            "stuck: {packets_out} of {searches} packets out"
        );
        let running: Vec<usize> = (0..q)
            .filter(|&s| matches!(slots[s], Slot::Running { .. }))
            .collect();
        let free: Vec<usize> = (0..q).filter(|&s| slots[s] == Slot::Free).collect();
        // A load, a photon entering a list and a search ending, each now and then,
        // each in a different slot.
        let load = (started < searches && r.gen_bool(0.3))
            .then(|| free.choose(&mut r).copied())
            .flatten();
        let insert = r
            .gen_bool(0.6)
            .then(|| running.choose(&mut r).copied())
            .flatten();
        let end = r
            .gen_bool(0.25)
            .then(|| {
                running
                    .iter()
                    .filter(|&&s| Some(s) != insert)
                    .copied()
                    .collect::<Vec<_>>()
            })
            .and_then(|c| c.choose(&mut r).copied());

        uut.id_write.next = load.is_some();
        uut.id_slot.next = (load.unwrap_or(r.gen_range(0..q)) as u64).into();
        // A tag no query in flight has (as the host's tag pool gives), its bits
        // above `id_bits` random: only the low ones come back.
        while pending.contains_key(&next_id)
            || slots.iter().any(|s| match s {
                Slot::Running { id, .. } | Slot::Finished { id } => *id == next_id,
                Slot::Free => false,
            })
        {
            next_id = (next_id + 1) & id_mask;
        }
        let id = (next_id | r.gen::<u64>() << cfg.id_bits()) & u32::MAX as u64;
        uut.id.next = id.into();
        uut.found_write.next = insert.is_some();
        let mut entry = (0usize, 0u64, 0u64);
        if let Some(s) = insert {
            if let Slot::Running { found, .. } = &slots[s] {
                let pos = if found.len() < k && (found.is_empty() || r.gen_bool(0.6)) {
                    found.len()
                } else {
                    r.gen_range(0..found.len())
                };
                entry = (
                    pos,
                    r.gen_range(1..1u64 << cfg.address_bits),
                    r.gen::<u64>() & low_mask(cfg.dist_bits()),
                );
            }
        }
        uut.found_slot.next = (insert.unwrap_or(0) as u64).into();
        uut.found_pos.next = (entry.0 as u64).into();
        uut.found_address.next = entry.1.into();
        uut.found_dist.next = entry.2.into();
        uut.done.next = end.is_some();
        uut.done_slot.next = (end.unwrap_or(0) as u64).into();
        let visited = r.gen::<u64>() & low_mask(cfg.visited_bits());
        let count = match end.map(|s| &slots[s]) {
            Some(Slot::Running { found, .. }) => found.len(),
            _ => r.gen_range(0..=k),
        };
        uut.done_count.next = (count as u64).into();
        uut.done_visited.next = visited.into();
        let ready = r.gen_bool(p_ready);
        uut.result.ready.next = ready;
        settle(&mut uut);

        // The stream.
        if uut.result.valid.val() {
            let b = uut.result.data.val();
            if let Some(s) = stalled {
                assert_eq!(b, s, "cycle {cycle}: a stalled beat changed");
            }
            stalled = (!ready).then_some(b);
            if ready {
                beats_out += 1;
                let (pid, i) = match current {
                    Some(c) => c,
                    None => {
                        assert!(b.header, "cycle {cycle}: a packet starts with {b:?}");
                        let pid = b.id.to_u64();
                        assert!(pending.contains_key(&pid), "cycle {cycle}: no packet {pid}");
                        (pid, 0)
                    }
                };
                let (want, slot, freed) = &pending[&pid];
                assert_eq!(
                    meaningful(&b),
                    want[i],
                    "cycle {cycle}: beat {i} of the packet of slot {slot}"
                );
                if i + 1 == want.len() {
                    assert!(
                        *freed || uut.freed.val().get_bit(*slot),
                        "cycle {cycle}: last beat of slot {slot} left before its slot was freed"
                    );
                    pending.remove(&pid);
                    current = None;
                    packets_out += 1;
                } else {
                    current = Some((pid, i + 1));
                }
            }
        } else {
            assert!(stalled.is_none(), "cycle {cycle}: a stalled beat vanished");
        }
        // Freed: one-hot, a finished slot whose packet is still owed.
        let freed = uut.freed.val().to_u64();
        assert!(
            freed & (freed.wrapping_sub(1)) == 0,
            "cycle {cycle}: freed {freed:#x}"
        );
        if freed != 0 {
            let s = freed.trailing_zeros() as usize;
            assert!(s < q, "cycle {cycle}: freed slot {s}");
            let Slot::Finished { id } = slots[s] else {
                panic!("cycle {cycle}: freed slot {s} in state {:?}", slots[s]);
            };
            // (None: its last beat left in this very cycle, checked above.)
            if let Some(p) = pending.get_mut(&id) {
                assert!(!p.2, "cycle {cycle}: slot {s} freed twice");
                p.2 = true;
            }
            slots[s] = Slot::Free;
        }

        // The model's writes, at the edge.
        if let Some(s) = load {
            slots[s] = Slot::Running {
                id: id & id_mask,
                found: Vec::new(),
            };
            started += 1;
            next_id = (next_id + 1) & id_mask;
        }
        if let Some(s) = insert {
            if let Slot::Running { found, .. } = &mut slots[s] {
                let (pos, a, d) = entry;
                if pos == found.len() {
                    found.push((a, d));
                } else {
                    found[pos] = (a, d);
                }
            }
        }
        if let Some(s) = end {
            if let Slot::Running { id, found } = &slots[s] {
                let id = *id;
                assert!(!pending.contains_key(&id), "ids in flight collide");
                pending.insert(id, (packet(id, visited, found), s, false));
                slots[s] = Slot::Finished { id };
                ended += 1;
            }
        }
        uut.clock.next = true.into();
        settle(&mut uut);
        uut.clock.next = false.into();
        settle(&mut uut);
    }
    assert_eq!(ended, searches);
    assert!(pending.is_empty());
    assert!(beats_out > searches, "no photons read out");
    assert!(
        slots.iter().all(|s| *s == Slot::Free),
        "a slot was never freed"
    );
}

#[test]
fn slot_readout_against_a_packet_model() {
    let barrel = CoreConfig {
        controller: Controller::Barrel,
        queries_per_port: BARREL_SLOTS,
        ..CoreConfig::paper()
    };
    for (k, q, pipelined, metric, p_ready, seed) in [
        (10usize, BARREL_SLOTS, true, Metric::L1, 0.6, 121u64),
        (10, BARREL_SLOTS, false, Metric::L2, 0.8, 122),
        (1, 3, true, Metric::L1, 0.5, 123),
        (2, 5, true, Metric::L2, 1.0, 124),
        (33, 11, true, Metric::L2, 0.4, 125),
        (64, 2, false, Metric::L1, 0.7, 126),
    ] {
        let cfg = CoreConfig {
            k,
            queries_per_port: q,
            pipelined,
            metric,
            ..barrel
        };
        readout_against_model(cfg, 1000, p_ready, seed);
    }
}
