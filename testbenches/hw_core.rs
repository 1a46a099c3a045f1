//! End-to-end tests of the simulated PhotonSearchCore against knn::search (same
//! slots, same reads) and brute force (same sorted distances): random maps, the hard
//! cases, random stalls on every stream, two maps loaded one after the other.

use crate::common::*;
use photon_fpga::hw::config::controller::Controller;
use photon_fpga::hw::config::core_config::{CoreConfig, BARREL_SLOTS};
use photon_fpga::hw::config::metric::Metric;
use photon_fpga::hw::config::photon_word::PhotonLayout;
use photon_fpga::hw::config::traversal::Traversal;
use photon_fpga::hw::sim::driver::HwQuery;
use photon_fpga::hw::sim::native::{run_gather, CoreSim, SimOptions};
use rand::Rng;

/// Every (traversal, controller) a port can be built with.
const EVERY_PORT: [(Traversal, Controller); 5] = [
    (Traversal::Remember, Controller::Modules),
    (Traversal::Reread, Controller::Modules),
    (Traversal::Cell, Controller::Modules),
    (Traversal::Remember, Controller::Barrel),
    (Traversal::Cell, Controller::Barrel),
];

/// The QueryModule core and the barrel core with the cell traversal.
fn both_controllers(cfg: CoreConfig) -> [CoreConfig; 2] {
    [cfg, variant(cfg, Traversal::Cell, Controller::Barrel)]
}

/// `cfg` with another traversal and controller, its Q kept (as QueryModules or
/// query slots per port).
fn variant(cfg: CoreConfig, traversal: Traversal, controller: Controller) -> CoreConfig {
    cfg.to_builder()
        .default_queries_per_port()
        .controller(controller)
        .traversal(traversal)
        .queries_per_port(cfg.queries_per_port)
        .build()
        .expect("config")
}

/// A small core for the map: Q capped to keep the simulation quick.
fn small_core(
    tree: &photon_fpga::host::map::kdtree::PackedTree,
    k: usize,
    metric: Metric,
) -> CoreConfig {
    let cfg = CoreConfig::for_map(tree.image(), k, metric).expect("config");
    cfg.to_builder()
        .queries_per_port(cfg.queries_per_port.min(6))
        .build()
        .expect("config")
}

fn run_case(
    points: &[[u32; 3]],
    layout: PhotonLayout,
    metric: Metric,
    k: usize,
    queries: &[HwQuery],
) {
    let tree = pack(points, layout);
    // Every traversal on QueryModules (the default path memory, the paper's
    // re-reads, the cell bound), and the two the barrel port runs.
    for (traversal, controller) in EVERY_PORT {
        let cfg = variant(small_core(&tree, k, metric), traversal, controller);
        let (results, _) =
            run_gather(&cfg, tree.image(), queries, &SimOptions::default()).expect("sim");
        check_results(&cfg, &tree, points, queries, &results);
    }
}

/// Queries that stress the boundary rules on `points`: on photons (split planes),
/// at the grid corners, radius 0 / exact / huge, k = 1, K, N.
pub(crate) fn hard_queries(
    points: &[[u32; 3]],
    layout: PhotonLayout,
    metric: Metric,
    k_max: usize,
    seed: u64,
) -> Vec<HwQuery> {
    let mut r = rng(seed);
    let max = [0, 1, 2].map(|a| layout.coord_max(a));
    let mut at: Vec<[u32; 3]> = vec![[0, 0, 0], max, [max[0], 0, max[2]]];
    at.extend(points.iter().take(6).copied());
    for _ in 0..3 {
        at.push([0, 1, 2].map(|a| r.gen_range(0..=max[a])));
    }
    let mut ks = vec![1u32, k_max as u32];
    if points.len() <= k_max {
        ks.push(points.len() as u32);
    }
    ks.push(r.gen_range(1..=k_max as u32));
    let mut queries = vec![];
    for (i, &c) in at.iter().enumerate() {
        // Radii: 0, the exact distance of some photon (a tie at the bound), huge.
        let p = points[r.gen_range(0..points.len())];
        let radii = [0, metric.dist(p, c), u64::MAX];
        for (j, &radius) in radii.iter().enumerate() {
            let k = ks[(i + j) % ks.len()];
            queries.push(HwQuery {
                id: queries.len() as u32,
                coords: c,
                radius,
                k,
            });
        }
    }
    queries
}

