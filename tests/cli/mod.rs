//! `photon-fpga gather`: exact answers on a user's CSV, and a clear error, exit
//! status 2 and no output file for every bad input; `export-verilog`'s files and errors.

use crate::refusals::{listing, refused_by};
use assert_cmd::Command;
use rand::{Rng, SeedableRng};
use std::path::{Path, PathBuf};

fn bin() -> Command {
    Command::cargo_bin("photon-fpga").unwrap()
}

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

fn points_csv(points: &[[f64; 3]], header: bool) -> String {
    let mut s = String::new();
    if header {
        s.push_str("x,y,z,power\n");
    }
    for p in points {
        s.push_str(&format!("{},{},{},0.5\n", p[0], p[1], p[2]));
    }
    s
}

/// Run `args` and assert the refusal ([`refused_by`]).
fn refused(dir: &Path, args: &[String], message: &str) {
    refused_by(bin(), dir, args, message);
}

/// Run gather and assert the failure: status 2, the message, no output file.
fn fails(dir: &Path, args: &[&str], message: &str) {
    let out = dir.join("out.csv");
    let _ = std::fs::remove_file(&out);
    let mut all = vec!["gather".to_string()];
    all.extend(args.iter().map(|s| s.to_string()));
    all.extend(["--out".to_string(), out.display().to_string()]);
    refused(dir, &all, message);
}

