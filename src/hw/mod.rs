//! The photon-search core (paper §4) as rust-hdl blocks.

pub mod axis_dist;
pub mod config;
pub mod core;
pub mod dist_module;
pub mod max_finder;
pub mod metric;
pub mod next_index;
pub mod photon_word;
pub mod port_arbiter;
pub mod query_module;
pub mod search_module;
pub mod search_port;
pub mod shell;
pub mod sim;
pub mod tree_module;
pub mod verilog;
