//! Cycle-exact cross-simulation of the exported Verilog against the rust-hdl model.
//!
//! [`record`] drives a [`PhotonSearchCore`] (or, for T > 1 trees, a
//! [`PhotonSearchArray`]) cycle by cycle with a reactive host
//! (reset, load each map, stream its queries, accept results; seeded random stalls on
//! every valid/ready stream; the next map is presented as soon as the previous map's
//! queries are all accepted, so the core must hold it back until its searches are
//! done). It records the input vector of every cycle (the *stimulus*) and every
//! handshake and status change it observes (the *responses*). A generated Verilog
//! testbench ([`testbench_verilog`]) replays the stimulus into the exported `top`
//! without looking at any output and writes the responses it samples in the same
//! format; under Icarus Verilog and Verilator the two response files must be equal
//! byte for byte ([`compare`]), which also means every result leaves at the same
//! cycle. Replaying blindly is what makes a divergence visible: if the Verilog
//! raises a ready one cycle late, its handshake lines move.
//!
//! # Stimulus file (`stim.hex`)
//!
//! Text, read by `$readmemh`. Lines starting with `//` are comments. Then one line
//! per clock cycle, cycle 0 first, with [`inputs`]`().len()` = 13 hexadecimal fields
//! separated by one space, in this fixed column order (width in bits; `W`, the
//! photon-word width [`CoreConfig::word_width`], is 32 or 64):
//!
//! ```text
//! reset(1) load_valid(1) load_address(24) load_word(W) load_last(1)
//! query_valid(1) query_id(32) query_x(16) query_y(16) query_z(16)
//! query_radius(32) query_k(8) result_ready(1)
//! ```
//!
//! Line `c` holds the inputs applied after the falling edge that precedes rising
//! edge `c` (cycle `c`); they hold until the next falling edge. Fields are
//! zero-padded to their width (1 hex digit per started 4 bits).
//!
//! # Response file (`resp.txt`)
//!
//! One line per event, in cycle order, `CYCLE` in decimal, fields in zero-padded hex
//! of the port's width, sampled just before rising edge `CYCLE` (what that edge acts
//! on). Within a cycle the order is L, Q, R, S:
//!
//! ```text
//! CYCLE L load_address load_word load_last        a load beat moved (valid && ready)
//! CYCLE Q query_id x y z radius k                 a query moved
//! CYCLE R header last id count visited address dist   a result beat moved
//! CYCLE S port_a_reading port_b_reading all_busy  status changed (and at cycle 0)
//! END CYCLES                                       the run's cycle count
//! ```
//!
//! A result header beat is `R 1 …` (id, count, visited meaningful); an entry beat is
//! `R 0 …` (id, address, dist meaningful); all fields are compared anyway, so any
//! difference in what the core drives on a moving beat is a mismatch.
//!
//! [`write_replay_dir`] writes `top.v`, `xsim_tb.v`, `stim.hex`, `expected.txt` and
//! `run_icarus.sh` / `run_verilator.sh` to a directory for replay by hand (Icarus
//! runs the [`glitch_free`] rewrite `top_icarus.v`, see there why).

use crate::host::error::Error;
use crate::host::kdtree::PackedTree;
use crate::hw::array::PhotonSearchArray;
use crate::hw::config::{dispatch_widths, CoreConfig};
use crate::hw::core::PhotonSearchCore;
use crate::hw::sim::{HwQuery, HwResult};
use crate::hw::top::SearchTop;
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;
use rust_hdl::prelude::*;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;

