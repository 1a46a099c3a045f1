//! BarrelPort: one TreeModule port whose Q queries share one traversal datapath
//! (`Controller::Barrel`). The interface is the [`SearchPort`]'s.
//!
//! Why: a port reads at most one photon per cycle, so at most one query per cycle
//! has anything to decide. The paper's port (§4.5) gives each of its Q queries a
//! whole QueryModule (MaxFinder, comparators, state machine), all but one waiting
//! in any cycle, and the QueryModules are most of the core's logic.
//! Here a query is a slot: its state lives in LUT-RAM and BlockRAM entries, and a
//! result is processed by a pipeline that reads the slot's state, updates it and
//! issues the slot's next read, one event per cycle, like a barrel processor.
//! Waiting costs memory bits, not logic. Only the traversals that remember the
//! path (`Remember`, `Cell`) are supported: the ascent is one step (below).
//!
//! An event is a SearchModule result, or (in a cycle without one) a new query
//! loaded into a free slot. It flows through seven stages; a slot has at most one
//! event or read in flight, so a stage never meets another event of its own slot
//! and the state read in stage A is always the one written by the slot's last
//! event in stage F:
//! * **A** — read the slot's state (LUT-RAM, asynchronous, by slot index); a
//!   photon in range enters the found list ([`FoundRule`], the QueryModule's);
//!   this level's pending bit.
//! * **B** — this level's pruning bound and (`Cell`) far-cell offsets are
//!   remembered (from registers: A's path would grow; external memory: written
//!   in C, [`PathWrite`]).
//! * **B**, **C**, **M** — when the list became or was full, its new maximum and
//!   the lowest slot holding it: a tree of comparators over the K entries, one
//!   level in B, two in C, the rest in M (paper §4.4 finds it bit-serially, one
//!   cycle per distance bit, per QueryModule; one pipelined tree per port costs
//!   less than Q MaxFinders and no cycles). Above
//!   [`FOUND_TREE_MAX_K`](crate::hw::config::core_config::FOUND_TREE_MAX_K) entries (the paper's
//!   high-quality regime, §3, wants 500) a tree over K entries grows linearly, so
//!   the lists are max-heaps in BlockRAM instead ([`FoundHeap`]): the insertion
//!   enters the heap in A, the new root leaves it in C, log2 K levels of one
//!   comparison each, the same maximum and the same entry.
//! * **D** — the ascent in one step ([`Ascent`]: the path memory of
//!   `Traversal::Remember`, searched at once): the deepest level above with a pending far child within
//!   R is where the search goes next; none: the search is over. Climbing one level
//!   per cycle (as a QueryModule does) would cost a pipeline pass per level.
//! * **E** — the far child's address; its cell's offsets are read (BlockRAM).
//! * **F** — the slot's new state is written and its next read issued.
//!
//! Reads per query are those of the software search (`knn::search_with`), read for
//! read; only the order in which the port interleaves its queries differs. A read
//! issued in F returns to A four cycles later (the SearchModule's pipeline), so a
//! slot reads every 11 cycles and 16 slots keep the port busy
//! ([`BARREL_SLOTS`](crate::hw::config::core_config::BARREL_SLOTS)); from a banked store later,
//! when its bank is free ([`ReadIssue`]).
//!
//! Result read-out is the SearchPort's packet format, two photons a beat from two
//! BlockRAMs written as photons enter the list ([`SlotReadout`]; [`ResultBeat`](crate::hw::primitives::stream::ResultBeat) says why two).

