//! The lab's subcommands; `main.rs` parses and dispatches. They take the product's
//! core options (`photon_fpga::cli::core_args`) so a measured core is named the way
//! a user names it.

pub mod banking;
pub mod bench_banks;
pub mod bench_core;
pub mod memory;
pub mod memory_core;
pub mod study;
