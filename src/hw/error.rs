//! The hardware layer's errors: what a configuration, a map, a simulation or the
//! export can get wrong. The host wraps them in its user-facing error.

/// An error of the hardware layer; the message names the value that is wrong.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum HwError {
    /// The configuration or the map does not fit the datapath.
    #[error("hardware core: {0}")]
    Config(String),
    /// The simulated core broke the stream protocol or stopped making progress.
    #[error("hardware simulation: {0}")]
    Simulation(String),
    /// The cross-simulation could not run or its tools failed.
    #[error("cross-simulation: {0}")]
    CrossSim(String),
    /// The Verilog export or its post-processing failed.
    #[error("Verilog export: {0}")]
    Export(String),
}
