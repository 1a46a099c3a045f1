//! PhotonSearchArray: T replicated trees, the paper's future work (§5: "replicate the
//! whole circuit including the TreeModule"). Each tree is a whole
//! [`PhotonSearchCore`] (TreeModule, SearchModules and QueryModules) holding a copy of
//! the photon map; the array puts the core's valid/ready streams in front of them:
//!
//! * load: broadcast. A beat moves only when every tree is ready, into all of them,
//!   so the trees always hold the same map; `ready` is a register, as in the core.
//! * query: dispatched round-robin (the core's [`Dispatcher`]) into a one-beat stage
//!   per tree, which hands it to its tree once the tree has a free QueryModule. A
//!   pending load blocks queries, as in the core, and waits for the stages to empty
//!   (a staged query belongs to the map it was sent against).
//! * result: the trees' result streams merged round-robin between packets (the
//!   core's [`PacketMerge`]).
//!
//! Why a stage per tree: without it the dispatch is one combinational path from
//! one tree's free-module registers through its ready, the array's round robin and
//! into another tree's query stage — across the die once the trees are placed
//! apart, and so a large array's critical path. With the stage, the array's round
//! robin sees only the stages' own valid flip-flops, and a tree's ready reaches
//! only its own stage.
//!
//! Photon reads per cycle scale with T (2T BlockRAM ports) for T times the area and
//! BlockRAM; the ports and their meaning are those of the core, so the host driver,
//! the cross-simulation and the export treat both tops alike (`rtl::top::SearchTop`). Status
//! outputs: `port_a_reading` / `port_b_reading` = some tree reads on that port,
//! `all_busy` = every QueryModule of every tree is busy; `trees_reading_a` /
//! `trees_reading_b` / `trees_busy` the same per tree (bit t = tree t), so a
//! simulation of the exported Verilog (Verilator) measures every port's reads as
//! the native simulation does by looking inside.

use crate::hw::config::core_config::{CoreConfig, MAX_TREES};
use crate::hw::primitives::stream::{LoadIn, QueryBeat, ResultBeat, StreamIn, StreamOut};
use crate::hw::top::core::PhotonSearchCore;
use crate::hw::top::dispatcher::Dispatcher;
use crate::hw::top::packet_merge::PacketMerge;
use rust_hdl::prelude::*;

#[derive(LogicBlock)]
pub struct PhotonSearchArray<const S: usize, const W: usize> {
    pub clock: Signal<In, Clock>,
    pub reset: Signal<In, bool>,
    /// Broadcast to every tree.
    pub load: LoadIn<W>,
    /// To one tree.
    pub query: StreamIn<QueryBeat>,
    /// Merged.
    pub result: StreamOut<ResultBeat>,
    /// Always empty: an array of whole cores has one result stream (the same
    /// ports as [`PhotonSearchCore`]'s, for the driver).
    pub more_results: Vec<StreamOut<ResultBeat>>,
    // Status: some tree reads on port A / B; every QueryModule of every tree busy.
    pub port_a_reading: Signal<Out, bool>,
    pub port_b_reading: Signal<Out, bool>,
    pub all_busy: Signal<Out, bool>,
    // The same per tree: bit t is tree t (bits from T up are 0).
    pub trees_reading_a: Signal<Out, Bits<MAX_TREES>>,
    pub trees_reading_b: Signal<Out, Bits<MAX_TREES>>,
    pub trees_busy: Signal<Out, Bits<MAX_TREES>>,
    pub trees: Vec<PhotonSearchCore<S, W>>,
    dispatch: Dispatcher<QueryBeat>,
    merge: PacketMerge,
    /// The query stages in front of the trees (bit / entry t = tree t).
    stage_valid: Vec<DFF<bool>>,
    stage_data: Vec<DFF<QueryBeat>>,
    stages_empty: Signal<Local, bool>,
    load_ready_all: Signal<Local, bool>,
    /// `load.ready`, registered like each core's: the AND over the
    /// trees' ready registers and the stages, a cycle ahead and with no query
    /// entering a stage, so the broadcast load's enable starts from one flip-flop
    /// instead of a path across every tree. (Each tree's `load_ready` is then still
    /// set: it was set a cycle ago and no query reached the tree since.)
    load_ready: DFF<bool>,
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
            load: Default::default(),
            query: Default::default(),
            result: Default::default(),
            more_results: vec![],
            port_a_reading: Default::default(),
            port_b_reading: Default::default(),
            all_busy: Default::default(),
            trees_reading_a: Default::default(),
            trees_reading_b: Default::default(),
            trees_busy: Default::default(),
            trees: (0..cfg.trees).map(|_| PhotonSearchCore::new(cfg)).collect(),
            dispatch: Dispatcher::new(cfg.trees),
            merge: PacketMerge::new(cfg.trees),
            stage_valid: (0..cfg.trees).map(|_| Default::default()).collect(),
            stage_data: (0..cfg.trees).map(|_| Default::default()).collect(),
            stages_empty: Default::default(),
            load_ready_all: Default::default(),
            load_ready: Default::default(),
            any_reading_a: Default::default(),
            any_reading_b: Default::default(),
            every_busy: Default::default(),
        }
    }
}

