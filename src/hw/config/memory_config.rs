//! The map in external memory ([`ExternalMemory`], `CoreConfig::memory`): the
//! banked core's levels below its replicas live in DRAM in blocks of
//! [`MEMORY_BLOCK_LEVELS`] levels ([`MemoryLayout`](crate::hw::config::memory_layout::MemoryLayout)),
//! and its banks are the cache of those blocks (`hw::memory`), so the map may be
//! as large as the paper's high-quality regime (§3: 1 M emitted photons, about
//! 1.9 M stored, H = 21) and beyond.

use crate::hw::error::HwError;

/// Levels per block, one block per cache line and per burst: the lab's cache
/// model's choice for both modelled memories (the fewest DRAM bytes per query,
/// docs/MEMORY.md "Block levels s").
pub const MEMORY_BLOCK_LEVELS: u32 = 4;

/// H limit of an external-memory core: the core's 24-bit heap addresses.
pub const MAX_MEMORY_ADDRESS_BITS: u32 = 24;

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

/// The external-memory store: the cache's lines (all banks together, each bank
/// the lines whose index is its own modulo B) and the levels per block.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ExternalMemory {
    pub cache_lines: u32,
    pub block_levels: u32,
}

impl ExternalMemory {
    /// A cache of `cache_lines` lines of [`MEMORY_BLOCK_LEVELS`]-level blocks.
    pub fn new(cache_lines: u32) -> Self {
        ExternalMemory {
            cache_lines,
            block_levels: MEMORY_BLOCK_LEVELS,
        }
    }

    /// Lines of each of `2^bank_bits` banks.
    pub fn bank_lines(self, bank_bits: u32) -> u32 {
        self.cache_lines >> bank_bits
    }

    /// Check the cache for `2^bank_bits` banks and H = `address_bits`.
    pub fn check(self, bank_bits: u32, address_bits: u32) -> Result<(), HwError> {
        let fail = |m: String| Err(HwError::Config(m));
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
