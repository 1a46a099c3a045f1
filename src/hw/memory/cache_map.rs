//! CacheMap: where a read of the external-memory core goes, as
//! [`BankMap`](crate::hw::store::bank_map::BankMap) says it for the on-chip banked
//! store: a node of the top `T` levels is in the datapath's replica; a node below
//! is word `offset` of its block ([`BlockMap`]), which lives in cache line
//! `block mod lines` (direct-mapped, docs/MEMORY.md) of bank `block mod B`, at
//! row `(block / B) · 2^s + offset`: the block's tag, its line in the bank and
//! the word in the block, the row a [`CacheBank`](crate::hw::memory::cache_bank::CacheBank)
//! reads. Combinational.

use crate::hw::config::core_config::Addr;
use crate::hw::config::memory_layout::MemoryLayout;
use crate::hw::memory::block_map::BlockMap;
use crate::hw::primitives::bank_bus::{BankIndex, BankRow};
use rust_hdl::prelude::*;

#[derive(LogicBlock)]
pub struct CacheMap {
    /// A heap address (1-based).
    pub address: Signal<In, Addr>,
    /// The node is in the replica (its row there is `address`).
    pub replicated: Signal<Out, bool>,
    /// Its cache bank and the row there, for a node in memory.
    pub bank: Signal<Out, BankIndex>,
    pub row: Signal<Out, BankRow>,
    /// `b`, `s` and the mask of a block's bank.
    bank_bits: Constant<Addr>,
    block_levels: Constant<Addr>,
    bank_mask: Constant<Addr>,
    blocks: BlockMap,
    block: Signal<Local, Addr>,
}

impl CacheMap {
    /// The placement of `layout` over `2^bank_bits` cache banks.
    pub fn new(layout: &MemoryLayout, bank_bits: u32) -> Self {
        CacheMap {
            address: Default::default(),
            replicated: Default::default(),
            bank: Default::default(),
            row: Default::default(),
            bank_bits: Constant::new(Addr::from(u64::from(bank_bits))),
            block_levels: Constant::new(Addr::from(u64::from(layout.block_levels))),
            bank_mask: Constant::new(Addr::from((1u64 << bank_bits) - 1)),
            blocks: BlockMap::new(layout),
            block: Default::default(),
        }
    }
}

impl Logic for CacheMap {
    #[hdl_gen]
    fn update(&mut self) {
        self.blocks.address.next = self.address.val();
        self.replicated.next = self.blocks.on_chip.val();
        self.block.next = bit_cast::<24, 32>(self.blocks.block.val());
        self.bank.next = bit_cast::<12, 24>(self.block.val() & self.bank_mask.val());
        self.row.next = ((self.block.val() >> self.bank_bits.val()) << self.block_levels.val())
            | bit_cast::<24, 8>(self.blocks.offset.val());
    }
}
