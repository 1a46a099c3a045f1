//! `photon-fpga-lab study` through the binary: `--quick` writes the table,
//! the CSV and the plots, and the table keeps its invariants (its `--exact` series:
//! `study_exact`); the error measures against independent computations; bad input
//! refused before any work.

use assert_cmd::Command;
use photon_fpga::host::gather::{FloatBackend, GatherBackend, GatherParams, Gathered, Neighbour};
use photon_fpga::hw::config::controller::Controller;
use photon_fpga::hw::config::metric::Metric;
use photon_fpga::hw::config::traversal::Traversal;
use photon_fpga_lab::study::hwcost::{cost, SynthResults};
use photon_fpga_lab::study::metrics::{host_radius, radius_rel_error, recall, rel_rmse};
use photon_fpga_lab::study::plan::STUDY_CONTROLLER;
use rand::{Rng, SeedableRng};
use std::collections::BTreeMap;
use std::path::Path;

/// The repository (the lab crate is one folder below it): the study reads
/// synth/results.json and writes docs/ from there.
fn repo() -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn bin() -> Command {
    Command::cargo_bin("photon-fpga-lab").unwrap()
}

/// Columns that hold text (names, sources) rather than numbers.
const TEXT: [&str; 8] = [
    "scene",
    "metric",
    "hw_capable",
    "hw_reads_source",
    "fmax_source",
    "luts",
    "ffs",
    "area_source",
];

fn run_quick(out: &Path, threads: &str) -> Vec<BTreeMap<String, String>> {
    bin()
        .current_dir(repo())
        .args(["study", "--quick", "--threads", threads, "--out"])
        .arg(out)
        .assert()
        .success();
    read_csv(&out.join("study.csv"))
}

fn read_csv(path: &Path) -> Vec<BTreeMap<String, String>> {
    let mut r = csv::Reader::from_path(path).unwrap();
    let header: Vec<String> = r.headers().unwrap().iter().map(String::from).collect();
    r.records()
        .map(|rec| {
            let rec = rec.unwrap();
            header
                .iter()
                .cloned()
                .zip(rec.iter().map(String::from))
                .collect()
        })
        .collect()
}

fn num(row: &BTreeMap<String, String>, col: &str) -> f64 {
    row[col]
        .parse()
        .unwrap_or_else(|_| panic!("{col} = {:?}", row[col]))
}

