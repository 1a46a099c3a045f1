//! PathWrite: a barrel datapath's path-memory writes of stage B — the level's
//! pruning bound into the [`Ascent`](crate::hw::barrel::ascent::Ascent), and with
//! `Traversal::Cell` the far cell's offsets into the offsets BlockRAMs — held one
//! cycle, so that they are written in stage C.
//!
//! Why: with `Cell` the bound is the far cell's distance, a sum of squares over
//! the slot's offsets ([`FarCellDist`](crate::hw::datapath::far_cell_dist::FarCellDist)),
//! and written in B it ends at the BlockRAM's data pins, which sit wherever the
//! BlockRAM columns are: once the external-memory core's read issue is staged,
//! that sum and the route to the BlockRAM are one cycle's path. Registered, each
//! is half a cycle. A write a cycle later is still before every read of it: the
//! ascent (D) and the far child's offsets (E) read only levels above the event's
//! own, written by the slot's earlier events, and a slot has one event in flight
//! (paper §4.5: a query's next read waits for its last result).

use crate::hw::config::core_config::{Dist, ModuleIndex};
use crate::hw::primitives::block_ram::{BramIndex, BramWord};
use crate::hw::primitives::lut_ram::RamIndex;
use rust_hdl::prelude::*;

/// One event's path-memory writes.
#[derive(Clone, Copy, Debug, PartialEq, Default, LogicStruct)]
pub struct PathWrites {
    /// The pruning bound of level `level` of slot `slot`.
    pub bound_write: bool,
    pub level: RamIndex,
    pub slot: ModuleIndex,
    pub bound: Dist,
    /// The far cell's offsets (x | y, z | distance) at `far_index`.
    pub far_write: bool,
    pub far_index: BramIndex,
    pub far_xy: BramWord,
    pub far_zd: BramWord,
}

#[derive(LogicBlock, Default)]
pub struct PathWrite {
    pub clock: Signal<In, Clock>,
    /// Stage B's writes (see [`PathWrites`]).
    pub bound_write: Signal<In, bool>,
    pub level: Signal<In, RamIndex>,
    pub slot: Signal<In, ModuleIndex>,
    pub bound: Signal<In, Dist>,
    pub far_write: Signal<In, bool>,
    pub far_index: Signal<In, BramIndex>,
    pub far_xy: Signal<In, BramWord>,
    pub far_zd: Signal<In, BramWord>,
    /// The same writes a cycle later (stage C).
    pub c_bound_write: Signal<Out, bool>,
    pub c_level: Signal<Out, RamIndex>,
    pub c_slot: Signal<Out, ModuleIndex>,
    pub c_bound: Signal<Out, Dist>,
    pub c_far_write: Signal<Out, bool>,
    pub c_far_index: Signal<Out, BramIndex>,
    pub c_far_xy: Signal<Out, BramWord>,
    pub c_far_zd: Signal<Out, BramWord>,
    held: DFF<PathWrites>,
}

impl Logic for PathWrite {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(self, clock, held);
        self.held.d.next.bound_write = self.bound_write.val();
        self.held.d.next.level = self.level.val();
        self.held.d.next.slot = self.slot.val();
        self.held.d.next.bound = self.bound.val();
        self.held.d.next.far_write = self.far_write.val();
        self.held.d.next.far_index = self.far_index.val();
        self.held.d.next.far_xy = self.far_xy.val();
        self.held.d.next.far_zd = self.far_zd.val();
        self.c_bound_write.next = self.held.q.val().bound_write;
        self.c_level.next = self.held.q.val().level;
        self.c_slot.next = self.held.q.val().slot;
        self.c_bound.next = self.held.q.val().bound;
        self.c_far_write.next = self.held.q.val().far_write;
        self.c_far_index.next = self.held.q.val().far_index;
        self.c_far_xy.next = self.held.q.val().far_xy;
        self.c_far_zd.next = self.held.q.val().far_zd;
    }
}
