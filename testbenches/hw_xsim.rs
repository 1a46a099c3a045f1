//! Cycle-exact cross-simulation: the rust-hdl simulation of the core records the
//! input vector of every cycle and every handshake (testbenches/common/xsim.rs documents both
//! files); the exported Verilog replays the stimulus blindly under Icarus Verilog
//! and Verilator and must write the same response file byte for byte, so every
//! load, query and result beat moves at the same cycle with the same bits. The
//! recorded results must also equal `knn::search` (same slots, same reads) and brute
//! force. A deliberately broken export (one `(a & b) == c` losing its parentheses,
//! the rust-hdl precedence hazard) must be reported as a mismatch.
//!
//! Both simulators get the small configuration (also without its ResultRegisters and
//! with the paper's re-read ascent, and as a PhotonSearchArray of two replicated
//! trees), a K = 40 configuration with
//! 12-bit coordinates (64-bit slot masks and photon words) and the paper configuration
//! (a Cornell-box map and hard cases; under Verilator also random maps and a map
//! reloaded after queries: Icarus replays the paper's core at tens of cycles a
//! second, and the small configurations' reload runs in both), and
//! barrel cores with found lists of K = 100 and 512 (heaps in BlockRAM), and a banked
//! core whose distances are narrower than its grid's diagonal (`radius_bits`:
//! saturating distances, 16-bit comparisons). Icarus simulates the
//! `export::glitch_free` rewrite of the export (the raw export loops forever in
//! Icarus at the first result beat; see there). Without a simulator its tests are
//! ignored (build.rs); under CI=true a missing simulator fails.
//! `PHOTON_FPGA_XSIM_DIR=dir` keeps every file (plus a hand-replay directory per case).

use crate::common::xsim::{self, XsimMap, XsimRun};
use crate::common::xsim_tb::{self, Simulator};
use crate::common::*;
use photon_fpga::host::gather::{GatherParams, QuantizedMap};
use photon_fpga::host::map::kdtree::PackedTree;
use photon_fpga::host::render::photons::trace_photons;
use photon_fpga::host::render::scene::Scene;
use photon_fpga::host::render::{self, eye_queries, RenderSettings};
use photon_fpga::hw::config::bank_config::BankPorts;
use photon_fpga::hw::config::controller::Controller;
use photon_fpga::hw::config::core_config::{Banking, CoreConfig};
use photon_fpga::hw::config::metric::Metric;
use photon_fpga::hw::config::photon_word::PhotonLayout;
use photon_fpga::hw::config::traversal::Traversal;
use photon_fpga::hw::export::verilog::export_verilog;
use photon_fpga::hw::sim::driver::HwQuery;
use std::path::PathBuf;
use std::time::Instant;

/// The tests below run only where build.rs found their simulator (or under CI=true,
/// where a missing one fails here).
fn require(sim: Simulator) {
    assert!(sim.available(), "{} is not installed", sim.name());
}

/// A map with the grid points it was built from (for brute force).
struct Map {
    points: Vec<[u32; 3]>,
    tree: PackedTree,
    queries: Vec<HwQuery>,
}

struct Case {
    name: &'static str,
    maps: Vec<Map>,
    stall_seed: u64,
}

fn map(points: Vec<[u32; 3]>, layout: PhotonLayout, queries: Vec<HwQuery>) -> Map {
    let tree = pack(&points, layout);
    Map {
        points,
        tree,
        queries,
    }
}

/// Boundary queries: grid corners and photons, radius 0 / a photon's exact distance
/// (a tie at the bound) / unbounded, k = 1, K and in between.
fn hard_queries(points: &[[u32; 3]], cfg: &CoreConfig, n: usize) -> Vec<HwQuery> {
    let max = [0, 1, 2].map(|a| cfg.layout.coord_max(a));
    let mut at = vec![[0, 0, 0], max];
    at.extend(points.iter().take(3).copied());
    let ks = [1, cfg.k as u32, (cfg.k as u32).div_ceil(2)];
    let mut queries = vec![];
    for (i, &c) in at.iter().enumerate() {
        let p = points[(i * 7) % points.len()];
        for (j, radius) in [0, cfg.metric.dist(p, c), u64::MAX].into_iter().enumerate() {
            queries.push(HwQuery {
                id: queries.len() as u32,
                coords: c,
                radius,
                k: ks[(i + j) % ks.len()],
            });
        }
    }
    queries.truncate(n);
    queries
}