use crate::hw::barrel::ascent::{Ascent, Climb};
use crate::hw::barrel::found_heap::FoundHeap;
use crate::hw::barrel::found_max::FoundMax;
use crate::hw::barrel::heap_stage::{HeapKey, HeapOp};
use crate::hw::barrel::path_write::PathWrite;
use crate::hw::barrel::slot_readout::SlotReadout;
use crate::hw::barrel::slot_store::{SlotEvent, SlotStore};
use crate::hw::config::core_config::{
    bits_for, low_mask, Addr, CoreConfig, Dist, Entry, LevelMask, ModuleIndex, ModuleMask,
    ReadCount,
};
use crate::hw::config::traversal::Traversal;
use crate::hw::datapath::far_cell_dist::FarCellDist;
use crate::hw::datapath::found_rule::FoundRule;
use crate::hw::datapath::query_limits::QueryLimits;
use crate::hw::datapath::search_module::SearchModule;
use crate::hw::primitives::bank_bus::{BankAnswerIn, BankRequester};
use crate::hw::primitives::block_ram::{BlockRam, BramIndex, BramWord};
use crate::hw::primitives::free_pick::FreePick;
use crate::hw::primitives::lut_ram::RamIndex;
use crate::hw::primitives::stream::PortIo;
use crate::hw::store::read_issue::ReadIssue;
use rust_hdl::prelude::*;

#[derive(LogicBlock)]
pub struct BarrelPort<const W: usize> {
    pub clock: Signal<In, Clock>,
    pub reset: Signal<In, bool>,
    /// Photon count, TreeModule port, queries (ready while a slot is free and no
    /// result takes stage A), result packets, status (a read was issued this
    /// cycle; every slot is occupied; none is).
    pub io: PortIo<W>,
    search: SearchModule<W>,
    /// Stage F's reads to the tree or the banks ([`ReadIssue`]).
    issue: ReadIssue<W>,
    /// `Traversal::Cell`: prune on the far cell's distance, restore its offsets.
    cell_mode: Constant<bool>,
    all_slots: Constant<ModuleMask>,
    one_level: Constant<LevelMask>,
    /// The widths the configuration needs (every register is loaded through them).
    dist_mask: Constant<Dist>,
    addr_mask: Constant<Addr>,
    visited_mask: Constant<ReadCount>,
    level_mask: Constant<RamIndex>,
    pending_mask: Constant<LevelMask>,
    entry_mask: Constant<Entry>,
    /// Levels of a slot in the offsets BlockRAMs (2^level_shift), and where the
    /// second offset of a word starts (the distance bits).
    level_shift: Constant<BramIndex>,
    dist_shift: Constant<Bits<8>>,
    dist_mask_wide: Constant<BramWord>,
    /// The slot state, one LUT-RAM entry per slot and field: read in A, written in F.
    store: SlotStore,
    /// Found distances and the comparator tree (stages B, C, M) for K <= 64 (above: a stub);
    /// above, heaps (in at A, root out at C, registered into M) keyed by distance over the
    /// inverted entry index: the root is the farthest photon, lowest entry among ties.
    found_max: FoundMax,
    heap: Vec<FoundHeap>,
    heap_max: Vec<DFF<HeapKey>>,
    heap_key_shift: Constant<Bits<8>>,
    heap_entry_mask: Constant<HeapKey>,
    no_heap_op: Constant<HeapOp>,
    heap_mode: Constant<bool>,
    /// The heap operation of this event (stage A) and the root it left (stage M).
    a_heap_op: Signal<Local, HeapOp>,
    m_heap_max: Signal<Local, HeapKey>,
    /// Each level's pruning bound (written in B) and the ascent over them (D).
    ascent: Ascent,
    /// `Cell`: per (slot, level), the offsets inside the level's far cell: x | y,
    /// and z | the far cell's distance. Written in B, read in E.
    far_xy: BlockRam,
    far_zd: BlockRam,
    /// External memory only: the path memory's writes a cycle later ([`PathWrite`]).
    path_write: Vec<PathWrite>,
    /// The result stream: found photons, ids and headers until read out.
    readout: SlotReadout,
    free: DFF<ModuleMask>,
    // Stage A.
    a_result: Signal<Local, bool>,
    a_load: Signal<Local, bool>,
    a_slot: Signal<Local, ModuleIndex>,
    a_ev: Signal<Local, SlotEvent>,
    a_insert: Signal<Local, bool>,
    /// The found list's rule and a new query's radius and k.
    a_rule: FoundRule<Entry>,
    a_limits: QueryLimits,
    /// The visited photon's far cell (`Cell`), from the slot's offsets.
    far_cell: FarCellDist,
    a_level_bit: Signal<Local, LevelMask>,
    /// This level's pruning bound, and (`Cell`) its entry of the offsets BlockRAMs.
    b_bound: Signal<Local, Dist>,
    b_far_index: Signal<Local, BramIndex>,
    b_far_xy: Signal<Local, BramWord>,
    b_far_zd: Signal<Local, BramWord>,
    /// The slot the next query goes to, picked a cycle ahead.
    free_pick: FreePick,
    // Stages B, C, M (the comparator tree is `found_max`'s).
    b_ev: DFF<SlotEvent>,
    c_ev: DFF<SlotEvent>,
    m_ev: DFF<SlotEvent>,
    // Stage D: the ascent.
    d_ev: DFF<SlotEvent>,
    // Stage E.
    e_ev: DFF<SlotEvent>,
    e_climb: DFF<Climb>,
    /// Levels from this node up to the target's child: the shift to its ancestor.
    e_shift: Signal<Local, RamIndex>,
    /// The (slot, target level) entry of the far-cell offsets BlockRAMs.
    e_far_index: Signal<Local, BramIndex>,
    // Stage F.
    f_ev: DFF<SlotEvent>,
    f_climb: DFF<Climb>,
    /// The far child's heap address: the next read when the search climbs.
    f_jump: DFF<Addr>,
    /// The query is over (no target), and whether a read is issued this cycle.
    f_done: Signal<Local, bool>,
    f_issue: Signal<Local, bool>,
    /// The slot's state as written back (and the next read's address).
    f_state: Signal<Local, SlotEvent>,
    /// A query beat is taken this cycle (valid and ready).
    query_fire: Signal<Local, bool>,
}

