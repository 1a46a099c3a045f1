//! The two-pass render (`render --method two-pass`): its caustic photons checked
//! against the scene's geometry, its radius-capped lookups (empty ones included)
//! against brute force through every backend, the CLI's byte-identity across
//! backends and thread counts, and its image against an independent path tracer.

use crate::exact::bits_of;
use assert_cmd::Command;
use glam::Vec3;
use photon_fpga::host::exact::ExactBackend;
use photon_fpga::host::gather::{
    make_backend, BackendKind, FloatBackend, GatherBackend, GatherParams, Gathered, SwBackend,
};
use photon_fpga::host::map::quantize::{GridPoint, Point, Quantizer};
use photon_fpga::host::render::caustics::caustic_photons;
use photon_fpga::host::render::final_gather::gather_hit;
use photon_fpga::host::render::photons::{trace_photon_paths, Photon};
use photon_fpga::host::render::scene::{Ray, Scene, Surface};
use photon_fpga::host::render::two_pass::{default_radius, render_two_pass, PhotonMaps};
use photon_fpga::host::render::{eye_queries, photon_points, RenderMethod, RenderSettings};
use photon_fpga::host::stages::StageTimes;
use photon_fpga::hw::config::metric::Metric;
use photon_fpga::hw::sim::native::SimOptions;
use rand::{Rng, SeedableRng};

pub fn bin() -> Command {
    Command::cargo_bin("photon-fpga").unwrap()
}

pub fn trace(scene: &Scene, emitted: usize, seed: u64) -> (Vec<Photon>, Vec<bool>) {
    trace_photon_paths(scene, emitted, seed, false, usize::MAX).unwrap()
}

/// The Cornell box with black walls: every photon is stored at its first diffuse
/// hit and absorbed, so its last flight came straight from the light or from a
/// sphere.
fn black_cornell() -> Scene {
    let text = include_str!("../scenes/cornell.toml")
        .replace("rgb = [0.75, 0.75, 0.75]", "rgb = [0.0, 0.0, 0.0]")
        .replace("rgb = [0.75, 0.2, 0.2]", "rgb = [0.0, 0.0, 0.0]")
        .replace("rgb = [0.2, 0.7, 0.2]", "rgb = [0.0, 0.0, 0.0]");
    Scene::from_toml_str(&text, "black.toml").unwrap()
}

/// A photon is caustic iff it came from a mirror or glass surface: looking back
/// along its arrival direction from where it was stored, the first thing seen is
/// a sphere for caustic photons and the light for the others (black walls: no
/// photon bounces diffusely).
#[test]
fn caustic_photons_are_those_seen_coming_from_a_specular_surface() {
    let scene = black_cornell();
    let (photons, caustic) = trace(&scene, 30_000, 5);
    assert_eq!(photons.len(), caustic.len());
    let n_caustic = caustic.iter().filter(|&&c| c).count();
    assert!(n_caustic > 300, "{n_caustic} caustic photons");
    assert!(n_caustic < photons.len() / 2);
    let mut grazing = 0;
    for (p, &c) in photons.iter().zip(&caustic) {
        let back = -p.dir;
        let ray = Ray::spawn(p.pos, back, back, scene.epsilon);
        let seen = scene.intersect(&ray).expect("a photon came from somewhere");
        let from_sphere = match seen.surface {
            Surface::Light => false,
            Surface::Material(m) => !matches!(
                scene.materials[m],
                photon_fpga::host::render::scene::Material::Diffuse { .. }
            ),
        };
        if c != from_sphere {
            // f32 rounding can tip a ray that grazes a sphere's silhouette either way:
            // only such a ray may disagree.
            let grazes = scene.spheres.iter().any(|(s, _)| {
                let to_c = s.center - ray.origin;
                let off_axis = (to_c - ray.dir * to_c.dot(ray.dir)).length();
                (off_axis - s.radius).abs() < scene.epsilon
            });
            assert!(
                grazes,
                "photon at {} (caustic {c}) from {:?}",
                p.pos, seen.surface
            );
            grazing += 1;
        }
    }
    assert!(grazing * 1000 < photons.len(), "{grazing} grazing photons");
    assert_eq!(caustic_photons(&photons, &caustic).len(), n_caustic);
}

