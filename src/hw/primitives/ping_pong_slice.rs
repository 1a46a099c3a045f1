//! PingPongSlice: a register slice on a valid/ready stream that behaves cycle for
//! cycle as [`RegisterSlice`](crate::hw::primitives::register_slice::RegisterSlice)
//! does (two beats held, a beat a cycle, `inbound.ready` a flip-flop's), built as
//! a two-entry ping-pong buffer instead of an output and a skid register.
//!
//! Why: in the skid buffer the output register reloads when the downstream takes
//! its beat, so `outbound.ready` is the load enable of every data flip-flop of the
//! slice. Where `ready` arrives late and the payload is wide — an offered read
//! whose `ready` is a bank's grant, at the end of a round trip through the
//! crossbar's arbiters (paper §4.5's port sharing, over banks) — that enable's
//! fanout to every data bit is the end of the critical path. Here a data entry
//! loads only while it is empty, an enable from its own valid flip-flop, and
//! `ready` moves three flip-flops: the taken entry's valid and the read pointer.
//! The price is a two-way multiplexer on the output data, after the flip-flops.

use crate::hw::primitives::stream::{StreamIn, StreamOut};
use rust_hdl::prelude::*;

#[derive(LogicBlock)]
pub struct PingPongSlice<T: Synth> {
    pub clock: Signal<In, Clock>,
    /// Empties both entries.
    pub reset: Signal<In, bool>,
    pub inbound: StreamIn<T>,
    pub outbound: StreamOut<T>,
    /// The two entries: each loads the inbound data whenever it is empty.
    first_valid: DFF<bool>,
    first_data: DFF<T>,
    second_valid: DFF<bool>,
    second_data: DFF<T>,
    /// The entry on offer (the older), and the entry the next beat goes to.
    read_second: DFF<bool>,
    write_second: DFF<bool>,
    /// A beat enters, and the offered beat leaves, this cycle.
    written: Signal<Local, bool>,
    taken: Signal<Local, bool>,
}

impl<T: Synth> PingPongSlice<T> {
    pub fn new() -> Self {
        PingPongSlice {
            clock: Default::default(),
            reset: Default::default(),
            inbound: Default::default(),
            outbound: Default::default(),
            first_valid: Default::default(),
            first_data: Default::default(),
            second_valid: Default::default(),
            second_data: Default::default(),
            read_second: Default::default(),
            write_second: Default::default(),
            written: Default::default(),
            taken: Default::default(),
        }
    }
}

impl<T: Synth> Default for PingPongSlice<T> {
    fn default() -> Self {
        Self::new()
    }
}

impl<T: Synth> Logic for PingPongSlice<T> {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(
            self,
            clock,
            first_valid,
            first_data,
            second_valid,
            second_data,
            read_second,
            write_second
        );
        // Room while either entry is empty: as the skid buffer's ready, a beat
        // can enter in the cycle the older one leaves.
        self.inbound.ready.next = !(self.first_valid.q.val() && self.second_valid.q.val());
        if self.read_second.q.val() {
            self.outbound.valid.next = self.second_valid.q.val();
            self.outbound.data.next = self.second_data.q.val();
        } else {
            self.outbound.valid.next = self.first_valid.q.val();
            self.outbound.data.next = self.first_data.q.val();
        }
        self.written.next = self.inbound.valid.val() && self.inbound.ready.val();
        self.taken.next = self.outbound.valid.val() && self.outbound.ready.val();
        // An empty entry follows the inbound data; it holds once it is valid.
        if !self.first_valid.q.val() {
            self.first_data.d.next = self.inbound.data.val();
        }
        if !self.second_valid.q.val() {
            self.second_data.d.next = self.inbound.data.val();
        }
        if self.written.val() {
            self.write_second.d.next = !self.write_second.q.val();
            if self.write_second.q.val() {
                self.second_valid.d.next = true;
            } else {
                self.first_valid.d.next = true;
            }
        }
        if self.taken.val() {
            self.read_second.d.next = !self.read_second.q.val();
            if self.read_second.q.val() {
                self.second_valid.d.next = false;
            } else {
                self.first_valid.d.next = false;
            }
        }
        if self.reset.val() {
            self.first_valid.d.next = false;
            self.second_valid.d.next = false;
            self.read_second.d.next = false;
            self.write_second.d.next = false;
        }
    }
}
