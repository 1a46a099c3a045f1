//! The core description file (`export-verilog` writes it, `--core FILE` reads it):
//! it round-trips every option of a core, the same file exports the same Verilog,
//! one Verilator model serves maps of different sizes with the software search's
//! very image, and a map, a gather or a file that does not fit is refused by name
//! with exit status 2 and nothing written.

use super::*;
use photon_fpga::hw::config::bank_config::BankMapping;
use photon_fpga::hw::config::controller::Controller;
use photon_fpga::hw::config::core_config::CoreConfig;
use photon_fpga::hw::config::core_file::{from_toml, to_toml, CORE_FILE_NAME};
use photon_fpga::hw::config::metric::Metric;
use photon_fpga::hw::config::photon_word::PhotonLayout;
use photon_fpga::hw::config::traversal::Traversal;

/// Export a core with `options` into `dir/name` and return its description file.
fn export_core(dir: &Path, name: &str, options: &[&str]) -> PathBuf {
    let out = dir.join(name);
    bin()
        .args(["export-verilog", "--out"])
        .arg(&out)
        .args(options)
        .assert()
        .success();
    out.join(CORE_FILE_NAME)
}

/// Every option of `CoreConfig` survives the file: cores that differ in each
/// option, built by the library, read back equal; the file spells Q as the
/// command line does, and a file of an earlier export (Q under its controller's
/// name) reads the same.
#[test]
fn the_file_round_trips_every_option() {
    let b = CoreConfig::builder;
    let cores = [
        CoreConfig::paper(),
        b().controller(Controller::Barrel)
            .traversal(Traversal::Cell)
            .queries_per_port(11)
            .k(40)
            .build()
            .unwrap(),
        b().layout(PhotonLayout::new([12, 9, 5]))
            .address_bits(17)
            .metric(Metric::L2)
            .traversal(Traversal::Reread)
            .queries_per_port(3)
            .trees(2)
            .pipelined(false)
            .build()
            .unwrap(),
        b().metric(Metric::L2).radius_bits(Some(9)).build().unwrap(),
        b().controller(Controller::Barrel)
            .traversal(Traversal::Cell)
            .address_bits(14)
            .banks(3, Some(5))
            .trees(2)
            .result_streams(2)
            .build()
            .unwrap(),
        b().controller(Controller::Barrel)
            .address_bits(12)
            .banks(2, None)
            .bank_mapping(BankMapping::Modulo)
            .build()
            .unwrap(),
    ];
    for cfg in cores {
        let text = to_toml(&cfg);
        assert_eq!(from_toml(&text, "core.toml").unwrap(), cfg, "{text}");
        let q = format!("queries_per_port = {}", cfg.queries_per_port);
        assert!(text.lines().any(|l| l == q), "{q} missing from\n{text}");
        let earlier = match cfg.controller {
            Controller::Modules => "modules_per_port",
            Controller::Barrel => "slots_per_port",
        };
        let old = text.replace("queries_per_port", earlier);
        assert_eq!(from_toml(&old, "old.toml").unwrap(), cfg, "{old}");
    }
}

/// A key a file leaves out is the default core's, as an option left off the
/// command line: the barrel controller with the cell traversal and 16 query
/// slots per port, K = 32, L2, 10-bit coordinates, pipelined, one tree (the
/// defaults export-verilog's help documents); a controller given alone brings its
/// own traversal and Q.
#[test]
fn a_key_left_out_is_the_default_cores() {
    let c = from_toml("address_bits = 12\n", "short.toml").unwrap();
    assert_eq!(
        (c.controller, c.traversal, c.queries_per_port, c.k, c.metric),
        (Controller::Barrel, Traversal::Cell, 16, 32, Metric::L2)
    );
    assert_eq!((c.layout.bits, c.address_bits), ([10; 3], 12));
    assert!(c.pipelined && c.trees == 1 && c.banking.is_none() && c.result_streams == 1);
    let m = from_toml("controller = \"modules\"\nk = 10\n", "modules.toml").unwrap();
    assert_eq!(m.traversal, Traversal::Remember);
    assert_eq!(m.queries_per_port, m.issue_interval());
    // The same core as the command line's.
    let dir = tempfile::tempdir().unwrap();
    let file = export_core(dir.path(), "cli", &["--controller", "modules", "--k", "10"]);
    let exported = std::fs::read_to_string(file).unwrap();
    assert_eq!(from_toml(&exported, "cli.toml").unwrap(), m);
}