/// Input ports of `top` in stimulus column order, with their widths, for a core with
/// `word_bits`-bit photon words.
pub fn inputs(word_bits: u32) -> [(&'static str, u32); 13] {
    [
        ("reset", 1),
        ("load_valid", 1),
        ("load_address", 24),
        ("load_word", word_bits),
        ("load_last", 1),
        ("query_valid", 1),
        ("query_id", 32),
        ("query_x", 16),
        ("query_y", 16),
        ("query_z", 16),
        ("query_radius", 32),
        ("query_k", 8),
        ("result_ready", 1),
    ]
}

/// One cycle's input vector, in [`inputs`] order.
pub type InputVector = [u64; 13];

/// Reset cycles at the start of every recording.
pub const RESET_CYCLES: usize = 2;
/// Idle cycles recorded after the last result.
pub const TAIL_CYCLES: usize = 4;

/// One map and the queries run on it.
#[derive(Clone, Debug)]
pub struct XsimMap {
    pub tree: PackedTree,
    pub queries: Vec<HwQuery>,
}

/// A recorded rust-hdl run.
#[derive(Clone, Debug)]
pub struct XsimRun {
    /// The core's photon-word width ([`CoreConfig::word_width`]).
    pub word_bits: u32,
    pub stimulus: Vec<InputVector>,
    /// The response file's text.
    pub responses: String,
    /// Per map, per query in input order: what the rust-hdl core returned.
    pub results: Vec<Vec<HwResult>>,
}

impl XsimRun {
    pub fn cycles(&self) -> usize {
        self.stimulus.len()
    }
}

fn xsim_error(msg: impl Into<String>) -> Error {
    Error::new(format!("cross-simulation: {}", msg.into()))
}

fn hex_digits(bits: u32) -> usize {
    bits.div_ceil(4) as usize
}

/// The stimulus file's text (see the module doc).
pub fn stimulus_text(run_: &XsimRun) -> String {
    let columns = inputs(run_.word_bits);
    let mut s = String::with_capacity(run_.stimulus.len() * 64 + 512);
    s.push_str("// photon-fpga cross-simulation stimulus: one line per cycle, columns:\n//");
    for (name, bits) in columns {
        let _ = write!(s, " {name}({bits})");
    }
    s.push('\n');
    for v in &run_.stimulus {
        for (i, (&x, (_, bits))) in v.iter().zip(columns).enumerate() {
            if i > 0 {
                s.push(' ');
            }
            let _ = write!(s, "{x:0w$x}", w = hex_digits(bits));
        }
        s.push('\n');
    }
    s
}

/// The host side: what it presents this cycle and where it is.
struct Host<'a> {
    maps: &'a [XsimMap],
    rng: Option<Pcg64>,
    /// Map being loaded or queried.
    map: usize,
    loading: bool,
    load_next: usize,
    load_presenting: bool,
    query_next: usize,
    query_presenting: bool,
    /// Global query tag = index into `tags`.
    tags: Vec<(usize, usize)>,
    tag_base: Vec<usize>,
    results: Vec<Vec<Option<HwResult>>>,
    received: usize,
    /// Result in progress: (tag, count).
    current: Option<(usize, usize)>,
}

impl Host<'_> {
    fn stall(&mut self) -> bool {
        match &mut self.rng {
            Some(r) => r.gen_bool(0.35),
            None => false,
        }
    }

    fn all_sent(&self) -> bool {
        self.map + 1 == self.maps.len()
            && !self.loading
            && self.query_next == self.maps[self.map].queries.len()
    }
}

/// Drive a fresh core for `cfg` through `maps` (each loaded, then queried; random
/// stalls from `stall_seed`), recording stimulus and responses.
pub fn record(
    cfg: &CoreConfig,
    maps: &[XsimMap],
    stall_seed: Option<u64>,
) -> Result<XsimRun, Error> {
    cfg.validate()?;
    if maps.is_empty() {
        return Err(xsim_error("no map"));
    }
    for m in maps {
        cfg.check_map(&m.tree)?;
        for q in &m.queries {
            if q.k == 0 || q.k as usize > cfg.k {
                return Err(xsim_error(format!(
                    "query {}: k = {} not in 1..=K",
                    q.id, q.k
                )));
            }
            if (0..3).any(|a| q.coords[a] > cfg.layout.coord_max(a)) {
                return Err(xsim_error(format!(
                    "query {}: coordinate off the grid",
                    q.id
                )));
            }
        }
    }
    dispatch_widths!(cfg, record_with(cfg, maps, stall_seed))
}

/// [`record`] on the top for `cfg` (the core, or the array of T > 1 trees) with
/// `S`-bit slot masks and `W`-bit photon words.
fn record_with<const S: usize, const W: usize>(
    cfg: &CoreConfig,
    maps: &[XsimMap],
    stall_seed: Option<u64>,
) -> Result<XsimRun, Error> {
    if cfg.trees == 1 {
        record_top::<W, PhotonSearchCore<S, W>>(cfg, maps, stall_seed)
    } else {
        record_top::<W, PhotonSearchArray<S, W>>(cfg, maps, stall_seed)
    }
}

