//! PhotonSearchArray (T replicated trees, src/hw/top/array.rs): every result equals the
//! software search and brute force whichever tree answered, under random stalls on
//! every stream, across map reloads; queries spread over all trees; the reads per
//! cycle scale with T.

use crate::common::*;
use photon_fpga::hw::config::core_config::CoreConfig;
use photon_fpga::hw::config::metric::Metric;
use photon_fpga::hw::config::photon_word::PhotonLayout;
use photon_fpga::hw::sim::driver::{HwQuery, SimStats};
use photon_fpga::hw::sim::native::{run_gather, CoreSim, SimOptions};

fn array_config(
    layout: PhotonLayout,
    k: usize,
    q: usize,
    metric: Metric,
    trees: usize,
) -> CoreConfig {
    small_config(layout, 8, k, q, metric)
        .to_builder()
        .trees(trees)
        .build()
        .expect("an array within the limits")
}

/// Reads of tree `t` (both its ports).
fn tree_reads(stats: &SimStats, t: usize) -> u64 {
    stats.reads_per_port[2 * t] + stats.reads_per_port[2 * t + 1]
}

#[test]
fn array_matches_software_search() {
    let layout = PhotonLayout::new([7, 7, 6]);
    for (trees, metric, seed) in [(2usize, Metric::L2, 81u64), (3, Metric::L1, 82)] {
        let mut r = rng(seed);
        let mut points = random_points(&mut r, 200, layout);
        points.extend(vec![[5, 6, 7]; 15]);
        let tree = pack(&points, layout);
        let cfg = array_config(layout, 6, 3, metric, trees);
        let mut queries = random_queries(&mut r, 60, layout, cfg.k, metric);
        queries.extend((0..10).map(|i| HwQuery {
            id: 2000 + i,
            coords: [5, 6, 7],
            radius: i as u64,
            k: 1 + i % cfg.k as u32,
        }));
        for opts in [SimOptions::default(), stalls(seed)] {
            let (results, stats) = run_gather(&cfg, tree.image(), &queries, &opts).expect("sim");
            check_results(&cfg, &tree, &points, &queries, &results);
            assert_eq!(stats.reads_per_port.len(), 2 * trees);
            // The round robin hands queries to every tree.
            for t in 0..trees {
                assert!(tree_reads(&stats, t) > 0, "tree {t} never read: {stats:?}");
            }
        }
    }
}

/// A second, smaller map over the first without reset (the load is broadcast, so
/// every tree must hold the new map), then a reset in the middle of a search.
#[test]
fn array_reload_and_reset() {
    let layout = PhotonLayout::new([6, 6, 6]);
    let metric = Metric::L2;
    let mut r = rng(83);
    let first = random_points(&mut r, 230, layout);
    let second = random_points(&mut r, 70, layout);
    let (t1, t2) = (pack(&first, layout), pack(&second, layout));
    let cfg = array_config(layout, 5, 2, metric, 2);
    let q1 = random_queries(&mut r, 30, layout, 5, metric);
    let q2 = random_queries(&mut r, 30, layout, 5, metric);
    let mut sim = CoreSim::new(&cfg, &stalls(84)).unwrap();
    sim.load_map(t1.image()).unwrap();
    check_results(&cfg, &t1, &first, &q1, &sim.run_queries(&q1).unwrap());
    sim.load_map(t2.image()).unwrap();
    check_results(&cfg, &t2, &second, &q2, &sim.run_queries(&q2).unwrap());
    // Abandon a search half way, reset, reload, and search again.
    let partial = sim.run_queries_for(&q1, 60).unwrap();
    assert!(partial.iter().any(Option::is_none), "the run was cut short");
    sim.reset().unwrap();
    sim.load_map(t1.image()).unwrap();
    check_results(&cfg, &t1, &first, &q1, &sim.run_queries(&q1).unwrap());
}

/// With every QueryModule of every tree busy, each of the 2T ports reads a photon
/// every cycle, so T = 2 does close to twice the reads per cycle of T = 1 on the
/// same query stream (same cycle-level model, measured side by side).
#[test]
fn reads_per_cycle_scale_with_trees() {
    let layout = PhotonLayout::paper();
    let mut r = rng(85);
    let points = random_points(&mut r, 255, layout);
    let tree = pack(&points, layout);
    let queries: Vec<HwQuery> = (0..240)
        .map(|i| HwQuery {
            id: i,
            coords: random_points(&mut r, 1, layout)[0],
            radius: u64::MAX,
            k: 10,
        })
        .collect();
    let mut per_cycle = vec![];
    for trees in [1usize, 2] {
        let cfg = CoreConfig::builder()
            .k(10)
            .metric(Metric::L1)
            .trees(trees)
            .build_for(tree.image())
            .unwrap();
        let (results, stats) =
            run_gather(&cfg, tree.image(), &queries, &SimOptions::default()).unwrap();
        check_results(&cfg, &tree, &points, &queries, &results);
        let reads: u64 = stats.reads_per_port.iter().sum();
        per_cycle.push(reads as f64 / stats.cycles as f64);
        assert!(stats.busy_cycles > stats.cycles / 2, "{stats:?}");
        for (p, &busy_reads) in stats.busy_reads_per_port.iter().enumerate() {
            let rate = busy_reads as f64 / stats.busy_cycles as f64;
            assert!(
                rate > 0.99,
                "T = {trees}, port {p}: {rate} reads/cycle while busy"
            );
        }
    }
    eprintln!(
        "reads per cycle: T = 1 {:.3}, T = 2 {:.3}",
        per_cycle[0], per_cycle[1]
    );
    assert!(
        per_cycle[1] > 1.8 * per_cycle[0],
        "T = 2 reads {:.3} per cycle, T = 1 {:.3}",
        per_cycle[1],
        per_cycle[0]
    );
}

#[test]
fn tree_count_is_checked() {
    let layout = PhotonLayout::new([5, 5, 5]);
    for trees in [0usize, 9] {
        // Refused when built, and by the simulator when set afterwards.
        let mut cfg = array_config(layout, 4, 2, Metric::L2, 1);
        let err = cfg.to_builder().trees(trees).build().unwrap_err();
        assert!(
            err.to_string().contains(&format!("trees = {trees}")),
            "{err}"
        );
        cfg.trees = trees;
        let err = CoreSim::new(&cfg, &SimOptions::default())
            .err()
            .expect("refused");
        assert!(err.to_string().contains("replicated trees"), "{err}");
    }
}
