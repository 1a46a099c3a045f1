//! BlockMap: where a heap address of the external-memory store lives, in gates:
//! on chip (the top `T` levels), or its word in the external memory's image,
//! block · 2^s + offset ([`MemoryLayout`], whose placement this is, and whose
//! docs say why subtree blocks). A level's nodes all sit at the same depth of a
//! band of blocks, so per level the block is the address shifted right by that
//! depth plus a constant, and the offset the address's low bits plus a constant:
//! one comparator pair, one shifter and two adders per level below T, the level
//! picked by the address's range. Combinational.

use crate::hw::config::core_config::Addr;
use crate::hw::config::memory_layout::MemoryLayout;
use rust_hdl::prelude::*;

/// A word address of the external memory's image (in photon words).
pub type MemoryWord = Bits<32>;

#[derive(LogicBlock)]
pub struct BlockMap {
    /// A heap address (1-based).
    pub address: Signal<In, Addr>,
    /// The node is on chip (its address there is `address`).
    pub on_chip: Signal<Out, bool>,
    /// Its word in the image, for a node in memory.
    pub word: Signal<Out, MemoryWord>,
    /// Its block (the cache line it is fetched with) and the word in it.
    pub block: Signal<Out, MemoryWord>,
    pub offset: Signal<Out, Bits<8>>,
    /// 2^T, s, and per level below T: its first address, its shift (depth in its
    /// band), the block's constant term and the offset's mask and constant.
    first_external: Constant<Addr>,
    block_shift: Constant<MemoryWord>,
    level_start: Vec<Constant<Addr>>,
    depth: Vec<Constant<Addr>>,
    block_base: Vec<Constant<Addr>>,
    offset_mask: Vec<Constant<Addr>>,
    offset_base: Vec<Constant<Addr>>,
    /// The block and the offset, at the address's width.
    block_at: Signal<Local, Addr>,
    offset_at: Signal<Local, Addr>,
}

impl BlockMap {
    /// The placement of `layout` (H up to 24, the core's address width, so that
    /// every block index fits it too).
    pub fn new(layout: &MemoryLayout) -> Self {
        assert!(layout.address_bits <= 24, "addresses of at most 24 bits");
        let t = layout.on_chip_levels;
        let (mut start, mut depth, mut base, mut mask, mut off) =
            (vec![], vec![], vec![], vec![], vec![]);
        for (i, &(root, first)) in layout.bands().iter().enumerate() {
            let level = t + i as u32;
            let d = level - root;
            start.push(Constant::new(Addr::from(1u64 << level)));
            depth.push(Constant::new(Addr::from(u64::from(d))));
            // block = first + (a >> d) − 2^root (the subtree root's index in its level).
            base.push(Constant::new(Addr::from(
                u64::from(first).wrapping_sub(1u64 << root) & 0xff_ffff,
            )));
            // offset = 2^d + (a mod 2^d) − 1 (the node's heap index in its block, from 0).
            mask.push(Constant::new(Addr::from((1u64 << d) - 1)));
            off.push(Constant::new(Addr::from((1u64 << d) - 1)));
        }
        BlockMap {
            address: Default::default(),
            on_chip: Default::default(),
            word: Default::default(),
            block: Default::default(),
            offset: Default::default(),
            first_external: Constant::new(Addr::from(1u64 << t)),
            block_shift: Constant::new(MemoryWord::from(u64::from(layout.block_levels))),
            level_start: start,
            depth,
            block_base: base,
            offset_mask: mask,
            offset_base: off,
            block_at: Default::default(),
            offset_at: Default::default(),
        }
    }
}

impl Logic for BlockMap {
    #[hdl_gen]
    fn update(&mut self) {
        self.on_chip.next = self.address.val() < self.first_external.val();
        self.block_at.next = 0.into();
        self.offset_at.next = 0.into();
        // The deepest level whose first address the address reaches is its level.
        for l in 0..self.level_start.len() {
            if self.address.val() >= self.level_start[l].val() {
                self.block_at.next =
                    (self.address.val() >> self.depth[l].val()) + self.block_base[l].val();
                self.offset_at.next =
                    (self.address.val() & self.offset_mask[l].val()) + self.offset_base[l].val();
            }
        }
        self.block.next = bit_cast::<32, 24>(self.block_at.val());
        self.offset.next = bit_cast::<8, 24>(self.offset_at.val());
        self.word.next =
            (self.block.val() << self.block_shift.val()) + bit_cast::<32, 8>(self.offset.val());
    }
}
