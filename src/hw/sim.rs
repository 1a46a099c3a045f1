//! Fast native driver of the simulated core: it toggles the clock and settles the
//! circuit with `simulate()` directly (no testbench threads), plays the host's side
//! of the load / query / result streams, optionally with random valid/ready stalls
//! on every stream, and optionally streams a VCD trace to a file.
//!
//! This is the `rtl` gather backend's engine: `run_gather` loads a packed tree,
//! runs the queries and returns one `HwResult` per query, in input order.

use crate::host::error::Error;
use crate::host::kdtree::PackedTree;
use crate::hw::array::PhotonSearchArray;
use crate::hw::config::{dispatch_widths, CoreConfig};
use crate::hw::core::PhotonSearchCore;
use crate::hw::top::SearchTop;
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;
use rust_hdl::core::vcd_probe::VCDProbe;
use rust_hdl::prelude::*;
use std::fs::File;
use std::io::BufWriter;
use std::path::PathBuf;

/// One query for the core: grid coordinates, inclusive integer radius bound in the
/// metric, and k (1..=K).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct HwQuery {
    pub id: u32,
    pub coords: [u32; 3],
    pub radius: u64,
    pub k: u32,
}

/// One query's answer: (heap address, distance) in found-list slot order.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct HwResult {
    pub id: u32,
    pub found: Vec<(u32 /*heap addr*/, u64 /*distance*/)>,
    /// Photon reads this query issued.
    pub visited: u32,
}

/// What the run cost, in clock cycles. Ports are listed tree by tree (A, B of tree
/// 0, then of tree 1, ...).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct SimStats {
    pub cycles: u64,
    pub reads_per_port: Vec<u64>,
    /// Cycles with every QueryModule (of every tree) occupied.
    pub busy_cycles: u64,
    pub busy_reads_per_port: Vec<u64>,
}

#[derive(Clone, Debug, Default)]
pub struct SimOptions {
    /// Stream a VCD trace here (also when env `PHOTON_FPGA_VCD=path` is set).
    pub vcd: Option<PathBuf>,
    /// Random valid/ready stalls on every stream, from this seed.
    pub stall_seed: Option<u64>,
}

/// Env var naming a VCD file to trace into when `SimOptions::vcd` is unset.
pub const VCD_ENV: &str = "PHOTON_FPGA_VCD";

/// The simulated top `U` (a core or an array, photon words `W` bits) and the host
/// side of its streams.
struct CoreSimOf<const W: usize, U: SearchTop<W>> {
    cfg: CoreConfig,
    uut: Box<U>,
    stalls: Option<Pcg64>,
    vcd: Option<VCDProbe<BufWriter<File>>>,
    time: u64,
    clock_high: bool,
    stats: SimStats,
}

fn sim_error(msg: impl Into<String>) -> Error {
    Error::new(format!("hardware simulation: {}", msg.into()))
}

impl<const W: usize, U: SearchTop<W>> CoreSimOf<W, U> {
    /// Elaborate and check a core for `cfg`.
    fn new(cfg: &CoreConfig, opts: &SimOptions) -> Result<Self, Error> {
        cfg.validate()?;
        let mut uut = Box::new(U::elaborate(cfg));
        uut.connect_all();
        check_all(uut.as_ref()).map_err(|e| sim_error(format!("circuit check failed: {e:?}")))?;
        let vcd_path = opts
            .vcd
            .clone()
            .or_else(|| std::env::var_os(VCD_ENV).map(PathBuf::from));
        let vcd = match vcd_path {
            Some(path) => {
                let file = File::create(&path).map_err(|e| {
                    sim_error(format!("cannot create VCD file {}: {e}", path.display()))
                })?;
                Some(write_vcd_header(BufWriter::new(file), uut.as_ref()))
            }
            None => None,
        };
        let mut sim = CoreSimOf {
            cfg: *cfg,
            uut,
            stalls: opts.stall_seed.map(Pcg64::seed_from_u64),
            vcd,
            time: 0,
            clock_high: false,
            stats: SimStats {
                reads_per_port: vec![0; 2 * cfg.trees],
                busy_reads_per_port: vec![0; 2 * cfg.trees],
                ..Default::default()
            },
        };
        sim.settle()?;
        if let Some(vcd) = sim.vcd.take() {
            sim.vcd = Some(write_vcd_dump(vcd, sim.uut.as_ref()));
        }
        sim.reset()?;
        Ok(sim)
    }

