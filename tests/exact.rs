//! `--exact`: the quantized backends' certified re-ranking gives exactly the float
//! backend's answers (same photons, same distance bits, same order) on every hard
//! case and on random maps, for both metrics; the bound δ is never beaten by a real
//! photon–query pair and a δ taken too small is caught (mutation).

use photon_fpga::host::exact::bound::Bound;
use photon_fpga::host::exact::ExactBackend;
use photon_fpga::host::gather::{BackendKind, FloatBackend, GatherBackend, GatherParams, Gathered};
use photon_fpga::host::map::knn::Scalar;
use photon_fpga::host::map::quantize::{GridPoint, Point, Quantizer};
use photon_fpga::hw::config::metric::Metric;
use photon_fpga::hw::sim::native::SimOptions;
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;

const METRICS: [Metric; 2] = [Metric::L2, Metric::L1];

fn rng(seed: u64) -> Pcg64Mcg {
    Pcg64Mcg::seed_from_u64(seed)
}

fn params(k: usize, radius: Option<f64>, bits: u32, metric: Metric) -> GatherParams {
    GatherParams {
        k,
        radius,
        bits,
        metric,
        ..GatherParams::default()
    }
}

/// The neighbours as comparable bits: (photon, distance bits) per query.
pub(crate) fn bits_of(g: &[Gathered]) -> Vec<Vec<(u32, u64)>> {
    g.iter()
        .map(|g| {
            g.neighbours
                .iter()
                .map(|n| (n.photon, n.distance.to_bits()))
                .collect()
        })
        .collect()
}

/// The exact backend (over `kind`) and the float backend on the same photons and
/// queries: equal answers, bit for bit. Returns the exact run's certified count.
fn same_as_float(
    kind: BackendKind,
    photons: &[Point],
    queries: &[Point],
    p: &GatherParams,
    refine: Option<usize>,
) -> u64 {
    let float = FloatBackend::new(photons, p)
        .unwrap()
        .gather(queries)
        .unwrap();
    let exact = ExactBackend::new(kind, photons, p, refine, &SimOptions::default()).unwrap();
    let got = exact.gather(queries).unwrap();
    assert_eq!(
        bits_of(&got),
        bits_of(&float),
        "{kind} --exact differs from float: k {} radius {:?} bits {} {} m {refine:?}",
        p.k,
        p.radius,
        p.bits,
        p.metric
    );
    let s = exact.stats();
    assert_eq!(s.queries, queries.len() as u64);
    assert_eq!(s.certified + s.uncertified + s.ties + s.outside, s.queries);
    s.certified
}

/// Every k, radius and metric of a case through the sw core (auto m and a given
/// m); returns the certified count over all of them.
fn check_case(photons: &[Point], queries: &[Point], bits: u32, radii: &[Option<f64>]) -> u64 {
    let mut certified = 0;
    for metric in METRICS {
        for k in [1, 4, 10] {
            for &r in radii {
                let p = params(k, r, bits, metric);
                for refine in [None, Some(0), Some(3)] {
                    certified += same_as_float(BackendKind::Sw, photons, queries, &p, refine);
                }
            }
        }
    }
    certified
}

fn uniform(r: &mut Pcg64Mcg, n: usize, lo: f64, hi: f64) -> Vec<Point> {
    (0..n)
        .map(|_| [0; 3].map(|_: i32| r.gen_range(lo..hi)))
        .collect()
}

#[test]
fn exact_random_maps_equal_float() {
    for (seed, n, bits) in [(1, 400, 10), (2, 1000, 6), (3, 300, 3), (4, 2000, 8)] {
        let mut r = rng(seed);
        let photons = uniform(&mut r, n, -3.0, 7.0);
        let queries = uniform(&mut r, 60, -3.0, 7.0);
        let certified = check_case(&photons, &queries, bits, &[None, Some(0.8), Some(3.0)]);
        // The certificate does the work: most answers come from the core.
        assert!(certified > 0, "seed {seed}: nothing certified");
    }
}

#[test]
fn exact_default_m_certifies_most_queries_on_a_dense_map() {
    let mut r = rng(9);
    let photons = uniform(&mut r, 5000, 0.0, 1.0);
    let queries = uniform(&mut r, 400, 0.0, 1.0);
    for metric in METRICS {
        let p = params(10, None, 10, metric);
        let certified = same_as_float(BackendKind::Sw, &photons, &queries, &p, None);
        assert!(certified * 100 >= 95 * 400, "{metric}: {certified} of 400");
    }
}

