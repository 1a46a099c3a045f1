//! The photon-search core (paper §4) as rust-hdl blocks.
//!
//! Block structure (one block per file, ports first, `#[hdl_gen] fn update`):
//!
//! ```text
//! PhotonSearchArray (array.rs)          T > 1 replicated trees: T cores, same streams
//! PhotonSearchCore (core.rs)            load / query / result valid-ready streams
//! ├── Dispatcher (dispatcher.rs)        queries to a port with a free QueryModule
//! ├── PacketMerge (packet_merge.rs)     the two ports' result packets into one stream
//! ├── TreeModule (tree_module.rs)       true dual-port BlockRAM, 2^H words
//! ├── SearchPort A (search_port.rs)     TreeModule port A (also the load port)
//! │   ├── QueryModule × Q (query_module.rs)
//! │   │   ├── MaxFinder (max_finder.rs) bit-transposed distance list, §4.4
//! │   │   └── CellBound (cell_bound.rs) offsets from the cell, `Traversal::Cell`
//! │   ├── PortArbiter (port_arbiter.rs) one read per cycle, round robin, §4.5
//! │   ├── SearchModule (search_module.rs)
//! │   │   ├── AxisDistModule (axis_dist.rs)
//! │   │   ├── DistModule (dist_module.rs)
//! │   │   └── NextIndexModule (next_index.rs)
//! │   └── ResultRegister (register_slice.rs) skid buffer on the result stream
//! └── SearchPort B                      TreeModule port B
//!   (or, with `Controller::Barrel`, per port:)
//!   BarrelPort (barrel_port.rs)         Q query slots behind one pipelined datapath
//!   ├── LutRam × … (lut_ram.rs)         per-slot state, found distances, bounds
//!   ├── BlockRam × 3 (block_ram.rs)     found entries, far-cell offsets
//!   ├── SearchModule                    as above
//!   └── ResultRegister
//! ```
//!
//! A QueryModule issues a read at most every `CoreConfig::issue_interval()` =
//! 8 + distance-bits cycles (the registered grant, grant, BlockRAM, its read-data
//! register, two SearchModule stages, insertion, the MaxFinder's priming cycle and
//! one cycle per distance bit, the R update; 6 + distance bits unpipelined); with Q >= that interval a
//! port reads a photon every cycle while all its QueryModules are busy. Results are
//! bit-identical to `host::map::knn::search_with` (same slots, same number of reads) for
//! the configured [`traversal::Traversal`]: by default a QueryModule remembers each
//! level's axis distance on the way down and climbs back up without reads (one
//! level per cycle, no port slot); `Reread` is the paper's ascent, which reads every
//! parent again.
//!
//! The streams are written once ([`stream`]); the core and the array share one
//! [`dispatcher::Dispatcher`] and one [`packet_merge::PacketMerge`]. Running the
//! core (simulation driver, export, cross-simulation) lives in [`rtl`], which
//! builds on these blocks; nothing here imports it, and nothing in `hw` imports the
//! host. Host-facing API: [`config::CoreConfig`], [`rtl::native::run_gather`],
//! [`rtl::export::export_verilog`]; both tops implement [`rtl::top::SearchTop`]. The datapath limits (words <= 47 bits, 32-bit distances,
//! H <= 20, K <= 64, Q <= 32, T <= 8) are in [`config`].

pub mod array;
pub mod axis_dist;
pub mod barrel_port;
pub mod block_ram;
pub mod cell_bound;
pub mod config;
pub mod config_builder;
pub mod controller;
pub mod core;
pub mod dispatcher;
pub mod dist_module;
pub mod error;
pub mod found_max;
pub mod lut_ram;
pub mod max_finder;
pub mod metric;
pub mod next_index;
pub mod packet_merge;
pub mod photon_word;
pub mod port_arbiter;
pub mod query_module;
pub mod register_slice;
pub mod rtl;
pub mod search_module;
pub mod search_port;
pub mod slot_readout;
pub mod slot_store;
pub mod stream;
pub mod traversal;
pub mod tree_module;