/// Six photons at equal distance around a centre, three shells.
fn cross(centre: [u32; 3]) -> Vec<[u32; 3]> {
    let mut pts = vec![];
    for d in 1..3u32 {
        for a in 0..3 {
            let mut p = centre;
            p[a] += d;
            pts.push(p);
            p[a] -= 2 * d;
            pts.push(p);
        }
    }
    pts
}

/// A Cornell-box photon map quantized to `bits`, with eye-ray queries.
/// At most `photons` stored photons (the first of the traced ones).
fn cornell(photons: usize, bits: u32, k: usize, metric: Metric, nq: usize) -> (Map, QuantizedMap) {
    let scene = Scene::cornell_box();
    let mut world = render::photon_points(&trace_photons(&scene, photons, 5, false));
    world.truncate(photons);
    let settings = RenderSettings {
        width: 4,
        height: 3,
        spp: 1,
        ..RenderSettings::default()
    };
    let (eye, _) = eye_queries(&scene, &settings);
    let params = GatherParams {
        k,
        radius: None,
        bits,
        metric,
        ..GatherParams::default()
    };
    let qmap = QuantizedMap::new(&world, &params).unwrap();
    let points: Vec<[u32; 3]> = world.iter().map(|&p| qmap.quant.quantize(p)).collect();
    let queries: Vec<HwQuery> = render::query_points(&eye)
        .iter()
        .take(nq)
        .enumerate()
        .map(|(i, &q)| HwQuery {
            id: 500 + i as u32,
            coords: qmap.quant.quantize(q),
            radius: qmap.radius_bound,
            k: k as u32,
        })
        .collect();
    let m = Map {
        points,
        tree: qmap.tree.clone(),
        queries,
    };
    (m, qmap)
}

/// The small configuration: the layout of a small Cornell-box map (6-bit grid),
/// H = 5, K = 3, Q = 2 per port, squared L2. Returns it with the Cornell map.
fn small() -> (CoreConfig, Map) {
    let (m, qmap) = cornell(24, 6, 3, Metric::L2, 3);
    let cfg = CoreConfig::builder()
        .k(3)
        .metric(Metric::L2)
        .for_map(qmap.tree.image())
        .address_bits(5)
        .queries_per_port(2)
        .build()
        .unwrap();
    cfg.check_map(m.tree.image()).unwrap();
    (cfg, m)
}

fn small_cases() -> (CoreConfig, Vec<Case>) {
    let (cfg, cornell_map) = small();
    let layout = cfg.layout;
    let mut r = rng(71);
    let a = random_points(&mut r, 20, layout);
    let qa = random_queries(&mut r, 5, layout, cfg.k, cfg.metric);
    let b = random_points(&mut r, 9, layout);
    let qb = random_queries(&mut r, 3, layout, cfg.k, cfg.metric);
    let one = vec![[1, 2, 3]; 7];
    let q_one = hard_queries(&one, &cfg, 4);
    let c = [3, 3, 3].map(|x: u32| x.min(layout.coord_max(0)));
    let ties = cross(c);
    let q_ties = hard_queries(&ties, &cfg, 5);
    let cases = vec![
        Case {
            name: "small_random_two_maps",
            maps: vec![map(a, layout, qa), map(b, layout, qb)],
            stall_seed: 1,
        },
        Case {
            name: "small_cornell",
            maps: vec![cornell_map],
            stall_seed: 2,
        },
        Case {
            name: "small_hard",
            maps: vec![map(one, layout, q_one), map(ties, layout, q_ties)],
            stall_seed: 3,
        },
    ];
    (cfg, cases)
}

/// K = 40 > 32 and 12-bit coordinates: the 64-bit slot masks and the 64-bit photon
/// word (a 38-bit word; H = 7, Q = 3 per port, L1), with a cluster of equal photons
/// so that lists fill and ties sit at the K-th distance.
fn wide_cases() -> (CoreConfig, Vec<Case>) {
    let layout = PhotonLayout::new([12, 12, 12]);
    let mut r = rng(73);
    let mut a = random_points(&mut r, 90, layout);
    a.extend(vec![[2049, 9, 4000]; 30]);
    let tree = pack(&a, layout);
    let cfg = CoreConfig::builder()
        .k(40)
        .metric(Metric::L1)
        .queries_per_port(3)
        .build_for(tree.image())
        .unwrap();
    assert_eq!((cfg.slot_bits(), cfg.word_width()), (64, 64));
    let mut qa = random_queries(&mut r, 6, layout, cfg.k, cfg.metric);
    qa.extend(hard_queries(&a, &cfg, 6));
    for (i, q) in qa.iter_mut().enumerate() {
        q.id = i as u32;
    }
    let cases = vec![Case {
        name: "wide_k40_12bit",
        maps: vec![map(a, layout, qa)],
        stall_seed: 4,
    }];
    (cfg, cases)
}

