//! SearchPort (paper §4.5): one TreeModule port with its Q QueryModules, the
//! round-robin PortArbiter and its own SearchModule, plus the hand-out of queries to
//! free QueryModules and the read-out of finished ones as a result stream.
//!
//! Query hand-out: the free QueryModule that takes the next query is picked one
//! cycle ahead into a register ([`FreePick`]), so `query.ready` and every module's
//! load enable come from flip-flops. The picked module then loads the query a cycle
//! later, from registers (`load_now`, `load_data`), so the load enable fanned out
//! to all Q modules starts from a flip-flop too. A module being loaded counts as
//! taken (not free, not idle).
//!
//! Read grant: with `CoreConfig::pipelined` the arbiter's grant is a register. The
//! grant for cycle t + 1 is decided in cycle t among the modules requesting then,
//! less the one granted in t (it leaves READY at that edge), so the granted
//! module's read reaches the TreeModule from flip-flops through the OR of the
//! modules' addresses only. Cost: one cycle more per read round trip
//! (`CoreConfig::issue_interval`).
//!
//! Query ids: only the read-out needs a query's id, so the port keeps them in one
//! LUT-RAM indexed by QueryModule (written at the load, read by the module being
//! read out) rather than in Q registers ORed together; the coordinates are kept
//! the same way by the SearchModule.
//!
//! Result stream, one beat per cycle when valid & ready: a header beat, then `count`
//! entry beats in found-list slot order
//! ([`ResultBeat`](crate::hw::primitives::stream::ResultBeat)), sequenced by a
//! [`ResultReadout`] (the selected module's count and reads are fetched into
//! registers a cycle before its header; with `CoreConfig::pipelined` every result
//! output is a flip-flop).

use crate::hw::config::core_config::{Addr, CoreConfig, Count, Dist, ModuleMask, ReadCount};
use crate::hw::datapath::search_module::SearchModule;
use crate::hw::modules::query_module::QueryModule;
use crate::hw::modules::result_readout::ResultReadout;
use crate::hw::primitives::free_pick::FreePick;
use crate::hw::primitives::lut_ram::LutRam;
use crate::hw::primitives::port_arbiter::PortArbiter;
use crate::hw::primitives::stream::{PortIo, QueryBeat, ReadRequest};
use rust_hdl::prelude::*;

#[derive(LogicBlock)]
pub struct SearchPort<const S: usize, const W: usize> {
    pub clock: Signal<In, Clock>,
    pub reset: Signal<In, bool>,
    /// Photon count, TreeModule port, queries (ready while a QueryModule is free),
    /// result packets, status (a read was granted this cycle; every QueryModule is
    /// occupied; none is).
    pub io: PortIo<W>,
    modules: Vec<QueryModule<S>>,
    arbiter: PortArbiter,
    /// `CoreConfig::pipelined`: the grant is registered, and whether there is one
    /// (`granted_reg` equals `grant_reg.any()`, kept so that the SearchModule's
    /// `request_valid` is a flip-flop, not an OR over Q bits).
    grant_stage: Constant<bool>,
    grant_reg: DFF<ModuleMask>,
    granted_reg: DFF<bool>,
    /// The grant in force this cycle (one-hot) and whether there is one.
    grant: Signal<Local, ModuleMask>,
    granted: Signal<Local, bool>,
    search: SearchModule<W>,
    /// One bit per QueryModule of this port.
    all_modules: Constant<ModuleMask>,
    requests: Signal<Local, ModuleMask>,
    free_mask: Signal<Local, ModuleMask>,
    /// The free module the next query goes to.
    free_pick: FreePick,
    /// The module loading the query accepted last cycle (one-hot), and that query.
    load_now: DFF<ModuleMask>,
    load_data: DFF<QueryBeat>,
    /// The query id of each QueryModule's query.
    ids: LutRam,
    query_fire: Signal<Local, bool>,
    finished_mask: Signal<Local, ModuleMask>,
    /// The granted module's read (zero when none is granted: not valid then).
    granted_read: Signal<Local, ReadRequest>,
    read_pick: Signal<Local, ReadRequest>,
    /// The result stream's sequencer, and the selected module's photons, count and
    /// reads (ORs over the zero-gated modules).
    readout: ResultReadout,
    photon_address: Signal<Local, Addr>,
    photon_dist: Signal<Local, Dist>,
    module_count: Signal<Local, Count>,
    module_visited: Signal<Local, ReadCount>,
}