#[test]
fn exact_clusters_planes_and_lines() {
    let mut r = rng(5);
    // All photons at one point (and queries at it and around it).
    let one = vec![[1.5, -2.0, 0.25]; 50];
    let mut qs = uniform(&mut r, 10, 1.0, 2.0);
    qs.push([1.5, -2.0, 0.25]);
    check_case(&one, &qs, 10, &[None, Some(0.0), Some(0.3)]);
    // A dense cluster at one point beside a sparse spread.
    let mut cl = uniform(&mut r, 100, 0.0, 10.0);
    cl.extend(vec![[4.0, 4.0, 4.0]; 80]);
    let mut qs = uniform(&mut r, 30, 0.0, 10.0);
    qs.push([4.0, 4.0, 4.0]);
    check_case(&cl, &qs, 8, &[None, Some(0.0), Some(1.0)]);
    // A plane and a line (queries on and off them).
    let plane: Vec<Point> = uniform(&mut r, 400, 0.0, 5.0)
        .into_iter()
        .map(|p| [p[0], 2.0, p[2]])
        .collect();
    let qs: Vec<Point> = uniform(&mut r, 40, 0.0, 5.0)
        .into_iter()
        .enumerate()
        .map(|(i, q)| [q[0], if i % 2 == 0 { 2.0 } else { q[1] }, q[2]])
        .collect();
    check_case(&plane, &qs, 9, &[None, Some(0.5)]);
    let line: Vec<Point> = (0..300)
        .map(|_| [r.gen_range(0.0..9.0), 1.0, -1.0])
        .collect();
    let qs: Vec<Point> = (0..40)
        .map(|i| [r.gen_range(0.0..9.0), 1.0 + (i % 3) as f64 * 0.01, -1.0])
        .collect();
    check_case(&line, &qs, 10, &[None, Some(0.2)]);
}

#[test]
fn exact_grid_and_cell_boundary_ties() {
    // Integer lattice photons with a grid step of exactly 1 (0..=7 at 3 bits), and
    // queries on lattice points, half-integers (cell boundaries, where the query's
    // rounding flips) and cell centres: ties at every rank.
    let mut photons = vec![];
    for x in 0..8 {
        for y in 0..8 {
            for z in 0..4 {
                photons.push([x as f64, y as f64, z as f64]);
            }
        }
    }
    let mut qs = vec![];
    for &(x, y, z) in &[
        (3.0, 3.0, 1.0),
        (3.5, 3.0, 1.0),
        (3.5, 3.5, 1.5),
        (0.5, 0.5, 0.5),
        (7.0, 7.0, 3.0),
        (2.25, 4.75, 2.5),
    ] {
        qs.push([x, y, z]);
    }
    check_case(&photons, &qs, 3, &[None, Some(0.0), Some(1.0), Some(1.5)]);
    // The same lattice on a finer grid: the lattice falls between grid points.
    check_case(&photons, &qs, 5, &[None, Some(1.0)]);
}

#[test]
fn exact_far_queries_tiny_and_huge_scales_and_k_beyond_the_photons() {
    let mut r = rng(11);
    let photons = uniform(&mut r, 200, 0.0, 1.0);
    // Far outside the photon box (the float search answers them) and just outside.
    let mut qs = uniform(&mut r, 10, 0.0, 1.0);
    qs.extend([
        [1e6, 0.5, 0.5],
        [-1.0, -1.0, 2.0],
        [1.0000001, 0.5, 0.5],
        [0.5, 0.5, 1e15],
        [0.5, 1e140, 0.5],
    ]);
    check_case(&photons, &qs, 10, &[None, Some(0.1)]);
    for scale in [1e-100, 1e-300, 1e140] {
        let ph: Vec<Point> = photons.iter().map(|p| p.map(|c| c * scale)).collect();
        let q: Vec<Point> = qs.iter().take(12).map(|p| p.map(|c| c * scale)).collect();
        check_case(&ph, &q, 10, &[None, Some(0.2 * scale)]);
    }
    // k beyond the photon count, with and without a radius.
    let few = uniform(&mut r, 7, 0.0, 1.0);
    for metric in METRICS {
        for r0 in [None, Some(0.0), Some(0.5)] {
            let p = params(12, r0, 10, metric);
            let mut q = few.clone();
            q.extend(&qs[..10]);
            let c = same_as_float(BackendKind::Sw, &few, &q, &p, None);
            // Fewer than k' found: every photon within the radius was returned, so
            // every query inside the photon box (at least the photons' own) is
            // certified.
            assert!(c >= 7, "{metric} {r0:?}: {c} certified");
        }
    }
}