/// The BlockRAMs of one barrel datapath of `cfg` (found lists, far-cell bounds, heap levels;
/// not the map's replica or banks): (index bits, width) each, for a device plan's count.
pub fn datapath_block_rams(cfg: &CoreConfig) -> Vec<(u32, u32)> {
    fn rams<const S: usize, const W: usize>(cfg: &CoreConfig) -> Vec<(u32, u32)> {
        BarrelPort::<W>::new(cfg).block_rams()
    }
    crate::dispatch_widths!(cfg, rams(cfg))
}

impl<const W: usize> BarrelPort<W> {
    /// This datapath's BlockRAMs ([`datapath_block_rams`]).
    pub fn block_rams(&self) -> Vec<(u32, u32)> {
        let mut rams = BlockRam::shapes([&self.far_xy, &self.far_zd]);
        rams.extend(self.readout.block_rams());
        for h in &self.heap {
            rams.extend(h.block_rams());
        }
        rams
    }

    pub fn new(cfg: &CoreConfig) -> Self {
        let q = cfg.queries_per_port;
        let cell = cfg.traversal == Traversal::Cell;
        let db = cfg.dist_bits();
        let levels = cfg.path_levels().max(1);
        let level_bits = bits_for(levels.saturating_sub(1) as u64);
        let slot_bits = bits_for(q.saturating_sub(1) as u64);
        let cell_bits = if cell { db } else { 1 };
        let far_index_bits = if cell { slot_bits + level_bits } else { 1 };
        let heap = cfg.uses_found_heap();
        BarrelPort {
            clock: Default::default(),
            reset: Default::default(),
            io: Default::default(),
            search: SearchModule::new(cfg),
            issue: ReadIssue::new(cfg),
            cell_mode: Constant::new(cell),
            all_slots: Constant::new(ModuleMask::from(cfg.port_queries_mask())),
            one_level: Constant::new(LevelMask::from(1u64)),
            dist_mask: Constant::new(Dist::from(cfg.dist_mask())),
            addr_mask: Constant::new(Addr::from(cfg.addr_mask())),
            visited_mask: Constant::new(ReadCount::from(cfg.visited_mask())),
            level_mask: Constant::new(RamIndex::from(cfg.level_index_mask())),
            pending_mask: Constant::new(LevelMask::from(cfg.pending_mask())),
            entry_mask: Constant::new(Entry::from(cfg.entry_mask())),
            level_shift: Constant::new(BramIndex::from(level_bits as u64)),
            dist_shift: Constant::new(Bits::<8>::from(db as u64)),
            dist_mask_wide: Constant::new(BramWord::from(cfg.dist_mask())),
            store: SlotStore::new(cfg),
            found_max: FoundMax::new(&CoreConfig {
                k: if heap { 1 } else { cfg.k },
                ..*cfg
            }),
            heap: (0..heap as usize)
                .map(|_| FoundHeap::new(cfg.heap_levels(), slot_bits.max(1)))
                .collect(),
            heap_max: (0..heap as usize).map(|_| Default::default()).collect(),
            heap_key_shift: Constant::new(Bits::<8>::from(cfg.entry_bits() as u64)),
            heap_entry_mask: Constant::new(HeapKey::from(low_mask(cfg.entry_bits()))),
            no_heap_op: Constant::new(HeapOp::default()),
            heap_mode: Constant::new(heap),
            a_heap_op: Default::default(),
            m_heap_max: Default::default(),
            ascent: Ascent::new(cfg),
            far_xy: BlockRam::new(far_index_bits, 2 * cell_bits),
            far_zd: BlockRam::new(far_index_bits, 2 * cell_bits),
            path_write: (0..usize::from(cfg.memory.is_some()))
                .map(|_| PathWrite::default())
                .collect(),
            readout: SlotReadout::new(cfg),
            free: Default::default(),
            a_result: Default::default(),
            a_load: Default::default(),
            a_slot: Default::default(),
            a_ev: Default::default(),
            a_insert: Default::default(),
            a_rule: FoundRule::new(cfg),
            a_limits: QueryLimits::new(cfg),
            a_level_bit: Default::default(),
            far_cell: FarCellDist::for_config(cfg),
            b_bound: Default::default(),
            b_far_index: Default::default(),
            b_far_xy: Default::default(),
            b_far_zd: Default::default(),
            free_pick: FreePick::new(q),
            b_ev: Default::default(),
            c_ev: Default::default(),
            m_ev: Default::default(),
            d_ev: Default::default(),
            e_ev: Default::default(),
            e_climb: Default::default(),
            e_shift: Default::default(),
            e_far_index: Default::default(),
            f_ev: Default::default(),
            f_climb: Default::default(),
            f_jump: Default::default(),
            f_done: Default::default(),
            f_issue: Default::default(),
            f_state: Default::default(),
            query_fire: Default::default(),
        }
    }
}

