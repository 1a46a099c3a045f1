//! ReadPlace: where the external-memory core's next read lives in the cache, for
//! its offer (`ReadIssue` with `CoreConfig::memory`): the read as the read issue's
//! stage registered it (slot and address) in, the same read with its place from a
//! [`CacheMap`] (the replica, or a cache bank and row) out. Combinational: it sits
//! between the stage's register and the offer's, so the placement's compare,
//! shift and adders have a cycle of their own.

use crate::hw::config::core_config::{Addr, ModuleIndex};
use crate::hw::config::memory_layout::MemoryLayout;
use crate::hw::memory::cache_map::CacheMap;
use crate::hw::primitives::bank_bus::{BankIndex, BankRow};
use rust_hdl::prelude::*;

/// A read on offer: its slot, heap address, and where it lives (the replica, or
/// a bank and row).
#[derive(Clone, Copy, Debug, PartialEq, Default, LogicStruct)]
pub struct OfferedRead {
    pub slot: ModuleIndex,
    pub address: Addr,
    pub replica: bool,
    pub bank: BankIndex,
    pub row: BankRow,
}

#[derive(LogicBlock)]
pub struct ReadPlace {
    /// The registered read: its slot and address (the rest is ignored).
    pub read: Signal<In, OfferedRead>,
    /// The read with its place in the cache.
    pub placed: Signal<Out, OfferedRead>,
    map: CacheMap,
}

impl ReadPlace {
    /// The placement of `layout` over `2^bank_bits` cache banks.
    pub fn new(layout: &MemoryLayout, bank_bits: u32) -> Self {
        ReadPlace {
            read: Default::default(),
            placed: Default::default(),
            map: CacheMap::new(layout, bank_bits),
        }
    }
}

impl Logic for ReadPlace {
    #[hdl_gen]
    fn update(&mut self) {
        self.map.address.next = self.read.val().address;
        self.placed.next.slot = self.read.val().slot;
        self.placed.next.address = self.read.val().address;
        self.placed.next.replica = self.map.replicated.val();
        self.placed.next.bank = self.map.bank.val();
        self.placed.next.row = self.map.row.val();
    }
}
