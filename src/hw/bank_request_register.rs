//! BankRequestRegister: a datapath's read requests on their way to the
//! [`BankCrossbar`](crate::hw::bank_crossbar::BankCrossbar), through a
//! [`RegisterSlice`] (verilog-axis' `axis_register`, REG_TYPE = 2).
//!
//! Why: a request offered straight to the crossbar is granted by its bank's
//! arbiter and the grant ("ready") returns to the datapath in the same cycle, a
//! round trip across the wires between the datapaths and the crossbar. Behind
//! this register the arbiters start from flip-flops beside them, the datapath
//! learns `ready` (room in the register) and `waiting` (a request before the
//! arbiters) from flip-flops, and each leg of the trip is a cycle of its own. A
//! read costs one cycle more; the skid register keeps a request a cycle.

use crate::hw::bank_crossbar::{BankClient, BankRead, BankRequester};
use crate::hw::register_slice::RegisterSlice;
use rust_hdl::prelude::*;

#[derive(LogicBlock)]
pub struct BankRequestRegister {
    pub clock: Signal<In, Clock>,
    /// Drops the registered requests.
    pub reset: Signal<In, bool>,
    /// From the datapath (`waiting`: the register's output is valid).
    pub client: BankClient,
    /// To the crossbar.
    pub request: BankRequester,
    offered: Signal<Local, BankRead>,
    slice: RegisterSlice<BankRead>,
}

impl Default for BankRequestRegister {
    fn default() -> Self {
        BankRequestRegister {
            clock: Default::default(),
            reset: Default::default(),
            client: Default::default(),
            request: Default::default(),
            offered: Default::default(),
            slice: RegisterSlice::new(false),
        }
    }
}

impl Logic for BankRequestRegister {
    #[hdl_gen]
    fn update(&mut self) {
        self.slice.clock.next = self.clock.val();
        self.slice.reset.next = self.reset.val();
        self.offered.next.bank = self.client.bank.val();
        self.offered.next.row = self.client.row.val();
        self.offered.next.tag = self.client.tag.val();
        self.slice.inbound.valid.next = self.client.valid.val();
        self.slice.inbound.data.next = self.offered.val();
        self.client.ready.next = self.slice.inbound.ready.val();
        self.client.waiting.next = self.slice.outbound.valid.val();
        self.request.valid.next = self.slice.outbound.valid.val();
        self.request.bank.next = self.slice.outbound.data.val().bank;
        self.request.row.next = self.slice.outbound.data.val().row;
        self.request.tag.next = self.slice.outbound.data.val().tag;
        self.slice.outbound.ready.next = self.request.ready.val();
    }
}
