//! The command line's own enum (`--device`). The library's enums (`Metric`, `Traversal`,
//! `Controller`, `BankPorts`, `Engine`, `BackendKind`) are value enums themselves
//! behind the `cli` feature: their names and help texts are written once, at their
//! definitions.

use clap::ValueEnum;

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
    pub fn device(self) -> &'static crate::host::device::plan::Device {
        use crate::host::device::plan::{ECP5_85K, XC6VSX475T};
        match self {
            DeviceArg::Ecp585k => &ECP5_85K,
            DeviceArg::Xc6vsx475t => &XC6VSX475T,
        }
    }
}
