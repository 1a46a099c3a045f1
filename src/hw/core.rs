//! PhotonSearchCore (paper §4): the top. One dual-port TreeModule, two SearchPorts
//! (each: Q QueryModules, a round-robin PortArbiter and a SearchModule), a dispatcher
//! handing queries to free QueryModules and a merger of the two result streams.
//!
//! Streams, all valid/ready (a beat moves when both are high at a clock edge):
//! * load:   `load_address`, `load_word`, `load_last` (the last word's address is
//!   latched as N, the photon count). Accepted only while no query is in flight, so
//!   a new map can be loaded after the previous one finished, with or without reset.
//! * query:  `query_id`, `query_x/y/z`, `query_radius` (inclusive integer bound in
//!   the metric, saturate larger values to the 32-bit maximum), `query_k` (1..=K).
//! * result: a header beat (`result_header`, id, count, visited, `last` iff count = 0)
//!   then count beats of (`result_address`, `result_dist`), `result_last` on the
//!   last. Results of different queries may leave out of order; beats of one result
//!   are contiguous.

use crate::hw::config::{Addr, Coord, CoreConfig, Count, Dist, QueryId, ReadCount, Word};
use crate::hw::search_port::SearchPort;
use crate::hw::tree_module::TreeModule;
use rust_hdl::prelude::*;

#[derive(LogicBlock)]
pub struct PhotonSearchCore<const S: usize, const W: usize> {
    pub clock: Signal<In, Clock>,
    pub reset: Signal<In, bool>,
    // Photon load.
    pub load_valid: Signal<In, bool>,
    pub load_ready: Signal<Out, bool>,
    pub load_address: Signal<In, Addr>,
    pub load_word: Signal<In, Word<W>>,
    pub load_last: Signal<In, bool>,
    // Queries.
    pub query_valid: Signal<In, bool>,
    pub query_ready: Signal<Out, bool>,
    pub query_id: Signal<In, QueryId>,
    pub query_x: Signal<In, Coord>,
    pub query_y: Signal<In, Coord>,
    pub query_z: Signal<In, Coord>,
    pub query_radius: Signal<In, Dist>,
    pub query_k: Signal<In, Count>,
    // Results.
    pub result_valid: Signal<Out, bool>,
    pub result_ready: Signal<In, bool>,
    pub result_header: Signal<Out, bool>,
    pub result_last: Signal<Out, bool>,
    pub result_id: Signal<Out, QueryId>,
    pub result_count: Signal<Out, Count>,
    pub result_visited: Signal<Out, ReadCount>,
    pub result_address: Signal<Out, Addr>,
    pub result_dist: Signal<Out, Dist>,
    // Status for measurement: a read on port A / B this cycle; every QueryModule busy.
    pub port_a_reading: Signal<Out, bool>,
    pub port_b_reading: Signal<Out, bool>,
    pub all_busy: Signal<Out, bool>,
    tree: TreeModule<W>,
    port_a: SearchPort<S, W>,
    port_b: SearchPort<S, W>,
    photon_count: DFF<Addr>,
    loaded: DFF<bool>,
    /// Dispatcher turn: the next query prefers port B.
    dispatch_prefers_b: DFF<bool>,
    /// Result merger: a multi-beat result from `result_owner_b` is in progress.
    result_locked: DFF<bool>,
    result_owner_b: DFF<bool>,
    result_prefers_b: DFF<bool>,
    load_fire: Signal<Local, bool>,
    query_to_b: Signal<Local, bool>,
    query_accept: Signal<Local, bool>,
    result_from_b: Signal<Local, bool>,
    result_fire: Signal<Local, bool>,
}

impl<const S: usize, const W: usize> PhotonSearchCore<S, W> {
    /// Elaborate a core for `cfg` (call `cfg.validate()` first).
    pub fn new(cfg: &CoreConfig) -> Self {
        PhotonSearchCore {
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
            tree: TreeModule::new(cfg.address_bits, cfg.layout.word_bits()),
            port_a: SearchPort::new(cfg),
            port_b: SearchPort::new(cfg),
            photon_count: Default::default(),
            loaded: Default::default(),
            dispatch_prefers_b: Default::default(),
            result_locked: Default::default(),
            result_owner_b: Default::default(),
            result_prefers_b: Default::default(),
            load_fire: Default::default(),
            query_to_b: Default::default(),
            query_accept: Default::default(),
            result_from_b: Default::default(),
            result_fire: Default::default(),
        }
    }
}

impl<const S: usize, const W: usize> Logic for PhotonSearchCore<S, W> {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(
            self,
            clock,
            photon_count,
            loaded,
            dispatch_prefers_b,
            result_locked,
            result_owner_b,
            result_prefers_b
        );
        self.tree.clock.next = self.clock.val();
        self.port_a.clock.next = self.clock.val();
        self.port_b.clock.next = self.clock.val();
        self.port_a.reset.next = self.reset.val();
        self.port_b.reset.next = self.reset.val();
        self.port_a.photon_count.next = self.photon_count.q.val();
        self.port_b.photon_count.next = self.photon_count.q.val();

