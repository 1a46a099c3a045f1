//! End-to-end tests of the simulated PhotonSearchCore against knn::search and brute
//! force: random maps and the hard cases.

mod common;
use common::*;
use photon_fpga::hw::config::CoreConfig;
use photon_fpga::hw::metric::Metric;
use photon_fpga::hw::photon_word::PhotonLayout;
use photon_fpga::hw::sim::{run_gather, HwQuery, SimOptions};

fn run_case(
    points: &[[u32; 3]],
    layout: PhotonLayout,
    metric: Metric,
    k: usize,
    queries: &[HwQuery],
) {
    let tree = pack(points, layout);
    let mut cfg = CoreConfig::for_map(&tree, k, metric).expect("config");
    cfg.queries_per_port = cfg.queries_per_port.min(6);
    let (results, _stats) = run_gather(&cfg, &tree, queries, &SimOptions::default()).expect("sim");
    check_results(&cfg, &tree, points, queries, &results);
}

#[test]
fn random_map_l2() {
    let layout = PhotonLayout::new([8, 7, 6]);
    let mut r = rng(1);
    let points = random_points(&mut r, 300, layout);
    let queries = random_queries(&mut r, 40, layout, 8, Metric::L2);
    run_case(&points, layout, Metric::L2, 8, &queries);
}
