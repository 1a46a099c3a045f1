//! Found lists deeper than the comparator tree's (K = 100 and K = 512, the paper's
//! high-quality regime, §3): the barrel core keeps them as heaps in BlockRAM
//! (`FoundHeap`). Against knn::search (same entries, same reads) and brute force
//! (same sorted distances) on random maps, clusters of equal photons (ties at the
//! K-th distance, so the lowest-entry rule decides), random stalls on every stream,
//! a second map and a reset in the middle of a search; the QueryModule controller
//! refuses K above its MaxFinder's rows.

use crate::common::*;
use crate::hw_core::hard_queries;
use photon_fpga::hw::config::controller::Controller;
use photon_fpga::hw::config::core_config::{CoreConfig, FOUND_TREE_MAX_K, MAX_K, MAX_K_MODULES};
use photon_fpga::hw::config::metric::Metric;
use photon_fpga::hw::config::photon_word::PhotonLayout;
use photon_fpga::hw::config::traversal::Traversal;
use photon_fpga::hw::sim::driver::HwQuery;
use photon_fpga::hw::sim::native::{run_gather, CoreSim, SimOptions};

/// The barrel core for `tree` with found lists of `k`.
fn barrel(
    tree: &photon_fpga::host::map::kdtree::PackedTree,
    k: usize,
    metric: Metric,
    traversal: Traversal,
) -> CoreConfig {
    let cfg = CoreConfig::builder()
        .k(k)
        .metric(metric)
        .controller(Controller::Barrel)
        .traversal(traversal)
        .build_for(tree.image())
        .expect("config");
    assert!(cfg.uses_found_heap(), "K = {k} is a heap configuration");
    cfg
}

/// A map with a cluster of `dup` equal photons, so that lists fill with ties.
fn map_with_cluster(seed: u64, n: usize, dup: usize, layout: PhotonLayout) -> Vec<[u32; 3]> {
    let mut r = rng(seed);
    let mut points = random_points(&mut r, n, layout);
    points.extend(vec![[40, 41, 42]; dup]);
    points
}

fn queries_for(
    points: &[[u32; 3]],
    layout: PhotonLayout,
    metric: Metric,
    k: usize,
) -> Vec<HwQuery> {
    let mut r = rng(k as u64);
    let mut queries = random_queries(&mut r, 8, layout, k, metric);
    queries.extend(hard_queries(points, layout, metric, k, k as u64 + 1));
    for (i, q) in queries.iter_mut().enumerate() {
        q.id = i as u32;
    }
    queries
}

#[test]
fn k100_and_k512_match_software_and_brute_force() {
    let layout = PhotonLayout::new([7, 7, 7]);
    for (k, metric, n, dup) in [
        (100usize, Metric::L2, 300, 120),
        (100, Metric::L1, 250, 40),
        (512, Metric::L2, 700, 300),
        (512, Metric::L1, 600, 80),
    ] {
        let points = map_with_cluster(k as u64 + n as u64, n, dup, layout);
        let tree = pack(&points, layout);
        let queries = queries_for(&points, layout, metric, k);
        for traversal in [Traversal::Cell, Traversal::Remember] {
            let cfg = barrel(&tree, k, metric, traversal);
            let (results, _) =
                run_gather(&cfg, tree.image(), &queries, &SimOptions::default()).expect("sim");
            check_results(&cfg, &tree, &points, &queries, &results);
            assert!(
                results.iter().any(|r| r.found.len() == k),
                "K = {k}: some list is full"
            );
        }
    }
}

#[test]
fn k512_stalls_second_map_and_reset() {
    let layout = PhotonLayout::new([7, 6, 7]);
    let metric = Metric::L2;
    let first = map_with_cluster(91, 650, 200, layout);
    let second = map_with_cluster(92, 300, 20, layout);
    let (t1, t2) = (pack(&first, layout), pack(&second, layout));
    let k = 512;
    let q1 = queries_for(&first, layout, metric, k);
    let q2 = queries_for(&second, layout, metric, k);
    let cfg = barrel(&t1, k, metric, Traversal::Cell);
    let mut sim = CoreSim::new(&cfg, &stalls(9)).unwrap();
    sim.load_map(t1.image()).unwrap();
    check_results(&cfg, &t1, &first, &q1, &sim.run_queries(&q1).unwrap());
    // A smaller map over the larger one, without a reset: stale heap entries of
    // the first map's queries must not leak into the second's lists.
    sim.load_map(t2.image()).unwrap();
    check_results(&cfg, &t2, &second, &q2, &sim.run_queries(&q2).unwrap());
    // A reset in the middle of a search, then the first map again.
    let partial = sim.run_queries_for(&q1, 400).unwrap();
    assert!(
        partial.iter().any(|p| p.is_none()),
        "still in flight at the reset"
    );
    sim.reset().unwrap();
    sim.load_map(t1.image()).unwrap();
    check_results(&cfg, &t1, &first, &q1, &sim.run_queries(&q1).unwrap());
}

#[test]
fn deep_lists_are_refused_where_they_cannot_be_built() {
    let layout = PhotonLayout::new([7, 7, 7]);
    let points = map_with_cluster(5, 100, 0, layout);
    let tree = pack(&points, layout);
    let build = |controller, k| {
        CoreConfig::builder()
            .k(k)
            .metric(Metric::L2)
            .controller(controller)
            .build_for(tree.image())
    };
    // The QueryModule controller stops at its MaxFinder's 64-bit rows.
    let e = build(Controller::Modules, MAX_K_MODULES + 1).unwrap_err();
    assert!(
        e.to_string().contains(&format!("1..={MAX_K_MODULES}")),
        "{e}"
    );
    assert!(build(Controller::Modules, MAX_K_MODULES).is_ok());
    // The barrel controller: the comparator tree up to 64, heaps up to 512.
    let tree_cfg = build(Controller::Barrel, FOUND_TREE_MAX_K).unwrap();
    assert!(!tree_cfg.uses_found_heap());
    assert!(build(Controller::Barrel, FOUND_TREE_MAX_K + 1)
        .unwrap()
        .uses_found_heap());
    assert!(build(Controller::Barrel, MAX_K).is_ok());
    let e = build(Controller::Barrel, MAX_K + 1).unwrap_err();
    assert!(e.to_string().contains(&format!("1..={MAX_K}")), "{e}");
    // A heap key holds the distance and the entry in 32 bits: 15-bit squared L2
    // distances (32 bits) leave no room for the entry.
    let wide = PhotonLayout::new([15, 15, 15]);
    let wpoints = map_with_cluster(6, 50, 0, wide);
    let wtree = pack(&wpoints, wide);
    let e = CoreConfig::builder()
        .k(100)
        .metric(Metric::L2)
        .controller(Controller::Barrel)
        .build_for(wtree.image())
        .unwrap_err();
    assert!(e.to_string().contains("heap"), "{e}");
    // The default render's grid (10 bits, squared L2) holds K = 512; 11 bits do not.
    for (bits, ok) in [(10, true), (11, false)] {
        let l = PhotonLayout::new([bits; 3]);
        let t = pack(&map_with_cluster(7, 50, 0, l), l);
        let built = CoreConfig::builder()
            .k(MAX_K)
            .metric(Metric::L2)
            .controller(Controller::Barrel)
            .build_for(t.image());
        assert_eq!(built.is_ok(), ok, "{bits} bits: {built:?}");
    }
}