impl<const W: usize> Logic for BarrelPort<W> {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(self, clock, free, b_ev, c_ev, m_ev, d_ev, e_ev, e_climb, f_ev, f_climb, f_jump);
        self.search.clock.next = self.clock.val();
        self.search.reset.next = self.reset.val();
        self.search.photon_count.next = self.io.photon_count.val();
        clock!(self, clock, store, found_max, far_xy, far_zd, readout, issue);
        self.readout.reset.next = self.reset.val();
        self.issue.reset.next = self.reset.val();

        // ---- Stage A: a result, else a new query into the picked free slot. ----
        // The free slot is picked a cycle ahead ([`FreePick`], the SearchPort's):
        // the slot index that addresses every state LUT-RAM then comes from
        // flip-flops through one multiplexer.
        self.a_result.next = self.search.result_valid.val();
        self.free_pick.clock.next = self.clock.val();
        self.free_pick.reset.next = self.reset.val();
        self.free_pick.free.next = self.free.q.val();
        self.io.query.ready.next =
            self.free_pick.pick_valid.val() && (!self.search.result_valid.val());
        self.query_fire.next = self.io.query.valid.val() && self.io.query.ready.val();
        self.a_load.next = self.query_fire.val();
        self.free_pick.take.next = self.a_load.val();
        if self.a_result.val() {
            self.a_slot.next = self.search.result.val().query_module;
        } else {
            self.a_slot.next = self.free_pick.pick_index.val();
        }
        // The slot's state as read, then this result's changes; only a result needs it or
        // inserts (a load sets every field), so both use the result's slot, not the load mux.
        self.store.read_index.next = self.search.result.val().query_module;
        self.a_ev.next = self.store.read.val();
        self.a_ev.next.slot = self.a_slot.val();
        self.a_ev.next.valid = self.a_result.val() || self.a_load.val();
        self.a_ev.next.load = self.a_load.val();
        self.a_ev.next.visited = (self.store.read.val().visited + 1) & self.visited_mask.val();
        self.a_ev.next.up = self.search.result.val().next_up;
        self.a_ev.next.address = self.search.result.val().address & self.addr_mask.val();
        self.a_ev.next.next_address = self.search.result.val().next_address & self.addr_mask.val();
        self.a_ev.next.result = self.a_result.val();
        self.a_ev.next.axis = self.search.result.val().axis;
        self.a_ev.next.axis_dist = self.search.result.val().axis_dist & self.dist_mask.val();
        self.a_ev.next.far_pending = self.search.result.val().far_pending;

