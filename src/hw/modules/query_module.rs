//! QueryModule (paper §4.2): the controller of one query. It holds the radius R, the
//! full flag, the count, the traversal state, the found-index list and (inside its
//! MaxFinder, bit-transposed) the found-distance list, K entries each.
//!
//! Per photon: request a read (READY), wait for the SearchModule's answer (WAIT),
//! then insert ([`FoundRule`]): while not full, append to slot `count`; when that
//! fills the list, run the MaxFinder and set R = max, remembering the max slot; once
//! full, a photon in range (d < R) overwrites the max slot and the MaxFinder runs
//! again (MAX_FIND). This is knn.rs's `FoundList` step for step, so slots and read
//! counts match.
//!
//! The query's coordinates and id are not here: the port keeps them once, in
//! LUT-RAM indexed by QueryModule, for the SearchModule and the read-out.
//!
//! The ascent (`CoreConfig::traversal`, see `hw::config::traversal`):
//! * `Reread` (the paper's): an "up" result is just the next read, of the parent.
//! * `Remember` (default): every result of a down visit records its level's axis
//!   distance and pending bit; an "up" result (after the MaxFinder, so R is current)
//!   starts ASCEND, one level per cycle and no port slot: at the parent's level, a
//!   pending far child within R is read next (the sibling of the node we came
//!   from); otherwise climb on, until the root ends the search.
//!
//! Where the lists live: the found-index list, a copy of the found
//! distances for the read-out and the path memory are each written and read one
//! entry per cycle by this module alone, so each is a small LUT-RAM of its own
//! ([`LutRam`]: no flip-flop per bit, no read multiplexer). The pending bits and the
//! one-hot level stay registers (all bits are tested at once), as do the MaxFinder's
//! distances (a row across all slots is read per cycle, which no RAM port gives).

use crate::hw::config::core_config::{
    Addr, CoreConfig, Count, Dist, LevelMask, ModuleIndex, ReadCount, SlotMask,
};
use crate::hw::config::traversal::Traversal;
use crate::hw::datapath::cell_bound::CellBound;
use crate::hw::datapath::found_rule::FoundRule;
use crate::hw::datapath::query_limits::QueryLimits;
use crate::hw::modules::max_finder::MaxFinder;
use crate::hw::primitives::lut_ram::{LutRam, RamIndex};
use crate::hw::primitives::priority_encoder::PriorityEncoder;
use crate::hw::primitives::stream::{QueryBeat, ReadRequest, ReadResult};
use rust_hdl::prelude::*;

