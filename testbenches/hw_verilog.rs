//! The exported Verilog passes yosys (hierarchy, proc, `check -assert`: no latches,
//! no undriven or multiply driven nets), Verilator lint and Icarus. Without those
//! tools the tests are ignored (build.rs), and under CI=true a missing tool fails.

use crate::common::{lint_top, require, run_tool, small_config};
use photon_fpga::hw::config::controller::Controller;
use photon_fpga::hw::config::core_config::CoreConfig;
use photon_fpga::hw::config::metric::Metric;
use photon_fpga::hw::config::photon_word::PhotonLayout;
use photon_fpga::hw::config::traversal::Traversal;
use photon_fpga::hw::export::ports::Port;
use photon_fpga::hw::export::verilog::{export_block, export_verilog, glitch_free};
use photon_fpga::hw::primitives::port_arbiter::PortArbiter;
use std::process::Command;

/// The tests below run only where build.rs found the tools (or under CI=true).
fn check_config(cfg: &CoreConfig) {
    let verilog = export_verilog(cfg).expect("export").verilog;
    assert!(verilog.contains("module top"));
    let w = cfg.layout.word_bits();
    assert!(
        verilog.contains(&format!(
            "reg [{}:0] mem[0:{}];",
            w - 1,
            cfg.tree_words() - 1
        )),
        "TreeModule memory of the configured width and depth"
    );
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("top.v");
    std::fs::write(&path, &verilog).unwrap();
    lint_top(dir.path());
}

#[test]
#[cfg_attr(
    not(all(has_yosys, has_verilator, has_iverilog)),
    ignore = "needs yosys, verilator and iverilog"
)]
fn small_core_verilog_is_clean() {
    check_config(&small_config(
        PhotonLayout::new([7, 6, 5]),
        8,
        4,
        3,
        Metric::L2,
    ));
}

#[test]
#[cfg_attr(
    not(all(has_yosys, has_verilator, has_iverilog)),
    ignore = "needs yosys, verilator and iverilog"
)]
fn paper_core_verilog_is_clean() {
    check_config(&CoreConfig::paper());
}

/// The barrel port's Verilog (LUT-RAM and BlockRAM templates, the comparator tree,
/// struct-field slices) through the same checks.
#[test]
#[cfg_attr(
    not(all(has_yosys, has_verilator, has_iverilog)),
    ignore = "needs yosys, verilator and iverilog"
)]
fn barrel_core_verilog_is_clean() {
    check_config(
        &CoreConfig::builder()
            .traversal(Traversal::Cell)
            .controller(Controller::Barrel)
            .queries_per_port(16)
            .build()
            .unwrap(),
    );
}

/// The TreeModule alone maps to Virtex-6 BlockRAM (RAMB36E1/RAMB18E1), not LUTs.
#[test]
#[cfg_attr(not(has_yosys), ignore = "needs yosys")]
fn tree_module_infers_block_ram() {
    use photon_fpga::hw::store::tree_module::TreeModule;
    use rust_hdl::prelude::*;
    let mut uut = TreeModule::<32>::new(10, 32);
    uut.connect_all();
    check_all(&uut).unwrap();
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("top.v"), generate_verilog(&uut)).unwrap();
    require("yosys");
    let out = Command::new("yosys")
        .current_dir(dir.path())
        .args([
            "-p",
            "read_verilog top.v; synth_xilinx -family xc6v -flatten -top top; stat",
        ])
        .output()
        .unwrap();
    let log = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{log}");
    assert!(
        log.contains("RAMB36E1") || log.contains("RAMB18E1"),
        "no BlockRAM:\n{log}"
    );
}

#[test]
fn export_rejects_unsupported_configs() {
    for (k, q) in [(0, 21), (65, 21), (10, 0), (10, 33)] {
        let mut cfg = CoreConfig::paper();
        cfg.k = k;
        cfg.queries_per_port = q;
        assert!(export_verilog(&cfg).is_err(), "K = {k}, Q = {q} accepted");
    }
}

/// An independent reading of `module top`'s port declarations in the Verilog text.
fn parse_top_ports(verilog: &str) -> Vec<Port> {
    let start = verilog.find("module top(").expect("module top");
    let mut ports = vec![];
    for line in verilog[start..].lines().skip(1) {
        let t = line.trim();
        let input = t.starts_with("input ");
        if !input && !t.starts_with("output ") {
            if ports.is_empty() && (t.is_empty() || t.starts_with("//")) {
                continue;
            }
            break;
        }
        let decl = t.trim_end_matches(';');
        let name = decl.split_whitespace().last().unwrap().to_string();
        let width = match (decl.find('['), decl.find(':')) {
            (Some(a), Some(b)) if a < b => decl[a + 1..b].trim().parse::<usize>().unwrap() + 1,
            _ => 1,
        };
        ports.push(Port { name, input, width });
    }
    ports
}

