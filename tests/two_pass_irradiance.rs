//! The two-pass render with Christensen's precomputed irradiance
//! (`render --method two-pass-irradiance`): the irradiance estimates against a
//! brute-force density estimate, the gather's 1-nearest lookups against brute force
//! through every backend, the CLI's byte-identity across backends and thread
//! counts, and its image against an independent path tracer.

use crate::exact::bits_of;
use crate::two_pass::{
    bin, brute_world, capped_params, check_against_brute_force, direct_error_at, lookup_workload,
    reference, reflected, rel_rmse, total_light, trace,
};
use glam::Vec3;
use photon_fpga::host::exact::ExactBackend;
use photon_fpga::host::gather::{
    make_backend, BackendKind, FloatBackend, GatherBackend, GatherParams, Gathered, SwBackend,
};
use photon_fpga::host::map::quantize::Point;
use photon_fpga::host::render::final_gather::gather_hit;
use photon_fpga::host::render::irradiance::{
    irradiance_params, irradiance_radiance, precompute_irradiance, IRRADIANCE_STRIDE,
};
use photon_fpga::host::render::scene::{cosine_direction, Scene};
use photon_fpga::host::render::two_pass::{default_radius, render_method};
use photon_fpga::host::render::{
    eye_queries, photon_points, QueryPoint, RenderMethod, RenderSettings,
};
use photon_fpga::host::stages::StageTimes;
use photon_fpga::hw::sim::native::SimOptions;
use rand::{Rng, SeedableRng};

/// The irradiance points of the lookup workload's global map (every
/// IRRADIANCE_STRIDE-th photon position), with the workload's queries.
fn irradiance_workload() -> (Vec<Point>, Vec<Point>) {
    let (global, _, queries) = lookup_workload();
    let points = global.iter().step_by(IRRADIANCE_STRIDE).copied().collect();
    (points, queries)
}

/// Each precomputed estimate is Jensen's density estimate at its photon, computed
/// here by brute force: the k nearest photons within the cap, those arriving from
/// the front of the surface summed, over the disc of the farthest one's radius (the
/// cap's when fewer than k lie inside), divided by π for radiance. Photons on the
/// floor get the floor's normal.
#[test]
fn precomputed_irradiance_is_the_brute_force_density_estimate() {
    let scene = Scene::cornell_box();
    let (photons, _) = trace(&scene, 6_000, 4);
    let world = photon_points(&photons);
    let params = capped_params();
    let global = FloatBackend::new(&world, &params).unwrap();
    let mut t = StageTimes::default();
    let (map, _) = precompute_irradiance(&scene, &photons, &global, &params, &mut t).unwrap();
    let cap = params.radius.unwrap();
    assert_eq!(map.points.len(), photons.len().div_ceil(IRRADIANCE_STRIDE));
    let (mut lit, mut on_floor, mut capped) = (0, 0, 0);
    for (i, p) in photons.iter().step_by(IRRADIANCE_STRIDE).enumerate() {
        assert_eq!(map.points[i], world[i * IRRADIANCE_STRIDE]);
        let n = map.normals[i];
        assert!(n.dot(p.dir) < 0.0, "normal {n} faces away from {}", p.dir);
        if p.pos.y.abs() < 1e-5 && p.pos.x > 0.01 && p.pos.z > 0.01 {
            assert!(
                (n - Vec3::Y).length() < 1e-6,
                "floor photon at {}: {n}",
                p.pos
            );
            on_floor += 1;
        }
        let near = brute_world(&world, world[i * IRRADIANCE_STRIDE], params.k, cap);
        let r = match near.len() == params.k {
            true => near.last().unwrap().0,
            false => {
                capped += 1;
                cap
            }
        };
        let flux: [f64; 3] = [0, 1, 2].map(|c| {
            near.iter()
                .map(|&(_, j)| &photons[j as usize])
                .filter(|q| q.dir.dot(n) < 0.0)
                .map(|q| q.power[c] as f64)
                .sum()
        });
        let pi = std::f64::consts::PI;
        for (c, f) in flux.iter().enumerate() {
            let want = f / (pi * r * r) / pi;
            let got = map.radiosity[i][c] as f64;
            assert!(
                (got - want).abs() <= 1e-4 * want.max(1e-6),
                "point {i} channel {c}: {got} vs {want}"
            );
        }
        lit += (map.radiosity[i].max_element() > 0.0) as usize;
    }
    assert!(on_floor > 50, "{on_floor} floor photons");
    assert!(
        capped > 0,
        "no estimate reached the cap: the test shows nothing"
    );
    assert!(lit * 10 > map.points.len() * 9, "{lit} lit");
}

