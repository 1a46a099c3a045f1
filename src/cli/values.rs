//! The command line's names for the library's enums. The hardware layer knows no
//! command line, so each value list is declared here once, with the help text of
//! every value, and converts to and from the library's type; an exhaustive `match`
//! both ways makes a value added to the library a compile error here until it gets
//! a name and a help text.

use clap::ValueEnum;
use photon_fpga::hw::bank_crossbar::BankPorts;
use photon_fpga::hw::controller::Controller;
use photon_fpga::hw::metric::Metric;
use photon_fpga::hw::rtl::native::Engine;
use photon_fpga::hw::traversal::Traversal;

photon_fpga::enum_mirror! {
    /// `--metric`: the distance of the search (paper §4.4).
    #[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
    MetricArg => Metric {
        /// Squared Euclidean distance (no square root in hardware).
        L2,
        /// Manhattan distance (the paper's 12-bit "absolute distance").
        L1,
    }
}

photon_fpga::enum_mirror! {
    /// `--traversal`: how the search climbs back up the tree (paper §2.2, §4.3).
    #[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
    TraversalArg => Traversal {
        /// Remember each level's axis distance on the way down: the ascent reads
        /// nothing (reads per query = distance tests).
        Remember,
        /// The paper's search: re-read every parent on the way up.
        Reread,
        /// Remember the path and prune on the distance to the far child's cell
        /// (Arya and Mount): fewest reads.
        Cell,
    }
}

photon_fpga::enum_mirror! {
    /// `--controller`: who runs a port's queries.
    #[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
    ControllerArg => Controller {
        /// Q QueryModules per port behind a round-robin arbiter (the paper's, §4.2).
        Modules,
        /// Q query slots in memory behind one pipelined datapath per port: about a
        /// fifth of the LUTs for nearly the same queries/s. Needs a traversal that
        /// remembers the path (remember, cell).
        Barrel,
    }
}

photon_fpga::enum_mirror! {
    /// `--bank-ports`: how a bank's two BlockRAM read ports serve the datapaths.
    #[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
    BankPortsArg => BankPorts {
        /// One read port per bank.
        One,
        /// Two ports, either one serving any datapath (the fewest bank conflicts).
        Shared,
        /// Two ports, the first serving the even datapaths and the second the odd
        /// ones: half the crossbar of shared (a bank's two reads in a cycle must
        /// come from a replica's two datapaths).
        Split,
    }
}

photon_fpga::enum_mirror! {
    /// `--engine`: the simulator that runs the core.
    #[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
    EngineArg => Engine {
        /// rust-hdl's own simulation of the blocks.
        Native,
        /// The exported Verilog under Verilator (built on first use, cached in
        /// $PHOTON_FPGA_CACHE_DIR, else $XDG_CACHE_HOME/photon-fpga or
        /// ~/.cache/photon-fpga).
        Verilator,
    }
}

/// `--device`: the FPGA a banked core is planned for (`host::device::plan`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum DeviceArg {
    /// Lattice ECP5-85k: 208 DP16KD (the open place-and-route target).
    #[value(name = "ecp5-85k")]
    Ecp585k,
    /// Xilinx XC6VSX475T: 1,064 RAMB36 (the paper's Virtex-6 family's largest).
    #[value(name = "xc6vsx475t")]
    Xc6vsx475t,
}

impl DeviceArg {
    pub fn device(self) -> &'static photon_fpga::host::device::plan::Device {
        use photon_fpga::host::device::plan::{ECP5_85K, XC6VSX475T};
        match self {
            DeviceArg::Ecp585k => &ECP5_85K,
            DeviceArg::Xc6vsx475t => &XC6VSX475T,
        }
    }
}

/// Every command-line enum's value names, for the help test.
#[cfg(test)]
pub fn all_value_lists() -> Vec<Vec<String>> {
    fn names<T: ValueEnum>() -> Vec<String> {
        T::value_variants()
            .iter()
            .filter_map(|v| v.to_possible_value())
            .map(|p| p.get_name().to_string())
            .collect()
    }
    vec![
        names::<MetricArg>(),
        names::<TraversalArg>(),
        names::<ControllerArg>(),
        names::<BankPortsArg>(),
        names::<EngineArg>(),
        names::<photon_fpga::host::gather::BackendKind>(),
        names::<photon_fpga::host::render::RenderMethod>(),
        names::<super::bench_core::WorkloadKind>(),
        names::<super::export::InterfaceArg>(),
        names::<DeviceArg>(),
    ]
}
