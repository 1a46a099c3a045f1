//! What a run cost ([`SimStats`]) and the driver's observer that counts it, cycle
//! by cycle, from the streams and the core's read status.

use crate::hw::error::HwError;
use crate::hw::sim::axi_memory::MemoryTraffic;
use crate::hw::sim::dut::{Cycle, Observer};

/// What a run cost, in clock cycles. Ports are listed tree by tree (A, B of tree 0,
/// then of tree 1, ...).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct SimStats {
    pub cycles: u64,
    /// Cycles from the first query presented on: the run without the map's load.
    pub search_cycles: u64,
    pub reads_per_port: Vec<u64>,
    /// Cycles with every QueryModule (of every tree) occupied.
    pub busy_cycles: u64,
    pub busy_reads_per_port: Vec<u64>,
    /// Result beats taken (valid and ready): what the result streams carry.
    pub result_beats: u64,
    /// The same, per result stream.
    pub result_beats_per_stream: Vec<u64>,
    /// With external memory: what it has carried since the map was put in it.
    pub memory: MemoryTraffic,
}

/// Counts cycles and photon reads ([`SimStats`]).
#[derive(Default)]
pub struct StatsObserver {
    pub stats: SimStats,
    /// A query has been presented (the load is over).
    searching: bool,
}

impl Observer for StatsObserver {
    fn sampled(&mut self, c: &Cycle<'_>) -> Result<(), HwError> {
        let trees = c.dut.config().trees;
        let s = &mut self.stats;
        if s.reads_per_port.is_empty() {
            s.reads_per_port = vec![0; 2 * trees];
            s.busy_reads_per_port = vec![0; 2 * trees];
        }
        // Twice over the trees rather than collecting: no allocation per cycle.
        let all_busy = (0..trees).all(|t| c.dut.tree_status(t)[2]);
        s.busy_cycles += all_busy as u64;
        for t in 0..trees {
            let [a, b, _] = c.dut.tree_status(t);
            for (port, reading) in [(2 * t, a), (2 * t + 1, b)] {
                s.reads_per_port[port] += reading as u64;
                if all_busy {
                    s.busy_reads_per_port[port] += reading as u64;
                }
            }
        }
        s.cycles += 1;
        let streams = c.dut.config().result_streams;
        if s.result_beats_per_stream.is_empty() {
            s.result_beats_per_stream = vec![0; streams];
        }
        for (i, beats) in s.result_beats_per_stream.iter_mut().enumerate() {
            let beat = (c.outputs.result_valid[i] && c.inputs.result_ready[i]) as u64;
            *beats += beat;
            s.result_beats += beat;
        }
        s.memory = c.dut.memory_traffic();
        self.searching |= c.inputs.query_valid;
        s.search_cycles += self.searching as u64;
        Ok(())
    }
}