/// The port list taken from the block (cross-simulation, shell) is the one the
/// exported `module top` declares, for the core and for an array.
#[test]
fn block_ports_are_the_exported_ports() {
    for trees in [1, 2] {
        let cfg = CoreConfig::paper_builder().trees(trees).build().unwrap();
        let e = export_verilog(&cfg).unwrap();
        let parsed = parse_top_ports(&e.verilog);
        assert!(parsed.len() >= 14, "{parsed:?}");
        assert_eq!(e.ports, parsed, "T = {trees}");
        assert!(e.ports.iter().any(|p| p.name == "query$data" && p.input));
        assert!(e.ports.iter().any(|p| p.name == "result$data" && !p.input));
    }
}

/// Golden files pin rust-hdl's output format that the post-processing reads (the
/// export of one small block) and the glitch-free rewrite of it. After a deliberate
/// change, regenerate with `PHOTON_FPGA_UPDATE_GOLDEN=1 cargo test --test hw golden`
/// and review the diff.
#[test]
fn export_and_glitch_free_match_golden_files() {
    let e = export_block(PortArbiter::default()).unwrap();
    let rewritten = glitch_free(&e.verilog).unwrap();
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("testbenches/golden");
    for (file, text) in [
        ("port_arbiter.v", &e.verilog),
        ("port_arbiter_glitch_free.v", &rewritten),
    ] {
        let path = dir.join(file);
        if std::env::var_os("PHOTON_FPGA_UPDATE_GOLDEN").is_some() {
            std::fs::create_dir_all(&dir).unwrap();
            std::fs::write(&path, text).unwrap();
        }
        let golden =
            std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        assert_eq!(text, &golden, "{file} differs from its golden file");
    }
    // The rewrite computes into shadows and copies once at the end of the block.
    assert!(rewritten.contains("__xs"));
    assert!(!e.verilog.contains("__xs"));
}

/// Cells and flip-flops of `cfg`'s core after yosys' generic `synth`, and the
/// flip-flops left after a SAT-based search for constant ones (`opt_dff -sat`).
fn generic_synth(cfg: &CoreConfig) -> (usize, usize, usize) {
    let verilog = export_verilog(cfg).expect("export").verilog;
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("top.v"), &verilog).unwrap();
    require("yosys");
    // Generic synthesis that keeps the TreeModule a memory (`$mem`): its bits are
    // the map's, not the datapath's.
    let script = "read_verilog top.v; synth -flatten -top top -run begin:fine; opt -full; \
                  techmap; opt -fast; abc -fast; opt -fast; tee -o before.txt stat; \
                  opt_dff -sat; opt_clean; tee -o after.txt stat";
    run_tool(
        Command::new("yosys")
            .current_dir(dir.path())
            .args(["-q", "-p", script]),
        "yosys synth",
    );
    let stat = |f: &str| {
        let text = std::fs::read_to_string(dir.path().join(f)).unwrap();
        let count = |pred: &dyn Fn(&str) -> bool| -> usize {
            text.lines()
                .filter_map(|l| {
                    let mut w = l.split_whitespace();
                    let (a, b) = (w.next()?, w.next()?);
                    // yosys 0.23: "     $_DFF_P_    123"; newer: "123 $_DFF_P_".
                    match (a.parse::<usize>(), b.parse::<usize>()) {
                        (Ok(n), _) if pred(b) => Some(n),
                        (_, Ok(n)) if pred(a) => Some(n),
                        _ => None,
                    }
                })
                .sum()
        };
        let cells = text
            .lines()
            .find_map(|l| l.trim().strip_prefix("Number of cells:"))
            .map(|n| n.trim().parse::<usize>().unwrap())
            .expect("cell count");
        (
            cells,
            count(&|c: &str| {
                c.starts_with("$_DFF")
                    || c.starts_with("$_SDFF")
                    || c.starts_with("$_DFFE")
                    || c.starts_with("$_SDFFE")
            }),
        )
    };
    let (cells, ffs) = stat("before.txt");
    let (_, ffs_after) = stat("after.txt");
    (cells, ffs, ffs_after)
}

/// "Only what the scene needs": the widths come from the configuration, so a
/// small map's core synthesises to fewer cells and flip-flops than a large one's
/// with the same QueryModule count, and no flip-flop that synthesis keeps is a
/// constant: a SAT-based `opt_dff` finds none to remove (it found the radius
/// registers' bits above the distance width and the heap address's bits above H
/// until those were masked too). One test per controller, so that the two
/// syntheses run side by side.
#[test]
#[cfg_attr(not(has_yosys), ignore = "needs yosys")]
fn a_small_map_synthesises_smaller_with_no_constant_flip_flops() {
    small_smaller_than_large(Controller::Modules);
}

