//! The elaboration-time options of a core, shared by `export-verilog` and
//! `bench-core`.

use clap::Args;
use photon_fpga::host::error::{Error, Result};
use photon_fpga::hw::config::{CoreConfig, BARREL_SLOTS};
use photon_fpga::hw::controller::Controller;
use photon_fpga::hw::metric::Metric;
use photon_fpga::hw::photon_word::PhotonLayout;
use photon_fpga::hw::traversal::Traversal;

/// The elaboration-time parameters of a core.
#[derive(Args)]
pub struct CoreArgs {
    /// Found-list depth K (the largest k a query may ask for).
    #[arg(long, default_value_t = CoreConfig::paper().k)]
    k: usize,
    /// Coordinate bits on every axis.
    #[arg(long, default_value_t = CoreConfig::paper().layout.bits[0])]
    bits: u32,
    /// Tree height H: the TreeModule holds 2^H photon words.
    #[arg(long, default_value_t = CoreConfig::paper().address_bits)]
    address_bits: u32,
    /// QueryModules per TreeModule port [default: the issue interval, so a busy
    /// port reads every cycle].
    #[arg(long)]
    queries_per_port: Option<usize>,
    /// Distance metric: l1 (the paper's 12-bit distance) or l2 (squared Euclidean).
    #[arg(long, default_value_t = CoreConfig::paper().metric)]
    metric: Metric,
    /// Leave out the pipeline registers (BlockRAM read data, result streams): two
    /// cycles less latency, longer critical paths. For before/after timing.
    #[arg(long)]
    unpipelined: bool,
    /// How a QueryModule climbs back up: remember (path memory, no re-reads),
    /// reread (the paper's re-read of every parent) or cell (remember, pruning on
    /// the distance to the far child's cell: fewest reads, more LUTs).
    #[arg(long, default_value_t = Traversal::default())]
    traversal: Traversal,
    /// Replicated trees T (the paper's future work): T copies of the core, each with
    /// its own copy of the map, behind one set of streams (src/hw/array.rs).
    #[arg(long, default_value_t = 1)]
    trees: usize,
    /// Who runs a port's queries: modules (the paper's Q QueryModules) or barrel
    /// (Q query slots in memory behind one pipelined datapath per port; needs
    /// --traversal remember or cell; Q defaults to 16 slots).
    #[arg(long, default_value_t = Controller::default())]
    controller: Controller,
}

impl CoreArgs {
    pub fn config(&self) -> Result<CoreConfig> {
        if !(1..=photon_fpga::hw::config::MAX_HW_COORD_BITS).contains(&self.bits) {
            return Err(Error::new(format!(
                "--bits {} is out of range (1..={})",
                self.bits,
                photon_fpga::hw::config::MAX_HW_COORD_BITS
            )));
        }
        let mut cfg = CoreConfig {
            layout: PhotonLayout::new([self.bits; 3]),
            address_bits: self.address_bits,
            k: self.k,
            queries_per_port: 1,
            metric: self.metric,
            pipelined: !self.unpipelined,
            trees: self.trees,
            traversal: self.traversal,
            controller: self.controller,
        };
        let default_q = match self.controller {
            Controller::Modules => cfg.issue_interval(),
            Controller::Barrel => BARREL_SLOTS,
        };
        cfg.queries_per_port = self.queries_per_port.unwrap_or(default_q);
        cfg.validate()?;
        Ok(cfg)
    }
}
