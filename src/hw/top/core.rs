//! PhotonSearchCore (paper §4): the top. T dual-port TreeModules (the whole map
//! each, or with banks replicas of its top levels over a [`BankStore`] of the
//! rest), 2T controller ports (one per TreeModule port: the paper's SearchPort of Q
//! QueryModules, or a barrel datapath of Q slots), a [`Dispatcher`] handing queries
//! to a port with room and a [`PacketMerge`] of the ports' result packets onto R
//! result streams.
//!
//! Streams ([`crate::hw::primitives::stream`]), all valid/ready:
//! * `load`: heap address, word, `last` (the last word's address is latched as N,
//!   the photon count). Accepted only while no query is in flight, so a new map can
//!   be loaded after the previous one finished, with or without reset; `ready` is
//!   a register, set the cycle after the core became idle.
//! * `query`: [`QueryBeat`]s, accepted once a map is loaded and no load is pending.
//! * `result`: [`ResultBeat`] packets, a header then the found photons, one a beat
//!   (SearchPort) or two (BarrelPort); with R result streams (`more_results`)
//!   stream s carries the packets of the s-th group of D / R datapaths, so that D
//!   datapaths answering more than one beat a cycle between them are not held back.
//!   Results of different queries may leave out of order; beats of one result are
//!   contiguous.
//!
//! Between the dispatcher and each port sits a one-beat query stage: the
//! dispatcher's grant ends in a register, and the port's load enables start from
//! one, so the hand-out is not one combinational path from one port's registered
//! pick through the dispatcher's round robin to every QueryModule's load enable. A
//! stage takes a query only while empty and while its port has a free
//! QueryModule picked; that module is reserved for this stage's query, which the
//! port takes a cycle later and loads into it from registers the cycle after.
//!
//! Each port is a [`ControllerPort`] (SearchPort or BarrelPort behind the same
//! [`PortIo`](crate::hw::primitives::stream::PortIo) bundle), so the ports are wired once,
//! whichever the controller.

use crate::hw::config::core_config::{Addr, CoreConfig, PORTS};
use crate::hw::config::memory_config::MEMORY_PORT_BITS;
use crate::hw::primitives::axi4_read::AxiReadMaster;
use crate::hw::primitives::stream::{LoadIn, QueryBeat, ResultBeat, StreamIn, StreamOut};
use crate::hw::store::bank_store::BankStore;
use crate::hw::store::tree_module::TreeModule;
use crate::hw::top::controller_port::ControllerPort;
use crate::hw::top::dispatcher::Dispatcher;
use crate::hw::top::packet_merge::PacketMerge;
use rust_hdl::prelude::*;

