//! `photon-fpga-lab bench-core`: a core simulated on a workload, checked query by
//! query against the software search; its refusals.

use crate::cli::*;

/// Issue 14: `bench-core` runs a stream on both engines (it fails if results,
/// cycles or read counters differ) and a Cornell-box image's whole eye-ray stream
/// under Verilator, checked query by query against the software search.
#[test]
#[cfg_attr(not(has_verilator), ignore = "needs verilator")]
fn bench_core_runs_both_engines_and_a_whole_cornell_stream() {
    let out = bin()
        .args(["bench-core", "--queries", "20", "--address-bits", "6"])
        .args(["--queries-per-port", "3", "--both-engines"])
        .assert()
        .success();
    let text = String::from_utf8_lossy(&out.get_output().stdout).to_string();
    assert!(
        text.contains("same stream, same results and cycles"),
        "{text}"
    );
    let out = bin()
        .args([
            "bench-core",
            "--engine",
            "verilator",
            "--workload",
            "cornell",
        ])
        .args(["--cornell-photons", "3000", "--cornell-size", "12x10"])
        .args(["--k", "8", "--metric", "l2", "--fit-q"])
        .assert()
        .success();
    let text = String::from_utf8_lossy(&out.get_output().stdout).to_string();
    // At most one query per pixel (one sample each), and most pixels see a
    // diffuse surface.
    let queries: usize = text
        .split(" queries, ")
        .next()
        .and_then(|s| s.rsplit(' ').next())
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("no query count in {text}"));
    assert!((100..=120).contains(&queries), "{queries} queries: {text}");
    assert!(text.contains("equal per query"), "{text}");
}

/// Class 9: bench-core refuses a stream of no queries and a clock that is not a
/// finite positive number before simulating anything.
#[test]
fn bench_core_refuses_no_queries_and_bad_clocks() {
    let dir = tempfile::tempdir().unwrap();
    refused(
        dir.path(),
        &strings(&["bench-core", "--queries", "0"]),
        "--queries must be at least 1, got 0",
    );
    for f in ["NaN", "inf", "-inf", "0", "-5"] {
        refused(
            dir.path(),
            &strings(&["bench-core", &format!("--fmax-mhz={f}")]),
            "--fmax-mhz must be a finite number > 0",
        );
    }
}

/// A core file (written by the product's `core_file::to_toml`) runs a Cornell map
/// on its own core, H and K the file's; a radius-limited file refuses an unbounded
/// gather by name; an option the file fixes cannot be given beside it.
#[test]
fn bench_core_runs_the_core_of_a_file() {
    use photon_fpga::hw::config::controller::Controller;
    use photon_fpga::hw::config::core_config::CoreConfig;
    use photon_fpga::hw::config::core_file::to_toml;
    use photon_fpga::hw::config::metric::Metric;
    use photon_fpga::hw::config::photon_word::PhotonLayout;
    use photon_fpga::hw::config::traversal::Traversal;
    let dir = tempfile::tempdir().unwrap();
    let write = |name: &str, cfg: &CoreConfig| {
        let p = dir.path().join(name);
        std::fs::write(&p, to_toml(cfg)).unwrap();
        p.display().to_string()
    };
    let barrel = CoreConfig::builder()
        .controller(Controller::Barrel)
        .k(5)
        .layout(PhotonLayout::new([7; 3]))
        .address_bits(11);
    let f = write("core.toml", &barrel.build().unwrap());
    let cornell = [
        "--workload",
        "cornell",
        "--cornell-photons",
        "200",
        "--cornell-size",
        "6x6",
    ];
    let bench = stdout_of(
        &[
            strings(&["bench-core", "--core", &f, "--queries", "12"]),
            strings(&cornell),
        ]
        .concat(),
    );
    let core = bench.lines().find(|l| l.starts_with("core: ")).unwrap();
    assert!(
        core.contains("barrel controller") && core.contains("H = 11, K = 5"),
        "{core}"
    );
    let radius = write(
        "radius.toml",
        &barrel
            .traversal(Traversal::Cell)
            .metric(Metric::L2)
            .radius_bits(Some(8))
            .build()
            .unwrap(),
    );
    refused(
        dir.path(),
        &[strings(&["bench-core", "--core", &radius]), strings(&cornell)].concat(),
        "an unbounded gather (no --radius) is beyond the core: radius_bits = 8 answers radii up to 254",
    );
    refused(
        dir.path(),
        &strings(&["bench-core", "--core", &f, "--address-bits", "6"]),
        &format!("--address-bits cannot be used with --core {f}: the file gives the whole core"),
    );
    refused(
        dir.path(),
        &strings(&[
            "bench-core",
            "--traversal",
            "reread",
            "--controller",
            "barrel",
        ]),
        "traversal = reread with controller barrel",
    );
}