/// `export-verilog --core FILE` of the file an export wrote writes the same
/// Verilog, byte for byte (same SHA-256), and the same file again.
#[test]
fn the_same_file_exports_the_same_verilog() {
    use sha2::{Digest, Sha256};
    let dir = tempfile::tempdir().unwrap();
    let options = [
        "--controller",
        "barrel",
        "--k",
        "5",
        "--bits",
        "6",
        "--address-bits",
        "7",
        "--metric",
        "l2",
        "--queries-per-port",
        "4",
    ];
    let file = export_core(dir.path(), "a", &options);
    let again = dir.path().join("b");
    bin()
        .args(["export-verilog", "--core"])
        .arg(&file)
        .arg("--out")
        .arg(&again)
        .assert()
        .success();
    for name in [
        "photon_search_core.v",
        "photon_search_core_sim.v",
        CORE_FILE_NAME,
    ] {
        let sha = |d: &Path| format!("{:x}", Sha256::digest(std::fs::read(d.join(name)).unwrap()));
        assert_eq!(sha(&dir.path().join("a")), sha(&again), "{name} differs");
    }
    let text = std::fs::read_to_string(&file).unwrap();
    let cfg = from_toml(&text, "a").unwrap();
    assert_eq!(
        (
            cfg.controller,
            cfg.k,
            cfg.layout.bits,
            cfg.address_bits,
            cfg.metric,
            cfg.queries_per_port
        ),
        (Controller::Barrel, 5, [6, 6, 6], 7, Metric::L2, 4)
    );
}

/// The photon counts of a render's stdout ("N photons stored from ...").
fn stored(stdout: &str) -> usize {
    stdout
        .split(" photons stored")
        .next()
        .and_then(|s| s.parse().ok())
        .unwrap_or_else(|| panic!("no stored count in {stdout}"))
}

/// Issue 31: `render --core FILE --backend verilator` renders maps of different
/// photon counts from one cached model (the cache holds exactly one entry), each
/// image byte-identical to `render --core FILE --backend sw`.
#[test]
#[cfg_attr(not(has_verilator), ignore = "needs verilator")]
fn one_model_renders_maps_of_every_size_like_sw() {
    let dir = tempfile::tempdir().unwrap();
    let cache = tempfile::tempdir().unwrap();
    let file = export_core(
        dir.path(),
        "core",
        &[
            "--controller",
            "modules",
            "--traversal",
            "remember",
            "--queries-per-port",
            "3",
            "--k",
            "6",
            "--bits",
            "8",
            "--address-bits",
            "11",
            "--metric",
            "l2",
        ],
    );
    let mut counts = vec![];
    for emitted in ["300", "800"] {
        let mut png = vec![];
        for backend in ["sw", "verilator"] {
            let out = dir.path().join(format!("{emitted}-{backend}.png"));
            let run = bin()
                .env("PHOTON_FPGA_CACHE_DIR", cache.path())
                .args([
                    "render",
                    "--method",
                    "direct",
                    "--size",
                    "12x10",
                    "--spp",
                    "1",
                    "--photons",
                    emitted,
                ])
                .args(["--backend", backend, "--core"])
                .arg(&file)
                .arg("--out")
                .arg(&out)
                .assert()
                .success();
            let stdout = String::from_utf8_lossy(&run.get_output().stdout).to_string();
            counts.push(stored(&stdout));
            png.push(std::fs::read(&out).unwrap());
        }
        assert!(
            png[0] == png[1],
            "{emitted} emitted: verilator and sw renders differ"
        );
    }
    assert!(
        counts[0] == counts[1] && counts[2] == counts[3],
        "{counts:?}"
    );
    assert_ne!(
        counts[0], counts[2],
        "the two maps have the same photon count"
    );
    let entries: Vec<String> = listing(cache.path())
        .into_iter()
        .filter(|n| !n.ends_with(".lock") && !n.starts_with('.'))
        .collect();
    assert_eq!(entries.len(), 1, "one model for both maps: {entries:?}");
}