#[derive(LogicBlock)]
pub struct PhotonSearchCore<const S: usize, const W: usize> {
    pub clock: Signal<In, Clock>,
    pub reset: Signal<In, bool>,
    pub load: LoadIn<W>,
    pub query: StreamIn<QueryBeat>,
    pub result: StreamOut<ResultBeat>,
    /// Result streams 1..R (`CoreConfig::result_streams`; empty with one stream):
    /// stream s carries the packets of datapaths s·D/R .. (s+1)·D/R − 1.
    pub more_results: Vec<StreamOut<ResultBeat>>,
    /// For measurement only (the simulations' reads per cycle; `export-verilog`
    /// leaves them out unless asked, `export::verilog::without_status`): a read on
    /// port A / B this cycle; every QueryModule busy.
    pub port_a_reading: Signal<Out, bool>,
    pub port_b_reading: Signal<Out, bool>,
    pub all_busy: Signal<Out, bool>,
    /// With banks (`CoreConfig::banking`): every port's reads this cycle (port
    /// 2t and 2t + 1 on tree t), for the reads-per-cycle measurement.
    pub ports_reading: Vec<Signal<Out, bool>>,
    /// With the map in external memory (`CoreConfig::memory`; none otherwise): the
    /// AXI4 read master that fetches its blocks. The memory holds the map's image
    /// (`MemoryLayout::image`, written by the host); the load stream brings the
    /// replicated levels and the last word (the photon count). A new map needs a
    /// reset first, which empties the cache.
    pub m_axi: Vec<AxiReadMaster<MEMORY_PORT_BITS>>,
    /// The TreeModules (the whole map, or with banks `trees` replicas of its top
    /// levels), ports A (also the load port) and B: one controller port each.
    trees: Vec<TreeModule<W>>,
    ports: Vec<ControllerPort<S, W>>,
    /// The levels below the replicas (no banks: empty).
    store: BankStore<W>,
    banked: Constant<bool>,
    first_banked: Constant<Addr>,
    in_replica: Signal<Local, bool>,
    all_idle: Signal<Local, bool>,
    dispatch: Dispatcher<QueryBeat>,
    merge: PacketMerge,
    photon_count: DFF<Addr>,
    loaded: DFF<bool>,
    /// `load.ready`, registered: computed from the ports' idle flags it would be
    /// one path from a QueryModule's state through the AND over every module,
    /// `load_fire` and the BlockRAM's port-A address multiplexer. Set from the
    /// cycle before: every module free, both stages empty and no query entering
    /// one, so the core is still idle when the load is taken (a pending load holds
    /// the dispatcher, so a burst of load beats keeps it set).
    load_ready: DFF<bool>,
    load_fire: Signal<Local, bool>,
    /// The query stages in front of the ports (entry i = port i).
    stage_valid: Vec<DFF<bool>>,
    stage_data: Vec<DFF<QueryBeat>>,
    stages_empty: Signal<Local, bool>,
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
            more_results: (1..cfg.result_streams)
                .map(|_| Default::default())
                .collect(),
            port_a_reading: Default::default(),
            port_b_reading: Default::default(),
            all_busy: Default::default(),
            ports_reading: (0..cfg.banking.map_or(0, |_| cfg.datapaths()))
                .map(|_| Default::default())
                .collect(),
            m_axi: (0..usize::from(cfg.memory.is_some() && cfg.banking.is_some()))
                .map(|_| Default::default())
                .collect(),
            trees: (0..cfg.datapaths() / PORTS)
                .map(|_| TreeModule::new(cfg.tree_address_bits(), cfg.layout.word_bits()))
                .collect(),
            ports: (0..cfg.datapaths())
                .map(|_| ControllerPort::new(cfg))
                .collect(),
            store: BankStore::new(cfg),
            banked: Constant::new(cfg.banking.is_some()),
            first_banked: Constant::new(Addr::from(1u64 << cfg.tree_address_bits())),
            in_replica: Default::default(),
            all_idle: Default::default(),
            dispatch: Dispatcher::new(cfg.datapaths()),
            merge: PacketMerge::grouped(cfg.datapaths(), cfg.result_streams),
            photon_count: Default::default(),
            loaded: Default::default(),
            load_ready: Default::default(),
            load_fire: Default::default(),
            stage_valid: (0..cfg.datapaths()).map(|_| Default::default()).collect(),
            stage_data: (0..cfg.datapaths()).map(|_| Default::default()).collect(),
            stages_empty: Default::default(),
            addr_mask: Constant::new(Addr::from(cfg.addr_mask())),
        }
    }
}

impl<const S: usize, const W: usize> Logic for PhotonSearchCore<S, W> {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(self, clock, photon_count, loaded, load_ready);
        clock!(self, clock, dispatch, merge, store);
        self.merge.reset.next = self.reset.val();
        self.store.reset.next = self.reset.val();

        // Queries to a port with a free QueryModule; a pending load goes first.
        self.dispatch.inbound.valid.next = self.query.valid.val();
        self.dispatch.inbound.data.next = self.query.data.val();
        self.query.ready.next = self.dispatch.inbound.ready.val();
        self.dispatch.hold.next = (!self.loaded.q.val()) || self.load.valid.val();
        // Each port, its query stage and its result stream. A stage: empty and the
        // port has a pick → ready; the staged query moves into the port when the
        // port takes it. An empty stage takes the inbound data every cycle and only
        // its valid bit waits for the dispatch, so the stage data's clock enable is
        // the stage's own flip-flop, not the dispatch decision.
        self.stages_empty.next = true;
        self.all_idle.next = true;
        for i in 0..self.ports.len() {
            self.all_idle.next = self.all_idle.val() && self.ports[i].io.idle.val();
            // (Without banks nothing answers: the store's loop below is empty.)
            self.ports[i].io.bank.ready.next = false;
            self.ports[i].io.bank_answer.valid.next = false;
            self.ports[i].io.bank_answer.tag.next = 0.into();
            self.ports[i].io.bank_answer.word.next = 0.into();
            self.ports[i].clock.next = self.clock.val();
            self.ports[i].reset.next = self.reset.val();
            self.ports[i].io.photon_count.next = self.photon_count.q.val();
            self.stage_valid[i].clock.next = self.clock.val();
            self.stage_data[i].clock.next = self.clock.val();
            self.stage_valid[i].d.next = self.stage_valid[i].q.val();
            self.stage_data[i].d.next = self.stage_data[i].q.val();
            self.stages_empty.next = self.stages_empty.val() && !self.stage_valid[i].q.val();
            self.ports[i].io.query.valid.next = self.stage_valid[i].q.val();
            self.ports[i].io.query.data.next = self.stage_data[i].q.val();
            self.dispatch.sinks[i].ready.next =
                self.ports[i].io.query.ready.val() && (!self.stage_valid[i].q.val());
            if self.stage_valid[i].q.val() && self.ports[i].io.query.ready.val() {
                self.stage_valid[i].d.next = false;
            }
            if !self.stage_valid[i].q.val() {
                self.stage_data[i].d.next = self.dispatch.sinks[i].data.val();
            }
            if self.dispatch.sinks[i].valid.val() && self.dispatch.sinks[i].ready.val() {
                self.stage_valid[i].d.next = true;
            }
            if self.reset.val() {
                self.stage_valid[i].d.next = false;
            }
            // Result packets of the ports, merged into the result streams.
            self.merge.sources[i].valid.next = self.ports[i].io.result.valid.val();
            self.merge.sources[i].data.next = self.ports[i].io.result.data.val();
            self.ports[i].io.result.ready.next = self.merge.sources[i].ready.val();
        }
        self.result.valid.next = self.merge.merged[0].valid.val();
        self.result.data.next = self.merge.merged[0].data.val();
        self.merge.merged[0].ready.next = self.result.ready.val();
        for s in 0..self.more_results.len() {
            self.more_results[s].valid.next = self.merge.merged[s + 1].valid.val();
            self.more_results[s].data.next = self.merge.merged[s + 1].data.val();
            self.merge.merged[s + 1].ready.next = self.more_results[s].ready.val();
        }

