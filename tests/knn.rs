//! The software search (the hardware's reference) and the float baseline against
//! brute force, on random maps and the hard cases: one point, duplicates, coplanar
//! and collinear maps, ties on split planes and at the k-th distance, counts around
//! powers of two.

use photon_fpga::host::map::kdtree::{left_subtree_size, KdTree, PackedTree};
use photon_fpga::host::map::knn::{brute_force, search, search_with, Scalar, Traversal};
use photon_fpga::host::map::quantize::Quantizer;
use photon_fpga::hw::config::metric::Metric;
use photon_fpga::hw::config::photon_word::PhotonLayout;
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;

const METRICS: [Metric; 2] = [Metric::L2, Metric::L1];

fn rng(seed: u64) -> Pcg64Mcg {
    Pcg64Mcg::seed_from_u64(seed)
}

fn layout_for(points: &[[u32; 3]]) -> PhotonLayout {
    let mut bits = [1u32; 3];
    for p in points {
        for a in 0..3 {
            bits[a] = bits[a].max(32 - p[a].leading_zeros());
        }
    }
    PhotonLayout::new(bits)
}

/// Check one query every way: the packed search and the f64 search against brute
/// force (sorted distances), the found set's own consistency, and the count.
fn check(points: &[[u32; 3]], q: [u32; 3], k: usize, r0: u64, metric: Metric) {
    let tree = KdTree::build(points);
    let packed = PackedTree::from_tree(&tree, layout_for(points));
    let truth = brute_force(points, q, k, r0, metric);
    let truth_d: Vec<u64> = truth.iter().map(|t| t.1).collect();

    let found = search(&packed, q, k, r0, metric);
    assert_eq!(
        found.sorted_dists(),
        truth_d,
        "packed search != brute force: q={q:?} k={k} r0={r0} {metric:?} n={}",
        points.len()
    );
    let in_range = points.iter().filter(|&&p| metric.dist(q, p) <= r0).count();
    assert_eq!(found.slots.len(), k.min(in_range));
    let mut seen = std::collections::HashSet::new();
    for &(addr, d) in &found.slots {
        assert!(seen.insert(addr), "address {addr} returned twice");
        assert!(
            addr >= 1 && addr as usize <= points.len(),
            "padding entry {addr}"
        );
        let p = points[tree.perm[addr as usize] as usize];
        assert_eq!(metric.dist(q, p), d, "reported distance is wrong");
    }
    // The decoded tree and the packed words give the very same search.
    assert_eq!(search(&tree, q, k, r0, metric), found);

    // The default ascent reads each photon once (reads = distance tests); the paper's
    // re-read ascent makes the same decisions with the same R, so it finds the same
    // slots after the same distance tests, with more reads.
    assert_eq!(found.visited, found.tested);
    let paper = search_with(&packed, q, k, r0, metric, Traversal::Reread);
    assert_eq!(
        paper.slots, found.slots,
        "reread and remember differ: q={q:?} k={k}"
    );
    assert_eq!(paper.tested, found.tested);
    assert!(paper.visited >= found.visited);

    // The cell-distance bound (Arya–Mount) prunes a subtree only if no photon in it
    // can be nearer than R: the same distances as brute force, never more reads.
    let cell = search_with(&packed, q, k, r0, metric, Traversal::Cell);
    assert_eq!(
        cell.sorted_dists(),
        truth_d,
        "cell traversal != brute force: q={q:?} k={k} r0={r0} {metric:?}"
    );
    assert_eq!(cell.visited, cell.tested);
    assert!(
        cell.visited <= found.visited,
        "cell read more: q={q:?} k={k}"
    );

    // The float search over the same (integer-valued) positions: exact in f64.
    let fpoints: Vec<[f64; 3]> = points.iter().map(|p| p.map(|c| c as f64)).collect();
    let ftree = KdTree::build(&fpoints);
    let fq = q.map(|c| c as f64);
    let fr0 = if r0 >= 1 << 52 {
        f64::MAX_DIST
    } else {
        photon_fpga::host::map::knn::FloatDist::new(r0 as f64)
    };
    let ffound = search(&ftree, fq, k, fr0, metric);
    let fd: Vec<u64> = ffound
        .sorted_dists()
        .iter()
        .map(|d| d.get() as u64)
        .collect();
    assert_eq!(fd, truth_d, "float search != brute force");
    // The float cell bound adds the offsets as the distance adds the axes: never
    // above a distance, so nothing is pruned that could enter.
    let fcell = search_with(&ftree, fq, k, fr0, metric, Traversal::Cell);
    assert_eq!(
        fcell.sorted_dists(),
        ffound.sorted_dists(),
        "float cell traversal"
    );
}

