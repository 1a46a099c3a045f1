//! SlotStore: a [`BarrelPort`](crate::hw::barrel::barrel_port::BarrelPort)'s per-query state,
//! one LUT-RAM entry per query slot and field: the fields of a [`SlotEvent`] that
//! outlive an event (level, pending far children, R, full flag, count, k, the
//! maximum's entry, photon reads, and with `Traversal::Cell` the offsets from the
//! current cell and its distance).
//!
//! Why LUT-RAM: a waiting query costs a QueryModule its registers and its logic;
//! here it costs a few bits of distributed RAM (an ECP5 DPR16X4 holds 16 slots of
//! 4 bits), and the one datapath reads and writes one slot per cycle. The port
//! reads a slot in its first stage and writes it back in its last.

use crate::hw::config::core_config::{
    Addr, CoreConfig, Count, Dist, Entry, LevelMask, ModuleIndex, ReadCount,
};
use crate::hw::config::traversal::Traversal;
use crate::hw::primitives::lut_ram::{LutRam, RamIndex};
use rust_hdl::prelude::*;

/// One event as it moves down the BarrelPort's pipeline: the slot's state as it
/// will be written back, and what the later stages still need of the result.
#[derive(Clone, Copy, Debug, PartialEq, Default, LogicStruct)]
pub struct SlotEvent {
    pub valid: bool,
    /// A new query (the first read is the root's).
    pub load: bool,
    pub slot: ModuleIndex,
    /// The list became or was full with this photon: a new maximum.
    pub run_max: bool,
    pub full: bool,
    pub radius: Dist,
    pub count: Count,
    pub k: Count,
    pub max_pos: Entry,
    pub visited: ReadCount,
    /// The level of the node just read, and the pending far children above.
    pub level: RamIndex,
    pub pending: LevelMask,
    /// No child to descend to: the ascent.
    pub up: bool,
    /// The node just read and the child to read next if not `up`.
    pub address: Addr,
    pub next_address: Addr,
    /// A result (not a load), and what the path memory keeps of it: the photon's
    /// axis, axis distance and whether its far child is pending.
    pub result: bool,
    pub axis: Bits<2>,
    pub axis_dist: Dist,
    pub far_pending: bool,
    /// `Cell`: the query's offsets from its current cell and the cell's distance.
    pub off_x: Dist,
    pub off_y: Dist,
    pub off_z: Dist,
    pub cell_dist: Dist,
}

#[derive(LogicBlock)]
pub struct SlotStore {
    pub clock: Signal<In, Clock>,
    /// The state of slot `read_index` (asynchronous; the other fields zero).
    pub read_index: Signal<In, ModuleIndex>,
    pub read: Signal<Out, SlotEvent>,
    /// Write `write`'s state fields into slot `write_index`.
    pub write_enable: Signal<In, bool>,
    pub write_index: Signal<In, ModuleIndex>,
    pub write: Signal<In, SlotEvent>,
    /// `Traversal::Cell`: the offsets are kept (else their memories are one bit).
    cell_mode: Constant<bool>,
    /// The widths the configuration needs (`CoreConfig`'s masks): each field is
    /// stored through its mask, so synthesis keeps only the LUT-RAM bits in use.
    dist_mask: Constant<Dist>,
    count_mask: Constant<Count>,
    visited_mask: Constant<ReadCount>,
    /// Levels (H) and found-list entries (K).
    level_mask: Constant<RamIndex>,
    entry_mask: Constant<Entry>,
    level: LutRam,
    pending: LutRam,
    radius: LutRam,
    full: LutRam,
    count: LutRam,
    k: LutRam,
    max_pos: LutRam,
    visited: LutRam,
    off_x: LutRam,
    off_y: LutRam,
    off_z: LutRam,
    cell_dist: LutRam,
}

impl SlotStore {
    pub fn new(cfg: &CoreConfig) -> Self {
        let q = cfg.queries_per_port;
        let db = cfg.dist_bits();
        let cell = cfg.traversal == Traversal::Cell;
        let (cell_depth, cell_bits) = if cell { (q, db) } else { (1, 1) };
        let level_bits = cfg.level_index_bits();
        let entry_bits = cfg.entry_bits();
        let ram = |width: u32| LutRam::new(q, width);
        SlotStore {
            clock: Default::default(),
            read_index: Default::default(),
            read: Default::default(),
            write_enable: Default::default(),
            write_index: Default::default(),
            write: Default::default(),
            cell_mode: Constant::new(cell),
            dist_mask: Constant::new(Dist::from(cfg.dist_mask())),
            count_mask: Constant::new(Count::from(cfg.count_mask())),
            visited_mask: Constant::new(ReadCount::from(cfg.visited_mask())),
            level_mask: Constant::new(RamIndex::from(cfg.level_index_mask())),
            entry_mask: Constant::new(Entry::from(cfg.entry_mask())),
            level: ram(level_bits),
            pending: ram(cfg.path_levels().max(1) as u32),
            radius: ram(db),
            full: ram(1),
            count: ram(cfg.count_bits()),
            k: ram(cfg.count_bits()),
            max_pos: ram(entry_bits),
            visited: ram(cfg.visited_bits()),
            off_x: LutRam::new(cell_depth, cell_bits),
            off_y: LutRam::new(cell_depth, cell_bits),
            off_z: LutRam::new(cell_depth, cell_bits),
            cell_dist: LutRam::new(cell_depth, cell_bits),
        }
    }
}

