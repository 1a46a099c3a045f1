//! [`MemoryLayout`]: where each kd-tree node lives once the map is larger than
//! the chip (paper §3: the high-quality regime's 1 M emitted photons, about 1.9 M
//! stored, H = 21, fit no device's BlockRAM). The top `T` levels of the packed
//! tree (heap layout, root 1, node i's children 2i and 2i + 1, §4.1) stay on chip;
//! the levels below are cut into blocks, each a subtree of at most `s` levels
//! stored contiguously in external memory and fetched in one burst, so a descent
//! touches one block per `s` levels (the subtree blocking of QuickNN, Pinkham et
//! al., HPCA 2020, cut at one height because one block is one cache line). The
//! lab's cache model chose `s = 4` (docs/MEMORY.md, `photon-fpga-lab memory`).
//!
//! The bands of `s` levels are aligned to the bottom of the tree: if `H − T` is
//! not a multiple of `s`, the short band is the one just under the on-chip levels,
//! whose blocks are few. Every block takes `2^s` words (a short band's blocks and
//! the one word a full subtree leaves unused), so block `b`'s words start at word
//! `b · 2^s` of the image; inside a block the nodes are in the subtree's own heap
//! order, its root at word 0. The hardware's `hw::memory::block_map` computes the
//! same placement with shifts and one adder per level.

use crate::hw::config::photon_word::TreeImage;
use crate::hw::error::HwError;

/// Where a node lives.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Place {
    /// In the top `T` levels, on chip, at its own heap address.
    OnChip,
    /// In external memory: its block and its word in the block.
    External { block: u32, offset: u32 },
}

/// The split of a tree of `H` levels into `T` on-chip levels and blocks of `s`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct MemoryLayout {
    /// H: the tree's levels (heap addresses below 2^H).
    pub address_bits: u32,
    /// T: levels on chip (addresses below 2^T).
    pub on_chip_levels: u32,
    /// s: levels per block.
    pub block_levels: u32,
    /// Per level below T: the level of its band's root and its band's first block.
    bands: Vec<(u32, u32)>,
}

/// Levels per block at most: a block of 2^s words stays one burst of a few
/// hundred bytes.
pub const MAX_BLOCK_LEVELS: u32 = 8;

impl MemoryLayout {
    /// The layout of a tree of `address_bits` levels, `on_chip_levels` of them on
    /// chip (below H), blocks of `block_levels` (1..=[`MAX_BLOCK_LEVELS`]).
    pub fn new(address_bits: u32, on_chip_levels: u32, block_levels: u32) -> Result<Self, HwError> {
        if !(1..=MAX_BLOCK_LEVELS).contains(&block_levels) {
            return Err(HwError::Config(format!(
                "block_levels = {block_levels}: unsupported (1..={MAX_BLOCK_LEVELS})"
            )));
        }
        if on_chip_levels == 0 || on_chip_levels >= address_bits || address_bits > 30 {
            return Err(HwError::Config(format!(
                "on-chip levels = {on_chip_levels} with H = {address_bits}: the chip keeps at \
                 least the root and leaves levels to memory (1 <= T < H <= 30)"
            )));
        }
        let below = address_bits - on_chip_levels;
        let first = match below % block_levels {
            0 => block_levels,
            r => r,
        };
        let mut bands = Vec::with_capacity(below as usize);
        let (mut root, mut height, mut base) = (on_chip_levels, first, 0u32);
        while root < address_bits {
            for _ in 0..height {
                bands.push((root, base));
            }
            base += 1 << root;
            root += height;
            height = block_levels;
        }
        Ok(MemoryLayout {
            address_bits,
            on_chip_levels,
            block_levels,
            bands,
        })
    }

    /// Words of one block in the image: 2^s.
    pub fn block_words(&self) -> u32 {
        1 << self.block_levels
    }

    /// Blocks of the whole tree.
    pub fn blocks(&self) -> u32 {
        let (root, base) = *self.bands.last().expect("at least one level below T");
        base + (1 << root)
    }

    /// Words of the whole image: every block's.
    pub fn image_words(&self) -> u64 {
        u64::from(self.blocks()) << self.block_levels
    }

    /// Per level below T (level T first): its band's root level and first block.
    pub fn bands(&self) -> &[(u32, u32)] {
        &self.bands
    }

    /// Where heap address `a` (1..2^H) lives.
    pub fn place(&self, a: u32) -> Place {
        let level = 31 - a.leading_zeros();
        if level < self.on_chip_levels {
            return Place::OnChip;
        }
        let (root_level, base) = self.bands[(level - self.on_chip_levels) as usize];
        let depth = level - root_level;
        let root = a >> depth;
        Place::External {
            block: base + (root - (1 << root_level)),
            offset: (1 << depth) + (a & ((1 << depth) - 1)) - 1,
        }
    }

    /// The image word of heap address `a`, if it lives in memory.
    pub fn word_of(&self, a: u32) -> Option<u64> {
        match self.place(a) {
            Place::OnChip => None,
            Place::External { block, offset } => {
                Some((u64::from(block) << self.block_levels) + u64::from(offset))
            }
        }
    }

    /// The external memory's image of `tree` (a tree of at most H levels): word
    /// `b · 2^s + o` holds the node at word `o` of block `b`, and 0 where a block
    /// has no node (beyond the map's N, or the word a full subtree leaves unused).
    /// A loader writes it block after block, in ascending addresses; the on-chip
    /// levels are the tree's words below 2^T, loaded as before.
    pub fn image(&self, tree: TreeImage<'_>) -> Vec<u64> {
        assert!(tree.address_bits() <= self.address_bits, "the map fits H");
        let mut words = vec![0u64; self.image_words() as usize];
        for a in (1usize << self.on_chip_levels)..tree.words.len() {
            if let Some(w) = self.word_of(a as u32) {
                words[w as usize] = tree.words[a];
            }
        }
        words
    }
}