        // The found list ([`FoundRule`]): a photon in range is appended or replaces
        // the maximum; filling the list or replacing in it sets a new R (stage M).
        // (The rule reads the state as read, before this event's changes.)
        self.a_insert.next = self.a_result.val() && self.search.result.val().in_range;
        self.a_rule.insert.next = self.a_insert.val();
        self.a_rule.full.next = self.store.read.val().full;
        self.a_rule.count.next = self.store.read.val().count;
        self.a_rule.k.next = self.store.read.val().k;
        self.a_rule.append_at.next = self.store.read.val().count;
        self.a_rule.max_at.next = self.store.read.val().max_pos;
        if self.a_rule.run_max.val() {
            self.a_ev.next.run_max = true;
        }
        if self.a_rule.fills.val() {
            self.a_ev.next.full = true;
        }
        if self.a_rule.appends.val() {
            self.a_ev.next.count = self.a_rule.next_count.val();
        }
        self.found_max.write_enable.next = self.a_insert.val();
        self.found_max.write_slot.next = self.search.result.val().query_module;
        self.found_max.write_pos.next = self.a_rule.at.val();
        self.found_max.write_dist.next = self.search.result.val().distance;
        // (Heaps: the same insertion as a heap insert or a replacement of the root.)
        self.a_heap_op.next = self.no_heap_op.val();
        self.a_heap_op.next.valid = self.a_insert.val();
        self.a_heap_op.next.replace = self.store.read.val().full;
        self.a_heap_op.next.slot = self.search.result.val().query_module;
        self.a_heap_op.next.key = (self.search.result.val().distance << self.heap_key_shift.val())
            | (bit_cast::<32, 16>(!self.a_rule.at.val()) & self.heap_entry_mask.val());
        if self.store.read.val().full {
            self.a_heap_op.next.size = self.store.read.val().k;
        } else {
            self.a_heap_op.next.size = self.a_rule.next_count.val();
        }
        for h in 0..self.heap.len() {
            self.heap[h].clock.next = self.clock.val();
            self.heap[h].op.next = self.a_heap_op.val();
        }
        self.readout.found_write.next = self.a_insert.val();
        self.readout.found_slot.next = self.search.result.val().query_module;
        self.readout.found_pos.next = self.a_rule.at.val();
        self.readout.found_address.next = self.search.result.val().address;
        self.readout.found_dist.next = self.search.result.val().distance;

        // The path memory of this level: its far child's pruning bound and whether
        // that child is still to be visited; `Cell`: the offsets inside it.
        self.a_level_bit.next = self.one_level.val() << self.a_ev.val().level;
        if self.search.result.val().far_pending {
            self.a_ev.next.pending =
                (self.store.read.val().pending | self.a_level_bit.val()) & self.pending_mask.val();
        } else {
            self.a_ev.next.pending =
                self.store.read.val().pending & (!self.a_level_bit.val()) & self.pending_mask.val();
        }