fn random_points(n: usize, max: u32, seed: u64) -> Vec<[u32; 3]> {
    let mut r = rng(seed);
    (0..n)
        .map(|_| [0; 3].map(|_: u32| r.gen_range(0..=max)))
        .collect()
}

fn check_queries(points: &[[u32; 3]], queries: &[[u32; 3]], ks: &[usize], radii: &[u64]) {
    for &metric in &METRICS {
        for &q in queries {
            for &k in ks {
                for &r in radii {
                    check(points, q, k, r, metric);
                }
            }
        }
    }
}

fn random_queries(n: usize, max: u32, seed: u64) -> Vec<[u32; 3]> {
    let mut qs = random_points(n, max, seed);
    qs.push([0, 0, 0]);
    qs.push([max, max, max]);
    qs.push([0, max, 0]);
    qs
}

const ALL: u64 = u64::MAX;

#[test]
fn photon_word_round_trip() {
    let mut r = rng(1);
    for _ in 0..1000 {
        let bits = [0; 3].map(|_: u32| r.gen_range(1..=16));
        let layout = PhotonLayout::new(bits);
        let c = [0, 1, 2].map(|a| r.gen_range(0..=layout.coord_max(a)));
        let axis = r.gen_range(0..3u8);
        let w = layout.pack(c, axis);
        assert!(w < 1u64 << layout.word_bits());
        assert_eq!(layout.unpack(w), (c, axis));
    }
    assert_eq!(PhotonLayout::paper().word_bits(), 32);
}

#[test]
fn left_subtree_sizes_match_a_complete_tree() {
    // Independent model: count the nodes of a heap of n whose path starts at 2.
    for n in 1..300usize {
        let mut left = 0;
        for i in 1..=n {
            let mut a = i;
            while a > 3 {
                a >>= 1;
            }
            if a == 2 {
                left += 1;
            }
        }
        assert_eq!(left_subtree_size(n), left, "n={n}");
    }
}

fn check_tree_invariants(points: &[[u32; 3]]) {
    let tree = KdTree::build(points);
    let n = points.len();
    assert_eq!(tree.len(), n);
    let mut perm: Vec<u32> = tree.perm[1..].to_vec();
    perm.sort();
    assert_eq!(perm, (0..n as u32).collect::<Vec<_>>(), "every photon once");
    for addr in 1..=n {
        assert_eq!(tree.coords[addr], points[tree.perm[addr] as usize]);
        let ax = tree.axis[addr] as usize;
        assert!(ax < 3);
        let split = tree.coords[addr][ax];
        // Every node of the left subtree <= split <= every node of the right one.
        let mut stack = vec![(2 * addr, true), (2 * addr + 1, false)];
        while let Some((a, left)) = stack.pop() {
            if a > n {
                continue;
            }
            let c = tree.coords[a][ax];
            if left {
                assert!(c <= split, "left subtree violates split at {addr}");
            } else {
                assert!(c >= split, "right subtree violates split at {addr}");
            }
            stack.push((2 * a, left));
            stack.push((2 * a + 1, left));
        }
    }
}

#[test]
fn tree_invariants() {
    for n in [1, 2, 3, 4, 5, 7, 8, 9, 15, 16, 17, 100, 1000] {
        check_tree_invariants(&random_points(n, 1023, n as u64));
        check_tree_invariants(&random_points(n, 3, n as u64)); // many equal coords
        check_tree_invariants(&vec![[5, 5, 5]; n]);
    }
}

#[test]
fn random_maps() {
    for (n, max, seed) in [(1023, 1023, 1), (500, 63, 2), (2000, 1023, 3)] {
        let pts = random_points(n, max, seed);
        check_queries(
            &pts,
            &random_queries(40, max, seed + 100),
            &[1, 5, 10, 50],
            &[ALL, 40, 2000],
        );
    }
}

#[test]
fn all_photons_at_one_point() {
    let pts = vec![[7, 7, 7]; 100];
    check_queries(
        &pts,
        &[[7, 7, 7], [0, 0, 0], [7, 8, 7]],
        &[1, 10, 100, 150],
        &[ALL, 0, 1, 3],
    );
}

#[test]
fn many_duplicates() {
    let base = random_points(20, 1023, 5);
    let pts: Vec<[u32; 3]> = (0..400).map(|i| base[i % 20]).collect();
    check_queries(
        &pts,
        &random_queries(20, 1023, 6),
        &[1, 10, 25, 60],
        &[ALL, 5000],
    );
}