fn hard_case(points: Vec<[u32; 3]>, layout: PhotonLayout) {
    for metric in [Metric::L2, Metric::L1] {
        let k = 6;
        let queries = hard_queries(&points, layout, metric, k, points.len() as u64);
        run_case(&points, layout, metric, k, &queries);
    }
}

#[test]
fn random_maps_both_metrics() {
    for (seed, metric) in [(1u64, Metric::L2), (2, Metric::L1)] {
        let layout = PhotonLayout::new([8, 7, 6]);
        let mut r = rng(seed);
        let points = random_points(&mut r, 300, layout);
        let queries = random_queries(&mut r, 40, layout, 8, metric);
        run_case(&points, layout, metric, 8, &queries);
    }
}

#[test]
fn all_photons_at_one_point() {
    let layout = PhotonLayout::new([6, 6, 6]);
    hard_case(vec![[17, 5, 40]; 40], layout);
    hard_case(vec![[0, 0, 0]; 9], layout);
    hard_case(vec![[63, 63, 63]; 9], layout);
}

#[test]
fn many_duplicates_and_ties_at_the_kth_distance() {
    let layout = PhotonLayout::new([5, 5, 5]);
    let mut r = rng(4);
    // Few distinct positions: many photons share a distance from any query.
    let base: Vec<[u32; 3]> = (0..5)
        .map(|_| [0, 1, 2].map(|_| r.gen_range(0..32)))
        .collect();
    let points: Vec<[u32; 3]> = (0..120).map(|i| base[i % base.len()]).collect();
    hard_case(points, layout);
    // A symmetric cross around (16,16,16): six photons at the same distance.
    let mut cross = vec![];
    for d in 1..4u32 {
        for a in 0..3 {
            let mut p = [16u32; 3];
            p[a] += d;
            cross.push(p);
            p[a] -= 2 * d;
            cross.push(p);
        }
    }
    let queries: Vec<HwQuery> = (1..=6)
        .flat_map(|k| {
            [1u64, 4, 9, u64::MAX].map(|radius| HwQuery {
                id: 0,
                coords: [16, 16, 16],
                radius,
                k,
            })
        })
        .collect();
    for metric in [Metric::L2, Metric::L1] {
        run_case(&cross, layout, metric, 6, &queries);
    }
}

#[test]
fn coplanar_and_collinear() {
    let layout = PhotonLayout::new([7, 7, 7]);
    let mut r = rng(5);
    let plane: Vec<[u32; 3]> = (0..100)
        .map(|_| [r.gen_range(0..128), r.gen_range(0..128), 64])
        .collect();
    hard_case(plane, layout);
    let line: Vec<[u32; 3]> = (0..60).map(|_| [r.gen_range(0..128), 3, 3]).collect();
    hard_case(line, layout);
    let diagonal: Vec<[u32; 3]> = (0..60).map(|i| [i * 2, i * 2, i * 2]).collect();
    hard_case(diagonal, layout);
}

#[test]
fn photon_counts_around_powers_of_two() {
    let layout = PhotonLayout::new([6, 5, 4]);
    let mut r = rng(6);
    for n in [1usize, 2, 3, 7, 8, 9, 15, 16, 17, 31, 32, 33] {
        let points = random_points(&mut r, n, layout);
        hard_case(points, layout);
    }
}

#[test]
fn paper_config_matches_software() {
    let cfg = CoreConfig::paper();
    let layout = cfg.layout;
    let mut r = rng(8);
    let points = random_points(&mut r, 1023, layout);
    let tree = pack(&points, layout);
    let mut queries = random_queries(&mut r, 60, layout, cfg.k, cfg.metric);
    for q in queries.iter_mut().take(30) {
        q.k = cfg.k as u32;
        q.radius = u64::MAX;
    }
    let barrel = cfg
        .to_builder()
        .default_queries_per_port()
        .traversal(Traversal::Cell)
        .controller(Controller::Barrel)
        .queries_per_port(BARREL_SLOTS)
        .build()
        .unwrap();
    for cfg in [cfg, barrel] {
        let (results, stats) =
            run_gather(&cfg, tree.image(), &queries, &SimOptions::default()).expect("sim");
        check_results(&cfg, &tree, &points, &queries, &results);
        assert!(
            stats.reads_per_port.iter().all(|&r| r > 0),
            "both ports read"
        );
    }
}

