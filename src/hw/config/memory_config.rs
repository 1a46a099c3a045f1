//! The map in external memory ([`ExternalMemory`], `CoreConfig::memory`): the
//! banked core's levels below its replicas live in DRAM in blocks of
//! [`MEMORY_BLOCK_LEVELS`] levels ([`MemoryLayout`](crate::hw::config::memory_layout::MemoryLayout)),
//! and its banks are the cache of those blocks (`hw::memory`), so the map may be
//! as large as the paper's high-quality regime (§3: 1 M emitted photons, about
//! 1.9 M stored, H = 21) and beyond.

use crate::hw::error::HwError;
use serde::{Deserialize, Serialize};

/// Levels per block, one block per cache line and per burst: the lab's cache
/// model's choice for both modelled memories (the fewest DRAM bytes per query,
/// docs/MEMORY.md "Block levels s").
pub const MEMORY_BLOCK_LEVELS: u32 = 4;

/// H limit of an external-memory core: the core's 24-bit heap addresses, whose
/// descent needs one bit above the map's (the child of a last-level node, §4.3's
/// next-index step), so 23.
pub const MAX_MEMORY_ADDRESS_BITS: u32 = 23;

/// Lines one cache bank holds at most (its valid, filling and used bits are
/// flip-flops, one 256-bit mask each).
pub const MAX_BANK_LINES: usize = 256;

/// Lines of a cache at most: the fills address its words with 16 bits.
pub const MAX_CACHE_LINES: u32 = (1 << 16) >> MEMORY_BLOCK_LEVELS;

/// Cache banks at most: one fill arbiter's requesters.
pub const MAX_CACHE_BANK_BITS: u32 = 5;

/// Cycles a read that missed waits before it is offered again: about one
/// burst's round trip in the modelled memories (their latency and a block's
/// beats, docs/MEMORY.md); earlier costs a bank read that misses again, later
/// costs the slot's wait.
pub const RETRY_CYCLES: u32 = 40;

/// Width of the core's AXI4 read data port (`rdata`): the widest memory data
/// width; a narrower memory uses its low bits (the AXI4-Stream top exposes only
/// those).
pub const MEMORY_PORT_BITS: usize = 64;

/// The memory's data width unless a core names one: the native port of both
/// modelled memories' controllers (docs/MEMORY.md, "Memories modelled":
/// LiteDRAM's 16-bit DDR3 at 1:2 gives 64 bits a controller cycle on the ECP5
/// boards; MIG's 64-bit DDR3 more), so a block of `2^s` narrow photon words
/// comes in half as many beats as one word a beat would take.
pub const DEFAULT_MEMORY_DATA_BITS: u32 = 64;

/// Where each cache bank keeps its lines' tags (the core file's `cache_tags`).
///
/// Why two: a bank's tags are a memory of one entry a line, which yosys puts in
/// BlockRAM from 64 lines a bank up, a DP16KD for each of a bank's two port
/// copies. At K = 500 on the ECP5-85k the heaps leave the cache too few
/// BlockRAMs for that (docs/MEMORY_CORE.md, "What fits"): in LUT-RAM, only as
/// wide as the map's tags, they take none, and the words keep theirs (two
/// DP16KD a copy hold 64 lines a bank as they hold 32).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum CacheTags {
    /// BlockRAM from 64 lines a bank up (LUT-RAM below), 24 bits wide.
    #[default]
    BlockRam,
    /// LUT-RAM at any depth, as wide as the map's largest tag.
    LutRam,
}

impl CacheTags {
    /// Its name in a core file.
    pub fn name(self) -> &'static str {
        match self {
            CacheTags::BlockRam => "block-ram",
            CacheTags::LutRam => "lut-ram",
        }
    }

    /// What a core's description adds for it (nothing for the default, so that
    /// the description of a core with BlockRAM tags reads as before).
    pub fn note(self) -> &'static str {
        match self {
            CacheTags::BlockRam => "",
            CacheTags::LutRam => " (tags in LUT-RAM)",
        }
    }
}

