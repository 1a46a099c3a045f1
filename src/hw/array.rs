//! PhotonSearchArray: T replicated trees, the paper's future work (§5: "replicate the
//! whole circuit including the TreeModule"). Each tree is a whole
//! [`PhotonSearchCore`] (TreeModule, SearchModules and QueryModules) holding a copy of
//! the photon map; the array puts the core's valid/ready streams in front of them:
//!
//! * load: broadcast. A beat moves only when every tree is ready, into all of them,
//!   so the trees always hold the same map.
//! * query: dispatched to one tree with a free QueryModule, round-robin
//!   ([`PortArbiter`] over the trees' `query_ready`). A pending load blocks queries,
//!   as in the core.
//! * result: the trees' result streams merged round-robin; the beats of one result
//!   stay together (the merger locks onto a tree until its `last` beat).
//!
//! Photon reads per cycle scale with T (2T BlockRAM ports) for T times the area and
//! BlockRAM; the ports and their meaning are those of the core, so the host driver,
//! the cross-simulation and the export treat both tops alike ([`SearchTop`]). Status
//! outputs: `port_a_reading` / `port_b_reading` = some tree reads on that port,
//! `all_busy` = every QueryModule of every tree is busy.

use crate::hw::config::{
    Addr, Coord, CoreConfig, Count, Dist, ModuleMask, QueryId, ReadCount, Word,
};
use crate::hw::core::PhotonSearchCore;
use crate::hw::port_arbiter::PortArbiter;
use rust_hdl::prelude::*;

#[derive(LogicBlock)]
pub struct PhotonSearchArray<const S: usize, const W: usize> {
    pub clock: Signal<In, Clock>,
    pub reset: Signal<In, bool>,
    // Photon load (broadcast to every tree).
    pub load_valid: Signal<In, bool>,
    pub load_ready: Signal<Out, bool>,
    pub load_address: Signal<In, Addr>,
    pub load_word: Signal<In, Word<W>>,
    pub load_last: Signal<In, bool>,
    // Queries (to one tree).
    pub query_valid: Signal<In, bool>,
    pub query_ready: Signal<Out, bool>,
    pub query_id: Signal<In, QueryId>,
    pub query_x: Signal<In, Coord>,
    pub query_y: Signal<In, Coord>,
    pub query_z: Signal<In, Coord>,
    pub query_radius: Signal<In, Dist>,
    pub query_k: Signal<In, Count>,
    // Results (merged).
    pub result_valid: Signal<Out, bool>,
    pub result_ready: Signal<In, bool>,
    pub result_header: Signal<Out, bool>,
    pub result_last: Signal<Out, bool>,
    pub result_id: Signal<Out, QueryId>,
    pub result_count: Signal<Out, Count>,
    pub result_visited: Signal<Out, ReadCount>,
    pub result_address: Signal<Out, Addr>,
    pub result_dist: Signal<Out, Dist>,
    // Status: some tree reads on port A / B; every QueryModule of every tree busy.
    pub port_a_reading: Signal<Out, bool>,
    pub port_b_reading: Signal<Out, bool>,
    pub all_busy: Signal<Out, bool>,
    pub trees: Vec<PhotonSearchCore<S, W>>,
    query_arbiter: PortArbiter,
    result_arbiter: PortArbiter,
    /// The tree whose multi-beat result is in progress (one-hot), while locked.
    result_locked: DFF<bool>,
    result_owner: DFF<ModuleMask>,
    load_ready_all: Signal<Local, bool>,
    query_ready_mask: Signal<Local, ModuleMask>,
    result_valid_mask: Signal<Local, ModuleMask>,
    query_pick: Signal<Local, ModuleMask>,
    result_pick: Signal<Local, ModuleMask>,
    any_reading_a: Signal<Local, bool>,
    any_reading_b: Signal<Local, bool>,
    every_busy: Signal<Local, bool>,
}

impl<const S: usize, const W: usize> PhotonSearchArray<S, W> {
    /// `cfg.trees` copies of the core for `cfg` (call `cfg.validate()` first).
    pub fn new(cfg: &CoreConfig) -> Self {
        PhotonSearchArray {
            clock: Default::default(),
            reset: Default::default(),
            load_valid: Default::default(),
            load_ready: Default::default(),
            load_address: Default::default(),
            load_word: Default::default(),
            load_last: Default::default(),
            query_valid: Default::default(),
            query_ready: Default::default(),
            query_id: Default::default(),
            query_x: Default::default(),
            query_y: Default::default(),
            query_z: Default::default(),
            query_radius: Default::default(),
            query_k: Default::default(),
            result_valid: Default::default(),
            result_ready: Default::default(),
            result_header: Default::default(),
            result_last: Default::default(),
            result_id: Default::default(),
            result_count: Default::default(),
            result_visited: Default::default(),
            result_address: Default::default(),
            result_dist: Default::default(),
            port_a_reading: Default::default(),
            port_b_reading: Default::default(),
            all_busy: Default::default(),
            trees: (0..cfg.trees).map(|_| PhotonSearchCore::new(cfg)).collect(),
            query_arbiter: Default::default(),
            result_arbiter: Default::default(),
            result_locked: Default::default(),
            result_owner: Default::default(),
            load_ready_all: Default::default(),
            query_ready_mask: Default::default(),
            result_valid_mask: Default::default(),
            query_pick: Default::default(),
            result_pick: Default::default(),
            any_reading_a: Default::default(),
            any_reading_b: Default::default(),
            every_busy: Default::default(),
        }
    }
}