/// True k nearest within `r` (inclusive) by brute force on world positions:
/// (distance, index), nearest first, ties by index.
pub fn brute_world(photons: &[Point], q: Point, k: usize, r: f64) -> Vec<(f64, u32)> {
    let mut all: Vec<(f64, u32)> = photons
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let d = [0, 1, 2].map(|a| p[a] - q[a]);
            ((d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt(), i as u32)
        })
        .filter(|&(d, _)| d <= r)
        .collect();
    all.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    all.truncate(k);
    all
}

/// True grid distances (squared, in steps²) of the k nearest within the integer
/// bound `r2`, for a query anywhere (inside the photon box or not).
pub fn brute_grid(grid: &[[u32; 3]], g: [i64; 3], k: usize, r2: u128) -> Vec<u128> {
    let mut all: Vec<u128> = grid
        .iter()
        .map(|p| {
            (0..3)
                .map(|a| {
                    let d = (p[a] as i64 - g[a]).unsigned_abs() as u128;
                    d * d
                })
                .sum()
        })
        .filter(|&d| d <= r2)
        .collect();
    all.sort_unstable();
    all.truncate(k);
    all
}

/// The two-pass render's lookups on the default scene: its caustic map (sparse:
/// most lookups find nothing inside the cap) and its global map, at eye shading
/// points and final-gather hits.
pub fn lookup_workload() -> (Vec<Point>, Vec<Point>, Vec<Point>) {
    let scene = Scene::cornell_box();
    let (photons, caustic) = trace(&scene, 6_000, 3);
    let settings = RenderSettings {
        width: 12,
        height: 10,
        spp: 1,
        ..RenderSettings::default()
    };
    let (points, _) = eye_queries(&scene, &settings);
    let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(9);
    let mut queries = photon_points_of(&points);
    for x in &points {
        let dir =
            photon_fpga::host::render::scene::cosine_direction(x.normal, rng.gen(), rng.gen());
        if let Some(h) = gather_hit(&scene, x, dir, &mut rng) {
            queries.push(h.pos.as_dvec3().to_array());
        }
    }
    let global = photon_points(&photons);
    let caustic = photon_points(&caustic_photons(&photons, &caustic));
    (global, caustic, queries)
}

fn photon_points_of(points: &[photon_fpga::host::render::QueryPoint]) -> Vec<Point> {
    photon_fpga::host::render::query_points(points)
}

/// Check `got` (one backend's answers) against brute force: the float answers for
/// unquantized backends, the grid's for quantized ones. Returns how many were empty.
pub fn check_against_brute_force(
    what: &str,
    map: &[Point],
    queries: &[Point],
    got: &[Gathered],
    params: &GatherParams,
    quant: Option<&Quantizer>,
) -> usize {
    let r = params.radius.unwrap();
    let mut empty = 0;
    for (i, (q, g)) in queries.iter().zip(got).enumerate() {
        empty += g.neighbours.is_empty() as usize;
        match quant {
            None => {
                let truth = brute_world(map, *q, params.k, r);
                let ids: Vec<u32> = g.neighbours.iter().map(|n| n.photon).collect();
                let want: Vec<u32> = truth.iter().map(|t| t.1).collect();
                assert_eq!(ids, want, "{what}: query {i}");
                for (n, t) in g.neighbours.iter().zip(&truth) {
                    assert!((n.distance - t.0).abs() <= 1e-12, "{what}: query {i}");
                }
            }
            Some(quant) => {
                let grid: Vec<[u32; 3]> = map.iter().map(|&p| quant.quantize(p)).collect();
                let g_q = match quant.grid(*q).unwrap() {
                    GridPoint::Inside(c) => c.map(|v| v as i64),
                    GridPoint::Outside(c) => c,
                };
                let r2 = Metric::L2.radius_bound_wide(r, quant.step);
                let truth = brute_grid(&grid, g_q, params.k, r2);
                let dists: Vec<f64> = truth
                    .iter()
                    .map(|&d| (d as f64).sqrt() * quant.step)
                    .collect();
                let got_d: Vec<f64> = g.neighbours.iter().map(|n| n.distance).collect();
                assert_eq!(got_d, dists, "{what}: query {i}");
                // Each neighbour is the photon at the distance it reports.
                for n in &g.neighbours {
                    let p = grid[n.photon as usize];
                    let d: u128 = (0..3)
                        .map(|a| {
                            let d = (p[a] as i64 - g_q[a]).unsigned_abs() as u128;
                            d * d
                        })
                        .sum();
                    assert_eq!((d as f64).sqrt() * quant.step, n.distance, "{what}: {i}");
                }
            }
        }
    }
    empty
}

