//! The AXI4-Stream top's generator (`rtl::axis_top`): its layouts against rust-hdl's
//! own packing of the payload structs and against the exported ports, the generated
//! top through yosys, Verilator's lint and Icarus with the core, the CLI's files,
//! and the README's table against the default export. Its behaviour is checked by
//! the cocotb bench (testbenches/cocotb).

use crate::common::{require, run_tool};
use photon_fpga::hw::config::controller::Controller;
use photon_fpga::hw::config::core_config::CoreConfig;
use photon_fpga::hw::config::photon_word::PhotonLayout;
use photon_fpga::hw::config::traversal::Traversal;
use photon_fpga::hw::export::axis_top::{axis_top, layout_table, StreamLayout};
use photon_fpga::hw::export::verilog::export_verilog;
use photon_fpga::hw::primitives::stream::{QueryBeat, ResultBeat};
use rust_hdl::prelude::*;
use std::process::Command;

fn configs() -> Vec<CoreConfig> {
    let barrel = CoreConfig::builder()
        .traversal(Traversal::Cell)
        .controller(Controller::Barrel)
        .queries_per_port(16)
        .build()
        .unwrap();
    // 12-bit coordinates: a 38-bit word on the 64-bit word port.
    let wide = CoreConfig::builder()
        .layout(PhotonLayout::new([12, 12, 12]))
        .address_bits(8)
        .k(20)
        .queries_per_port(2)
        .build()
        .unwrap();
    let array = CoreConfig::builder()
        .address_bits(6)
        .k(4)
        .queries_per_port(2)
        .trees(2)
        .build()
        .unwrap();
    vec![CoreConfig::paper(), barrel, wide, array]
}

/// Fields byte-aligned, in their slots, in order, not overlapping; tdata a power of
/// two bytes holding them all.
fn check_alignment(s: &StreamLayout) {
    assert!(
        s.tdata_bits.is_multiple_of(8) && (s.tdata_bits / 8).is_power_of_two(),
        "{s:?}"
    );
    let mut end = 0;
    for f in &s.fields {
        assert!(f.lsb >= end, "{}: {} overlaps", s.name, f.name);
        assert!(f.width >= 1 && f.width <= f.slot, "{}: {}", s.name, f.name);
        end = f.lsb + f.slot;
    }
    assert!(end <= s.tdata_bits, "{}: fields beyond tdata", s.name);
    if s.name != "s_axis_photon" {
        for f in &s.fields {
            assert_eq!(
                f.lsb % 8,
                0,
                "{}: {} not on a byte boundary",
                s.name,
                f.name
            );
            assert!(
                f.slot.is_multiple_of(8),
                "{}: {} slot not whole bytes",
                s.name,
                f.name
            );
        }
    }
}

/// Each field's `core_lsb`/`width` picks exactly that field out of rust-hdl's packed
/// bits of a beat whose fields all hold distinct values.
fn check_core_slices<T: Synth>(s: &StreamLayout, beat: T, values: &[(&str, u64)]) {
    // rust-hdl's own Verilog literal of the packed struct, as the export sees it,
    // as bits (LSB first).
    let lit = format!("{:x}", beat.verilog());
    let digits = lit.split_once("'h").map_or(lit.as_str(), |(_, d)| d);
    let bits: Vec<bool> = digits
        .chars()
        .rev()
        .filter(|c| *c != '_')
        .flat_map(|c| {
            let n = c.to_digit(16).expect("hex digit");
            (0..4).map(move |i| (n >> i) & 1 == 1)
        })
        .collect();
    assert_eq!(s.fields.len(), values.len(), "{}: field count", s.name);
    for (f, (name, v)) in s.fields.iter().zip(values) {
        assert_eq!(&f.name, name, "{}: field order", s.name);
        let lsb = f.core_lsb.expect("a struct field");
        let got = (0..f.width)
            .filter(|&i| bits.get(lsb + i).copied().unwrap_or(false))
            .fold(0u64, |a, i| a | (1 << i));
        assert_eq!(got, *v, "{}: field {name}", s.name);
    }
}