impl<const S: usize, const W: usize> Logic for PhotonSearchArray<S, W> {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(self, clock, result_locked, result_owner);
        self.query_arbiter.clock.next = self.clock.val();
        self.result_arbiter.clock.next = self.clock.val();

        // Collect the trees' handshake and status bits.
        self.load_ready_all.next = true;
        self.query_ready_mask.next = 0.into();
        self.result_valid_mask.next = 0.into();
        self.any_reading_a.next = false;
        self.any_reading_b.next = false;
        self.every_busy.next = true;
        for i in 0..self.trees.len() {
            self.load_ready_all.next = self.load_ready_all.val() && self.trees[i].load_ready.val();
            self.query_ready_mask.next = self
                .query_ready_mask
                .val()
                .replace_bit(i, self.trees[i].query_ready.val());
            self.result_valid_mask.next = self
                .result_valid_mask
                .val()
                .replace_bit(i, self.trees[i].result_valid.val());
            self.any_reading_a.next =
                self.any_reading_a.val() || self.trees[i].port_a_reading.val();
            self.any_reading_b.next =
                self.any_reading_b.val() || self.trees[i].port_b_reading.val();
            self.every_busy.next = self.every_busy.val() && self.trees[i].all_busy.val();
        }

        // Round robin over the trees that can take a query / have a result beat.
        self.query_arbiter.requests.next = self.query_ready_mask.val();
        self.query_pick.next = self.query_arbiter.grant.val();
        self.result_arbiter.requests.next = self.result_valid_mask.val();
        if self.result_locked.q.val() {
            self.result_pick.next = self.result_owner.q.val();
        } else {
            self.result_pick.next = self.result_arbiter.grant.val();
        }

        self.load_ready.next = self.load_ready_all.val();
        // A pending load has priority so that queries cannot starve it.
        self.query_ready.next = self.query_ready_mask.val().any() && (!self.load_valid.val());
        self.result_valid.next = false;
        self.result_header.next = false;
        self.result_last.next = false;
        self.result_id.next = 0.into();
        self.result_count.next = 0.into();
        self.result_visited.next = 0.into();
        self.result_address.next = 0.into();
        self.result_dist.next = 0.into();
        for i in 0..self.trees.len() {
            self.trees[i].clock.next = self.clock.val();
            self.trees[i].reset.next = self.reset.val();
            // Broadcast load: the beat moves into every tree at once.
            self.trees[i].load_valid.next = self.load_valid.val() && self.load_ready_all.val();
            self.trees[i].load_address.next = self.load_address.val();
            self.trees[i].load_word.next = self.load_word.val();
            self.trees[i].load_last.next = self.load_last.val();
            // The query goes to the picked tree only.
            self.trees[i].query_valid.next = self.query_valid.val()
                && self.query_ready.val()
                && self.query_pick.val().get_bit(i);
            self.trees[i].query_id.next = self.query_id.val();
            self.trees[i].query_x.next = self.query_x.val();
            self.trees[i].query_y.next = self.query_y.val();
            self.trees[i].query_z.next = self.query_z.val();
            self.trees[i].query_radius.next = self.query_radius.val();
            self.trees[i].query_k.next = self.query_k.val();
            // The picked tree's result beat.
            self.trees[i].result_ready.next =
                self.result_ready.val() && self.result_pick.val().get_bit(i);
            if self.result_pick.val().get_bit(i) {
                self.result_valid.next = self.trees[i].result_valid.val();
                self.result_header.next = self.trees[i].result_header.val();
                self.result_last.next = self.trees[i].result_last.val();
                self.result_id.next = self.trees[i].result_id.val();
                self.result_count.next = self.trees[i].result_count.val();
                self.result_visited.next = self.trees[i].result_visited.val();
                self.result_address.next = self.trees[i].result_address.val();
                self.result_dist.next = self.trees[i].result_dist.val();
            }
        }
        // Lock onto a tree from its first beat to its last.
        if self.result_valid.val() && self.result_ready.val() {
            self.result_locked.d.next = !self.result_last.val();
            self.result_owner.d.next = self.result_pick.val();
        }
        if self.reset.val() {
            self.result_locked.d.next = false;
        }
        self.port_a_reading.next = self.any_reading_a.val();
        self.port_b_reading.next = self.any_reading_b.val();
        self.all_busy.next = self.every_busy.val();
    }
}