/// The bound against every kind of photon–query pair, placed adversarially: each
/// coordinate just inside a rounding boundary, so the grid error approaches its
/// worst case. `scale` multiplies δ's photon part (1 = the derived bound).
/// Returns how many pairs the bound claimed farther than they are.
fn bound_violations(metric: Metric, scale: f64, seed: u64) -> usize {
    let mut r = rng(seed);
    // A grid of step 1: photons spanning 0..=1023 on x at 10 bits.
    let quant = Quantizer::from_points(&[[0.0, 0.0, 0.0], [1023.0, 1023.0, 1023.0]], 10).unwrap();
    let mut b = Bound::new(metric, &quant);
    b.delta *= scale;
    // A coordinate just inside a rounding boundary of grid point `c`.
    let near_half = |r: &mut Pcg64Mcg, c: f64| {
        let e = 0.5 - r.gen_range(0.0..1e-6);
        if r.gen_bool(0.5) {
            c + e
        } else {
            c - e
        }
    };
    let mut bad = 0;
    for i in 0..20_000 {
        let gp0 = [0; 3].map(|_: i32| r.gen_range(100..900) as f64);
        let p: Point = gp0.map(|c| near_half(&mut r, c));
        // Half the pairs along a diagonal, where the triangle inequality is tight.
        let n = r.gen_range(1..60) as f64;
        let mut q: Point = [0.0; 3];
        for a in 0..3 {
            let c = if i % 2 == 0 {
                gp0[a] + if r.gen_bool(0.5) { n } else { -n }
            } else {
                r.gen_range(1..1000) as f64
            };
            q[a] = near_half(&mut r, c);
        }
        let (gp, gq) = (quant.quantize(p), quant.quantize(q));
        let GridPoint::Inside(c) = quant.grid(q).unwrap() else {
            panic!("query inside the box")
        };
        assert_eq!(c, gq);
        let g = metric.dist(gp, gq);
        let d = f64::dist(metric, q, p);
        // The photon's own distance is never proved exceeded.
        if b.exceeds(g, b.query_delta(q, c), d) {
            bad += 1;
        }
        // The radius conversion keeps the photon at radius d.
        if scale == 1.0 {
            assert!(b.grid_radius(d, u64::MAX) >= g, "{metric} {p:?} {q:?}");
        }
    }
    bad
}

#[test]
fn exact_bound_holds_and_a_smaller_delta_breaks_it() {
    for metric in METRICS {
        assert_eq!(bound_violations(metric, 1.0, 21), 0, "{metric}");
        // Mutation: δ's photon part 5 % too small is beaten by real pairs.
        assert!(
            bound_violations(metric, 0.95, 21) > 0,
            "{metric}: mutation survived"
        );
    }
}

/// Mutation through the backend: with δ's photon part zero the certificate passes
/// queries whose answer is wrong, and the comparison with the float search catches
/// it (the correct δ on the same maps gives the float answers, as tested above).
#[test]
fn exact_with_delta_too_small_gives_wrong_answers() {
    for metric in METRICS {
        let mut caught = false;
        for seed in 0..20 {
            let mut r = rng(100 + seed);
            let photons = uniform(&mut r, 300, 0.0, 1.0);
            let queries = uniform(&mut r, 100, 0.0, 1.0);
            let p = params(4, None, 4, metric);
            let float = FloatBackend::new(&photons, &p)
                .unwrap()
                .gather(&queries)
                .unwrap();
            let mut exact = ExactBackend::new(
                BackendKind::Sw,
                &photons,
                &p,
                Some(0),
                &SimOptions::default(),
            )
            .unwrap();
            let right = exact.gather(&queries).unwrap();
            assert_eq!(bits_of(&right), bits_of(&float));
            exact.bound.delta = 0.0;
            if bits_of(&exact.gather(&queries).unwrap()) != bits_of(&float) {
                caught = true;
                break;
            }
        }
        assert!(caught, "{metric}: δ = 0 never gave a wrong answer");
    }
}

#[test]
fn exact_rtl_equals_float_on_small_maps() {
    let mut r = rng(31);
    let mut photons = uniform(&mut r, 150, 0.0, 2.0);
    photons.extend(vec![[1.0, 1.0, 1.0]; 20]);
    let mut queries = uniform(&mut r, 25, 0.0, 2.0);
    queries.extend([[1.0, 1.0, 1.0], [5.0, 1.0, 1.0]]);
    for metric in METRICS {
        for (k, radius) in [(5, None), (3, Some(0.3)), (8, Some(0.0))] {
            let p = params(k, radius, 10, metric);
            same_as_float(BackendKind::Native, &photons, &queries, &p, None);
        }
        // k beyond the photons: the core's list holds them all.
        let p = params(40, None, 10, metric);
        let few = &photons[..30];
        same_as_float(BackendKind::Native, few, &queries, &p, Some(0));
    }
}

/// One thread or three: the same answers and the same run summary (m, certified
/// count, reads), on the software model and on the simulated core.
#[test]
fn exact_is_the_same_whatever_the_thread_count() {
    let mut r = rng(51);
    let photons = uniform(&mut r, 600, 0.0, 1.0);
    let queries = uniform(&mut r, 80, -0.1, 1.1);
    for kind in [BackendKind::Sw, BackendKind::Native] {
        let p = params(6, Some(0.2), 9, Metric::L2);
        let run = |threads| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            pool.install(|| {
                let e =
                    ExactBackend::new(kind, &photons, &p, None, &SimOptions::default()).unwrap();
                let g = e.gather(&queries).unwrap();
                (bits_of(&g), e.stats().summary())
            })
        };
        assert_eq!(run(1), run(3), "{kind}");
    }
}
