//! The `rtl` backend through the CLI: a render through the simulated core is
//! byte-identical to the software search's, and `gather --backend rtl` returns the
//! exact k nearest of a user's CSV (checked against an independent brute force).

use assert_cmd::Command;
use rand::{Rng, SeedableRng};

/// Points as CSV lines `x,y,z`.
fn csv(pts: &[[i32; 3]]) -> String {
    pts.iter()
        .map(|p| format!("{},{},{}\n", p[0], p[1], p[2]))
        .collect()
}

fn bin() -> Command {
    Command::cargo_bin("photon-fpga").unwrap()
}

/// The PNG bytes of the same render through each of `backends`.
fn renders(backends: &[&str], size: &str, photons: &str, k: &str) -> Vec<Vec<u8>> {
    let runs: Vec<Vec<&str>> = backends.iter().map(|b| vec!["--backend", b]).collect();
    let runs: Vec<&[&str]> = runs.iter().map(|r| r.as_slice()).collect();
    renders_with(&runs, size, photons, k)
        .into_iter()
        .map(|(png, _)| png)
        .collect()
}

/// The PNG bytes and stdout of the same render with each of `runs`' options.
fn renders_with(runs: &[&[&str]], size: &str, photons: &str, k: &str) -> Vec<(Vec<u8>, String)> {
    let dir = tempfile::tempdir().unwrap();
    runs.iter()
        .enumerate()
        .map(|(i, args)| {
            let out = dir.path().join(format!("{i}.png"));
            let run = bin()
                .args(["render", "--method", "direct", "--size", size, "--spp", "1"])
                .args(["--photons", photons])
                .args(["--k", k, "--out", out.to_str().unwrap()])
                .args(*args)
                .assert()
                .success();
            let stdout = String::from_utf8_lossy(&run.get_output().stdout).to_string();
            (std::fs::read(&out).unwrap(), stdout)
        })
        .collect()
}

#[test]
fn rtl_render_is_byte_identical_to_sw() {
    let pngs = renders(&["sw", "rtl"], "16x12", "1500", "6");
    assert!(pngs[0] == pngs[1], "rtl and sw renders differ");
}

/// The core options reach the simulated core: the default hardware core is the
/// barrel controller with the cell traversal, and the paper's QueryModules, an
/// array of trees and a chosen Q render the very image the software search does.
#[test]
fn rtl_render_runs_the_chosen_core() {
    let runs: [&[&str]; 3] = [
        &["--backend", "sw"],
        &["--backend", "rtl"],
        &["--backend", "rtl", "--controller", "modules"],
    ];
    let out = renders_with(&runs, "12x10", "1200", "5");
    let core = |s: &str| {
        s.lines()
            .find(|l| l.starts_with("core: "))
            .unwrap_or_else(|| panic!("no core line in {s}"))
            .to_string()
    };
    assert!(
        core(&out[1].1).contains("barrel controller"),
        "{}",
        out[1].1
    );
    assert!(core(&out[1].1).contains("cell traversal"), "{}", out[1].1);
    assert!(
        core(&out[2].1).contains("modules controller"),
        "{}",
        out[2].1
    );
    assert!(
        core(&out[2].1).contains("remember traversal"),
        "{}",
        out[2].1
    );
    for (png, stdout) in &out[1..] {
        assert!(*png == out[0].0, "rtl and sw renders differ: {stdout}");
    }
    let runs: [&[&str]; 2] = [
        &["--backend", "sw", "--traversal", "reread"],
        &[
            "--backend",
            "rtl",
            "--controller",
            "modules",
            "--traversal",
            "reread",
        ],
    ];
    let rr = renders_with(&runs, "12x10", "1200", "5");
    assert!(
        rr[0].0 == out[0].0 && rr[1].0 == out[0].0,
        "reread renders differ"
    );
    let runs: [&[&str]; 1] = [&[
        "--backend",
        "rtl",
        "--trees",
        "2",
        "--queries-per-port",
        "6",
    ]];
    let arr = renders_with(&runs, "12x10", "1200", "5");
    assert!(core(&arr[0].1).contains("T = 2 tree(s)"), "{}", arr[0].1);
    assert!(
        core(&arr[0].1).contains("2 x 6 query slots per tree"),
        "{}",
        arr[0].1
    );
    assert!(arr[0].0 == out[0].0, "the array's render differs");
}