fn record_top<const W: usize, U: SearchTop<W>>(
    cfg: &CoreConfig,
    maps: &[XsimMap],
    stall_seed: Option<u64>,
) -> Result<XsimRun, Error> {
    let mut uut = Box::new(U::elaborate(cfg));
    uut.connect_all();
    check_all(uut.as_ref()).map_err(|e| xsim_error(format!("circuit check failed: {e:?}")))?;
    let settle = |uut: &mut U| -> Result<(), Error> {
        if simulate(uut, 200) {
            Ok(())
        } else {
            Err(xsim_error("the circuit did not settle"))
        }
    };
    uut.ports().clock.next = false.into();
    settle(uut.as_mut())?;

    let mut tags = vec![];
    let mut tag_base = vec![];
    for (mi, m) in maps.iter().enumerate() {
        tag_base.push(tags.len());
        tags.extend((0..m.queries.len()).map(|qi| (mi, qi)));
    }
    let total_queries = tags.len();
    let mut host = Host {
        maps,
        rng: stall_seed.map(Pcg64::seed_from_u64),
        map: 0,
        loading: true,
        load_next: 1,
        load_presenting: false,
        query_next: 0,
        query_presenting: false,
        tags,
        tag_base,
        results: maps.iter().map(|m| vec![None; m.queries.len()]).collect(),
        received: 0,
        current: None,
    };
    let word_bits = W as u32;
    let mut stimulus: Vec<InputVector> = vec![];
    let mut resp = String::new();
    let mut status: Option<[bool; 3]> = None;
    let mut tail = 0usize;
    let mut since_progress = 0u64;
    let patience = 10_000 + 8 * (cfg.tree_words() as u64 + 2) * cfg.issue_interval() as u64;
    let mut v: InputVector = [0; 13];
    loop {
        let cycle = stimulus.len();
        let done = host.received == total_queries && host.all_sent();
        if done {
            if tail == TAIL_CYCLES {
                break;
            }
            tail += 1;
        }
        // This cycle's inputs. Data fields keep their last value while not valid.
        let in_reset = cycle < RESET_CYCLES;
        v[0] = in_reset as u64;
        v[1] = 0;
        v[5] = 0;
        v[12] = 0;
        if !in_reset && !done {
            let m = &maps[host.map];
            if host.loading {
                if !host.load_presenting && !host.stall() {
                    host.load_presenting = true;
                }
                let n = m.tree.len();
                v[1] = host.load_presenting as u64;
                v[2] = host.load_next as u64;
                v[3] = m.tree.words[host.load_next];
                v[4] = (host.load_next == n) as u64;
            } else if host.query_next < m.queries.len() {
                if !host.query_presenting && !host.stall() {
                    host.query_presenting = true;
                }
                let q = &m.queries[host.query_next];
                v[5] = host.query_presenting as u64;
                v[6] = (host.tag_base[host.map] + host.query_next) as u64;
                v[7] = q.coords[0] as u64;
                v[8] = q.coords[1] as u64;
                v[9] = q.coords[2] as u64;
                v[10] = q.radius.min(u32::MAX as u64);
                v[11] = q.k as u64;
            }
            v[12] = !host.stall() as u64;
        } else if done {
            v[12] = 1;
        }
        stimulus.push(v);
        {
            let u = uut.ports();
            u.reset.next = v[0] != 0;
            u.load_valid.next = v[1] != 0;
            u.load_address.next = v[2].into();
            u.load_word.next = v[3].into();
            u.load_last.next = v[4] != 0;
            u.query_valid.next = v[5] != 0;
            u.query_id.next = v[6].into();
            u.query_x.next = v[7].into();
            u.query_y.next = v[8].into();
            u.query_z.next = v[9].into();
            u.query_radius.next = v[10].into();
            u.query_k.next = v[11].into();
            u.result_ready.next = v[12] != 0;
            u.clock.next = false.into();
        }
        settle(uut.as_mut())?;
        // Sample what the rising edge will act on.
        let u = uut.ports();
        let load_fire = v[1] != 0 && u.load_ready.val();
        let query_fire = v[5] != 0 && u.query_ready.val();
        let result_fire = v[12] != 0 && u.result_valid.val();
        if load_fire {
            let _ = writeln!(
                resp,
                "{cycle} L {:06x} {:0w$x} {:x}",
                v[2],
                v[3],
                v[4],
                w = hex_digits(word_bits)
            );
        }
        if query_fire {
            let _ = writeln!(
                resp,
                "{cycle} Q {:08x} {:04x} {:04x} {:04x} {:08x} {:02x}",
                v[6], v[7], v[8], v[9], v[10], v[11]
            );
        }
        if result_fire {
            let header = u.result_header.val();
            let last = u.result_last.val();
            let tag = u.result_id.val().to_u64() as usize;
            let count = u.result_count.val().to_u64() as usize;
            let visited = u.result_visited.val().to_u64();
            let addr = u.result_address.val().to_u64();
            let dist = u.result_dist.val().to_u64();
            let _ = writeln!(
                resp,
                "{cycle} R {:x} {:x} {tag:08x} {count:02x} {visited:08x} {addr:06x} {dist:08x}",
                header as u8, last as u8
            );
            let &(mi, qi) = host
                .tags
                .get(tag)
                .ok_or_else(|| xsim_error(format!("result for unknown tag {tag}")))?;
            if header {
                if host.current.is_some() {
                    return Err(xsim_error("result header inside a result"));
                }
                if host.results[mi][qi].is_some() {
                    return Err(xsim_error(format!("duplicate result for tag {tag}")));
                }
                host.results[mi][qi] = Some(HwResult {
                    id: maps[mi].queries[qi].id,
                    found: Vec::with_capacity(count),
                    visited: visited as u32,
                });
                if (count == 0) != last {
                    return Err(xsim_error("result header: last and count disagree"));
                }
                host.current = Some((tag, count));
            } else {
                let (ctag, ccount) = host
                    .current
                    .ok_or_else(|| xsim_error("result entry without a header"))?;
                if ctag != tag {
                    return Err(xsim_error("result entries of two queries interleaved"));
                }
                let r = host.results[mi][qi].as_mut().expect("header seen");
                r.found.push((addr as u32, dist));
                if (r.found.len() == ccount) != last {
                    return Err(xsim_error("result entries: last and count disagree"));
                }
            }
            if last {
                host.current = None;
                host.received += 1;
            }
        }
        let st = [
            u.port_a_reading.val(),
            u.port_b_reading.val(),
            u.all_busy.val(),
        ];
        if status != Some(st) {
            let _ = writeln!(
                resp,
                "{cycle} S {:x} {:x} {:x}",
                st[0] as u8, st[1] as u8, st[2] as u8
            );
            status = Some(st);
        }
        // Rising edge.
        uut.ports().clock.next = true.into();
        settle(uut.as_mut())?;
        // Host bookkeeping after the edge.
        if load_fire {
            host.load_presenting = false;
            if host.load_next == maps[host.map].tree.len() {
                host.loading = false;
                host.query_next = 0;
            } else {
                host.load_next += 1;
            }
        }
        if query_fire {
            host.query_presenting = false;
            host.query_next += 1;
        }
        if !host.loading
            && host.query_next == maps[host.map].queries.len()
            && host.map + 1 < maps.len()
        {
            host.map += 1;
            host.loading = true;
            host.load_next = 1;
        }
        if load_fire || query_fire || result_fire || in_reset {
            since_progress = 0;
        } else {
            since_progress += 1;
            if since_progress > patience {
                return Err(xsim_error(format!(
                    "no progress for {patience} cycles at cycle {cycle}"
                )));
            }
        }
    }
    let _ = writeln!(resp, "END {}", stimulus.len());
    let results = host
        .results
        .into_iter()
        .map(|m| m.into_iter().map(|r| r.expect("all received")).collect())
        .collect();
    Ok(XsimRun {
        word_bits,
        stimulus,
        responses: resp,
        results,
    })
}