/// The external-memory store: the cache's lines (all banks together, each bank
/// the lines whose index is its own modulo B), the levels per block, the
/// memory's data width (AXI4 `rdata` bits: one or two photon words a beat) and
/// where the tags live.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ExternalMemory {
    pub cache_lines: u32,
    pub block_levels: u32,
    pub data_bits: u32,
    pub tags: CacheTags,
}

impl ExternalMemory {
    /// A cache of `cache_lines` lines of [`MEMORY_BLOCK_LEVELS`]-level blocks,
    /// behind a memory of [`DEFAULT_MEMORY_DATA_BITS`].
    pub fn new(cache_lines: u32) -> Self {
        ExternalMemory {
            cache_lines,
            block_levels: MEMORY_BLOCK_LEVELS,
            data_bits: DEFAULT_MEMORY_DATA_BITS,
            tags: CacheTags::default(),
        }
    }

    /// This cache with its tags in `tags`.
    pub fn with_tags(self, tags: CacheTags) -> Self {
        ExternalMemory { tags, ..self }
    }

    /// This cache behind a memory of `data_bits`-bit beats.
    pub fn with_data_bits(self, data_bits: u32) -> Self {
        ExternalMemory { data_bits, ..self }
    }

    /// Photon words of `word_width` bits (the image's word: 32 or 64) a beat.
    pub fn words_per_beat(self, word_width: usize) -> u32 {
        (self.data_bits / word_width as u32).max(1)
    }

    /// Lines of each of `2^bank_bits` banks.
    pub fn bank_lines(self, bank_bits: u32) -> u32 {
        self.cache_lines >> bank_bits
    }

    /// Check the cache for `2^bank_bits` banks, H = `address_bits` and image
    /// words of `word_width` bits.
    pub fn check(
        self,
        bank_bits: u32,
        address_bits: u32,
        word_width: usize,
    ) -> Result<(), HwError> {
        let fail = |m: String| Err(HwError::Config(m));
        let w = word_width as u32;
        if self.data_bits != w && self.data_bits != 2 * w.min(32) {
            return fail(format!(
                "memory_data_bits = {}: one or two {w}-bit photon words a beat, at most \
                 {MEMORY_PORT_BITS} bits ({})",
                self.data_bits,
                if w < 64 { "32 or 64" } else { "64" }
            ));
        }
        if bank_bits > MAX_CACHE_BANK_BITS {
            return fail(format!(
                "{} banks with cache_lines: the cache has at most {} banks",
                1u64 << bank_bits,
                1u32 << MAX_CACHE_BANK_BITS
            ));
        }
        let per_bank = u64::from(self.cache_lines) >> bank_bits;
        if !self.cache_lines.is_power_of_two() || per_bank == 0 || per_bank > MAX_BANK_LINES as u64
        {
            return fail(format!(
                "cache_lines = {}: a power of two, {}..={} with {} banks (1 to {MAX_BANK_LINES} \
                 lines a bank)",
                self.cache_lines,
                1u64 << bank_bits,
                (MAX_BANK_LINES as u64) << bank_bits,
                1u64 << bank_bits
            ));
        }
        if u64::from(self.cache_lines) << self.block_levels > 1 << 16 {
            return fail(format!(
                "cache_lines = {}: the fills address the cache's words with 16 bits, so at \
                 most {} lines of {} words",
                self.cache_lines,
                (1u64 << 16) >> self.block_levels,
                1u64 << self.block_levels
            ));
        }
        if address_bits > MAX_MEMORY_ADDRESS_BITS {
            return fail(format!(
                "address_bits (H) = {address_bits} with external memory: unsupported \
                 (..={MAX_MEMORY_ADDRESS_BITS}, at most {} photons)",
                (1u64 << MAX_MEMORY_ADDRESS_BITS) - 1
            ));
        }
        Ok(())
    }
}