        // A new query: the root is read first, with the initial radius and k
        // ([`QueryLimits`], the QueryModule's).
        self.a_limits.query.next = self.io.query.data.val();
        if self.a_load.val() {
            self.a_ev.next.radius = self.a_limits.radius.val();
            self.a_ev.next.k = self.a_limits.k.val();
            self.a_ev.next.full = false;
            self.a_ev.next.count = 0.into();
            self.a_ev.next.max_pos = 0.into();
            self.a_ev.next.visited = 0.into();
            self.a_ev.next.level = 0.into();
            self.a_ev.next.pending = 0.into();
            self.a_ev.next.up = false;
            self.a_ev.next.address = 0.into();
            self.a_ev.next.next_address = 1.into();
            self.a_ev.next.off_x = 0.into();
            self.a_ev.next.off_y = 0.into();
            self.a_ev.next.off_z = 0.into();
            self.a_ev.next.cell_dist = 0.into();
        }
        self.readout.id_write.next = self.a_load.val();
        self.readout.id_slot.next = self.a_slot.val();
        self.readout.id.next = self.io.query.data.val().id;
        self.search.query_write.next = self.a_load.val();
        self.search.query_module.next = self.a_slot.val();
        self.search.query.next = self.io.query.data.val();

        // ---- Stage B (first part): the path memory of the level just read. ----
        // Its far child's pruning bound (`Cell`: the far cell's distance, from the offsets as
        // read in A) and the offsets inside that cell (in A, the state read, this sum and the
        // BlockRAM's write would be one path). The ascent reads them two stages later, for
        // levels above this one, written by earlier events (external memory: written in C).
        self.far_cell.off_x.next = self.b_ev.q.val().off_x;
        self.far_cell.off_y.next = self.b_ev.q.val().off_y;
        self.far_cell.off_z.next = self.b_ev.q.val().off_z;
        self.far_cell.cell_dist.next = self.b_ev.q.val().cell_dist;
        self.far_cell.axis.next = self.b_ev.q.val().axis;
        self.far_cell.axis_dist.next = self.b_ev.q.val().axis_dist;
        self.b_bound.next = self.b_ev.q.val().axis_dist;
        if self.cell_mode.val() {
            self.b_bound.next = self.far_cell.far_dist.val();
        }
        self.ascent.clock.next = self.clock.val();
        self.ascent.write_enable.next = self.b_ev.q.val().result;
        self.ascent.write_level.next = self.b_ev.q.val().level;
        self.ascent.write_slot.next = self.b_ev.q.val().slot;
        self.ascent.write_bound.next = self.b_bound.val();
        // (Only a level whose far child is pending is ever entered.)
        self.b_far_index.next = (bit_cast::<16, 8>(self.b_ev.q.val().slot)
            << self.level_shift.val())
            | bit_cast::<16, 8>(self.b_ev.q.val().level);
        self.b_far_xy.next = bit_cast::<64, 32>(self.b_ev.q.val().off_x);
        if self.b_ev.q.val().axis == 0 {
            self.b_far_xy.next = bit_cast::<64, 32>(self.b_ev.q.val().axis_dist);
        }
        if self.b_ev.q.val().axis == 1 {
            self.b_far_xy.next = self.b_far_xy.val()
                | (bit_cast::<64, 32>(self.b_ev.q.val().axis_dist) << self.dist_shift.val());
        } else {
            self.b_far_xy.next = self.b_far_xy.val()
                | (bit_cast::<64, 32>(self.b_ev.q.val().off_y) << self.dist_shift.val());
        }
        if self.b_ev.q.val().axis == 2 {
            self.b_far_zd.next = bit_cast::<64, 32>(self.b_ev.q.val().axis_dist);
        } else {
            self.b_far_zd.next = bit_cast::<64, 32>(self.b_ev.q.val().off_z);
        }
        self.b_far_zd.next =
            self.b_far_zd.val() | (bit_cast::<64, 32>(self.b_bound.val()) << self.dist_shift.val());
        self.far_xy.write_enable.next =
            self.b_ev.q.val().result && self.cell_mode.val() && self.b_ev.q.val().far_pending;
        self.far_zd.write_enable.next =
            self.b_ev.q.val().result && self.cell_mode.val() && self.b_ev.q.val().far_pending;
        self.far_xy.write_index.next = self.b_far_index.val();
        self.far_zd.write_index.next = self.b_far_index.val();
        self.far_xy.write_data.next = self.b_far_xy.val();
        self.far_zd.write_data.next = self.b_far_zd.val();
        for p in 0..self.path_write.len() {
            self.path_write[p].clock.next = self.clock.val();
            self.path_write[p].bound_write.next = self.b_ev.q.val().result;
            self.path_write[p].level.next = self.b_ev.q.val().level;
            self.path_write[p].slot.next = self.b_ev.q.val().slot;
            self.path_write[p].bound.next = self.b_bound.val();
            self.path_write[p].far_write.next =
                self.b_ev.q.val().result && self.cell_mode.val() && self.b_ev.q.val().far_pending;
            self.path_write[p].far_index.next = self.b_far_index.val();
            self.path_write[p].far_xy.next = self.b_far_xy.val();
            self.path_write[p].far_zd.next = self.b_far_zd.val();
            self.ascent.write_enable.next = self.path_write[p].c_bound_write.val();
            self.ascent.write_level.next = self.path_write[p].c_level.val();
            self.ascent.write_slot.next = self.path_write[p].c_slot.val();
            self.ascent.write_bound.next = self.path_write[p].c_bound.val();
            self.far_xy.write_enable.next = self.path_write[p].c_far_write.val();
            self.far_zd.write_enable.next = self.path_write[p].c_far_write.val();
            self.far_xy.write_index.next = self.path_write[p].c_far_index.val();
            self.far_zd.write_index.next = self.path_write[p].c_far_index.val();
            self.far_xy.write_data.next = self.path_write[p].c_far_xy.val();
            self.far_zd.write_data.next = self.path_write[p].c_far_zd.val();
        }