pub fn capped_params() -> GatherParams {
    GatherParams {
        k: 8,
        radius: Some(0.04),
        ..GatherParams::default()
    }
}

/// Radius-capped k-nearest lookups, as the two-pass render makes them, through
/// every backend: float and `--exact` equal the float brute force, sw and rtl the
/// grid's, empty answers (no photon inside the cap) included.
#[test]
fn capped_lookups_match_brute_force_through_every_backend() {
    let (global, caustic, queries) = lookup_workload();
    let params = capped_params();
    let sim = SimOptions::default();
    for (name, map) in [("global", &global), ("caustic", &caustic)] {
        let float = FloatBackend::new(map, &params).unwrap();
        let want = float.gather(&queries).unwrap();
        let empty = check_against_brute_force(name, map, &queries, &want, &params, None);
        if name == "caustic" {
            assert!(
                empty > queries.len() / 2,
                "{empty} empty of {}",
                queries.len()
            );
            assert!(empty < queries.len(), "every caustic lookup empty");
        }
        let exact = ExactBackend::new(BackendKind::Sw, map, &params, None, &sim).unwrap();
        let neighbours =
            |g: &[Gathered]| -> Vec<_> { g.iter().map(|g| g.neighbours.clone()).collect() };
        assert_eq!(
            neighbours(&exact.gather(&queries).unwrap()),
            neighbours(&want),
            "{name}: exact sw"
        );
        let sw = SwBackend::new(map, &params).unwrap();
        let quant = sw.map.quant.clone();
        let sw_got = sw.gather(&queries).unwrap();
        check_against_brute_force(name, map, &queries, &sw_got, &params, Some(&quant));
        let rtl = make_backend(BackendKind::Native, map, &params, &sim).unwrap();
        let rtl_got = rtl.gather(&queries).unwrap();
        assert_eq!(bits_of(&rtl_got), bits_of(&sw_got), "{name}: rtl");
    }
}

/// The same, through the exported Verilog under Verilator.
#[test]
#[cfg_attr(not(has_verilator), ignore = "needs verilator")]
fn capped_lookups_through_verilator_equal_sw() {
    let (global, caustic, queries) = lookup_workload();
    let params = capped_params();
    for map in [&global, &caustic] {
        let sw = SwBackend::new(map, &params)
            .unwrap()
            .gather(&queries)
            .unwrap();
        let v = make_backend(BackendKind::Verilator, map, &params, &SimOptions::default())
            .unwrap()
            .gather(&queries)
            .unwrap();
        let n = |g: &[Gathered]| -> Vec<Vec<u32>> {
            g.iter()
                .map(|g| g.neighbours.iter().map(|n| n.photon).collect())
                .collect()
        };
        assert_eq!(n(&v), n(&sw));
    }
}

/// PNG bytes and stdout of `render ARGS` on a small two-pass image.
fn two_pass_png(args: &[&str]) -> (Vec<u8>, String) {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("r.png");
    let run = bin()
        .args([
            "render", "--method", "two-pass", "--size", "10x8", "--spp", "1",
        ])
        .args(["--photons", "3000", "--k", "8", "--gather-rays", "4"])
        .args(["--out", out.to_str().unwrap()])
        .args(args)
        .assert()
        .success();
    let stdout = String::from_utf8_lossy(&run.get_output().stdout).to_string();
    (std::fs::read(&out).unwrap(), stdout)
}

#[test]
fn two_pass_rtl_render_is_byte_identical_to_sw() {
    let (sw, out) = two_pass_png(&["--backend", "sw"]);
    assert!(out.contains("final-gather lookups"), "{out}");
    let (rtl, _) = two_pass_png(&["--backend", "rtl"]);
    assert!(rtl == sw, "two-pass: rtl and sw renders differ");
}

/// Through the exported Verilog under Verilator: `sw`'s image, and with `--exact`
/// `float`'s.
#[test]
#[cfg_attr(not(has_verilator), ignore = "needs verilator")]
fn two_pass_verilator_render_is_byte_identical_to_sw_and_exact_to_float() {
    let (sw, _) = two_pass_png(&["--backend", "sw"]);
    let (v, _) = two_pass_png(&["--backend", "verilator"]);
    assert!(v == sw, "two-pass: verilator and sw renders differ");
    let (float, _) = two_pass_png(&["--backend", "float"]);
    let (exact, out) = two_pass_png(&["--backend", "verilator", "--exact"]);
    assert!(
        exact == float,
        "two-pass: verilator --exact and float differ: {out}"
    );
}