fn paper_cases() -> (CoreConfig, Vec<Case>) {
    let cfg = CoreConfig::paper();
    let layout = cfg.layout;
    let mut r = rng(72);
    let a = random_points(&mut r, 1000, layout);
    let qa = random_queries(&mut r, 40, layout, cfg.k, cfg.metric);
    let b = random_points(&mut r, 200, layout);
    let qb = random_queries(&mut r, 12, layout, cfg.k, cfg.metric);
    let (cm, qmap) = cornell(800, 10, cfg.k, cfg.metric, 12);
    assert_eq!(
        qmap.tree.layout, layout,
        "Cornell map layout != paper layout"
    );
    let one = vec![[512, 3, 1023]; 40];
    let q_one = hard_queries(&one, &cfg, 15);
    let ties = cross([500, 500, 500]);
    let q_ties = hard_queries(&ties, &cfg, 15);
    let plane: Vec<[u32; 3]> = (0..100)
        .map(|i| [(i * 37) % 1024, (i * 91) % 1024, 64])
        .collect();
    let q_plane = hard_queries(&plane, &cfg, 15);
    let cases = vec![
        Case {
            name: "paper_random_two_maps",
            maps: vec![map(a, layout, qa), map(b, layout, qb)],
            stall_seed: 11,
        },
        Case {
            name: "paper_cornell",
            maps: vec![cm],
            stall_seed: 12,
        },
        Case {
            name: "paper_hard",
            maps: vec![
                map(one, layout, q_one),
                map(ties, layout, q_ties),
                map(plane, layout, q_plane),
            ],
            stall_seed: 13,
        },
    ];
    (cfg, cases)
}

/// Found lists deeper than the comparator tree's (the barrel core's heaps in
/// BlockRAM): K = 100 and K = 512 on a map with a cluster of equal photons (ties at
/// the K-th distance), squared L2 (the heap key holds distance and entry).
fn deep_cases(k: usize, n: usize) -> (CoreConfig, Vec<Case>) {
    let layout = PhotonLayout::new([7, 7, 7]);
    let mut r = rng(74 + k as u64);
    let mut a = random_points(&mut r, n, layout);
    a.extend(vec![[90, 3, 77]; n / 3]);
    let tree = pack(&a, layout);
    let cfg = CoreConfig::builder()
        .k(k)
        .metric(Metric::L2)
        .controller(Controller::Barrel)
        .traversal(Traversal::Cell)
        .queries_per_port(4)
        .build_for(tree.image())
        .unwrap();
    assert!(cfg.uses_found_heap());
    let mut qa = random_queries(&mut r, 4, layout, cfg.k, cfg.metric);
    qa.extend(hard_queries(&a, &cfg, 2));
    for (i, q) in qa.iter_mut().enumerate() {
        q.id = i as u32;
    }
    let cases = vec![Case {
        name: if k == 100 { "deep_k100" } else { "deep_k512" },
        maps: vec![map(a, layout, qa)],
        stall_seed: 5,
    }];
    (cfg, cases)
}

fn deep_found_lists(sim: Simulator) {
    require(sim);
    for (label, k, n) in [("barrel_k100", 100, 180), ("barrel_k512", 512, 600)] {
        let (cfg, cases) = deep_cases(k, n);
        let runs = record(&cfg, &cases);
        let verilog = export_verilog(&cfg).unwrap().verilog;
        cross_simulate(sim, label, &verilog, &cases, &runs).unwrap();
    }
}

#[test]
#[cfg_attr(not(has_iverilog), ignore = "needs iverilog")]
fn icarus_deep_found_lists() {
    deep_found_lists(Simulator::Icarus);
}

#[test]
#[cfg_attr(not(has_verilator), ignore = "needs verilator")]
fn verilator_deep_found_lists() {
    deep_found_lists(Simulator::Verilator);
}

