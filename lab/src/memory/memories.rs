//! The external memories modelled and what BlockRAM each device leaves for the
//! cache. Every figure is labelled: "from" a named source (a board's LiteX target, a
//! PHY's source, a data sheet) or "assumed" (a reasoned guess, to be replaced by the
//! measurement of the external-memory core against its memory model).

use super::layout::BlockLayout;
use photon_fpga::host::device::plan::{Device, ECP5_85K, XC6VSX475T};

/// One external memory, its figures in the core's clock cycles.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Memory {
    pub name: &'static str,
    /// The device whose BlockRAM holds the cache in front of it.
    pub device: &'static Device,
    /// The core's clock (the memory controller's user clock, or the clock its
    /// figures are converted to), MHz.
    pub clock_mhz: f64,
    /// Peak bytes per core cycle on the controller's user port.
    pub peak_bytes_per_cycle: f64,
    /// Share of the peak a stream of random one-block reads sustains.
    pub efficiency: f64,
    /// Bytes of one DRAM burst (BL8 × the data width): a block is whole bursts.
    pub burst_bytes: u32,
    /// Read latency in core cycles, request to data.
    pub latency: u64,
    /// The datapaths the device holds beside the cache (`device::plan`'s
    /// minimum on the ECP5-85k; assumed on the XC6VSX475T).
    pub datapaths: usize,
    /// Levels of the replica beside each datapath (one BlockRAM deep: 2^L − 1 ≤
    /// the BlockRAM's words, as `device::plan` takes them).
    pub replica_levels: u32,
    /// Where each figure comes from.
    pub source: &'static str,
}

impl Memory {
    /// Sustained bytes per core cycle (peak × efficiency).
    pub fn bytes_per_cycle(&self) -> f64 {
        self.peak_bytes_per_cycle * self.efficiency
    }
}

/// An ECP5-85k board's 16-bit DDR3 through LiteDRAM.
pub const ECP5_DDR3: Memory = Memory {
    name: "ECP5-85k + 16-bit DDR3 (LiteDRAM)",
    device: &ECP5_85K,
    clock_mhz: 75.0,
    peak_bytes_per_cycle: 8.0,
    efficiency: 0.8,
    burst_bytes: 16,
    latency: 22,
    datapaths: 4,
    replica_levels: 9,
    source: "board: LambdaConcept ECPIX-5 (LFE5UM5G-85F, one 16-bit MT41K256M16 DDR3), \
             LiteX target litex-boards `ecpix5.py`: sys clock 75 MHz, `ECP5DDRPHY` at 1:2 \
             (the Lattice Versa ECP5 target, `lattice_versa_ecp5.py`, is the same with a \
             MT41K64M16). From litedram `phy/ecp5ddrphy.py`: 2 phases × 2 beats × 16 bits \
             = 8 bytes per 75 MHz cycle peak (600 MB/s), a BL8 burst is 16 bytes, the \
             PHY's read latency is ceil(CL/2) + 10 = 13 cycles at CL = 6 (`common.py`'s \
             CL below DDR3-800). Assumed: 9 more cycles for LiteDRAM's crossbar, bank \
             machine and command multiplexer and a row miss's precharge and activate \
             (tRP = tRCD = 13.1 ns, one cycle each at 75 MHz), so 22 cycles; 80 % of the \
             peak sustained on read-only random bursts (no bus turnaround; refresh and \
             row misses); the core runs on the controller's 75 MHz clock",
};

/// The ML605's 64-bit DDR3 SO-DIMM through MIG, taken as the XC6VSX475T's memory.
pub const V6_DDR3: Memory = Memory {
    name: "XC6VSX475T + 64-bit DDR3 (MIG, ML605's)",
    device: &XC6VSX475T,
    clock_mhz: 100.0,
    peak_bytes_per_cycle: 64.0,
    efficiency: 0.8,
    burst_bytes: 64,
    latency: 24,
    datapaths: 16,
    replica_levels: 10,
    source: "board: Xilinx ML605 (its FPGA is an XC6VLX240T; its memory is taken as an \
             XC6VSX475T board's, as issue 52 asks for a Virtex-6 board's DDR3): one 64-bit \
             DDR3 SO-DIMM, MIG for Virtex-6 at 400 MHz (DDR3-800; Xilinx DS186 gives 400 \
             MHz for DDR3 in a -1 part), 6.4 GB/s peak, a BL8 burst 64 bytes. Assumed: \
             the core at 100 MHz behind MIG's 200 MHz user interface (64 bytes per core \
             cycle peak), 24 core cycles (240 ns) from request to data (MIG's user \
             interface, controller and PHY pipeline, CL 6, a row miss's precharge and \
             activate, the clock-domain FIFOs), 80 % of the peak sustained, D = 16 \
             datapaths (XC6VSX475T logic for up to 38 at 60 % of its LUTs, \
             `device::plan`'s datapath cost)",
};

pub const MEMORIES: [&Memory; 2] = [&ECP5_DDR3, &V6_DDR3];

/// BlockRAMs `caches` caches of `lines` lines each take on `dev` (data: a block's
/// words, one 32-bit word a BlockRAM row, since a read takes one node; tags: one
/// row a line, tag and state fit 36 bits).
pub fn cache_brams(dev: &Device, layout: &BlockLayout, lines: usize, caches: usize) -> u32 {
    let depth = dev.shape.0 as usize;
    let words = layout.block_bytes() as usize / layout.word_bytes as usize;
    let data = (lines * words).div_ceil(depth);
    let tags = lines.div_ceil(depth);
    ((data + tags) * caches) as u32
}

/// BlockRAMs left for the cache on `m`'s device: all but the datapaths' own
/// (`datapath_brams` each) and their replicas of the top levels (one BlockRAM
/// each, as `device::plan` counts them), and the on-chip levels below the
/// replica (`on_chip` > replica: the banked store of those levels).
pub fn cache_budget(m: &Memory, on_chip: u32) -> u32 {
    let dev = m.device;
    let per_dp = 1 + dev.datapath_brams;
    let extra_levels = if on_chip > m.replica_levels {
        let words = (1u64 << on_chip) - (1u64 << m.replica_levels);
        words.div_ceil(u64::from(dev.shape.0)) as u32
    } else {
        0
    };
    dev.brams
        .saturating_sub(per_dp * m.datapaths as u32)
        .saturating_sub(extra_levels)
}

/// The most lines (a power of two) `caches` caches can hold in `budget` BlockRAMs
/// on `m`'s device, in total.
pub fn lines_in_budget(m: &Memory, layout: &BlockLayout, caches: usize, budget: u32) -> usize {
    let mut lines = caches.next_power_of_two();
    while cache_brams(m.device, layout, 2 * lines / caches, caches) <= budget {
        lines *= 2;
    }
    lines
}
