//! PacketMerge: N result streams into R, round-robin between packets; the beats of
//! one packet stay together (each output locks onto a source from its first beat
//! to its `last`), like verilog-axis' `axis_arb_mux` with its last-beat lock. The
//! core merges its datapaths' streams with it (R streams when the datapaths fill
//! more than one, `CoreConfig::result_streams`), the array its trees (into one).
//!
//! Output g merges sources `g·N/R .. (g+1)·N/R − 1`. Its arbiter is N/R wide: it
//! sees its group's requests shifted down by the group's first index (a constant),
//! and its grant is shifted back up and masked by the group, so a grant bit is a
//! source index. The mux of each output then has constant-zero selects outside its
//! group, and synthesis keeps only the group's N/R inputs; without the mask each of
//! the R outputs would be an N-input mux of a 195-bit beat.
//!
//! An output's valid is not read through its grant: between packets the arbiter
//! grants a requesting source whenever one requests, so valid is the OR of the
//! group's valids; within a packet it is the held source's valid. The turn's
//! `advance` (valid and ready) then starts from the sources' valids and two gates,
//! not from the arbiter's carry chain and the beat multiplexer behind it.

use crate::hw::config::core_config::ModuleMask;
use crate::hw::primitives::port_arbiter::PortArbiter;
use crate::hw::primitives::stream::{ResultBeat, StreamIn, StreamOut};
use rust_hdl::prelude::*;

#[derive(LogicBlock)]
pub struct PacketMerge {
    pub clock: Signal<In, Clock>,
    pub reset: Signal<In, bool>,
    pub sources: Vec<StreamIn<ResultBeat>>,
    pub merged: Vec<StreamOut<ResultBeat>>,
    /// One per output: grants round-robin between packets; while `locked` it
    /// holds the packet's source (its last grant), so no owner register is needed.
    arbiters: Vec<PortArbiter>,
    /// Each output's grant as a source mask (its arbiter's grant shifted up).
    grants: Vec<Signal<Local, ModuleMask>>,
    /// Each group's first source index.
    offset: Vec<Constant<ModuleMask>>,
    /// A packet is in progress on the output (its first beat moved, its last has not).
    locked: Vec<DFF<bool>>,
    /// The sources of each output's group, one bit each.
    group: Vec<Constant<ModuleMask>>,
    valid_mask: Signal<Local, ModuleMask>,
    /// Each output's last grant as a source mask: the packet's source while `locked`.
    held: Vec<Signal<Local, ModuleMask>>,
    /// The beat of the output being wired (a temporary reused for each output).
    picked: Signal<Local, ResultBeat>,
    fire: Vec<Signal<Local, bool>>,
}

impl PacketMerge {
    /// A merge of `n` streams (at most 32) into one.
    pub fn new(n: usize) -> Self {
        PacketMerge::grouped(n, 1)
    }

    /// A merge of `n` streams into `r` (a divisor of `n`), output g taking the
    /// g-th `n / r` sources.
    pub fn grouped(n: usize, r: usize) -> Self {
        assert!(
            r >= 1 && n.is_multiple_of(r) && n <= 32,
            "{n} sources into {r} outputs"
        );
        let g = n / r;
        PacketMerge {
            clock: Default::default(),
            reset: Default::default(),
            sources: (0..n).map(|_| Default::default()).collect(),
            merged: (0..r).map(|_| Default::default()).collect(),
            arbiters: (0..r).map(|_| PortArbiter::new(g)).collect(),
            grants: (0..r).map(|_| Default::default()).collect(),
            offset: (0..r)
                .map(|o| Constant::new(ModuleMask::from((o * g) as u64)))
                .collect(),
            locked: (0..r).map(|_| Default::default()).collect(),
            group: (0..r)
                .map(|o| Constant::new(ModuleMask::from(((1u64 << g) - 1) << (o * g))))
                .collect(),
            valid_mask: Default::default(),
            held: (0..r).map(|_| Default::default()).collect(),
            picked: Default::default(),
            fire: (0..r).map(|_| Default::default()).collect(),
        }
    }
}

impl Logic for PacketMerge {
    #[hdl_gen]
    fn update(&mut self) {
        self.valid_mask.next = 0.into();
        for i in 0..self.sources.len() {
            self.valid_mask.next = self
                .valid_mask
                .val()
                .replace_bit(i, self.sources[i].valid.val());
        }
        for o in 0..self.merged.len() {
            self.arbiters[o].clock.next = self.clock.val();
            self.locked[o].clock.next = self.clock.val();
            self.locked[o].d.next = self.locked[o].q.val();
            self.arbiters[o].requests.next =
                (self.valid_mask.val() & self.group[o].val()) >> self.offset[o].val();
            self.arbiters[o].hold.next = self.locked[o].q.val();
            // Masked by the group as well: the arbiter's held grant is a register,
            // whose bits above N/R synthesis cannot prove zero.
            self.grants[o].next =
                (self.arbiters[o].grant.val() << self.offset[o].val()) & self.group[o].val();
            self.held[o].next =
                (self.arbiters[o].last_grant.val() << self.offset[o].val()) & self.group[o].val();
            // Valid: the held source's within a packet, else any of the group's (the
            // arbiter then grants one of them).
            if self.locked[o].q.val() {
                self.merged[o].valid.next = (self.valid_mask.val() & self.held[o].val()).any();
            } else {
                self.merged[o].valid.next = (self.valid_mask.val() & self.group[o].val()).any();
            }
            // The picked source's beat (source 0's while nothing is picked: valid is low).
            self.picked.next = self.sources[0].data.val();
            for i in 0..self.sources.len() {
                if self.grants[o].val().get_bit(i) {
                    self.picked.next = self.sources[i].data.val();
                }
            }
            self.merged[o].data.next = self.picked.val();
            self.fire[o].next = self.merged[o].valid.val() && self.merged[o].ready.val();
            self.arbiters[o].advance.next = self.fire[o].val();
            if self.fire[o].val() {
                self.locked[o].d.next = !self.picked.val().last;
            }
            if self.reset.val() {
                self.locked[o].d.next = false;
            }
        }
        // A source moves when the output that granted it takes the beat.
        for i in 0..self.sources.len() {
            self.sources[i].ready.next = false;
            for o in 0..self.merged.len() {
                if self.grants[o].val().get_bit(i) {
                    self.sources[i].ready.next = self.merged[o].ready.val();
                }
            }
        }
    }
}