/// A Verilog testbench `xsim_tb` that replays a stimulus file into `top` and writes
/// the response file. Plusargs: `+stim=FILE +resp=FILE +cycles=N` (N <= `max_cycles`).
/// It drives the clock itself (inputs at the falling edge, outputs sampled 1 ns
/// before the rising edge), so Verilator's extra edge at time 0 cannot occur.
/// `word_bits` is the core's photon-word width ([`CoreConfig::word_width`]).
pub fn testbench_verilog(max_cycles: usize, word_bits: u32) -> String {
    let columns = inputs(word_bits);
    let ninputs = columns.len();
    // One memory word per stimulus field: as wide as the widest field.
    let stim_bits = columns.iter().map(|c| c.1).max().unwrap_or(32);
    let mut decl = String::new();
    let mut apply = String::new();
    for (i, (name, bits)) in columns.iter().enumerate() {
        if *bits == 1 {
            let _ = writeln!(decl, "  reg {name} = 0;");
        } else {
            let _ = writeln!(decl, "  reg [{}:0] {name} = 0;", bits - 1);
        }
        let _ = writeln!(apply, "      {name} = stim[base + {i}];");
    }
    format!(
        r#"`timescale 1ns/1ps
// Generated by photon_fpga::hw::xsim: replays a stimulus file into `top` and writes
// the response file (formats: src/hw/xsim.rs).
module xsim_tb;
  reg clock = 0;
{decl}  wire load_ready, query_ready, result_valid, result_header, result_last;
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
  reg [{stim_msb}:0] stim [0:{words}];
  reg [8*512-1:0] stim_file, resp_file;
  integer cycles, c, base, fd, have_status;
  reg [2:0] status;
  initial begin
    if (!$value$plusargs("stim=%s", stim_file)) begin $display("xsim_tb: +stim=FILE missing"); $finish; end
    if (!$value$plusargs("resp=%s", resp_file)) begin $display("xsim_tb: +resp=FILE missing"); $finish; end
    if (!$value$plusargs("cycles=%d", cycles)) begin $display("xsim_tb: +cycles=N missing"); $finish; end
    if (cycles > {max_cycles} || cycles < 1) begin $display("xsim_tb: cycles out of range"); $finish; end
    $readmemh(stim_file, stim, 0, cycles * {ninputs} - 1);
    fd = $fopen(resp_file, "w");
    have_status = 0;
    for (c = 0; c < cycles; c = c + 1) begin
      base = c * {ninputs};
{apply}      #4;
      if (load_valid && load_ready)
        $fwrite(fd, "%0d L %h %h %h\n", c, load_address, load_word, load_last);
      if (query_valid && query_ready)
        $fwrite(fd, "%0d Q %h %h %h %h %h %h\n", c, query_id, query_x, query_y, query_z,
                query_radius, query_k);
      if (result_valid && result_ready)
        $fwrite(fd, "%0d R %h %h %h %h %h %h %h\n", c, result_header, result_last, result_id,
                result_count, result_visited, result_address, result_dist);
      if (!have_status || status !== {{port_a_reading, port_b_reading, all_busy}}) begin
        $fwrite(fd, "%0d S %h %h %h\n", c, port_a_reading, port_b_reading, all_busy);
        status = {{port_a_reading, port_b_reading, all_busy}};
        have_status = 1;
      end
      #1 clock = 1;
      #5 clock = 0;
    end
    $fwrite(fd, "END %0d\n", cycles);
    $fclose(fd);
    $finish;
  end
endmodule
"#,
        words = max_cycles * ninputs - 1,
        stim_msb = stim_bits - 1,
    )
}

