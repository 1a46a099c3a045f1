//! MaxFinder (paper §4.4): the found-distance list stored bit-transposed, and the
//! search for its maximum in one cycle per distance bit, independent of K.
//!
//! Row n is bit n of every list entry (one bit per slot). Starting from a filter
//! with a one for every candidate slot, each row from the MSB down is ANDed with the
//! filter; if the AND is non-zero it becomes the filter and bit n of the maximum is 1
//! (the OR of the AND). After the last row the filter marks the slots holding the
//! maximum and a [`PriorityEncoder`] picks the LOWEST of them: the replacement rule
//! of the software search (knn.rs, "the lowest list slot among ties").
//!
//! Where the bits live: the K × B bits are the paper's, but each slot's entry is
//! one register and a row is gathered across them: bit `gather_bit` of every slot,
//! a B-to-1 multiplexer per slot with a binary select (about half the LUTs of a
//! one-hot AND-OR over the B bits). Stored as rows, a write touches bit s of every
//! row, a LUT per bit (keep, set or clear); stored as slots, a write is the clock
//! enable of one slot's register with the distance on its D inputs, no LUT at all.
//! The list is not read out here: the QueryModule keeps a LUT-RAM copy of the
//! distances for its result stream, which costs less than a K-way read-out mux.
//!
//! The row under examination is gathered into a register the cycle before it is
//! examined (gathering a row, ANDing it with the filter, testing for any bit and
//! updating the filter would otherwise be one long path). The search therefore starts with
//! one priming cycle that gathers the top row, from the slots as they are after the
//! write that may coincide with `start`: `busy` lasts one cycle per distance bit
//! plus one. (Gathering the top row in the `start` cycle itself, with the written
//! slot's bit taken from the write port, costs more LUTs per QueryModule: the
//! select of every slot's row multiplexer then depends on `start`.)
//!
//! Slots are addressed one-hot throughout (write slot, max slot), which is what the
//! filter naturally is.
//!
//! `S` is the width of the slot masks (32 or 64, see `CoreConfig::slot_bits`): a
//! const generic because rust-hdl's `Bits` width must be a constant.

use crate::hw::config::core_config::{bits_for, low_mask, Dist, SlotMask};
use crate::hw::primitives::priority_encoder::PriorityEncoder;
use rust_hdl::prelude::*;

/// Index of a row (a distance bit).
pub type RowIndex = Bits<5>;

#[derive(LogicBlock)]
pub struct MaxFinder<const S: usize> {
    pub clock: Signal<In, Clock>,
    /// Store `write_dist` into the slot `write_slot` (one-hot) at the clock edge.
    pub write_enable: Signal<In, bool>,
    pub write_slot: Signal<In, SlotMask<S>>,
    pub write_dist: Signal<In, Dist>,
    /// Start a search; may coincide with a write (the rows are read from the next
    /// cycle on). Not while `busy`.
    pub start: Signal<In, bool>,
    /// The slots that take part, read in the cycle after `start` (the priming
    /// cycle: a slot appended with `start` is then already in the caller's mask).
    pub candidates: Signal<In, SlotMask<S>>,
    /// High from the cycle after `start` for one cycle per distance bit, plus one.
    pub busy: Signal<Out, bool>,
    /// Valid when not busy after a search: the maximum, the slots holding it and the
    /// lowest of them (one-hot).
    pub max_dist: Signal<Out, Dist>,
    pub filter: Signal<Out, SlotMask<S>>,
    pub max_slot: Signal<Out, SlotMask<S>>,
    /// slots[s] = the distance in slot s (K of them; row n is bit n of each).
    slots: Vec<DFF<Dist>>,
    filter_reg: DFF<SlotMask<S>>,
    /// The row gathered in this cycle (examined in the next), as a bit index.
    gather_bit: DFF<RowIndex>,
    /// The row examined in this cycle and its weight in the maximum (one-hot).
    row_reg: DFF<SlotMask<S>>,
    weight: DFF<Dist>,
    /// The priming cycle after `start`: a row is gathered, none examined.
    priming: DFF<bool>,
    max_reg: DFF<Dist>,
    busy_reg: DFF<bool>,
    top_row: Constant<Dist>,
    top_bit: Constant<RowIndex>,
    /// The bits a row index needs: the others stay constant zero.
    row_index_mask: Constant<RowIndex>,
    /// The K slots that exist: the other row bits are constant zero, so synthesis
    /// drops them (the slot masks are S bits wide).
    slot_mask: Constant<SlotMask<S>>,
    /// The distance bits: the others of each slot are constant zero.
    dist_mask: Constant<Dist>,
    /// The lowest slot of the filter.
    lowest_max: PriorityEncoder<S>,
    gathered: Signal<Local, SlotMask<S>>,
    row_and_filter: Signal<Local, SlotMask<S>>,
    /// The top row's weight in the priming cycle, else zero.
    priming_weight: Signal<Local, Dist>,
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
            busy: Default::default(),
            max_dist: Default::default(),
            filter: Default::default(),
            max_slot: Default::default(),
            slots: (0..slots).map(|_| DFF::default()).collect(),
            filter_reg: Default::default(),
            gather_bit: Default::default(),
            row_reg: Default::default(),
            weight: Default::default(),
            priming: Default::default(),
            max_reg: Default::default(),
            busy_reg: Default::default(),
            top_row: Constant::new(Dist::from(1u64 << (dist_bits - 1))),
            top_bit: Constant::new(RowIndex::from((dist_bits - 1) as u64)),
            row_index_mask: Constant::new(RowIndex::from(low_mask(bits_for(
                (dist_bits - 1) as u64,
            )))),
            slot_mask: Constant::new(SlotMask::<S>::from(u64::MAX >> (64 - slots))),
            dist_mask: Constant::new(Dist::from(u64::MAX >> (64 - dist_bits))),
            lowest_max: PriorityEncoder::lowest(slots),
            gathered: Default::default(),
            row_and_filter: Default::default(),
            priming_weight: Default::default(),
        }
    }
}