#[derive(LogicBlock)]
pub struct QueryModule<const S: usize> {
    pub clock: Signal<In, Clock>,
    pub reset: Signal<In, bool>,
    // Query load from the dispatcher (taken when `free`).
    pub load: Signal<In, bool>,
    pub load_query: Signal<In, QueryBeat>,
    pub free: Signal<Out, bool>,
    // Read request to the port arbiter, with what the SearchModule needs.
    pub read_request: Signal<Out, bool>,
    pub read_grant: Signal<In, bool>,
    pub read: Signal<Out, ReadRequest>,
    // The SearchModule's result, broadcast to every QueryModule of the port;
    // `result_valid` only for the module it is for (the SearchModule decodes it).
    pub result_valid: Signal<In, bool>,
    pub result: Signal<In, ReadResult>,
    // Result read-out.
    pub finished: Signal<Out, bool>,
    pub result_taken: Signal<In, bool>,
    /// This module is the one being read out (its id, count and reads appear).
    pub out_enable: Signal<In, bool>,
    /// The entry being read out (the same for every module) and whether it is this
    /// module's (a port flip-flop: the read-out path is the LUT-RAM read and one
    /// gate, not a one-hot slot encoded here).
    pub out_entry: Signal<In, RamIndex>,
    pub out_reading: Signal<In, bool>,
    pub out_count: Signal<Out, Count>,
    pub out_visited: Signal<Out, ReadCount>,
    pub out_address: Signal<Out, Addr>,
    pub out_dist: Signal<Out, Dist>,
    my_index: Constant<ModuleIndex>,
    /// `Traversal::Remember` or `Cell`: the ascent from the path memory.
    remember: Constant<bool>,
    /// `Traversal::Cell`: prune on the distance to the far child's cell.
    cell_bound: Constant<bool>,
    /// The widths the configuration needs: every register is loaded
    /// through its mask, so synthesis drops the bits above (a flip-flop whose input
    /// is constant or itself): distance bits of the metric, H levels, H − 1 that
    /// can be pending, heap address (H bits), counts (0..=K), photon reads (H + 1
    /// bits), the K slots that exist.
    dist_mask: Constant<Dist>,
    level_mask: Constant<LevelMask>,
    pending_mask: Constant<LevelMask>,
    addr_mask: Constant<Addr>,
    count_mask: Constant<Count>,
    visited_mask: Constant<ReadCount>,
    slot_mask: Constant<SlotMask<S>>,
    /// The state, one-hot: a flip-flop per state, so that each state's next value
    /// is a small function of its own inputs (yosys keeps a rust-hdl enum's binary
    /// code: its register has an initial value, so `fsm` does not recode it, and
    /// the insertion's next state is then a deep function). IDLE (power-up): none
    /// set. READY requests a read of `address`; WAIT waits for its result; MAX_FIND
    /// runs the MaxFinder; ASCEND climbs the remembered path a level per cycle;
    /// DONE waits for the read-out. `st_taken` = not IDLE, a flip-flop for `free`.
    st_ready: DFF<bool>,
    st_wait: DFF<bool>,
    st_max_find: DFF<bool>,
    st_ascend: DFF<bool>,
    st_done: DFF<bool>,
    st_taken: DFF<bool>,
    radius_reg: DFF<Dist>,
    full_reg: DFF<bool>,
    k_reg: DFF<Count>,
    count: DFF<Count>,
    /// One-hot: the slot the next append goes to (slot `count`).
    append_slot: DFF<SlotMask<S>>,
    /// Slots holding a photon.
    occupied: DFF<SlotMask<S>>,
    /// One-hot: the slot holding the maximum (valid once full).
    max_slot: DFF<SlotMask<S>>,
    address: DFF<Addr>,
    up: DFF<bool>,
    came_from_right: DFF<bool>,
    search_done: DFF<bool>,
    visited: DFF<ReadCount>,
    /// One-hot level of `address` (the root is bit 0).
    level: DFF<LevelMask>,
    /// Levels of the current path whose far child is still to be visited.
    pending: DFF<LevelMask>,
    /// The last result asked for the ascent (entered once the MaxFinder is done).
    ascending: DFF<bool>,
    /// The path memory: the pruning bound of the far child of the node read at each
    /// level (`CoreConfig::path_levels` entries), in LUT-RAM: its axis distance, or
    /// with `Traversal::Cell` the distance to its cell.
    path: LutRam,
    /// The same entries again, read at `grand_at`: the pruning test reads the
    /// parent's entry while waiting and the grandparent's while climbing; two
    /// copies read at two registers, the choice after the read, keep a multiplexer
    /// off the LUT-RAM's read index.
    path_up: LutRam,
    /// `Traversal::Cell`: the query's offsets from its cell, and the rest of each
    /// level ([`CellBound`]; one-entry memories never written otherwise).
    cell_state: CellBound,
    /// The found-index list: K heap addresses, in LUT-RAM.
    found: LutRam,
    /// The found distances again, for the read-out (the MaxFinder's are read by row).
    found_dist: LutRam,
    /// The insertion slot (one-hot) as a RAM index.
    insert_index: PriorityEncoder<S>,
    /// The path-memory entries of `level` and its parent, in registers (ASCEND's
    /// read of the parent's starts from flip-flops, not a one-hot encoder).
    level_at: DFF<RamIndex>,
    parent_at: DFF<RamIndex>,
    /// The entry above `parent_at` (saturating): the next parent's while climbing.
    grand_at: DFF<RamIndex>,
    /// ASCEND's pruning test, registered: the parent's remembered bound within R,
    /// compared a cycle ahead for the parent and R the module will have (in the
    /// same cycle it would follow the LUT-RAM read and the comparison).
    parent_within: DFF<bool>,
    /// The bound `parent_within` was computed from: the far cell's distance,
    /// `cell_dist` on entering it.
    parent_bound: DFF<Dist>,
    /// The next insertion runs the MaxFinder: full or one photon short (`full ∨
    /// count + 1 = k`), registered (from `FoundRule::fills_next`): one flip-flop
    /// is one input to MAX_FIND, not the comparison before the insertion's next
    /// state.
    runs_max: DFF<bool>,
    level_index_mask: Constant<RamIndex>,
    max_finder: MaxFinder<S>,
    result_mine: Signal<Local, bool>,
    insert: Signal<Local, bool>,
    /// The found list's rule (where a photon goes) and a loaded query's R and k.
    rule: FoundRule<SlotMask<S>>,
    limits: QueryLimits,
    /// ASCEND's view of the parent level.
    parent_level: Signal<Local, LevelMask>,
    /// The parent's pending bit, registered a cycle ahead like `parent_within`
    /// (the AND-OR over the pending bits from flip-flops).
    parent_pending: DFF<bool>,
    /// For the registered pruning test: the entry the parent will have next cycle
    /// (read from the path memory), the R and the full flag it will be tested with.
    ahead_dist: Signal<Local, Dist>,
    ahead_radius: Signal<Local, Dist>,
    ahead_full: Signal<Local, bool>,
}