    fn settle(&mut self) -> Result<(), Error> {
        if simulate(self.uut.as_mut(), 200) {
            Ok(())
        } else {
            Err(sim_error(
                "the circuit did not settle (combinational loop?)",
            ))
        }
    }

    fn trace(&mut self) {
        if let Some(mut vcd) = self.vcd.take() {
            let _ = vcd.timestamp(self.time);
            self.vcd = Some(write_vcd_change(vcd, self.uut.as_ref()));
        }
    }

    /// Falling edge (if the clock is high) merged with the settling of the inputs
    /// the caller just set: one `simulate` per half cycle.
    fn settle_low(&mut self) -> Result<(), Error> {
        self.uut.ports().clock.next = false.into();
        self.settle()?;
        if self.clock_high {
            self.clock_high = false;
            self.time += 5;
            self.trace();
        }
        Ok(())
    }

    /// One clock cycle: count this cycle's reads, then the rising edge. The clock
    /// stays high until the next `settle_low`.
    fn tick(&mut self) -> Result<(), Error> {
        if self.clock_high {
            self.settle_low()?;
        }
        let all_busy = self.uut.ports().all_busy.val();
        self.stats.busy_cycles += all_busy as u64;
        for t in 0..self.cfg.trees {
            let [a, b, _] = self.uut.tree_status(t);
            for (port, reading) in [(2 * t, a), (2 * t + 1, b)] {
                self.stats.reads_per_port[port] += reading as u64;
                if all_busy {
                    self.stats.busy_reads_per_port[port] += reading as u64;
                }
            }
        }
        self.stats.cycles += 1;
        self.uut.ports().clock.next = true.into();
        self.settle()?;
        self.clock_high = true;
        self.time += 5;
        self.trace();
        Ok(())
    }

    /// A random stall decision (never stalls without a seed).
    fn stall(&mut self) -> bool {
        match &mut self.stalls {
            Some(rng) => rng.gen_bool(0.35),
            None => false,
        }
    }

    /// Synchronous reset for two cycles.
    fn reset(&mut self) -> Result<(), Error> {
        self.uut.ports().reset.next = true;
        self.settle_low()?;
        self.tick()?;
        self.tick()?;
        self.uut.ports().reset.next = false;
        self.settle_low()
    }

    /// Stream `tree`'s words into the TreeModule (addresses 1..=N, `last` on N).
    fn load_map(&mut self, tree: &PackedTree) -> Result<(), Error> {
        self.cfg.check_map(tree)?;
        let n = tree.len();
        let mut next = 1usize;
        let mut presenting = false;
        let mut idle_cycles = 0u64;
        while next <= n {
            if !presenting && !self.stall() {
                presenting = true;
            }
            let uut = self.uut.ports();
            uut.load_valid.next = presenting;
            uut.load_address.next = (next as u64).into();
            uut.load_word.next = tree.words[next].into();
            uut.load_last.next = next == n;
            self.settle_low()?;
            let fire = presenting && self.uut.ports().load_ready.val();
            self.tick()?;
            if fire {
                next += 1;
                presenting = false;
                idle_cycles = 0;
            } else {
                idle_cycles += 1;
                if idle_cycles > 1_000_000 {
                    return Err(sim_error("the core never accepted the photon load"));
                }
            }
        }
        self.uut.ports().load_valid.next = false;
        self.settle_low()
    }

