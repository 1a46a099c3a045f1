//! OfferQueue: three entries offering beats to a taker that says a cycle late
//! whether it took one (a [`BankCrossbar`](crate::hw::store::bank_crossbar::BankCrossbar)
//! with a registered `ready`: paper §4.5's port sharing, over banks across the
//! chip).
//!
//! Why: with a same-cycle `ready` the offer, the taker's arbitration and the
//! grant's way back to the offer's registers are one cycle that crosses the chip
//! twice. Here `taken` (high: the beat offered in the previous cycle was taken)
//! arrives from the taker's register and only clears that entry's valid bit; the
//! offer for the next cycle is chosen from the entries' state and registered.
//!
//! An entry offered in one cycle waits for its verdict in the next, so the queue
//! offers another entry then: the oldest (in the order the beats came in) that is
//! valid and not waiting. A refused beat is offered again when its turn comes.
//! Three entries keep one beat a cycle going out while one waits for its verdict
//! and another is on offer, with `inbound.ready` from flip-flops (an entry empty);
//! an empty entry loads the inbound data, so `taken` enables no data register.
//! Beats leave in order unless one is refused.
//!
//! A refused beat is thus offered at most every other cycle, which a round robin
//! over three or more takers' requesters can pass over forever. Built
//! [`OfferQueue::persistent`], the queue offers a beat refused once in every
//! cycle from its next offer until it is taken, the other entries waiting; the
//! taker must then ignore a beat offered again in the cycle after it took it
//! (`BankCrossbar::masks_repeats`).

use crate::hw::primitives::stream::StreamIn;
use rust_hdl::prelude::*;

#[derive(LogicBlock)]
pub struct OfferQueue<T: Synth> {
    pub clock: Signal<In, Clock>,
    /// Empties every entry and withdraws the offer.
    pub reset: Signal<In, bool>,
    /// Beats in; `ready` while an entry is empty (from the valid flip-flops).
    pub inbound: StreamIn<T>,
    /// This cycle's offer: its valid bit and the offered entry's beat.
    pub offer_valid: Signal<Out, bool>,
    pub offer: Signal<Out, T>,
    /// The beat offered in the previous cycle was taken.
    pub taken: Signal<In, bool>,
    /// The three entries; an empty one follows the inbound data.
    a_valid: DFF<bool>,
    a_data: DFF<T>,
    b_valid: DFF<bool>,
    b_data: DFF<T>,
    c_valid: DFF<bool>,
    c_data: DFF<T>,
    /// Which entry's beat came in first (meaningful between valid entries).
    a_before_b: DFF<bool>,
    a_before_c: DFF<bool>,
    b_before_c: DFF<bool>,
    /// The entry on offer (one-hot; none while `offering` is low), and the one
    /// offered in the previous cycle, whose verdict `taken` is. `offering` is
    /// the OR of the three, kept as its own flip-flop so that the offer's valid
    /// bit reaches the crossbar from a register, not through a gate.
    offering: DFF<bool>,
    on_a: DFF<bool>,
    on_b: DFF<bool>,
    on_c: DFF<bool>,
    was_a: DFF<bool>,
    was_b: DFF<bool>,
    was_c: DFF<bool>,
    /// Built persistent (none otherwise), per entry: its beat was refused.
    refused_a: Vec<DFF<bool>>,
    refused_b: Vec<DFF<bool>>,
    refused_c: Vec<DFF<bool>>,
    /// A beat comes in this cycle, into the lowest empty entry.
    written: Signal<Local, bool>,
    into_a: Signal<Local, bool>,
    into_b: Signal<Local, bool>,
    into_c: Signal<Local, bool>,
    /// The entries in the next cycle: valid, the order, and those that may be
    /// offered then (valid, and not on offer now).
    next_a: Signal<Local, bool>,
    next_b: Signal<Local, bool>,
    next_c: Signal<Local, bool>,
    next_a_before_b: Signal<Local, bool>,
    next_a_before_c: Signal<Local, bool>,
    next_b_before_c: Signal<Local, bool>,
    free_a: Signal<Local, bool>,
    free_b: Signal<Local, bool>,
    free_c: Signal<Local, bool>,
}

