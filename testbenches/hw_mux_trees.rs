//! MuxTrees against plain indexing: every index of every tree, for 1 to 4,096
//! inputs (a power of two or rounded up to one), random inputs; and its exported
//! Verilog, linted and run in Icarus against the same model for every index.

use photon_fpga::hw::export::verilog::export_block;
use photon_fpga::hw::primitives::mux_trees::MuxTrees;
use rand::Rng;
use rust_hdl::prelude::*;

use crate::common::{lint_top, require, rng, run_tool, settle};

type Word = Bits<16>;

/// Random inputs for `uut`; the values, flat as its inputs.
fn drive(uut: &mut MuxTrees<Word, 12>, r: &mut rand_pcg::Pcg64) -> Vec<u64> {
    let v: Vec<u64> = (0..uut.inputs.len())
        .map(|_| r.gen::<u16>() as u64)
        .collect();
    for (i, x) in v.iter().enumerate() {
        uut.inputs[i].next = (*x).into();
    }
    v
}

#[test]
fn every_tree_picks_the_input_its_index_names() {
    let mut r = rng(7);
    for (trees, inputs) in [
        (1, 1),
        (3, 1),
        (2, 2),
        (3, 5),
        (4, 8),
        (2, 64),
        (1, 2048),
        (1, 4096),
    ] {
        let mut uut = MuxTrees::<Word, 12>::new(trees, inputs);
        uut.connect_all();
        check_all(&uut).unwrap();
        let leaves = uut.leaves();
        assert_eq!(leaves, inputs.next_power_of_two());
        let v = drive(&mut uut, &mut r);
        // Every index on tree 0 (the others on random ones, so that trees do not
        // share an index by accident), then random indices with bits above n.
        let rounds = leaves.min(256) + 64;
        for round in 0..rounds {
            let idx: Vec<usize> = (0..trees)
                .map(|m| {
                    if m == 0 && round < leaves.min(256) {
                        round * (leaves / leaves.min(256))
                    } else {
                        r.gen_range(0..4096)
                    }
                })
                .collect();
            for (m, i) in idx.iter().enumerate() {
                uut.index[m].next = (*i as u64).into();
            }
            settle(&mut uut);
            for (m, i) in idx.iter().enumerate() {
                let want = v[m * leaves + i % leaves];
                assert_eq!(
                    uut.output[m].val().to_u64(),
                    want,
                    "{trees} trees of {inputs}: tree {m}, index {i}"
                );
            }
        }
    }
}

/// An Icarus testbench: for each case, the inputs and indices, then the expected
/// outputs after a delay, `$fatal` on a mismatch.
fn icarus_bench(cases: &[(Vec<u64>, Vec<usize>)], leaves: usize) -> String {
    let mut s = String::from("module bench;\n");
    let (inputs, trees) = (cases[0].0.len(), cases[0].1.len());
    for i in 0..inputs {
        s += &format!("reg [15:0] in{i};\n");
    }
    for m in 0..trees {
        s += &format!("reg [11:0] ix{m};\nwire [15:0] out{m};\n");
    }
    s += "top uut(";
    let mut ports: Vec<String> = (0..inputs).map(|i| format!(".inputs${i}(in{i})")).collect();
    for m in 0..trees {
        ports.push(format!(".index${m}(ix{m})"));
        ports.push(format!(".output${m}(out{m})"));
    }
    s += &ports.join(", ");
    s += ");\ninitial begin\n";
    for (v, idx) in cases {
        for (i, x) in v.iter().enumerate() {
            s += &format!("  in{i} = 16'd{x};\n");
        }
        for (m, i) in idx.iter().enumerate() {
            s += &format!("  ix{m} = 12'd{i};\n");
        }
        s += "  #1;\n";
        for (m, i) in idx.iter().enumerate() {
            let want = v[m * leaves + i % leaves];
            s += &format!(
                "  if (out{m} !== 16'd{want}) begin $display(\"tree {m} index {i}: %d, want {want}\", out{m}); $fatal(1); end\n"
            );
        }
    }
    s += "  $display(\"PASS\");\n  $finish;\nend\nendmodule\n";
    s
}

#[test]
#[cfg_attr(
    not(all(has_yosys, has_verilator, has_iverilog)),
    ignore = "needs yosys, verilator and iverilog"
)]
fn exported_verilog_lints_and_picks_the_same_inputs() {
    let mut r = rng(8);
    for (trees, inputs) in [(1, 1), (3, 6), (2, 32)] {
        let uut = MuxTrees::<Word, 12>::new(trees, inputs);
        let leaves = uut.leaves();
        let e = export_block(uut).unwrap();
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("top.v"), &e.verilog).unwrap();
        lint_top(dir.path());
        let cases: Vec<(Vec<u64>, Vec<usize>)> = (0..40)
            .map(|_| {
                let v = (0..trees * leaves).map(|_| r.gen::<u16>() as u64).collect();
                let idx = (0..trees).map(|_| r.gen_range(0..4096)).collect();
                (v, idx)
            })
            .collect();
        std::fs::write(dir.path().join("bench.v"), icarus_bench(&cases, leaves)).unwrap();
        require("iverilog");
        run_tool(
            std::process::Command::new("iverilog")
                .current_dir(dir.path())
                .args(["-g2005", "-o", "bench.vvp", "bench.v", "top.v"]),
            "iverilog",
        );
        let out = std::process::Command::new("vvp")
            .current_dir(dir.path())
            .arg("bench.vvp")
            .output()
            .unwrap();
        let text = String::from_utf8_lossy(&out.stdout);
        assert!(
            out.status.success() && text.contains("PASS"),
            "{trees} trees of {inputs}:\n{text}"
        );
    }
}
