//! The exported core under Verilator as a [`Dut`] of the one driver: the
//! same load / query / result streams as rust-hdl's native simulation, some 100x
//! faster, on the Verilog that is cross-simulated cycle-exactly against it.
//!
//! Why a generated C++ harness loaded in-process (rather than a Rust–Verilator
//! binding crate, or a child process behind a pipe): it needs nothing but
//! `verilator` and a C++ compiler; the harness is generated from the top's ports
//! (no port named here) and built with the model into a shared library that
//! [`libloading`] opens, so a cycle costs two function calls instead of a pipe round
//! trip (which would bound the speed, not the model). Per cycle, [`Dut::drive`] hands the input ports'
//! values to `pf_sample` (applied with the clock low, evaluated, output ports'
//! values written back) and [`Dut::rising_edge`] calls `pf_edge`. Values travel as
//! little-endian 32-bit words per port, in port order.
//!
//! The built model is kept in the user's model cache ([`model_cache`]: keyed by the
//! Verilog, the harness, Verilator's version and arguments), so only the first run
//! of a configuration pays the build (seconds to a minute). A VCD trace (`--vcd`) comes from Verilator's own tracer in a second
//! build with `--trace`, with the native trace's timing (inputs settled at 10·c,
//! the rising edge at 10·c + 5); an untraced model carries no tracing code. Tree
//! status: the core's status outputs for T = 1, the array's per-tree status
//! vectors for T > 1.

use crate::hw::config::core_config::{Addr, CoreConfig, MAX_RESULT_STREAMS};
use crate::hw::config::photon_word::TreeImage;
use crate::hw::error::HwError;
use crate::hw::export::ports::Port;
use crate::hw::export::verilog::{export_verilog, Exported};
use crate::hw::primitives::stream::{QueryBeat, ResultBeat};
use crate::hw::sim::axi_memory::{AxiBurst, AxiMemory, AxiSlaveOut, AxiTiming, MemoryTraffic};
use crate::hw::sim::driver::{Dut, Inputs, Outputs};
use crate::hw::sim::model_cache;
use crate::hw::sim::verilator_harness::{harness_cpp, input_words, output_words, words};
use libloading::Library;
use rust_hdl::prelude::*;
use std::collections::HashMap;
use std::ffi::{c_char, c_void, CString};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::Mutex;

fn verr(msg: impl Into<String>) -> HwError {
    HwError::Simulation(format!("verilator: {}", msg.into()))
}

/// `verilator --build-jobs`: the C++ of a model compiles one file per core (a large
/// core's model is dozens of files, and make runs one at a time by default).
pub fn build_jobs() -> String {
    std::thread::available_parallelism()
        .map_or(1, |n| n.get())
        .to_string()
}

/// Verilator's arguments for a model (the sources are appended).
fn verilator_args(trace: bool) -> Vec<&'static str> {
    let mut args = vec![
        "--cc",
        "--exe",
        "--build",
        "-O3",
        "--x-assign",
        "fast",
        "--x-initial",
        "fast",
        "-Wno-fatal",
        "-Wno-WIDTH",
        "-Wno-UNOPTFLAT",
        "--top-module",
        "top",
        // A shared library instead of an executable: every object position
        // independent, linked with -shared.
        "-CFLAGS",
        "-fPIC",
        "-LDFLAGS",
        "-shared",
        "-MAKEFLAGS",
        "OPT_FAST=-O2 OPT_SLOW=-O1",
        "-o",
        "libvtop.so",
    ];
    if trace {
        args.push("--trace");
    }
    args
}

const NO_VERILATOR: &str = "install it (apt-get install verilator) and a C++ compiler (g++, make)";

/// `verilator --version`: part of the model's key (another Verilator builds
/// another model).
fn verilator_version() -> Result<String, HwError> {
    let out = Command::new("verilator")
        .arg("--version")
        .output()
        .map_err(|e| verr(format!("cannot run verilator ({e}): {NO_VERILATOR}")))?;
    Ok(String::from_utf8_lossy(&out.stdout).trim().to_string())
}