/// A Verilog simulator that can replay a stimulus.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Simulator {
    Icarus,
    Verilator,
}

impl Simulator {
    pub fn name(self) -> &'static str {
        match self {
            Simulator::Icarus => "icarus",
            Simulator::Verilator => "verilator",
        }
    }

    /// Is the simulator's compiler on the PATH?
    pub fn available(self) -> bool {
        let (cmd, arg) = match self {
            Simulator::Icarus => ("iverilog", "-V"),
            Simulator::Verilator => ("verilator", "--version"),
        };
        Command::new(cmd).arg(arg).output().is_ok()
    }

    fn build_command(self) -> Vec<&'static str> {
        match self {
            Simulator::Icarus => vec![
                "iverilog",
                "-g2005",
                "-o",
                "xsim_icarus.vvp",
                "-s",
                "xsim_tb",
            ],
            Simulator::Verilator => vec![
                "verilator",
                "--binary",
                "--timing",
                "-Wno-fatal",
                "-Wno-WIDTH",
                "-Wno-UNOPTFLAT",
                "--top-module",
                "xsim_tb",
                "-MAKEFLAGS",
                "OPT_FAST=-O0 OPT_SLOW=-O0 OPT_GLOBAL=-O0",
                "-o",
                "xsim_verilator",
            ],
        }
    }

    fn run_command(self) -> Vec<&'static str> {
        match self {
            Simulator::Icarus => vec!["vvp", "-n", "xsim_icarus.vvp"],
            Simulator::Verilator => vec!["obj_dir/xsim_verilator"],
        }
    }
}

