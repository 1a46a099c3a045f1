//! Ascent: a [`BarrelPort`](crate::hw::barrel::barrel_port::BarrelPort)'s path memory of
//! pruning bounds and its one-step ascent (stage D).
//!
//! Each level's pruning bound (its far child's split-axis distance, or with
//! `Traversal::Cell` the far cell's distance) is kept per query slot, one LUT-RAM
//! per level, written when the level is read (stage B). When a search turns up, the
//! software search (`knn::search_with`) climbs level by level with R fixed and
//! enters the first pending far child within R (`bound < R` once the list is full,
//! `bound ≤ R` before: the initial radius is inclusive). Here every level is read
//! at once and compared in parallel, so the deepest such level above the node is
//! found in one cycle (`climb`); a QueryModule climbs one level per cycle instead,
//! which in a barrel would cost a pipeline pass per level.
//!
//! The comparisons are made on the low 16 bits when the distances fit them (see
//! [`FoundMax`](crate::hw::barrel::found_max::FoundMax): yosys keeps a comparison as wide
//! as its masked 32-bit operands).

use crate::hw::config::core_config::{CoreConfig, Dist, LevelMask, ModuleIndex};
use crate::hw::primitives::lut_ram::{LutRam, RamIndex};
use rust_hdl::prelude::*;

/// Where the search climbs from a node (stage D): the deepest level above it with
/// a pending far child within R (`target`), if there is one (`found`; none: the
/// query is done). It travels with the event through E and F.
#[derive(Clone, Copy, Debug, PartialEq, Default, LogicStruct)]
pub struct Climb {
    pub target: RamIndex,
    pub found: bool,
}

#[derive(LogicBlock)]
pub struct Ascent {
    pub clock: Signal<In, Clock>,
    /// Remember `write_bound` as the pruning bound of level `write_level` of slot
    /// `write_slot`.
    pub write_enable: Signal<In, bool>,
    pub write_level: Signal<In, RamIndex>,
    pub write_slot: Signal<In, ModuleIndex>,
    pub write_bound: Signal<In, Dist>,
    /// The climb of slot `read_slot` from a node at `level` (asynchronous): its
    /// pending far children, whether its list is full, and R.
    pub read_slot: Signal<In, ModuleIndex>,
    pub level: Signal<In, RamIndex>,
    pub pending: Signal<In, LevelMask>,
    pub full: Signal<In, bool>,
    pub radius: Signal<In, Dist>,
    pub climb: Signal<Out, Climb>,
    bound: Vec<LutRam>,
    level_index: Vec<Constant<RamIndex>>,
    dist_mask: Constant<Dist>,
    /// The distances fit 16 bits: compare the low 16.
    cmp16: Constant<bool>,
    /// Per level: its bound is below R, or at most R.
    below: Vec<Signal<Local, bool>>,
    at_most: Vec<Signal<Local, bool>>,
}

impl Ascent {
    /// For `cfg`'s levels (one per level that can have children), slots and
    /// distance bits.
    pub fn new(cfg: &CoreConfig) -> Self {
        let levels = cfg.path_levels().max(1);
        let db = cfg.dist_bits();
        Ascent {
            clock: Default::default(),
            write_enable: Default::default(),
            write_level: Default::default(),
            write_slot: Default::default(),
            write_bound: Default::default(),
            read_slot: Default::default(),
            level: Default::default(),
            pending: Default::default(),
            full: Default::default(),
            radius: Default::default(),
            climb: Default::default(),
            bound: (0..levels)
                .map(|_| LutRam::new(cfg.queries_per_port, db))
                .collect(),
            level_index: (0..levels)
                .map(|i| Constant::new(RamIndex::from(i as u64)))
                .collect(),
            dist_mask: Constant::new(Dist::from(cfg.dist_mask())),
            cmp16: Constant::new(db <= 16),
            below: (0..levels).map(|_| Default::default()).collect(),
            at_most: (0..levels).map(|_| Default::default()).collect(),
        }
    }
}

impl Logic for Ascent {
    #[hdl_gen]
    fn update(&mut self) {
        self.climb.next.target = 0.into();
        self.climb.next.found = false;
        for l in 0..self.bound.len() {
            self.bound[l].clock.next = self.clock.val();
            self.bound[l].write_enable.next =
                self.write_enable.val() && (self.write_level.val() == self.level_index[l].val());
            self.bound[l].write_index.next = self.write_slot.val();
            self.bound[l].write_data.next = self.write_bound.val() & self.dist_mask.val();
            self.bound[l].read_index.next = self.read_slot.val();
            self.below[l].next =
                (self.bound[l].read_data.val() & self.dist_mask.val()) < self.radius.val();
            self.at_most[l].next =
                (self.bound[l].read_data.val() & self.dist_mask.val()) <= self.radius.val();
            if self.cmp16.val() {
                self.below[l].next = self.bound[l].read_data.val().get_bits::<16>(0)
                    < self.radius.val().get_bits::<16>(0);
                self.at_most[l].next = self.bound[l].read_data.val().get_bits::<16>(0)
                    <= self.radius.val().get_bits::<16>(0);
            }
            // The deepest pending level above the node whose far child is within R
            // (the loop runs from the root down, the last match wins).
            if (self.level_index[l].val() < self.level.val()) && self.pending.val().get_bit(l) {
                if self.full.val() {
                    if self.below[l].val() {
                        self.climb.next.target = self.level_index[l].val();
                        self.climb.next.found = true;
                    }
                } else if self.at_most[l].val() {
                    self.climb.next.target = self.level_index[l].val();
                    self.climb.next.found = true;
                }
            }
        }
    }
}
