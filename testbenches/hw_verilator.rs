//! Issue 14: the exported core under Verilator (`Engine::Verilator`) gives the same
//! results and the same cycle counts as rust-hdl's native simulation, query by
//! query, through the same driver: random maps, hard cases (all photons at one
//! point, ties), random stalls on every stream, and a replicated array (results
//! and cycles; its per-tree read counters are only visible natively).

use crate::common::*;
use photon_fpga::hw::config::CoreConfig;
use photon_fpga::hw::metric::Metric;
use photon_fpga::hw::photon_word::PhotonLayout;
use photon_fpga::hw::rtl::driver::HwQuery;
use photon_fpga::hw::rtl::native::{run_gather, Engine, SimOptions};

fn both(cfg: &CoreConfig, points: &[[u32; 3]], queries: &[HwQuery], stall_seed: Option<u64>) {
    let tree = pack(points, cfg.layout);
    let run = |engine| {
        let opts = SimOptions {
            engine,
            stall_seed,
            ..SimOptions::default()
        };
        run_gather(cfg, tree.image(), queries, &opts).expect("simulation")
    };
    let (native, ns) = run(Engine::Native);
    let (verilated, vs) = run(Engine::Verilator);
    assert_eq!(native, verilated, "results differ");
    assert_eq!(ns.cycles, vs.cycles, "cycle counts differ");
    if cfg.trees == 1 {
        assert_eq!(ns, vs, "read counters differ");
    }
    check_results(cfg, &tree, points, queries, &native);
}

#[test]
#[cfg_attr(not(has_verilator), ignore = "needs verilator")]
fn verilator_equals_the_native_simulation() {
    let cfg = CoreConfig {
        layout: PhotonLayout::new([7, 6, 5]),
        address_bits: 7,
        k: 5,
        queries_per_port: 4,
        metric: Metric::L2,
        pipelined: true,
        trees: 1,
        traversal: Default::default(),
    };
    let mut r = rng(31);
    let points = random_points(&mut r, 100, cfg.layout);
    let queries = random_queries(&mut r, 40, cfg.layout, cfg.k, cfg.metric);
    both(&cfg, &points, &queries, None);
    both(&cfg, &points, &queries, Some(7));
    // Hard cases: every photon at one point, and ties around a centre.
    let one = vec![[3, 4, 5]; 20];
    let q_one: Vec<HwQuery> = (0..10)
        .map(|i| HwQuery {
            id: i,
            coords: [3, 4, 5],
            radius: [0, 1, u64::MAX][i as usize % 3],
            k: 1 + i % 5,
        })
        .collect();
    both(&cfg, &one, &q_one, Some(8));
    // A replicated array of two trees.
    let array = CoreConfig { trees: 2, ..cfg };
    both(&array, &points, &queries, Some(9));
}