/// K > 32 switches the core to 64-bit slot masks: K = 50 (the paper's §5 example)
/// and K = 64 (every slot bit used), with ties at the K-th distance.
#[test]
fn wide_found_lists() {
    let layout = PhotonLayout::new([6, 6, 6]);
    let mut r = rng(50);
    let mut points = random_points(&mut r, 150, layout);
    points.extend(vec![[20, 20, 20]; 70]);
    for (k, metric) in [(50usize, Metric::L1), (64, Metric::L2)] {
        let mut queries = random_queries(&mut r, 10, layout, k, metric);
        queries.extend(hard_queries(&points, layout, metric, k, k as u64));
        for (i, q) in queries.iter_mut().enumerate() {
            q.id = i as u32;
        }
        let tree = pack(&points, layout);
        let cfg = small_core(&tree, k, metric);
        assert_eq!(cfg.slot_bits(), 64);
        let (results, _) =
            run_gather(&cfg, tree.image(), &queries, &SimOptions::default()).expect("sim");
        check_results(&cfg, &tree, &points, &queries, &results);
        assert!(results.iter().any(|r| r.found.len() == k));
    }
}

/// Photon words wider than 32 bits (12-bit coordinates: 38 bits; 15-bit: 47 bits) on
/// the 64-bit word ports: the split axis and z sit above bit 32, so a truncated
/// word would send the search down the wrong subtrees. Against knn::search and brute
/// force, with a cluster at the top of every axis.
#[test]
fn wide_photon_words() {
    for (bits, metric, k, seed) in [
        ([12, 12, 12], Metric::L1, 10usize, 55u64),
        ([15, 15, 15], Metric::L2, 8, 56),
    ] {
        let layout = PhotonLayout::new(bits);
        let mut r = rng(seed);
        let mut points = random_points(&mut r, 200, layout);
        let top = [0, 1, 2].map(|a| layout.coord_max(a));
        points.extend(vec![top; 12]);
        points.extend((0..8).map(|i| [top[0] - i, top[1], top[2] - 2 * i]));
        let mut queries = random_queries(&mut r, 20, layout, k, metric);
        queries.extend(hard_queries(&points, layout, metric, k, 20));
        for (i, q) in queries.iter_mut().enumerate() {
            q.id = i as u32;
        }
        let tree = pack(&points, layout);
        let cfg = small_core(&tree, k, metric);
        assert_eq!((cfg.slot_bits(), cfg.word_width()), (32, 64));
        let (results, _) =
            run_gather(&cfg, tree.image(), &queries, &SimOptions::default()).expect("sim");
        check_results(&cfg, &tree, &points, &queries, &results);
        assert!(results.iter().any(|r| r.found.len() == k));
    }
}

#[test]
fn random_stalls_on_every_stream() {
    let layout = PhotonLayout::new([7, 7, 7]);
    for (seed, metric) in [(21u64, Metric::L2), (22, Metric::L1)] {
        let mut r = rng(seed);
        let points = random_points(&mut r, 200, layout);
        let tree = pack(&points, layout);
        let queries = random_queries(&mut r, 60, layout, 7, metric);
        let opts = SimOptions {
            vcd: None,
            stall_seed: Some(seed),
            ..Default::default()
        };
        for cfg in both_controllers(small_core(&tree, 7, metric)) {
            let (results, _) = run_gather(&cfg, tree.image(), &queries, &opts).expect("sim");
            check_results(&cfg, &tree, &points, &queries, &results);
        }
    }
}

#[test]
fn two_maps_one_after_the_other() {
    let layout = PhotonLayout::new([7, 6, 5]);
    let metric = Metric::L2;
    let mut r = rng(31);
    let first = random_points(&mut r, 250, layout);
    let second = random_points(&mut r, 90, layout);
    let (t1, t2) = (pack(&first, layout), pack(&second, layout));
    let q1 = random_queries(&mut r, 25, layout, 5, metric);
    let q2 = random_queries(&mut r, 25, layout, 5, metric);
    for (cfg, stall_seed) in both_controllers(small_core(&t1, 5, metric))
        .into_iter()
        .flat_map(|c| [(c, None), (c, Some(5))])
    {
        let mut sim = CoreSim::new(
            &cfg,
            &SimOptions {
                vcd: None,
                stall_seed,
                ..Default::default()
            },
        )
        .unwrap();
        sim.load_map(t1.image()).unwrap();
        check_results(&cfg, &t1, &first, &q1, &sim.run_queries(&q1).unwrap());
        // Second map without reset: a smaller map over the larger one.
        sim.load_map(t2.image()).unwrap();
        check_results(&cfg, &t2, &second, &q2, &sim.run_queries(&q2).unwrap());
        // Back to the first map, with a reset in between.
        sim.reset().unwrap();
        sim.load_map(t1.image()).unwrap();
        check_results(&cfg, &t1, &first, &q1, &sim.run_queries(&q1).unwrap());
    }
}