fn run(dir: &Path, argv: &[&str], what: &str) -> Result<String, Error> {
    let out = Command::new(argv[0])
        .args(&argv[1..])
        .current_dir(dir)
        .output()
        .map_err(|e| xsim_error(format!("{what}: cannot run {}: {e}", argv[0])))?;
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    if !out.status.success() {
        return Err(xsim_error(format!(
            "{what} failed ({}):\n{text}",
            out.status
        )));
    }
    Ok(text)
}

/// Compile `verilog` (the core, top module `top`) with a testbench for up to
/// `max_cycles` cycles in `dir` (writes `top.v`, `xsim_tb.v`). Verilator gets the
/// export as it is; Icarus gets its [`glitch_free`] rewrite (the raw export makes
/// Icarus loop forever at one simulation time).
/// `word_bits` is the core's photon-word width ([`CoreConfig::word_width`]).
pub fn build(
    sim: Simulator,
    dir: &Path,
    verilog: &str,
    max_cycles: usize,
    word_bits: u32,
) -> Result<(), Error> {
    let io = |e: std::io::Error| xsim_error(format!("{}: {e}", dir.display()));
    std::fs::create_dir_all(dir).map_err(io)?;
    let verilog = match sim {
        Simulator::Icarus => glitch_free(verilog)?,
        Simulator::Verilator => verilog.to_string(),
    };
    std::fs::write(dir.join("top.v"), verilog).map_err(io)?;
    std::fs::write(
        dir.join("xsim_tb.v"),
        testbench_verilog(max_cycles, word_bits),
    )
    .map_err(io)?;
    let mut argv = sim.build_command();
    argv.extend(["xsim_tb.v", "top.v"]);
    run(dir, &argv, &format!("{} build", sim.name()))?;
    Ok(())
}

/// Replay `run`'s stimulus in the simulator built in `dir`; returns the response
/// file's text. `name` names the files (`NAME.stim.hex`, `NAME.resp.txt`).
pub fn replay(sim: Simulator, dir: &Path, name: &str, run_: &XsimRun) -> Result<String, Error> {
    let io = |e: std::io::Error| xsim_error(format!("{}: {e}", dir.display()));
    let stim = format!("{name}.stim.hex");
    let resp = format!("{name}.{}.resp.txt", sim.name());
    std::fs::write(dir.join(&stim), stimulus_text(run_)).map_err(io)?;
    std::fs::write(dir.join(format!("{name}.expected.txt")), &run_.responses).map_err(io)?;
    let _ = std::fs::remove_file(dir.join(&resp));
    let mut argv = sim.run_command();
    let plus = [
        format!("+stim={stim}"),
        format!("+resp={resp}"),
        format!("+cycles={}", run_.cycles()),
    ];
    argv.extend(plus.iter().map(String::as_str));
    run(dir, &argv, &format!("{} run of {name}", sim.name()))?;
    std::fs::read_to_string(dir.join(&resp))
        .map_err(|e| xsim_error(format!("{}: no response file: {e}", sim.name())))
}

/// The first difference between two response files.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Mismatch {
    /// 1-based line number.
    pub line: usize,
    pub expected: Option<String>,
    pub got: Option<String>,
}

