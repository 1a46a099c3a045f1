//! The devices a plan is for: each one's BlockRAM (count and shapes) and logic,
//! and what a barrel datapath, the crossbar and the external-memory cache cost on
//! it (from the synthesised cores each constant names), and a datapath's own
//! BlockRAMs counted from the core planned.

use crate::hw::barrel::barrel_port::datapath_block_rams;
use crate::hw::config::bank_config::BankPorts;
use crate::hw::config::core_config::CoreConfig;

/// A device's BlockRAM and logic.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Device {
    pub name: &'static str,
    pub brams: u32,
    /// (words, bits) of one BlockRAM port in its widest true-dual-port shape.
    pub shape: (u32, u32),
    /// Logic cells (ECP5 LUT4s, Virtex-6 6-input LUTs).
    pub luts: u32,
    /// (words, bits) of each BlockRAM shape a memory may take, widest first (a
    /// memory takes the shape that needs the fewest: [`Device::brams_for`]).
    pub bram_shapes: &'static [(u32, u32)],
    /// One barrel datapath's own BlockRAMs (far-cell bounds, found lists) at the
    /// default K = 32, for the lab's studies (the product counts its core's:
    /// [`datapath_brams`]), and logic, from the synthesised barrel core
    /// (synth/REPORT.md: 2 datapaths per core).
    pub datapath_brams: u32,
    pub datapath_luts: u32,
    /// The crossbar's logic cells per requester and bank, with shared and with
    /// split bank ports (yosys counts of the crossbar alone, see each device).
    pub crossbar_luts_shared: f64,
    pub crossbar_luts_split: f64,
    /// The external-memory cache's logic cells per line and per cache bank: each
    /// line's valid, filling and used bits are flip-flops beside its bank, with
    /// the logic that reads and updates them, and each bank has its miss register,
    /// tag compare and fill request (`hw::memory::cache_bank`), so the cache costs
    /// logic as well as BlockRAM.
    pub cache_line_luts: f64,
    pub cache_bank_luts: f64,
}

impl Device {
    /// The BlockRAMs of a memory of `2^index_bits` words of `width` bits: the
    /// fewest any one shape takes (yosys picks one shape for a memory); memories
    /// of under 32 words are logic.
    pub fn brams_for(&self, index_bits: u32, width: u32) -> u32 {
        if index_bits < 5 {
            return 0;
        }
        self.bram_shapes
            .iter()
            .map(|&(words, bits)| width.div_ceil(bits) * (1u32 << index_bits).div_ceil(words))
            .min()
            .unwrap_or(0)
    }

    /// The crossbar's logic for `d` requesters on `banks` banks with `ports`
    /// (one port a bank costs what split ports do: one port's arbiter and row
    /// tree over all D, one word input a bank for each requester).
    pub fn crossbar_luts(&self, d: u32, banks: u32, ports: BankPorts) -> u64 {
        let per = match ports {
            BankPorts::Shared => self.crossbar_luts_shared,
            BankPorts::Split | BankPorts::One => self.crossbar_luts_split,
        };
        (per * f64::from(d) * f64::from(banks)).ceil() as u64
    }
}

/// Lattice ECP5-85k: 208 DP16KD of 18 Kbit (widest true-dual-port shape 1K × 18;
/// the 512 × 36 shape is pseudo-dual-port, one read port, which is all a
/// single-ported bank needs; two read ports take two 1K × 18 halves of a word).
/// Barrel datapath at K = 32 (the direct render's k), from the placed banked
/// cores of synth/REPORT.md (B = 16 split, the same map): D = 8 takes 74,674 LUT4s
/// and 200 DP16KD, D = 4 37,940 and 164, so four datapaths cost 36,734 LUT4s less
/// the crossbar's growth (4 × 16 × ECP5_XBAR_SPLIT): about 7,930 each, and 36
/// DP16KD, of which 8 each are its own (a replica's two DP16KD serve two datapaths).
/// Crossbar: ECP5_XBAR.
pub const ECP5_85K: Device = Device {
    name: "ECP5-85k",
    brams: 208,
    shape: (512, 36),
    luts: 83_640,
    bram_shapes: &[
        (512, 36),
        (1024, 18),
        (2048, 9),
        (4096, 4),
        (8192, 2),
        (16384, 1),
    ],
    datapath_brams: 8,
    datapath_luts: 7_930,
    crossbar_luts_shared: ECP5_XBAR_SHARED,
    crossbar_luts_split: ECP5_XBAR_SPLIT,
    cache_line_luts: ECP5_CACHE_LINE,
    cache_bank_luts: ECP5_CACHE_BANK,
};

