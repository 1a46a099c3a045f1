//! RegisterSlice: a register slice on a valid/ready stream of any payload — the skid
//! buffer of verilog-axis' `axis_register` (REG_TYPE = 2); `bypass` makes it wires
//! (REG_TYPE = 0). The core uses it on each SearchPort's result stream
//! ([`ResultRegister`]).
//!
//! Why: without it, the read-out path runs from the read-out sequencer's registers
//! through the found-list mux of the selected QueryModule, the OR of all Q modules'
//! outputs, the merge of the two ports and out of the core in one cycle; place and
//! route named it the critical path (synth/REPORT.md). The slice cuts it at the port:
//! every output is a flip-flop, and so is `inbound.ready`, so a downstream stall does
//! not reach back into the sequencer combinationally either. Full throughput (a beat
//! per cycle) is kept by the second, "skid" register that catches the beat sent in
//! the cycle the output stalls.
//!
//! With `bypass` (an elaboration constant, `CoreConfig::pipelined` false) the slice
//! is wires, so the unpipelined core can still be built and measured.

use crate::hw::primitives::stream::{ResultBeat, StreamIn, StreamOut};
use rust_hdl::prelude::*;

#[derive(LogicBlock)]
pub struct RegisterSlice<T: Synth> {
    pub clock: Signal<In, Clock>,
    pub reset: Signal<In, bool>,
    pub inbound: StreamIn<T>,
    pub outbound: StreamOut<T>,
    bypass: Constant<bool>,
    /// The output register.
    out_valid: DFF<bool>,
    out_data: DFF<T>,
    /// The skid register: holds the beat accepted while the output was stalled.
    skid_valid: DFF<bool>,
    skid_data: DFF<T>,
    /// The output register may load this cycle (it is empty or being emptied).
    out_free: Signal<Local, bool>,
}

/// The slice on a SearchPort's result stream.
pub type ResultRegister = RegisterSlice<ResultBeat>;

impl<T: Synth> RegisterSlice<T> {
    /// A register slice, or wires if `bypass`.
    pub fn new(bypass: bool) -> Self {
        RegisterSlice {
            clock: Default::default(),
            reset: Default::default(),
            inbound: Default::default(),
            outbound: Default::default(),
            bypass: Constant::new(bypass),
            out_valid: Default::default(),
            out_data: Default::default(),
            skid_valid: Default::default(),
            skid_data: Default::default(),
            out_free: Default::default(),
        }
    }
}

impl<T: Synth> Logic for RegisterSlice<T> {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(self, clock, out_valid, out_data, skid_valid, skid_data);
        self.out_free.next = self.outbound.ready.val() || (!self.out_valid.q.val());
        if self.out_free.val() {
            if self.skid_valid.q.val() {
                // Drain the skid register first; the input waits (its ready is low).
                self.out_valid.d.next = true;
                self.out_data.d.next = self.skid_data.q.val();
                self.skid_valid.d.next = false;
            } else {
                self.out_valid.d.next = self.inbound.valid.val();
                self.out_data.d.next = self.inbound.data.val();
            }
        } else if self.inbound.valid.val() && (!self.skid_valid.q.val()) {
            // The output stalled in the cycle this beat was sent: keep it aside.
            self.skid_valid.d.next = true;
            self.skid_data.d.next = self.inbound.data.val();
        }
        if self.reset.val() {
            self.out_valid.d.next = false;
            self.skid_valid.d.next = false;
        }

        if self.bypass.val() {
            self.inbound.ready.next = self.outbound.ready.val();
            self.outbound.valid.next = self.inbound.valid.val();
            self.outbound.data.next = self.inbound.data.val();
        } else {
            self.inbound.ready.next = !self.skid_valid.q.val();
            self.outbound.valid.next = self.out_valid.q.val();
            self.outbound.data.next = self.out_data.q.val();
        }
    }
}
