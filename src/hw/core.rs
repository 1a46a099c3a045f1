//! PhotonSearchCore (paper §4): the top. One dual-port TreeModule, two SearchPorts
//! (each: Q QueryModules, a round-robin PortArbiter and a SearchModule), a
//! [`Dispatcher`] handing queries to a port with a free QueryModule and a
//! [`PacketMerge`] of the two ports' result streams.
//!
//! Streams ([`crate::hw::stream`]), all valid/ready:
//! * `load`: heap address, word, `last` (the last word's address is latched as N,
//!   the photon count). Accepted only while no query is in flight, so a new map can
//!   be loaded after the previous one finished, with or without reset; `ready` is
//!   a register, set the cycle after the core became idle.
//! * `query`: [`QueryBeat`]s, accepted once a map is loaded and no load is pending.
//! * `result`: [`ResultBeat`] packets, a header then the found photons, one a beat
//!   (SearchPort) or two (BarrelPort).
//!   Results of different queries may leave out of order; beats of one result are
//!   contiguous.
//!
//! Between the dispatcher and each port sits a one-beat query stage (issue 11): the
//! dispatcher's grant ends in a register, and the port's load enables start from
//! one, so the hand-out is no longer one combinational path from one port's
//! registered pick through the dispatcher's round robin to every QueryModule's load
//! enable (the 2 × 11 core's ECP5 critical path after the registered pick: 61.8 MHz,
//! 12 nets). A stage takes a query only while empty and while its port has a free
//! QueryModule picked; that module is reserved for this stage's query, which the
//! port takes a cycle later and loads into it from registers the cycle after.

use crate::hw::barrel_port::BarrelPort;
use crate::hw::config::{low_mask, Addr, CoreConfig, PORTS};
use crate::hw::controller::Controller;
use crate::hw::dispatcher::Dispatcher;
use crate::hw::packet_merge::PacketMerge;
use crate::hw::search_port::SearchPort;
use crate::hw::stream::{LoadIn, QueryBeat, ResultBeat, StreamIn, StreamOut};
use crate::hw::tree_module::TreeModule;
use rust_hdl::prelude::*;

#[derive(LogicBlock)]
pub struct PhotonSearchCore<const S: usize, const W: usize> {
    pub clock: Signal<In, Clock>,
    pub reset: Signal<In, bool>,
    pub load: LoadIn<W>,
    pub query: StreamIn<QueryBeat>,
    pub result: StreamOut<ResultBeat>,
    // Status for measurement: a read on port A / B this cycle; every QueryModule busy.
    pub port_a_reading: Signal<Out, bool>,
    pub port_b_reading: Signal<Out, bool>,
    pub all_busy: Signal<Out, bool>,
    tree: TreeModule<W>,
    /// The two ports: SearchPorts (`Controller::Modules`) or BarrelPorts
    /// (`Controller::Barrel`), one of each pair of vectors empty.
    port_a: Vec<SearchPort<S, W>>,
    port_b: Vec<SearchPort<S, W>>,
    barrel_a: Vec<BarrelPort<W>>,
    barrel_b: Vec<BarrelPort<W>>,
    /// What the core sees of its ports, whichever they are.
    a_ram_address: Signal<Local, Addr>,
    b_ram_address: Signal<Local, Addr>,
    a_query_ready: Signal<Local, bool>,
    b_query_ready: Signal<Local, bool>,
    a_result_valid: Signal<Local, bool>,
    b_result_valid: Signal<Local, bool>,
    a_result_data: Signal<Local, ResultBeat>,
    b_result_data: Signal<Local, ResultBeat>,
    a_idle: Signal<Local, bool>,
    b_idle: Signal<Local, bool>,
    a_reading: Signal<Local, bool>,
    b_reading: Signal<Local, bool>,
    a_all_busy: Signal<Local, bool>,
    b_all_busy: Signal<Local, bool>,
    dispatch: Dispatcher<QueryBeat>,
    merge: PacketMerge,
    photon_count: DFF<Addr>,
    loaded: DFF<bool>,
    /// `load.ready`, registered (issue 11): computed from the ports' idle flags it
    /// was one path from a QueryModule's state through the AND over every module,
    /// `load_fire` and the BlockRAM's port-A address multiplexer (the 2 × 12
    /// core's ECP5 critical path, seed 3, 98.3 MHz). Set from the cycle before:
    /// every module free, both stages empty and no query entering one, so the
    /// core is still idle when the load is taken (a pending load holds the
    /// dispatcher, so a burst of load beats keeps it set).
    load_ready: DFF<bool>,
    load_fire: Signal<Local, bool>,
    /// The query stages in front of the ports.
    stage_a_valid: DFF<bool>,
    stage_a_data: DFF<QueryBeat>,
    stage_b_valid: DFF<bool>,
    stage_b_data: DFF<QueryBeat>,
    /// H address bits: the photon count register is as wide as the tree.
    addr_mask: Constant<Addr>,
}