impl<const S: usize, const W: usize> Logic for PhotonSearchArray<S, W> {
    #[hdl_gen]
    fn update(&mut self) {
        clock!(self, clock, dispatch, merge);
        self.merge.reset.next = self.reset.val();
        dff_setup!(self, clock, load_ready);

        // Collect the trees' load handshake and status bits.
        self.load_ready_all.next = true;
        self.stages_empty.next = true;
        self.any_reading_a.next = false;
        self.any_reading_b.next = false;
        self.every_busy.next = true;
        self.trees_reading_a.next = 0.into();
        self.trees_reading_b.next = 0.into();
        self.trees_busy.next = 0.into();
        for i in 0..self.trees.len() {
            self.trees_reading_a.next = self
                .trees_reading_a
                .val()
                .replace_bit(i, self.trees[i].port_a_reading.val());
            self.trees_reading_b.next = self
                .trees_reading_b
                .val()
                .replace_bit(i, self.trees[i].port_b_reading.val());
            self.trees_busy.next = self
                .trees_busy
                .val()
                .replace_bit(i, self.trees[i].all_busy.val());
            self.load_ready_all.next = self.load_ready_all.val() && self.trees[i].load.ready.val();
            self.stages_empty.next = self.stages_empty.val() && !self.stage_valid[i].q.val();
            self.any_reading_a.next =
                self.any_reading_a.val() || self.trees[i].port_a_reading.val();
            self.any_reading_b.next =
                self.any_reading_b.val() || self.trees[i].port_b_reading.val();
            self.every_busy.next = self.every_busy.val() && self.trees[i].all_busy.val();
        }
        // A load waits for the stages: their queries were sent against the old map.
        self.load_ready.d.next = self.load_ready_all.val()
            && self.stages_empty.val()
            && !(self.query.valid.val() && self.dispatch.inbound.ready.val());
        if self.reset.val() {
            self.load_ready.d.next = false;
        }
        self.load.ready.next = self.load_ready.q.val();

        // Queries to one tree; a pending load goes first.
        self.dispatch.inbound.valid.next = self.query.valid.val();
        self.dispatch.inbound.data.next = self.query.data.val();
        self.query.ready.next = self.dispatch.inbound.ready.val();
        self.dispatch.hold.next = self.load.valid.val();
        self.merge.merged[0].ready.next = self.result.ready.val();
        self.result.valid.next = self.merge.merged[0].valid.val();
        self.result.data.next = self.merge.merged[0].data.val();
        for i in 0..self.trees.len() {
            self.trees[i].clock.next = self.clock.val();
            self.trees[i].reset.next = self.reset.val();
            // Broadcast load: the beat moves into every tree at once.
            self.trees[i].load.valid.next = self.load.valid.val() && self.load_ready.q.val();
            self.trees[i].load.address.next = self.load.address.val();
            self.trees[i].load.word.next = self.load.word.val();
            self.trees[i].load.last.next = self.load.last.val();
            // Stage i: takes a query while empty, hands it on when tree i takes it.
            self.stage_valid[i].clock.next = self.clock.val();
            self.stage_data[i].clock.next = self.clock.val();
            self.stage_valid[i].d.next = self.stage_valid[i].q.val();
            self.stage_data[i].d.next = self.stage_data[i].q.val();
            self.dispatch.sinks[i].ready.next = !self.stage_valid[i].q.val();
            self.trees[i].query.valid.next = self.stage_valid[i].q.val();
            self.trees[i].query.data.next = self.stage_data[i].q.val();
            if self.stage_valid[i].q.val() && self.trees[i].query.ready.val() {
                self.stage_valid[i].d.next = false;
            }
            // An empty stage takes the inbound data every cycle (only its valid bit
            // waits for the dispatch), so the data's clock enable is the stage's
            // own flip-flop, not the round robin (as in the core).
            if !self.stage_valid[i].q.val() {
                self.stage_data[i].d.next = self.dispatch.sinks[i].data.val();
            }
            if self.dispatch.sinks[i].valid.val() && !self.stage_valid[i].q.val() {
                self.stage_valid[i].d.next = true;
            }
            if self.reset.val() {
                self.stage_valid[i].d.next = false;
            }
            self.merge.sources[i].valid.next = self.trees[i].result.valid.val();
            self.merge.sources[i].data.next = self.trees[i].result.data.val();
            self.trees[i].result.ready.next = self.merge.sources[i].ready.val();
        }
        self.port_a_reading.next = self.any_reading_a.val();
        self.port_b_reading.next = self.any_reading_b.val();
        self.all_busy.next = self.every_busy.val();
    }
}
