//! What the driver drives ([`Dut`]: a simulated core, cycle by cycle, its
//! [`Inputs`] and [`Outputs`]) and who watches it ([`Observer`]s, shown each
//! [`Cycle`]).

use crate::hw::config::core_config::{CoreConfig, MAX_RESULT_STREAMS};
use crate::hw::config::photon_word::TreeImage;
use crate::hw::error::HwError;
use crate::hw::primitives::stream::{QueryBeat, ResultBeat};
use crate::hw::sim::axi_memory::MemoryTraffic;

/// The load beat the host presents.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct LoadBeat {
    pub address: u64,
    pub word: u64,
    pub last: bool,
}

/// The core's inputs in one cycle, as the host drives them (data fields keep their
/// last value while not valid).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Inputs {
    pub reset: bool,
    pub load_valid: bool,
    pub load: LoadBeat,
    pub query_valid: bool,
    pub query: QueryBeat,
    /// Per result stream (`CoreConfig::result_streams`; the rest unused).
    pub result_ready: [bool; MAX_RESULT_STREAMS],
}

/// The core's stream outputs in one cycle.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Outputs {
    pub load_ready: bool,
    pub query_ready: bool,
    /// Per result stream, as `Inputs::result_ready`.
    pub result_valid: [bool; MAX_RESULT_STREAMS],
    pub result: [ResultBeat; MAX_RESULT_STREAMS],
}

/// A simulated core, cycle by cycle.
pub trait Dut {
    fn config(&self) -> &CoreConfig;
    /// Apply `inputs` with the clock low and settle (this is also the falling edge
    /// of the previous cycle).
    fn drive(&mut self, inputs: &Inputs) -> Result<(), HwError>;
    /// The stream outputs, settled.
    fn outputs(&mut self) -> Outputs;
    /// Tree `t`'s status: port A reads, port B reads, all its QueryModules busy.
    fn tree_status(&self, t: usize) -> [bool; 3];
    /// The rising clock edge.
    fn rising_edge(&mut self) -> Result<(), HwError>;
    /// With the map in external memory (`CoreConfig::memory`): put `tree`'s
    /// image (`MemoryLayout::image`) into the memory model that answers the
    /// core's AXI4 master, replacing what it held.
    fn load_memory(&mut self, _tree: TreeImage<'_>) -> Result<(), HwError> {
        Err(HwError::Simulation(
            "this simulated core has no external memory".into(),
        ))
    }
    /// With external memory: what its model has carried since the map was put in
    /// it (zero without).
    fn memory_traffic(&self) -> MemoryTraffic {
        MemoryTraffic::default()
    }
    /// Settle passes so far (every block's `update`, repeated until nothing
    /// changes), for simulators that settle by passes (native): bench-core's
    /// simulation profile.
    fn settle_passes(&self) -> Option<u64> {
        None
    }
    /// The rust-hdl block, for observers that read every port (native simulation).
    fn block(&self) -> Option<&dyn rust_hdl::prelude::Block> {
        None
    }
}

/// One cycle as observers see it.
pub struct Cycle<'a> {
    /// Cycle number since the core was built (the reset cycles are 0 and 1).
    pub index: u64,
    pub dut: &'a dyn Dut,
    pub inputs: &'a Inputs,
    pub outputs: &'a Outputs,
}

/// Sees every cycle of a run.
pub trait Observer {
    /// The cycle's inputs are applied and settled; its rising edge comes next.
    fn sampled(&mut self, _cycle: &Cycle<'_>) -> Result<(), HwError> {
        Ok(())
    }
    /// The cycle's rising edge has happened.
    fn edge(&mut self, _cycle: &Cycle<'_>) -> Result<(), HwError> {
        Ok(())
    }
}