impl<const S: usize> QueryModule<S> {
    /// QueryModule number `index` of its port.
    pub fn new(cfg: &CoreConfig, index: usize) -> Self {
        let cell = cfg.traversal == Traversal::Cell;
        let (cell_levels, cell_bits) = if cell {
            (cfg.path_levels().max(1), cfg.dist_bits())
        } else {
            (1, 1)
        };
        QueryModule {
            clock: Default::default(),
            reset: Default::default(),
            load: Default::default(),
            load_query: Default::default(),
            free: Default::default(),
            read_request: Default::default(),
            read_grant: Default::default(),
            read: Default::default(),
            result_valid: Default::default(),
            result: Default::default(),
            finished: Default::default(),
            result_taken: Default::default(),
            out_enable: Default::default(),
            out_entry: Default::default(),
            out_reading: Default::default(),
            out_count: Default::default(),
            out_visited: Default::default(),
            out_address: Default::default(),
            out_dist: Default::default(),
            my_index: Constant::new(ModuleIndex::from(index as u64)),
            remember: Constant::new(cfg.traversal.remembers()),
            cell_bound: Constant::new(cfg.traversal == Traversal::Cell),
            dist_mask: Constant::new(Dist::from(cfg.dist_mask())),
            level_mask: Constant::new(LevelMask::from(cfg.level_onehot_mask())),
            pending_mask: Constant::new(LevelMask::from(cfg.pending_mask())),
            addr_mask: Constant::new(Addr::from(cfg.addr_mask())),
            count_mask: Constant::new(Count::from(cfg.count_mask())),
            visited_mask: Constant::new(ReadCount::from(cfg.visited_mask())),
            slot_mask: Constant::new(SlotMask::<S>::from(cfg.slot_mask())),
            st_ready: Default::default(),
            st_wait: Default::default(),
            st_max_find: Default::default(),
            st_ascend: Default::default(),
            st_done: Default::default(),
            st_taken: Default::default(),
            radius_reg: Default::default(),
            full_reg: Default::default(),
            k_reg: Default::default(),
            count: Default::default(),
            append_slot: Default::default(),
            occupied: Default::default(),
            max_slot: Default::default(),
            address: Default::default(),
            up: Default::default(),
            came_from_right: Default::default(),
            search_done: Default::default(),
            visited: Default::default(),
            level: Default::default(),
            pending: Default::default(),
            ascending: Default::default(),
            path: LutRam::new(cfg.path_levels().max(1), cfg.dist_bits()),
            path_up: LutRam::new(cfg.path_levels().max(1), cfg.dist_bits()),
            cell_state: CellBound::new(cell_levels, cell_bits, cfg.saturates()),
            found: LutRam::new(cfg.k, cfg.address_bits),
            found_dist: LutRam::new(cfg.k, cfg.dist_bits()),
            insert_index: PriorityEncoder::one_hot(cfg.k),
            level_at: Default::default(),
            parent_at: Default::default(),
            grand_at: Default::default(),
            parent_within: Default::default(),
            parent_bound: Default::default(),
            runs_max: Default::default(),
            level_index_mask: Constant::new(RamIndex::from(cfg.level_index_mask())),
            max_finder: MaxFinder::new(cfg.dist_bits(), cfg.k),
            result_mine: Default::default(),
            insert: Default::default(),
            rule: FoundRule::new(cfg),
            limits: QueryLimits::new(cfg),
            parent_level: Default::default(),
            parent_pending: Default::default(),
            ahead_dist: Default::default(),
            ahead_radius: Default::default(),
            ahead_full: Default::default(),
        }
    }
}

