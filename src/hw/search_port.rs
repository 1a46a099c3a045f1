//! SearchPort (paper §4.5): one TreeModule port with its Q QueryModules, the
//! round-robin PortArbiter and its own SearchModule, plus the hand-out of queries to
//! free QueryModules and the read-out of finished ones as a result stream.
//!
//! Query hand-out (issue 11): the free QueryModule that takes the next query is
//! picked one cycle ahead into a register (`load_pick`), so `query.ready` and every
//! module's load enable come from flip-flops. Combinationally (a module's state →
//! the port's free mask → lowest set bit → the core's dispatcher → another module's
//! load enable) this was the critical path of the 2 × 11 core on the ECP5 (62.1 MHz,
//! 12 nets). A free module stays free until it is loaded, so the registered pick is
//! still free when it is used; the module loaded in this cycle is left out of the
//! next pick. Cost: a module freed in cycle t can take a query in t + 1, not t.
//! The picked module then loads the query a cycle later, from registers
//! (`load_now`, `load_data`): the load enable of a module placed anywhere on the die
//! was the port's accepted-query AND (its stage's valid and the pick) fanned out to
//! all Q modules, the 2 × 12 core's ECP5 critical path on all three seeds once
//! `load.ready` was registered (83–89 MHz, 9–10 ns of 11–12 routing). A module
//! being loaded counts as taken (not free, not idle).
//!
//! Read grant (issue 11): with `CoreConfig::pipelined` the arbiter's grant is a
//! register. The grant for cycle t + 1 is decided in cycle t among the modules
//! requesting then, less the one granted in t (it leaves READY at that edge), so the
//! granted module's read reaches the TreeModule from flip-flops through the OR of
//! the modules' addresses only. Combinationally (a module's state → the round-robin
//! arbiter's priority chain → the grant → the OR tree → the BlockRAM address) this
//! was the ECP5 critical path of the 2 × 11 core (81.1 MHz, 8 nets). Cost: one cycle
//! more per read round trip (`CoreConfig::issue_interval`).
//!
//! Query ids (issue 11): only the read-out needs a query's id, so the port keeps
//! them in one LUT-RAM indexed by QueryModule (written at the load, read by the
//! module being read out) rather than in Q registers ORed together; the
//! coordinates are kept the same way by the SearchModule.
//!
//! Result stream, one beat per cycle when valid & ready: a header beat, then `count`
//! entry beats in found-list slot order ([`ResultBeat`]). The read-out takes the
//! selected module's count and photon reads into registers one cycle before its
//! header (issue 11: the module's count through the port's OR tree into `last` and
//! the sequencer was the critical path of the 2 × 11 core on the ECP5, 64.9 MHz), so
//! `last` and every sequencer decision come from flip-flops. The beats pass
//! through a [`ResultRegister`], so with `CoreConfig::pipelined` every result
//! output is a flip-flop and a result leaves one cycle after it is read out.

use crate::hw::config::{
    bits_for, low_mask, Addr, CoreConfig, Count, ModuleIndex, ModuleMask, ReadCount, Word,
};
use crate::hw::lut_ram::{LutRam, RamIndex};
use crate::hw::port_arbiter::PortArbiter;
use crate::hw::query_module::QueryModule;
use crate::hw::register_slice::ResultRegister;
use crate::hw::search_module::SearchModule;
use crate::hw::stream::{QueryBeat, ReadRequest, ResultBeat, StreamIn, StreamOut};
use rust_hdl::prelude::*;

