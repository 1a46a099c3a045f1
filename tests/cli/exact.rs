//! `--exact` through the binary: `gather --exact` on sw, rtl and verilator writes the
//! very bytes `gather --backend float` writes, `render --exact` at the defaults is
//! byte-identical to the float render with most queries certified, and the options
//! the re-ranking cannot honour are refused before any work.

use super::*;

/// A small map with the hard parts: a cluster at one point, a plane, integer
/// lattice ties; queries on photons, on cell boundaries and outside the box.
fn hard_map(seed: u64) -> (Vec<[f64; 3]>, Vec<[f64; 3]>) {
    let mut r = rand_pcg::Pcg64Mcg::seed_from_u64(seed);
    let mut photons: Vec<[f64; 3]> = (0..120)
        .map(|_| [0; 3].map(|_: i32| r.gen_range(0.0..4.0)))
        .collect();
    photons.extend(vec![[1.0, 1.0, 1.0]; 12]);
    photons.extend((0..40).map(|_| [r.gen_range(0.0..4.0), 2.0, r.gen_range(0.0..4.0)]));
    photons.extend((0..27).map(|i| [(i % 3) as f64, ((i / 3) % 3) as f64, (i / 9) as f64]));
    let mut queries: Vec<[f64; 3]> = (0..20)
        .map(|_| [0; 3].map(|_: i32| r.gen_range(0.0..4.0)))
        .collect();
    queries.extend([
        [1.0, 1.0, 1.0],
        [0.5, 0.5, 0.5],
        [1.5, 2.0, 0.5],
        [9.0, 1.0, 1.0],
        [-2.0, -2.0, 5.0],
    ]);
    (photons, queries)
}

/// The output bytes of `gather` with `extra` options on P.csv and Q.csv, and stdout.
fn gather_bytes(dir: &Path, p: &Path, q: &Path, extra: &[&str], name: &str) -> (Vec<u8>, String) {
    let out = dir.join(name);
    let run = bin()
        .args(["gather", "--photons", p.to_str().unwrap()])
        .args([
            "--queries",
            q.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ])
        .args(extra)
        .assert()
        .success();
    let stdout = String::from_utf8_lossy(&run.get_output().stdout).to_string();
    (std::fs::read(&out).unwrap(), stdout)
}

/// (backend, metric, k, radius, --refine).
type Case = (
    &'static str,
    &'static str,
    &'static str,
    Option<&'static str>,
    Option<&'static str>,
);

#[test]
fn gather_exact_writes_the_float_bytes_on_every_quantized_backend() {
    let dir = tempfile::tempdir().unwrap();
    let (photons, queries) = hard_map(41);
    let p = write(dir.path(), "p.csv", &points_csv(&photons, true));
    let q = write(dir.path(), "q.csv", &points_csv(&queries, false));
    // Verilator on two cases, one per metric, to keep CI short.
    let cases: [Case; 8] = [
        ("sw", "l2", "8", None, None),
        ("sw", "l1", "5", Some("0.7"), None),
        ("sw", "l2", "300", None, Some("0")),
        ("sw", "l1", "3", Some("0"), Some("2")),
        ("rtl", "l2", "6", Some("1.2"), None),
        ("rtl", "l1", "10", None, Some("4")),
        ("verilator", "l1", "7", None, None),
        ("verilator", "l2", "4", Some("0.9"), Some("3")),
    ];
    for (i, (backend, metric, k, radius, refine)) in cases.into_iter().enumerate() {
        let mut common = vec!["--metric", metric, "--k", k];
        if let Some(r) = radius {
            common.extend(["--radius", r]);
        }
        let (float, _) = gather_bytes(
            dir.path(),
            &p,
            &q,
            &[common.as_slice(), &["--backend", "float"]].concat(),
            &format!("f{i}.csv"),
        );
        let mut exact = common.clone();
        exact.extend(["--backend", backend, "--exact"]);
        if let Some(m) = refine {
            exact.extend(["--refine", m]);
        }
        let (got, stdout) = gather_bytes(dir.path(), &p, &q, &exact, &format!("e{i}.csv"));
        assert!(
            got == float,
            "{backend} --exact differs from float ({metric}, k {k}, radius {radius:?})"
        );
        assert!(stdout.contains("exact: m = "), "no summary: {stdout}");
        assert!(stdout.contains("certified "), "{stdout}");
    }
}

/// The summary's certified percentage and m.
fn certified_and_m(stdout: &str) -> (f64, usize) {
    let pct = stdout
        .split(" core queries (")
        .nth(1)
        .and_then(|s| s.split(" %").next())
        .and_then(|s| s.parse().ok())
        .unwrap_or_else(|| panic!("no certified share in {stdout}"));
    let m = stdout
        .split("exact: m = ")
        .nth(1)
        .and_then(|s| s.split(' ').next())
        .and_then(|s| s.parse().ok())
        .unwrap_or_else(|| panic!("no m in {stdout}"));
    (pct, m)
}

