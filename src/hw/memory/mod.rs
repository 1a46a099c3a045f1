//! The photon map in external memory (beyond the paper, whose §3 names larger maps
//! as future work): the top levels stay on chip, the levels below live in DRAM in
//! subtree blocks, one burst each ([`MemoryLayout`](crate::hw::config::memory_layout::MemoryLayout),
//! the lab's cache model, docs/MEMORY.md).
//!
//! * `BlockMap`: a heap address to its block and word (combinational).
//! * `CacheBank`: one bank of the direct-mapped cache: a bank's read port with a
//!   miss flag, the line's tag and valid bit, a miss's fill request.
//! * `LineFill`: the AXI4 master (`primitives::axi4_read`) that brings blocks into
//!   cache lines, several bursts in flight to cover the memory's latency.
//!
//! # How the blocks join the banked core (the next step)
//! The external-memory core is the banked core (`store::bank_store`) with its
//! banks turned into the cache, so that the datapaths, the replicas (the `T`
//! on-chip levels) and the crossbar stay as they are:
//! * **Where a read goes.** Below the replica, a node's block (`BlockMap`) picks
//!   its line (block mod lines: direct-mapped, the lab's choice) and the line its
//!   bank (line mod B: the cache banked by block id); the bank row is the line in
//!   the bank and the word in the block, and the block's tag (block / lines) rides
//!   in the row's high bits, which a BlockRAM bank ignores.
//! * **A miss.** A `CacheBank` reads the word and the line's tag together and
//!   answers the word with a miss flag above it, and asks `LineFill` for the
//!   block unless the line is already being filled (built and tested). To do:
//!   `ReadIssue`, one stage before the SearchModule takes the word, drops a
//!   missed read and parks its slot (its context stays in the slot's LUT-RAM
//!   entries); a filled line wakes the parked slots, which offer their reads
//!   again, while the other slots go on, as on a busy bank.
//! * **The memory port.** One `LineFill` for all banks, its AXI4 master the core's
//!   `m_axi_*` port; the host loads the on-chip levels through the photon stream
//!   and the blocks into memory as `MemoryLayout::image` lays them out.

pub mod block_map;
pub mod cache_bank;
pub mod cache_map;
pub mod cache_port;
pub mod line_fill;