/// Random photons and queries in a 4 x 2 x 1 box as CSV files in `dir` (their
/// paths), from `seed`.
fn box_points(dir: &Path, photons: usize, queries: usize, seed: u64) -> (String, String) {
    let mut r = rand_pcg::Pcg64Mcg::seed_from_u64(seed);
    let mut pts = |n| -> Vec<[f64; 3]> {
        (0..n)
            .map(|_| [0, 1, 2].map(|a| r.gen_range(0.0..[4.0, 2.0, 1.0][a])))
            .collect()
    };
    let p = write(dir, "p.csv", &points_csv(&pts(photons), false));
    let q = write(dir, "q.csv", &points_csv(&pts(queries), false));
    (p.display().to_string(), q.display().to_string())
}

/// `gather --core FILE` of `photons` and `queries` with `--backend sw` and `rtl`
/// (and `extra` options): each output's lines.
fn sw_and_rtl(
    dir: &Path,
    file: &str,
    photons: &str,
    queries: &str,
    extra: &[&str],
) -> [Vec<String>; 2] {
    ["sw", "rtl"].map(|backend| {
        let out = dir.join(format!("{backend}.csv"));
        let args = [
            &[
                "--photons",
                photons,
                "--queries",
                queries,
                "--core",
                file,
                "--backend",
                backend,
            ][..],
            extra,
        ]
        .concat();
        gather_lines(&args, &out)
    })
}

/// The fixed core under rust-hdl's own simulation: `gather --core FILE --backend
/// rtl` on a map far smaller than the core's H (40 photons in a 2^11-word tree)
/// writes the very file sw does on the same core, k the file's K.
#[test]
fn the_fixed_core_answers_small_maps_like_sw() {
    let dir = tempfile::tempdir().unwrap();
    let file = export_core(
        dir.path(),
        "core",
        &[
            "--controller",
            "barrel",
            "--k",
            "5",
            "--bits",
            "7",
            "--address-bits",
            "11",
        ],
    );
    let file = file.display().to_string();
    let (p, q) = box_points(dir.path(), 40, 25, 11);
    let files = sw_and_rtl(dir.path(), &file, &p, &q, &[]);
    assert_eq!(files[0], files[1], "rtl and sw differ on the file's core");
    assert_eq!(files[0].len(), 1 + 25 * 5, "k defaults to the file's K");
}

/// A core built for a largest radius (`--radius-bits 8`: squared-L2 radii up to
/// 254 on its grid) answers a gather within a radius it holds like sw, and refuses
/// by name, exit 2, a larger radius or none.
#[test]
fn a_core_for_a_radius_answers_it_and_refuses_more() {
    let dir = tempfile::tempdir().unwrap();
    let file = export_core(
        dir.path(),
        "core",
        &"--controller barrel --traversal cell --k 5 --bits 7 --address-bits 11 --metric l2 \
          --radius-bits 8"
            .split_whitespace()
            .collect::<Vec<_>>(),
    );
    let f = file.display().to_string();
    let (p, q) = box_points(dir.path(), 300, 40, 12);
    let files = sw_and_rtl(dir.path(), &f, &p, &q, &["--radius", "0.3"]);
    assert_eq!(files[0], files[1], "rtl and sw differ within the radius");
    // Some queries find fewer than k within the radius, some all k.
    let per_query = |i: usize| {
        files[0]
            .iter()
            .filter(|l| l.starts_with(&format!("{i},")))
            .count()
    };
    let counts: Vec<usize> = (0..40).map(per_query).collect();
    assert!(
        counts.iter().any(|&c| c < 5) && counts.contains(&5),
        "{counts:?}"
    );
    let out = dir.path().join("g.csv").display().to_string();
    let gather = |extra: &[&str]| {
        cmdline(
            &[
                "gather",
                "--photons",
                &p,
                "--queries",
                &q,
                "--core",
                &f,
                "--out",
                &out,
            ],
            extra,
        )
    };
    refused(
        dir.path(),
        &gather(&["--backend", "rtl", "--radius", "1.0"]),
        &format!("beyond the core of {f}: radius_bits = 8 answers radii up to 254"),
    );
    refused(
        dir.path(),
        &gather(&["--backend", "rtl"]),
        "an unbounded gather (no --radius), beyond the core",
    );
}

