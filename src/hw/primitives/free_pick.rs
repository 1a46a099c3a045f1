//! FreePick: which free query of a port takes the next query — a SearchPort's
//! QueryModule or a BarrelPort's slot (paper §4.5: queries are handed to the
//! port's free QueryModules) — picked one cycle ahead into registers.
//!
//! Why registered: the pick drives the port's `query.ready` and the load enable
//! (or the slot index that addresses every state LUT-RAM) of what it picked;
//! combinationally the lowest-free-bit carry chain and the index encoder would sit
//! in front of them, on the path from the queries' state through the core's
//! dispatcher. A free entry stays free until it is loaded, so the registered pick
//! is still free when it is used; the one taken in this cycle is left out of the
//! next pick (`still_free`). Cost: an entry freed in cycle t can take a query in
//! t + 1, not t. Both next picks — with and without the current pick taken — are
//! encoded side by side and `take` selects one: `take` can arrive late (in a
//! banked core it is a bank's grant, at the end of a round trip through the
//! crossbar), and then only a multiplexer stands between it and the registers,
//! not the lowest-bit carry chain.

use crate::hw::config::core_config::{ModuleIndex, ModuleMask};
use crate::hw::primitives::priority_encoder::PriorityEncoder;
use rust_hdl::prelude::*;

#[derive(LogicBlock)]
pub struct FreePick {
    pub clock: Signal<In, Clock>,
    pub reset: Signal<In, bool>,
    /// The free entries, one bit each (only the port's entries set).
    pub free: Signal<In, ModuleMask>,
    /// The pick is taken in this cycle (a query loads into it).
    pub take: Signal<In, bool>,
    /// The free entries but the one taken now: the candidates for the next pick.
    pub still_free: Signal<Out, ModuleMask>,
    /// The pick for this cycle (flip-flops): one-hot (zero: none free), its
    /// index, and whether there is one.
    pub pick: Signal<Out, ModuleMask>,
    pub pick_index: Signal<Out, ModuleIndex>,
    pub pick_valid: Signal<Out, bool>,
    /// The lowest free entry, and the lowest but the current pick.
    lowest_free: PriorityEncoder<32>,
    lowest_rest: PriorityEncoder<32>,
    rest: Signal<Local, ModuleMask>,
    pick_reg: DFF<ModuleMask>,
    pick_index_reg: DFF<ModuleIndex>,
    pick_valid_reg: DFF<bool>,
}

impl FreePick {
    /// A pick among `entries` (1..=32) entries.
    pub fn new(entries: usize) -> Self {
        FreePick {
            clock: Default::default(),
            reset: Default::default(),
            free: Default::default(),
            take: Default::default(),
            still_free: Default::default(),
            pick: Default::default(),
            pick_index: Default::default(),
            pick_valid: Default::default(),
            lowest_free: PriorityEncoder::lowest(entries),
            lowest_rest: PriorityEncoder::lowest(entries),
            rest: Default::default(),
            pick_reg: Default::default(),
            pick_index_reg: Default::default(),
            pick_valid_reg: Default::default(),
        }
    }
}

impl Logic for FreePick {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(self, clock, pick_reg, pick_index_reg, pick_valid_reg);
        self.rest.next = self.free.val() & (!self.pick_reg.q.val());
        self.lowest_free.mask.next = self.free.val();
        self.lowest_rest.mask.next = self.rest.val();
        self.still_free.next = self.free.val();
        self.pick_reg.d.next = self.lowest_free.lowest.val();
        self.pick_index_reg.d.next = self.lowest_free.index.val();
        self.pick_valid_reg.d.next = self.free.val().any();
        if self.take.val() {
            self.still_free.next = self.rest.val();
            self.pick_reg.d.next = self.lowest_rest.lowest.val();
            self.pick_index_reg.d.next = self.lowest_rest.index.val();
            self.pick_valid_reg.d.next = self.rest.val().any();
        }
        if self.reset.val() {
            self.pick_reg.d.next = 0.into();
            self.pick_valid_reg.d.next = false;
        }
        self.pick.next = self.pick_reg.q.val();
        self.pick_index.next = self.pick_index_reg.q.val();
        self.pick_valid.next = self.pick_valid_reg.q.val();
    }
}