#[test]
fn quick_study_writes_a_complete_table_whose_error_falls_with_bits() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("study");
    let rows = run_quick(&out, "2");
    assert!(!rows.is_empty());
    // Every number present: finite, or an explicit "n/a: why".
    for row in &rows {
        for (col, v) in row {
            assert!(!v.is_empty(), "empty {col} in {row:?}");
            if !TEXT.contains(&col.as_str()) && !v.starts_with("n/a") {
                let x: f64 = v.parse().unwrap_or_else(|_| panic!("{col} = {v:?}"));
                assert!(x.is_finite(), "{col} = {v}");
            }
        }
    }
    // Per scene, photons, metric and k: error against float falls (non-strictly,
    // 2% noise allowed) as bits grow, and 16 bits is within 0.1% of float.
    let mut groups: BTreeMap<Vec<String>, Vec<(u32, f64)>> = BTreeMap::new();
    for row in &rows {
        let key: Vec<String> = ["scene", "emitted", "metric", "k"]
            .iter()
            .map(|c| row[*c].clone())
            .collect();
        groups
            .entry(key)
            .or_default()
            .push((num(row, "bits") as u32, num(row, "rel_rmse_vs_float")));
    }
    for (key, mut v) in groups {
        v.sort_by_key(|p| p.0);
        for w in v.windows(2) {
            assert!(w[1].1 <= w[0].1 * 1.02 + 1e-5, "{key:?}: error rises {w:?}");
        }
        let (bits, err) = *v.last().unwrap();
        assert_eq!(bits, 16);
        assert!(err <= 1e-3, "{key:?}: 16 bits at {err} of float");
        assert!(v[0].1 > err, "{key:?}: 6 bits no worse than 16?");
    }
    // The core's columns: simulated where it can run, labelled n/a where it cannot.
    for row in &rows {
        if row["bits"] == "16" {
            assert!(row["hw_reads_per_cycle"].starts_with("n/a"), "{row:?}");
        } else {
            let rpc = num(row, "hw_reads_per_cycle");
            assert!(
                rpc > 0.0 && rpc <= 2.0,
                "two ports read at most 2 per cycle: {rpc}"
            );
            assert!(row["hw_reads_source"].starts_with("simulated"));
        }
        assert!(num(row, "recall_at_k") <= 1.0);
    }
    let md = std::fs::read_to_string(out.join("STUDY.md")).unwrap();
    assert!(
        md.contains("| l1 | 10 | 10 |") && md.contains("[P&R]"),
        "{md}"
    );
    for png in [
        "pareto.png",
        "exact.png",
        "fig3.png",
        "fig4.png",
        "fig5.png",
        "fig6.png",
    ] {
        let bytes = std::fs::read(out.join(png)).unwrap();
        assert!(bytes.starts_with(b"\x89PNG\r\n\x1a\n"), "{png}: not a PNG");
        let img = image::load_from_memory_with_format(&bytes, image::ImageFormat::Png)
            .unwrap_or_else(|e| panic!("{png}: {e}"));
        assert!(img.width() >= 800 && img.height() >= 400, "{png}");
        // Drawn on: more than a blank page.
        let rgb = img.to_rgb8();
        let inked = rgb.pixels().filter(|p| p.0 != [255, 255, 255]).count();
        assert!(inked > 1000, "{png}: {inked} non-white pixels");
    }
    crate::study_exact::check_exact_series(&out, &md);
    // Same seed, same table whatever the thread count (the measured software
    // queries/s, the last column, aside).
    let again = run_quick(&dir.path().join("again"), "1");
    let strip = |rows: &[BTreeMap<String, String>]| -> Vec<BTreeMap<String, String>> {
        rows.iter()
            .map(|r| {
                let mut r = r.clone();
                r.remove("sw_queries_per_s_measured");
                r
            })
            .collect()
    };
    assert_eq!(strip(&rows), strip(&again));
    // The exact series has no measured column: the same bytes.
    assert!(
        std::fs::read(out.join("exact.csv")).unwrap()
            == std::fs::read(dir.path().join("again/exact.csv")).unwrap(),
        "exact.csv depends on the thread count"
    );
}

#[test]
fn quick_study_runs_and_costs_the_chosen_core() {
    // The barrel core (cell traversal by default with it): its simulation is
    // checked query by query against the software search inside the study, and
    // its clock and area must be the barrel row's of results.json, read here
    // independently of the study's own reader.
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("barrel");
    bin()
        .current_dir(repo())
        .args(["study", "--quick", "--controller", "barrel", "--out"])
        .arg(&out)
        .assert()
        .success();
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(repo().join("synth/results.json")).unwrap())
            .unwrap();
    let barrel = json["rows"]
        .as_array()
        .unwrap()
        .iter()
        .find(|r| {
            let o = &r["core"];
            o["controller"] == "barrel"
                && o["traversal"] == "cell"
                && o["trees"] == 1
                && o["banks"].is_null()
                && o["k"] == 10
                && o["coordinate_bits"] == serde_json::json!([10, 10, 10])
                && o["metric"] == "l1"
                && r["ecp5"].is_object()
        })
        .expect("results.json has a routed single barrel core");
    let fmax = barrel["ecp5"]["fmax_mhz"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| f.as_f64().unwrap())
        .fold(0.0, f64::max);
    let mut r = csv::Reader::from_path(out.join("study.csv")).unwrap();
    let header: Vec<String> = r.headers().unwrap().iter().map(String::from).collect();
    let col = |name: &str| header.iter().position(|h| h == name).unwrap();
    let mut seen = 0;
    for rec in r.records() {
        let rec = rec.unwrap();
        if &rec[col("metric")] == "l1" && &rec[col("k")] == "10" && &rec[col("bits")] == "10" {
            seen += 1;
            assert!(
                rec[col("hw_reads_source")].contains("query slots"),
                "{rec:?}"
            );
            let f: f64 = rec[col("fmax_mhz")].parse().unwrap();
            assert!(
                (f - fmax).abs() < 0.05,
                "fmax {f} against the barrel row's {fmax}"
            );
            assert!(
                rec[col("fmax_source")].contains(barrel["name"].as_str().unwrap()),
                "{rec:?}"
            );
        }
    }
    assert!(seen > 0, "no l1 k=10 10-bit point in the quick study");
    let md = std::fs::read_to_string(out.join("STUDY.md")).unwrap();
    assert!(
        md.contains("--controller barrel"),
        "the regenerate line names the core"
    );
}

