//! The banked core itself, simulated (the exported Verilog under Verilator, or
//! rust-hdl's own simulation), where `sim` is the cycle model: reads per cycle
//! against D and B on one query stream (the bank-conflict curve), and queries per
//! second against map size for the core a device's plan holds. Every answer is
//! checked against the software search read for read (the photons it read and the
//! distances it found), so a point is only reported for a core that answered right.

use crate::workload;
use photon_fpga::host::device::banked_core::{self, result_streams};
use photon_fpga::host::device::plan::Device;
use photon_fpga::host::error::{Error, Result};
use photon_fpga::host::map::kdtree::PackedTree;
use photon_fpga::host::map::knn::search_with;
use photon_fpga::host::render::RenderSettings;
use photon_fpga::hw::config::bank_config::BankPorts;
use photon_fpga::hw::config::config_builder::CoreBuilder;
use photon_fpga::hw::config::controller::Controller;
use photon_fpga::hw::config::core_config::{Banking, CoreConfig, PORTS};
use photon_fpga::hw::config::metric::Metric;
use photon_fpga::hw::config::traversal::Traversal;
use photon_fpga::hw::sim::driver::HwQuery;
use photon_fpga::hw::sim::native::{CoreSim, Engine, SimOptions};

/// Grid bits of the measured maps (the default render's).
pub const GRID_BITS: u32 = 10;

/// One simulated run: the core, the stream and what it cost.
#[derive(Clone, Debug, PartialEq)]
pub struct RtlPoint {
    pub config: CoreConfig,
    pub photons: usize,
    pub queries: usize,
    /// Cycles from the first query to the last result (the map's load left out).
    pub cycles: u64,
    pub reads: u64,
    pub result_beats: u64,
}

impl RtlPoint {
    /// Datapaths of the whole top: two a tree, whether the trees are replicas of
    /// a banked core's top levels or whole cores of an array.
    pub fn datapaths(&self) -> usize {
        PORTS * self.config.trees
    }
    /// Banks (1: none, each replica holds the whole map).
    pub fn banks(&self) -> u64 {
        self.config.banking.map_or(1, |b| 1 << b.bank_bits)
    }
    /// The banks' port mode ("–": no banks).
    pub fn ports(&self) -> &'static str {
        self.config.banking.map_or("–", |b| b.ports.name())
    }
    pub fn reads_per_cycle(&self) -> f64 {
        self.reads as f64 / self.cycles.max(1) as f64
    }
    pub fn per_datapath(&self) -> f64 {
        self.reads_per_cycle() / self.datapaths() as f64
    }
    pub fn reads_per_query(&self) -> f64 {
        self.reads as f64 / self.queries.max(1) as f64
    }
    /// Beats a cycle on each result stream (the mean of the streams).
    pub fn beats_per_stream_cycle(&self) -> f64 {
        self.result_beats as f64 / self.cycles.max(1) as f64 / self.config.result_streams as f64
    }
    /// Queries per second at `mhz` (simulated reads × the clock given).
    pub fn queries_per_s(&self, mhz: f64) -> f64 {
        self.reads_per_cycle() * mhz * 1e6 / self.reads_per_query().max(f64::MIN_POSITIVE)
    }
}

/// The barrel core the sweeps measure: k = K, squared L2 (the direct render's
/// gather), the cell traversal, 16 slots a datapath.
fn base(k: usize) -> CoreBuilder {
    CoreConfig::builder()
        .k(k)
        .metric(Metric::L2)
        .controller(Controller::Barrel)
        .traversal(Traversal::Cell)
}