/// `bench-core --workload two-pass`: the two-pass render's final gathers, capped
/// at the render's radius, through the core; every answer equals the software
/// search's.
#[test]
fn bench_core_runs_the_two_pass_lookups() {
    let bench = stdout_of(&strings(&[
        "bench-core",
        "--workload",
        "two-pass",
        "--cornell-photons",
        "400",
        "--cornell-size",
        "6x5",
        "--queries",
        "40",
        "--k",
        "6",
        "--metric",
        "l2",
    ]));
    assert!(bench.contains("equal per query"), "{bench}");
    assert!(bench.contains(" 40 queries,"), "{bench}");
    let core = bench.lines().find(|l| l.starts_with("core: ")).unwrap();
    assert!(core.contains("world units) on the grid"), "{core}");
}

/// `bench-core --workload two-pass` on a banked core (the two-pass gather stream
/// on the hardware): the final gathers through banks behind the crossbar, two
/// replicas of the top levels (four datapaths) and two result streams, every
/// answer equal to the software search's (bench-core refuses a disagreement).
#[test]
fn bench_core_runs_the_two_pass_lookups_on_a_banked_core() {
    let bench = stdout_of(&strings(&[
        "bench-core",
        "--workload",
        "two-pass",
        "--cornell-photons",
        "400",
        "--cornell-size",
        "6x5",
        "--queries",
        "40",
        "--k",
        "6",
        "--metric",
        "l2",
        "--controller",
        "barrel",
        "--traversal",
        "cell",
        "--banks",
        "4",
        "--replicas",
        "2",
        "--replicated-levels",
        "3",
        "--bank-ports",
        "split",
        "--result-streams",
        "2",
    ]));
    assert!(bench.contains("equal per query"), "{bench}");
    assert!(bench.contains(" 40 queries,"), "{bench}");
    let core = bench.lines().find(|l| l.starts_with("core: ")).unwrap();
    assert!(core.contains("world units) on the grid"), "{core}");
    // Four datapaths read, and the two result streams both carry answers.
    let ports = bench
        .lines()
        .find(|l| l.starts_with("reads per port per cycle (whole run): "))
        .unwrap();
    assert_eq!(ports.split(", ").count(), 4, "{ports}");
    let streams = bench
        .lines()
        .find(|l| l.starts_with("result stream: "))
        .unwrap();
    assert!(streams.contains("per stream"), "{streams}");
}

/// `bench-core --workload two-pass-irradiance`: the 1-nearest lookups of the
/// precomputed-irradiance render in its irradiance points, through a banked K = 1
/// core, every answer equal to the software search's; any other k is refused.
#[test]
fn bench_core_runs_the_irradiance_lookups() {
    let args = |k: &str| {
        strings(&[
            "bench-core",
            "--workload",
            "two-pass-irradiance",
            "--cornell-photons",
            "400",
            "--cornell-size",
            "6x5",
            "--queries",
            "40",
            "--k",
            k,
            "--metric",
            "l2",
            "--controller",
            "barrel",
            "--traversal",
            "cell",
            "--banks",
            "4",
            "--replicas",
            "2",
            "--replicated-levels",
            "3",
            "--bank-ports",
            "split",
        ])
    };
    let bench = stdout_of(&args("1"));
    assert!(bench.contains("equal per query"), "{bench}");
    assert!(bench.contains(" 40 queries,"), "{bench}");
    let core = bench.lines().find(|l| l.starts_with("core: ")).unwrap();
    assert!(core.contains("K = 1,"), "{core}");
    // The map is the irradiance points: about a quarter of the photons the
    // `two-pass` workload's map holds for the same emitted photons.
    let photons = |text: &str| -> usize {
        let line = text.lines().find(|l| l.contains(" photons, ")).unwrap();
        line.split(' ').next().unwrap().parse().unwrap()
    };
    let global = stdout_of(&strings(&[
        "bench-core",
        "--workload",
        "two-pass",
        "--cornell-photons",
        "400",
        "--cornell-size",
        "6x5",
        "--queries",
        "40",
        "--k",
        "6",
        "--metric",
        "l2",
    ]));
    assert_eq!(photons(&bench), photons(&global).div_ceil(4));
    let dir = tempfile::tempdir().unwrap();
    refused(
        dir.path(),
        &args("4"),
        "--workload two-pass-irradiance makes 1-nearest lookups: give --k 1, got 4",
    );
}