impl<const S: usize, const W: usize> PhotonSearchCore<S, W> {
    /// Elaborate a core for `cfg` (call `cfg.validate()` first).
    pub fn new(cfg: &CoreConfig) -> Self {
        PhotonSearchCore {
            clock: Default::default(),
            reset: Default::default(),
            load: Default::default(),
            query: Default::default(),
            result: Default::default(),
            port_a_reading: Default::default(),
            port_b_reading: Default::default(),
            all_busy: Default::default(),
            tree: TreeModule::new(cfg.address_bits, cfg.layout.word_bits()),
            port_a: search_ports(cfg),
            port_b: search_ports(cfg),
            barrel_a: barrel_ports(cfg),
            barrel_b: barrel_ports(cfg),
            a_ram_address: Default::default(),
            b_ram_address: Default::default(),
            a_query_ready: Default::default(),
            b_query_ready: Default::default(),
            a_result_valid: Default::default(),
            b_result_valid: Default::default(),
            a_result_data: Default::default(),
            b_result_data: Default::default(),
            a_idle: Default::default(),
            b_idle: Default::default(),
            a_reading: Default::default(),
            b_reading: Default::default(),
            a_all_busy: Default::default(),
            b_all_busy: Default::default(),
            dispatch: Dispatcher::new(PORTS),
            merge: PacketMerge::new(PORTS),
            photon_count: Default::default(),
            loaded: Default::default(),
            load_ready: Default::default(),
            load_fire: Default::default(),
            stage_a_valid: Default::default(),
            stage_a_data: Default::default(),
            stage_b_valid: Default::default(),
            stage_b_data: Default::default(),
            addr_mask: Constant::new(Addr::from(low_mask(cfg.address_bits))),
        }
    }
}

/// One SearchPort for a port of `Controller::Modules`, none otherwise.
fn search_ports<const S: usize, const W: usize>(cfg: &CoreConfig) -> Vec<SearchPort<S, W>> {
    (0..(cfg.controller == Controller::Modules) as usize)
        .map(|_| SearchPort::new(cfg))
        .collect()
}

/// One BarrelPort for a port of `Controller::Barrel`, none otherwise.
fn barrel_ports<const W: usize>(cfg: &CoreConfig) -> Vec<BarrelPort<W>> {
    (0..(cfg.controller == Controller::Barrel) as usize)
        .map(|_| BarrelPort::new(cfg))
        .collect()
}