impl<const S: usize, const W: usize> SearchPort<S, W> {
    pub fn new(cfg: &CoreConfig) -> Self {
        let q = cfg.queries_per_port;
        SearchPort {
            clock: Default::default(),
            reset: Default::default(),
            io: Default::default(),
            modules: (0..q).map(|i| QueryModule::new(cfg, i)).collect(),
            arbiter: PortArbiter::new(q),
            grant_stage: Constant::new(cfg.pipelined),
            grant_reg: Default::default(),
            granted_reg: Default::default(),
            grant: Default::default(),
            granted: Default::default(),
            search: SearchModule::new(cfg),
            all_modules: Constant::new(ModuleMask::from(cfg.port_queries_mask())),
            requests: Default::default(),
            free_mask: Default::default(),
            free_pick: FreePick::new(q),
            load_now: Default::default(),
            load_data: Default::default(),
            ids: LutRam::new(q, cfg.id_bits()),
            query_fire: Default::default(),
            finished_mask: Default::default(),
            granted_read: Default::default(),
            read_pick: Default::default(),
            readout: ResultReadout::new(cfg, 1),
            photon_address: Default::default(),
            photon_dist: Default::default(),
            module_count: Default::default(),
            module_visited: Default::default(),
        }
    }
}

impl<const S: usize, const W: usize> Logic for SearchPort<S, W> {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(self, clock, load_now, load_data, grant_reg, granted_reg);
        clock!(self, clock, arbiter, search);
        self.search.reset.next = self.reset.val();
        self.search.photon_count.next = self.io.photon_count.val();
        self.search.word.next = self.io.ram_data.val();
        // (A QueryModule expects its word the next cycle: no banks.)
        self.io.bank.valid.next = false;
        self.io.bank.bank.next = 0.into();
        self.io.bank.row.next = 0.into();
        self.io.bank.tag.next = 0.into();

        // Collect the modules' status bits.
        self.requests.next = 0.into();
        self.free_mask.next = 0.into();
        self.finished_mask.next = 0.into();
        for i in 0..self.modules.len() {
            self.requests.next = self
                .requests
                .val()
                .replace_bit(i, self.modules[i].read_request.val());
            self.free_mask.next = self.free_mask.val().replace_bit(
                i,
                self.modules[i].free.val() && !self.load_now.q.val().get_bit(i),
            );
            self.finished_mask.next = self
                .finished_mask
                .val()
                .replace_bit(i, self.modules[i].finished.val());
        }
        // One read per cycle: every grant is used.
        self.arbiter.hold.next = false;
        self.arbiter.advance.next = self.arbiter.granted.val();
        self.grant_reg.d.next = self.arbiter.grant.val() & self.all_modules.val();
        self.granted_reg.d.next = self.arbiter.granted.val();
        if self.grant_stage.val() {
            // Decide the next cycle's grant; the module granted now is leaving READY.
            self.arbiter.requests.next = self.requests.val() & (!self.grant_reg.q.val());
            self.grant.next = self.grant_reg.q.val();
            self.granted.next = self.granted_reg.q.val();
        } else {
            self.arbiter.requests.next = self.requests.val();
            self.grant.next = self.arbiter.grant.val();
            self.granted.next = self.arbiter.granted.val();
        }
        if self.reset.val() {
            self.grant_reg.d.next = 0.into();
            self.granted_reg.d.next = false;
        }
        // Hand a query to the registered pick; the module loaded now is left out
        // of the next pick.
        self.free_pick.clock.next = self.clock.val();
        self.free_pick.reset.next = self.reset.val();
        self.free_pick.free.next = self.free_mask.val() & self.all_modules.val();
        self.io.query.ready.next = self.free_pick.pick_valid.val();
        self.query_fire.next = self.io.query.valid.val() && self.free_pick.pick_valid.val();
        self.free_pick.take.next = self.query_fire.val();
        self.load_now.d.next = 0.into();
        if self.query_fire.val() {
            self.load_now.d.next = self.free_pick.pick.val();
        }
        self.load_data.d.next = self.io.query.data.val();
        if self.reset.val() {
            self.load_now.d.next = 0.into();
        }
        // The loaded query's id and coordinates go to the picked module's entries.
        self.ids.clock.next = self.clock.val();
        self.ids.write_enable.next = self.query_fire.val();
        self.ids.write_index.next = self.free_pick.pick_index.val();
        self.ids.write_data.next = self.io.query.data.val().id;
        self.ids.read_index.next = self.readout.index.val();
        self.search.query_write.next = self.query_fire.val();
        self.search.query_module.next = self.free_pick.pick_index.val();
        self.search.query.next = self.io.query.data.val();

