//! The banked core from the command line (`--banks`, `--device`; the detail, as
//! `--replicated-levels`, through export-verilog's core file): render through it
//! is the software search's very image, its core file carries the banks, and what
//! it cannot build is refused by name with exit status 2 and nothing written.

use super::*;
use photon_fpga::hw::config::core_file::{from_toml, CORE_FILE_NAME};

/// `render` of a small scene with `args` and the backend, the PNG's bytes.
fn render_png(dir: &Path, name: &str, args: &[&str]) -> Vec<u8> {
    let out = dir.join(name);
    bin()
        .args([
            "render", "--method", "direct", "--size", "8x6", "--spp", "1",
        ])
        .args(["--photons", "1500"])
        .args(args)
        .arg("--out")
        .arg(&out)
        .assert()
        .success();
    std::fs::read(&out).unwrap()
}

/// rust-hdl's simulation of a banked core (two replicas, four datapaths, 8
/// banks, two result streams; then split bank ports), exported as a core file,
/// renders the image of the software search on that core.
#[test]
fn render_through_the_banked_core_is_the_sw_image() {
    let dir = tempfile::tempdir().unwrap();
    let core = |name: &str, extra: &[&str]| {
        let out = dir.path().join(name);
        bin()
            .args([
                "export-verilog",
                "--controller",
                "barrel",
                "--traversal",
                "cell",
            ])
            .args([
                "--k",
                "32",
                "--bits",
                "10",
                "--address-bits",
                "12",
                "--metric",
                "l2",
            ])
            .args([
                "--banks",
                "8",
                "--replicas",
                "2",
                "--replicated-levels",
                "4",
            ])
            .args(extra)
            .arg("--out")
            .arg(&out)
            .assert()
            .success();
        out.join(CORE_FILE_NAME).display().to_string()
    };
    // Two result streams, then split bank ports (even datapaths on a bank's first
    // port, odd on its second).
    for (name, extra) in [
        ("streams", ["--result-streams", "2"]),
        ("split", ["--bank-ports", "split"]),
    ] {
        let f = core(name, &extra);
        let sw = render_png(dir.path(), "sw.png", &["--backend", "sw", "--core", &f]);
        let hw = render_png(dir.path(), "rtl.png", &["--backend", "rtl", "--core", &f]);
        assert!(sw == hw, "the {name} banked core's render differs from sw");
    }
}

/// export-verilog --device writes a core file with banks that reads back as a
/// banked barrel core holding the map it was planned for.
#[test]
fn a_device_plans_a_banked_core_file() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("core");
    bin()
        .args([
            "export-verilog",
            "--device",
            "ecp5-85k",
            "--bank-ports",
            "split",
            "--address-bits",
            "14",
            "--out",
        ])
        .arg(&out)
        .assert()
        .success();
    let path = out.join(CORE_FILE_NAME);
    let text = std::fs::read_to_string(&path).unwrap();
    let cfg = from_toml(&text, &path.display().to_string()).unwrap();
    let b = cfg.banking.expect("a banked core");
    assert!(
        text.contains(&format!("banks = {}", 1u64 << b.bank_bits)),
        "{text}"
    );
    assert!(text.contains("bank_ports = \"split\""), "{text}");
    assert_eq!(b.ports.to_string(), "two split ports per bank");
    assert_eq!(cfg.controller.to_string(), "barrel");
    assert_eq!(cfg.address_bits, 14);
    assert!(b.replicated_levels < 14 && b.bank_bits <= b.replicated_levels);
    assert!(cfg.datapaths() >= 2);
    assert!(cfg.memory.is_none(), "{text}");
    // The paper's 1 M-photon map (H = 21) is beyond the BlockRAM: the plan keeps
    // the top levels on chip and the rest in the board's memory behind a cache.
    let big = dir.path().join("big");
    bin()
        .args([
            "export-verilog",
            "--device",
            "ecp5-85k",
            "--address-bits",
            "21",
        ])
        .arg("--out")
        .arg(&big)
        .assert()
        .success();
    let path = big.join(CORE_FILE_NAME);
    let text = std::fs::read_to_string(&path).unwrap();
    let cfg = from_toml(&text, &path.display().to_string()).unwrap();
    let m = cfg.memory.expect("an external-memory core");
    let b = cfg.banking.expect("banks: the cache's");
    assert_eq!(cfg.address_bits, 21);
    assert!(b.replicated_levels < 21 && m.cache_lines >= 1 << b.bank_bits);
    assert!(
        text.contains(&format!("cache_lines = {}", m.cache_lines)),
        "{text}"
    );
    // A core file that names its cache is built as written, not re-planned.
    let mine = dir.path().join("mine.toml");
    std::fs::write(
        &mine,
        text.replace(
            &format!("cache_lines = {}", m.cache_lines),
            &format!("cache_lines = {}", m.cache_lines / 2),
        ),
    )
    .unwrap();
    let again = dir.path().join("again");
    bin()
        .args(["export-verilog", "--core"])
        .arg(&mine)
        .arg("--out")
        .arg(&again)
        .assert()
        .success();
    let path = again.join(CORE_FILE_NAME);
    let text = std::fs::read_to_string(&path).unwrap();
    let cfg = from_toml(&text, &path.display().to_string()).unwrap();
    assert_eq!(cfg.memory.map(|c| c.cache_lines), Some(m.cache_lines / 2));
}

