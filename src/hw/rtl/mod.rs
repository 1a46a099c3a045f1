//! Running the core: the one simulation driver and its native (rust-hdl) target,
//! the Verilog export and its post-processing, the cross-simulation against Icarus
//! and Verilator, and the registered shell for place and route. Builds on the
//! blocks of `hw`; nothing in the blocks imports this.

pub mod axis_top;
pub mod driver;
pub mod entry_distances;
pub mod export;
pub mod model_cache;
pub mod native;
pub mod ports;
pub mod shell;
pub mod top;
pub mod verilator;
pub mod xsim;
pub mod xsim_tb;
