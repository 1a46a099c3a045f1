//! Dispatcher: one valid/ready stream fanned out to N sinks, each beat to one sink
//! that is ready, round-robin ([`PortArbiter`], the turn moves when a beat moves).
//! The core hands queries to its two SearchPorts with it (a port is ready while one
//! of its QueryModules is free), the array to its trees. `hold` refuses beats: a
//! pending photon load has priority over queries, so queries cannot starve it.

use crate::hw::config::core_config::ModuleMask;
use crate::hw::primitives::port_arbiter::PortArbiter;
use crate::hw::primitives::stream::{StreamIn, StreamOut};
use rust_hdl::prelude::*;

#[derive(LogicBlock)]
pub struct Dispatcher<T: Synth> {
    pub clock: Signal<In, Clock>,
    pub inbound: StreamIn<T>,
    pub hold: Signal<In, bool>,
    pub sinks: Vec<StreamOut<T>>,
    arbiter: PortArbiter,
    ready_mask: Signal<Local, ModuleMask>,
    fire: Signal<Local, bool>,
}

impl<T: Synth> Dispatcher<T> {
    /// A dispatcher to `n` sinks (at most 32, one arbiter bit each).
    pub fn new(n: usize) -> Self {
        Dispatcher {
            clock: Default::default(),
            inbound: Default::default(),
            hold: Default::default(),
            sinks: (0..n).map(|_| Default::default()).collect(),
            arbiter: PortArbiter::new(n),
            ready_mask: Default::default(),
            fire: Default::default(),
        }
    }
}

impl<T: Synth> Logic for Dispatcher<T> {
    #[hdl_gen]
    fn update(&mut self) {
        self.arbiter.clock.next = self.clock.val();
        self.ready_mask.next = 0.into();
        for i in 0..self.sinks.len() {
            self.ready_mask.next = self
                .ready_mask
                .val()
                .replace_bit(i, self.sinks[i].ready.val());
        }
        self.arbiter.requests.next = self.ready_mask.val();
        self.arbiter.hold.next = false;
        self.inbound.ready.next = self.ready_mask.val().any() && (!self.hold.val());
        self.fire.next = self.inbound.valid.val() && self.inbound.ready.val();
        self.arbiter.advance.next = self.fire.val();
        for i in 0..self.sinks.len() {
            self.sinks[i].valid.next = self.fire.val() && self.arbiter.grant.val().get_bit(i);
            self.sinks[i].data.next = self.inbound.data.val();
        }
    }
}