        // Load: only while every QueryModule is free (no search reads port A) and no
        // query waits in a stage — decided a cycle ahead (`load_ready`).
        self.load_ready.d.next = self.all_idle.val()
            && self.stages_empty.val()
            && !(self.query.valid.val() && self.dispatch.inbound.ready.val());
        self.load.ready.next = self.load_ready.q.val();
        self.load_fire.next = self.load.valid.val() && self.load.ready.val();
        // Each TreeModule: port A reads for port 2t or writes a loaded word, port B
        // reads for port 2t + 1. With banks a word below the replicated levels goes
        // to its bank instead, the others to every replica.
        self.in_replica.next =
            (!self.banked.val()) || (self.load.address.val() < self.first_banked.val());
        for t in 0..self.trees.len() {
            self.trees[t].clock.next = self.clock.val();
            if self.load_fire.val() {
                self.trees[t].a_address.next = self.load.address.val();
            } else {
                self.trees[t].a_address.next = self.ports[2 * t].io.ram_address.val();
            }
            self.trees[t].a_write_enable.next = self.load_fire.val() && self.in_replica.val();
            self.trees[t].a_write_data.next = self.load.word.val();
            self.trees[t].b_address.next = self.ports[2 * t + 1].io.ram_address.val();
            self.ports[2 * t].io.ram_data.next = self.trees[t].a_read_data.val();
            self.ports[2 * t + 1].io.ram_data.next = self.trees[t].b_read_data.val();
        }
        self.store.write_enable.next = self.load_fire.val() && !self.in_replica.val();
        self.store.write_address.next = self.load.address.val();
        self.store.write_word.next = self.load.word.val();
        for m in 0..self.m_axi.len() {
            AxiReadMaster::<MEMORY_PORT_BITS>::link(&mut self.m_axi[m], &mut self.store.m_axi[m]);
        }
        for i in 0..self.store.clients.len() {
            self.store.clients[i].valid.next = self.ports[i].io.bank.valid.val();
            self.store.clients[i].bank.next = self.ports[i].io.bank.bank.val();
            self.store.clients[i].row.next = self.ports[i].io.bank.row.val();
            self.store.clients[i].tag.next = self.ports[i].io.bank.tag.val();
            self.ports[i].io.bank.ready.next = self.store.clients[i].ready.val();
            self.ports[i].io.bank_answer.valid.next = self.store.answers[i].valid.val();
            self.ports[i].io.bank_answer.tag.next = self.store.answers[i].tag.val();
            self.ports[i].io.bank_answer.word.next = self.store.answers[i].word.val();
        }
        if self.load_fire.val() {
            self.loaded.d.next = self.load.last.val();
            if self.load.last.val() {
                self.photon_count.d.next = self.load.address.val() & self.addr_mask.val();
            }
        }

        if self.reset.val() {
            self.loaded.d.next = false;
            self.load_ready.d.next = false;
        }
        self.port_a_reading.next = false;
        self.port_b_reading.next = false;
        self.all_busy.next = true;
        for t in 0..self.trees.len() {
            self.port_a_reading.next =
                self.port_a_reading.val() || self.ports[2 * t].io.reading.val();
            self.port_b_reading.next =
                self.port_b_reading.val() || self.ports[2 * t + 1].io.reading.val();
            self.all_busy.next = self.all_busy.val()
                && self.ports[2 * t].io.all_busy.val()
                && self.ports[2 * t + 1].io.all_busy.val();
        }
        for i in 0..self.ports_reading.len() {
            self.ports_reading[i].next = self.ports[i].io.reading.val();
        }
    }
}