impl<const S: usize> Logic for QueryModule<S> {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(
            self,
            clock,
            st_ready,
            st_wait,
            st_max_find,
            st_ascend,
            st_done,
            st_taken,
            radius_reg,
            full_reg,
            k_reg,
            count,
            append_slot,
            occupied,
            max_slot,
            address,
            up,
            came_from_right,
            search_done,
            visited,
            level,
            pending,
            ascending,
            level_at,
            parent_at,
            grand_at,
            parent_within,
            parent_pending,
            parent_bound,
            runs_max
        );
        clock!(self, clock, found, found_dist, path, path_up, cell_state);
        self.parent_level.next = self.level.q.val() >> 1;
        // Its pending bit next cycle: while climbing, the grandparent's; otherwise
        // the parent stays (WAIT changes only the current level's bit).
        if self.st_ascend.q.val() {
            self.parent_pending.d.next = (self.pending.q.val() & (self.level.q.val() >> 2)).any();
        } else {
            self.parent_pending.d.next = (self.pending.q.val() & self.parent_level.val()).any();
        }
        // The pruning test a cycle ahead. ASCEND is entered from WAIT (R and the
        // parent unchanged: an insertion that changes R goes through MAX_FIND) or
        // from MAX_FIND (the parent unchanged, R = the MaxFinder's maximum, full);
        // while climbing, the next parent is `grand_at` and R stays. No entry is
        // written in the cycle it is read (WAIT writes the current level).
        self.path.read_index.next = self.parent_at.q.val();
        self.path_up.read_index.next = self.grand_at.q.val();
        if self.st_ascend.q.val() {
            self.ahead_dist.next = self.path_up.read_data.val();
        } else {
            self.ahead_dist.next = self.path.read_data.val();
        }
        if self.st_max_find.q.val() {
            self.ahead_radius.next = self.max_finder.max_dist.val() & self.dist_mask.val();
            self.ahead_full.next = true;
        } else {
            self.ahead_radius.next = self.radius_reg.q.val();
            self.ahead_full.next = self.full_reg.q.val();
        }
        if self.ahead_full.val() {
            self.parent_within.d.next = self.ahead_dist.val() < self.ahead_radius.val();
        } else {
            self.parent_within.d.next = self.ahead_dist.val() <= self.ahead_radius.val();
        }
        self.parent_bound.d.next = self.ahead_dist.val() & self.dist_mask.val();
        // `Cell`: a down visit's far cell distance is the level's bound; an ASCEND
        // step below the root enters or passes the parent level (`CellBound`).
        self.cell_state.load.next = self.load.val();
        self.cell_state.axis.next = self.result.val().axis;
        self.cell_state.axis_dist.next = self.result.val().axis_dist;
        self.cell_state.write_index.next = self.level_at.q.val();
        self.cell_state.visit.next = false;
        self.cell_state.read_index.next = self.parent_at.q.val();
        self.cell_state.step.next =
            self.cell_bound.val() && self.st_ascend.q.val() && !self.level.q.val().get_bit(0);
        self.cell_state.enter.next = self.parent_pending.q.val() && self.parent_within.q.val();
        self.cell_state.enter_bound.next = self.parent_bound.q.val();
        self.max_finder.clock.next = self.clock.val();
        self.max_finder.start.next = false;
        self.max_finder.candidates.next = self.occupied.q.val();
        self.max_finder.write_dist.next = self.result.val().distance;

