//! photon-fpga: the photon-search core of Kuhara et al. (rust-hdl blocks, their
//! simulation and Verilog export) and the host that feeds and checks it.
//! Layers, lowest first: `hw`, `host`, `cli` (tests/layers.rs checks them).

#[cfg(feature = "cli")]
pub mod cli;
pub mod host;
pub mod hw;