#[derive(LogicBlock)]
pub struct SearchPort<const S: usize, const W: usize> {
    pub clock: Signal<In, Clock>,
    pub reset: Signal<In, bool>,
    pub photon_count: Signal<In, Addr>,
    /// TreeModule port: read address now, word next cycle.
    pub ram_address: Signal<Out, Addr>,
    pub ram_data: Signal<In, Word<W>>,
    /// Queries, ready while a QueryModule is free.
    pub query: StreamIn<QueryBeat>,
    /// Result packets.
    pub result: StreamOut<ResultBeat>,
    /// Status: a read was granted this cycle; every QueryModule is occupied; none is.
    pub reading: Signal<Out, bool>,
    pub all_busy: Signal<Out, bool>,
    pub idle: Signal<Out, bool>,
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
    result_register: ResultRegister,
    /// One bit per QueryModule of this port.
    all_modules: Constant<ModuleMask>,
    /// The bits of an entry index (0..K).
    entry_mask: Constant<RamIndex>,
    requests: Signal<Local, ModuleMask>,
    free_mask: Signal<Local, ModuleMask>,
    /// Free modules not loaded in this cycle: the candidates for the next pick.
    still_free: Signal<Local, ModuleMask>,
    /// The module the next query goes to (one-hot; zero: none free), and its index.
    load_pick: DFF<ModuleMask>,
    load_pick_index: DFF<ModuleIndex>,
    /// The module loading the query accepted last cycle (one-hot), and that query.
    load_now: DFF<ModuleMask>,
    load_data: DFF<QueryBeat>,
    next_pick: Signal<Local, ModuleMask>,
    next_pick_index: Signal<Local, ModuleIndex>,
    /// The lowest finished module (one-hot) and its index.
    finished_pick: Signal<Local, ModuleMask>,
    finished_pick_index: Signal<Local, ModuleIndex>,
    /// Index of each QueryModule, to turn a one-hot mask into a RAM index.
    module_index: Vec<Constant<ModuleIndex>>,
    /// The query id of each QueryModule's query.
    ids: LutRam,
    query_fire: Signal<Local, bool>,
    finished_mask: Signal<Local, ModuleMask>,
    result_fire: Signal<Local, bool>,
    /// The granted module's read (zero when none is granted: not valid then).
    granted_read: Signal<Local, ReadRequest>,
    read_pick: Signal<Local, ReadRequest>,
    /// The beat being read out, before the ResultRegister.
    beat: Signal<Local, ResultBeat>,
    out_active: DFF<bool>,
    out_select: DFF<ModuleMask>,
    /// Index of `out_select`'s module.
    out_index: DFF<ModuleIndex>,
    out_header: DFF<bool>,
    /// The entry being read out, and the module whose entries are (one-hot: each
    /// module's gate is one flip-flop).
    out_entry: DFF<RamIndex>,
    out_reading: DFF<ModuleMask>,
    out_left: DFF<Count>,
    /// The cycle after the selection: the module's header is being fetched.
    out_fetch: DFF<bool>,
    /// The selected module's count and photon reads, and `last` of the header
    /// (count = 0) and of the entry beat now (one entry left).
    hdr_count: DFF<Count>,
    hdr_visited: DFF<ReadCount>,
    hdr_last: DFF<bool>,
    out_last: DFF<bool>,
    /// The selected module's count and reads (an OR over the zero-gated modules).
    module_count: Signal<Local, Count>,
    module_visited: Signal<Local, ReadCount>,
}

impl<const S: usize, const W: usize> SearchPort<S, W> {
    pub fn new(cfg: &CoreConfig) -> Self {
        let q = cfg.queries_per_port;
        SearchPort {
            clock: Default::default(),
            reset: Default::default(),
            photon_count: Default::default(),
            ram_address: Default::default(),
            ram_data: Default::default(),
            query: Default::default(),
            result: Default::default(),
            reading: Default::default(),
            all_busy: Default::default(),
            idle: Default::default(),
            modules: (0..q).map(|i| QueryModule::new(cfg, i)).collect(),
            arbiter: PortArbiter::new(q),
            grant_stage: Constant::new(cfg.pipelined),
            grant_reg: Default::default(),
            granted_reg: Default::default(),
            grant: Default::default(),
            granted: Default::default(),
            search: SearchModule::new(cfg),
            result_register: ResultRegister::new(!cfg.pipelined),
            all_modules: Constant::new(ModuleMask::from(((1u64 << q) - 1) & 0xFFFF_FFFF)),
            entry_mask: Constant::new(RamIndex::from(low_mask(bits_for(
                cfg.k.saturating_sub(1) as u64
            )))),
            requests: Default::default(),
            free_mask: Default::default(),
            still_free: Default::default(),
            load_pick: Default::default(),
            load_pick_index: Default::default(),
            load_now: Default::default(),
            load_data: Default::default(),
            next_pick: Default::default(),
            next_pick_index: Default::default(),
            finished_pick: Default::default(),
            finished_pick_index: Default::default(),
            module_index: (0..q)
                .map(|i| Constant::new(ModuleIndex::from(i as u64)))
                .collect(),
            ids: LutRam::new(q, cfg.id_bits()),
            query_fire: Default::default(),
            finished_mask: Default::default(),
            result_fire: Default::default(),
            granted_read: Default::default(),
            read_pick: Default::default(),
            beat: Default::default(),
            out_active: Default::default(),
            out_select: Default::default(),
            out_index: Default::default(),
            out_header: Default::default(),
            out_entry: Default::default(),
            out_reading: Default::default(),
            out_left: Default::default(),
            out_fetch: Default::default(),
            hdr_count: Default::default(),
            hdr_visited: Default::default(),
            hdr_last: Default::default(),
            out_last: Default::default(),
            module_count: Default::default(),
            module_visited: Default::default(),
        }
    }
}