        self.result_mine.next = self.result_valid.val();
        // A photon enters the list: appended while not full, else into the max slot.
        self.insert.next = false;
        if self.st_wait.q.val() {
            self.insert.next = self.result_mine.val() && self.result.val().in_range;
        }
        self.rule.insert.next = self.insert.val();
        self.rule.full.next = self.full_reg.q.val();
        self.rule.count.next = self.count.q.val();
        self.rule.k.next = self.k_reg.q.val();
        self.rule.append_at.next = self.append_slot.q.val();
        self.rule.max_at.next = self.max_slot.q.val();
        self.max_finder.write_enable.next = self.insert.val();
        self.max_finder.write_slot.next = self.rule.at.val();
        self.insert_index.mask.next = self.rule.at.val();
        self.found.write_enable.next = self.insert.val();
        self.found.write_index.next = self.insert_index.index.val();
        self.found.write_data.next =
            bit_cast::<32, 24>(self.result.val().address & self.addr_mask.val());
        self.found.read_index.next = self.out_entry.val();
        self.found_dist.write_enable.next = self.insert.val();
        self.found_dist.write_index.next = self.insert_index.index.val();
        self.found_dist.write_data.next = self.result.val().distance & self.dist_mask.val();
        self.found_dist.read_index.next = self.out_entry.val();
        // The path memory takes each down visit's pruning bound at its level.
        // (Both copies alike.)
        self.path.write_enable.next = false;
        self.path_up.write_enable.next = false;
        self.path.write_index.next = self.level_at.q.val();
        self.path_up.write_index.next = self.level_at.q.val();
        if self.cell_bound.val() {
            self.path.write_data.next = self.cell_state.far_cell_dist.val();
            self.path_up.write_data.next = self.cell_state.far_cell_dist.val();
        } else {
            self.path.write_data.next = self.result.val().axis_dist & self.dist_mask.val();
            self.path_up.write_data.next = self.result.val().axis_dist & self.dist_mask.val();
        }

