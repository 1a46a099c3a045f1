//! The subcommands that are more than a call into the library; `main.rs` parses
//! and dispatches.

pub mod bench_core;
pub mod core_args;