/// The built models this process has opened, by library path. Libraries are
/// never closed (a handful per process), so their functions stay valid.
static LIBRARIES: Mutex<Option<HashMap<PathBuf, &'static Library>>> = Mutex::new(None);

/// The library inside a cache entry.
const LIBRARY: &str = "obj_dir/libvtop.so";

/// Open the model of `exported` and `harness`, built into the user's model cache
/// ([`model_cache`]) unless it is there. One build at a time in this process: the
/// rtl backend starts one model per thread, and they share the cached build.
fn open(exported: &Exported, harness: &str, trace: bool) -> Result<&'static Library, HwError> {
    let mut libs = LIBRARIES.lock().unwrap_or_else(|e| e.into_inner());
    let args = verilator_args(trace);
    let version = verilator_version()?;
    let key = model_cache::key(&[
        exported.verilog.as_bytes(),
        harness.as_bytes(),
        version.as_bytes(),
        args.join("\0").as_bytes(),
    ]);
    let root = model_cache::cache_root();
    let lib = root.join(&key).join(LIBRARY);
    if let Some(l) = libs.get_or_insert_with(HashMap::new).get(&lib) {
        return Ok(l);
    }
    let build = |dir: &Path| build(dir, exported, harness, &args);
    let mut entry = model_cache::get_or_build(&root, &key, LIBRARY, build)?;
    // SAFETY: the library is the model built from our own harness; its
    // initialisers only set up Verilator's statics.
    let opened = match unsafe { Library::new(entry.join(LIBRARY)) } {
        Ok(l) => l,
        Err(_) => {
            // A library that matches its record but will not load (built by a
            // toolchain that has since changed underneath): built again, once.
            model_cache::evict(&root, &key)?;
            entry = model_cache::get_or_build(&root, &key, LIBRARY, build)?;
            unsafe { Library::new(entry.join(LIBRARY)) }
                .map_err(|e| verr(format!("cannot load {}: {e}", lib.display())))?
        }
    };
    let leaked: &'static Library = Box::leak(Box::new(opened));
    libs.get_or_insert_with(HashMap::new).insert(lib, leaked);
    Ok(leaked)
}

/// Build the model into the empty directory `dir`.
fn build(dir: &Path, exported: &Exported, harness: &str, args: &[&str]) -> Result<(), HwError> {
    let io = |e: std::io::Error| verr(format!("{}: {e}", dir.display()));
    std::fs::write(dir.join("top.v"), &exported.verilog).map_err(io)?;
    std::fs::write(dir.join("harness.cpp"), harness).map_err(io)?;
    // Not part of the model's key: they change how fast, not what, is built.
    let mut verilator = Command::new("verilator");
    verilator
        .current_dir(dir)
        .args(args)
        .args(["--build-jobs", &build_jobs()]);
    share_runtime(&mut verilator);
    let out = verilator
        .args(["top.v", "harness.cpp"])
        .output()
        .map_err(|e| verr(format!("cannot run verilator ({e}): {NO_VERILATOR}")))?;
    if !out.status.success() || !dir.join(LIBRARY).exists() {
        return Err(verr(format!(
            "the Verilator build failed:\n{}{}",
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        )));
    }
    Ok(())
}

/// Let a `verilator --build` command take Verilator's runtime from ccache
/// (`OBJCACHE`) when ccache is on the PATH: every model compiles that runtime
/// (verilated.cpp) with the same flags, so it is compiled once.
pub fn share_runtime(verilator: &mut Command) {
    let has_ccache = Command::new("ccache")
        .arg("--version")
        .output()
        .is_ok_and(|o| o.status.success());
    if has_ccache {
        verilator.env("OBJCACHE", "ccache");
    }
}

type NewFn = unsafe extern "C" fn() -> *mut c_void;
type TraceFn = unsafe extern "C" fn(*mut c_void, *const c_char) -> i32;
type SampleFn = unsafe extern "C" fn(*mut c_void, *const u32, *mut u32);
type EdgeFn = unsafe extern "C" fn(*mut c_void);

