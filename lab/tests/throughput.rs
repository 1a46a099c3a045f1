//! Throughput (paper §4.5): with every QueryModule busy on a long random query
//! stream, each TreeModule port reads a photon (almost) every cycle. Also reports
//! simulation speed and photons visited per query against the software search.

use crate::common::*;
use photon_fpga::host::map::knn;
use photon_fpga::hw::config::core_config::CoreConfig;
use photon_fpga::hw::config::metric::Metric;
use photon_fpga::hw::config::photon_word::PhotonLayout;
use photon_fpga::hw::config::traversal::Traversal;
use photon_fpga::hw::sim::driver::HwQuery;
use photon_fpga::hw::sim::native::{run_gather, CoreSim, SimOptions};
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
        CoreConfig::paper_builder()
            .metric(metric)
            .traversal(traversal)
            .build()
    } else {
        CoreConfig::builder()
            .k(10)
            .metric(metric)
            .traversal(traversal)
            .build_for(tree.image())
    }
    .expect("config");
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

/// Right-sized Q: Q fitted to a query stream from the software model of
/// its read intervals (`CoreConfig::fit_queries_per_port`) is below the worst-case
/// issue interval and still keeps every port reading ≥ 0.98 photons per cycle while
/// all QueryModules are busy, on the paper workload (with the default and the
/// cell-distance traversal) and on a Cornell-box stream; every result equals the
/// software search.
#[test]
fn fitted_q_keeps_every_port_reading() {
    use photon_fpga::hw::config::core_config::ReadProfile;
    use photon_fpga_lab::workload;
    let paper = CoreConfig::paper();
    let uniform = workload::uniform(paper.layout, 1023, 150, 5);
    let cornell = workload::cornell(60_000, usize::MAX, 10, 64, 6);
    let cornell_cfg = CoreConfig::builder()
        .k(10)
        .metric(Metric::L1)
        .traversal(Traversal::Remember)
        .build_for(cornell.tree.image())
        .expect("config");
    let paper_cell = paper
        .to_builder()
        .traversal(Traversal::Cell)
        .build()
        .unwrap();
    for (name, mut cfg, w) in [
        ("paper", paper, &uniform),
        ("paper, cell traversal", paper_cell, &uniform),
        ("cornell", cornell_cfg, &cornell),
    ] {
        let max = cfg.max_dist();
        let step = (w.queries.len() / 150).max(1);
        let points: Vec<[u32; 3]> = w.queries.iter().step_by(step).take(150).copied().collect();
        let queries = HwQuery::k_nearest(&cfg, &points);
        let soft: Vec<_> = queries
            .iter()
            .map(|q| knn::search_with(&w.tree, q.coords, cfg.k, max, cfg.metric, cfg.traversal))
            .collect();
        let profile: ReadProfile = soft.iter().map(|f| f.read_profile()).sum();
        cfg.fit_queries_per_port(&profile);
        assert!(
            cfg.queries_per_port < cfg.issue_interval(),
            "{name}: fitted Q {} is the worst case",
            cfg.queries_per_port
        );
        let (results, stats) =
            run_gather(&cfg, w.tree.image(), &queries, &SimOptions::default()).expect("sim");
        for (r, f) in results.iter().zip(&soft) {
            assert_eq!(r.visited, f.visited, "{name}: reads differ");
            let mut d: Vec<u64> = r.found.iter().map(|x| x.1).collect();
            d.sort();
            assert_eq!(d, f.sorted_dists(), "{name}: distances differ");
        }
        for (p, &reads) in stats.busy_reads_per_port.iter().enumerate() {
            let rate = reads as f64 / stats.busy_cycles.max(1) as f64;
            eprintln!(
                "{name}: Q = {}, port {p}: {rate:.3} reads per busy cycle",
                cfg.queries_per_port
            );
            assert!(
                rate >= 0.98,
                "{name}: port {p} reads {rate:.3} per cycle with Q = {}",
                cfg.queries_per_port
            );
        }
    }
}

/// The barrel port (`Controller::Barrel`): 16 query slots behind one datapath per
/// port keep the port reading ≥ 0.93 photons per cycle over the whole run of 600
/// queries, fill and drain included (measured 0.95–0.96; the QueryModule cores
/// are held to 0.98 only while all their modules are busy, a state a barrel port
/// is rarely in: a query enters in a cycle without a result), on the paper
/// workload (both traversals it runs) and on a Cornell-box stream, every result
/// the software search's, read for read.
#[test]
fn barrel_port_reads_nearly_every_cycle() {
    use photon_fpga::hw::config::controller::Controller;
    use photon_fpga::hw::config::core_config::BARREL_SLOTS;
    use photon_fpga_lab::workload;
    let barrel = CoreConfig::builder()
        .controller(Controller::Barrel)
        .queries_per_port(BARREL_SLOTS);
    let paper = barrel.build().unwrap();
    let uniform = workload::uniform(paper.layout, 1023, 600, 7);
    let cornell = workload::cornell(60_000, usize::MAX, 10, 64, 6);
    let cornell_cfg = barrel
        .traversal(Traversal::Cell)
        .build_for(cornell.tree.image())
        .expect("config");
    for (name, cfg, w) in [
        ("paper, remember", paper, &uniform),
        (
            "paper, cell",
            barrel.traversal(Traversal::Cell).build().unwrap(),
            &uniform,
        ),
        ("cornell, cell", cornell_cfg, &cornell),
    ] {
        let max = cfg.max_dist();
        let step = (w.queries.len() / 600).max(1);
        let points: Vec<[u32; 3]> = w.queries.iter().step_by(step).take(600).copied().collect();
        let queries = HwQuery::k_nearest(&cfg, &points);
        // Counted from the end of the map load.
        let mut sim = CoreSim::new(&cfg, &SimOptions::default()).expect("sim");
        sim.load_map(w.tree.image()).expect("load");
        let before = sim.stats().clone();
        let results = sim.run_queries(&queries).expect("run");
        let stats = sim.stats().clone();
        for (q, r) in queries.iter().zip(&results) {
            let f = knn::search_with(&w.tree, q.coords, cfg.k, max, cfg.metric, cfg.traversal);
            assert_eq!(r.found, f.slots, "{name}: found lists differ");
            assert_eq!(r.visited, f.visited, "{name}: reads differ");
        }
        let cycles = stats.cycles - before.cycles;
        for (p, (&reads, &loaded)) in stats
            .reads_per_port
            .iter()
            .zip(&before.reads_per_port)
            .enumerate()
        {
            let rate = (reads - loaded) as f64 / cycles as f64;
            eprintln!("{name}: port {p}: {rate:.3} reads per cycle over the run");
            assert!(rate >= 0.93, "{name}: port {p} reads {rate:.3} per cycle");
        }
    }
}