impl<const S: usize, const W: usize> Logic for SearchPort<S, W> {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(
            self,
            clock,
            load_pick,
            load_pick_index,
            load_now,
            load_data,
            grant_reg,
            granted_reg,
            out_active,
            out_select,
            out_index,
            out_header,
            out_entry,
            out_reading,
            out_left,
            out_fetch,
            hdr_count,
            hdr_visited,
            hdr_last,
            out_last
        );
        self.arbiter.clock.next = self.clock.val();
        self.search.clock.next = self.clock.val();
        self.search.reset.next = self.reset.val();
        self.search.photon_count.next = self.photon_count.val();
        self.search.word.next = self.ram_data.val();

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
        // Hand a query to the registered pick; pick the lowest free module, other
        // than the one loaded now, for the next cycle.
        self.query.ready.next = self.load_pick.q.val().any();
        self.query_fire.next = self.query.valid.val() && self.load_pick.q.val().any();
        self.still_free.next = self.free_mask.val() & self.all_modules.val();
        if self.query_fire.val() {
            self.still_free.next =
                self.free_mask.val() & self.all_modules.val() & !self.load_pick.q.val();
        }
        self.next_pick.next = self.still_free.val() & ((!self.still_free.val()) + 1);
        self.finished_pick.next = self.finished_mask.val() & ((!self.finished_mask.val()) + 1);
        self.next_pick_index.next = 0.into();
        self.finished_pick_index.next = 0.into();
        for i in 0..self.module_index.len() {
            if self.next_pick.val().get_bit(i) {
                self.next_pick_index.next = self.next_pick_index.val() | self.module_index[i].val();
            }
            if self.finished_pick.val().get_bit(i) {
                self.finished_pick_index.next =
                    self.finished_pick_index.val() | self.module_index[i].val();
            }
        }
        self.load_pick.d.next = self.next_pick.val();
        self.load_pick_index.d.next = self.next_pick_index.val();
        self.load_now.d.next = 0.into();
        if self.query_fire.val() {
            self.load_now.d.next = self.load_pick.q.val();
        }
        self.load_data.d.next = self.query.data.val();
        if self.reset.val() {
            self.load_pick.d.next = 0.into();
            self.load_now.d.next = 0.into();
        }
        // The loaded query's id and coordinates go to the picked module's entries.
        self.ids.clock.next = self.clock.val();
        self.ids.write_enable.next = self.query_fire.val();
        self.ids.write_index.next = self.load_pick_index.q.val();
        self.ids.write_data.next = self.query.data.val().id;
        self.ids.read_index.next = self.out_index.q.val();
        self.search.query_write.next = self.query_fire.val();
        self.search.query_module.next = self.load_pick_index.q.val();
        self.search.query.next = self.query.data.val();

