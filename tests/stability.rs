//! Numerical stability of the radiance estimate on hard cases.
//! The same scene at scales 1e-6 and 1e6 is `cli::limits::scenes_at_any_scale`
//! (the CLI renders the same image); the kNN hard cases (one point, a plane, a
//! line, split-plane ties) are in `knn`. Here: what the renderer makes of them —
//! the L1 area on tilted surfaces against geometry, photons on one plane or line,
//! all k photons at one point, photons exactly on grid cell boundaries.

use glam::{DVec3, Vec3};
use photon_fpga::host::gather::{FloatBackend, GatherBackend, GatherParams, SwBackend};
use photon_fpga::host::map::knn;
use photon_fpga::host::map::quantize::{Point, Quantizer};
use photon_fpga::host::render::l1_area::l1_section_area;
use photon_fpga::host::render::photons::Photon;
use photon_fpga::host::render::{photon_points, query_points, radiance, QueryPoint};
use photon_fpga::hw::config::metric::Metric;

/// Area of {p in the plane through 0 with normal n : |p|_1 <= 1} by counting the
/// cells of a fine grid over the plane (independent of the polygon construction).
fn section_area_by_counting(n: DVec3, cells: usize) -> f64 {
    let n = n.normalize();
    let u = n.any_orthonormal_vector();
    let v = n.cross(u);
    let h = 2.0 / cells as f64;
    let mut inside = 0usize;
    for i in 0..cells {
        for j in 0..cells {
            let (a, b) = (-1.0 + (i as f64 + 0.5) * h, -1.0 + (j as f64 + 0.5) * h);
            let p = u * a + v * b;
            inside += (p.x.abs() + p.y.abs() + p.z.abs() <= 1.0) as usize;
        }
    }
    inside as f64 * h * h
}

#[test]
fn l1_section_area_is_the_octahedron_cut_by_the_tangent_plane() {
    for n in [DVec3::X, DVec3::Y, DVec3::Z, -DVec3::Z] {
        assert_eq!(l1_section_area(n), 2.0, "axis-aligned {n}: the diamond 2r²");
    }
    let hexagon = 3.0 * 3f64.sqrt() / 4.0;
    assert!((l1_section_area(DVec3::ONE) - hexagon).abs() < 1e-12);
    for n in [
        DVec3::new(1.0, -1.0, 0.125),
        DVec3::new(0.3, 0.9, -0.2),
        DVec3::new(1.0, 1.0, 0.0),
        DVec3::new(-0.05, 1.0, 0.02),
    ] {
        let want = section_area_by_counting(n, 1500);
        let got = l1_section_area(n);
        assert!(
            (got - want).abs() / want < 0.005,
            "normal {n}: polygon {got}, counted {want}"
        );
    }
}

/// Photons on a square grid of spacing `h` in the plane through `c` with normal
/// `n`, arriving from the `n` side, each of power `phi`.
fn plane_photons(c: Vec3, n: Vec3, h: f32, half: i32, phi: Vec3) -> Vec<Photon> {
    let n = n.normalize();
    let u = n.any_orthonormal_vector();
    let v = n.cross(u);
    let dir = (-n + 0.3 * u).normalize();
    let mut out = vec![];
    for i in -half..=half {
        for j in -half..=half {
            out.push(Photon {
                pos: c + u * (i as f32 * h) + v * (j as f32 * h),
                power: phi,
                dir,
            });
        }
    }
    out
}

fn query(pos: Vec3, normal: Vec3) -> QueryPoint {
    QueryPoint {
        pixel: 0,
        pos,
        normal: normal.normalize(),
        albedo: Vec3::new(0.8, 0.5, 0.2),
        weight: Vec3::ONE,
    }
}

fn backend(kind: &str, photons: &[Photon], params: &GatherParams) -> Box<dyn GatherBackend> {
    let pts = photon_points(photons);
    match kind {
        "float" => Box::new(FloatBackend::new(&pts, params).unwrap()),
        _ => Box::new(SwBackend::new(&pts, params).unwrap()),
    }
}

fn estimate(
    kind: &str,
    photons: &[Photon],
    queries: &[QueryPoint],
    params: &GatherParams,
) -> Vec<Vec3> {
    let b = backend(kind, photons, params);
    let g = b.gather(&query_points(queries)).unwrap();
    radiance(queries, photons, &g, params.k, None, params.metric)
}

#[test]
fn l1_radiance_on_tilted_planes_matches_the_analytic_value() {
    // Uniform irradiance E = Φ/h² on a Lambertian plane: L = albedo · E / π, for
    // every orientation; with the old 2r² area the (1,1,1) plane came out 35% dark.
    let (h, phi) = (0.01f32, Vec3::new(1e-4, 2e-4, 3e-4));
    for n in [
        Vec3::Z,
        Vec3::ONE,
        Vec3::new(1.0, -1.0, 0.125),
        Vec3::new(0.2, 1.0, 0.5),
    ] {
        let c = Vec3::new(0.3, 0.4, 0.5);
        let photons = plane_photons(c, n, h, 60, phi);
        let u = n.normalize().any_orthonormal_vector();
        let queries: Vec<QueryPoint> = [0.0031f32, 0.123, -0.211]
            .iter()
            .map(|&t| query(c + u * t + n.normalize().cross(u) * (0.5 * t), n))
            .collect();
        for kind in ["float", "sw"] {
            let params = GatherParams {
                k: 400,
                bits: 14,
                metric: Metric::L1,
                ..GatherParams::default()
            };
            for (q, l) in queries
                .iter()
                .zip(estimate(kind, &photons, &queries, &params))
            {
                let want = q.albedo * phi / (h * h) / std::f32::consts::PI;
                let rel = ((l - want) / want).abs().max_element();
                assert!(rel < 0.04, "{kind}, normal {n}: {l} vs {want} ({rel})");
            }
        }
    }
}