#[test]
fn layouts_follow_the_structs_and_the_ports() {
    for cfg in configs() {
        let core = export_verilog(&cfg).expect("export");
        let axis = axis_top(&core, &cfg).expect("axis top");
        let width = |n: &str| core.ports.iter().find(|p| p.name == n).unwrap().width;
        let [photon, query, result] = &axis.streams[..] else {
            panic!("three streams")
        };
        for s in &axis.streams {
            check_alignment(s);
        }
        // Photon word: x, y, z, axis at the layout's offsets, the word port inside tdata.
        let l = cfg.layout;
        let offs: Vec<(usize, usize)> = photon.fields.iter().map(|f| (f.lsb, f.width)).collect();
        assert_eq!(
            offs,
            vec![
                (0, l.bits[0] as usize),
                (l.offset(1) as usize, l.bits[1] as usize),
                (l.offset(2) as usize, l.bits[2] as usize),
                (l.axis_offset() as usize, 2)
            ]
        );
        assert!(photon.tdata_bits >= width("load$word"));
        // Struct fields: widths sum to the port, slices match rust-hdl's packing.
        let sum = |s: &StreamLayout| s.fields.iter().map(|f| f.width).sum::<usize>();
        assert_eq!(sum(query), width("query$data"));
        assert_eq!(sum(result), width("result$data"));
        let q = QueryBeat {
            id: 0xdead_beef_u64.into(),
            x: 0x1234_u64.into(),
            y: 0x5678_u64.into(),
            z: 0x9abc_u64.into(),
            radius: 0x0fed_cba9_u64.into(),
            k: 0x3f_u64.into(),
        };
        let qv = [
            ("id", 0xdead_beef),
            ("x", 0x1234),
            ("y", 0x5678),
            ("z", 0x9abc),
            ("radius", 0x0fed_cba9),
            ("k", 0x3f),
        ];
        check_core_slices(query, q, &qv);
        let r = ResultBeat {
            header: true,
            last: false,
            id: 0x1357_9bdf_u64.into(),
            count: 0x2a_u64.into(),
            visited: 0x0246_8ace_u64.into(),
            address: 0xa5_5a5a_u64.into(),
            distance: 0x7654_3210_u64.into(),
            pair: true,
            address2: 0x12_3456_u64.into(),
            distance2: 0x0bad_cafe_u64.into(),
        };
        let rv = [
            ("header", 1),
            ("last", 0),
            ("id", 0x1357_9bdf),
            ("count", 0x2a),
            ("visited", 0x0246_8ace),
            ("address", 0xa5_5a5a),
            ("distance", 0x7654_3210),
            ("pair", 1),
            ("address2", 0x12_3456),
            ("distance2", 0x0bad_cafe),
        ];
        check_core_slices(result, r, &rv);
        // The JSON is the same layout.
        let json: serde_json::Value = serde_json::from_str(&axis.json).unwrap();
        for s in &axis.streams {
            let js = &json["streams"][s.name];
            assert_eq!(js["tdata_bits"], s.tdata_bits);
            let fields: Vec<(String, usize, usize)> = js["fields"]
                .as_array()
                .unwrap()
                .iter()
                .map(|f| {
                    (
                        f["name"].as_str().unwrap().to_string(),
                        f["lsb"].as_u64().unwrap() as usize,
                        f["width"].as_u64().unwrap() as usize,
                    )
                })
                .collect();
            let want: Vec<(String, usize, usize)> = s
                .fields
                .iter()
                .map(|f| (f.name.clone(), f.lsb, f.width))
                .collect();
            assert_eq!(fields, want, "{}", s.name);
        }
        assert_eq!(json["core"]["k"], cfg.k);
        assert_eq!(json["core"]["id_bits"], cfg.id_bits());
        // The header's table is the layout's.
        for line in layout_table(&axis.streams).lines() {
            assert!(axis.verilog.contains(&format!("//   {line}\n")), "{line}");
        }
    }
}