impl<const S: usize> Logic for MaxFinder<S> {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(
            self, clock, filter_reg, gather_bit, row_reg, weight, priming, max_reg, busy_reg
        );
        // Write one slot: its register's clock enable.
        for s in 0..self.slots.len() {
            self.slots[s].clock.next = self.clock.val();
            self.slots[s].d.next = self.slots[s].q.val();
            if self.write_enable.val() && self.write_slot.val().get_bit(s) {
                self.slots[s].d.next = self.write_dist.val() & self.dist_mask.val();
            }
        }
        // Gather row `gather_bit` across the slots: a multiplexer per slot with a
        // binary select. (Only while busy: this also keeps the Rust simulation
        // from evaluating it in idle QueryModules.)
        self.gathered.next = 0.into();
        if self.busy_reg.q.val() {
            for s in 0..self.slots.len() {
                self.gathered.next = self.gathered.val().replace_bit(
                    s,
                    self.slots[s]
                        .q
                        .val()
                        .get_bit(self.gather_bit.q.val().index()),
                );
            }
        }
        self.row_and_filter.next = self.row_reg.q.val() & self.filter_reg.q.val();
        self.priming_weight.next = 0.into();
        if self.priming.q.val() {
            self.priming_weight.next = self.top_row.val();
        }
        // `start` reaches neither the row register nor the filter (in their clock
        // enables, S bits wide, `start`, the end of the QueryModule's insertion,
        // would lengthen the insertion's path): the busy registers do not depend on it (`start` never comes while busy: the
        // QueryModule waits in MAX_FIND), and the filter is loaded from
        // `candidates` in the priming cycle. The clears at `start` are the
        // flip-flops' synchronous resets, no LUT (clearing `max_reg` in the priming
        // cycle instead costs LUTs in every QueryModule).
        if self.busy_reg.q.val() {
            // The gathered row is examined in the next cycle.
            self.row_reg.d.next = self.gathered.val();
            // The weight of the row gathered now, one-hot, from the top row down:
            // a shift whose top bit comes from `priming` (the weight is zero then),
            // so no multiplexer.
            self.weight.d.next = (self.weight.q.val() >> 1) | self.priming_weight.val();
            self.gather_bit.d.next = (self.gather_bit.q.val() - 1) & self.row_index_mask.val();
            self.priming.d.next = false;
            if self.priming.q.val() {
                self.filter_reg.d.next = self.candidates.val() & self.slot_mask.val();
            } else {
                if self.row_and_filter.val().any() {
                    self.filter_reg.d.next = self.row_and_filter.val();
                    self.max_reg.d.next = self.max_reg.q.val() | self.weight.q.val();
                }
                if self.weight.q.val().get_bit(0) {
                    self.busy_reg.d.next = false;
                }
            }
        }
        // Last, so that only these registers see `start` (as their synchronous set
        // or reset).
        if self.start.val() {
            self.gather_bit.d.next = self.top_bit.val();
            self.weight.d.next = 0.into();
            self.priming.d.next = true;
            self.max_reg.d.next = 0.into();
            self.busy_reg.d.next = true;
        }
        self.busy.next = self.busy_reg.q.val();
        self.max_dist.next = self.max_reg.q.val();
        self.filter.next = self.filter_reg.q.val();
        // The lowest slot holding the maximum.
        self.lowest_max.mask.next = self.filter_reg.q.val();
        self.max_slot.next = self.lowest_max.lowest.val();
    }
}
