//! The exported Verilog, simulated by Verilator, gives the same results as the
//! Rust model and as knn::search. This guards against rust-hdl's silent
//! Rust-vs-Verilog divergences (operator precedence, dropped match guards, …): the
//! Rust simulation alone cannot see them. A missing Verilator fails the test when
//! CI=true and is reported loudly otherwise. (Icarus runs rust-hdl's one-big-
//! `always @(*)`-per-module output at ~30 cycles/s, far too slow; Verilator builds
//! it in seconds and runs it instantly.)

mod common;
use common::*;
use photon_fpga::host::kdtree::PackedTree;
use photon_fpga::hw::config::CoreConfig;
use photon_fpga::hw::metric::Metric;
use photon_fpga::hw::photon_word::PhotonLayout;
use photon_fpga::hw::sim::{run_gather, HwQuery, HwResult, SimOptions};
use photon_fpga::hw::verilog::export_verilog;
use std::fmt::Write;
use std::process::Command;

fn verilator_available() -> bool {
    let found = Command::new("verilator").arg("--version").output().is_ok();
    if !found {
        if std::env::var("CI").map(|v| v == "true").unwrap_or(false) {
            panic!("verilator is not installed (CI=true)");
        }
        eprintln!("\n!!! verilator NOT FOUND: the Verilog of the core was NOT co-simulated !!!\n");
    }
    found
}

/// A Verilog testbench that resets the core, loads `tree`, streams `queries` and
/// prints every result beat. Inputs change on the falling edge; a handshake is
/// sampled just after it, which is what the rising edge will see.
fn testbench(tree: &PackedTree, queries: &[HwQuery]) -> String {
    let n = tree.len();
    let nq = queries.len();
    let mut init = String::new();
    for a in 1..=n {
        writeln!(init, "    words[{a}] = 32'h{:x};", tree.words[a]).unwrap();
    }
    for (i, q) in queries.iter().enumerate() {
        writeln!(
            init,
            "    qx[{i}] = {}; qy[{i}] = {}; qz[{i}] = {}; qr[{i}] = 32'd{}; qk[{i}] = {};",
            q.coords[0],
            q.coords[1],
            q.coords[2],
            q.radius.min(u32::MAX as u64),
            q.k
        )
        .unwrap();
    }
    format!(
        r#"`timescale 1ns/1ps
module tb;
  reg clock = 0;
  reg reset = 1;
  reg load_valid = 0; wire load_ready; reg [23:0] load_address = 0; reg [31:0] load_word = 0; reg load_last = 0;
  reg query_valid = 0; wire query_ready; reg [31:0] query_id = 0;
  reg [15:0] query_x = 0, query_y = 0, query_z = 0; reg [31:0] query_radius = 0; reg [7:0] query_k = 0;
  wire result_valid; reg result_ready = 1; wire result_header, result_last;
  wire [31:0] result_id; wire [7:0] result_count; wire [31:0] result_visited;
  wire [23:0] result_address; wire [31:0] result_dist;
  wire port_a_reading, port_b_reading, all_busy;
  top dut(.clock(clock), .reset(reset),
    .load_valid(load_valid), .load_ready(load_ready), .load_address(load_address),
    .load_word(load_word), .load_last(load_last),
    .query_valid(query_valid), .query_ready(query_ready), .query_id(query_id),
    .query_x(query_x), .query_y(query_y), .query_z(query_z),
    .query_radius(query_radius), .query_k(query_k),
    .result_valid(result_valid), .result_ready(result_ready), .result_header(result_header),
    .result_last(result_last), .result_id(result_id), .result_count(result_count),
    .result_visited(result_visited), .result_address(result_address), .result_dist(result_dist),
    .port_a_reading(port_a_reading), .port_b_reading(port_b_reading), .all_busy(all_busy));
  always #5 clock = ~clock;
  reg [31:0] words [1:{n}];
  reg [15:0] qx [0:{nqm}]; reg [15:0] qy [0:{nqm}]; reg [15:0] qz [0:{nqm}];
  reg [31:0] qr [0:{nqm}]; reg [7:0] qk [0:{nqm}];
  integer next, received, cycles, fire_q;
  initial begin
{init}
    @(negedge clock); @(negedge clock); @(negedge clock);
    reset = 0;
    next = 1;
    while (next <= {n}) begin
      load_valid = 1; load_address = next; load_word = words[next]; load_last = (next == {n});
      #1;
      if (load_ready) next = next + 1;
      @(negedge clock);
    end
    load_valid = 0;
    next = 0; received = 0; cycles = 0;
    while (received < {nq} && cycles < 2000000) begin
      query_valid = (next < {nq});
      if (next < {nq}) begin
        query_id = next; query_x = qx[next]; query_y = qy[next]; query_z = qz[next];
        query_radius = qr[next]; query_k = qk[next];
      end
      #1;
      fire_q = query_valid && query_ready;
      if (result_valid && result_ready) begin
        if (result_header) $display("H %0d %0d %0d", result_id, result_count, result_visited);
        else $display("E %0d %0d", result_address, result_dist);
        if (result_last) received = received + 1;
      end
      if (fire_q) next = next + 1;
      cycles = cycles + 1;
      @(negedge clock);
    end
    $display("END %0d", received);
    $finish;
  end
endmodule
"#,
        nqm = nq.max(1) - 1,
    )
}