/// What does not fit the file's core is refused before any work, naming the limit
/// and the file: a map beyond its H (render and gather), k above its K, a
/// --capacity above its H; the options the file fixes given with it; a backend
/// that runs no quantized search; and a file that is not a core (its line and
/// value named).
#[test]
fn what_does_not_fit_the_file_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let file = export_core(dir.path(), "core", &["--k", "4", "--address-bits", "5"]);
    let f = file.display().to_string();
    let out = dir.path().join("r.png").display().to_string();
    let render = |extra: &[&str]| cmdline(&["render", "--out", &out, "--core", &f], extra);
    refused(
        dir.path(),
        &render(&["--photons", "100", "--backend", "verilator"]),
        &format!("store more than the 31 photons the core of {f} holds (address_bits = 5)"),
    );
    refused(
        dir.path(),
        &render(&["--k", "5"]),
        &format!("--k 5 exceeds the found list of the core of {f} (k = 4"),
    );
    refused(
        dir.path(),
        &render(&["--capacity", "32", "--backend", "rtl"]),
        &format!("--capacity 32 exceeds the 31 photons the core of {f} holds"),
    );
    refused(
        dir.path(),
        &render(&["--trees", "2"]),
        &format!("--trees cannot be used with --core {f}: the file gives the whole core"),
    );
    for extra in [&["--bits", "8"][..], &["--metric", "l1"], &["--exact"]] {
        refused(
            dir.path(),
            &render(extra),
            &format!(
                "the argument '--core <FILE>' cannot be used with '{}",
                extra[0]
            ),
        );
    }
    refused(
        dir.path(),
        &render(&["--backend", "float"]),
        "--backend float searches the unquantized positions",
    );
    // gather: a CSV map of 32 photons does not fit 2^5 - 1.
    let p: Vec<[f64; 3]> = (0..32).map(|i| [i as f64, 0.0, 1.0]).collect();
    let p = write(dir.path(), "p.csv", &points_csv(&p, false))
        .display()
        .to_string();
    let q = write(dir.path(), "q.csv", "1,0,1\n").display().to_string();
    fails(
        dir.path(),
        &["--photons", &p, "--queries", &q, "--core", &f],
        &format!("32 photons exceed the 31 photons the core of {f} holds (address_bits = 5)"),
    );
    // Files that are not a core: a wrong value and an unknown key (each named
    // with its line), a core out of range.
    let text = std::fs::read_to_string(&file).unwrap();
    let bad = |name: &str, text: String, message: &str| {
        let path = write(dir.path(), name, &text).display().to_string();
        fails(
            dir.path(),
            &["--photons", &p, "--queries", &q, "--core", &path],
            message,
        );
    };
    let line = |key: &str| 1 + text.lines().position(|l| l.starts_with(key)).unwrap();
    bad(
        "value.toml",
        text.replace("trees = 1", "trees = \"one\""),
        &format!(
            "value.toml: line {}: invalid type: string \"one\"",
            line("trees")
        ),
    );
    bad(
        "unknown.toml",
        format!("{text}colour = 3\n"),
        &format!(
            "unknown.toml: line {}: unknown key `colour`",
            text.lines().count() + 1
        ),
    );
    bad(
        "big_h.toml",
        text.replace("address_bits = 5", "address_bits = 21"),
        "big_h.toml: address_bits (H) = 21 unsupported",
    );
    fails(
        dir.path(),
        &["--photons", &p, "--queries", &q, "--core", "nope.toml"],
        "nope.toml: cannot read",
    ); // Coordinate widths the core cannot have, and a fourth width.
    let widths = |w: &str| {
        text.replace(
            "coordinate_bits = [10, 10, 10]",
            &format!("coordinate_bits = {w}"),
        )
    };
    for (name, w) in [("zero.toml", "[0, 0, 0]"), ("wide.toml", "[17, 17, 17]")] {
        bad(
            name,
            widths(w),
            &format!("{name}: coordinate_bits = {w}: each width must be 1..=15"),
        );
    }
    bad(
        "four.toml",
        widths("[10, 10, 10, 10]"),
        "coordinate_bits = [10, 10, 10, 10]: expected three widths (x, y, z), got 4",
    );
}

