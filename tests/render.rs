//! The render pipeline end to end: determinism across thread counts, the software
//! search against brute force on real Cornell-box photon maps, and the `render` CLI.

use assert_cmd::Command;
use photon_fpga::host::gather::{GatherParams, SwBackend};
use photon_fpga::host::map::kdtree::PackedTree;
use photon_fpga::host::map::knn::{brute_force, search};
use photon_fpga::host::map::quantize::Quantizer;
use photon_fpga::host::render::photons::trace_photons;
use photon_fpga::host::render::scene::Scene;
use photon_fpga::host::render::{self, eye_queries, render_image, RenderSettings};
use photon_fpga::host::stages::StageTimes;
use photon_fpga::hw::config::metric::Metric;

fn pool(threads: usize) -> rayon::ThreadPool {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
}

#[test]
fn one_and_two_threads_give_identical_photon_maps_and_images() {
    let scene = Scene::cornell_box();
    let settings = RenderSettings {
        width: 48,
        height: 40,
        spp: 2,
        ..RenderSettings::default()
    };
    let params = GatherParams {
        k: 30,
        ..GatherParams::default()
    };
    let run = |threads| {
        pool(threads).install(|| {
            let photons = trace_photons(&scene, 20_000, 7, false);
            let backend = SwBackend::new(&render::photon_points(&photons), &params).unwrap();
            let img = render_image(
                &scene,
                &settings,
                &photons,
                &backend,
                &params,
                &mut StageTimes::default(),
            )
            .unwrap()
            .image;
            let bits: Vec<[u32; 9]> = photons
                .iter()
                .map(|p| {
                    let a = [p.pos, p.power, p.dir];
                    [0, 1, 2, 3, 4, 5, 6, 7, 8].map(|i| a[i / 3][i % 3].to_bits())
                })
                .collect();
            (bits, img.into_raw())
        })
    };
    let (p1, i1) = run(1);
    let (p2, i2) = run(2);
    assert!(!p1.is_empty());
    assert!(p1 == p2, "photon maps differ between 1 and 2 threads");
    assert!(i1 == i2, "images differ between 1 and 2 threads");
    assert!(i1.iter().any(|&b| b > 0), "the image is black");
}

#[test]
fn cornell_box_maps_match_brute_force() {
    let scene = Scene::cornell_box();
    let photons = trace_photons(&scene, 4_000, 11, false);
    let points = render::photon_points(&photons);
    let settings = RenderSettings {
        width: 16,
        height: 12,
        spp: 1,
        ..RenderSettings::default()
    };
    let (queries, _) = eye_queries(&scene, &settings);
    for bits in [6, 10] {
        let quant = Quantizer::from_points(&points, bits).unwrap();
        let grid: Vec<[u32; 3]> = points.iter().map(|&p| quant.quantize(p)).collect();
        let tree = PackedTree::build(&points, &quant);
        for metric in [Metric::L2, Metric::L1] {
            for q in render::query_points(&queries) {
                let q = quant.quantize(q);
                for (k, r0) in [(1, u64::MAX), (10, u64::MAX), (100, u64::MAX), (50, 400)] {
                    let truth: Vec<u64> = brute_force(&grid, q, k, r0, metric)
                        .iter()
                        .map(|t| t.1)
                        .collect();
                    let found = search(&tree, q, k, r0, metric);
                    assert_eq!(found.sorted_dists(), truth, "bits {bits} {metric:?} k {k}");
                }
            }
        }
    }
}

fn bin() -> Command {
    Command::cargo_bin("photon-fpga").unwrap()
}

#[test]
fn render_cli_writes_a_png_and_the_stage_table() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("r.png");
    let assert = bin()
        .args([
            "render",
            "--size",
            "32x24",
            "--photons",
            "5000",
            "--k",
            "20",
        ])
        .args(["--out", out.to_str().unwrap()])
        .assert()
        .success();
    let stdout = String::from_utf8_lossy(&assert.get_output().stdout).to_string();
    for stage in [
        "ray emission",
        "photon emission",
        "kd-tree build",
        "kd-tree search",
        "other",
    ] {
        assert!(stdout.contains(stage), "{stdout}");
    }
    assert!(stdout.contains("photons visited per query"));
    let img = image::open(&out).unwrap();
    assert_eq!((img.width(), img.height()), (32, 24));
}

#[test]
fn render_cli_rejects_bad_input() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("r.png");
    let scene = dir.path().join("bad.toml");
    std::fs::write(&scene, "[camera]\nposition = [0, 0, \"x\"]\n").unwrap();
    let cases: Vec<(Vec<String>, &str)> = vec![
        (
            vec!["--scene".into(), scene.display().to_string()],
            "bad.toml:2",
        ),
        (
            vec!["--scene".into(), "/nonexistent/s.toml".into()],
            "/nonexistent/s.toml",
        ),
        (vec!["--size".into(), "0x5".into()], "invalid size '0x5'"),
        (vec!["--k".into(), "0".into()], "--k must be at least 1"),
        (
            vec!["--photons".into(), "0".into()],
            "--photons must be in 1..=",
        ),
        (
            vec!["--radius".into(), "-2".into()],
            "--radius must be a finite number",
        ),
        (
            vec!["--metric".into(), "cosine".into()],
            "invalid value 'cosine' for '--metric <METRIC>'",
        ),
    ];
    for (args, message) in cases {
        let assert = bin()
            .arg("render")
            .args(&args)
            .args(["--out", out.to_str().unwrap()])
            .assert()
            .code(2);
        let stderr = String::from_utf8_lossy(&assert.get_output().stderr).to_string();
        assert!(stderr.contains(message), "{args:?}: {stderr}");
        assert!(!stderr.contains("panicked"), "{stderr}");
        assert!(!out.exists());
    }
}