#[test]
fn study_refuses_bad_input_before_any_work_and_leaves_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("file");
    std::fs::write(&file, "x").unwrap();
    let listing = || {
        let mut v: Vec<String> = std::fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    };
    let before = listing();
    let cases: Vec<(Vec<String>, &str)> = vec![
        (
            vec!["--out".into(), file.display().to_string()],
            "is not a directory",
        ),
        (
            vec![
                "--scene".into(),
                dir.path().join("none.toml").display().to_string(),
                "--out".into(),
                dir.path().join("o").display().to_string(),
            ],
            "none.toml",
        ),
        (
            vec![
                "--report".into(),
                dir.path().join("R.md").display().to_string(),
                "--out".into(),
                dir.path().join("o").display().to_string(),
            ],
            "R.md: cannot read the synthesis report",
        ),
        (
            vec![
                "--out".into(),
                dir.path().join("no/such/dir").display().to_string(),
            ],
            "no/such/dir",
        ),
        (
            vec![
                "--controller".into(),
                "barrel".into(),
                "--queries-per-port".into(),
                "40".into(),
                "--out".into(),
                dir.path().join("o").display().to_string(),
            ],
            "queries_per_port = 40 unsupported",
        ),
        (
            vec![
                "--controller".into(),
                "barrel".into(),
                "--traversal".into(),
                "reread".into(),
                "--out".into(),
                dir.path().join("o").display().to_string(),
            ],
            "reread",
        ),
    ];
    for (args, msg) in cases {
        let a = bin()
            .current_dir(repo())
            .arg("study")
            .arg("--quick")
            .args(&args)
            .assert()
            .code(2);
        let stderr = String::from_utf8_lossy(&a.get_output().stderr).to_string();
        assert!(stderr.contains(msg), "{args:?}: {stderr}");
        assert_eq!(listing(), before, "{args:?} left files behind");
    }
}

fn gathered(ids: &[(u32, f64)]) -> Gathered {
    Gathered {
        neighbours: ids
            .iter()
            .map(|&(photon, distance)| Neighbour { photon, distance })
            .collect(),
        visited: 0,
    }
}