/// World distance in `metric` ("l2" Euclidean, "l1" Manhattan).
fn world_dist(metric: &str, p: &[f64; 3], q: &[f64; 3]) -> f64 {
    let d = [0, 1, 2].map(|a| (p[a] - q[a]).abs());
    if metric == "l2" {
        (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt()
    } else {
        d[0] + d[1] + d[2]
    }
}

/// Every photon's distance from `q`, nearest first (brute force).
fn true_dists(metric: &str, photons: &[[f64; 3]], q: &[f64; 3]) -> Vec<f64> {
    let mut truth: Vec<f64> = photons.iter().map(|p| world_dist(metric, p, q)).collect();
    truth.sort_by(f64::total_cmp);
    truth
}

fn setup() -> (tempfile::TempDir, String, String) {
    let dir = tempfile::tempdir().unwrap();
    let p = write(
        dir.path(),
        "p.csv",
        &points_csv(&[[0.0, 0.0, 0.0], [1.0, 2.0, 3.0]], false),
    );
    let q = write(dir.path(), "q.csv", "0.5,0.5,0.5\n");
    (dir, p.display().to_string(), q.display().to_string())
}

#[test]
fn gather_returns_the_exact_k_nearest() {
    // Integer positions spanning [0, 1023] on the longest axis: at 10 bits the grid
    // step is exactly 1, so grid distances are true distances.
    let mut r = rand_pcg::Pcg64Mcg::seed_from_u64(3);
    let mut photons: Vec<[f64; 3]> = (0..500)
        .map(|_| {
            [
                r.gen_range(0..1024) as f64,
                r.gen_range(0..1024) as f64,
                r.gen_range(0..512) as f64,
            ]
        })
        .collect();
    photons.push([0.0, 0.0, 0.0]);
    photons.push([1023.0, 0.0, 0.0]);
    let queries: Vec<[f64; 3]> = (0..30)
        .map(|_| {
            [
                r.gen_range(0..1024) as f64,
                r.gen_range(0..1024) as f64,
                r.gen_range(0..512) as f64,
            ]
        })
        .collect();
    let dir = tempfile::tempdir().unwrap();
    let p = write(dir.path(), "p.csv", &points_csv(&photons, true));
    let q = write(dir.path(), "q.csv", &points_csv(&queries, false));
    for (metric, k) in [("l2", 7), ("l1", 12)] {
        let out = dir.path().join(format!("out-{metric}.csv"));
        bin()
            .args([
                "gather",
                "--photons",
                p.to_str().unwrap(),
                "--queries",
                q.to_str().unwrap(),
            ])
            .args([
                "--k",
                &k.to_string(),
                "--metric",
                metric,
                "--out",
                out.to_str().unwrap(),
            ])
            .assert()
            .success();
        let text = std::fs::read_to_string(&out).unwrap();
        let mut lines = text.lines();
        assert_eq!(lines.next(), Some("query,rank,photon,distance"));
        let rows: Vec<Vec<f64>> = lines
            .map(|l| l.split(',').map(|f| f.parse().unwrap()).collect())
            .collect();
        assert_eq!(rows.len(), queries.len() * k);
        for (qi, qp) in queries.iter().enumerate() {
            let dist = |p: &[f64; 3]| world_dist(metric, p, qp);
            let truth = true_dists(metric, &photons, qp);
            let got: Vec<&Vec<f64>> = rows.iter().filter(|r| r[0] as usize == qi).collect();
            for (rank, row) in got.iter().enumerate() {
                assert_eq!(row[1] as usize, rank);
                let photon = &photons[row[2] as usize];
                assert!((dist(photon) - row[3]).abs() < 1e-9, "reported distance");
                assert!((truth[rank] - row[3]).abs() < 1e-9, "q{qi} rank {rank}");
            }
        }
    }
}

#[test]
fn missing_and_unreadable_files() {
    let (dir, p, q) = setup();
    let missing = dir.path().join("nope.csv").display().to_string();
    fails(
        dir.path(),
        &["--photons", &missing, "--queries", &q],
        "nope.csv: cannot open",
    );
    let d = dir.path().display().to_string();
    fails(
        dir.path(),
        &["--photons", &p, "--queries", &d],
        "cannot read",
    );
}

#[test]
fn malformed_line_names_file_line_and_text() {
    let (dir, _, q) = setup();
    let bad = write(dir.path(), "bad.csv", "x,y,z\n1,2,3\n4,five,6\n");
    fails(
        dir.path(),
        &["--photons", bad.to_str().unwrap(), "--queries", &q],
        "bad.csv:3: expected three numbers x,y,z, got '4,five,6'",
    );
    let short = write(dir.path(), "short.csv", "1,2,3\n1,2\n");
    fails(
        dir.path(),
        &["--photons", short.to_str().unwrap(), "--queries", &q],
        "short.csv:2:",
    );
}

#[test]
fn nan_and_inf() {
    let (dir, p, _) = setup();
    let nan = write(dir.path(), "nan.csv", "1,2,3\nNaN,0,0\n");
    fails(
        dir.path(),
        &["--photons", &p, "--queries", nan.to_str().unwrap()],
        "nan.csv:2: coordinates must be finite",
    );
    let inf = write(dir.path(), "inf.csv", "1,inf,3\n");
    fails(
        dir.path(),
        &["--photons", inf.to_str().unwrap(), "--queries", &p],
        "inf.csv:1: coordinates must be finite",
    );
}

#[test]
fn bad_parameters() {
    let (dir, p, q) = setup();
    fails(
        dir.path(),
        &["--photons", &p, "--queries", &q, "--k", "0"],
        "--k must be at least 1",
    );
    fails(
        dir.path(),
        &["--photons", &p, "--queries", &q, "--radius", "-1"],
        "--radius must be a finite number >= 0, got -1",
    );
    fails(
        dir.path(),
        &["--photons", &p, "--queries", &q, "--capacity", "1"],
        "2 photons exceed the configured capacity of 1",
    );
    fails(
        dir.path(),
        &["--photons", &p, "--queries", &q, "--metric", "l3"],
        "invalid value 'l3' for '--metric <METRIC>'",
    );
    fails(
        dir.path(),
        &["--photons", &p, "--queries", &q, "--backend", "gpu"],
        "invalid value 'gpu' for '--backend <BACKEND>'",
    );
    fails(
        dir.path(),
        &["--photons", &p, "--queries", &q, "--bits", "40"],
        "--bits 40 is out of range",
    );
}

#[test]
fn empty_photon_set() {
    let (dir, _, q) = setup();
    let empty = write(dir.path(), "empty.csv", "x,y,z\n");
    fails(
        dir.path(),
        &["--photons", empty.to_str().unwrap(), "--queries", &q],
        "the photon set is empty",
    );
}

/// export-verilog writes the core, its event-driven-simulator rewrite and the shell;
/// a core beyond the limits is refused with exit status 2 and no files.
#[test]
fn export_verilog_files_and_errors() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("v");
    let args = [
        "export-verilog",
        "--k",
        "3",
        "--bits",
        "4",
        "--address-bits",
        "4",
    ];
    bin()
        .args(args)
        .args(["--queries-per-port", "2", "--shell-trees", "2", "--out"])
        .arg(&out)
        .assert()
        .success();
    let core = std::fs::read_to_string(out.join("photon_search_core.v")).unwrap();
    let sim = std::fs::read_to_string(out.join("photon_search_core_sim.v")).unwrap();
    let shell = std::fs::read_to_string(out.join("shell.v")).unwrap();
    assert!(core.contains("module top("));
    assert!(sim.contains("module top(") && sim.contains("__xs") && !core.contains("__xs"));
    assert!(shell.contains("top core_0(") && shell.contains("top core_1("));

    // Refused exports create nothing (`refused` compares the directory listing).
    let bad = dir.path().join("bad").display().to_string();
    let export = |extra: &[&str]| cmdline(&["export-verilog", "--out", &bad], extra);
    refused(
        dir.path(),
        &export(&["--paper", "--k", "65"]),
        "K = 65 unsupported by the modules controller (1..=64)",
    );

    // Replicated trees: T = 3 cores inside one top; T = 9 is refused.
    let array = dir.path().join("array");
    bin()
        .args(args)
        .args(["--queries-per-port", "2", "--trees", "3", "--out"])
        .arg(&array)
        .assert()
        .success();
    let core = std::fs::read_to_string(array.join("photon_search_core.v")).unwrap();
    assert_eq!(core.matches("module top(").count(), 1);
    for t in 0..3 {
        assert!(core.contains(&format!("trees${t}$")), "tree {t} missing");
    }
    assert!(!core.contains("trees$3$"));
    refused(
        dir.path(),
        &export(&["--trees", "9"]),
        "trees = 9: replicated trees unsupported (1..=8)",
    );
    refused(
        dir.path(),
        &export(&["--shell-trees", "0"]),
        "--shell-trees must be at least 1",
    );
}

// ---- Issue 13: every CLI promise kept. One test per class of failure. ----

fn strings(args: &[&str]) -> Vec<String> {
    args.iter().map(|s| s.to_string()).collect()
}

/// A command line: `head` then `tail`.
fn cmdline(head: &[&str], tail: &[&str]) -> Vec<String> {
    strings(&[head, tail].concat())
}

/// Run gather successfully and return the output's lines.
fn gather_lines(args: &[&str], out: &Path) -> Vec<String> {
    bin()
        .arg("gather")
        .args(args)
        .arg("--out")
        .arg(out)
        .assert()
        .success();
    std::fs::read_to_string(out)
        .unwrap()
        .lines()
        .map(String::from)
        .collect()
}

mod backends;
mod banked;
mod core_file;
mod exact;
mod limits;