        // Load: only while every QueryModule is free (no search reads port A).
        self.load_ready.next = self.port_a.idle.val() && self.port_b.idle.val();
        self.load_fire.next = self.load_valid.val() && self.load_ready.val();
        if self.load_fire.val() {
            self.tree.a_address.next = self.load_address.val();
        } else {
            self.tree.a_address.next = self.port_a.ram_address.val();
        }
        self.tree.a_write_enable.next = self.load_fire.val();
        self.tree.a_write_data.next = self.load_word.val();
        self.tree.b_address.next = self.port_b.ram_address.val();
        self.port_a.ram_data.next = self.tree.a_read_data.val();
        self.port_b.ram_data.next = self.tree.b_read_data.val();
        if self.load_fire.val() {
            self.loaded.d.next = self.load_last.val();
            if self.load_last.val() {
                self.photon_count.d.next = self.load_address.val();
            }
        }

        // Dispatch: alternate between the ports, take whichever has a free module.
        // A pending load has priority so that it cannot be starved by queries.
        self.query_to_b.next = self.port_b.query_ready.val()
            && (self.dispatch_prefers_b.q.val() || (!self.port_a.query_ready.val()));
        self.query_ready.next = self.loaded.q.val()
            && (!self.load_valid.val())
            && (self.port_a.query_ready.val() || self.port_b.query_ready.val());
        self.query_accept.next = self.query_valid.val() && self.query_ready.val();
        self.port_a.query_valid.next = self.query_accept.val() && (!self.query_to_b.val());
        self.port_b.query_valid.next = self.query_accept.val() && self.query_to_b.val();
        if self.query_accept.val() {
            self.dispatch_prefers_b.d.next = !self.query_to_b.val();
        }
        self.port_a.query_id.next = self.query_id.val();
        self.port_a.query_x.next = self.query_x.val();
        self.port_a.query_y.next = self.query_y.val();
        self.port_a.query_z.next = self.query_z.val();
        self.port_a.query_radius.next = self.query_radius.val();
        self.port_a.query_k.next = self.query_k.val();
        self.port_b.query_id.next = self.query_id.val();
        self.port_b.query_x.next = self.query_x.val();
        self.port_b.query_y.next = self.query_y.val();
        self.port_b.query_z.next = self.query_z.val();
        self.port_b.query_radius.next = self.query_radius.val();
        self.port_b.query_k.next = self.query_k.val();

        // Merge the result streams; a result's beats stay together.
        if self.result_locked.q.val() {
            self.result_from_b.next = self.result_owner_b.q.val();
        } else {
            self.result_from_b.next = self.port_b.result_valid.val()
                && (self.result_prefers_b.q.val() || (!self.port_a.result_valid.val()));
        }
        if self.result_from_b.val() {
            self.result_valid.next = self.port_b.result_valid.val();
            self.result_header.next = self.port_b.result_header.val();
            self.result_last.next = self.port_b.result_last.val();
            self.result_id.next = self.port_b.result_id.val();
            self.result_count.next = self.port_b.result_count.val();
            self.result_visited.next = self.port_b.result_visited.val();
            self.result_address.next = self.port_b.result_address.val();
            self.result_dist.next = self.port_b.result_dist.val();
        } else {
            self.result_valid.next = self.port_a.result_valid.val();
            self.result_header.next = self.port_a.result_header.val();
            self.result_last.next = self.port_a.result_last.val();
            self.result_id.next = self.port_a.result_id.val();
            self.result_count.next = self.port_a.result_count.val();
            self.result_visited.next = self.port_a.result_visited.val();
            self.result_address.next = self.port_a.result_address.val();
            self.result_dist.next = self.port_a.result_dist.val();
        }
        self.port_a.result_ready.next = self.result_ready.val() && (!self.result_from_b.val());
        self.port_b.result_ready.next = self.result_ready.val() && self.result_from_b.val();
        self.result_fire.next = self.result_valid.val() && self.result_ready.val();
        if self.result_fire.val() {
            if self.result_last.val() {
                self.result_locked.d.next = false;
                self.result_prefers_b.d.next = !self.result_from_b.val();
            } else {
                self.result_locked.d.next = true;
                self.result_owner_b.d.next = self.result_from_b.val();
            }
        }

        if self.reset.val() {
            self.loaded.d.next = false;
            self.result_locked.d.next = false;
        }
        self.port_a_reading.next = self.port_a.reading.val();
        self.port_b_reading.next = self.port_b.reading.val();
        self.all_busy.next = self.port_a.all_busy.val() && self.port_b.all_busy.val();
    }
}