#[test]
fn error_measures_against_hand_and_brute_force() {
    // rel. RMSE by hand: error (3, 4) on a reference of norm 10 is 0.5.
    let want = [[6.0, 8.0, 0.0]];
    assert_eq!(rel_rmse(&[[9.0, 12.0, 0.0]], &want), 0.5);
    assert_eq!(rel_rmse(&want, &want), 0.0);
    // Recall and radius error by hand.
    let truth = [gathered(&[(1, 1.0), (2, 2.0)]), gathered(&[(5, 4.0)])];
    let got = [gathered(&[(2, 1.5), (7, 3.0)]), gathered(&[(5, 5.0)])];
    assert_eq!(recall(&got, &truth), 0.75);
    assert_eq!(radius_rel_error(&got, &truth), (0.5 + 0.25) / 2.0);
    // Recall of the float search against brute force on random points is 1.
    let mut r = rand_pcg::Pcg64Mcg::seed_from_u64(3);
    let pts: Vec<[f64; 3]> = (0..2000).map(|_| [r.gen(), r.gen(), r.gen()]).collect();
    let qs: Vec<[f64; 3]> = (0..50).map(|_| [r.gen(), r.gen(), r.gen()]).collect();
    let params = GatherParams {
        k: 12,
        metric: Metric::L1,
        ..GatherParams::default()
    };
    let float = FloatBackend::new(&pts, &params)
        .unwrap()
        .gather(&qs)
        .unwrap();
    let brute: Vec<Gathered> = qs
        .iter()
        .map(|&q| {
            let d = |p: &[f64; 3]| (0..3).map(|a| (p[a] - q[a]).abs()).sum::<f64>();
            let mut all: Vec<(u32, f64)> = pts
                .iter()
                .enumerate()
                .map(|(i, p)| (i as u32, d(p)))
                .collect();
            all.sort_by(|a, b| a.1.total_cmp(&b.1));
            all.truncate(12);
            gathered(&all)
        })
        .collect();
    assert_eq!(recall(&float, &brute), 1.0);
    assert!(radius_rel_error(&float, &brute) < 1e-12);
    // The host's radius from float positions is the float search's own.
    let host = host_radius(&float, &qs, &pts, Metric::L1);
    for (h, f) in host.iter().zip(&float) {
        assert_eq!(h.neighbours.len(), f.neighbours.len());
        for (a, b) in h.neighbours.iter().zip(&f.neighbours) {
            assert!((a.distance - b.distance).abs() < 1e-12, "{a:?} {b:?}");
        }
    }
}

fn results() -> SynthResults {
    SynthResults::read(&repo().join("synth/results.json")).unwrap()
}

#[test]
fn results_rows_give_clocks_and_areas_with_their_source() {
    let all = results();
    let rows = all.study_rows(Traversal::Cell, STUDY_CONTROLLER);
    // Only single-tree, pipelined cores of the study's own traversal and controller.
    for r in &rows {
        let o = &all.rows.iter().find(|x| x.name == r.name).unwrap().core;
        assert_eq!(
            (
                o.choice.trees,
                o.build.banks,
                o.build.pipelined,
                o.choice.traversal,
                o.choice.controller
            ),
            (
                Some(1),
                None,
                Some(true),
                Some(Traversal::Cell),
                Some(STUDY_CONTROLLER)
            ),
            "{}",
            r.name
        );
    }
    let c = cost(&rows, 10, 10, Metric::L1);
    let f = c
        .fmax_mhz
        .expect("the study's core at the paper's k and bits has a placed-and-routed clock");
    assert!(c.fmax_source.starts_with("placed-and-routed"), "{c:?}");
    // That clock is the best seed of a matching record.
    assert!(all.rows.iter().any(|r| r.core.build.k == Some(10)
        && r.core.build.coordinate_bits.is_some_and(|w| w.0 == [10; 3])
        && r.core.build.metric == Some(Metric::L1)
        && r.ecp5
            .as_ref()
            .is_some_and(|e| e.fmax_mhz.iter().all(|&s| s <= f) && e.fmax_mhz.contains(&f))));
    // A configuration the results lack is never given its own numbers.
    let other = cost(&rows, 32, 13, Metric::L2);
    assert_eq!(other.luts, "not in REPORT.md");
    assert!(other.fmax_mhz.is_none() || other.fmax_source.starts_with("assumed"));
    // A synthetic record: matched by its options, not its name; a cell-traversal
    // record of the same k, bits and metric is not the study's core.
    let record = |name: &str, traversal: &str, fmax: &str| {
        format!(
            r#"{{"name": "{name}", "core": {{"k": 10, "coordinate_bits": [10, 10, 10], "address_bits": 10,
            "queries_per_port": 7, "metric": "l2", "traversal": "{traversal}",
            "controller": "modules", "trees": 1, "pipelined": true}},
            "xc6v": {{"luts": 1234, "lutram": 0, "ffs": 567}},
            "ecp5": {{"fmax_mhz": [{fmax}], "error": null}}, "status": null}}"#
        )
    };
    let text = format!(
        r#"{{"schema": 2, "rows": [{}, {}]}}"#,
        record("cell one", "cell", "99.0"),
        record("any name", "remember", "39.0, 40.5")
    );
    let synthetic = SynthResults::parse(&text, Path::new("x.json")).unwrap();
    let rows = synthetic.study_rows(Traversal::default(), Controller::default());
    let c = cost(&rows, 10, 10, Metric::L2);
    assert_eq!(
        (c.fmax_mhz, c.luts.as_str(), c.ffs.as_str()),
        (Some(40.5), "1,234", "567")
    );
    assert!(c.area_source.contains("'any name' (2 x 7)"), "{c:?}");
    // Bad data is refused with the file's name.
    let bad = text.replace("\"l2\"", "\"l3\"");
    let e = SynthResults::parse(&bad, Path::new("x.json")).unwrap_err();
    assert!(
        e.to_string().contains("x.json") && e.to_string().contains("l3"),
        "{e}"
    );
}

