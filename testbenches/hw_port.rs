//! One bench for a TreeModule port's controller, either kind, driven through the
//! one port bundle (`PortIo`) of a `ControllerPort`: a BlockRAM model holds a
//! random small map (the word at the address of the cycle before, as the
//! TreeModule reads), random queries arrive with random gaps, the result stream is
//! stalled at random, and every result packet is checked against the software
//! search (same slots, same reads) and brute force. Both controllers, several
//! traversals, both metrics.

use crate::common::*;
use photon_fpga::hw::config::controller::Controller;
use photon_fpga::hw::config::core_config::{CoreConfig, BARREL_SLOTS};
use photon_fpga::hw::config::metric::Metric;
use photon_fpga::hw::config::photon_word::PhotonLayout;
use photon_fpga::hw::config::traversal::Traversal;
use photon_fpga::hw::primitives::stream::QueryBeat;
use photon_fpga::hw::sim::driver::HwResult;
use photon_fpga::hw::top::controller_port::ControllerPort;
use rand::Rng;
use rust_hdl::prelude::*;
use std::collections::HashMap;

type Port = ControllerPort<32, 32>;

fn cycle(uut: &mut Port) {
    clock_cycle(uut, |u| &mut u.clock);
}

fn run(cfg: &CoreConfig, seed: u64) {
    let mut r = rng(seed);
    let n = r.gen_range(1..(1usize << cfg.address_bits));
    let points = random_points(&mut r, n, cfg.layout);
    let tree = pack(&points, cfg.layout);
    let words = tree.image().words.to_vec();
    let queries = random_queries(&mut r, 40, cfg.layout, cfg.k, cfg.metric);
    let mut uut = Port::new(cfg);
    uut.connect_all();
    check_all(&uut).unwrap();
    // Tags from the port's id bits, none reused while its query is in flight.
    let tags = 1usize << cfg.id_bits();
    let mut in_flight: HashMap<usize, usize> = HashMap::new();
    let mut results: Vec<Option<HwResult>> = vec![None; queries.len()];
    let mut open: Option<(usize, HwResult, usize)> = None;
    let mut next = 0;
    let mut read_word = 0u64;
    uut.reset.next = true;
    cycle(&mut uut);
    uut.reset.next = false;
    uut.io.photon_count.next = (n as u64).into();
    let mut cycles = 0;
    while results.iter().any(|x| x.is_none()) {
        cycles += 1;
        assert!(cycles < 200_000, "the port stopped answering");
        let offer =
            next < queries.len() && !in_flight.contains_key(&(next % tags)) && r.gen_bool(0.7);
        uut.io.query.valid.next = offer;
        if next < queries.len() {
            let q = &queries[next];
            uut.io.query.data.next = QueryBeat {
                id: ((next % tags) as u64).into(),
                x: (q.coords[0] as u64).into(),
                y: (q.coords[1] as u64).into(),
                z: (q.coords[2] as u64).into(),
                radius: q.radius.min(u32::MAX as u64).into(),
                k: (q.k as u64).into(),
            };
        }
        uut.io.result.ready.next = r.gen_bool(0.6);
        uut.io.ram_data.next = read_word.into();
        settle(&mut uut);
        if offer && uut.io.query.ready.val() {
            in_flight.insert(next % tags, next);
            next += 1;
        }
        if uut.io.result.valid.val() && uut.io.result.ready.val() {
            let b = uut.io.result.data.val();
            let (i, res, count) = match open.take() {
                None => {
                    assert!(b.header, "a packet starts with its header");
                    let i = in_flight
                        .remove(&(b.id.to_u64() as usize))
                        .expect("a header for a query in flight");
                    let res = HwResult {
                        id: queries[i].id,
                        found: vec![],
                        visited: b.visited.to_u32(),
                    };
                    (i, res, b.count.to_u64() as usize)
                }
                Some((i, mut res, count)) => {
                    assert!(!b.header);
                    res.found.push((b.address.to_u32(), b.distance.to_u64()));
                    if b.pair {
                        res.found.push((b.address2.to_u32(), b.distance2.to_u64()));
                    }
                    (i, res, count)
                }
            };
            assert_eq!(b.last, res.found.len() == count, "last on the final beat");
            if b.last {
                results[i] = Some(res);
            } else {
                open = Some((i, res, count));
            }
        }
        // The BlockRAM model: the word at this cycle's address, next cycle.
        let addr = uut.io.ram_address.val().to_u64() as usize;
        read_word = words.get(addr).copied().unwrap_or(0);
        cycle(&mut uut);
    }
    let results: Vec<HwResult> = results.into_iter().map(Option::unwrap).collect();
    check_results(cfg, &tree, &points, &queries, &results);
}

#[test]
fn either_controller_through_the_port_bundle() {
    let layout = PhotonLayout::new([5, 5, 4]);
    let mut seed = 70;
    for (traversal, controller, q) in [
        (Traversal::Remember, Controller::Modules, 5usize),
        (Traversal::Reread, Controller::Modules, 3),
        (Traversal::Cell, Controller::Modules, 4),
        (Traversal::Remember, Controller::Barrel, BARREL_SLOTS),
        (Traversal::Cell, Controller::Barrel, BARREL_SLOTS),
    ] {
        for (metric, k) in [(Metric::L1, 6usize), (Metric::L2, 11)] {
            let cfg = CoreConfig {
                traversal,
                controller,
                queries_per_port: q,
                ..small_config(layout, 7, k, q, metric)
            };
            seed += 1;
            run(&cfg, seed);
        }
    }
}