/// The exported core running under Verilator.
pub struct VerilatorDut {
    cfg: CoreConfig,
    ports: Vec<Port>,
    model: *mut c_void,
    sample: SampleFn,
    edge: EdgeFn,
    free: EdgeFn,
    outputs: Outputs,
    /// Per tree: port A reads, port B reads, all busy.
    status: Vec<[bool; 3]>,
    /// One cycle's input and output records.
    in_words: Vec<u32>,
    out_words: Vec<u32>,
    /// With external memory: its model, what it drives this cycle, and the
    /// core's address channel and `rready` as sampled.
    memory: Option<AxiMemory>,
    timing: AxiTiming,
    axi_in: AxiSlaveOut,
    axi_ar: AxiBurst,
    axi_arvalid: bool,
    axi_rready: bool,
}

// SAFETY: the model has its own VerilatedContext and is only ever used through
// `&mut self`, by one thread at a time.
unsafe impl Send for VerilatorDut {}

/// Write `value`'s low `width` bits at bit `at` of `bits` (little-endian words,
/// zeroed by the caller).
fn put(bits: &mut [u32], at: &mut usize, value: u64, width: usize) {
    let mut v = if width < 64 {
        value & ((1u64 << width) - 1)
    } else {
        value
    };
    let (mut pos, mut rest) = (*at, width);
    while rest > 0 {
        let (i, off) = (pos / 32, pos % 32);
        let n = (32 - off).min(rest);
        bits[i] |= ((v & ((1u64 << n) - 1)) as u32) << off;
        v >>= n;
        pos += n;
        rest -= n;
    }
    *at += width;
}

/// `width` (≤ 64) bits at bit `at` of `bits`.
/// A result beat from its packed bits: each field at the offset and width the
/// `LogicStruct` derive gives it (the struct definition's order).
fn result_beat(w: &[u32]) -> ResultBeat {
    let d = ResultBeat::default();
    let f = |mut at: usize, width: usize| take(w, &mut at, width);
    ResultBeat {
        header: f(d.get_my_offset_header(), d.get_my_width_header()) == 1,
        last: f(d.get_my_offset_last(), d.get_my_width_last()) == 1,
        id: f(d.get_my_offset_id(), d.get_my_width_id()).into(),
        count: f(d.get_my_offset_count(), d.get_my_width_count()).into(),
        visited: f(d.get_my_offset_visited(), d.get_my_width_visited()).into(),
        address: f(d.get_my_offset_address(), d.get_my_width_address()).into(),
        distance: f(d.get_my_offset_distance(), d.get_my_width_distance()).into(),
        pair: f(d.get_my_offset_pair(), d.get_my_width_pair()) == 1,
        address2: f(d.get_my_offset_address2(), d.get_my_width_address2()).into(),
        distance2: f(d.get_my_offset_distance2(), d.get_my_width_distance2()).into(),
    }
}

/// Result stream of a `more_results$s$member` port: s + 1.
fn more_stream(name: &str) -> Result<usize, HwError> {
    name.split('$')
        .nth(1)
        .and_then(|s| s.parse::<usize>().ok())
        .filter(|&s| s + 1 < MAX_RESULT_STREAMS)
        .map(|s| s + 1)
        .ok_or_else(|| verr(format!("port `{name}`: no result stream index")))
}

fn take(bits: &[u32], at: &mut usize, width: usize) -> u64 {
    let (mut v, mut got, mut pos) = (0u64, 0, *at);
    while got < width {
        let (i, off) = (pos / 32, pos % 32);
        let n = (32 - off).min(width - got);
        v |= (((bits[i] >> off) as u64) & ((1u64 << n) - 1)) << got;
        got += n;
        pos += n;
    }
    *at += width;
    v
}

fn symbol<T: Copy>(lib: &'static Library, name: &[u8]) -> Result<T, HwError> {
    // SAFETY: the names and signatures are those of `harness_cpp`.
    unsafe { lib.get::<T>(name) }
        .map(|s| *s)
        .map_err(|e| verr(format!("harness symbol missing: {e}")))
}

