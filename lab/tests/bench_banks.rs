//! `photon-fpga-lab bench-banks`: the banked core's simulated sweeps. The reads the
//! report gives are the software search's on the same map and queries (an
//! independent count), every point within what its datapaths can read, and bad
//! input is refused by name with exit status 2 and nothing written.

use crate::cli::*;
use photon_fpga::host::map::knn::search_with;
use photon_fpga::host::render::RenderSettings;
use photon_fpga::hw::config::metric::Metric;
use photon_fpga::hw::config::traversal::Traversal;
use photon_fpga_lab::workload;

const TINY: [&str; 20] = [
    "bench-banks",
    "--photons",
    "400",
    "--size",
    "8x8",
    "--spp",
    "1",
    "--k",
    "6",
    "--datapaths",
    "2,4",
    "--banks",
    "1,4",
    "--bank-ports",
    "shared,split",
    "--map-photons",
    "300",
    "--map-queries",
    "40",
    "--engine",
];

#[test]
fn bench_banks_reports_the_software_searchs_reads() {
    let dir = tempfile::tempdir().unwrap();
    bin()
        .args(TINY)
        .args(["native", "--out"])
        .arg(dir.path())
        .assert()
        .success();
    for f in [
        "BANKED_CORE.md",
        "banked_conflicts.png",
        "banked_map_sizes.png",
    ] {
        assert!(dir.path().join(f).metadata().unwrap().len() > 0, "{f}");
    }
    // The same map and queries, searched in software (squared L2, cell traversal).
    let settings = RenderSettings {
        width: 8,
        height: 8,
        spp: 1,
        seed: 1,
        ..RenderSettings::default()
    };
    let w = workload::cornell_image(400, usize::MAX, 10, &settings);
    let max = u64::MAX >> 1;
    let reads: u64 = w
        .queries
        .iter()
        .map(|&q| search_with(&w.tree, q, 6, max, Metric::L2, Traversal::Cell).visited as u64)
        .sum();
    let csv = std::fs::read_to_string(dir.path().join("banked_core.csv")).unwrap();
    let rows: Vec<Vec<&str>> = csv
        .lines()
        .skip(1)
        .map(|l| l.split(',').collect())
        .collect();
    let curve: Vec<&Vec<&str>> = rows.iter().filter(|r| r[0] == "conflicts").collect();
    // D = 2 with and without banks, D = 4 with banks (four datapaths of whole
    // copies would be an array, not one banked core), each banked shape with both
    // port modes (one whole copy has no bank ports).
    let shapes: Vec<(&str, &str, &str)> = curve.iter().map(|r| (r[2], r[3], r[4])).collect();
    assert_eq!(
        shapes,
        [
            ("2", "1", "–"),
            ("2", "4", "shared"),
            ("2", "4", "split"),
            ("4", "4", "shared"),
            ("4", "4", "split")
        ]
    );
    for r in &curve {
        assert_eq!(r[1], w.tree.len().to_string(), "photons");
        assert_eq!(r[7], w.queries.len().to_string(), "queries");
        assert_eq!(
            r[9],
            reads.to_string(),
            "the core's reads are the software search's"
        );
        let (d, rpc): (f64, f64) = (r[2].parse().unwrap(), r[11].parse().unwrap());
        assert!(rpc > 0.0 && rpc <= d, "reads/cycle {rpc} with D = {d}");
    }
    assert_eq!(rows.iter().filter(|r| r[0] == "map_size").count(), 1);
}

/// `--map-photons` with no value runs the conflict curve alone.
#[test]
fn bench_banks_without_a_map_sweep() {
    let dir = tempfile::tempdir().unwrap();
    let mut args = TINY.to_vec();
    let at = args.iter().position(|&a| a == "--map-photons").unwrap();
    args.remove(at + 1);
    bin()
        .args(args)
        .args(["native", "--out"])
        .arg(dir.path())
        .assert()
        .success();
    let csv = std::fs::read_to_string(dir.path().join("banked_core.csv")).unwrap();
    let sweeps: Vec<&str> = csv
        .lines()
        .skip(1)
        .filter_map(|l| l.split(',').next())
        .collect();
    assert!(
        !sweeps.is_empty() && sweeps.iter().all(|&s| s == "conflicts"),
        "{csv}"
    );
}

#[test]
fn bench_banks_refuses_bad_input_by_name() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().to_string_lossy().to_string();
    let with = |extra: &[&str]| -> Vec<String> {
        let mut a: Vec<String> = TINY.iter().map(|s| s.to_string()).collect();
        a.push("native".into());
        a.extend(extra.iter().map(|s| s.to_string()));
        a.extend(["--out".to_string(), out.clone()]);
        a
    };
    refused(dir.path(), &with(&["--datapaths", "3"]), "--datapaths 3");
    refused(dir.path(), &with(&["--datapaths", "34"]), "--datapaths 34");
    refused(dir.path(), &with(&["--banks", "6"]), "--banks 6");
    refused(dir.path(), &with(&["--map-queries", "0"]), "--map-queries");
    refused(dir.path(), &with(&["--fmax-mhz", "0"]), "--fmax-mhz");
    refused(dir.path(), &with(&["--k", "0"]), "--k");
}
