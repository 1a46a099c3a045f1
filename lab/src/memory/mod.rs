//! The photon map in external memory behind an on-chip cache, modelled in software
//! before it is built: the paper's high-quality regime (§3: at least 1 M emitted
//! photons, about 1.9 M stored in the Cornell box, H = 21) does not fit any
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
//! The rules that pick each item are in the report (`report`, `timing`), applied to
//! the measured tables, so the report says what the numbers chose; at the paper's
//! regime (1 M emitted, 1.9 M photons, H = 21, the default 256 × 256 image, k = 32
//! and 500) they choose:
//! * **Layout: the replica's levels on chip (T = 9 on the ECP5-85k, 10 on the
//!   XC6VSX475T), blocks of s = 4 levels below** (15 nodes, 64 bytes: four 16-byte
//!   DDR3 bursts on the ECP5 board, one 64-byte burst on the ML605). Smaller blocks
//!   miss once per 2 or 3 levels and waste the 64-byte burst; larger ones fetch
//!   words the search never reads, so the bytes per query stop falling at s = 4.
//!   Deeper on-chip levels in the same BlockRAM take lines from the cache and save
//!   under 5 % of the traffic, not worth a banked store and its crossbar.
//! * **Line = one block; direct-mapped.** A coherent stream's working set is small
//!   beside the device's budget (4 K lines on the ECP5-85k, 32 K on the
//!   XC6VSX475T), so 2, 4, 8 ways or full associativity, LRU or FIFO, gain under
//!   half a point of hit rate; a direct-mapped cache has no replacement state.
//! * **One cache shared by all datapaths**, banked by block id like the on-chip
//!   store: a cache per datapath pair holds the same blocks again in each pair
//!   and moves several times the DRAM bytes, the more so the more pairs.
//! * **Query order: Hilbert** (Steinhurst et al., TVCG 2008): Morton is as good;
//!   the renderer's raster order is nearly as good at k = 32, but at k = 500
//!   Hilbert moves far fewer bytes; a shuffled stream moves many times more.
//! * **S = 16 slots per datapath**, the barrel's own: at these hit rates
//!   L + m × Lm is about one slot loop, and the cycle model keeps each datapath
//!   reading nearly every cycle on both memories; the latency table says how many
//!   a slower memory needs.
//!
//! Not modelled: the shared cache's bank conflicts (docs/BANKING.md measures those
//! of the same crossbar), DRAM row hits and refresh beyond the assumed efficiency,
//! and writes (the map is loaded once).
pub mod cache;
pub mod core_report;
pub mod core_sweep;
pub mod layout;
pub mod memories;
pub mod report;
pub mod sim;
pub mod sweep;
pub mod timing;
pub mod trace;