/// The same for the barrel controller.
#[test]
#[cfg_attr(not(has_yosys), ignore = "needs yosys")]
fn a_small_barrel_map_synthesises_smaller_with_no_constant_flip_flops() {
    small_smaller_than_large(Controller::Barrel);
}

fn small_smaller_than_large(controller: Controller) {
    let small = CoreConfig::builder()
        .layout(PhotonLayout::new([6, 6, 5]))
        .address_bits(6)
        .k(4)
        .metric(Metric::L2)
        .traversal(Traversal::Cell)
        .controller(controller)
        .queries_per_port(2);
    let large = small
        .layout(PhotonLayout::new([10, 10, 10]))
        .address_bits(10)
        .k(10)
        .metric(Metric::L1)
        .build()
        .unwrap();
    let small = small.build().unwrap();
    let (small_cells, small_ffs, small_after) = generic_synth(&small);
    let (large_cells, large_ffs, large_after) = generic_synth(&large);
    eprintln!(
        "{controller}: small: {small_cells} cells, {small_ffs} FFs; large: {large_cells} cells, {large_ffs} FFs"
    );
    assert!(small_ffs > 0 && large_ffs > 0);
    assert!(small_cells < large_cells, "{small_cells} >= {large_cells}");
    assert!(small_ffs < large_ffs, "{small_ffs} >= {large_ffs}");
    for (name, before, after) in [
        ("small", small_ffs, small_after),
        ("large", large_ffs, large_after),
    ] {
        eprintln!("{name}: opt_dff -sat leaves {after} of {before} flip-flops");
        assert_eq!(
            after,
            before,
            "{name}: {} of {before} flip-flops are constant",
            before - after
        );
    }
}

/// The export a user builds into a system has no measurement outputs: the top's
/// ports are the measured export's without them (and without nothing else), the
/// logic is the same, and it lints. The cocotb bench (testbenches/cocotb) runs
/// these exports behind the AXI4-Stream top against its own brute force.
#[test]
#[cfg_attr(
    not(all(has_yosys, has_verilator)),
    ignore = "needs yosys and verilator"
)]
fn the_users_export_has_no_measurement_outputs() {
    use photon_fpga::hw::config::bank_config::{BankMapping, BankPorts};
    use photon_fpga::hw::config::core_config::Banking;
    use photon_fpga::hw::export::verilog::{is_status_port, without_status};
    let plain = small_config(PhotonLayout::new([6, 6, 6]), 9, 4, 2, Metric::L1);
    let banked = |lines: Option<u32>| {
        CoreConfig::builder()
            .k(6)
            .metric(Metric::L2)
            .controller(Controller::Barrel)
            .traversal(Traversal::Cell)
            .address_bits(12)
            .trees(2)
            .banking(Some(Banking {
                bank_bits: 2,
                replicated_levels: 4,
                ports: BankPorts::Split,
                mapping: BankMapping::Xor,
            }))
            .cache_lines(lines)
            .build()
            .expect("a banked core")
    };
    let array = plain.to_builder().trees(2).build().expect("an array");
    for cfg in [plain, banked(None), banked(Some(16)), array] {
        let measured = export_verilog(&cfg).expect("export");
        let user = without_status(&measured).expect("strip");
        let kept: Vec<&Port> = measured
            .ports
            .iter()
            .filter(|p| p.input || !is_status_port(&p.name))
            .collect();
        assert!(kept.len() < measured.ports.len(), "{cfg}: no status port");
        assert_eq!(user.ports.iter().collect::<Vec<_>>(), kept, "{cfg}");
        // The top module's text (its submodules keep their own ports).
        let top = user.verilog.split("endmodule").next().unwrap();
        for p in measured.ports.iter().filter(|p| !kept.contains(p)) {
            assert!(
                !top.contains(&format!("output reg  {};", p.name))
                    && !top.contains(&format!("output wire  {};", p.name)),
                "{cfg}: {} still an output",
                p.name
            );
        }
        // Only the top's header and those declarations changed.
        let changed = measured
            .verilog
            .lines()
            .zip(user.verilog.lines())
            .filter(|(a, b)| a != b)
            .count();
        assert_eq!(changed, 1 + measured.ports.len() - kept.len(), "{cfg}");
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("top.v"), &user.verilog).unwrap();
        lint_top(dir.path());
    }
}