/// The final gather's lookups in the irradiance points (radius-capped, 1 nearest)
/// through every backend: float and `--exact` equal the float brute force, sw the
/// grid's, rtl sw's bit for bit; some find no point inside the cap.
#[test]
fn irradiance_lookups_match_brute_force_through_every_backend() {
    let (points, queries) = irradiance_workload();
    let params = GatherParams {
        radius: Some(0.025),
        ..irradiance_params(&capped_params())
    };
    assert_eq!(params.k, 1);
    let sim = SimOptions::default();
    let float = FloatBackend::new(&points, &params).unwrap();
    let want = float.gather(&queries).unwrap();
    let empty = check_against_brute_force("irradiance", &points, &queries, &want, &params, None);
    assert!(empty > 0 && empty < queries.len() / 2, "{empty} empty");
    let exact = ExactBackend::new(BackendKind::Sw, &points, &params, None, &sim).unwrap();
    let neighbours =
        |g: &[Gathered]| -> Vec<_> { g.iter().map(|g| g.neighbours.clone()).collect() };
    assert_eq!(
        neighbours(&exact.gather(&queries).unwrap()),
        neighbours(&want),
        "exact sw"
    );
    let sw = SwBackend::new(&points, &params).unwrap();
    let quant = sw.map.quant.clone();
    let sw_got = sw.gather(&queries).unwrap();
    check_against_brute_force(
        "irradiance sw",
        &points,
        &queries,
        &sw_got,
        &params,
        Some(&quant),
    );
    let rtl = make_backend(BackendKind::Native, &points, &params, &sim).unwrap();
    assert_eq!(
        bits_of(&rtl.gather(&queries).unwrap()),
        bits_of(&sw_got),
        "rtl"
    );
}

/// The same lookups through the exported Verilog (a K = 1 core) under Verilator.
#[test]
#[cfg_attr(not(has_verilator), ignore = "needs verilator")]
fn irradiance_lookups_through_verilator_equal_sw() {
    let (points, queries) = irradiance_workload();
    let params = irradiance_params(&capped_params());
    let sw = SwBackend::new(&points, &params)
        .unwrap()
        .gather(&queries)
        .unwrap();
    let v = make_backend(
        BackendKind::Verilator,
        &points,
        &params,
        &SimOptions::default(),
    )
    .unwrap()
    .gather(&queries)
    .unwrap();
    assert_eq!(bits_of(&v), bits_of(&sw));
}

/// A gather ray's radiance at its hit is the hit's albedo times the E / π of the
/// nearest irradiance point (found here by brute force), 0 when none lies inside
/// the cap or the nearest faces away from the hit.
#[test]
fn gather_hits_read_their_nearest_irradiance_point() {
    let scene = Scene::cornell_box();
    let (photons, _) = trace(&scene, 6_000, 4);
    let params = capped_params();
    let global = FloatBackend::new(&photon_points(&photons), &params).unwrap();
    let mut t = StageTimes::default();
    let (map, _) = precompute_irradiance(&scene, &photons, &global, &params, &mut t).unwrap();
    let settings = RenderSettings {
        width: 12,
        height: 10,
        spp: 1,
        ..RenderSettings::default()
    };
    let (eye, _) = eye_queries(&scene, &settings);
    let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(11);
    let mut hits = Vec::new();
    for x in &eye {
        for _ in 0..4 {
            let dir = cosine_direction(x.normal, rng.gen(), rng.gen());
            if let Some(h) = gather_hit(&scene, x, dir, &mut rng) {
                hits.push(QueryPoint {
                    pixel: 0,
                    pos: h.pos,
                    normal: h.normal,
                    albedo: h.albedo,
                    weight: Vec3::ONE,
                });
            }
        }
    }
    let cap = 0.02;
    let lookup = GatherParams {
        radius: Some(cap),
        ..irradiance_params(&params)
    };
    let backend = FloatBackend::new(&map.points, &lookup).unwrap();
    let positions: Vec<Point> = hits.iter().map(|h| h.pos.as_dvec3().to_array()).collect();
    let got = irradiance_radiance(&hits, &map, &backend.gather(&positions).unwrap());
    let mut zero = 0;
    for (i, h) in hits.iter().enumerate() {
        let want = match brute_world(&map.points, positions[i], 1, cap).first() {
            Some(&(_, j)) if map.normals[j as usize].dot(h.normal) >= 0.0 => {
                h.albedo * map.radiosity[j as usize]
            }
            _ => Vec3::ZERO,
        };
        zero += (want == Vec3::ZERO) as usize;
        assert_eq!(got[i], want, "hit {i} at {}", h.pos);
    }
    assert!(zero < hits.len() / 2, "{zero} of {} hits dark", hits.len());
}