#[test]
fn rejects_what_it_cannot_do() {
    let layout = PhotonLayout::new([6, 6, 6]);
    let points = vec![[1, 2, 3]; 5];
    let tree = pack(&points, layout);
    let cfg = small_core(&tree, 4, Metric::L2);
    let bad_k = [HwQuery {
        id: 0,
        coords: [1, 1, 1],
        radius: 5,
        k: 5,
    }];
    assert!(run_gather(&cfg, tree.image(), &bad_k, &SimOptions::default()).is_err());
    let bad_coord = [HwQuery {
        id: 0,
        coords: [64, 1, 1],
        radius: 5,
        k: 1,
    }];
    assert!(run_gather(&cfg, tree.image(), &bad_coord, &SimOptions::default()).is_err());
    // Too wide for the 32-bit word / distance datapath, too many slots.
    let wide = pack(&points, PhotonLayout::new([16, 16, 16]));
    assert!(CoreConfig::for_map(wide.image(), 4, Metric::L2).is_err());
    assert!(CoreConfig::for_map(tree.image(), 65, Metric::L2).is_err());
    let other_layout = pack(&points, PhotonLayout::new([6, 6, 7]));
    assert!(run_gather(&cfg, other_layout.image(), &[], &SimOptions::default()).is_err());
}

/// A core built for a largest radius (`radius_bits`, narrower than the grid's
/// diagonal): most photons lie beyond its distances, which saturate, and still
/// every port answers as the software search and brute force do, read for read,
/// with radii up to the largest it takes (ties at the bound, 0, a photon's exact
/// distance). A larger radius is refused.
#[test]
fn narrow_distances_answer_radii_below_saturation() {
    let layout = PhotonLayout::new([8, 7, 6]);
    for (seed, metric, bits) in [(41u64, Metric::L2, 12u32), (42, Metric::L1, 7)] {
        let mut r = rng(seed);
        let points = random_points(&mut r, 400, layout);
        let tree = pack(&points, layout);
        let base = small_core(&tree, 8, metric)
            .to_builder()
            .radius_bits(Some(bits))
            .build()
            .expect("config");
        assert!(base.saturates() && base.dist_bits() == bits);
        let top = base.max_radius();
        let mut queries: Vec<HwQuery> = (0..40)
            .map(|i| {
                let coords = [0, 1, 2].map(|a| r.gen_range(0..=layout.coord_max(a)));
                let p = points[r.gen_range(0..points.len())];
                let radius = match i % 4 {
                    0 => top,
                    1 => metric.dist(p, coords).min(top),
                    2 => 0,
                    _ => r.gen_range(0..=top),
                };
                HwQuery {
                    id: i,
                    coords,
                    radius,
                    k: r.gen_range(1..=8),
                }
            })
            .collect();
        for (traversal, controller) in EVERY_PORT {
            let cfg = variant(base, traversal, controller);
            let (results, _) =
                run_gather(&cfg, tree.image(), &queries, &SimOptions::default()).expect("sim");
            check_results(&cfg, &tree, &points, &queries, &results);
        }
        // Most distances of the grid are beyond the width: saturation was exercised.
        let beyond = points
            .iter()
            .filter(|&&p| metric.dist(p, queries[0].coords) > (1u64 << bits) - 1)
            .count();
        assert!(beyond > points.len() / 2, "{metric}: {beyond} beyond");
        queries.truncate(1);
        queries[0].radius = top + 1;
        let refused = run_gather(&base, tree.image(), &queries, &SimOptions::default())
            .expect_err("a radius above the saturated distance")
            .to_string();
        // The largest radius below the saturated distance 2^bits − 1.
        let limit = format!("answers radii up to {} on the grid", (1u64 << bits) - 2);
        assert!(
            refused.contains(&format!("radius {} is beyond", top + 1)),
            "{refused}"
        );
        assert!(refused.contains(&limit), "{refused}");
    }
}