/// The core file is an input: no output of render, gather or export-verilog may
/// replace it (exit 2, the file as it was, nothing else written).
#[test]
fn no_output_replaces_the_core_file() {
    let dir = tempfile::tempdir().unwrap();
    let d = export_core(dir.path(), "core", &["--k", "4", "--address-bits", "6"]);
    // The user's own comment: it must survive every refused run.
    let text = format!("# my core\n{}", std::fs::read_to_string(&d).unwrap());
    std::fs::write(&d, &text).unwrap();
    let f = d.display().to_string();
    let (p, q) = box_points(dir.path(), 20, 5, 3);
    let gather = |extra: &[&str]| {
        cmdline(
            &["gather", "--photons", &p, "--queries", &q, "--core", &f],
            extra,
        )
    };
    let input = "is also an input";
    refused(dir.path(), &gather(&["--out", &f]), input);
    let csv = dir.path().join("g.csv").display().to_string();
    refused(
        dir.path(),
        &gather(&["--out", &csv, "--backend", "rtl", "--vcd", &f]),
        input,
    );
    refused(
        dir.path(),
        &strings(&["render", "--core", &f, "--out", &f, "--photons", "20"]),
        input,
    );
    let core_dir = d.parent().unwrap().display().to_string();
    refused(
        dir.path(),
        &strings(&["export-verilog", "--core", &f, "--out", &core_dir]),
        input,
    );
    assert_eq!(std::fs::read_to_string(&d).unwrap(), text);
}

/// A gather interrupted (SIGINT, as Ctrl-C sends) while it writes its output leaves
/// no temporary file beside it, and exits 130.
#[test]
#[cfg(unix)]
fn an_interrupted_gather_leaves_no_temporary_file() {
    let dir = tempfile::tempdir().unwrap();
    let (p, q) = box_points(dir.path(), 3000, 40_000, 9);
    let out = dir.path().join("out.csv");
    let bin = assert_cmd::cargo::cargo_bin("photon-fpga");
    let mut child = std::process::Command::new(bin)
        .args([
            "gather",
            "--photons",
            &p,
            "--queries",
            &q,
            "--k",
            "64",
            "--threads",
            "1",
        ])
        .arg("--out")
        .arg(&out)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    // The temporary files beside the output, and whether one holds bytes yet (the
    // output check's probe is empty and gone at once; the write's fills).
    let temporary = |written: bool| {
        std::fs::read_dir(dir.path()).unwrap().any(|e| {
            let e = e.unwrap();
            e.file_name().to_string_lossy().starts_with(".photon-fpga-")
                && (!written || e.metadata().is_ok_and(|m| m.len() > 0))
        })
    };
    let start = std::time::Instant::now();
    while !temporary(true) {
        assert!(
            child.try_wait().unwrap().is_none(),
            "the gather ended before its output was staged"
        );
        assert!(start.elapsed().as_secs() < 120, "no output staged");
        std::thread::sleep(std::time::Duration::from_millis(1));
    }
    let pid = child.id().to_string();
    let killed = std::process::Command::new("kill")
        .args(["-INT", &pid])
        .status()
        .unwrap();
    assert!(killed.success());
    let status = child.wait().unwrap();
    assert_eq!(status.code(), Some(130), "{status:?}");
    assert!(!temporary(false), "a temporary file was left behind");
    assert!(!out.exists(), "a half output was left");
}
