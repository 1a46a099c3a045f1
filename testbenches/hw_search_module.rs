//! SearchModule (paper §4.3) against a software computation: random photon maps in
//! a model TreeModule (the word of a read arrives one cycle after its request, as
//! the BlockRAM's registered read port gives it), random query coordinates written
//! into the block's query store, a random read request in most cycles (any
//! QueryModule, address, direction, came-from bit, radius and full flag) and a reset
//! now and then. Every cycle the block's result is compared with the expected
//! result of the request made `latency` cycles before (§4.3's pipeline: three
//! stages, four with the BlockRAM's read-data register) or with none.
//!
//! The expectation is computed from the decoded photon (`PackedTree::node`) with the
//! software metric and the traversal rules of `host::map::knn`'s documentation: the
//! distance, in range iff a down visit with `d <= R` before the list is full and
//! `d < R` once it is; the near child right iff `q[a] >= p[a]`, children existing
//! iff their address is at most N; a down visit goes to the near child, else to the
//! far child if the axis distance is within R, else up; an up visit goes to the far
//! child if it came from the near one and the far child is within R, else up; up is
//! to `address / 2` with the came-from bit of the address, and up from the root is
//! the end. A far child is pending on a down visit that goes to the near child
//! while the far child exists.

use photon_fpga::host::map::kdtree::PackedTree;
use photon_fpga::hw::config::core_config::CoreConfig;
use photon_fpga::hw::config::metric::Metric;
use photon_fpga::hw::config::photon_word::PhotonLayout;
use photon_fpga::hw::datapath::search_module::SearchModule;
use photon_fpga::hw::primitives::stream::{QueryBeat, ReadRequest, ReadResult};
use rand::Rng;
use rust_hdl::prelude::*;
use std::collections::VecDeque;

use crate::common::settle;

/// What the bench expects of one read.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Expected {
    pub(crate) module: usize,
    pub(crate) address: u64,
    pub(crate) in_range: bool,
    pub(crate) distance: u64,
    pub(crate) next_address: u64,
    pub(crate) next_up: bool,
    /// Only meaningful going up.
    pub(crate) next_came_from_right: bool,
    pub(crate) done: bool,
    pub(crate) axis_dist: u64,
    pub(crate) far_pending: bool,
    pub(crate) axis: u64,
}

/// The software computation of one read of `tree` for a query at `q`.
pub(crate) fn expect(
    tree: &PackedTree,
    metric: Metric,
    module: usize,
    q: [u32; 3],
    req: &ReadRequest,
) -> Expected {
    let n = tree.len() as u64;
    let addr = req.address.to_u64();
    let (p, axis) = tree.node(addr as usize);
    let a = axis as usize;
    let (up, from_right, full) = (req.up, req.came_from_right, req.full);
    let radius = req.radius.to_u64();
    let within = |d: u64| if full { d < radius } else { d <= radius };
    let distance = metric.dist(p, q);
    let axis_dist = metric.axis_dist(q[a], p[a]);
    let near_right = q[a] >= p[a];
    let near = 2 * addr + near_right as u64;
    let far = 2 * addr + 1 - near_right as u64;
    let down_to = if !up {
        if near <= n {
            Some(near)
        } else if far <= n && within(axis_dist) {
            Some(far)
        } else {
            None
        }
    } else if from_right == near_right && far <= n && within(axis_dist) {
        Some(far)
    } else {
        None
    };
    Expected {
        module,
        address: addr,
        in_range: !up && within(distance),
        distance,
        next_address: down_to.unwrap_or(addr / 2),
        next_up: down_to.is_none(),
        next_came_from_right: down_to.is_none() && addr % 2 == 1,
        done: down_to.is_none() && addr == 1,
        axis_dist,
        far_pending: !up && near <= n && far <= n,
        axis: axis as u64,
    }
}

fn observed(r: &ReadResult) -> Expected {
    Expected {
        module: r.query_module.to_u64() as usize,
        address: r.address.to_u64(),
        in_range: r.in_range,
        distance: r.distance.to_u64(),
        next_address: r.next_address.to_u64(),
        next_up: r.next_up,
        next_came_from_right: r.next_up && r.next_came_from_right,
        done: r.done,
        axis_dist: r.axis_dist.to_u64(),
        far_pending: r.far_pending,
        axis: r.axis.to_u64(),
    }
}

