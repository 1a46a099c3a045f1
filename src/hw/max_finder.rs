//! MaxFinder (paper §4.4): the found-distance list stored bit-transposed, and the
//! search for its maximum in one cycle per distance bit, independent of K.
//!
//! Row n holds bit n of every list entry (one bit per slot). Starting from a filter
//! with a one for every candidate slot, each row from the MSB down is ANDed with the
//! filter; if the AND is non-zero it becomes the filter and bit n of the maximum is 1
//! (the OR of the AND). After the last row the filter marks the slots holding the
//! maximum and a priority encoder picks the LOWEST of them: the replacement rule of
//! the software search (knn.rs, "the lowest list slot among ties").
//!
//! Slots are addressed one-hot throughout (write slot, read slot, max slot), which is
//! what the filter naturally is.
//!
//! `S` is the width of the slot masks (32 or 64, see `CoreConfig::slot_bits`): a
//! const generic because rust-hdl's `Bits` width must be a constant.

use crate::hw::config::{Dist, SlotMask};
use rust_hdl::prelude::*;

#[derive(LogicBlock)]
pub struct MaxFinder<const S: usize> {
    pub clock: Signal<In, Clock>,
    /// Store `write_dist` into the slot `write_slot` (one-hot) at the clock edge.
    pub write_enable: Signal<In, bool>,
    pub write_slot: Signal<In, SlotMask<S>>,
    pub write_dist: Signal<In, Dist>,
    /// Start a search over the slots set in `candidates`; may coincide with a write
    /// (the rows are read from the next cycle on).
    pub start: Signal<In, bool>,
    pub candidates: Signal<In, SlotMask<S>>,
    /// Column read-out of one slot (one-hot), combinational.
    pub read_slot: Signal<In, SlotMask<S>>,
    pub read_dist: Signal<Out, Dist>,
    /// High from the cycle after `start` for one cycle per distance bit.
    pub busy: Signal<Out, bool>,
    /// Valid when not busy after a search: the maximum, the slots holding it and the
    /// lowest of them (one-hot).
    pub max_dist: Signal<Out, Dist>,
    pub filter: Signal<Out, SlotMask<S>>,
    pub max_slot: Signal<Out, SlotMask<S>>,
    /// rows[n] = bit n of every slot's distance.
    rows: Vec<DFF<SlotMask<S>>>,
    filter_reg: DFF<SlotMask<S>>,
    /// One-hot: the row being examined, which is also its weight in the maximum.
    row_select: DFF<Dist>,
    max_reg: DFF<Dist>,
    busy_reg: DFF<bool>,
    top_row: Constant<Dist>,
    /// The K slots that exist: the other row bits are constant zero, so synthesis
    /// drops them (the slot masks are S bits wide).
    slot_mask: Constant<SlotMask<S>>,
    slot_write: Signal<Local, SlotMask<S>>,
    current_row: Signal<Local, SlotMask<S>>,
    row_and_filter: Signal<Local, SlotMask<S>>,
}

impl<const S: usize> MaxFinder<S> {
    /// A MaxFinder over `slots` (1..=S) distances of `dist_bits` bits.
    pub fn new(dist_bits: u32, slots: usize) -> Self {
        assert!((1..=32).contains(&dist_bits));
        assert!((1..=S).contains(&slots));
        MaxFinder {
            clock: Default::default(),
            write_enable: Default::default(),
            write_slot: Default::default(),
            write_dist: Default::default(),
            start: Default::default(),
            candidates: Default::default(),
            read_slot: Default::default(),
            read_dist: Default::default(),
            busy: Default::default(),
            max_dist: Default::default(),
            filter: Default::default(),
            max_slot: Default::default(),
            rows: (0..dist_bits).map(|_| DFF::default()).collect(),
            filter_reg: Default::default(),
            row_select: Default::default(),
            max_reg: Default::default(),
            busy_reg: Default::default(),
            top_row: Constant::new(Dist::from(1u64 << (dist_bits - 1))),
            slot_mask: Constant::new(SlotMask::<S>::from(u64::MAX >> (64 - slots))),
            slot_write: Default::default(),
            current_row: Default::default(),
            row_and_filter: Default::default(),
        }
    }
}

impl<const S: usize> Logic for MaxFinder<S> {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(self, clock, filter_reg, row_select, max_reg, busy_reg);
        for n in 0..self.rows.len() {
            self.rows[n].clock.next = self.clock.val();
            self.rows[n].d.next = self.rows[n].q.val();
        }
        // Write one slot: bit n of the distance goes to row n.
        self.slot_write.next = self.write_slot.val() & self.slot_mask.val();
        if self.write_enable.val() {
            for n in 0..self.rows.len() {
                if self.write_dist.val().get_bit(n) {
                    self.rows[n].d.next = self.rows[n].q.val() | self.slot_write.val();
                } else {
                    self.rows[n].d.next = self.rows[n].q.val() & (!self.slot_write.val());
                }
            }
        }
        // The row under examination, and its AND with the filter.
        // (Gated by busy: the mux output is only used while busy; this also keeps
        // the Rust simulation from evaluating it in idle QueryModules.)
        self.current_row.next = 0.into();
        if self.busy_reg.q.val() {
            for n in 0..self.rows.len() {
                if self.row_select.q.val().get_bit(n) {
                    self.current_row.next = self.current_row.val() | self.rows[n].q.val();
                }
            }
        }
        self.row_and_filter.next = self.current_row.val() & self.filter_reg.q.val();
        if self.start.val() {
            self.filter_reg.d.next = self.candidates.val() & self.slot_mask.val();
            self.row_select.d.next = self.top_row.val();
            self.max_reg.d.next = 0.into();
            self.busy_reg.d.next = true;
        } else if self.busy_reg.q.val() {
            if self.row_and_filter.val().any() {
                self.filter_reg.d.next = self.row_and_filter.val();
                self.max_reg.d.next = self.max_reg.q.val() | self.row_select.q.val();
            }
            self.row_select.d.next = self.row_select.q.val() >> 1;
            if self.row_select.q.val().get_bit(0) {
                self.busy_reg.d.next = false;
            }
        }
        self.busy.next = self.busy_reg.q.val();
        self.max_dist.next = self.max_reg.q.val();
        self.filter.next = self.filter_reg.q.val();
        // Priority encoder: isolate the lowest set bit of the filter.
        self.max_slot.next = self.filter_reg.q.val() & ((!self.filter_reg.q.val()) + 1);
        // Column read-out.
        self.read_dist.next = 0.into();
        if self.read_slot.val().any() {
            for n in 0..self.rows.len() {
                self.read_dist.next = self
                    .read_dist
                    .val()
                    .replace_bit(n, (self.rows[n].q.val() & self.read_slot.val()).any());
            }
        }
    }
}