#[test]
#[cfg_attr(
    not(all(has_yosys, has_verilator, has_iverilog)),
    ignore = "needs yosys, verilator and iverilog"
)]
fn axis_top_is_clean_verilog() {
    // A banked core of two result streams: two result ports.
    let banked = CoreConfig::builder()
        .traversal(Traversal::Cell)
        .controller(Controller::Barrel)
        .address_bits(10)
        .banks(3, Some(4))
        .trees(2)
        .result_streams(2)
        .build()
        .unwrap();
    for cfg in [configs()[1], configs()[3], banked] {
        let core = export_verilog(&cfg).expect("export");
        let axis = axis_top(&core, &cfg).expect("axis top");
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("top.v"), &core.verilog).unwrap();
        std::fs::write(dir.path().join("axis.v"), &axis.verilog).unwrap();
        require("yosys");
        run_tool(
            Command::new("yosys").current_dir(dir.path()).args([
                "-q",
                "-p",
                "read_verilog top.v axis.v; hierarchy -check -top photon_search_axis; \
                 proc; check -assert",
            ]),
            "yosys check",
        );
        // -Wall on the wrapper; the core's own lint is hw_verilog's. Allowed: the
        // file name, the status outputs left open, the tdata padding bits unread
        // and the core's valid/ready pairs that look circular per always block.
        std::fs::write(
            dir.path().join("core.vlt"),
            "`verilator_config\nlint_off -file \"*top.v\"\n",
        )
        .unwrap();
        require("verilator");
        run_tool(
            Command::new("verilator").current_dir(dir.path()).args([
                "--lint-only",
                "-Wall",
                "-Wno-DECLFILENAME",
                "-Wno-PINCONNECTEMPTY",
                "-Wno-UNUSEDSIGNAL",
                "-Wno-UNOPTFLAT",
                "--top-module",
                "photon_search_axis",
                "core.vlt",
                "top.v",
                "axis.v",
            ]),
            "verilator lint",
        );
        require("iverilog");
        run_tool(
            Command::new("iverilog").current_dir(dir.path()).args([
                "-g2005",
                "-s",
                "photon_search_axis",
                "-o",
                "/dev/null",
                "top.v",
                "axis.v",
            ]),
            "iverilog compile",
        );
    }
}

/// `export-verilog --interface axis` writes the top and its JSON beside the core, and
/// the README's table is the paper's core's (`--paper`).
#[test]
fn cli_writes_the_axis_top_and_the_readme_table_is_current() {
    let dir = tempfile::tempdir().unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_photon-fpga"))
        .args(["export-verilog", "--interface", "axis", "--paper", "--out"])
        .arg(dir.path())
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v = std::fs::read_to_string(dir.path().join("photon_search_axis.v")).unwrap();
    assert!(v.contains("module photon_search_axis ("));
    assert!(dir.path().join("photon_search_axis.json").is_file());
    let table: String = v
        .lines()
        .take_while(|l| !l.starts_with("module"))
        .filter_map(|l| l.strip_prefix("//   |"))
        .map(|l| format!("|{l}\n"))
        .collect();
    assert!(table.lines().count() > 10, "table in the header:\n{v}");
    let doc =
        |f: &str| std::fs::read_to_string(format!("{}/{f}", env!("CARGO_MANIFEST_DIR"))).unwrap();
    assert!(
        doc("docs/AXIS.md").contains(&table),
        "docs/AXIS.md's layout table differs from the paper's core's; replace it with:\n{table}"
    );
    // The README's one row per stream, from the same layout (the JSON written).
    let json: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(dir.path().join("photon_search_axis.json")).unwrap(),
    )
    .unwrap();
    let mut summary = String::from("| stream | tdata fields, bits |\n|---|---|\n");
    for name in ["s_axis_photon", "s_axis_query", "m_axis_result"] {
        let s = &json["streams"][name];
        let fields: Vec<String> = s["fields"]
            .as_array()
            .unwrap()
            .iter()
            .map(|f| {
                let (lsb, w) = (f["lsb"].as_u64().unwrap(), f["width"].as_u64().unwrap());
                let n = f["name"].as_str().unwrap();
                if w == 1 {
                    format!("{n} [{lsb}]")
                } else {
                    format!("{n} [{}:{lsb}]", lsb + w - 1)
                }
            })
            .collect();
        summary += &format!(
            "| {name} ({} bytes) | {} |\n",
            s["tdata_bits"].as_u64().unwrap() / 8,
            fields.join(", ")
        );
    }
    assert!(
        doc("README.md").contains(&summary),
        "README.md's AXI4-Stream table differs from the paper's core's; replace it with:\n{summary}"
    );
    // Without --interface only the core is written.
    let bare = tempfile::tempdir().unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_photon-fpga"))
        .args(["export-verilog", "--out"])
        .arg(bare.path())
        .output()
        .unwrap();
    assert!(out.status.success());
    assert!(!bare.path().join("photon_search_axis.v").exists());
}
