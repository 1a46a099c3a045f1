//! A core simulated on a query stream, every answer checked against the software
//! search (the photons read and the distances found, query by query): what
//! `bench-core` and the external-memory sweep measure.

use photon_fpga::host::error::{Error, Result};
use photon_fpga::host::map::kdtree::PackedTree;
use photon_fpga::host::map::knn::search_with;
use photon_fpga::hw::config::core_config::CoreConfig;
use photon_fpga::hw::sim::driver::{HwQuery, HwResult, SimStats};
use photon_fpga::hw::sim::native::{CoreSim, SimOptions};

/// One stream through one core.
pub struct CheckedRun {
    /// The answers, in the stream's order.
    pub results: Vec<HwResult>,
    /// The simulation's counters (the map's load included; see `load_cycles`).
    pub stats: SimStats,
    pub load_cycles: u64,
    /// Wall time of the queries' simulation.
    pub secs: f64,
    /// Native settle passes during the queries (none under Verilator).
    pub passes: Option<u64>,
    /// The software search's photon reads and distance tests, summed.
    pub sw_visited: u64,
    pub sw_tested: u64,
}

impl CheckedRun {
    /// Cycles of the queries, after the load.
    pub fn cycles(&self) -> u64 {
        self.stats.cycles - self.load_cycles
    }

    /// Photon reads of every port.
    pub fn reads(&self) -> u64 {
        self.stats.reads_per_port.iter().sum()
    }
}

/// The sorted distances of a core's answer.
fn distances(r: &HwResult) -> Vec<u64> {
    let mut d: Vec<u64> = r.found.iter().map(|x| x.1).collect();
    d.sort();
    d
}

/// Run `queries` (initial radius `max` on the grid) through `cfg` holding `tree`,
/// and check every answer against the software search.
pub fn run_checked(
    cfg: &CoreConfig,
    tree: &PackedTree,
    queries: &[HwQuery],
    max: u64,
    opts: &SimOptions,
) -> Result<CheckedRun> {
    let mut sim = CoreSim::new(cfg, opts)?;
    sim.load_map(tree.image())?;
    let load_cycles = sim.stats().cycles;
    let passes0 = sim.settle_passes();
    let t0 = std::time::Instant::now();
    let results = sim.run_queries(queries)?;
    let secs = t0.elapsed().as_secs_f64();
    let passes = sim.settle_passes().zip(passes0).map(|(b, a)| b - a);
    let (mut sw_visited, mut sw_tested) = (0u64, 0u64);
    for (q, r) in queries.iter().zip(&results) {
        let f = search_with(tree, q.coords, cfg.k, max, cfg.metric, cfg.traversal);
        if f.visited != r.visited || f.sorted_dists() != distances(r) {
            return Err(Error::new(format!(
                "query {}: the core disagrees with the software search \
                 (core: {} reads, distances {:?}; software: {} reads, {:?})",
                q.id,
                r.visited,
                distances(r),
                f.visited,
                f.sorted_dists()
            )));
        }
        sw_visited += f.visited as u64;
        sw_tested += f.tested as u64;
    }
    Ok(CheckedRun {
        stats: sim.stats().clone(),
        results,
        load_cycles,
        secs,
        passes,
        sw_visited,
        sw_tested,
    })
}