/// The ECP5 cache's logic: external-memory cores, D = 4 on 16 cache banks,
/// synthesised as the banked rows are (Debian yosys `synth_ecp5` without its
/// share pass) and packed by nextpnr-ecp5. Per line: the difference between 2,048
/// lines (90,558 LUT4s) and 1,024 (77,654), two cores of the same build. Per bank:
/// the 1,024-line core as built now (the 64-bit memory port, the state bits of the
/// lines a bank does not have dropped, registered fill requests: 73,021 LUT4s,
/// synth/REPORT.md's row "external memory D=4, K=32") beyond the banked D = 4 core
/// without a cache (39,471 LUT4s) and beyond its lines. docs/MEMORY_CORE.md
/// ("What fits").
const ECP5_CACHE_LINE: f64 = (90_558.0 - 77_654.0) / 1_024.0;
const ECP5_CACHE_BANK: f64 = (73_021.0 - 39_471.0 - 1_024.0 * ECP5_CACHE_LINE) / 16.0;

/// The ECP5 crossbar per requester and bank: Debian yosys `synth_ecp5` (coarse
/// step without share, as synth/report.py does for banked rows) of the crossbar
/// alone of the D = 8, B = 16 banked core, LUT4s plus two a CCU2C: split ports
/// 9,529 + 2 × 256 = 10,041, shared ports 19,089 + 2 × 256 = 19,601.
const ECP5_XBAR_SPLIT: f64 = 10_041.0 / 128.0;
const ECP5_XBAR_SHARED: f64 = 19_601.0 / 128.0;

/// Xilinx XC6VSX475T: 1,064 RAMB36 (1K × 36). Barrel datapath at K = 32: 3,654
/// LUTs and 254 LUT-RAM primitives of 4 LUTs each, and 4 RAMB36 of its own (yosys
/// counts of one datapath of the D = 32 banked core, synth/REPORT.md).
/// Crossbar (yosys `synth_xilinx -family xc6v` of the crossbar alone, D = 8,
/// B = 32, docs/HARDWARE.md): 16,125 LUTs shared, 6,639 split, per D × B.
pub const XC6VSX475T: Device = Device {
    name: "XC6VSX475T",
    brams: 1_064,
    shape: (1024, 36),
    luts: 297_600,
    bram_shapes: &[
        (512, 72),
        (1024, 36),
        (2048, 18),
        (4096, 9),
        (8192, 4),
        (16384, 2),
        (32768, 1),
    ],
    datapath_brams: 4,
    datapath_luts: 3_654 + 4 * 254,
    crossbar_luts_shared: 16_125.0 / 256.0,
    crossbar_luts_split: 6_639.0 / 256.0,
    // Not synthesised for the Virtex-6: the ECP5's counts of 4-input LUTs, an
    // upper bound for the same logic in 6-input LUTs.
    cache_line_luts: ECP5_CACHE_LINE,
    cache_bank_luts: ECP5_CACHE_BANK,
};

/// One barrel datapath's own BlockRAMs on `dev` for `core` with its map's
/// address bits (the found lists hold photon addresses): its memories as its
/// blocks build them (`datapath_block_rams`: found lists, far-cell bounds, and
/// for K > 64 the heaps' levels), each in the device's fewest BlockRAMs.
pub fn datapath_brams(dev: &Device, core: &CoreConfig) -> u32 {
    datapath_block_rams(core)
        .into_iter()
        .map(|(index_bits, width)| dev.brams_for(index_bits, width))
        .sum()
}