impl<T: Synth> OfferQueue<T> {
    pub fn new() -> Self {
        Self::build(false)
    }

    /// A queue that offers a beat refused once in every cycle until it is taken.
    pub fn persistent() -> Self {
        Self::build(true)
    }

    fn build(persistent: bool) -> Self {
        let p = usize::from(persistent);
        OfferQueue {
            clock: Default::default(),
            reset: Default::default(),
            inbound: Default::default(),
            offer_valid: Default::default(),
            offer: Default::default(),
            taken: Default::default(),
            a_valid: Default::default(),
            a_data: Default::default(),
            b_valid: Default::default(),
            b_data: Default::default(),
            c_valid: Default::default(),
            c_data: Default::default(),
            a_before_b: Default::default(),
            a_before_c: Default::default(),
            b_before_c: Default::default(),
            offering: Default::default(),
            on_a: Default::default(),
            on_b: Default::default(),
            on_c: Default::default(),
            was_a: Default::default(),
            was_b: Default::default(),
            was_c: Default::default(),
            written: Default::default(),
            into_a: Default::default(),
            into_b: Default::default(),
            into_c: Default::default(),
            next_a: Default::default(),
            next_b: Default::default(),
            next_c: Default::default(),
            next_a_before_b: Default::default(),
            next_a_before_c: Default::default(),
            next_b_before_c: Default::default(),
            free_a: Default::default(),
            free_b: Default::default(),
            free_c: Default::default(),
            refused_a: (0..p).map(|_| Default::default()).collect(),
            refused_b: (0..p).map(|_| Default::default()).collect(),
            refused_c: (0..p).map(|_| Default::default()).collect(),
        }
    }
}

impl<T: Synth> Default for OfferQueue<T> {
    fn default() -> Self {
        Self::new()
    }
}