        // The granted read goes to the TreeModule and, with its context, the SearchModule.
        self.search.request_valid.next = self.granted.val();
        // The granted module's read: every module drives zeros unless granted, so
        // the selection is an OR over modules, not a chain of multiplexers.
        self.granted_read.next.query_module = 0.into();
        self.granted_read.next.address = 0.into();
        self.granted_read.next.up = false;
        self.granted_read.next.came_from_right = false;
        // (x, y, z: the SearchModule looks them up.)
        self.granted_read.next.x = 0.into();
        self.granted_read.next.y = 0.into();
        self.granted_read.next.z = 0.into();
        self.granted_read.next.radius = 0.into();
        self.granted_read.next.full = false;
        // The read-out: only the selected module drives its count and reads, only
        // the one being read its photons (the others give zeros), so the beat is an
        // OR over modules. One photon per beat (the found lists have one read port).
        self.module_count.next = 0.into();
        self.module_visited.next = 0.into();
        self.photon_address.next = 0.into();
        self.photon_dist.next = 0.into();
        for i in 0..self.modules.len() {
            self.modules[i].clock.next = self.clock.val();
            self.modules[i].reset.next = self.reset.val();
            self.modules[i].read_grant.next = self.grant.val().get_bit(i);
            self.read_pick.next = self.modules[i].read.val();
            self.granted_read.next.query_module =
                self.granted_read.val().query_module | self.read_pick.val().query_module;
            self.granted_read.next.address =
                self.granted_read.val().address | self.read_pick.val().address;
            self.granted_read.next.up = self.granted_read.val().up || self.read_pick.val().up;
            self.granted_read.next.came_from_right =
                self.granted_read.val().came_from_right || self.read_pick.val().came_from_right;
            self.granted_read.next.radius =
                self.granted_read.val().radius | self.read_pick.val().radius;
            self.granted_read.next.full = self.granted_read.val().full || self.read_pick.val().full;
            // SearchModule result broadcast.
            self.modules[i].result_valid.next = self.search.result_for.val().get_bit(i);
            self.modules[i].result.next = self.search.result.val();
            // Query hand-out broadcast, a cycle after the port took it; only the
            // picked module loads.
            self.modules[i].load.next = self.load_now.q.val().get_bit(i);
            self.modules[i].load_query.next = self.load_data.q.val();
            self.modules[i].out_enable.next = self.readout.select.val().get_bit(i);
            self.modules[i].out_entry.next = self.readout.entry.val();
            self.modules[i].out_reading.next = self.readout.reading.val().get_bit(i);
            self.module_count.next = self.module_count.val() | self.modules[i].out_count.val();
            self.module_visited.next =
                self.module_visited.val() | self.modules[i].out_visited.val();
            self.photon_address.next =
                self.photon_address.val() | self.modules[i].out_address.val();
            self.photon_dist.next = self.photon_dist.val() | self.modules[i].out_dist.val();
            // The last beat frees the selected module.
            self.modules[i].result_taken.next =
                self.readout.done.val() && self.readout.select.val().get_bit(i);
        }
        self.search.request.next = self.granted_read.val();
        self.io.ram_address.next = self.granted_read.val().address;

        // Result packets: the lowest finished module's.
        self.readout.clock.next = self.clock.val();
        self.readout.reset.next = self.reset.val();
        self.readout.finished.next = self.finished_mask.val();
        self.readout.count.next = self.module_count.val();
        self.readout.visited.next = self.module_visited.val();
        self.readout.id.next = self.ids.read_data.val();
        self.readout.address.next = self.photon_address.val();
        self.readout.distance.next = self.photon_dist.val();
        self.readout.pair.next = false;
        self.readout.address2.next = 0.into();
        self.readout.distance2.next = 0.into();
        self.io.result.valid.next = self.readout.result.valid.val();
        self.io.result.data.next = self.readout.result.data.val();
        self.readout.result.ready.next = self.io.result.ready.val();

        self.io.reading.next = self.granted.val();
        self.io.all_busy.next = (self.free_mask.val() & self.all_modules.val()) == 0;
        self.io.idle.next =
            (self.free_mask.val() & self.all_modules.val()) == self.all_modules.val();
    }
}