    fn drive_queries(
        &mut self,
        queries: &[HwQuery],
        max_cycles: Option<u64>,
    ) -> Result<Vec<Option<HwResult>>, Error> {
        let cfg = self.cfg;
        let start_cycle = self.stats.cycles;
        for q in queries {
            if q.k == 0 || q.k as usize > cfg.k {
                return Err(sim_error(format!(
                    "query {}: k = {} outside 1..={} (the core's K)",
                    q.id, q.k, cfg.k
                )));
            }
            for a in 0..3 {
                if q.coords[a] > cfg.layout.coord_max(a) {
                    return Err(sim_error(format!(
                        "query {}: coordinate {} = {} exceeds the {}-bit axis",
                        q.id, a, q.coords[a], cfg.layout.bits[a]
                    )));
                }
            }
        }
        let mut results: Vec<Option<HwResult>> = vec![None; queries.len()];
        let mut received = 0usize;
        let mut next_query = 0usize;
        let mut presenting = false;
        // The result being received: (query index, expected count).
        let mut current: Option<(usize, usize)> = None;
        let mut since_progress = 0u64;
        let patience = 10_000 + 8 * (cfg.tree_words() as u64 + 2) * cfg.issue_interval() as u64;
        while received < queries.len() {
            if max_cycles.is_some_and(|m| self.stats.cycles - start_cycle >= m) {
                break;
            }
            if next_query < queries.len() && !presenting && !self.stall() {
                presenting = true;
            }
            let result_ready = !self.stall();
            {
                let uut = self.uut.ports();
                uut.query_valid.next = presenting;
                if next_query < queries.len() {
                    let q = &queries[next_query];
                    uut.query_id.next = (next_query as u64).into();
                    uut.query_x.next = (q.coords[0] as u64).into();
                    uut.query_y.next = (q.coords[1] as u64).into();
                    uut.query_z.next = (q.coords[2] as u64).into();
                    uut.query_radius.next = q.radius.min(u32::MAX as u64).into();
                    uut.query_k.next = (q.k as u64).into();
                }
                uut.result_ready.next = result_ready;
            }
            self.settle_low()?;
            let uut = self.uut.ports();
            let query_fire = presenting && uut.query_ready.val();
            let result_fire = result_ready && uut.result_valid.val();
            if result_fire {
                let id = uut.result_id.val().to_u64() as usize;
                let last = uut.result_last.val();
                if uut.result_header.val() {
                    if current.is_some() {
                        return Err(sim_error("result header inside a result"));
                    }
                    let q = queries
                        .get(id)
                        .ok_or_else(|| sim_error(format!("result for unknown query tag {id}")))?;
                    if results[id].is_some() {
                        return Err(sim_error(format!("duplicate result for query {}", q.id)));
                    }
                    let count = uut.result_count.val().to_u64() as usize;
                    results[id] = Some(HwResult {
                        id: q.id,
                        found: Vec::with_capacity(count),
                        visited: uut.result_visited.val().to_u64() as u32,
                    });
                    current = Some((id, count));
                    if (count == 0) != last {
                        return Err(sim_error("result header: last flag and count disagree"));
                    }
                } else {
                    let (cid, count) =
                        current.ok_or_else(|| sim_error("result entry without a header"))?;
                    if id != cid {
                        return Err(sim_error("result entries of two queries interleaved"));
                    }
                    let r = results[cid].as_mut().expect("header seen");
                    r.found.push((
                        uut.result_address.val().to_u64() as u32,
                        uut.result_dist.val().to_u64(),
                    ));
                    if (r.found.len() == count) != last {
                        return Err(sim_error("result entries: last flag and count disagree"));
                    }
                }
                if last {
                    current = None;
                    received += 1;
                }
            }
            self.tick()?;
            if query_fire {
                next_query += 1;
                presenting = false;
            }
            if query_fire || result_fire {
                since_progress = 0;
            } else {
                since_progress += 1;
                if since_progress > patience {
                    return Err(sim_error(format!(
                        "no progress for {patience} cycles ({received} of {} results)",
                        queries.len()
                    )));
                }
            }
        }
        {
            let uut = self.uut.ports();
            uut.query_valid.next = false;
            uut.result_ready.next = false;
        }
        self.settle_low()?;
        if let Some(vcd) = &mut self.vcd {
            let _ = vcd.timestamp(self.time);
        }
        Ok(results)
    }
}