impl<T: Synth> Logic for OfferQueue<T> {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(
            self, clock, a_valid, a_data, b_valid, b_data, c_valid, c_data, a_before_b, a_before_c,
            b_before_c, offering, on_a, on_b, on_c, was_a, was_b, was_c
        );
        // The offer, from flip-flops through one multiplexer.
        self.offer_valid.next = self.offering.q.val();
        if self.on_a.q.val() {
            self.offer.next = self.a_data.q.val();
        } else if self.on_b.q.val() {
            self.offer.next = self.b_data.q.val();
        } else {
            self.offer.next = self.c_data.q.val();
        }
        // A beat comes into the lowest empty entry; an empty entry follows the
        // inbound data, so the one written holds it from the next cycle.
        self.inbound.ready.next =
            !(self.a_valid.q.val() && self.b_valid.q.val() && self.c_valid.q.val());
        self.written.next = self.inbound.valid.val() && self.inbound.ready.val();
        self.into_a.next = self.written.val() && !self.a_valid.q.val();
        self.into_b.next = self.written.val() && self.a_valid.q.val() && !self.b_valid.q.val();
        self.into_c.next = self.written.val() && self.a_valid.q.val() && self.b_valid.q.val();
        if !self.a_valid.q.val() {
            self.a_data.d.next = self.inbound.data.val();
        }
        if !self.b_valid.q.val() {
            self.b_data.d.next = self.inbound.data.val();
        }
        if !self.c_valid.q.val() {
            self.c_data.d.next = self.inbound.data.val();
        }
        // The entry offered last cycle leaves if it was taken.
        self.next_a.next = (self.a_valid.q.val() && !(self.taken.val() && self.was_a.q.val()))
            || self.into_a.val();
        self.next_b.next = (self.b_valid.q.val() && !(self.taken.val() && self.was_b.q.val()))
            || self.into_b.val();
        self.next_c.next = (self.c_valid.q.val() && !(self.taken.val() && self.was_c.q.val()))
            || self.into_c.val();
        // A beat written now comes after every beat already in.
        self.next_a_before_b.next = self.a_before_b.q.val();
        self.next_a_before_c.next = self.a_before_c.q.val();
        self.next_b_before_c.next = self.b_before_c.q.val();
        if self.into_a.val() {
            self.next_a_before_b.next = false;
            self.next_a_before_c.next = false;
        }
        if self.into_b.val() {
            self.next_a_before_b.next = true;
            self.next_b_before_c.next = false;
        }
        if self.into_c.val() {
            self.next_a_before_c.next = true;
            self.next_b_before_c.next = true;
        }
        // The next offer: the oldest entry valid then and not on offer now
        // (that one waits for its verdict).
        self.free_a.next = self.next_a.val() && !self.on_a.q.val();
        self.free_b.next = self.next_b.val() && !self.on_b.q.val();
        self.free_c.next = self.next_c.val() && !self.on_c.q.val();
        self.on_a.d.next = self.free_a.val()
            && (!self.free_b.val() || self.next_a_before_b.val())
            && (!self.free_c.val() || self.next_a_before_c.val());
        self.on_b.d.next = self.free_b.val()
            && (!self.free_a.val() || !self.next_a_before_b.val())
            && (!self.free_c.val() || self.next_b_before_c.val());
        self.on_c.d.next = self.free_c.val()
            && (!self.free_a.val() || !self.next_a_before_c.val())
            && (!self.free_b.val() || !self.next_b_before_c.val());
        self.offering.d.next = self.free_a.val() || self.free_b.val() || self.free_c.val();
        // Persistent: an entry refused once and on offer now stays on offer
        // while it stays in.
        for p in 0..self.refused_a.len() {
            self.refused_a[p].clock.next = self.clock.val();
            self.refused_b[p].clock.next = self.clock.val();
            self.refused_c[p].clock.next = self.clock.val();
            self.refused_a[p].d.next = (self.refused_a[p].q.val()
                || (self.was_a.q.val() && self.a_valid.q.val() && !self.taken.val()))
                && !self.into_a.val();
            self.refused_b[p].d.next = (self.refused_b[p].q.val()
                || (self.was_b.q.val() && self.b_valid.q.val() && !self.taken.val()))
                && !self.into_b.val();
            self.refused_c[p].d.next = (self.refused_c[p].q.val()
                || (self.was_c.q.val() && self.c_valid.q.val() && !self.taken.val()))
                && !self.into_c.val();
            if (self.on_a.q.val() && self.refused_a[p].q.val() && self.next_a.val())
                || (self.on_b.q.val() && self.refused_b[p].q.val() && self.next_b.val())
                || (self.on_c.q.val() && self.refused_c[p].q.val() && self.next_c.val())
            {
                self.on_a.d.next = self.on_a.q.val();
                self.on_b.d.next = self.on_b.q.val();
                self.on_c.d.next = self.on_c.q.val();
                self.offering.d.next = true;
            }
            if self.reset.val() {
                self.refused_a[p].d.next = false;
                self.refused_b[p].d.next = false;
                self.refused_c[p].d.next = false;
            }
        }
        self.was_a.d.next = self.on_a.q.val();
        self.was_b.d.next = self.on_b.q.val();
        self.was_c.d.next = self.on_c.q.val();
        self.a_valid.d.next = self.next_a.val();
        self.b_valid.d.next = self.next_b.val();
        self.c_valid.d.next = self.next_c.val();
        self.a_before_b.d.next = self.next_a_before_b.val();
        self.a_before_c.d.next = self.next_a_before_c.val();
        self.b_before_c.d.next = self.next_b_before_c.val();
        if self.reset.val() {
            self.a_valid.d.next = false;
            self.b_valid.d.next = false;
            self.c_valid.d.next = false;
            self.offering.d.next = false;
            self.on_a.d.next = false;
            self.on_b.d.next = false;
            self.on_c.d.next = false;
            self.was_a.d.next = false;
            self.was_b.d.next = false;
            self.was_c.d.next = false;
        }
    }
}