fn search_module_against_software<const W: usize>(cfg: CoreConfig, photons: usize, seed: u64) {
    cfg.validate().expect("config");
    assert_eq!(cfg.word_width(), W);
    let q = cfg.queries_per_port;
    let layout = cfg.layout;
    let metric = cfg.metric;
    let mut r = crate::common::rng(seed);
    let points = crate::common::random_points(&mut r, photons, layout);
    let tree = crate::common::pack(&points, layout);
    assert!(tree.len() < cfg.tree_words());
    let n = tree.len() as u64;
    // §4.3: three registered stages after the request, one more for the word register.
    let latency = 3 + cfg.pipelined as usize;

    let mut uut = SearchModule::<W>::new(&cfg);
    uut.connect_all();
    check_all(&uut).expect("SearchModule checks");
    uut.photon_count.next = n.into();
    uut.reset.next = false;

    let max = metric.max_dist(layout.bits);
    let mut coords = vec![[0u32; 3]; q];
    // The expected result of the request made `latency` cycles before (front) ...
    let mut in_flight: VecDeque<Option<Expected>> = (0..latency).map(|_| None).collect();
    // ... and the cycle of each module's last request (its coordinates stay put
    // while a read of it is in flight, as a QueryModule's do).
    let mut last_request = vec![None::<usize>; q];
    let mut word_next = 0u64;
    let mut results = 0;
    for cycle in 0..6000 {
        let reset = r.gen_bool(0.01);
        let request = !reset && r.gen_bool(0.75);
        let module = r.gen_range(0..q);
        // A query load into a module with no read in flight.
        let mut load = None;
        let m = r.gen_range(0..q);
        let idle = last_request[m].is_none_or(|c| cycle > c + latency);
        if r.gen_bool(0.2) && idle && !(request && m == module) {
            load = Some((m, [0, 1, 2].map(|a| r.gen_range(0..=layout.coord_max(a)))));
        }
        let radius: u64 = match r.gen_range(0..5) {
            0 => u32::MAX as u64,
            1 => max,
            2 => r.gen_range(0..=max),
            _ => r.gen_range(0..=max / 16),
        };
        let req = ReadRequest {
            query_module: (module as u64).into(),
            address: r.gen_range(1..=n).into(),
            up: r.gen_bool(0.3),
            came_from_right: r.gen(),
            // Not used: the coordinates come from the query store.
            x: r.gen_range(0..1u64 << 16).into(),
            y: r.gen_range(0..1u64 << 16).into(),
            z: r.gen_range(0..1u64 << 16).into(),
            radius: radius.into(),
            full: r.gen(),
        };
        uut.reset.next = reset;
        uut.request_valid.next = request;
        uut.request.next = req;
        uut.word.next = word_next.into();
        uut.query_write.next = load.is_some();
        if let Some((m, c)) = load {
            uut.query_module.next = (m as u64).into();
            uut.query.next = QueryBeat {
                id: r.gen_range(0..1u64 << 32).into(),
                x: (c[0] as u64).into(),
                y: (c[1] as u64).into(),
                z: (c[2] as u64).into(),
                radius: r.gen_range(0..1u64 << 32).into(),
                k: r.gen_range(0..256u64).into(),
            };
        } else {
            // A module's index and a query on the bus without the write enable.
            uut.query_module.next = (m as u64).into();
            uut.query.next = QueryBeat {
                x: 77.into(),
                ..Default::default()
            };
        }
        settle(&mut uut);

        let want = in_flight.pop_front().unwrap();
        let got = uut.result_valid.val().then(|| observed(&uut.result.val()));
        assert_eq!(
            got, want,
            "{metric} pipelined {} Q {q} cycle {cycle}: result",
            cfg.pipelined
        );
        let want_for = want.map_or(0, |e| 1u64 << e.module);
        assert_eq!(
            uut.result_for.val().to_u64(),
            want_for,
            "cycle {cycle}: result_for"
        );
        results += want.is_some() as usize;

        // The request enters the model with the coordinates its module has now.
        in_flight.push_back(request.then(|| expect(&tree, metric, module, coords[module], &req)));
        if request {
            last_request[module] = Some(cycle);
        }
        if reset {
            in_flight.iter_mut().for_each(|e| *e = None);
        }
        if let Some((m, c)) = load {
            coords[m] = c;
        }
        // The model TreeModule: the word at the requested address, a cycle later
        // (any word when nothing was requested).
        word_next = if request {
            tree.words[req.address.to_u64() as usize]
        } else {
            r.gen::<u64>() & (u64::MAX >> (64 - W))
        };
        uut.clock.next = true.into();
        settle(&mut uut);
        uut.clock.next = false.into();
        settle(&mut uut);
    }
    assert!(results > 3000, "only {results} results checked");
}

#[test]
fn search_module_against_the_software_search() {
    let paper = CoreConfig::paper();
    for (metric, pipelined, q, photons, seed) in [
        (Metric::L1, true, 21usize, 1000usize, 111u64),
        (Metric::L2, true, 6, 300, 112),
        (Metric::L2, false, 1, 90, 113),
        (Metric::L1, false, 32, 7, 114),
    ] {
        let cfg = CoreConfig {
            metric,
            pipelined,
            queries_per_port: q,
            ..paper
        };
        search_module_against_software::<32>(cfg, photons, seed);
    }
}

/// Wider coordinates: a 38-bit photon word on the 64-bit port, a taller tree.
#[test]
fn search_module_wide_words() {
    let cfg = CoreConfig {
        layout: PhotonLayout::new([12, 12, 12]),
        address_bits: 12,
        metric: Metric::L2,
        queries_per_port: 9,
        ..CoreConfig::paper()
    };
    search_module_against_software::<64>(cfg, 3000, 115);
}