#[test]
fn coplanar_and_collinear() {
    let mut r = rng(7);
    let wall: Vec<[u32; 3]> = (0..500)
        .map(|_| [0, r.gen_range(0..1024), r.gen_range(0..1024)])
        .collect();
    check_queries(
        &wall,
        &random_queries(20, 1023, 8),
        &[1, 10, 40],
        &[ALL, 900],
    );
    let line: Vec<[u32; 3]> = (0..300).map(|_| [r.gen_range(0..1024), 9, 9]).collect();
    check_queries(
        &line,
        &random_queries(20, 1023, 9),
        &[1, 10, 40],
        &[ALL, 900],
    );
}

#[test]
fn equal_coordinates_on_the_split_axis() {
    // x spreads furthest but takes only three values: the median splits runs of ties.
    let mut r = rng(10);
    let pts: Vec<[u32; 3]> = (0..600)
        .map(|_| {
            [
                [0, 512, 1023][r.gen_range(0..3)],
                r.gen_range(0..50),
                r.gen_range(0..50),
            ]
        })
        .collect();
    let mut qs = random_queries(20, 1023, 11);
    qs.extend([[512, 25, 25], [511, 25, 25], [513, 0, 49]]);
    check_queries(&pts, &qs, &[1, 10, 100], &[ALL, 300]);
}

#[test]
fn query_on_split_planes() {
    let pts = random_points(300, 1023, 12);
    let tree = KdTree::build(&pts);
    // Queries that share the split coordinate of the first few nodes.
    let mut qs = Vec::new();
    for addr in 1..20 {
        let mut q = [500, 500, 500];
        let ax = tree.axis[addr] as usize;
        q[ax] = tree.coords[addr][ax];
        qs.push(q);
        qs.push(tree.coords[addr]);
    }
    check_queries(&pts, &qs, &[1, 8, 30], &[ALL, 1000]);
}

#[test]
fn ties_at_the_kth_distance() {
    // A lattice: many photons at exactly equal distances from its centre.
    let mut pts = Vec::new();
    for x in 0..9 {
        for y in 0..9 {
            for z in 0..9 {
                pts.push([x * 10, y * 10, z * 10]);
            }
        }
    }
    let qs = [[40, 40, 40], [45, 45, 45], [0, 0, 0], [40, 40, 45]];
    check_queries(&pts, &qs, &[1, 2, 5, 7, 19, 27, 33, 100], &[ALL, 100, 200]);
}

#[test]
fn photon_counts_around_powers_of_two() {
    for h in 1..=7u32 {
        for n in [(1usize << h) - 1, 1 << h, (1 << h) + 1] {
            let pts = random_points(n, 255, n as u64 + 50);
            check_queries(
                &pts,
                &random_queries(8, 255, 60),
                &[1, 3, n, n + 5],
                &[ALL, 500],
            );
        }
    }
}

#[test]
fn radius_zero_and_larger_than_the_scene() {
    let pts = random_points(200, 31, 13);
    let qs: Vec<[u32; 3]> = pts
        .iter()
        .take(20)
        .copied()
        .chain(random_queries(10, 31, 14))
        .collect();
    check_queries(&pts, &qs, &[1, 4, 300], &[0, 1, 10_000_000]);
}

#[test]
fn quantizer_fits_each_axis_to_its_extent() {
    // A flat slab: 10 m x 10 m x 0.1 m.
    let pts: Vec<[f64; 3]> = (0..100)
        .map(|i| {
            [
                (i % 10) as f64,
                0.01 * (i % 11) as f64,
                (i / 10) as f64 * 10.0 / 9.0,
            ]
        })
        .collect();
    let q = Quantizer::from_points(&pts, 10).unwrap();
    assert!((q.step - 10.0 / 1023.0).abs() < 1e-12);
    assert_eq!(q.axis_bits()[2], 10);
    assert_eq!(q.axis_bits()[0], 10); // 9 m -> 921 steps
    assert_eq!(q.axis_bits()[1], 4); // 0.1 m -> 10 steps
    for p in &pts {
        let g = q.quantize(*p);
        let back = q.dequantize(g);
        for a in 0..3 {
            assert!((back[a] - p[a]).abs() <= q.step / 2.0 + 1e-9);
        }
    }
    // Outside the box: clamped onto the grid.
    assert_eq!(q.quantize([-5.0, 100.0, 5.0])[0], 0);
    assert_eq!(q.quantize([-5.0, 100.0, 5.0])[1], 15);
    // All photons at one point.
    let one = Quantizer::from_points(&[[1.0, 2.0, 3.0]; 4], 10).unwrap();
    assert_eq!(one.axis_bits(), [1, 1, 1]);
    assert_eq!(one.quantize([1.0, 2.0, 3.0]), [0, 0, 0]);
    assert!(Quantizer::from_points(&[], 10).is_err());
    assert!(Quantizer::from_points(&pts, 0).is_err());
    assert!(Quantizer::from_points(&pts, 17).is_err());
}