impl VerilatorDut {
    /// Export the core for `cfg`, build it (or reuse the cached build) and start it;
    /// with `vcd`, trace every signal into that file.
    pub fn new(cfg: &CoreConfig, vcd: Option<&Path>, timing: AxiTiming) -> Result<Self, HwError> {
        let exported = export_verilog(cfg)?;
        let harness = harness_cpp(&exported.ports);
        let trace = vcd.is_some();
        let lib = open(&exported, &harness, trace)?;
        let new: NewFn = symbol(lib, b"pf_new")?;
        let sample: SampleFn = symbol(lib, b"pf_sample")?;
        let edge: EdgeFn = symbol(lib, b"pf_edge")?;
        let free: EdgeFn = symbol(lib, b"pf_free")?;
        // SAFETY: pf_new returns a fresh model owned by this value (freed in Drop).
        let model = unsafe { new() };
        let dut = VerilatorDut {
            cfg: *cfg,
            in_words: vec![0; input_words(&exported.ports)],
            out_words: vec![0; output_words(&exported.ports)],
            ports: exported.ports,
            model,
            sample,
            edge,
            free,
            outputs: Outputs::default(),
            status: vec![[false; 3]; cfg.trees],
            memory: None,
            timing,
            axi_in: AxiSlaveOut::default(),
            axi_ar: AxiBurst {
                addr: 0,
                len: 0,
                size: 0,
                burst: 0,
            },
            axi_arvalid: false,
            axi_rready: false,
        };
        if let Some(path) = vcd {
            let start: TraceFn = symbol(lib, b"pf_trace")?;
            let c_path = CString::new(path.as_os_str().as_encoded_bytes())
                .map_err(|_| verr(format!("VCD path {} has a NUL byte", path.display())))?;
            // SAFETY: a live model and a NUL-terminated path.
            if unsafe { start(dut.model, c_path.as_ptr()) } != 1 {
                return Err(verr(format!("cannot create VCD file {}", path.display())));
            }
        }
        Ok(dut)
    }

    /// One port's value for `v`, as bits of the port's width at `at`.
    fn input_bits(
        name: &str,
        v: &Inputs,
        axi: &AxiSlaveOut,
        out: &mut [u32],
        at: &mut usize,
    ) -> Result<(), HwError> {
        let q = &v.query;
        match name {
            "m_axi$0$arready" => put(out, at, axi.arready as u64, 1),
            "m_axi$0$rvalid" => put(out, at, axi.rvalid as u64, 1),
            "m_axi$0$rdata" => put(out, at, axi.rdata, 64),
            "m_axi$0$rlast" => put(out, at, axi.rlast as u64, 1),
            "m_axi$0$rresp" => put(out, at, u64::from(axi.rresp), 2),
            "reset" => put(out, at, v.reset as u64, 1),
            "load$valid" => put(out, at, v.load_valid as u64, 1),
            "load$address" => put(out, at, v.load.address, Addr::BITS),
            "load$word" => put(out, at, v.load.word, 64),
            "load$last" => put(out, at, v.load.last as u64, 1),
            "query$valid" => put(out, at, v.query_valid as u64, 1),
            "query$data" => {
                // Packed as rust-hdl packs the `LogicStruct` (its `From` for `Bits`).
                let packed: Bits<{ QueryBeat::BITS }> = (*q).into();
                let mut k = 0;
                while k < QueryBeat::BITS {
                    let n = (QueryBeat::BITS - k).min(32);
                    put(out, at, packed.get_bits::<32>(k).to_u64(), n);
                    k += n;
                }
            }
            "result$ready" => put(out, at, v.result_ready[0] as u64, 1),
            name if name.starts_with("more_results$") && name.ends_with("$ready") => {
                let s = more_stream(name)?;
                put(out, at, v.result_ready[s] as u64, 1)
            }
            other => return Err(verr(format!("unknown input port `{other}`"))),
        }
        Ok(())
    }
}

impl Drop for VerilatorDut {
    fn drop(&mut self) {
        // SAFETY: the model is live and dropped once (this also closes its VCD).
        unsafe { (self.free)(self.model) }
    }
}

impl Dut for VerilatorDut {
    fn config(&self) -> &CoreConfig {
        &self.cfg
    }