        // Read-out sequencer signals (registered state, see below).
        self.result_fire.next = self.out_active.q.val()
            && (!self.out_fetch.q.val())
            && self.result_register.inbound.ready.val();
        self.beat.next.header = self.out_header.q.val();
        self.beat.next.id = 0.into();
        if self.out_active.q.val() {
            self.beat.next.id = self.ids.read_data.val();
        }
        self.beat.next.count = self.hdr_count.q.val();
        self.beat.next.visited = self.hdr_visited.q.val();
        self.module_count.next = 0.into();
        self.module_visited.next = 0.into();
        self.beat.next.address = 0.into();
        self.beat.next.distance = 0.into();
        // One photon per beat (the QueryModules' found lists have one read port).
        self.beat.next.pair = false;
        self.beat.next.address2 = 0.into();
        self.beat.next.distance2 = 0.into();

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
            // Result read-out: only the selected module sees a slot and drives its
            // outputs (the others give zeros), so the beat is an OR over modules.
            self.modules[i].out_enable.next = self.out_select.q.val().get_bit(i);
            self.modules[i].out_entry.next = self.out_entry.q.val();
            self.modules[i].out_reading.next = self.out_reading.q.val().get_bit(i);
            self.module_count.next = self.module_count.val() | self.modules[i].out_count.val();
            self.module_visited.next =
                self.module_visited.val() | self.modules[i].out_visited.val();
            self.beat.next.address = self.beat.val().address | self.modules[i].out_address.val();
            self.beat.next.distance = self.beat.val().distance | self.modules[i].out_dist.val();
        }
        self.search.request.next = self.granted_read.val();
        self.ram_address.next = self.granted_read.val().address;
        if self.out_header.q.val() {
            self.beat.next.last = self.hdr_last.q.val();
        } else {
            self.beat.next.last = self.out_last.q.val();
        }
        // The last beat frees the selected module.
        for i in 0..self.modules.len() {
            self.modules[i].result_taken.next = self.result_fire.val()
                && self.beat.val().last
                && self.out_select.q.val().get_bit(i);
        }
        // The beat leaves through the ResultRegister.
        self.result_register.clock.next = self.clock.val();
        self.result_register.reset.next = self.reset.val();
        self.result_register.inbound.valid.next =
            self.out_active.q.val() && (!self.out_fetch.q.val());
        self.result_register.inbound.data.next = self.beat.val();
        self.result_register.outbound.ready.next = self.result.ready.val();
        self.result.valid.next = self.result_register.outbound.valid.val();
        self.result.data.next = self.result_register.outbound.data.val();

        // Read-out sequencer: pick a finished module, fetch its header, stream the
        // header then the entries.
        if !self.out_active.q.val() {
            if self.finished_mask.val().any() {
                self.out_active.d.next = true;
                self.out_fetch.d.next = true;
                self.out_select.d.next = self.finished_pick.val();
                self.out_index.d.next = self.finished_pick_index.val();
            }
        } else if self.out_fetch.q.val() {
            self.out_fetch.d.next = false;
            self.out_header.d.next = true;
            self.hdr_count.d.next = self.module_count.val();
            self.hdr_visited.d.next = self.module_visited.val();
            self.hdr_last.d.next = self.module_count.val() == 0;
        } else if self.result_fire.val() {
            if self.out_header.q.val() {
                self.out_header.d.next = false;
                self.out_entry.d.next = 0.into();
                self.out_reading.d.next = self.out_select.q.val();
                self.out_left.d.next = self.hdr_count.q.val();
                self.out_last.d.next = self.hdr_count.q.val() == 1;
            } else {
                self.out_entry.d.next = (self.out_entry.q.val() + 1) & self.entry_mask.val();
                self.out_left.d.next = self.out_left.q.val() - 1;
                self.out_last.d.next = self.out_left.q.val() == 2;
            }
            if self.beat.val().last {
                self.out_active.d.next = false;
                self.out_select.d.next = 0.into();
                self.out_index.d.next = 0.into();
                self.out_reading.d.next = 0.into();
            }
        }
        if self.reset.val() {
            self.out_active.d.next = false;
            self.out_fetch.d.next = false;
            self.out_select.d.next = 0.into();
            self.out_index.d.next = 0.into();
            self.out_reading.d.next = 0.into();
        }

        self.reading.next = self.granted.val();
        self.all_busy.next = (self.free_mask.val() & self.all_modules.val()) == 0;
        self.idle.next = (self.free_mask.val() & self.all_modules.val()) == self.all_modules.val();
    }
}
