//! The photon-search core (paper §4) as rust-hdl blocks.
//!
//! Folders, lowest first (tests/layers.rs checks that none imports a later one):
//! `config` (what a core is), `primitives` (RAMs, arbiters, encoders, the stream and
//! bank-bus bundles), `store` (the TreeModule, the banked store and the read issue
//! in front of it), `memory` (the map's levels in external memory), `datapath` (the search both controllers share), `modules` (the
//! paper's QueryModule controller), `barrel` (the barrel controller), `top` (the
//! core and the array), `export` (Verilog), `sim` (running the core). One block per file, ports first, `#[hdl_gen] fn update`:
//!
//! ```text
//! PhotonSearchArray (top/array.rs)          T > 1 whole cores side by side, same streams
//! PhotonSearchCore (top/core.rs)            load / query / R result valid-ready streams
//! ├── Dispatcher (top/dispatcher.rs)        queries to a port with a free QueryModule or slot
//! │   └── PortArbiter
//! ├── PacketMerge (top/packet_merge.rs)     the ports' result packets onto R streams
//! ├── TreeModule × T (store/tree_module.rs)   true dual-port BlockRAM: the whole tree, or
//! │                                     with banks a replica of its top L levels
//! ├── BankStore (store/bank_store.rs)         with banks: the levels below, over B banks
//! │   ├── BankMap (store/bank_map.rs)          heap address → bank and row (XOR-fold)
//! │   ├── TreeModule × B                 one bank each
//! │   ├── BankCrossbar (store/bank_crossbar.rs)  D datapaths × B banks, round robin per port
//! │   │   ├── PortArbiter, PriorityEncoder  per bank port: its grant and its index
//! │   │   └── MuxTrees × 2 (primitives/mux_trees.rs)   rows to the banks, words back
//! │   ├── CacheBank × B (memory/cache_bank.rs)  with external memory, the banks are a cache
//! │   ├── FillArbiter (memory/fill_arbiter.rs)  their fill requests, registered picks
//! │   └── LineFill (memory/line_fill.rs)         its AXI4 master: the core's m_axi port
//! └── ControllerPort × 2T (top/controller_port.rs)  a tree's port A (also the load
//!     │                                 port) or B, behind one bundle (primitives/stream.rs PortIo)
//!     ├── SearchPort (modules/search_port.rs)   `Controller::Modules`, §4.5
//!     │   ├── QueryModule × Q (modules/query_module.rs)  §4.2
//!     │   │   ├── MaxFinder (modules/max_finder.rs)      bit-transposed distance list, §4.4
//!     │   │   │   └── PriorityEncoder (primitives/priority_encoder.rs)  lowest slot among ties
//!     │   │   ├── FoundRule (datapath/found_rule.rs)      where a photon enters the found list
//!     │   │   ├── QueryLimits (datapath/query_limits.rs)  the loaded query's R and k
//!     │   │   ├── PriorityEncoder                one-hot slot → LUT-RAM index
//!     │   │   ├── CellBound (datapath/cell_bound.rs)      offsets from the cell, `Traversal::Cell`
//!     │   │   └── LutRam × 4 (primitives/lut_ram.rs)        found list, distances, path memory
//!     │   ├── PortArbiter (primitives/port_arbiter.rs)      one read per cycle, round robin, §4.5
//!     │   ├── FreePick (primitives/free_pick.rs)            the free module the next query takes
//!     │   │   └── PriorityEncoder
//!     │   ├── LutRam                             query ids
//!     │   ├── SearchModule (datapath/search_module.rs)
//!     │   │   ├── DistModule (datapath/dist_module.rs)       with the paper's AxisDistModule
//!     │   │   └── NextIndexModule (datapath/next_index.rs)
//!     │   └── ResultReadout (modules/result_readout.rs)  the result stream's sequencer
//!     │       ├── PriorityEncoder                the lowest finished query
//!     │       └── ResultRegister (primitives/register_slice.rs)  skid buffer on the result stream
//!     └── BarrelPort (barrel/barrel_port.rs)   `Controller::Barrel`: Q query slots behind one
//!         │                             pipelined datapath
//!         ├── SearchModule                       as above
//!         ├── ReadIssue (store/read_issue.rs)          its reads to the replica or a bank
//!         │   │                                  (wires without banks)
//!         │   ├── ReadPlace (store/read_place.rs)       with external memory: the staged read's
//!         │   │   └── CacheMap (memory/cache_map.rs)    bank and row in the cache
//!         │   ├── OfferQueue (primitives/offer_queue.rs)  with external memory: the offer
//!         │   └── MissPark (store/miss_park.rs)         parks a missed read, retries it
//!         ├── FreePick                           the free slot the next query takes
//!         ├── FoundRule, QueryLimits             as in the QueryModule
//!         ├── SlotStore (barrel/slot_store.rs)          per-slot state in LUT-RAM
//!         ├── FoundMax (barrel/found_max.rs)            K ≤ 64: found distances, comparator tree, §4.4
//!         ├── FoundHeap (barrel/found_heap.rs)          K > 64: per-slot max-heaps in BlockRAM
//!         │   └── HeapStage × levels + 1 (barrel/heap_stage.rs)  one level of insert / replace
//!         ├── FarCellDist                        the far-cell bound, as in CellBound
//!         ├── Ascent (barrel/ascent.rs)                 pruning bounds (LutRam × levels), stage D
//!         ├── BlockRam × 2 (primitives/block_ram.rs)        far cells' offsets
//!         └── SlotReadout (barrel/slot_readout.rs)      found photons, ids, headers (BlockRAM,
//!                                            LUT-RAM) and its read-out sequencer
//! ```
//!
//! A QueryModule issues a read at most every `CoreConfig::issue_interval()` =
//! 8 + distance-bits cycles (the registered grant, grant, BlockRAM, its read-data
//! register, two SearchModule stages, insertion, the MaxFinder's priming cycle and
//! one cycle per distance bit, the R update; 6 + distance bits unpipelined); with Q >= that interval a
//! port reads a photon every cycle while all its QueryModules are busy. Results are
//! bit-identical to `host::map::knn::search_with` (same slots, same number of reads) for
//! the configured [`config::traversal::Traversal`]: by default a QueryModule remembers each
//! level's axis distance on the way down and climbs back up without reads (one
//! level per cycle, no port slot); `Reread` is the paper's ascent, which reads every
//! parent again.
//!
//! The streams are written once ([`top::stream`]); the core and the array share one
//! [`top::dispatcher::Dispatcher`] and one [`top::packet_merge::PacketMerge`]. Running the
//! core lives in [`sim`] and its Verilog in [`export`], which build on these blocks;
//! nothing in the blocks imports them, and nothing in `hw` imports the host.
//! Host-facing API: [`config::core_config::CoreConfig`], [`sim::native::run_gather`],
//! [`export::verilog::export_verilog`]; both tops implement [`sim::top::SearchTop`].
//! The datapath limits (words, distances, H, K, Q, T, banks and result streams)
//! are in [`config::core_config`] and [`config::bank_config`].

pub mod barrel;
pub mod config;
pub mod datapath;
pub mod error;
pub mod export;
pub mod memory;
pub mod modules;
pub mod primitives;
pub mod sim;
pub mod store;
pub mod top;

/// `n` default signals, registers or blocks: a block's `Vec` of sub-blocks built at
/// elaboration (rust-hdl elaborates a `Vec` field element by element).
pub(crate) fn many<T: Default>(n: usize) -> Vec<T> {
    (0..n).map(|_| T::default()).collect()
}
