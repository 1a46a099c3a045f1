//! The photon map in external memory (beyond the paper, whose §3 names larger maps
//! as future work): the top levels stay on chip, the levels below live in DRAM in
//! subtree blocks, one burst each ([`MemoryLayout`](crate::hw::config::memory_layout::MemoryLayout),
//! the lab's cache model, docs/MEMORY.md).
//!
//! * `BlockMap`: a heap address to its block and word (combinational).
//! * `CacheMap`: a read's place in the cache: the replica, or a bank and row
//!   (block mod B, `(block / B) · 2^s + offset`), as `BankMap` is for banks.
//! * `CacheBank`: one bank of the direct-mapped cache: a bank's read ports with a
//!   miss flag above the word, the lines' tags and valid bits, a miss's fill request.
//! * `FillArbiter`: the banks' fill requests in round robin, registered on both
//!   sides and between (a request from a bank's register, the pick into one, the
//!   chosen bank's block into a third).
//! * `LineFill`: the AXI4 master (`primitives::axi4_read`) that brings blocks into
//!   cache lines, up to 16 bursts in flight to cover the memory's latency.
//!
//! # How they make the external-memory core (`CoreConfig::memory`)
//! The banked core (`store::bank_store`) with its banks turned into the cache, so
//! that the datapaths, the replicas (the `T` on-chip levels) and the crossbar stay
//! as they are:
//! * **Where a read goes.** `ReadIssue` places each read with a `CacheMap` instead
//!   of a `BankMap`; the crossbar carries one more bit of answer, the miss flag.
//! * **A miss.** A `CacheBank` answers with the flag set and asks for the block
//!   unless its line is already being filled; `store::miss_park`, between the
//!   answer and the SearchModule, drops the read and parks its slot (its context
//!   stays in the slot's LUT-RAM entries), and offers it again after
//!   `RETRY_CYCLES`, while the other slots go on, as on a busy bank.
//! * **The memory port.** One `LineFill` for all banks, the banks' requests in
//!   round robin (`FillArbiter`); its AXI4 master is the core's `m_axi` port. The host writes the
//!   map's image (`MemoryLayout::image`) into the memory and streams the on-chip
//!   levels and the last word (the photon count) through the load stream.

pub mod block_map;
pub mod cache_bank;
pub mod cache_map;
pub mod cache_port;
pub mod fill_arbiter;
pub mod line_fill;