/// Against an independent path tracer, at matched photon lookups (the direct
/// method gets at least as many eye samples as the irradiance render makes
/// lookups, precomputation included), the irradiance render is closer than the
/// direct visualization on a sparse map, and its total light is the reference's:
/// the nearest point's irradiance stands for the hit's without losing or doubling
/// light.
#[test]
fn two_pass_irradiance_beats_direct_at_matched_lookups_against_a_path_tracer() {
    let scene = Scene::cornell_box();
    let (w, h) = (32, 32);
    let reference = reference::path_trace(&scene, w, h, 4096, 77, usize::MAX);
    let (photons, caustic) = trace(&scene, 20_000, 2);
    let params = GatherParams {
        k: 32,
        radius: Some(default_radius(&photons)),
        ..GatherParams::default()
    };
    let global = FloatBackend::new(&photon_points(&photons), &params).unwrap();
    let settings = RenderSettings {
        width: w,
        height: h,
        spp: 16,
        seed: 2,
        method: RenderMethod::TwoPassIrradiance,
        gather_rays: 16,
        ..RenderSettings::default()
    };
    let build = |p: &[Point], prm: &GatherParams| -> photon_fpga::host::error::Result<_> {
        Ok(Box::new(FloatBackend::new(p, prm)?) as Box<dyn GatherBackend>)
    };
    let mut t = StageTimes::default();
    let (pass, stats) = render_method(
        &scene, &settings, &photons, &caustic, &global, &build, &params, &mut t,
    )
    .unwrap();
    let stats = stats.unwrap();
    assert_eq!(
        stats.irradiance_points as usize,
        photons.len().div_ceil(IRRADIANCE_STRIDE)
    );
    let lookups = stats.caustic_lookups + stats.gather_lookups + stats.irradiance_points;
    assert_eq!(pass.queries as u64, lookups);
    let (e_direct, spp) = direct_error_at(&scene, &photons, (w, h), lookups, &reference);
    let img = reflected(&scene, &settings, &pass.linear);
    let e_irr = rel_rmse(&img, &reference);
    let (a, b) = (total_light(&img), total_light(&reference));
    assert!(
        (a - b).abs() < 0.03 * b,
        "irradiance total {a} vs reference {b}"
    );
    assert!(
        e_irr < 0.85 * e_direct,
        "irradiance {e_irr:.4} vs direct {e_direct:.4} at {lookups} lookups (direct spp {spp})"
    );
}

/// PNG bytes and stdout of `render --method METHOD ARGS` on a small image.
fn png(method: &str, args: &[&str]) -> (Vec<u8>, String) {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("r.png");
    let run = bin()
        .args(["render", "--method", method, "--size", "10x8", "--spp", "1"])
        .args(["--photons", "3000", "--k", "8", "--gather-rays", "4"])
        .args(["--out", out.to_str().unwrap()])
        .args(args)
        .assert()
        .success();
    let stdout = String::from_utf8_lossy(&run.get_output().stdout).to_string();
    (std::fs::read(&out).unwrap(), stdout)
}

const IRR: &str = "two-pass-irradiance";

#[test]
fn irradiance_render_rtl_equals_sw_and_exact_equals_float_for_any_threads() {
    let (sw, out) = png(IRR, &["--backend", "sw"]);
    assert!(out.contains("points precomputed"), "{out}");
    let (rtl, _) = png(IRR, &["--backend", "rtl"]);
    assert!(rtl == sw, "rtl and sw renders differ");
    let (float, _) = png(IRR, &["--backend", "float"]);
    let (exact, out) = png(IRR, &["--backend", "sw", "--exact"]);
    assert!(exact == float, "--exact and float renders differ: {out}");
    assert!(sw != float, "the 10-bit grid changed no pixel");
    let (one, _) = png(IRR, &["--threads", "1"]);
    let (two, _) = png(IRR, &["--threads", "2"]);
    assert!(one == two, "1 and 2 threads differ");
    let (lookup, _) = png("two-pass", &[]);
    assert!(lookup != one, "the irradiance gather changed no pixel");
}

/// Through the exported Verilog under Verilator: `sw`'s image, and with `--exact`
/// `float`'s.
#[test]
#[cfg_attr(not(has_verilator), ignore = "needs verilator")]
fn irradiance_render_verilator_is_byte_identical_to_sw_and_exact_to_float() {
    let (sw, _) = png(IRR, &["--backend", "sw"]);
    let (v, _) = png(IRR, &["--backend", "verilator"]);
    assert!(v == sw, "verilator and sw renders differ");
    let (float, _) = png(IRR, &["--backend", "float"]);
    let (exact, out) = png(IRR, &["--backend", "verilator", "--exact"]);
    assert!(exact == float, "verilator --exact and float differ: {out}");
}
