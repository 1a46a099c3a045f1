//! The photon map in external memory (beyond the paper, whose §3 names larger maps
//! as future work): the top levels stay on chip, the levels below live in DRAM in
//! subtree blocks, one burst each ([`MemoryLayout`](crate::hw::config::memory_layout::MemoryLayout),
//! the lab's cache model, docs/MEMORY.md).
//!
//! * `BlockMap`: a heap address to its block and word (combinational).
//! * `LineFill`: the AXI4 master (`primitives::axi4_read`) that brings blocks into
//!   cache lines, several bursts in flight to cover the memory's latency.

pub mod block_map;
pub mod line_fill;