impl Logic for SlotStore {
    #[hdl_gen]
    fn update(&mut self) {
        clock!(
            self, clock, level, pending, radius, full, count, k, max_pos, visited, off_x, off_y,
            off_z, cell_dist
        );
        self.level.read_index.next = self.read_index.val();
        self.pending.read_index.next = self.read_index.val();
        self.radius.read_index.next = self.read_index.val();
        self.full.read_index.next = self.read_index.val();
        self.count.read_index.next = self.read_index.val();
        self.k.read_index.next = self.read_index.val();
        self.max_pos.read_index.next = self.read_index.val();
        self.visited.read_index.next = self.read_index.val();
        self.off_x.read_index.next = self.read_index.val();
        self.off_y.read_index.next = self.read_index.val();
        self.off_z.read_index.next = self.read_index.val();
        self.cell_dist.read_index.next = self.read_index.val();
        // (The event fields are not stored: zero.)
        self.read.next.valid = false;
        self.read.next.load = false;
        self.read.next.run_max = false;
        self.read.next.up = false;
        self.read.next.address = 0.into();
        self.read.next.next_address = 0.into();
        self.read.next.result = false;
        self.read.next.axis = 0.into();
        self.read.next.axis_dist = 0.into();
        self.read.next.far_pending = false;
        self.read.next.slot = self.read_index.val();
        self.read.next.level =
            bit_cast::<8, 32>(self.level.read_data.val()) & self.level_mask.val();
        self.read.next.pending = self.pending.read_data.val();
        self.read.next.radius = self.radius.read_data.val() & self.dist_mask.val();
        self.read.next.full = self.full.read_data.val().get_bit(0);
        self.read.next.count =
            bit_cast::<16, 32>(self.count.read_data.val()) & self.count_mask.val();
        self.read.next.k = bit_cast::<16, 32>(self.k.read_data.val()) & self.count_mask.val();
        self.read.next.max_pos =
            bit_cast::<16, 32>(self.max_pos.read_data.val()) & self.entry_mask.val();
        self.read.next.visited = self.visited.read_data.val() & self.visited_mask.val();
        self.read.next.off_x = self.off_x.read_data.val() & self.dist_mask.val();
        self.read.next.off_y = self.off_y.read_data.val() & self.dist_mask.val();
        self.read.next.off_z = self.off_z.read_data.val() & self.dist_mask.val();
        self.read.next.cell_dist = self.cell_dist.read_data.val() & self.dist_mask.val();

        self.level.write_enable.next = self.write_enable.val();
        self.pending.write_enable.next = self.write_enable.val();
        self.radius.write_enable.next = self.write_enable.val();
        self.full.write_enable.next = self.write_enable.val();
        self.count.write_enable.next = self.write_enable.val();
        self.k.write_enable.next = self.write_enable.val();
        self.max_pos.write_enable.next = self.write_enable.val();
        self.visited.write_enable.next = self.write_enable.val();
        self.off_x.write_enable.next = self.write_enable.val() && self.cell_mode.val();
        self.off_y.write_enable.next = self.write_enable.val() && self.cell_mode.val();
        self.off_z.write_enable.next = self.write_enable.val() && self.cell_mode.val();
        self.cell_dist.write_enable.next = self.write_enable.val() && self.cell_mode.val();
        self.level.write_index.next = self.write_index.val();
        self.pending.write_index.next = self.write_index.val();
        self.radius.write_index.next = self.write_index.val();
        self.full.write_index.next = self.write_index.val();
        self.count.write_index.next = self.write_index.val();
        self.k.write_index.next = self.write_index.val();
        self.max_pos.write_index.next = self.write_index.val();
        self.visited.write_index.next = self.write_index.val();
        self.off_x.write_index.next = self.write_index.val();
        self.off_y.write_index.next = self.write_index.val();
        self.off_z.write_index.next = self.write_index.val();
        self.cell_dist.write_index.next = self.write_index.val();
        self.level.write_data.next = bit_cast::<32, 8>(self.write.val().level);
        self.pending.write_data.next = self.write.val().pending;
        self.radius.write_data.next = self.write.val().radius;
        self.full.write_data.next = 0.into();
        if self.write.val().full {
            self.full.write_data.next = 1.into();
        }
        self.count.write_data.next = bit_cast::<32, 16>(self.write.val().count);
        self.k.write_data.next = bit_cast::<32, 16>(self.write.val().k);
        self.max_pos.write_data.next = bit_cast::<32, 16>(self.write.val().max_pos);
        self.visited.write_data.next = self.write.val().visited;
        self.off_x.write_data.next = self.write.val().off_x;
        self.off_y.write_data.next = self.write.val().off_y;
        self.off_z.write_data.next = self.write.val().off_z;
        self.cell_dist.write_data.next = self.write.val().cell_dist;
    }
}