        // Each state's work on the datapath. WAIT and ASCEND write the same
        // registers, so they are one if-else: a register then gets one multiplexer
        // with its own value last, which yosys makes a clock enable and, for the
        // bits the masks clear, no flip-flop at all (separate `if`s kept all 24
        // address bits). READY and MAX_FIND, with registers of their own, stay out
        // of it, so WAIT's and ASCEND's clock enables do not test them.
        if self.st_ready.q.val() && self.read_grant.val() {
            self.visited.d.next = (self.visited.q.val() + 1) & self.visited_mask.val();
        }
        if self.st_max_find.q.val() && !self.max_finder.busy.val() {
            self.radius_reg.d.next = self.max_finder.max_dist.val() & self.dist_mask.val();
            self.full_reg.d.next = true;
            self.max_slot.d.next = self.max_finder.max_slot.val();
        }
        if self.st_wait.q.val() {
            if self.result_mine.val() {
                self.search_done.d.next = self.result.val().done;
                self.ascending.d.next = false;
                if self.remember.val() {
                    // Remember this level; go down, or climb (after the MaxFinder).
                    self.path.write_enable.next = true;
                    self.path_up.write_enable.next = true;
                    self.cell_state.visit.next = self.cell_bound.val();
                    if self.result.val().far_pending {
                        self.pending.d.next =
                            (self.pending.q.val() | self.level.q.val()) & self.pending_mask.val();
                    } else {
                        self.pending.d.next = self.pending.q.val() & (!self.level.q.val());
                    }
                    if self.result.val().next_up {
                        self.ascending.d.next = true;
                    } else {
                        self.address.d.next = self.result.val().next_address & self.addr_mask.val();
                        self.level.d.next = (self.level.q.val() << 1) & self.level_mask.val();
                        self.grand_at.d.next = self.parent_at.q.val();
                        self.parent_at.d.next = self.level_at.q.val();
                        self.level_at.d.next =
                            (self.level_at.q.val() + 1) & self.level_index_mask.val();
                    }
                } else {
                    self.address.d.next = self.result.val().next_address & self.addr_mask.val();
                    self.up.d.next = self.result.val().next_up;
                    self.came_from_right.d.next = self.result.val().next_came_from_right;
                }
                if self.rule.appends.val() {
                    self.count.d.next = self.rule.next_count.val();
                    self.occupied.d.next = self.occupied.q.val() | self.append_slot.q.val();
                    self.append_slot.d.next =
                        (self.append_slot.q.val() << 1) & self.slot_mask.val();
                    self.runs_max.d.next = self.runs_max.q.val() || self.rule.fills_next.val();
                }
            }
        } else if self.st_ascend.q.val() {
            // One level per cycle, with R as it is now (after every insertion).
            // At the root (level 0: one flip-flop, not an address comparison).
            if self.level.q.val().get_bit(0) {
                self.search_done.d.next = true;
            } else if self.parent_pending.q.val() && self.parent_within.q.val() {
                // Enter the far child: the sibling of the node we came from.
                self.address.d.next = (self.address.q.val() ^ 1) & self.addr_mask.val();
                self.pending.d.next = self.pending.q.val() & (!self.parent_level.val());
                self.ascending.d.next = false;
            } else {
                self.address.d.next = (self.address.q.val() >> 1) & self.addr_mask.val();
                self.level.d.next = self.parent_level.val() & self.level_mask.val();
                self.level_at.d.next = self.parent_at.q.val();
                self.parent_at.d.next = self.grand_at.q.val();
                if self.grand_at.q.val().any() {
                    self.grand_at.d.next =
                        (self.grand_at.q.val() - 1) & self.level_index_mask.val();
                }
            }
        }
        // The state transitions, one `if` per state: one state bit is set, so each
        // bit's next value depends only on the states that enter or leave it.
        if self.st_ready.q.val() && self.read_grant.val() {
            self.st_ready.d.next = false;
            self.st_wait.d.next = true;
        }
        if self.st_wait.q.val() && self.result_mine.val() {
            self.st_wait.d.next = false;
            if self.insert.val() && self.runs_max.q.val() {
                // Full (the photon replaced the max) or this append fills the list:
                // a new R (`candidates` is read a cycle later, with the new slot).
                self.max_finder.start.next = true;
                self.st_max_find.d.next = true;
            } else if self.result.val().done {
                self.st_done.d.next = true;
            } else if self.remember.val() && self.result.val().next_up {
                self.st_ascend.d.next = true;
            } else {
                self.st_ready.d.next = true;
            }
        }
        if self.st_max_find.q.val() && !self.max_finder.busy.val() {
            self.st_max_find.d.next = false;
            if self.search_done.q.val() {
                self.st_done.d.next = true;
            } else if self.ascending.q.val() {
                self.st_ascend.d.next = true;
            } else {
                self.st_ready.d.next = true;
            }
        }
        if self.st_ascend.q.val() {
            if self.level.q.val().get_bit(0) {
                self.st_ascend.d.next = false;
                self.st_done.d.next = true;
            } else if self.parent_pending.q.val() && self.parent_within.q.val() {
                self.st_ascend.d.next = false;
                self.st_ready.d.next = true;
            }
        }
        if self.st_done.q.val() && self.result_taken.val() {
            self.st_done.d.next = false;
            self.st_taken.d.next = false;
        }
        // Load a query ([`QueryLimits`]: R and k as kept). The port loads only a
        // free module, so `load` implies IDLE and is tested alone: the clear is one
        // net per module, where `load && IDLE` would be a gate per flip-flop.
        self.limits.query.next = self.load_query.val();
        if self.load.val() {
            self.radius_reg.d.next = self.limits.radius.val();
            self.k_reg.d.next = self.limits.k.val();
            self.runs_max.d.next = self.limits.k.val() == 1;
            self.full_reg.d.next = false;
            self.count.d.next = 0.into();
            self.append_slot.d.next = 1.into();
            self.occupied.d.next = 0.into();
            self.address.d.next = 1.into();
            self.up.d.next = false;
            self.came_from_right.d.next = false;
            self.search_done.d.next = false;
            self.visited.d.next = 0.into();
            if self.remember.val() {
                self.level.d.next = 1.into();
                self.level_at.d.next = 0.into();
                self.parent_at.d.next = 0.into();
                self.grand_at.d.next = 0.into();
            }
            self.pending.d.next = 0.into();
            self.ascending.d.next = false;
            // READY alone (as the binary `= Ready`): one bit set, whatever came before.
            self.st_taken.d.next = true;
            self.st_ready.d.next = true;
            self.st_wait.d.next = false;
            self.st_max_find.d.next = false;
            self.st_ascend.d.next = false;
            self.st_done.d.next = false;
        }
        if self.reset.val() {
            self.st_taken.d.next = false;
            self.st_ready.d.next = false;
            self.st_wait.d.next = false;
            self.st_max_find.d.next = false;
            self.st_ascend.d.next = false;
            self.st_done.d.next = false;
        }

