//! The banked photon store, measured in software: one kd-tree spread over many
//! BlockRAM banks and shared by D barrel datapaths, so that maps far larger than
//! one BlockRAM copy per core are searched at many reads per cycle. The read stream is the software search's, which the barrel datapath
//! matches read for read; a cycle model of D datapaths × B banks replays it under
//! each bank mapping and query order (`photon-fpga-lab banking` writes the numbers to
//! docs/BANKING.md, every number with where it comes from).
//!
//! * `stream`: the Cornell image's queries and the addresses each one reads.
//! * `order`: query orders (raster, tile, Morton, Hilbert, shuffled).
//! * `mapping`: the replicated top levels and the node → bank mappings.
//! * `sim`: the cycle model (slots, slot loop, per-bank round robin).
//! * `sweep`: the measured points; `report`: docs/BANKING.md.
//! * `rtl_sweep`: the banked core itself, simulated (every answer checked), and
//!   `rtl_report` its tables and plots (`photon-fpga-lab bench-banks`).
//! * `host::device::plan`: B, L, D from the map size and the device.
//!
//! # The mapping chosen, by the numbers (docs/BANKING.md)
//! * **Replicate the top levels.** Every query reads the root and the levels under
//!   it, so their banks are the busiest: with no replica (L = 0) the busiest bank
//!   takes 1.48 × the mean bank's reads and D = 16 datapaths on 64 banks read 0.892
//!   photons per cycle each, against 1.02 × and 0.912 with L = 10 (QuickNN, Pinkham
//!   et al., HPCA 2020, keeps its tree nodes beside every query engine for the same
//!   reason). One BlockRAM of replica per datapath holds L = 9 (ECP5) or 10
//!   (Virtex-6) levels.
//! * **XOR-fold below them.** The four bijective mappings (modulo, XOR-fold,
//!   level-skewed, hash) read within 0.003 photons per cycle of each other in every
//!   query order: what costs is two datapaths meeting at one bank in one cycle,
//!   which any mapping that spreads neighbouring nodes does alike. XOR-fold has the
//!   best or equal-best mean over the orders in each table and the most even bank
//!   load (busiest bank 1.02 × the mean, modulo 1.10); it is an XOR of the address's
//!   `b`-bit groups, its row the address's high bits (no table). A subtree per bank
//!   loses up to 12 % under a coherent query order: neighbouring queries then
//!   descend the same subtree, so they queue at the same bank.
//! * **Order.** Coherence does not help the banks: a coherent order (tile, Morton,
//!   Hilbert) sends several datapaths down the same path at once and costs up to
//!   1 % against the renderer's raster order, and a shuffled order reads about 2 %
//!   more than raster. Coherent orders are for a cache (Heinzle et al., Graphics
//!   Hardware 2008; Steinhurst et al., TVCG 2008), which this store does not have.
//! * **Banks per datapath.** B = 4 × D reads 0.91–0.92 photons per cycle per
//!   datapath for D = 8 to 32 (0.8 needs B >= 2 × D); a second read port per bank
//!   (the BlockRAMs are dual-ported) lifts D = 16 on 64 banks from 0.91 to 0.99.
//!   [`plan`](photon_fpga::host::device::plan::plan) asks for B >= 4 × D.

pub mod mapping;
pub mod order;
pub mod report;
pub mod rtl_report;
pub mod rtl_sweep;
pub mod sim;
pub mod stream;
pub mod sweep;