impl std::fmt::Display for Mismatch {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let show = |s: &Option<String>| s.clone().unwrap_or_else(|| "<end of file>".into());
        write!(
            f,
            "responses differ at line {}: rust-hdl `{}`, Verilog `{}`",
            self.line,
            show(&self.expected),
            show(&self.got)
        )
    }
}

/// Byte-for-byte comparison of response files; the first differing line if any.
pub fn compare(expected: &str, got: &str) -> Result<(), Mismatch> {
    if expected == got {
        return Ok(());
    }
    let mut e = expected.lines();
    let mut g = got.lines();
    let mut line = 0;
    loop {
        line += 1;
        let (a, b) = (e.next(), g.next());
        if a != b || (a.is_none() && b.is_none()) {
            return Err(Mismatch {
                line,
                expected: a.map(String::from),
                got: b.map(String::from),
            });
        }
    }
}

/// Write everything needed to replay `run_` by hand into `dir`: `top.v` (the core's
/// Verilog), `top_icarus.v` (its [`glitch_free`] rewrite), `xsim_tb.v`, `stim.hex`,
/// `expected.txt` and two scripts that build,
/// replay and `cmp` the responses (`run_icarus.sh`, `run_verilator.sh`).
pub fn write_replay_dir(dir: &Path, verilog: &str, run_: &XsimRun) -> Result<PathBuf, Error> {
    let io = |e: std::io::Error| xsim_error(format!("{}: {e}", dir.display()));
    std::fs::create_dir_all(dir).map_err(io)?;
    std::fs::write(dir.join("top.v"), verilog).map_err(io)?;
    std::fs::write(dir.join("top_icarus.v"), glitch_free(verilog)?).map_err(io)?;
    std::fs::write(
        dir.join("xsim_tb.v"),
        testbench_verilog(run_.cycles(), run_.word_bits),
    )
    .map_err(io)?;
    std::fs::write(dir.join("stim.hex"), stimulus_text(run_)).map_err(io)?;
    std::fs::write(dir.join("expected.txt"), &run_.responses).map_err(io)?;
    for sim in [Simulator::Icarus, Simulator::Verilator] {
        let quote = |a: &str| {
            if a.contains(' ') {
                format!("\"{a}\"")
            } else {
                a.to_string()
            }
        };
        let build: Vec<String> = sim.build_command().iter().map(|a| quote(a)).collect();
        let runc: Vec<String> = sim.run_command().iter().map(|a| quote(a)).collect();
        let script = format!(
            "#!/bin/sh\n# Replays stim.hex into {top} with {name} and compares with expected.txt.\nset -e\ncd \"$(dirname \"$0\")\"\n{} xsim_tb.v {top}\n{} +stim=stim.hex +resp={name}.resp.txt +cycles={}\ncmp expected.txt {name}.resp.txt && echo \"{name}: responses equal\"\n",
            build.join(" "),
            runc.join(" "),
            run_.cycles(),
            name = sim.name(),
            top = match sim {
                Simulator::Icarus => "top_icarus.v",
                Simulator::Verilator => "top.v",
            },
        );
        let path = dir.join(format!("run_{}.sh", sim.name()));
        std::fs::write(&path, script).map_err(io)?;
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            let _ = std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o755));
        }
    }
    Ok(dir.to_path_buf())
}

/// Suffix of the shadow variables [`glitch_free`] introduces.
pub const SHADOW_SUFFIX: &str = "__xs";

fn is_ident_start(c: u8) -> bool {
    c.is_ascii_alphabetic() || c == b'_'
}

fn is_ident_char(c: u8) -> bool {
    c.is_ascii_alphanumeric() || c == b'_' || c == b'$'
}

/// Replace every identifier of `names` in `line` by its shadow (identifiers right
/// after a `'` are number bases/digits, e.g. `32'hff`, and are left alone).
fn shadow_line(line: &str, names: &std::collections::HashSet<String>) -> String {
    let b = line.as_bytes();
    let mut out = String::with_capacity(line.len() + 16);
    let mut i = 0;
    while i < b.len() {
        if is_ident_start(b[i]) && (i == 0 || !is_ident_char(b[i - 1])) {
            let start = i;
            while i < b.len() && is_ident_char(b[i]) {
                i += 1;
            }
            let tok = &line[start..i];
            out.push_str(tok);
            if (start == 0 || b[start - 1] != b'\'') && names.contains(tok) {
                out.push_str(SHADOW_SUFFIX);
            }
        } else {
            // Copy one whole UTF-8 character.
            let ch = line[i..].chars().next().expect("in bounds");
            out.push(ch);
            i += ch.len_utf8();
        }
    }
    out
}