/// At the defaults (Cornell box, 200,000 emitted photons, 10 bits, k = 32) the exact
/// render is the float render, byte for byte, with at least 95 % of its queries
/// certified at the chosen m, and m <= k.
#[test]
fn render_exact_at_the_defaults_is_the_float_render() {
    let dir = tempfile::tempdir().unwrap();
    let (f, e) = (dir.path().join("f.png"), dir.path().join("e.png"));
    bin()
        .args(["render", "--method", "direct", "--backend", "float"])
        .args(["--out", f.to_str().unwrap()])
        .assert()
        .success();
    let run = bin()
        .args(["render", "--method", "direct", "--exact"])
        .args(["--out", e.to_str().unwrap()])
        .assert()
        .success();
    let stdout = String::from_utf8_lossy(&run.get_output().stdout).to_string();
    assert!(
        std::fs::read(&f).unwrap() == std::fs::read(&e).unwrap(),
        "the exact render differs from the float render"
    );
    let (pct, m) = certified_and_m(&stdout);
    assert!(pct >= 95.0, "{pct} % certified: {stdout}");
    assert!(m <= 32, "m = {m}");
}

#[test]
fn render_exact_on_the_simulated_core_is_the_float_render() {
    let run = |extra: &[&str]| {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("r.png");
        bin()
            .args([
                "render",
                "--method",
                "direct",
                "--size",
                "16x12",
                "--spp",
                "1",
                "--photons",
                "1500",
            ])
            .args(["--k", "6", "--out", out.to_str().unwrap()])
            .args(extra)
            .assert()
            .success();
        std::fs::read(&out).unwrap()
    };
    assert!(run(&["--backend", "float"]) == run(&["--backend", "rtl", "--exact"]));
}

#[test]
fn exact_refusals_come_before_any_work() {
    let (dir, p, q) = setup();
    let out = dir.path().join("r.png").display().to_string();
    let render = |extra: &[&str]| cmdline(&["render", "--out", &out], extra);
    refused(
        dir.path(),
        &render(&["--exact", "--backend", "float"]),
        "--backend float is exact already",
    );
    // The core's K is its controller's: 512 for the barrel core (the hardware
    // default), 64 for QueryModules.
    for backend in ["rtl", "verilator"] {
        refused(
            dir.path(),
            &render(&["--exact", "--backend", backend, "--refine", "481"]),
            "--refine 481 with --k 32 asks the core for 513 candidates per query; its found list holds at most 512",
        );
        refused(
            dir.path(),
            &render(&["--exact", "--backend", backend, "--controller", "modules", "--refine", "33"]),
            "--refine 33 with --k 32 asks the core for 65 candidates per query; its found list holds at most 64",
        );
    }
    refused(dir.path(), &render(&["--refine", "4"]), "--exact");
    refused(
        dir.path(),
        &render(&["--exact", "--refine", &usize::MAX.to_string()]),
        "is too large",
    );
    let g = dir.path().join("g.csv").display().to_string();
    let gather = |extra: &[&str]| {
        cmdline(
            &["gather", "--photons", &p, "--queries", &q, "--out", &g],
            extra,
        )
    };
    refused(
        dir.path(),
        &gather(&["--exact", "--backend", "float"]),
        "--backend float is exact already",
    );
    refused(
        dir.path(),
        &gather(&["--exact", "--backend", "rtl", "--k", "513"]),
        "K = 513 unsupported by the barrel controller",
    );
    refused(
        dir.path(),
        &gather(&[
            "--exact",
            "--backend",
            "rtl",
            "--controller",
            "modules",
            "--k",
            "70",
        ]),
        "K = 70 unsupported by the modules controller",
    );
    refused(
        dir.path(),
        &gather(&["--exact", "--k", "0"]),
        "--k must be at least 1",
    );
}

/// `render --exact` writes the float render's bytes on the study's quick scene,
/// photons and image (the lab's `--exact` series points), at the series' coarsest grid (the most fallbacks) with no
/// extra candidates, a few, and the chosen m: the exact image error against float
/// is zero, measured here apart from the study's own check.
#[test]
fn render_exact_is_the_float_render_at_the_series_points() {
    let dir = tempfile::tempdir().unwrap();
    let run = |name: &str, extra: &[&str]| {
        let out = dir.path().join(name);
        bin()
            .args([
                "render",
                "--method",
                "direct",
                "--photons",
                "3000",
                "--size",
                "32x32",
                "--spp",
                "1",
            ])
            .args(["--k", "10", "--out", out.to_str().unwrap()])
            .args(extra)
            .assert()
            .success();
        std::fs::read(&out).unwrap()
    };
    let float = run("float.png", &["--backend", "float"]);
    let quantized = run("sw.png", &["--bits", "8"]);
    assert!(quantized != float, "8 bits without --exact should differ");
    for refine in [Some("0"), Some("4"), None] {
        let mut args = vec!["--bits", "8", "--exact"];
        if let Some(m) = refine {
            args.extend(["--refine", m]);
        }
        let exact = run("exact.png", &args);
        assert!(exact == float, "--exact {refine:?} differs from float");
    }
}