/// A core of K answers every k up to K: a study point without a row of its own k
/// takes the clock and area of the smallest K above it (same bits and metric) and
/// says so; with no such row, the clock assumed is the nearest K's, not a small
/// core's.
#[test]
fn a_larger_k_row_costs_the_k_it_holds_and_says_so() {
    let record = |name: &str, k: usize, bits: u32, fmax: &str| {
        format!(
            r#"{{"name": "{name}", "core": {{"k": {k}, "coordinate_bits": [{bits}, {bits}, {bits}], "address_bits": 10,
            "queries_per_port": 16, "metric": "l2", "traversal": "cell",
            "controller": "barrel", "trees": 1, "pipelined": true}},
            "xc6v": {{"luts": {k}, "lutram": 0, "ffs": 1}},
            "ecp5": {{"fmax_mhz": [{fmax}], "error": null}}, "status": null}}"#
        )
    };
    let text = format!(
        r#"{{"schema": 2, "rows": [{}, {}, {}]}}"#,
        record("small", 10, 10, "99.0"),
        record("big", 512, 10, "48.0"),
        record("mid", 100, 10, "45.0")
    );
    let all = SynthResults::parse(&text, Path::new("x.json")).unwrap();
    let rows = all.study_rows(Traversal::Cell, Controller::Barrel);
    // k = 500 at 10 bits: the K = 512 row, placed and routed, labelled as holding it.
    let c = cost(&rows, 500, 10, Metric::L2);
    assert_eq!((c.fmax_mhz, c.luts.as_str()), (Some(48.0), "512"));
    assert!(c.fmax_source.starts_with("placed-and-routed"), "{c:?}");
    assert!(
        c.fmax_source.contains("'big', K = 512 holds k = 500"),
        "{c:?}"
    );
    assert!(c.area_source.contains("K = 512 holds k = 500"), "{c:?}");
    // k = 64: the smallest K above it is 100, not 512.
    assert_eq!(cost(&rows, 64, 10, Metric::L2).fmax_mhz, Some(45.0));
    // An exact row wins and carries no note.
    let exact = cost(&rows, 100, 10, Metric::L2);
    assert_eq!(exact.fmax_mhz, Some(45.0));
    assert!(!exact.fmax_source.contains("holds"), "{exact:?}");
    // Other bits: no area, and the clock assumed from the nearest K (512 for 500,
    // 100 for 64), never the small core's.
    let other = cost(&rows, 500, 12, Metric::L2);
    assert_eq!(other.luts, "not in REPORT.md");
    assert_eq!(other.fmax_mhz, Some(48.0));
    assert!(other.fmax_source.starts_with("assumed"), "{other:?}");
    assert_eq!(cost(&rows, 64, 12, Metric::L2).fmax_mhz, Some(45.0));
    // Above every K: the largest K's clock, assumed.
    let above = cost(&rows, 600, 10, Metric::L2);
    assert_eq!(above.fmax_mhz, Some(48.0));
    assert!(above.fmax_source.starts_with("assumed"), "{above:?}");
}