/// A semantically identical rewrite of rust-hdl's Verilog for event-driven
/// simulators. rust-hdl writes each module's logic as one `always @(*)` block that
/// assigns defaults and then overrides them (`x = 0; if (c) x = y;`), so a variable
/// can glitch within one execution of the block. Icarus Verilog wakes every block
/// sensitive to a variable on each such glitch; two blocks feeding each other
/// glitches (a SearchPort and its QueryModules on the result path) then wake each
/// other forever at one simulation time: the raw export hangs Icarus at the first
/// result beat. The rewrite lets every `always @(*) begin … end` block compute into
/// shadow variables (`name__xs`, same declaration) and copy them to the real ones
/// at its end, so each variable changes at most once per execution. Nothing else
/// changes (same expressions, same order), so a precedence bug in the export stays
/// a precedence bug here.
pub fn glitch_free(verilog: &str) -> Result<String, Error> {
    use std::collections::{HashMap, HashSet};
    const START: &str = "    always @(*) begin";
    const END: &str = "    end";
    let lines: Vec<&str> = verilog.lines().collect();
    let mut out: Vec<String> = Vec::with_capacity(lines.len() + 1024);
    // Declarations of the current module: name -> "[w:0] " or "".
    let mut decls: HashMap<String, String> = HashMap::new();
    let mut i = 0;
    let mut blocks = 0;
    while i < lines.len() {
        let line = lines[i];
        let t = line.trim_start();
        if t.starts_with("module ") {
            decls.clear();
        }
        let decl = t
            .strip_prefix("output reg")
            .or_else(|| t.strip_prefix("reg"));
        if let Some(rest) = decl.filter(|r| r.starts_with(' ') && r.ends_with(';')) {
            let rest = rest.trim().trim_end_matches(';').trim();
            let (width, name) = match rest.rfind(']') {
                Some(p) => (format!("{} ", &rest[..=p]), rest[p + 1..].trim()),
                None => (String::new(), rest),
            };
            if !name.is_empty() && name.bytes().all(is_ident_char) {
                decls.insert(name.to_string(), width);
            }
        }
        if line != START {
            out.push(line.to_string());
            i += 1;
            continue;
        }
        let end = (i + 1..lines.len())
            .find(|&j| lines[j] == END)
            .ok_or_else(|| xsim_error(format!("line {}: always block without end", i + 1)))?;
        let body = &lines[i + 1..end];
        let mut assigned: Vec<String> = vec![];
        let mut seen = HashSet::new();
        for l in body {
            let t = l.trim_start();
            let n = t.bytes().take_while(|&c| is_ident_char(c)).count();
            if n == 0 || !is_ident_start(t.as_bytes()[0]) {
                continue;
            }
            let rest = t[n..].trim_start();
            if rest.starts_with('=') && !rest.starts_with("==") {
                let name = t[..n].to_string();
                if !decls.contains_key(&name) {
                    return Err(xsim_error(format!(
                        "line {}: no reg declaration of `{name}`",
                        i + 1
                    )));
                }
                if seen.insert(name.clone()) {
                    assigned.push(name);
                }
            }
        }
        for name in &assigned {
            out.push(format!("    reg {}{name}{SHADOW_SUFFIX};", decls[name]));
        }
        out.push(line.to_string());
        for l in body {
            out.push(shadow_line(l, &seen));
        }
        for name in &assigned {
            out.push(format!("        {name} = {name}{SHADOW_SUFFIX};"));
        }
        out.push(lines[end].to_string());
        blocks += 1;
        i = end + 1;
    }
    if blocks == 0 {
        return Err(xsim_error("no `always @(*)` block found to rewrite"));
    }
    let mut s = out.join("\n");
    s.push('\n');
    Ok(s)
}