        self.free.next = !self.st_taken.q.val();
        self.read_request.next = self.st_ready.q.val();
        self.finished.next = self.st_done.q.val();
        // The read and its context, zero unless granted (the port ORs its modules).
        self.read.next.query_module = 0.into();
        self.read.next.address = 0.into();
        self.read.next.up = false;
        self.read.next.came_from_right = false;
        // (x, y, z: the SearchModule looks them up by `query_module`.)
        self.read.next.x = 0.into();
        self.read.next.y = 0.into();
        self.read.next.z = 0.into();
        self.read.next.radius = 0.into();
        self.read.next.full = false;
        if self.read_grant.val() {
            self.read.next.query_module = self.my_index.val();
            self.read.next.address = self.address.q.val();
            self.read.next.up = self.up.q.val();
            self.read.next.came_from_right = self.came_from_right.q.val();
            self.read.next.radius = self.radius_reg.q.val();
            self.read.next.full = self.full_reg.q.val();
        }
        // Read-out: zero unless this module is selected, so that the port merges
        // its modules with an OR tree instead of a chain of multiplexers.
        self.out_count.next = 0.into();
        self.out_visited.next = 0.into();
        if self.out_enable.val() {
            self.out_count.next = self.count.q.val();
            self.out_visited.next = self.visited.q.val();
        }
        self.out_address.next = 0.into();
        self.out_dist.next = 0.into();
        if self.out_reading.val() {
            self.out_address.next = bit_cast::<24, 32>(self.found.read_data.val());
            self.out_dist.next = self.found_dist.read_data.val() & self.dist_mask.val();
        }
    }
}
