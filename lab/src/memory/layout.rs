//! Where each kd-tree node lives once the map is larger than the chip: the top T
//! levels of the packed tree (heap layout, root 1, node i's children 2i and 2i + 1,
//! paper §4.1) stay on chip, and the levels below are cut into blocks, each a
//! subtree of `s` levels (2^s − 1 nodes) stored contiguously in external memory and
//! fetched in one burst. A descent then touches one block per `s` levels instead of
//! one DRAM row per node: the subtree blocking of QuickNN (Pinkham et al., HPCA
//! 2020, tree top on chip and buckets fetched from DRAM in bursts) and of the
//! van Emde Boas layout (Prokop, MIT 1999; Brodal et al., SODA 2002), cut at one
//! fixed height because one block is one cache line.
//!
//! The bands of `s` levels are aligned to the bottom of the tree (the deepest band
//! ends at the last level): if `H − T` is not a multiple of `s`, the short band is
//! the one just under the on-chip levels, whose 2^T blocks are few, rather than the
//! deepest one, whose blocks are most of the map. Every block has the same size
//! (a short band's blocks leave words unused), so a block's memory address is its
//! id × the block's bytes. Inside a block the words are in the subtree's own heap
//! order (its root first), so the word of a node is found with shifts alone.

/// The heap level of address `a` (the root, 1, is level 0).
#[inline]
pub fn level(a: u32) -> u32 {
    31 - a.leading_zeros()
}

/// Where a node lives.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Place {
    /// In the top levels on chip (read without the cache).
    OnChip,
    /// In external memory: its block and its word within the block.
    External { block: u32, offset: u32 },
}

/// The split of a tree of `levels` levels into on-chip levels and blocks.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BlockLayout {
    /// H: the tree's levels (heap addresses below 2^H).
    pub levels: u32,
    /// T: levels kept on chip (addresses below 2^T).
    pub on_chip: u32,
    /// s: levels per block.
    pub block_levels: u32,
    /// Bytes of one photon word in memory (4 for the paper's 32-bit word).
    pub word_bytes: u32,
    /// The memory's burst in bytes: a block is a whole number of bursts.
    pub burst_bytes: u32,
}

impl BlockLayout {
    /// The layout of a tree with `levels` levels.
    pub fn new(levels: u32, on_chip: u32, block_levels: u32, word_bytes: u32, burst: u32) -> Self {
        assert!(block_levels >= 1 && levels <= 31 && word_bytes >= 1 && burst >= 1);
        BlockLayout {
            levels,
            on_chip: on_chip.min(levels),
            block_levels,
            word_bytes,
            burst_bytes: burst,
        }
    }

    /// Levels of the short band just under the on-chip levels (`s` if none is short).
    fn first_band(&self) -> u32 {
        let below = self.levels - self.on_chip;
        match below % self.block_levels {
            0 => self.block_levels.min(below.max(1)),
            r => r,
        }
    }

    /// The band of a level at or below T: (its root level, its levels, its first
    /// block id).
    fn band_of(&self, lvl: u32) -> (u32, u32, u32) {
        let t = self.on_chip;
        let h0 = self.first_band();
        if lvl < t + h0 {
            return (t, h0, 0);
        }
        let j = (lvl - t - h0) / self.block_levels;
        let root = t + h0 + j * self.block_levels;
        // Blocks of the bands above: 2^T for the first, then 2^(root level) each.
        let mut base = 1u32 << t;
        let mut r = t + h0;
        while r < root {
            base += 1 << r;
            r += self.block_levels;
        }
        (root, self.block_levels, base)
    }

    /// Where heap address `a` (1..2^H) lives.
    #[inline]
    pub fn place(&self, a: u32) -> Place {
        let lvl = level(a);
        if lvl < self.on_chip {
            return Place::OnChip;
        }
        let (root_level, _, base) = self.band_of(lvl);
        let depth = lvl - root_level;
        let root = a >> depth;
        let local = (1u32 << depth) | (a & ((1u32 << depth) - 1));
        Place::External {
            block: base + (root - (1 << root_level)),
            offset: local - 1,
        }
    }

    /// The heap address stored at word `offset` of `block`, if that slot holds a
    /// node of a tree of H levels (the inverse of [`place`](Self::place)).
    pub fn address(&self, block: u32, offset: u32) -> Option<u32> {
        if block >= self.blocks() {
            return None;
        }
        // Find the band: walk the bands' first block ids.
        let t = self.on_chip;
        let (mut root_level, mut height, mut base) = (t, self.first_band(), 0u32);
        loop {
            let count = 1u32 << root_level;
            if block < base + count {
                break;
            }
            base += count;
            root_level += height;
            height = self.block_levels;
        }
        let local = offset + 1;
        let depth = level(local);
        if depth >= height || root_level + depth >= self.levels {
            return None;
        }
        let root = (1u32 << root_level) + (block - base);
        Some((root << depth) | (local - (1 << depth)))
    }

    /// Blocks of the whole layout (every band of a full tree of H levels).
    pub fn blocks(&self) -> u32 {
        if self.on_chip >= self.levels {
            return 0;
        }
        let (mut n, mut r) = (1u32 << self.on_chip, self.on_chip + self.first_band());
        while r < self.levels {
            n += 1 << r;
            r += self.block_levels;
        }
        n
    }

    /// Words of one block: 2^s − 1 nodes.
    pub fn block_words(&self) -> u32 {
        (1 << self.block_levels) - 1
    }

    /// Bytes one block takes in memory and on the bus: its nodes' words, rounded up
    /// to whole bursts.
    pub fn block_bytes(&self) -> u32 {
        (self.block_words() * self.word_bytes).div_ceil(self.burst_bytes) * self.burst_bytes
    }

    /// The memory's bytes for the whole map in this layout.
    pub fn memory_bytes(&self) -> u64 {
        u64::from(self.blocks()) * u64::from(self.block_bytes())
    }

    /// The byte address of `a` in memory (None on chip).
    pub fn byte_address(&self, a: u32) -> Option<u64> {
        match self.place(a) {
            Place::OnChip => None,
            Place::External { block, offset } => Some(
                u64::from(block) * u64::from(self.block_bytes())
                    + u64::from(offset) * u64::from(self.word_bytes),
            ),
        }
    }
}