/// The banked core: two replicas of the top 4 levels, four datapaths, 8 banks
/// behind the crossbar, the results on two streams; a second map over the first.
fn banked_cases() -> (CoreConfig, Vec<Case>) {
    let layout = PhotonLayout::new([7, 7, 6]);
    let mut r = rng(76);
    let a = random_points(&mut r, 300, layout);
    let b = random_points(&mut r, 120, layout);
    let tree = pack(&a, layout);
    let cfg = CoreConfig::builder()
        .k(6)
        .metric(Metric::L2)
        .controller(Controller::Barrel)
        .traversal(Traversal::Cell)
        .queries_per_port(6)
        .trees(2)
        .banking(Some(Banking {
            bank_bits: 3,
            replicated_levels: 4,
            ports: BankPorts::Split,
            mapping: Default::default(),
        }))
        .result_streams(2)
        .radius_bits(Some(12))
        .build_for(tree.image())
        .unwrap();
    let mut qa = random_queries(&mut r, 24, layout, cfg.k, cfg.metric);
    qa.extend(hard_queries(&a, &cfg, 4));
    let mut qb = random_queries(&mut r, 12, layout, cfg.k, cfg.metric);
    // Distances of 12 bits (the grid's diagonal needs 16): most photons lie beyond,
    // saturated, and the radii go up to the largest the core answers.
    for (i, q) in qa.iter_mut().chain(qb.iter_mut()).enumerate() {
        q.id = i as u32;
        q.radius = q.radius.min(cfg.max_radius());
    }
    let cases = vec![Case {
        name: "banked",
        maps: vec![map(a, layout, qa), map(b, layout, qb)],
        stall_seed: 6,
    }];
    (cfg, cases)
}

fn banked_core(sim: Simulator) {
    require(sim);
    let (cfg, cases) = banked_cases();
    let runs = record(&cfg, &cases);
    let verilog = export_verilog(&cfg).unwrap().verilog;
    cross_simulate(sim, "banked", &verilog, &cases, &runs).unwrap();
}

#[test]
#[cfg_attr(not(has_iverilog), ignore = "needs iverilog")]
fn icarus_banked_core() {
    banked_core(Simulator::Icarus);
}

#[test]
#[cfg_attr(not(has_verilator), ignore = "needs verilator")]
fn verilator_banked_core() {
    banked_core(Simulator::Verilator);
}

/// Record every case in rust-hdl and check its results against the software search.
fn record(cfg: &CoreConfig, cases: &[Case]) -> Vec<XsimRun> {
    cases
        .iter()
        .map(|case| {
            let t = Instant::now();
            let maps: Vec<XsimMap> = case
                .maps
                .iter()
                .map(|m| XsimMap {
                    tree: m.tree.image(),
                    queries: m.queries.clone(),
                })
                .collect();
            let run = xsim::record(cfg, &maps, Some(case.stall_seed)).unwrap();
            for (m, results) in case.maps.iter().zip(&run.results) {
                check_results(cfg, &m.tree, &m.points, &m.queries, results);
            }
            eprintln!(
                "{}: rust-hdl recorded {} cycles, {} response lines in {:.1?}",
                case.name,
                run.cycles,
                run.responses.lines().count(),
                t.elapsed()
            );
            run
        })
        .collect()
}

fn work_dir(label: &str) -> (Option<tempfile::TempDir>, PathBuf) {
    match std::env::var_os("PHOTON_FPGA_XSIM_DIR") {
        Some(d) => {
            let p = PathBuf::from(d).join(label);
            std::fs::create_dir_all(&p).unwrap();
            (None, p)
        }
        None => {
            let t = tempfile::tempdir().unwrap();
            let p = t.path().to_path_buf();
            (Some(t), p)
        }
    }
}

/// Build `verilog` in `sim` and replay every run; the first mismatch, if any.
fn cross_simulate(
    sim: Simulator,
    label: &str,
    verilog: &str,
    cases: &[Case],
    runs: &[XsimRun],
) -> Result<(), String> {
    let (_keep, dir) = work_dir(&format!("{label}_{}", sim.name()));
    let max_cycles = runs.iter().map(|r| r.cycles).max().unwrap();
    let t = Instant::now();
    xsim_tb::build(sim, &dir, verilog, &runs[0].ports, max_cycles).unwrap();
    eprintln!("{label}: {} build {:.1?}", sim.name(), t.elapsed());
    for (case, run) in cases.iter().zip(runs) {
        if std::env::var_os("PHOTON_FPGA_XSIM_DIR").is_some() {
            xsim_tb::write_replay_dir(&dir.join(format!("{}_replay", case.name)), verilog, run)
                .unwrap();
        }
        let t = Instant::now();
        let got = xsim_tb::replay(sim, &dir, case.name, run).unwrap();
        eprintln!(
            "{label}/{}: {} replayed {} cycles in {:.1?}",
            case.name,
            sim.name(),
            run.cycles,
            t.elapsed()
        );
        if let Err(m) = xsim::compare(&run.responses, &got) {
            let msg = format!("{label}/{} under {}: {m}", case.name, sim.name());
            eprintln!("{msg}");
            return Err(msg);
        }
    }
    Ok(())
}

