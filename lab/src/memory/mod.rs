//! The photon map in external memory behind an on-chip cache, modelled in software
//! before it is built (issue 52): the paper's high-quality regime (§3: at least 1 M
//! emitted photons, about 1.9 M stored in the Cornell box, H = 21) does not fit any
//! device's BlockRAM, so the top levels stay on chip and the rest lives in DRAM in
//! burst-sized subtree blocks behind a cache (QuickNN, Pinkham et al., HPCA 2020;
//! Heinzle et al., Graphics Hardware 2008, a neighbour cache for coherent queries;
//! Steinhurst et al., TVCG 2008, photon-map traffic under coherent query orders).
//! `photon-fpga-lab memory` writes the numbers to docs/MEMORY.md, every one modelled
//! and labelled with its source.
//!
//! * `layout`: node address → on chip, or (block, offset) in memory.
//! * `cache`: set-associative / fully associative, LRU / FIFO.
//! * `trace`: the functional model (hit rates, bytes per query) on the interleaved
//!   read streams of `banking::stream`, in `banking::order`'s query orders.
//! * `sim`: the cycle model with a cache and a memory (latency, bandwidth, bursts in
//!   flight), extending `banking::sim`'s datapaths and slots.
//! * `memories`: the DDR3 of an ECP5-85k board (LiteDRAM) and of the Virtex-6
//!   ML605 (MIG), and each device's BlockRAM left for the cache.
//! * `sweep`: the streams and the parallel runs; `report` and `timing`:
//!   docs/MEMORY.md.
//!
//! # The choice, and why (the numbers: docs/MEMORY.md, `photon-fpga-lab memory`)
//! CHOICE
pub mod cache;
pub mod layout;
pub mod memories;
pub mod report;
pub mod sim;
pub mod sweep;
pub mod timing;
pub mod trace;