#[test]
fn radius_bound_is_the_largest_distance_within_r() {
    let mut r = rng(15);
    for _ in 0..2000 {
        let step = r.gen_range(0.001..2.0);
        let radius = r.gen_range(0.0..100.0);
        for metric in METRICS {
            let max = 3 * 1023 * 1023;
            let b = metric.radius_bound(radius, step, max);
            // Independent: d is inside iff its world distance <= radius.
            let inside = |d: u64| metric.to_world(d, step) <= radius;
            assert!(b == max || !inside(b + 1), "b={b} not maximal");
            assert!(inside(b) || b == 0, "b={b} outside");
        }
    }
}

#[test]
fn float_search_on_float_points_matches_brute_force() {
    let mut r = rng(16);
    let pts: Vec<[f64; 3]> = (0..3000)
        .map(|_| {
            [
                r.gen_range(-1.0..1.0),
                r.gen_range(-1.0..1.0),
                r.gen_range(0.0..0.01),
            ]
        })
        .collect();
    let tree = KdTree::build(&pts);
    for _ in 0..200 {
        let q = [
            r.gen_range(-1.2..1.2),
            r.gen_range(-1.2..1.2),
            r.gen_range(-0.1..0.1),
        ];
        for metric in METRICS {
            for k in [1, 10, 100] {
                let truth = brute_force(&pts, q, k, f64::MAX_DIST, metric);
                let td: Vec<_> = truth.iter().map(|t| t.1).collect();
                assert_eq!(
                    search(&tree, q, k, f64::MAX_DIST, metric).sorted_dists(),
                    td
                );
            }
        }
    }
}

/// A query whose every far subtree is pruned reads exactly its descent path: the
/// photons lie on even grid points and the query on odd ones, so with R0 = 0 no axis
/// distance is within R and nothing is in range. The path is walked here
/// independently of the search (near child while one exists).
#[test]
fn pruned_ascent_reads_only_the_descent_path() {
    for (n, seed) in [
        (1usize, 1u64),
        (2, 2),
        (3, 3),
        (1000, 4),
        (4095, 5),
        (4096, 6),
    ] {
        let points: Vec<[u32; 3]> = random_points(n, 511, seed)
            .into_iter()
            .map(|p| p.map(|c| 2 * c))
            .collect();
        let tree = KdTree::build(&points);
        let packed = PackedTree::from_tree(&tree, layout_for(&points));
        let mut r = rng(seed + 100);
        for metric in METRICS {
            for _ in 0..50 {
                let q = [0; 3].map(|_: u32| 2 * r.gen_range(0..=512u32) + 1);
                let mut depth = 0u32;
                let mut addr = 1usize;
                loop {
                    depth += 1;
                    let (p, ax) = packed.node(addr);
                    let near = 2 * addr + (q[ax as usize] >= p[ax as usize]) as usize;
                    if near > n {
                        break;
                    }
                    addr = near;
                }
                let f = search(&packed, q, 1, 0, metric);
                assert!(f.slots.is_empty());
                assert_eq!(f.visited, depth, "n={n} q={q:?}");
                let paper = search_with(&packed, q, 1, 0, metric, Traversal::Reread);
                assert_eq!(paper.visited, 2 * depth - 1, "n={n} q={q:?}");
            }
        }
    }
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig::with_cases(256))]
    /// Any small map, query, k, radius and metric: `check` (both ascents and the
    /// float search against brute force, slot consistency, counts). proptest shrinks
    /// a failure to a minimal map.
    #[test]
    fn any_small_map_matches_brute_force(
        points in proptest::collection::vec([0u32..64, 0u32..64, 0u32..64], 1..80),
        q in [0u32..64, 0u32..64, 0u32..64],
        k in 1usize..12,
        r0 in proptest::prop_oneof![proptest::strategy::Just(u64::MAX), 0u64..3000],
        l1 in proptest::bool::ANY,
    ) {
        let metric = if l1 { Metric::L1 } else { Metric::L2 };
        check(&points, q, k, r0, metric);
    }
}
