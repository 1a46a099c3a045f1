//! The photon-search core (paper §4) as rust-hdl blocks.
//!
//! Block structure (one block per file, ports first, `#[hdl_gen] fn update`):
//!
//! ```text
//! PhotonSearchArray (array.rs)          T > 1 whole cores side by side, same streams
//! PhotonSearchCore (core.rs)            load / query / R result valid-ready streams
//! ├── Dispatcher (dispatcher.rs)        queries to a port with a free QueryModule or slot
//! │   └── PortArbiter
//! ├── PacketMerge (packet_merge.rs)     the ports' result packets onto R streams
//! ├── TreeModule × T (tree_module.rs)   true dual-port BlockRAM: the whole tree, or
//! │                                     with banks a replica of its top L levels
//! ├── BankStore (bank_store.rs)         with banks: the levels below, over B banks
//! │   ├── BankMap (bank_map.rs)          heap address → bank and row (XOR-fold)
//! │   ├── TreeModule × B                 one bank each
//! │   └── BankCrossbar (bank_crossbar.rs)  D datapaths × B banks, round robin per port
//! │       ├── PortArbiter, PriorityEncoder  per bank port: its grant and its index
//! │       └── MuxTrees × 2 (mux_trees.rs)   rows to the banks, words back
//! └── ControllerPort × 2T (controller_port.rs)  a tree's port A (also the load
//!     │                                 port) or B, behind one bundle (stream.rs PortIo)
//!     ├── SearchPort (search_port.rs)   `Controller::Modules`, §4.5
//!     │   ├── QueryModule × Q (query_module.rs)  §4.2
//!     │   │   ├── MaxFinder (max_finder.rs)      bit-transposed distance list, §4.4
//!     │   │   │   └── PriorityEncoder (priority_encoder.rs)  lowest slot among ties
//!     │   │   ├── FoundRule (found_rule.rs)      where a photon enters the found list
//!     │   │   ├── QueryLimits (query_limits.rs)  the loaded query's R and k
//!     │   │   ├── PriorityEncoder                one-hot slot → LUT-RAM index
//!     │   │   ├── CellBound (cell_bound.rs)      offsets from the cell, `Traversal::Cell`
//!     │   │   └── LutRam × 4 (lut_ram.rs)        found list, distances, path memory
//!     │   ├── PortArbiter (port_arbiter.rs)      one read per cycle, round robin, §4.5
//!     │   ├── FreePick (free_pick.rs)            the free module the next query takes
//!     │   │   └── PriorityEncoder
//!     │   ├── LutRam                             query ids
//!     │   ├── SearchModule (search_module.rs)
//!     │   │   ├── DistModule (dist_module.rs)       with the paper's AxisDistModule
//!     │   │   └── NextIndexModule (next_index.rs)
//!     │   └── ResultReadout (result_readout.rs)  the result stream's sequencer
//!     │       ├── PriorityEncoder                the lowest finished query
//!     │       └── ResultRegister (register_slice.rs)  skid buffer on the result stream
//!     └── BarrelPort (barrel_port.rs)   `Controller::Barrel`: Q query slots behind one
//!         │                             pipelined datapath
//!         ├── SearchModule                       as above
//!         ├── ReadIssue (read_issue.rs)          its reads to the replica or a bank
//!         │                                      (wires without banks)
//!         ├── FreePick                           the free slot the next query takes
//!         ├── FoundRule, QueryLimits             as in the QueryModule
//!         ├── SlotStore (slot_store.rs)          per-slot state in LUT-RAM
//!         ├── FoundMax (found_max.rs)            K ≤ 64: found distances, comparator tree, §4.4
//!         ├── FoundHeap (found_heap.rs)          K > 64: per-slot max-heaps in BlockRAM
//!         │   └── HeapStage × levels + 1 (heap_stage.rs)  one level of insert / replace
//!         ├── FarCellDist                        the far-cell bound, as in CellBound
//!         ├── Ascent (ascent.rs)                 pruning bounds (LutRam × levels), stage D
//!         ├── BlockRam × 2 (block_ram.rs)        far cells' offsets
//!         └── SlotReadout (slot_readout.rs)      found photons, ids, headers (BlockRAM,
//!                                            LUT-RAM) and its read-out sequencer
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
//! [`rtl::export::export_verilog`]; both tops implement [`rtl::top::SearchTop`]. The datapath limits (words, distances, H, K, Q, T,
//! banks and result streams) are in [`config`] and [`bank_config`].

pub mod array;
pub mod ascent;
pub mod bank_config;
pub mod bank_crossbar;
pub mod bank_map;
pub mod bank_store;
pub mod barrel_port;
pub mod block_ram;
pub mod cell_bound;
pub mod config;
pub mod config_builder;
pub mod config_widths;
pub mod controller;
pub mod controller_port;
pub mod core;
pub mod core_file;
pub mod dispatcher;
pub mod dist_module;
pub mod enum_mirror;
pub mod error;
pub mod far_cell_dist;
pub mod found_heap;
pub mod found_max;
pub mod found_rule;
pub mod free_pick;
pub mod heap_stage;
pub mod lut_ram;
pub mod max_finder;
pub mod metric;
pub mod mux_trees;
pub mod next_index;
pub mod packet_merge;
pub mod photon_word;
pub mod port_arbiter;
pub mod priority_encoder;
pub mod query_limits;
pub mod query_module;
pub mod read_issue;
pub mod register_slice;
pub mod result_readout;
pub mod rtl;
pub mod search_module;
pub mod search_port;
pub mod slot_readout;
pub mod slot_store;
pub mod stream;
pub mod traversal;
pub mod tree_module;

/// `n` default signals, registers or blocks: a block's `Vec` of sub-blocks built at
/// elaboration (rust-hdl elaborates a `Vec` field element by element).
pub(crate) fn many<T: Default>(n: usize) -> Vec<T> {
    (0..n).map(|_| T::default()).collect()
}