        // ---- Stages B, C, M: the new maximum (the comparator tree). ----
        self.b_ev.d.next = self.a_ev.val();
        self.found_max.read_slot.next = self.b_ev.q.val().slot;
        self.found_max.read_k.next = self.b_ev.q.val().k;
        self.c_ev.d.next = self.b_ev.q.val();
        self.m_ev.d.next = self.c_ev.q.val();
        self.d_ev.d.next = self.m_ev.q.val();
        if self.m_ev.q.val().run_max {
            self.d_ev.d.next.radius = self.found_max.max.val() & self.dist_mask.val();
            self.d_ev.d.next.max_pos = self.found_max.max_pos.val() & self.entry_mask.val();
        }
        self.m_heap_max.next = 0.into();
        for h in 0..self.heap_max.len() {
            self.heap_max[h].clock.next = self.clock.val();
            self.heap_max[h].d.next = self.heap[h].max.val();
            self.m_heap_max.next = self.heap_max[h].q.val();
        }
        if self.heap_mode.val() && self.m_ev.q.val().run_max {
            self.d_ev.d.next.radius =
                (self.m_heap_max.val() >> self.heap_key_shift.val()) & self.dist_mask.val();
            self.d_ev.d.next.max_pos =
                bit_cast::<16, 32>((!self.m_heap_max.val()) & self.heap_entry_mask.val());
        }

        // ---- Stage D: the ascent in one step ([`Ascent`]). ----
        self.ascent.read_slot.next = self.d_ev.q.val().slot;
        self.ascent.level.next = self.d_ev.q.val().level;
        self.ascent.pending.next = self.d_ev.q.val().pending;
        self.ascent.full.next = self.d_ev.q.val().full;
        self.ascent.radius.next = self.d_ev.q.val().radius;
        self.e_ev.d.next = self.d_ev.q.val();
        self.e_climb.d.next = self.ascent.climb.val();

        // ---- Stage E: the far child's address; its cell's offsets are read. ----
        // The far child is the sibling of the path's node one level below the
        // target: this node's ancestor there.
        self.e_shift.next =
            ((self.e_ev.q.val().level - self.e_climb.q.val().target) - 1) & self.level_mask.val();
        self.f_jump.d.next =
            ((self.e_ev.q.val().address >> self.e_shift.val()) ^ 1) & self.addr_mask.val();
        self.e_far_index.next = (bit_cast::<16, 8>(self.e_ev.q.val().slot)
            << self.level_shift.val())
            | bit_cast::<16, 8>(self.e_climb.q.val().target);
        self.far_xy.read_index.next = self.e_far_index.val();
        self.far_zd.read_index.next = self.e_far_index.val();
        self.f_ev.d.next = self.e_ev.q.val();
        self.f_climb.d.next = self.e_climb.q.val();

