//! rust-hdl's native simulation of the core as a [`Dut`]: the clock is toggled and
//! the circuit settled with `simulate()` directly (no testbench threads, ~100x
//! faster than rust-hdl's threaded testbenches), optionally streaming a VCD trace.
//!
//! [`CoreSim`] is the native core behind the one [`Driver`]; [`run_gather`] is the
//! `rtl` gather backend's engine: it loads a map, runs the queries and returns one
//! [`HwResult`] per query, in input order.

use crate::hw::config::core_config::{dispatch_widths, CoreConfig};
use crate::hw::config::photon_word::TreeImage;
use crate::hw::error::HwError;
use crate::hw::sim::axi_memory::{AxiBurst, AxiMemory, AxiTiming, MemoryTraffic};
use crate::hw::sim::driver::{
    Cycle, Driver, Dut, HwQuery, HwResult, Inputs, Job, Observer, Outputs, RunLimits, SimStats,
};
use crate::hw::sim::top::SearchTop;
use crate::hw::top::array::PhotonSearchArray;
use crate::hw::top::core::PhotonSearchCore;
use rust_hdl::core::vcd_probe::VCDProbe;
use rust_hdl::prelude::*;
use std::fs::File;
use std::io::BufWriter;
use std::path::PathBuf;

#[derive(Clone, Debug, Default)]
pub struct SimOptions {
    /// Stream a VCD trace here (also when env `PHOTON_FPGA_VCD=path` is set).
    pub vcd: Option<PathBuf>,
    /// Random valid/ready stalls on every stream, from this seed.
    pub stall_seed: Option<u64>,
    /// Which simulator runs the core.
    pub engine: Engine,
    /// How the external memory answers a core whose map is there (default:
    /// [`AxiTiming::ecp5_ddr3`]).
    pub memory: Option<AxiTiming>,
}

/// The simulator behind the driver (`--engine`); each variant's doc is its help
/// text.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
pub enum Engine {
    /// rust-hdl's own simulation of the blocks (VCD traces).
    #[default]
    Native,
    /// The exported Verilog under Verilator (built on first use, cached in
    /// $PHOTON_FPGA_CACHE_DIR, else $XDG_CACHE_HOME/photon-fpga or
    /// ~/.cache/photon-fpga).
    Verilator,
}

/// Env var naming a VCD file to trace into when `SimOptions::vcd` is unset.
pub const VCD_ENV: &str = "PHOTON_FPGA_VCD";

fn sim_error(msg: impl Into<String>) -> HwError {
    HwError::Simulation(msg.into())
}

/// The natively simulated top `U` (a core or an array, `W`-bit photon words).
pub struct NativeDut<const W: usize, U: SearchTop<W>> {
    cfg: CoreConfig,
    uut: Box<U>,
    passes: u64,
    /// The external memory's model (with `CoreConfig::memory`, once a map is in it).
    memory: Option<AxiMemory>,
    timing: AxiTiming,
}

impl<const W: usize, U: SearchTop<W>> NativeDut<W, U> {
    /// Elaborate and check the top for `cfg`.
    pub fn new(cfg: &CoreConfig, timing: AxiTiming) -> Result<Self, HwError> {
        cfg.validate()?;
        let mut uut = Box::new(U::elaborate(cfg));
        uut.connect_all();
        check_all(uut.as_ref()).map_err(|e| sim_error(format!("circuit check failed: {e:?}")))?;
        let mut dut = NativeDut {
            cfg: *cfg,
            uut,
            passes: 0,
            memory: None,
            timing,
        };
        dut.uut.io().clock.next = false.into();
        dut.settle()?;
        Ok(dut)
    }

    /// rust-hdl's `simulate`, counting passes: every block's `update` runs once
    /// per pass, and a value crosses one parent/child boundary per pass, so a
    /// settle takes as many passes as the deepest combinational path has block
    /// crossings (about 8 in the core).
    fn settle(&mut self) -> Result<(), HwError> {
        for _ in 0..200 {
            self.passes += 1;
            self.uut.update_all();
            if !self.uut.has_changed() {
                return Ok(());
            }
        }
        Err(sim_error(
            "the circuit did not settle (combinational loop?)",
        ))
    }
}

impl<const W: usize, U: SearchTop<W>> Dut for NativeDut<W, U> {
    fn config(&self) -> &CoreConfig {
        &self.cfg
    }

