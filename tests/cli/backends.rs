//! Each backend's own limits and the core options: refused by name, with exit
//! status 2 and nothing left behind, before any work starts.

use super::*;

/// Class 8: a backend's photon limit is its own. The simulated core holds at most
/// 2^23 − 1 photons (the external-memory core's 23 address bits) and a larger
/// --capacity is refused up front; the float and sw searches are bounded by memory
/// alone, so a render of more than 2^20 stored photons runs on them with no flag.
#[test]
fn each_backend_has_its_own_photon_limit() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("r.png").display().to_string();
    let render = |extra: &[&str]| cmdline(&["render", "--out", &out], extra);
    for backend in ["native", "verilator"] {
        refused(
            dir.path(),
            &render(&["--backend", backend, "--capacity", "8388608"]),
            &format!("--capacity 8388608 exceeds what --backend {backend} can hold"),
        );
    }
    let run = bin()
        .args(render(&["--backend", "float", "--photons", "2000000"]))
        .args(["--method", "direct"])
        .args(["--size", "4x4", "--spp", "1"])
        .assert()
        .success();
    let stdout = String::from_utf8_lossy(&run.get_output().stdout).to_string();
    assert_beyond_the_blockram_tree(&stdout);
}

/// A render's printout says it stored more photons than the BlockRAM tree's
/// 2^20 − 1.
fn assert_beyond_the_blockram_tree(stdout: &str) {
    let stored: usize = stdout
        .split(" photons stored")
        .next()
        .and_then(|s| s.parse().ok())
        .unwrap_or_else(|| panic!("no stored count in {stdout}"));
    assert!(stored > (1 << 20) - 1, "{stored} stored: {stdout}");
}

/// Class 10: the core options are checked before any work: Q under the name of
/// the other controller, the barrel controller with the re-read ascent, core
/// limits, and core options given to a backend that runs no core.
#[test]
fn core_options_are_refused_by_name() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("r.png").display().to_string();
    let v = dir.path().join("v").display().to_string();
    let render = |extra: &[&str]| cmdline(&["render", "--out", &out, "--backend", "rtl"], extra);
    // Q has one name for both controllers; the old two are gone.
    for old in ["--modules-per-port", "--slots-per-port"] {
        refused(
            dir.path(),
            &render(&[old, "4"]),
            &format!("unexpected argument '{old}' found"),
        );
    }
    refused(
        dir.path(),
        &render(&["--controller", "barrel", "--traversal", "reread"]),
        "traversal = reread with controller barrel",
    );
    refused(dir.path(), &render(&["--trees", "9"]), "trees = 9");
    refused(
        dir.path(),
        &render(&["--queries-per-port", "40"]),
        "queries_per_port = 40 unsupported (1..=32 query slots",
    );
    for backend in ["sw", "float"] {
        refused(
            dir.path(),
            &strings(&[
                "render",
                "--out",
                &out,
                "--backend",
                backend,
                "--controller",
                "barrel",
            ]),
            &format!("--controller configures the simulated core; --backend {backend} runs none"),
        );
    }
    refused(
        dir.path(),
        &strings(&[
            "export-verilog",
            "--out",
            &v,
            "--controller",
            "modules",
            "--queries-per-port",
            "0",
        ]),
        "queries_per_port = 0 unsupported (1..=32 QueryModules",
    );
}

/// The paper's quality regime (§3: 1 M emitted photons store ~1.9 M) needs more
/// than the BlockRAM tree's 20 address bits: with no --core or --device the
/// simulated core is the external-memory core the ECP5-85k plan gives, and its
/// render (the memory model answering its AXI4 master) is the software search's,
/// byte for byte.
#[test]
#[cfg_attr(not(has_verilator), ignore = "needs verilator")]
fn a_map_beyond_the_blockram_tree_renders_through_the_external_memory_core() {
    let dir = tempfile::tempdir().unwrap();
    let png = |backend: &str| {
        let out = dir.path().join(format!("{backend}.png"));
        let run = bin()
            .args(["render", "--method", "direct", "--photons", "540000"])
            .args(["--size", "6x5", "--spp", "1", "--backend", backend])
            .arg("--out")
            .arg(&out)
            .assert()
            .success();
        let stdout = String::from_utf8_lossy(&run.get_output().stdout).to_string();
        (std::fs::read(&out).unwrap(), stdout)
    };
    let (sw, stored) = png("sw");
    let (hw, core) = png("verilator");
    assert_beyond_the_blockram_tree(&stored);
    assert!(core.contains("in external memory"), "{core}");
    assert!(
        sw == hw,
        "the external-memory core's render differs from sw"
    );
}