    fn drive(&mut self, v: &Inputs) -> Result<(), HwError> {
        // The hot path of this backend: no allocation per cycle.
        self.in_words.fill(0);
        if let Some(memory) = &mut self.memory {
            self.axi_in = memory.drive();
        }
        let mut base = 0;
        for p in self.ports.iter().filter(|p| p.input && p.name != "clock") {
            let mut at = 32 * base;
            Self::input_bits(&p.name, v, &self.axi_in, &mut self.in_words, &mut at)?;
            base += words(p.width);
        }
        // SAFETY: the buffers have the harness' input and output record sizes.
        unsafe {
            (self.sample)(
                self.model,
                self.in_words.as_ptr(),
                self.out_words.as_mut_ptr(),
            )
        };
        let out = &self.out_words;
        let mut k = 0;
        let mut o = Outputs::default();
        for p in self.ports.iter().filter(|p| !p.input) {
            let w = &out[k..k + words(p.width)];
            k += words(p.width);
            let bit = |t: usize| (w[0] >> t) & 1 == 1;
            let low = u64::from(w[0]) | w.get(1).map_or(0, |&h| u64::from(h) << 32);
            match p.name.as_str() {
                "m_axi$0$arvalid" => self.axi_arvalid = bit(0),
                "m_axi$0$araddr" => self.axi_ar.addr = low,
                "m_axi$0$arlen" => self.axi_ar.len = low as u8,
                "m_axi$0$arsize" => self.axi_ar.size = low as u8,
                "m_axi$0$arburst" => self.axi_ar.burst = low as u8,
                "m_axi$0$rready" => self.axi_rready = bit(0),
                "load$ready" => o.load_ready = bit(0),
                "query$ready" => o.query_ready = bit(0),
                "result$valid" => o.result_valid[0] = bit(0),
                "result$data" => o.result[0] = result_beat(w),
                name if name.starts_with("more_results$") && name.ends_with("$valid") => {
                    o.result_valid[more_stream(name)?] = bit(0)
                }
                name if name.starts_with("more_results$") && name.ends_with("$data") => {
                    o.result[more_stream(name)?] = result_beat(w)
                }
                // T = 1: the core's own status; T > 1: per tree from the vectors
                // (the array's any/every outputs are implied by them).
                // A banked core: each port's reads from `ports_reading`.
                "port_a_reading" if self.cfg.trees == 1 => self.status[0][0] = bit(0),
                "port_b_reading" if self.cfg.trees == 1 => self.status[0][1] = bit(0),
                "all_busy" if !self.cfg.is_array() => {
                    for s in self.status.iter_mut() {
                        s[2] = bit(0);
                    }
                }
                name if name.starts_with("ports_reading$") => {
                    let i: usize = name["ports_reading$".len()..]
                        .parse()
                        .map_err(|_| verr(format!("output port `{name}`: no port index")))?;
                    self.status[i / 2][i % 2] = bit(0);
                }
                "port_a_reading" | "port_b_reading" | "all_busy" => {}
                "trees_reading_a" | "trees_reading_b" | "trees_busy" => {
                    let j = match p.name.as_str() {
                        "trees_reading_a" => 0,
                        "trees_reading_b" => 1,
                        _ => 2,
                    };
                    for (t, s) in self.status.iter_mut().enumerate() {
                        s[j] = bit(t);
                    }
                }
                other => return Err(verr(format!("unknown output port `{other}`"))),
            }
        }
        self.outputs = o;
        Ok(())
    }

    fn outputs(&mut self) -> Outputs {
        self.outputs
    }

    fn tree_status(&self, t: usize) -> [bool; 3] {
        self.status[t]
    }

    fn rising_edge(&mut self) -> Result<(), HwError> {
        if let Some(memory) = &mut self.memory {
            memory.edge(self.axi_arvalid.then_some(self.axi_ar), self.axi_rready);
        }
        // SAFETY: a live model.
        unsafe { (self.edge)(self.model) };
        Ok(())
    }

    fn load_memory(&mut self, tree: TreeImage<'_>) -> Result<(), HwError> {
        self.memory = Some(AxiMemory::for_map(&self.cfg, tree, self.timing)?);
        Ok(())
    }

    fn memory_traffic(&self) -> MemoryTraffic {
        self.memory
            .as_ref()
            .map(AxiMemory::traffic)
            .unwrap_or_default()
    }
}