/// Run `queries` (k = K, unbounded radius) through `cfg` holding `tree`, and check
/// every answer against the software search.
pub fn run_checked(
    cfg: &CoreConfig,
    tree: &PackedTree,
    queries: &[[u32; 3]],
    engine: Engine,
) -> Result<RtlPoint> {
    let max = cfg.max_dist();
    let hw = HwQuery::k_nearest(cfg, queries);
    let mut sim = CoreSim::new(
        cfg,
        &SimOptions {
            engine,
            ..SimOptions::default()
        },
    )?;
    sim.load_map(tree.image())?;
    let loaded = sim.stats().clone();
    let results = sim.run_queries(&hw)?;
    let st = sim.stats();
    for (q, r) in hw.iter().zip(&results) {
        let f = search_with(tree, q.coords, cfg.k, max, cfg.metric, cfg.traversal);
        let mut got: Vec<u64> = r.found.iter().map(|x| x.1).collect();
        got.sort_unstable();
        if f.visited != r.visited || f.sorted_dists() != got {
            return Err(Error::new(format!(
                "query {} at {:?}: the core ({} reads, distances {got:?}) disagrees with the \
                 software search ({} reads, {:?})",
                q.id,
                q.coords,
                r.visited,
                f.visited,
                f.sorted_dists()
            )));
        }
    }
    let reads = st.reads_per_port.iter().sum::<u64>() - loaded.reads_per_port.iter().sum::<u64>();
    Ok(RtlPoint {
        config: *cfg,
        photons: tree.len(),
        queries: hw.len(),
        cycles: st.cycles - loaded.cycles,
        reads,
        result_beats: st.result_beats - loaded.result_beats,
    })
}

/// The bank-conflict curve: for each D (an even number, D / 2 replicas), bank-port
/// mode and B (a power of two; 1 = no banks: one whole copy per core), the core
/// with the replicated levels' default and one result stream per
/// [`banked_core::DATAPATHS_PER_STREAM`] datapaths, on `w`'s queries.
pub fn conflict_curve(
    w: &workload::Workload,
    k: usize,
    datapaths: &[usize],
    banks: &[u64],
    ports: &[BankPorts],
    engine: Engine,
    mut progress: impl FnMut(&RtlPoint),
) -> Result<Vec<RtlPoint>> {
    let mut out = vec![];
    for &d in datapaths {
        if d == 0 || d % PORTS != 0 {
            return Err(Error::new(format!(
                "--datapaths {d}: D is two a replica (an even number from 2)"
            )));
        }
        for (i, &mode) in ports.iter().enumerate() {
            for &b in banks {
                let mut spec = base(k).trees(d / PORTS).result_streams(result_streams(d));
                if b > 1 {
                    let bits = Banking::bank_bits_for(b).map_err(|_| {
                        Error::new(format!("--banks {b}: a power of two from 2 to 1024"))
                    })?;
                    spec = spec.banks(bits, None).bank_ports(mode);
                } else if d > PORTS || i > 0 {
                    // Whole copies: D > 2 would be an array of cores, not one banked
                    // core; and without banks there are no bank ports to vary.
                    continue;
                } else {
                    spec = spec.banking(None);
                }
                let cfg = spec.build_for(w.tree.image())?;
                let p = run_checked(&cfg, &w.tree, &w.queries, engine)?;
                progress(&p);
                out.push(p);
            }
        }
    }
    Ok(out)
}

/// A map of the sweep over map sizes: measured, or refused by the device's plan.
pub enum MapPoint {
    Measured(RtlPoint),
    Refused { photons: usize, why: String },
}

/// Queries/s against map size: for each emitted photon count, the Cornell map
/// (on the [`GRID_BITS`] grid) and an even sample of `queries` of `settings`'
/// eye-ray hits, through the core `device`'s plan holds for that map.
pub fn map_sizes(
    emitted: &[usize],
    settings: &RenderSettings,
    k: usize,
    queries: usize,
    device: &Device,
    engine: Engine,
    mut progress: impl FnMut(&MapPoint),
) -> Result<Vec<MapPoint>> {
    let mut out = vec![];
    for &e in emitted {
        let w = workload::cornell_image(e, usize::MAX, GRID_BITS, settings);
        let map = w.tree.image();
        let p = match banked_core::for_device(base(k), map.len(), map.layout.word_bits(), device) {
            Err(why) => MapPoint::Refused {
                photons: map.len(),
                why: why.to_string(),
            },
            Ok(spec) => {
                let cfg = spec.build_for(map)?;
                MapPoint::Measured(run_checked(
                    &cfg,
                    &w.tree,
                    &sample(&w.queries, queries),
                    engine,
                )?)
            }
        };
        progress(&p);
        out.push(p);
    }
    Ok(out)
}

/// An even sample of `n` of `queries` (all of them if there are fewer).
pub fn sample(queries: &[[u32; 3]], n: usize) -> Vec<[u32; 3]> {
    let step = (queries.len() / n.max(1)).max(1);
    queries.iter().step_by(step).take(n).copied().collect()
}