fn parse(out: &str, queries: &[HwQuery]) -> Vec<HwResult> {
    let mut results: Vec<Option<HwResult>> = vec![None; queries.len()];
    let mut current = None;
    for line in out.lines() {
        let f: Vec<&str> = line.split_whitespace().collect();
        match f.first() {
            Some(&"H") => {
                let id: usize = f[1].parse().unwrap();
                assert!(results[id].is_none(), "duplicate result {id}");
                results[id] = Some(HwResult {
                    id: queries[id].id,
                    found: vec![],
                    visited: f[3].parse().unwrap(),
                });
                current = Some(id);
            }
            Some(&"E") => {
                let r = results[current.expect("header first")].as_mut().unwrap();
                r.found.push((f[1].parse().unwrap(), f[2].parse().unwrap()));
            }
            _ => {}
        }
    }
    results
        .into_iter()
        .map(|r| r.expect("every query answered"))
        .collect()
}

/// Where the co-simulation runs: a temp dir, or `PHOTON_FPGA_COSIM_DIR` to keep it.
enum KeepDir {
    Temp(tempfile::TempDir),
    Kept(std::path::PathBuf),
}

impl KeepDir {
    fn path(&self) -> &std::path::Path {
        match self {
            KeepDir::Temp(t) => t.path(),
            KeepDir::Kept(p) => p,
        }
    }
}

fn cosim(cfg: &CoreConfig, points: &[[u32; 3]], queries: &[HwQuery]) {
    if !verilator_available() {
        return;
    }
    let tree = pack(points, cfg.layout);
    let dir = tempfile::tempdir().unwrap();
    let dir = match std::env::var_os("PHOTON_FPGA_COSIM_DIR") {
        Some(keep) => {
            std::fs::create_dir_all(&keep).unwrap();
            KeepDir::Kept(keep.into())
        }
        None => KeepDir::Temp(dir),
    };
    std::fs::write(dir.path().join("top.v"), export_verilog(cfg).unwrap()).unwrap();
    std::fs::write(dir.path().join("tb.v"), testbench(&tree, queries)).unwrap();
    // Verilator 5.006 fires an extra edge at time 0: the testbench drives and
    // samples on the falling edge. -O0 keeps the C++ build short.
    let build = Command::new("verilator")
        .current_dir(dir.path())
        .args([
            "--binary",
            "--timing",
            "-Wno-WIDTH",
            "-Wno-UNOPTFLAT",
            "-Wno-fatal",
            "--top-module",
            "tb",
            "-MAKEFLAGS",
            "OPT_FAST=-O0 OPT_SLOW=-O0 OPT_GLOBAL=-O0",
            "-o",
            "simv",
            "tb.v",
            "top.v",
        ])
        .output()
        .unwrap();
    assert!(
        build.status.success(),
        "{}",
        String::from_utf8_lossy(&build.stderr)
    );
    let run = Command::new(dir.path().join("obj_dir/simv"))
        .current_dir(dir.path())
        .output()
        .unwrap();
    let out = String::from_utf8_lossy(&run.stdout);
    assert!(
        out.contains(&format!("END {}", queries.len())),
        "Verilog run incomplete:\n{out}"
    );
    let verilog_results = parse(&out, queries);
    check_results(cfg, &tree, points, queries, &verilog_results);
    let (rust_results, _) = run_gather(cfg, &tree, queries, &SimOptions::default()).unwrap();
    assert_eq!(
        verilog_results, rust_results,
        "Verilog and Rust simulations differ"
    );
}

#[test]
fn verilog_matches_rust_and_software_l2() {
    let layout = PhotonLayout::new([7, 6, 5]);
    let mut r = rng(51);
    let points = random_points(&mut r, 150, layout);
    let queries = random_queries(&mut r, 30, layout, 5, Metric::L2);
    let cfg = CoreConfig {
        layout,
        address_bits: 8,
        k: 5,
        queries_per_port: 4,
        metric: Metric::L2,
    };
    cosim(&cfg, &points, &queries);
}

#[test]
fn verilog_matches_rust_and_software_paper_l1() {
    let cfg = CoreConfig::paper();
    let mut r = rng(52);
    let points = random_points(&mut r, 1000, cfg.layout);
    let queries = random_queries(&mut r, 60, cfg.layout, cfg.k, cfg.metric);
    cosim(&cfg, &points, &queries);
}