fn small_and_paper(sim: Simulator) {
    require(sim);
    // The small config also unpipelined and with the paper's re-read ascent (the
    // "before" rows of synth/REPORT.md); every other config has the default ascent.
    let unregistered = {
        let (cfg, cases) = small_cases();
        let b = cfg
            .to_builder()
            .pipelined(false)
            .traversal(Traversal::Reread);
        (b.build().unwrap(), cases)
    };
    // The cell-distance traversal (more QueryModule state, a wider path memory).
    let cell = {
        let (cfg, cases) = small_cases();
        (
            cfg.to_builder().traversal(Traversal::Cell).build().unwrap(),
            cases,
        )
    };
    // The barrel port: Q = 4 query slots behind one datapath per port, both
    // traversals it runs.
    let barrel = |traversal| {
        let (cfg, cases) = small_cases();
        let b = cfg.to_builder().default_queries_per_port();
        let b = b.traversal(traversal).controller(Controller::Barrel);
        (b.queries_per_port(4).build().unwrap(), cases)
    };
    // Two replicated trees (PhotonSearchArray) on the small config's cases.
    let array = {
        let (cfg, cases) = small_cases();
        (cfg.to_builder().trees(2).build().unwrap(), cases)
    };
    for (label, (cfg, cases)) in [
        ("small", small_cases()),
        ("small_unregistered_reread", unregistered),
        ("small_cell", cell),
        ("array_t2", array),
        ("small_barrel_remember", barrel(Traversal::Remember)),
        ("small_barrel_cell", barrel(Traversal::Cell)),
        ("wide", wide_cases()),
        ("paper", paper_cases()),
    ] {
        // Icarus (four-state, event-driven: X propagation and races Verilator cannot
        // see) replays the paper's core at about 40 cycles a second: it gets the
        // hard cases, Verilator the Cornell map, the random maps and the reload too
        // (the small configurations' Cornell map and reload run in both).
        let cases: Vec<Case> = cases
            .into_iter()
            .filter(|c| {
                sim == Simulator::Verilator
                    || !c.name.starts_with("paper_")
                    || c.name == "paper_hard"
            })
            .collect();
        let runs = record(&cfg, &cases);
        let verilog = export_verilog(&cfg).unwrap().verilog;
        cross_simulate(sim, label, &verilog, &cases, &runs).unwrap();
    }
}

#[test]
#[cfg_attr(not(has_iverilog), ignore = "needs iverilog")]
fn icarus_small_and_paper_config() {
    small_and_paper(Simulator::Icarus);
}

#[test]
#[cfg_attr(not(has_verilator), ignore = "needs verilator")]
fn verilator_small_and_paper_config() {
    small_and_paper(Simulator::Verilator);
}

/// rust-hdl prints `(a & b) == c` without the parentheses when they are left out in
/// Rust, where Verilog then reads `a & (b == c)`. Reproduce that on SearchPort's
/// `idle` (which gates the load stream) and require a reported mismatch.
#[test]
#[cfg_attr(
    not(all(has_iverilog, has_verilator)),
    ignore = "needs iverilog and verilator"
)]
fn broken_export_is_caught() {
    const GOOD: &str = "io$idle = (free_mask & all_modules) == all_modules;";
    const BAD: &str = "io$idle = free_mask & all_modules == all_modules;";
    let sims = [Simulator::Verilator, Simulator::Icarus];
    sims.into_iter().for_each(require);
    let (cfg, cases) = small_cases();
    let cases: Vec<Case> = cases
        .into_iter()
        .filter(|c| c.name == "small_random_two_maps")
        .collect();
    let runs = record(&cfg, &cases);
    let verilog = export_verilog(&cfg).unwrap().verilog;
    let hits = verilog.matches(GOOD).count();
    assert!(hits > 0, "mutation site `{GOOD}` not found in the export");
    let broken = verilog.replacen(GOOD, BAD, 1);
    for sim in sims {
        match cross_simulate(sim, "broken", &broken, &cases, &runs) {
            Ok(()) => panic!("{}: the broken export was NOT caught", sim.name()),
            Err(m) => eprintln!("caught as expected: {m}"),
        }
    }
}