#[test]
fn two_pass_exact_render_is_byte_identical_to_float() {
    let (float, _) = two_pass_png(&["--backend", "float"]);
    let (exact, out) = two_pass_png(&["--backend", "sw", "--exact"]);
    assert!(
        exact == float,
        "two-pass: --exact and float renders differ: {out}"
    );
    let (sw, _) = two_pass_png(&["--backend", "sw"]);
    assert!(
        sw != float,
        "the 10-bit grid changed no pixel: the test shows nothing"
    );
}

#[test]
fn two_pass_render_is_the_same_for_any_thread_count() {
    let (one, _) = two_pass_png(&["--threads", "1"]);
    let (two, _) = two_pass_png(&["--threads", "2"]);
    assert!(one == two, "two-pass: 1 and 2 threads differ");
    // `--method two-pass-irradiance` is the default; direct is a different image.
    let dir = tempfile::tempdir().unwrap();
    let png = |args: &[&str], name: &str| {
        let out = dir.path().join(name);
        bin()
            .args([
                "render",
                "--size",
                "10x8",
                "--spp",
                "1",
                "--photons",
                "3000",
            ])
            .args(["--k", "8", "--out", out.to_str().unwrap()])
            .args(args)
            .assert()
            .success();
        std::fs::read(out).unwrap()
    };
    let default = png(&[], "d.png");
    assert!(default == png(&["--method", "two-pass-irradiance"], "i.png"));
    assert!(default != png(&["--method", "direct"], "e.png"));
}

#[test]
fn two_pass_options_refuse_bad_input() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("r.png");
    let vcd = dir.path().join("t.vcd");
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (
            vec!["--method", "photon-tracing"],
            "invalid value 'photon-tracing' for '--method <METHOD>'",
        ),
        (
            vec!["--method", "two-pass", "--gather-rays", "0"],
            "--gather-rays must be in 1..=4096, got 0",
        ),
        (
            vec!["--method", "direct", "--gather-rays", "8"],
            "--gather-rays sets the final gather of --method two-pass",
        ),
        // The default method is two-pass: a bare render's --vcd is refused too.
        (
            vec!["--backend", "rtl", "--vcd", vcd.to_str().unwrap()],
            "--vcd (or PHOTON_FPGA_VCD) records one simulation of one map",
        ),
        (
            vec![
                "--method",
                "two-pass",
                "--backend",
                "rtl",
                "--vcd",
                vcd.to_str().unwrap(),
            ],
            "--vcd (or PHOTON_FPGA_VCD) records one simulation of one map",
        ),
    ];
    for (args, message) in cases {
        let args: Vec<String> = ["render"]
            .iter()
            .chain(&args)
            .chain(&["--out", out.to_str().unwrap()])
            .map(|s| s.to_string())
            .collect();
        crate::refusals::refused_by(bin(), dir.path(), &args, message);
    }
}
#[path = "two_pass_reference.rs"]
pub mod reference;
pub use reference::{direct_error_at, reflected, rel_rmse, total_light};

/// Against an independent path tracer, at matched photon lookups (the direct
/// method gets at least as many eye samples as the two-pass render makes caustic
/// and final-gather lookups), two-pass is closer than the direct visualization on a
/// sparse map (20,000 emitted photons): final gathering averages the map's
/// blotches away, where the direct method shows them however many samples it
/// takes.
#[test]
fn two_pass_beats_direct_at_matched_lookups_against_a_path_tracer() {
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
    let caustic = caustic_photons(&photons, &caustic);
    let caustic_map = FloatBackend::new(&photon_points(&caustic), &params).unwrap();
    let two = RenderSettings {
        width: w,
        height: h,
        spp: 16,
        seed: 2,
        method: RenderMethod::TwoPass,
        gather_rays: 16,
        ..RenderSettings::default()
    };
    let maps = PhotonMaps {
        global: (&global, &photons),
        caustic: Some((&caustic_map, &caustic)),
        irradiance: None,
    };
    let mut t = StageTimes::default();
    let (two_pass, stats) = render_two_pass(&scene, &two, &maps, &params, &mut t).unwrap();
    let lookups = stats.caustic_lookups + stats.gather_lookups;
    assert_eq!(two_pass.queries as u64, lookups);
    let (e_direct, spp) = direct_error_at(&scene, &photons, (w, h), lookups, &reference);
    let two_pass = reflected(&scene, &two, &two_pass.linear);
    let e_two = rel_rmse(&two_pass, &reference);
    // No path counted twice or missed: the image's total light is the reference's
    // (a doubled direct or caustic term would add tens of percent).
    let (a, b) = (total_light(&two_pass), total_light(&reference));
    assert!(
        (a - b).abs() < 0.03 * b,
        "two-pass total {a} vs reference {b}"
    );
    assert!(
        e_two < 0.85 * e_direct,
        "two-pass {e_two:.4} vs direct {e_direct:.4} at {lookups} lookups (direct spp {spp})"
    );
}

