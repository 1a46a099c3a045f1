//! Shared helpers of the hardware testbenches: point sets, trees, and the check of a
//! hardware result against the software search and brute force.
#![allow(dead_code)]

pub mod xsim;
pub mod xsim_tb;

use photon_fpga::host::map::kdtree::{KdTree, PackedTree};
use photon_fpga::host::map::knn;
use photon_fpga::hw::config::core_config::CoreConfig;
use photon_fpga::hw::config::metric::Metric;
use photon_fpga::hw::config::photon_word::PhotonLayout;
use photon_fpga::hw::config::traversal::Traversal;
use photon_fpga::hw::sim::driver::{HwQuery, HwResult};
use photon_fpga::hw::sim::native::SimOptions;
use rand::Rng;
use rand_pcg::Pcg64;
use rust_hdl::prelude::{simulate, Block, Clock, In, Signal};

/// Propagate a block's combinational logic until it settles (fails the test if not).
pub fn settle<B: Block>(b: &mut B) {
    assert!(simulate(b, 100), "did not settle");
}

/// One clock cycle of a block with a `clock` input: settle, rising edge, falling
/// edge.
pub fn clock_cycle<B: Block>(uut: &mut B, clock: fn(&mut B) -> &mut Signal<In, Clock>) {
    settle(uut);
    clock(uut).next = true.into();
    settle(uut);
    clock(uut).next = false.into();
    settle(uut);
}

pub fn rng(seed: u64) -> Pcg64 {
    use rand::SeedableRng;
    Pcg64::seed_from_u64(seed)
}

/// `n` random points of the layout's grid.
pub fn random_points(rng: &mut Pcg64, n: usize, layout: PhotonLayout) -> Vec<[u32; 3]> {
    (0..n)
        .map(|_| [0, 1, 2].map(|a| rng.gen_range(0..=layout.coord_max(a))))
        .collect()
}

pub fn pack(points: &[[u32; 3]], layout: PhotonLayout) -> PackedTree {
    PackedTree::from_tree(&KdTree::build(points), layout)
}

/// Simulation options with random valid/ready stalls on every stream from `seed`.
pub fn stalls(seed: u64) -> SimOptions {
    SimOptions {
        vcd: None,
        stall_seed: Some(seed),
        ..Default::default()
    }
}

/// Random queries on the grid with k in 1..=k_max and radii from 0 to unbounded.
pub fn random_queries(
    rng: &mut Pcg64,
    n: usize,
    layout: PhotonLayout,
    k_max: usize,
    metric: Metric,
) -> Vec<HwQuery> {
    let max = metric.max_dist(layout.bits);
    (0..n)
        .map(|i| HwQuery {
            id: 1000 + i as u32,
            coords: [0, 1, 2].map(|a| rng.gen_range(0..=layout.coord_max(a))),
            radius: match rng.gen_range(0..4) {
                0 => u64::MAX,
                1 => max,
                _ => rng.gen_range(0..=max / 8),
            },
            k: rng.gen_range(1..=k_max as u32),
        })
        .collect()
}

/// Every result equals `knn::search` on the same tree (same slots, same reads), its
/// sorted distances equal brute force, and count = min(k, photons within r0).
pub fn check_results(
    cfg: &CoreConfig,
    tree: &PackedTree,
    points: &[[u32; 3]],
    queries: &[HwQuery],
    results: &[HwResult],
) {
    assert_eq!(results.len(), queries.len());
    for (q, r) in queries.iter().zip(results) {
        assert_eq!(r.id, q.id);
        let sw = knn::search_with(
            tree,
            q.coords,
            q.k as usize,
            q.radius,
            cfg.metric,
            cfg.traversal,
        );
        assert_eq!(
            r.found, sw.slots,
            "query {q:?}: found list differs from knn::search"
        );
        assert_eq!(
            r.visited, sw.visited,
            "query {q:?}: reads differ from knn::search"
        );
        let bf = knn::brute_force(points, q.coords, q.k as usize, q.radius, cfg.metric);
        let mut hw: Vec<u64> = r.found.iter().map(|f| f.1).collect();
        hw.sort();
        let bf_d: Vec<u64> = bf.iter().map(|f| f.1).collect();
        assert_eq!(hw, bf_d, "query {q:?}: distances differ from brute force");
        let within = points
            .iter()
            .filter(|&&p| cfg.metric.dist(p, q.coords) <= q.radius)
            .count();
        assert_eq!(
            r.found.len(),
            within.min(q.k as usize),
            "query {q:?}: count"
        );
        for &(addr, d) in &r.found {
            assert!(addr >= 1 && addr as usize <= tree.len());
            let (p, _) = tree.node(addr as usize);
            assert_eq!(
                d,
                cfg.metric.dist(p, q.coords),
                "query {q:?}: distance of {addr}"
            );
        }
    }
}

/// A small configuration for quick tests.
pub fn small_config(
    layout: PhotonLayout,
    address_bits: u32,
    k: usize,
    q: usize,
    metric: Metric,
) -> CoreConfig {
    CoreConfig::builder()
        .layout(layout)
        .address_bits(address_bits)
        .k(k)
        .queries_per_port(q)
        .metric(metric)
        .build()
        .expect("a small core within the limits")
}

/// A block's configurations to test: `base` with each (traversal, metric, k) in
/// `cases`, validated, each with its seed.
pub fn variants(
    base: CoreConfig,
    cases: &[(Traversal, Metric, usize, u64)],
) -> Vec<(CoreConfig, u64)> {
    cases
        .iter()
        .map(|&(traversal, metric, k, seed)| {
            let cfg = CoreConfig {
                traversal,
                metric,
                k,
                ..base
            };
            cfg.validate().expect("a configuration within the limits");
            (cfg, seed)
        })
        .collect()
}

/// `tool` is installed (else the test fails, naming the packages to install).
pub fn require(tool: &str) {
    let found = std::process::Command::new(tool).arg("-V").output().is_ok()
        || std::process::Command::new(tool)
            .arg("--version")
            .output()
            .is_ok();
    assert!(
        found,
        "{tool} is not installed: apt-get install -y yosys verilator iverilog"
    );
}

/// Run `cmd`; fail the test with its output unless it succeeds.
pub fn run_tool(cmd: &mut std::process::Command, what: &str) {
    let out = cmd.output().unwrap_or_else(|e| panic!("{what}: {e}"));
    assert!(
        out.status.success(),
        "{what} failed:\n{}\n{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
}

/// The exported `top.v` in `dir` passes yosys `check -assert` (no undriven or
/// multiply driven nets, no combinational loops), Verilator's lint and an Icarus
/// compile.
pub fn lint_top(dir: &std::path::Path) {
    use std::process::Command;
    require("yosys");
    run_tool(
        Command::new("yosys").current_dir(dir).args([
            "-q",
            "-p",
            "read_verilog top.v; hierarchy -check -top top; proc; check -assert",
        ]),
        "yosys check",
    );
    require("verilator");
    run_tool(
        Command::new("verilator").current_dir(dir).args([
            "--lint-only",
            "-Wno-WIDTH",
            // rust-hdl emits one `always @(*)` per module, so a valid/ready pair
            // between two modules looks like a loop at block granularity. That is
            // Verilator's performance warning, not a real loop: yosys `check
            // -assert` above rejects true combinational loops.
            "-Wno-UNOPTFLAT",
            "--top-module",
            "top",
            "top.v",
        ]),
        "verilator lint",
    );
    require("iverilog");
    run_tool(
        Command::new("iverilog")
            .current_dir(dir)
            .args(["-g2005", "-o", "/dev/null", "top.v"]),
        "iverilog compile",
    );
}
