//! PacketMerge: N result streams into one, round-robin between packets; the beats of
//! one packet stay together (the merge locks onto a source from its first beat to
//! its `last`), like verilog-axis' `axis_arb_mux` with its last-beat lock. The core
//! merges its two SearchPorts with it, the array its trees.

use crate::hw::config::ModuleMask;
use crate::hw::port_arbiter::PortArbiter;
use crate::hw::stream::{ResultBeat, StreamIn, StreamOut};
use rust_hdl::prelude::*;

#[derive(LogicBlock)]
pub struct PacketMerge {
    pub clock: Signal<In, Clock>,
    pub reset: Signal<In, bool>,
    pub sources: Vec<StreamIn<ResultBeat>>,
    pub merged: StreamOut<ResultBeat>,
    /// Grants round-robin between packets; while `locked` it holds the packet's
    /// source (its last grant), so no separate owner register is needed.
    arbiter: PortArbiter,
    /// A packet is in progress (its first beat moved, its last has not).
    locked: DFF<bool>,
    valid_mask: Signal<Local, ModuleMask>,
    fire: Signal<Local, bool>,
}

impl PacketMerge {
    /// A merge of `n` streams (at most 32).
    pub fn new(n: usize) -> Self {
        PacketMerge {
            clock: Default::default(),
            reset: Default::default(),
            sources: (0..n).map(|_| Default::default()).collect(),
            merged: Default::default(),
            arbiter: PortArbiter::new(n),
            locked: Default::default(),
            valid_mask: Default::default(),
            fire: Default::default(),
        }
    }
}

impl Logic for PacketMerge {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(self, clock, locked);
        self.arbiter.clock.next = self.clock.val();
        self.valid_mask.next = 0.into();
        for i in 0..self.sources.len() {
            self.valid_mask.next = self
                .valid_mask
                .val()
                .replace_bit(i, self.sources[i].valid.val());
        }
        self.arbiter.requests.next = self.valid_mask.val();
        self.arbiter.hold.next = self.locked.q.val();
        // The picked source's beat (source 0's while nothing is picked: valid is low).
        self.merged.valid.next = false;
        self.merged.data.next = self.sources[0].data.val();
        for i in 0..self.sources.len() {
            if self.arbiter.grant.val().get_bit(i) {
                self.merged.valid.next = self.sources[i].valid.val();
                self.merged.data.next = self.sources[i].data.val();
            }
            self.sources[i].ready.next =
                self.merged.ready.val() && self.arbiter.grant.val().get_bit(i);
        }
        self.fire.next = self.merged.valid.val() && self.merged.ready.val();
        self.arbiter.advance.next = self.fire.val();
        if self.fire.val() {
            self.locked.d.next = !self.merged.data.val().last;
        }
        if self.reset.val() {
            self.locked.d.next = false;
        }
    }
}