/// The committed study (docs/study.csv, made by `photon-fpga-lab study --out docs`)
/// took its clocks and areas from these results: every hardware point's columns
/// are what `cost` gives now, so the selection by options picks the rows the study
/// used (and a rerun synthesis that changes them shows here until the study is rerun).
#[test]
fn committed_study_used_these_results() {
    let rows = results().study_rows(Traversal::Cell, STUDY_CONTROLLER);
    let mut r = csv::Reader::from_path(repo().join("docs/study.csv")).unwrap();
    let header: Vec<String> = r.headers().unwrap().iter().map(String::from).collect();
    let col = |n: &str| header.iter().position(|h| h == n).unwrap();
    let mut checked = 0;
    for rec in r.records() {
        let rec = rec.unwrap();
        if rec[col("fmax_mhz")].starts_with("n/a") {
            continue;
        }
        let metric = match &rec[col("metric")] {
            "l1" => Metric::L1,
            "l2" => Metric::L2,
            m => panic!("metric {m}"),
        };
        let c = cost(
            &rows,
            rec[col("k")].parse().unwrap(),
            rec[col("bits")].parse().unwrap(),
            metric,
        );
        // (The CSV keeps the clock to 0.1 MHz.)
        let fmax = c.fmax_mhz.map(|f| format!("{f:.1}"));
        assert_eq!(fmax.as_deref(), Some(&rec[col("fmax_mhz")]), "{rec:?}");
        assert_eq!(c.fmax_source, &rec[col("fmax_source")], "{rec:?}");
        assert_eq!(c.luts, &rec[col("luts")], "{rec:?}");
        assert_eq!(c.ffs, &rec[col("ffs")], "{rec:?}");
        assert_eq!(c.area_source, &rec[col("area_source")], "{rec:?}");
        checked += 1;
    }
    assert!(checked > 0);
}

/// python3 with `args` in the repository. python3 is one of the test tools (as
/// yosys and verilator are): missing, this fails rather than skips.
fn python3(args: &[&str]) -> std::process::Output {
    std::process::Command::new("python3")
        .args(args)
        .current_dir(repo())
        .output()
        .unwrap_or_else(|e| panic!("python3 is needed to check synth/report.py: {e}"))
}

/// REPORT.md and README.md's results table are the render of synth/results.json
/// (`synth/report.py render --check`), so neither can drift from the data.
#[test]
fn report_and_readme_are_the_render_of_results_json() {
    let out = python3(&["synth/report.py", "render", "--check"]);
    assert!(
        out.status.success(),
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
}

/// A row re-run step by step is rendered between its steps: simulated, not yet
/// placed. README's table then shows its reads and no rates (it used to stop the
/// run with an exception).
#[test]
fn a_simulated_row_without_a_clock_renders_without_rates() {
    let script = "import sys; sys.path.insert(0, 'synth'); import report as R
res = R.load_results()
r = next(r for r in res.rows if r.headline and not r.core.get('banks') and r.sim)
r.ecp5 = None
R.derive(r)
line = next(l for l in R.render_headline(res).splitlines() if l.startswith(f'| {r.name} '))
print(line)";
    let out = python3(&["-c", script]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let line = String::from_utf8_lossy(&out.stdout);
    let cells: Vec<&str> = line.trim().split('|').map(str::trim).collect();
    // | name | area | clock | reads/cycle | reads/query | queries/s | vs kiddo |
    assert_eq!(cells.len(), 9, "{line}");
    assert_eq!(cells[3], "–", "{line}");
    assert!(cells[4].parse::<f64>().is_ok(), "{line}");
    assert_eq!((cells[6], cells[7]), ("", ""), "{line}");
}