/// The two-pass direct term (shadow rays) against the path tracer stopped at its
/// first diffuse vertex (next-event estimation there, nothing after): both are
/// unbiased estimates of the same direct light, so they agree up to noise.
#[test]
fn direct_light_matches_path_traced_direct_light() {
    let scene = Scene::cornell_box();
    let (w, h) = (24, 24);
    let reference = reference::path_trace(&scene, w, h, 1024, 5, 1);
    let settings = RenderSettings {
        width: w,
        height: h,
        spp: 64,
        ..RenderSettings::default()
    };
    let (points, _) = eye_queries(&scene, &settings);
    let direct = photon_fpga::host::render::direct_light::direct_light(&scene, &points, 1);
    let zero = vec![Vec3::ZERO; (w * h) as usize];
    let img = photon_fpga::host::render::pixel_radiance(w, h, &points, &direct, &zero);
    let mean = |v: &[Vec3]| v.iter().map(|c| c.element_sum() as f64).sum::<f64>();
    let (a, b) = (mean(&img), mean(&reference));
    assert!((a - b).abs() < 0.01 * b, "mean {a} vs reference {b}");
    let e = rel_rmse(&img, &reference);
    assert!(e < 0.05, "rel. RMSE {e:.4}");
}

/// `--out NAME.pfm` writes the linear radiance the PNG of the same render encodes:
/// exposed, clamped and gamma-encoded, each PFM value gives the PNG's byte.
#[test]
fn pfm_output_is_the_linear_radiance_of_the_png() {
    let (png, _) = two_pass_png(&[]);
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("r.pfm");
    bin()
        .args([
            "render", "--method", "two-pass", "--size", "10x8", "--spp", "1",
        ])
        .args(["--photons", "3000", "--k", "8", "--gather-rays", "4"])
        .args(["--out", out.to_str().unwrap()])
        .assert()
        .success();
    let bytes = std::fs::read(&out).unwrap();
    let header = b"PF\n10 8\n-1.0\n";
    assert_eq!(&bytes[..header.len()], header);
    let floats: Vec<f32> = bytes[header.len()..]
        .chunks(4)
        .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect();
    assert_eq!(floats.len(), 10 * 8 * 3);
    let img = image::load_from_memory(&png).unwrap().to_rgb8();
    let exposure = photon_fpga::host::render::DEFAULT_EXPOSURE;
    for (y, row) in floats.chunks(10 * 3).rev().enumerate() {
        for (x, c) in row.chunks(3).enumerate() {
            let want = img.get_pixel(x as u32, y as u32).0;
            for (v, w) in c.iter().zip(want) {
                let e = ((v * exposure).clamp(0.0, 1.0).powf(1.0 / 2.2) * 255.0 + 0.5) as u8;
                assert_eq!(e, w, "pixel ({x}, {y})");
            }
        }
    }
}

/// A scene without mirrors or glass has no caustic photons: no caustic map, no
/// caustic lookups, and the render still succeeds.
#[test]
fn two_pass_without_specular_surfaces_has_no_caustic_map() {
    let text = include_str!("../scenes/cornell.toml");
    let cut = text.find("[[sphere]]").unwrap();
    let light = text.find("# A 0.25 x 0.25 square").unwrap();
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("plain.toml");
    std::fs::write(&scene, format!("{}{}", &text[..cut], &text[light..])).unwrap();
    let (_, out) = two_pass_png(&["--scene", scene.to_str().unwrap()]);
    assert!(
        out.contains("0 caustic photons, 0 caustic lookups"),
        "{out}"
    );
}