    fn drive(&mut self, v: &Inputs) -> Result<(), HwError> {
        let io = self.uut.io();
        io.clock.next = false.into();
        io.reset.next = v.reset;
        io.load.valid.next = v.load_valid;
        io.load.address.next = v.load.address.into();
        io.load.word.next = v.load.word.into();
        io.load.last.next = v.load.last;
        io.query.valid.next = v.query_valid;
        io.query.data.next = v.query;
        io.result.ready.next = v.result_ready[0];
        for (s, r) in io.more_results.iter_mut().enumerate() {
            r.ready.next = v.result_ready[s + 1];
        }
        if let (Some(memory), Some(port)) = (&mut self.memory, self.uut.memory_port()) {
            let out = memory.drive();
            port.arready.next = out.arready;
            port.rvalid.next = out.rvalid;
            port.rdata.next = out.rdata.into();
            port.rlast.next = out.rlast;
            port.rresp.next = u64::from(out.rresp).into();
        }
        self.settle()
    }

    fn outputs(&mut self) -> Outputs {
        let io = self.uut.io();
        let mut o = Outputs {
            load_ready: io.load.ready.val(),
            query_ready: io.query.ready.val(),
            ..Outputs::default()
        };
        o.result_valid[0] = io.result.valid.val();
        o.result[0] = io.result.data.val();
        for (s, r) in io.more_results.iter().enumerate() {
            o.result_valid[s + 1] = r.valid.val();
            o.result[s + 1] = r.data.val();
        }
        o
    }

    fn tree_status(&self, t: usize) -> [bool; 3] {
        self.uut.tree_status(t)
    }

    fn rising_edge(&mut self) -> Result<(), HwError> {
        if let (Some(memory), Some(port)) = (&mut self.memory, self.uut.memory_port()) {
            let ar = port.arvalid.val().then(|| AxiBurst {
                addr: port.araddr.val().to_u64(),
                len: port.arlen.val().to_u64() as u8,
                size: port.arsize.val().to_u64() as u8,
                burst: port.arburst.val().to_u64() as u8,
            });
            memory.edge(ar, port.rready.val());
        }
        self.uut.io().clock.next = true.into();
        self.settle()
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

    fn settle_passes(&self) -> Option<u64> {
        Some(self.passes)
    }

    fn block(&self) -> Option<&dyn Block> {
        Some(self.uut.as_ref())
    }
}

/// Streams a VCD trace of every signal: the cycle's inputs settled at 10·c, its
/// rising edge at 10·c + 5 (in the VCD's time unit).
pub struct VcdObserver {
    file: Option<BufWriter<File>>,
    vcd: Option<VCDProbe<BufWriter<File>>>,
}

impl VcdObserver {
    /// Trace into a new file at `path`.
    pub fn create(path: &std::path::Path) -> Result<Self, HwError> {
        let file = File::create(path)
            .map_err(|e| sim_error(format!("cannot create VCD file {}: {e}", path.display())))?;
        Ok(VcdObserver {
            file: Some(BufWriter::new(file)),
            vcd: None,
        })
    }