impl<const S: usize, const W: usize> Logic for PhotonSearchCore<S, W> {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(
            self,
            clock,
            photon_count,
            loaded,
            load_ready,
            stage_a_valid,
            stage_a_data,
            stage_b_valid,
            stage_b_data
        );
        self.tree.clock.next = self.clock.val();
        self.dispatch.clock.next = self.clock.val();
        self.merge.clock.next = self.clock.val();
        self.merge.reset.next = self.reset.val();
        // The ports' inputs.
        for i in 0..self.port_a.len() {
            self.port_a[i].clock.next = self.clock.val();
            self.port_a[i].reset.next = self.reset.val();
            self.port_a[i].photon_count.next = self.photon_count.q.val();
            self.port_a[i].ram_data.next = self.tree.a_read_data.val();
            self.port_a[i].query.valid.next = self.stage_a_valid.q.val();
            self.port_a[i].query.data.next = self.stage_a_data.q.val();
            self.port_a[i].result.ready.next = self.merge.sources[0].ready.val();
        }
        for i in 0..self.port_b.len() {
            self.port_b[i].clock.next = self.clock.val();
            self.port_b[i].reset.next = self.reset.val();
            self.port_b[i].photon_count.next = self.photon_count.q.val();
            self.port_b[i].ram_data.next = self.tree.b_read_data.val();
            self.port_b[i].query.valid.next = self.stage_b_valid.q.val();
            self.port_b[i].query.data.next = self.stage_b_data.q.val();
            self.port_b[i].result.ready.next = self.merge.sources[1].ready.val();
        }
        for i in 0..self.barrel_a.len() {
            self.barrel_a[i].clock.next = self.clock.val();
            self.barrel_a[i].reset.next = self.reset.val();
            self.barrel_a[i].photon_count.next = self.photon_count.q.val();
            self.barrel_a[i].ram_data.next = self.tree.a_read_data.val();
            self.barrel_a[i].query.valid.next = self.stage_a_valid.q.val();
            self.barrel_a[i].query.data.next = self.stage_a_data.q.val();
            self.barrel_a[i].result.ready.next = self.merge.sources[0].ready.val();
        }
        for i in 0..self.barrel_b.len() {
            self.barrel_b[i].clock.next = self.clock.val();
            self.barrel_b[i].reset.next = self.reset.val();
            self.barrel_b[i].photon_count.next = self.photon_count.q.val();
            self.barrel_b[i].ram_data.next = self.tree.b_read_data.val();
            self.barrel_b[i].query.valid.next = self.stage_b_valid.q.val();
            self.barrel_b[i].query.data.next = self.stage_b_data.q.val();
            self.barrel_b[i].result.ready.next = self.merge.sources[1].ready.val();
        }
        // The ports' outputs, from whichever kind there is.
        self.a_ram_address.next = 0.into();
        self.b_ram_address.next = 0.into();
        self.a_query_ready.next = false;
        self.b_query_ready.next = false;
        self.a_result_valid.next = false;
        self.b_result_valid.next = false;
        self.a_result_data.next = self.result.data.val();
        self.b_result_data.next = self.result.data.val();
        self.a_idle.next = false;
        self.b_idle.next = false;
        self.a_reading.next = false;
        self.b_reading.next = false;
        self.a_all_busy.next = false;
        self.b_all_busy.next = false;
        for i in 0..self.port_a.len() {
            self.a_ram_address.next = self.port_a[i].ram_address.val();
            self.a_query_ready.next = self.port_a[i].query.ready.val();
            self.a_result_valid.next = self.port_a[i].result.valid.val();
            self.a_result_data.next = self.port_a[i].result.data.val();
            self.a_idle.next = self.port_a[i].idle.val();
            self.a_reading.next = self.port_a[i].reading.val();
            self.a_all_busy.next = self.port_a[i].all_busy.val();
        }
        for i in 0..self.port_b.len() {
            self.b_ram_address.next = self.port_b[i].ram_address.val();
            self.b_query_ready.next = self.port_b[i].query.ready.val();
            self.b_result_valid.next = self.port_b[i].result.valid.val();
            self.b_result_data.next = self.port_b[i].result.data.val();
            self.b_idle.next = self.port_b[i].idle.val();
            self.b_reading.next = self.port_b[i].reading.val();
            self.b_all_busy.next = self.port_b[i].all_busy.val();
        }
        for i in 0..self.barrel_a.len() {
            self.a_ram_address.next = self.barrel_a[i].ram_address.val();
            self.a_query_ready.next = self.barrel_a[i].query.ready.val();
            self.a_result_valid.next = self.barrel_a[i].result.valid.val();
            self.a_result_data.next = self.barrel_a[i].result.data.val();
            self.a_idle.next = self.barrel_a[i].idle.val();
            self.a_reading.next = self.barrel_a[i].reading.val();
            self.a_all_busy.next = self.barrel_a[i].all_busy.val();
        }
        for i in 0..self.barrel_b.len() {
            self.b_ram_address.next = self.barrel_b[i].ram_address.val();
            self.b_query_ready.next = self.barrel_b[i].query.ready.val();
            self.b_result_valid.next = self.barrel_b[i].result.valid.val();
            self.b_result_data.next = self.barrel_b[i].result.data.val();
            self.b_idle.next = self.barrel_b[i].idle.val();
            self.b_reading.next = self.barrel_b[i].reading.val();
            self.b_all_busy.next = self.barrel_b[i].all_busy.val();
        }

