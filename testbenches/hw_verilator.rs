//! Issue 14: the exported core under Verilator (`Engine::Verilator`) gives the same
//! results and the same cycle counts as rust-hdl's native simulation, query by
//! query, through the same driver: random maps, hard cases (all photons at one
//! point, ties), random stalls on every stream, and a replicated array (results,
//! cycles and every tree's read counters); and its `--vcd` trace shows the same
//! stream handshakes at the same times as the native trace.

use crate::common::*;
use photon_fpga::hw::config::controller::Controller;
use photon_fpga::hw::config::core_config::CoreConfig;
use photon_fpga::hw::config::metric::Metric;
use photon_fpga::hw::config::photon_word::PhotonLayout;
use photon_fpga::hw::config::traversal::Traversal;
use photon_fpga::hw::sim::driver::HwQuery;
use photon_fpga::hw::sim::native::{run_gather, Engine, SimOptions};

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
    assert_eq!(ns, vs, "read counters differ");
    check_results(cfg, &tree, points, queries, &native);
}

#[test]
#[cfg_attr(not(has_verilator), ignore = "needs verilator")]
fn verilator_equals_the_native_simulation() {
    let cfg = small_config(PhotonLayout::new([7, 6, 5]), 7, 5, 4, Metric::L2);
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
    let array = cfg.to_builder().trees(2).build().unwrap();
    both(&array, &points, &queries, Some(9));
    // The barrel port (cell traversal, 4 slots), alone and in an array.
    let barrel = CoreConfig::builder()
        .layout(cfg.layout)
        .address_bits(cfg.address_bits)
        .k(cfg.k)
        .metric(cfg.metric)
        .traversal(Traversal::Cell)
        .controller(Controller::Barrel)
        .queries_per_port(4);
    both(&barrel.build().unwrap(), &points, &queries, Some(10));
    both(&barrel.build().unwrap(), &one, &q_one, Some(11));
    both(
        &barrel.trees(2).build().unwrap(),
        &points,
        &queries,
        Some(12),
    );
}

/// The value changes of the top-level port `name` in a VCD file: (time, value).
/// A variable's name is its path below the outermost scope joined by `$` (rust-hdl
/// nests a bundle's members in a scope, Verilator writes `query$valid`); the
/// shallowest match is the top's own port, not a child's.
fn port_trace(path: &std::path::Path, name: &str) -> Vec<(u64, String)> {
    let file = std::io::BufReader::new(std::fs::File::open(path).expect("vcd written"));
    let mut parser = vcd::Parser::new(file);
    let header = parser.parse_header().expect("vcd header");
    type Best = Option<(usize, vcd::IdCode)>;
    fn find(items: &[vcd::ScopeItem], name: &str, prefix: &[String], best: &mut Best) {
        for item in items {
            match item {
                vcd::ScopeItem::Var(v) => {
                    let mut full = prefix.get(1..).unwrap_or_default().to_vec();
                    full.push(v.reference.clone());
                    if full.join("$") == name && best.is_none_or(|(d, _)| prefix.len() < d) {
                        *best = Some((prefix.len(), v.code));
                    }
                }
                vcd::ScopeItem::Scope(s) => {
                    let mut p = prefix.to_vec();
                    p.push(s.identifier.clone());
                    find(&s.children, name, &p, best);
                }
            }
        }
    }
    let mut best = None;
    find(&header.items, name, &[], &mut best);
    let code = best
        .unwrap_or_else(|| panic!("{name} not in {}", path.display()))
        .1;
    let mut time = 0;
    let mut changes: Vec<(u64, String)> = vec![];
    for cmd in parser {
        match cmd.expect("vcd body") {
            vcd::Command::Timestamp(t) => time = t,
            vcd::Command::ChangeScalar(c, v) if c == code => {
                let v = v.to_string();
                if changes.last().is_none_or(|(_, last)| *last != v) {
                    changes.push((time, v));
                }
            }
            _ => {}
        }
    }
    changes
}

#[test]
#[cfg_attr(not(has_verilator), ignore = "needs verilator")]
fn verilator_vcd_shows_the_native_handshakes() {
    let cfg = small_config(PhotonLayout::new([6, 6, 6]), 6, 3, 3, Metric::L1);
    let mut r = rng(32);
    let points = random_points(&mut r, 40, cfg.layout);
    let queries = random_queries(&mut r, 12, cfg.layout, cfg.k, cfg.metric);
    let tree = pack(&points, cfg.layout);
    let dir = tempfile::tempdir().expect("tempdir");
    let trace = |engine, file: &str| {
        let path = dir.path().join(file);
        let opts = SimOptions {
            engine,
            stall_seed: Some(5),
            vcd: Some(path.clone()),
            memory: None,
        };
        let (results, _) = run_gather(&cfg, tree.image(), &queries, &opts).expect("simulation");
        check_results(&cfg, &tree, &points, &queries, &results);
        path
    };
    let native = trace(Engine::Native, "native.vcd");
    let verilated = trace(Engine::Verilator, "verilator.vcd");
    for port in [
        "query$valid",
        "query$ready",
        "result$valid",
        "result$ready",
        "load$ready",
    ] {
        let n = port_trace(&native, port);
        let v = port_trace(&verilated, port);
        assert!(
            n.len() >= 3,
            "{port} hardly changes in the native trace: {n:?}"
        );
        assert_eq!(n, v, "{port}: native and Verilator traces differ");
    }
}