/// `render --backend verilator --controller barrel --traversal cell` is
/// byte-identical to the software search.
#[test]
#[cfg_attr(not(has_verilator), ignore = "needs verilator")]
fn verilator_barrel_cell_render_is_byte_identical_to_sw() {
    let runs: [&[&str]; 2] = [
        &["--backend", "sw"],
        &[
            "--backend",
            "verilator",
            "--controller",
            "barrel",
            "--traversal",
            "cell",
        ],
    ];
    let out = renders_with(&runs, "24x16", "4000", "8");
    assert!(
        out[0].0 == out[1].0,
        "verilator barrel and sw renders differ"
    );
}

/// `gather --backend rtl` returns the exact k nearest with every core: the default
/// (barrel, cell), the barrel port with a chosen number of slots, and the paper's
/// QueryModules in an array of two trees.
#[test]
fn rtl_gather_returns_the_exact_k_nearest() {
    let mut r = rand_pcg::Pcg64Mcg::seed_from_u64(9);
    // Integer positions with the longest extent 0..=1023: the 10-bit grid step is 1.
    let mut photons: Vec<[i32; 3]> = (0..300)
        .map(|_| {
            [
                r.gen_range(0..1024),
                r.gen_range(0..300),
                r.gen_range(0..1024),
            ]
        })
        .collect();
    photons.extend([[0, 0, 0], [1023, 0, 0], [5, 5, 5], [5, 5, 5]]);
    let queries: Vec<[i32; 3]> = (0..25)
        .map(|_| {
            [
                r.gen_range(0..1024),
                r.gen_range(0..300),
                r.gen_range(0..1024),
            ]
        })
        .chain([[5, 5, 5], [0, 0, 0]])
        .collect();
    let dir = tempfile::tempdir().unwrap();
    let (pp, qp) = (dir.path().join("p.csv"), dir.path().join("q.csv"));
    std::fs::write(&pp, csv(&photons)).unwrap();
    std::fs::write(&qp, format!("x,y,z\n{}", csv(&queries))).unwrap();
    let cores: [&[&str]; 3] = [
        &[],
        &["--controller", "barrel", "--queries-per-port", "5"],
        &[
            "--controller",
            "modules",
            "--queries-per-port",
            "3",
            "--trees",
            "2",
        ],
    ];
    for ((metric, k, radius), core) in [("l2", 5, None), ("l1", 9, Some("150"))]
        .into_iter()
        .flat_map(|case| cores.iter().map(move |c| (case, *c)))
    {
        let out = dir.path().join(format!("{metric}.csv"));
        let mut cmd = bin();
        cmd.args([
            "gather",
            "--backend",
            "rtl",
            "--metric",
            metric,
            "--k",
            &k.to_string(),
        ])
        .args([
            "--photons",
            pp.to_str().unwrap(),
            "--queries",
            qp.to_str().unwrap(),
        ])
        .args(["--out", out.to_str().unwrap()])
        .args(core);
        if let Some(r) = radius {
            cmd.args(["--radius", r]);
        }
        cmd.assert().success();
        let text = std::fs::read_to_string(&out).unwrap();
        let rows: Vec<Vec<f64>> = text
            .lines()
            .skip(1)
            .map(|l| l.split(',').map(|f| f.parse().unwrap()).collect())
            .collect();
        for (qi, q) in queries.iter().enumerate() {
            let dist = |p: &[i32; 3]| {
                let d = [0, 1, 2].map(|a| (p[a] - q[a]).abs() as f64);
                if metric == "l2" {
                    (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt()
                } else {
                    d[0] + d[1] + d[2]
                }
            };
            let limit = radius
                .map(|r| r.parse::<f64>().unwrap())
                .unwrap_or(f64::MAX);
            let mut truth: Vec<f64> = photons.iter().map(dist).filter(|&d| d <= limit).collect();
            truth.sort_by(|a, b| a.total_cmp(b));
            truth.truncate(k);
            let got: Vec<&Vec<f64>> = rows.iter().filter(|r| r[0] as usize == qi).collect();
            assert_eq!(got.len(), truth.len(), "query {qi}: count");
            for (rank, row) in got.iter().enumerate() {
                assert_eq!(row[1] as usize, rank);
                assert!((dist(&photons[row[2] as usize]) - row[3]).abs() < 1e-9);
                assert!(
                    (truth[rank] - row[3]).abs() < 1e-9,
                    "query {qi} rank {rank}"
                );
            }
        }
    }
}

/// `render ARGS` exits 2 naming `message`, and writes no image.
fn render_fails(args: &[&str], message: &str) {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("r.png");
    let assert = bin()
        .arg("render")
        .args(args)
        .args(["--photons", "100", "--out", out.to_str().unwrap()])
        .assert()
        .code(2);
    let stderr = String::from_utf8_lossy(&assert.get_output().stderr).to_string();
    assert!(stderr.contains(message), "{stderr}");
    assert!(!out.exists());
}

#[test]
fn rtl_refuses_what_the_core_cannot_hold() {
    // Above the barrel core's K = 512, and above the QueryModules' 64.
    render_fails(&["--backend", "rtl", "--k", "513"], "513");
    render_fails(
        &["--backend", "rtl", "--controller", "modules", "--k", "65"],
        "K = 65 unsupported by the modules controller",
    );
    render_fails(
        &["--backend", "sw", "--vcd", "x.vcd"],
        "--vcd needs --backend native or verilator",
    );
}

/// Issue 14: `render --backend verilator` (the exported core under Verilator) is
/// byte-identical to the software search at 64×64, where the native simulation
/// would take minutes.
#[test]
#[cfg_attr(not(has_verilator), ignore = "needs verilator")]
fn verilator_render_is_byte_identical_to_sw() {
    let pngs = renders(&["sw", "verilator"], "64x64", "20000", "10");
    assert!(pngs[0] == pngs[1], "verilator and sw renders differ");
}

/// The paper's high-quality regime (§3: at least 500 search photons):
/// `render --backend verilator --k 500` on the default scene and photon map (the
/// barrel core sized to K = 500, its found lists max-heaps in BlockRAM) is
/// byte-identical to the software search.
#[test]
#[cfg_attr(not(has_verilator), ignore = "needs verilator")]
fn verilator_render_at_k_500_is_byte_identical_to_sw() {
    let pngs = renders(&["sw", "verilator"], "32x24", "200000", "500");
    assert!(
        pngs[0] == pngs[1],
        "k = 500: verilator and sw renders differ"
    );
}

/// Issue 14: `gather --backend verilator` writes the very file `--backend rtl`
/// writes, on hard cases: every photon of a cluster at one point, photons on one
/// plane and on one line, ties on grid cell boundaries, queries on photons, at the
/// grid corners and beyond the photon box, radius 0, bounded and unbounded, both
/// metrics.
#[test]
#[cfg_attr(not(has_verilator), ignore = "needs verilator")]
fn verilator_gather_equals_rtl_on_hard_cases() {
    let mut photons: Vec<[i32; 3]> = vec![[7, 7, 7]; 20];
    photons.extend((0..40).map(|i| [i * 3 % 64, i * 7 % 64, 10]));
    photons.extend((0..20).map(|i| [i * 3, 5, 5]));
    photons.extend([
        [0, 0, 0],
        [63, 63, 63],
        [32, 32, 32],
        [31, 32, 32],
        [33, 32, 32],
    ]);
    let queries: Vec<[i32; 3]> = vec![
        [7, 7, 7],
        [0, 0, 0],
        [63, 63, 63],
        [32, 32, 32],
        [12, 5, 5],
        [30, 30, 10],
        [100, -5, 7],
    ];
    let dir = tempfile::tempdir().unwrap();
    let (pp, qp) = (dir.path().join("p.csv"), dir.path().join("q.csv"));
    std::fs::write(&pp, csv(&photons)).unwrap();
    std::fs::write(&qp, csv(&queries)).unwrap();
    for (metric, k, radius) in [("l2", 6, None), ("l1", 4, Some("3")), ("l2", 3, Some("0"))] {
        let mut outputs = vec![];
        for backend in ["rtl", "verilator"] {
            let out = dir.path().join(format!("{metric}_{k}_{backend}.csv"));
            let mut cmd = bin();
            cmd.args(["gather", "--backend", backend, "--metric", metric])
                .args(["--k", &k.to_string()])
                .args(["--photons", pp.to_str().unwrap()])
                .args(["--queries", qp.to_str().unwrap()])
                .args(["--out", out.to_str().unwrap()]);
            if let Some(r) = radius {
                cmd.args(["--radius", r]);
            }
            // One Verilator run also writes its waveform (Verilator's tracer; a
            // second model build, so only once).
            let vcd = dir.path().join("wave.vcd");
            let traced = backend == "verilator" && radius.is_none();
            if traced {
                cmd.args(["--vcd", vcd.to_str().unwrap()]);
            }
            cmd.assert().success();
            outputs.push(std::fs::read(&out).unwrap());
            if traced {
                let text = std::fs::read_to_string(&vcd).unwrap();
                assert!(text.contains("$enddefinitions") && text.contains("result$valid"));
            }
        }
        assert!(
            outputs[0] == outputs[1],
            "{metric}, k = {k}, radius {radius:?}: verilator and rtl files differ"
        );
    }
}

/// The Verilator model cache: three concurrent first runs of one model, started
/// from one working directory, all succeed with the same file as the rtl backend's
/// and leave nothing but their outputs there; a damaged cached model is rebuilt;
/// a run that cannot find Verilator fails with exit 2 and leaves no cache entry.
#[test]
#[cfg_attr(not(has_verilator), ignore = "needs verilator")]
fn verilator_model_cache_is_shared_safely_and_repairs_itself() {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(31);
    let photons: Vec<[i32; 3]> = (0..300)
        .map(|_| {
            [
                rng.gen_range(0..50),
                rng.gen_range(0..50),
                rng.gen_range(0..50),
            ]
        })
        .collect();
    let queries: Vec<[i32; 3]> = (0..40)
        .map(|_| {
            [
                rng.gen_range(0..50),
                rng.gen_range(0..50),
                rng.gen_range(0..50),
            ]
        })
        .collect();
    let work = tempfile::tempdir().unwrap();
    let cache = tempfile::tempdir().unwrap();
    std::fs::write(work.path().join("p.csv"), csv(&photons)).unwrap();
    std::fs::write(work.path().join("q.csv"), csv(&queries)).unwrap();
    let gather = |backend: &str, out: &str| {
        let mut c = std::process::Command::new(assert_cmd::cargo::cargo_bin("photon-fpga"));
        c.current_dir(work.path())
            .env("PHOTON_FPGA_CACHE_DIR", cache.path())
            .args(["gather", "--backend", backend, "--k", "5"])
            .args(["--photons", "p.csv", "--queries", "q.csv", "--out", out]);
        c
    };
    let listing = |d: &std::path::Path| {
        let mut v: Vec<String> = std::fs::read_dir(d)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    };
    assert!(gather("rtl", "rtl.csv").status().unwrap().success());
    let want = std::fs::read(work.path().join("rtl.csv")).unwrap();
    let runs: Vec<std::process::Child> = (0..3)
        .map(|i| gather("verilator", &format!("v{i}.csv")).spawn().unwrap())
        .collect();
    for (i, mut r) in runs.into_iter().enumerate() {
        assert!(r.wait().unwrap().success(), "concurrent run {i} failed");
        let got = std::fs::read(work.path().join(format!("v{i}.csv"))).unwrap();
        assert!(got == want, "concurrent run {i} differs from rtl");
    }
    assert_eq!(
        listing(work.path()),
        ["p.csv", "q.csv", "rtl.csv", "v0.csv", "v1.csv", "v2.csv"],
        "the working directory gained files"
    );
    // One model, one entry (and its lock file).
    let entries: Vec<std::path::PathBuf> = std::fs::read_dir(cache.path())
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.is_dir())
        .collect();
    assert_eq!(entries.len(), 1, "{entries:?}");
    // Damage the library: the next run rebuilds it and answers the same.
    let lib = entries[0].join("obj_dir/libvtop.so");
    let len = std::fs::metadata(&lib).unwrap().len();
    std::fs::OpenOptions::new()
        .write(true)
        .open(&lib)
        .unwrap()
        .set_len(len / 2)
        .unwrap();
    assert!(gather("verilator", "v3.csv").status().unwrap().success());
    assert!(std::fs::read(work.path().join("v3.csv")).unwrap() == want);
    assert_eq!(std::fs::metadata(&lib).unwrap().len(), len, "not rebuilt");
    // No Verilator on the PATH: a clear error, exit 2, no new entry or build dir.
    let before = listing(cache.path());
    let out = gather("verilator", "none.csv")
        .env("PHOTON_FPGA_CACHE_DIR", cache.path().join("fresh"))
        .env("PATH", "/nonexistent")
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("verilator"));
    assert!(!work.path().join("none.csv").exists());
    assert_eq!(listing(cache.path()), before);
    assert!(!cache.path().join("fresh").exists());
}