#[test]
fn what_the_banked_core_cannot_build_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("x.png").display().to_string();
    let render = |extra: &[&str]| -> Vec<String> {
        [
            "render",
            "--method",
            "direct",
            "--size",
            "8x6",
            "--spp",
            "1",
            "--photons",
            "1500",
            "--backend",
            "rtl",
        ]
        .iter()
        .chain(extra)
        .map(|s| s.to_string())
        .chain(["--out".to_string(), out.clone()])
        .collect()
    };
    let v = dir.path().join("v").display().to_string();
    let export = |extra: &[&str]| -> Vec<String> {
        [
            "export-verilog",
            "--controller",
            "barrel",
            "--address-bits",
            "12",
        ]
        .iter()
        .chain(extra)
        .map(|s| s.to_string())
        .chain(["--out".to_string(), v.clone()])
        .collect()
    };
    refused(
        dir.path(),
        &export(&["--banks", "6"]),
        "banks = 6: unsupported (a power of two",
    );
    refused(
        dir.path(),
        &strings(&["export-verilog", "--bank-ports", "split", "--out", &v]),
        "--bank-ports split: without --banks or --device",
    );
    refused(
        dir.path(),
        &strings(&[
            "export-verilog",
            "--banks",
            "8",
            "--controller",
            "modules",
            "--out",
            &v,
        ]),
        "banks with controller modules",
    );
    refused(
        dir.path(),
        &render(&["--device", "ecp5-85k", "--controller", "modules"]),
        "cannot wait for a bank",
    );
    // A map beyond the BlockRAM gets the external-memory core (planned below);
    // beyond its 23 address bits it is refused with the largest map named, and
    // the largest builds.
    let largest = format!("{v}-largest");
    bin()
        .args(["export-verilog", "--device", "ecp5-85k"])
        .args(["--address-bits", "23", "--out", &largest])
        .assert()
        .success();
    refused(
        dir.path(),
        &strings(&[
            "export-verilog",
            "--device",
            "ecp5-85k",
            "--address-bits",
            "24",
            "--out",
            &v,
        ]),
        "the largest that fits is 8388607 photons",
    );
    // The memory's data width and the cache's tags (core file keys): one or two
    // photon words a beat, and only with a memory.
    for (text, message) in [
        (
            "banks = 4\ncache_lines = 16\nmemory_data_bits = 48\n",
            "memory_data_bits = 48: one or two 32-bit photon words a beat",
        ),
        (
            "banks = 4\nmemory_data_bits = 32\n",
            "memory_data_bits = 32 without cache_lines",
        ),
        // Where the cache keeps its tags: a named place, and only with a cache.
        (
            "banks = 4\ncache_tags = \"lut-ram\"\n",
            "cache_tags = \"lut-ram\" without cache_lines",
        ),
        (
            "banks = 4\ncache_lines = 16\ncache_tags = \"flip-flops\"\n",
            "unknown variant `flip-flops`, expected `block-ram` or `lut-ram`",
        ),
    ] {
        let file = dir.path().join("memory.toml");
        std::fs::write(&file, format!("controller = \"barrel\"\n{text}")).unwrap();
        let path = file.display().to_string();
        refused(
            dir.path(),
            &strings(&["export-verilog", "--core", &path, "--out", &v]),
            message,
        );
    }
    refused(
        dir.path(),
        &export(&[
            "--banks",
            "4",
            "--cache-lines",
            "16",
            "--memory-data-bits",
            "32",
        ]),
        "unexpected argument '--memory-data-bits' found",
    );
    // Result streams split the datapaths evenly (four here: 1, 2 or 4 streams).
    refused(
        dir.path(),
        &export(&["--banks", "8", "--replicas", "2", "--result-streams", "3"]),
        "result_streams = 3",
    );
    // Render takes a banked core from --device or a core file only; an array's
    // trees are whole cores, a banked core's copies are replicas.
    refused(
        dir.path(),
        &render(&["--banks", "8"]),
        "unexpected argument '--banks' found",
    );
    refused(
        dir.path(),
        &export(&["--banks", "8", "--trees", "2"]),
        "the argument '--banks <B>' cannot be used with '--trees <T>'",
    );
    refused(
        dir.path(),
        &export(&["--replicas", "2"]),
        "replicas = 2 without banks",
    );
}

/// A core of two result streams gets an AXI4-Stream top with two result ports,
/// `m_axis_result_0` and `m_axis_result_1`, named in its JSON.
#[test]
fn the_axis_top_has_a_port_per_result_stream() {
    let dir = tempfile::tempdir().unwrap();
    let axis = dir.path().join("axis");
    bin()
        .args([
            "export-verilog",
            "--address-bits",
            "12",
            "--banks",
            "8",
            "--replicas",
            "2",
            "--result-streams",
            "2",
            "--interface",
            "axis",
            "--out",
        ])
        .arg(&axis)
        .assert()
        .success();
    let v = std::fs::read_to_string(axis.join("photon_search_axis.v")).unwrap();
    for port in ["m_axis_result_0_tvalid", "m_axis_result_1_tlast"] {
        assert!(v.contains(&format!("output wire {port}")), "{port} missing");
    }
    assert!(!v.contains("output wire m_axis_result_tvalid"));
    let json: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(axis.join("photon_search_axis.json")).unwrap(),
    )
    .unwrap();
    assert_eq!(
        json["core"]["result_ports"],
        serde_json::json!(["m_axis_result_0", "m_axis_result_1"])
    );
}