#[test]
fn vcd_trace_is_streamed() {
    let layout = PhotonLayout::new([5, 5, 5]);
    let mut r = rng(61);
    let points = random_points(&mut r, 20, layout);
    let tree = pack(&points, layout);
    let cfg = small_core(&tree, 3, Metric::L1);
    let queries = random_queries(&mut r, 3, layout, 3, Metric::L1);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("core.vcd");
    let opts = SimOptions {
        vcd: Some(path.clone()),
        stall_seed: None,
        ..Default::default()
    };
    let (results, stats) = run_gather(&cfg, tree.image(), &queries, &opts).expect("sim");
    check_results(&cfg, &tree, &points, &queries, &results);
    let vcd = std::fs::read_to_string(&path).unwrap();
    assert!(vcd.contains("$enddefinitions"));
    assert!(vcd.contains("result_valid"));
    // One timestamp per clock edge at least.
    let stamps = vcd.lines().filter(|l| l.starts_with('#')).count() as u64;
    assert!(
        stamps >= 2 * stats.cycles - 2,
        "{stamps} timestamps for {} cycles",
        stats.cycles
    );
}

#[test]
fn reset_in_the_middle_of_a_search() {
    let layout = PhotonLayout::new([7, 7, 6]);
    let metric = Metric::L1;
    let mut r = rng(81);
    let points = random_points(&mut r, 200, layout);
    let tree = pack(&points, layout);
    let queries = random_queries(&mut r, 30, layout, 6, metric);
    for cfg in both_controllers(small_core(&tree, 6, metric)) {
        let mut sim = CoreSim::new(&cfg, &SimOptions::default()).unwrap();
        sim.load_map(tree.image()).unwrap();
        for cycles in [3u64, 57, 200] {
            let partial = sim.run_queries_for(&queries, cycles).unwrap();
            assert!(
                partial.iter().any(|p| p.is_none()),
                "still in flight at the reset"
            );
            sim.reset().unwrap();
            // The map survives a reset but must be reloaded to be searched again.
            sim.load_map(tree.image()).unwrap();
            check_results(
                &cfg,
                &tree,
                &points,
                &queries,
                &sim.run_queries(&queries).unwrap(),
            );
        }
    }
}

/// A query whose every far subtree is pruned reads exactly its descent path in the
/// core too: photons on even grid points, queries on odd ones, R0 = 0, so no axis
/// distance is within R. The path length is walked here from the packed words
/// (near child while one exists); the paper's re-read ascent reads every parent
/// once more.
#[test]
fn pruned_ascent_reads_only_the_descent_path() {
    let layout = PhotonLayout::new([7, 7, 7]);
    let mut r = rng(77);
    let points: Vec<[u32; 3]> = random_points(&mut r, 200, PhotonLayout::new([6, 6, 6]))
        .into_iter()
        .map(|p| p.map(|c| 2 * c))
        .collect();
    let tree = pack(&points, layout);
    let queries: Vec<HwQuery> = (0..12)
        .map(|i| HwQuery {
            id: i,
            coords: [0; 3].map(|_: u32| 2 * r.gen_range(0..64u32) + 1),
            radius: 0,
            k: 3,
        })
        .collect();
    let depth = |q: [u32; 3]| {
        let (mut addr, mut depth) = (1usize, 0u32);
        loop {
            depth += 1;
            let (p, ax) = tree.node(addr);
            let near = 2 * addr + (q[ax as usize] >= p[ax as usize]) as usize;
            if near > tree.len() {
                return depth;
            }
            addr = near;
        }
    };
    for metric in [Metric::L1, Metric::L2] {
        for traversal in [Traversal::Remember, Traversal::Reread, Traversal::Cell] {
            let cfg = variant(small_core(&tree, 3, metric), traversal, Controller::Modules);
            let (results, _) =
                run_gather(&cfg, tree.image(), &queries, &SimOptions::default()).expect("sim");
            for (q, res) in queries.iter().zip(&results) {
                assert!(res.found.is_empty());
                let d = depth(q.coords);
                let want = match traversal {
                    Traversal::Remember | Traversal::Cell => d,
                    Traversal::Reread => 2 * d - 1,
                };
                assert_eq!(res.visited, want, "{traversal} {metric} {q:?}");
            }
        }
    }
}