        // ---- Stage F: the slot's new state; its next read. ----
        self.f_state.next = self.f_ev.q.val();
        self.f_done.next = false;
        if self.f_ev.q.val().load {
            self.f_state.next.level = 0.into();
        } else if !self.f_ev.q.val().up {
            self.f_state.next.level = (self.f_ev.q.val().level + 1) & self.level_mask.val();
        } else if self.f_climb.q.val().found {
            self.f_state.next.level = (self.f_climb.q.val().target + 1) & self.level_mask.val();
            self.f_state.next.next_address = self.f_jump.q.val();
            self.f_state.next.pending = self.f_ev.q.val().pending
                & (!(self.one_level.val() << self.f_climb.q.val().target));
            if self.cell_mode.val() {
                self.f_state.next.off_x =
                    bit_cast::<32, 64>(self.far_xy.read_data.val() & self.dist_mask_wide.val());
                self.f_state.next.off_y = bit_cast::<32, 64>(
                    (self.far_xy.read_data.val() >> self.dist_shift.val())
                        & self.dist_mask_wide.val(),
                );
                self.f_state.next.off_z =
                    bit_cast::<32, 64>(self.far_zd.read_data.val() & self.dist_mask_wide.val());
                self.f_state.next.cell_dist = bit_cast::<32, 64>(
                    (self.far_zd.read_data.val() >> self.dist_shift.val())
                        & self.dist_mask_wide.val(),
                );
            }
        } else {
            self.f_done.next = true;
        }
        self.f_issue.next = self.f_ev.q.val().valid && (!self.f_done.val());
        self.issue.push.next = self.f_issue.val();
        self.issue.push_slot.next = self.f_ev.q.val().slot;
        self.issue.push_address.next = self.f_state.val().next_address;
        self.issue.push_radius.next = self.f_state.val().radius;
        self.issue.push_full.next = self.f_state.val().full;
        // The read reaches the SearchModule now (one tree) or once memory takes it.
        self.search.request_valid.next = self.issue.request_valid.val();
        self.search.request.next = self.issue.request.val();
        self.search.word.next = self.issue.word.val();
        self.io.ram_address.next = self.issue.ram_address.val();
        self.issue.ram_data.next = self.io.ram_data.val();
        BankRequester::link(&mut self.io.bank, &mut self.issue.bank);
        BankAnswerIn::link(&mut self.io.bank_answer, &mut self.issue.bank_answer);
        self.io.reading.next = self.issue.reading.val();
        // The state write (every event), and the header of a finished search.
        self.store.write_enable.next = self.f_ev.q.val().valid;
        self.store.write_index.next = self.f_ev.q.val().slot;
        self.store.write.next = self.f_state.val();
        self.readout.done.next = self.f_ev.q.val().valid && self.f_done.val();
        self.readout.done_slot.next = self.f_ev.q.val().slot;
        self.readout.done_count.next = self.f_state.val().count;
        self.readout.done_visited.next = self.f_state.val().visited;
        self.io.result.valid.next = self.readout.result.valid.val();
        self.io.result.data.next = self.readout.result.data.val();
        self.readout.result.ready.next = self.io.result.ready.val();

        // Slots: taken by a load, freed by their last beat (masked to the Q slots, so
        // synthesis sees the bits above are constant without a SAT solver).
        self.free.d.next =
            (self.free_pick.still_free.val() | self.readout.freed.val()) & self.all_slots.val();
        if self.reset.val() {
            self.free.d.next = self.all_slots.val();
            self.b_ev.d.next.valid = false;
            self.c_ev.d.next.valid = false;
            self.m_ev.d.next.valid = false;
            self.d_ev.d.next.valid = false;
            self.e_ev.d.next.valid = false;
            self.f_ev.d.next.valid = false;
        }
        self.io.all_busy.next = (self.free.q.val() & self.all_slots.val()) == 0;
        self.io.idle.next = (self.free.q.val() & self.all_slots.val()) == self.all_slots.val();
    }
}