    fn write(&mut self, c: &Cycle<'_>, time: u64) {
        let Some(block) = c.dut.block() else { return };
        let vcd = match (self.vcd.take(), self.file.take()) {
            (Some(mut vcd), _) => {
                let _ = vcd.timestamp(time);
                write_vcd_change(vcd, block)
            }
            (None, Some(file)) => write_vcd_dump(write_vcd_header(file, block), block),
            (None, None) => return,
        };
        self.vcd = Some(vcd);
    }
}

impl Observer for VcdObserver {
    fn sampled(&mut self, c: &Cycle<'_>) -> Result<(), HwError> {
        self.write(c, 10 * c.index);
        Ok(())
    }
    fn edge(&mut self, c: &Cycle<'_>) -> Result<(), HwError> {
        self.write(c, 10 * c.index + 5);
        Ok(())
    }
}

/// The native core (T = 1) or array (T > 1) for `cfg` as a boxed [`Dut`], with the
/// slot-mask and word widths `S`, `W` that `cfg` needs.
fn native_dut<const S: usize, const W: usize>(
    cfg: &CoreConfig,
    timing: AxiTiming,
) -> Result<Box<dyn Dut>, HwError> {
    Ok(if !cfg.is_array() {
        Box::new(NativeDut::<W, PhotonSearchCore<S, W>>::new(cfg, timing)?)
    } else {
        Box::new(NativeDut::<W, PhotonSearchArray<S, W>>::new(cfg, timing)?)
    })
}

/// rust-hdl's simulation of the core for any configuration: the slot-mask width is
/// chosen from K ([`CoreConfig::slot_bits`]), the word width from the layout
/// ([`CoreConfig::word_width`]), so the paper's core keeps rust-hdl's fast 32-bit
/// `Bits`; T > 1 simulates a [`PhotonSearchArray`].
pub fn elaborate(cfg: &CoreConfig) -> Result<Box<dyn Dut>, HwError> {
    elaborate_with(cfg, AxiTiming::ecp5_ddr3())
}

/// [`elaborate`], its external memory (if any) answering with `timing`.
pub fn elaborate_with(cfg: &CoreConfig, timing: AxiTiming) -> Result<Box<dyn Dut>, HwError> {
    cfg.validate()?;
    dispatch_widths!(cfg, native_dut(cfg, timing))
}

impl Dut for Box<dyn Dut> {
    fn config(&self) -> &CoreConfig {
        self.as_ref().config()
    }
    fn drive(&mut self, inputs: &Inputs) -> Result<(), HwError> {
        self.as_mut().drive(inputs)
    }
    fn outputs(&mut self) -> Outputs {
        self.as_mut().outputs()
    }
    fn tree_status(&self, t: usize) -> [bool; 3] {
        self.as_ref().tree_status(t)
    }
    fn rising_edge(&mut self) -> Result<(), HwError> {
        self.as_mut().rising_edge()
    }
    fn settle_passes(&self) -> Option<u64> {
        self.as_ref().settle_passes()
    }
    fn block(&self) -> Option<&dyn Block> {
        self.as_ref().block()
    }
    fn load_memory(&mut self, tree: TreeImage<'_>) -> Result<(), HwError> {
        self.as_mut().load_memory(tree)
    }
    fn memory_traffic(&self) -> MemoryTraffic {
        self.as_ref().memory_traffic()
    }
}

/// The natively simulated core driven by the one [`Driver`], with the stalls and
/// VCD trace of `opts`.
pub struct CoreSim(Driver<Box<dyn Dut>>);

impl CoreSim {
    /// Elaborate and check a core for `cfg`, then reset it.
    pub fn new(cfg: &CoreConfig, opts: &SimOptions) -> Result<Self, HwError> {
        let vcd_path = opts
            .vcd
            .clone()
            .or_else(|| std::env::var_os(VCD_ENV).map(PathBuf::from));
        let mut observers: Vec<Box<dyn Observer>> = vec![];
        let dut: Box<dyn Dut> = match opts.engine {
            Engine::Native => {
                if let Some(path) = &vcd_path {
                    observers.push(Box::new(VcdObserver::create(path)?));
                }
                elaborate_with(cfg, opts.memory.unwrap_or_else(AxiTiming::ecp5_ddr3))?
            }
            Engine::Verilator => {
                cfg.validate()?;
                Box::new(crate::hw::sim::verilator::VerilatorDut::new(
                    cfg,
                    vcd_path.as_deref(),
                    opts.memory.unwrap_or_else(AxiTiming::ecp5_ddr3),
                )?)
            }
        };
        Ok(CoreSim(Driver::new(dut, opts.stall_seed, observers)?))
    }

    pub fn config(&self) -> &CoreConfig {
        self.0.config()
    }

    /// Counters since the core was built.
    pub fn stats(&self) -> &SimStats {
        self.0.stats()
    }

    /// The native simulation's settle passes since the core was built.
    pub fn settle_passes(&self) -> Option<u64> {
        self.0.dut().settle_passes()
    }

    /// Synchronous reset.
    pub fn reset(&mut self) -> Result<(), HwError> {
        self.0.reset()
    }

    /// Stream `tree`'s words into the TreeModule (addresses 1..=N, `last` on N).
    pub fn load_map(&mut self, tree: TreeImage<'_>) -> Result<(), HwError> {
        let job = Job {
            load: Some(tree),
            queries: &[],
        };
        self.0.run(&[job], RunLimits::default())?;
        Ok(())
    }

    /// Run `queries` on the loaded map; results in input order.
    pub fn run_queries(&mut self, queries: &[HwQuery]) -> Result<Vec<HwResult>, HwError> {
        let job = Job {
            load: None,
            queries,
        };
        let mut results = self.0.run(&[job], RunLimits::default())?;
        Ok(results
            .pop()
            .unwrap_or_default()
            .into_iter()
            .map(|r| r.expect("all received"))
            .collect())
    }

    /// Feed `queries` for at most `cycles` cycles and return what completed by then
    /// (`None` for the rest), leaving the others in flight: e.g. to test a reset
    /// in the middle of a search.
    pub fn run_queries_for(
        &mut self,
        queries: &[HwQuery],
        cycles: u64,
    ) -> Result<Vec<Option<HwResult>>, HwError> {
        let job = Job {
            load: None,
            queries,
        };
        let limits = RunLimits {
            max_cycles: Some(cycles),
            tail_cycles: 0,
        };
        Ok(self.0.run(&[job], limits)?.pop().unwrap_or_default())
    }
}

/// Load `tree` into a fresh core for `cfg`, run `queries`, return the results in
/// input order and the cycle counts.
pub fn run_gather(
    cfg: &CoreConfig,
    tree: TreeImage<'_>,
    queries: &[HwQuery],
    opts: &SimOptions,
) -> Result<(Vec<HwResult>, SimStats), HwError> {
    cfg.check_map(tree)?;
    let mut sim = CoreSim::new(cfg, opts)?;
    sim.load_map(tree)?;
    let results = sim.run_queries(queries)?;
    Ok((results, sim.stats().clone()))
}
