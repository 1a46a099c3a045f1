//! The command line's own enum (`--device`) and the list of every enum an option
//! takes, for the help test. The library's enums (`Metric`, `Traversal`,
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

/// Every command-line enum's value names, for the help test.
#[cfg(test)]
pub fn all_value_lists() -> Vec<Vec<String>> {
    use crate::hw::config::bank_config::BankPorts;
    use crate::hw::config::controller::Controller;
    use crate::hw::config::metric::Metric;
    use crate::hw::config::traversal::Traversal;
    use crate::hw::sim::native::Engine;
    fn names<T: ValueEnum>() -> Vec<String> {
        T::value_variants()
            .iter()
            .filter_map(|v| v.to_possible_value())
            .map(|p| p.get_name().to_string())
            .collect()
    }
    vec![
        names::<Metric>(),
        names::<Traversal>(),
        names::<Controller>(),
        names::<BankPorts>(),
        names::<Engine>(),
        names::<crate::host::gather::BackendKind>(),
        names::<crate::host::render::RenderMethod>(),
        names::<super::export::InterfaceArg>(),
        names::<DeviceArg>(),
    ]
}
