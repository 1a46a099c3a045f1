//! Throughput (paper §4.5): with every QueryModule busy on a long random query
//! stream, each TreeModule port reads a photon (almost) every cycle. Also reports
//! simulation speed and photons visited per query against the software search.

use crate::common::*;
use photon_fpga::host::map::knn;
use photon_fpga::hw::config::CoreConfig;
use photon_fpga::hw::metric::Metric;
use photon_fpga::hw::photon_word::PhotonLayout;
use photon_fpga::hw::rtl::driver::HwQuery;
use photon_fpga::hw::rtl::native::{run_gather, SimOptions};
use photon_fpga::hw::traversal::Traversal;
use rand::Rng;
use std::time::Instant;

/// Run `queries` random unbounded 10-NN queries on a random map of `photons` on the
/// paper's 10-bit grid; `paper_core` uses `CoreConfig::paper()` (Q = 21 per port),
/// else `CoreConfig::for_map` (Q = the issue interval).
fn throughput(
    metric: Metric,
    photons: usize,
    queries: usize,
    seed: u64,
    paper_core: bool,
    traversal: Traversal,
) {
    let layout = PhotonLayout::paper();
    let mut r = rng(seed);
    let points = random_points(&mut r, photons, layout);
    let tree = pack(&points, layout);
    let cfg = if paper_core {
        CoreConfig {
            metric,
            pipelined: true,
            trees: 1,
            ..CoreConfig::paper()
        }
    } else {
        CoreConfig::for_map(tree.image(), 10, metric).expect("config")
    };
    let cfg = CoreConfig { traversal, ..cfg };
    let qs: Vec<HwQuery> = (0..queries)
        .map(|i| HwQuery {
            id: i as u32,
            coords: [0, 1, 2].map(|a| r.gen_range(0..=layout.coord_max(a))),
            radius: u64::MAX,
            k: 10,
        })
        .collect();
    let start = Instant::now();
    let (results, stats) =
        run_gather(&cfg, tree.image(), &qs, &SimOptions::default()).expect("sim");
    let secs = start.elapsed().as_secs_f64();
    check_results(&cfg, &tree, &points, &qs, &results);
    let sw_visited: u64 = qs
        .iter()
        .map(|q| knn::search_with(&tree, q.coords, 10, q.radius, metric, traversal).visited as u64)
        .sum();
    let hw_visited: u64 = results.iter().map(|r| r.visited as u64).sum();
    println!(
        "{metric}: {photons} photons, {queries} queries, Q = {} per port, interval {}: {} cycles in {secs:.2} s = {:.0} cycles/s",
        cfg.queries_per_port,
        cfg.issue_interval(),
        stats.cycles,
        stats.cycles as f64 / secs
    );
    println!(
        "  visited/query hw {:.2} sw {:.2}; reads/port/cycle overall {:?}",
        hw_visited as f64 / queries as f64,
        sw_visited as f64 / queries as f64,
        stats
            .reads_per_port
            .iter()
            .map(|&x| x as f64 / stats.cycles as f64)
            .collect::<Vec<_>>()
    );
    let busy: Vec<f64> = stats
        .busy_reads_per_port
        .iter()
        .map(|&x| x as f64 / stats.busy_cycles as f64)
        .collect();
    println!(
        "  busy cycles {} reads/port/cycle while all busy {busy:?}",
        stats.busy_cycles
    );
    assert_eq!(hw_visited, sw_visited);
    assert!(
        stats.busy_cycles as f64 > 0.5 * stats.cycles as f64,
        "the stream keeps the core busy"
    );
    for b in busy {
        assert!(b >= 0.95, "reads per port per cycle {b} < 0.95");
    }
}

#[test]
fn every_port_reads_every_cycle_l1() {
    throughput(Metric::L1, 3000, 300, 41, false, Traversal::Remember);
}

#[test]
fn every_port_reads_every_cycle_l2() {
    throughput(Metric::L2, 2000, 200, 42, false, Traversal::Remember);
}

#[test]
fn paper_core_reads_every_cycle() {
    throughput(Metric::L1, 1023, 200, 43, true, Traversal::Remember);
}

#[test]
fn paper_core_reads_every_cycle_with_rereads() {
    throughput(Metric::L1, 1023, 200, 43, true, Traversal::Reread);
}