        // Load: only while every QueryModule is free (no search reads port A) and no
        // query waits in a stage — decided a cycle ahead (`load_ready`).
        self.load_ready.d.next = self.a_idle.val()
            && self.b_idle.val()
            && (!self.stage_a_valid.q.val())
            && (!self.stage_b_valid.q.val())
            && !(self.query.valid.val() && self.dispatch.inbound.ready.val());
        self.load.ready.next = self.load_ready.q.val();
        self.load_fire.next = self.load.valid.val() && self.load.ready.val();
        if self.load_fire.val() {
            self.tree.a_address.next = self.load.address.val();
        } else {
            self.tree.a_address.next = self.a_ram_address.val();
        }
        self.tree.a_write_enable.next = self.load_fire.val();
        self.tree.a_write_data.next = self.load.word.val();
        self.tree.b_address.next = self.b_ram_address.val();
        if self.load_fire.val() {
            self.loaded.d.next = self.load.last.val();
            if self.load.last.val() {
                self.photon_count.d.next = self.load.address.val() & self.addr_mask.val();
            }
        }

        // Queries to a port with a free QueryModule; a pending load goes first.
        self.dispatch.inbound.valid.next = self.query.valid.val();
        self.dispatch.inbound.data.next = self.query.data.val();
        self.query.ready.next = self.dispatch.inbound.ready.val();
        self.dispatch.hold.next = (!self.loaded.q.val()) || self.load.valid.val();
        // Each port's stage: empty and the port has a pick → ready; the staged
        // query moves into the port when the port takes it. An empty stage takes
        // the inbound data every cycle and only its valid bit waits for the
        // dispatch (issue 11: the dispatch decision → the stage data's clock
        // enable, fanned out over the die, was a critical path on ECP5).
        self.dispatch.sinks[0].ready.next =
            self.a_query_ready.val() && (!self.stage_a_valid.q.val());
        self.dispatch.sinks[1].ready.next =
            self.b_query_ready.val() && (!self.stage_b_valid.q.val());
        if self.stage_a_valid.q.val() && self.a_query_ready.val() {
            self.stage_a_valid.d.next = false;
        }
        if !self.stage_a_valid.q.val() {
            self.stage_a_data.d.next = self.dispatch.sinks[0].data.val();
        }
        if self.dispatch.sinks[0].valid.val() && self.dispatch.sinks[0].ready.val() {
            self.stage_a_valid.d.next = true;
        }
        if self.stage_b_valid.q.val() && self.b_query_ready.val() {
            self.stage_b_valid.d.next = false;
        }
        if !self.stage_b_valid.q.val() {
            self.stage_b_data.d.next = self.dispatch.sinks[1].data.val();
        }
        if self.dispatch.sinks[1].valid.val() && self.dispatch.sinks[1].ready.val() {
            self.stage_b_valid.d.next = true;
        }

        // Result packets of both ports, merged.
        self.merge.sources[0].valid.next = self.a_result_valid.val();
        self.merge.sources[0].data.next = self.a_result_data.val();
        self.merge.sources[1].valid.next = self.b_result_valid.val();
        self.merge.sources[1].data.next = self.b_result_data.val();
        self.result.valid.next = self.merge.merged.valid.val();
        self.result.data.next = self.merge.merged.data.val();
        self.merge.merged.ready.next = self.result.ready.val();

        if self.reset.val() {
            self.loaded.d.next = false;
            self.load_ready.d.next = false;
            self.stage_a_valid.d.next = false;
            self.stage_b_valid.d.next = false;
        }
        self.port_a_reading.next = self.a_reading.val();
        self.port_b_reading.next = self.b_reading.val();
        self.all_busy.next = self.a_all_busy.val() && self.b_all_busy.val();
    }
}