/// Queries spread over the photons' bounding box.
fn queries_in(photons: &[Photon], n: usize, normal: Vec3) -> Vec<QueryPoint> {
    let (lo, hi) = photons.iter().fold(
        (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)),
        |(l, h), p| (l.min(p.pos), h.max(p.pos)),
    );
    (0..n)
        .map(|i| {
            let t = (i as f32 + 0.37) / n as f32;
            query(lo + (hi - lo) * t, normal)
        })
        .collect()
}

#[test]
fn photons_on_one_plane_or_one_line_give_finite_radiance_equal_to_float_at_16_bits() {
    let phi = Vec3::splat(1e-3);
    let plane = plane_photons(Vec3::new(0.5, 0.2, 0.0), Vec3::Z, 0.004, 100, phi);
    let line: Vec<Photon> = (0..5000)
        .map(|i| Photon {
            pos: Vec3::new(0.1 + i as f32 * 1e-4, 0.7, 0.7),
            power: phi,
            dir: -Vec3::Y,
        })
        .collect();
    for (name, photons) in [("plane", &plane), ("line", &line)] {
        let queries = queries_in(photons, 40, Vec3::Y + Vec3::Z);
        for metric in [Metric::L1, Metric::L2] {
            let params = GatherParams {
                k: 32,
                bits: 16,
                metric,
                ..GatherParams::default()
            };
            let float = estimate("float", photons, &queries, &params);
            let sw = estimate("sw", photons, &queries, &params);
            for (f, s) in float.iter().zip(&sw) {
                assert!(f.is_finite() && s.is_finite(), "{name} {metric}: {f} {s}");
                let rel = ((*s - *f).length()) / f.length().max(1e-30);
                assert!(rel < 0.01, "{name} {metric}: sw {s} vs float {f}");
            }
        }
    }
}

#[test]
fn all_k_photons_at_one_point_give_black_not_nan_or_inf() {
    let p = Vec3::new(0.25, 0.5, 0.75);
    let mut photons: Vec<Photon> = (0..20)
        .map(|_| Photon {
            pos: p,
            power: Vec3::ONE,
            dir: -Vec3::Y,
        })
        .collect();
    // Two more a hair apart (1e-25: r² underflows f32) and one far away.
    for d in [1e-25f32, 2e-25] {
        photons.push(Photon {
            pos: p + Vec3::new(d, 0.0, 0.0),
            ..photons[0]
        });
    }
    photons.push(Photon {
        pos: p + Vec3::ONE,
        ..photons[0]
    });
    let queries = vec![
        query(p, Vec3::Y),
        query(p + Vec3::new(1e-25, 0.0, 0.0), Vec3::Y),
        query(p + Vec3::splat(0.5), Vec3::Y),
    ];
    for metric in [Metric::L1, Metric::L2] {
        for kind in ["float", "sw"] {
            let params = GatherParams {
                k: 10,
                metric,
                ..GatherParams::default()
            };
            let l = estimate(kind, &photons, &queries, &params);
            assert!(l.iter().all(|c| c.is_finite()), "{kind} {metric}: {l:?}");
            assert_eq!(l[0], Vec3::ZERO, "{kind} {metric}: radius 0 is black");
            assert!(
                l[2].max_element() > 0.0,
                "{kind} {metric}: a real region is lit"
            );
        }
    }
}

#[test]
fn photons_exactly_on_grid_cell_boundaries_are_searched_exactly() {
    // Photons halfway between grid points (where rounding could go either way),
    // the box pinned by photons at 0 and 1: the quantized search must equal brute
    // force on the very grid coordinates the quantizer gives, and its radiance must
    // stay finite and close to float.
    let bits = 6;
    let step = 1.0 / ((1u32 << bits) - 1) as f32;
    let mut photons = vec![];
    for i in 0..40 {
        for j in 0..40 {
            let pos = Vec3::new(
                (i as f32 + 0.5) * step * 0.8,
                (j as f32 + 0.5) * step * 0.8,
                0.5,
            );
            photons.push(Photon {
                pos,
                power: Vec3::splat(1e-3),
                dir: -Vec3::Z,
            });
        }
    }
    for corner in [Vec3::ZERO, Vec3::ONE] {
        photons.push(Photon {
            pos: corner,
            ..photons[0]
        });
    }
    let pts: Vec<Point> = photon_points(&photons);
    let quant = Quantizer::from_points(&pts, bits).unwrap();
    let grid: Vec<[u32; 3]> = pts.iter().map(|&p| quant.quantize(p)).collect();
    let queries = queries_in(&photons[..1600], 25, Vec3::Z);
    for metric in [Metric::L1, Metric::L2] {
        let params = GatherParams {
            k: 16,
            bits,
            metric,
            ..GatherParams::default()
        };
        let sw = backend("sw", &photons, &params);
        let got = sw.gather(&query_points(&queries)).unwrap();
        for (q, g) in queries.iter().zip(&got) {
            let c = quant.quantize(q.pos.as_dvec3().to_array());
            let truth = knn::brute_force(&grid, c, params.k, u64::MAX, metric);
            let want: Vec<f64> = truth
                .iter()
                .map(|t| metric.to_world(t.1, quant.step))
                .collect();
            let have: Vec<f64> = g.neighbours.iter().map(|n| n.distance).collect();
            assert_eq!(have, want, "{metric}: query {c:?}");
        }
        let l = radiance(&queries, &photons, &got, params.k, None, metric);
        assert!(
            l.iter().all(|c| c.is_finite() && c.max_element() > 0.0),
            "{metric}: {l:?}"
        );
    }
}