/// What [`CoreSim`] needs from a [`CoreSimOf`], whatever its top and widths.
trait Driver {
    fn config(&self) -> &CoreConfig;
    fn stats(&self) -> &SimStats;
    fn reset(&mut self) -> Result<(), Error>;
    fn load_map(&mut self, tree: &PackedTree) -> Result<(), Error>;
    fn drive_queries(
        &mut self,
        queries: &[HwQuery],
        max_cycles: Option<u64>,
    ) -> Result<Vec<Option<HwResult>>, Error>;
}

impl<const W: usize, U: SearchTop<W>> Driver for CoreSimOf<W, U> {
    fn config(&self) -> &CoreConfig {
        &self.cfg
    }
    fn stats(&self) -> &SimStats {
        &self.stats
    }
    fn reset(&mut self) -> Result<(), Error> {
        CoreSimOf::reset(self)
    }
    fn load_map(&mut self, tree: &PackedTree) -> Result<(), Error> {
        CoreSimOf::load_map(self, tree)
    }
    fn drive_queries(
        &mut self,
        queries: &[HwQuery],
        max_cycles: Option<u64>,
    ) -> Result<Vec<Option<HwResult>>, Error> {
        CoreSimOf::drive_queries(self, queries, max_cycles)
    }
}

/// The core (T = 1) or the array of T trees for `cfg`, with the slot-mask and word
/// widths `S`, `W` that `cfg` needs.
fn driver<const S: usize, const W: usize>(
    cfg: &CoreConfig,
    opts: &SimOptions,
) -> Result<Box<dyn Driver>, Error> {
    Ok(if cfg.trees == 1 {
        Box::new(CoreSimOf::<W, PhotonSearchCore<S, W>>::new(cfg, opts)?)
    } else {
        Box::new(CoreSimOf::<W, PhotonSearchArray<S, W>>::new(cfg, opts)?)
    })
}

/// The simulated core for any configuration: the slot-mask width is chosen from K
/// ([`CoreConfig::slot_bits`]), the word width from the layout
/// ([`CoreConfig::word_width`]), so the paper's core keeps rust-hdl's fast 32-bit
/// `Bits`; T > 1 simulates a [`PhotonSearchArray`].
pub struct CoreSim(Box<dyn Driver>);

impl CoreSim {
    /// Elaborate and check a core for `cfg`.
    pub fn new(cfg: &CoreConfig, opts: &SimOptions) -> Result<Self, Error> {
        cfg.validate()?;
        Ok(CoreSim(dispatch_widths!(cfg, driver(cfg, opts))?))
    }

    pub fn config(&self) -> &CoreConfig {
        self.0.config()
    }

    /// Counters since the core was built.
    pub fn stats(&self) -> &SimStats {
        self.0.stats()
    }

    /// Synchronous reset for two cycles.
    pub fn reset(&mut self) -> Result<(), Error> {
        self.0.reset()
    }

    /// Stream `tree`'s words into the TreeModule (addresses 1..=N, `last` on N).
    pub fn load_map(&mut self, tree: &PackedTree) -> Result<(), Error> {
        self.0.load_map(tree)
    }

    /// Run `queries` on the loaded map; results in input order.
    pub fn run_queries(&mut self, queries: &[HwQuery]) -> Result<Vec<HwResult>, Error> {
        let results = self.0.drive_queries(queries, None)?;
        Ok(results
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
    ) -> Result<Vec<Option<HwResult>>, Error> {
        self.0.drive_queries(queries, Some(cycles))
    }
}

/// Load `tree` into a fresh core for `cfg`, run `queries`, return the results in
/// input order and the cycle counts.
pub fn run_gather(
    cfg: &CoreConfig,
    tree: &PackedTree,
    queries: &[HwQuery],
    opts: &SimOptions,
) -> Result<(Vec<HwResult>, SimStats), Error> {
    cfg.check_map(tree)?;
    let mut sim = CoreSim::new(cfg, opts)?;
    sim.load_map(tree)?;
    let results = sim.run_queries(queries)?;
    Ok((results, sim.stats().clone()))
}
