//! CellBound: a QueryModule's `Traversal::Cell` state (see `hw::config::traversal`). The
//! query's offset from its current kd-tree cell along each axis and the cell's
//! distance (their sum: both metrics add over the axes), kept so that a far child
//! is pruned on the distance to its whole cell — Arya and Mount's incremental
//! distance — instead of to its splitting plane alone.
//!
//! * A down visit (`visit`) gives the photon's axis and axis distance; the far
//!   child's cell is the current one with the offset along that axis replaced by
//!   the axis distance (never smaller: the split lies inside the cell), so its
//!   distance is `cell_dist - off[axis] + axis_dist` (`far_cell_dist`, from a
//!   [`FarCellDist`], which the QueryModule remembers as the level's pruning
//!   bound). This block remembers the rest of the level: the axis, the offset
//!   before and the axis distance.
//! * An ascent step below the root (`step`) at the parent level either enters its
//!   far child (`enter`: the offset along its axis becomes its axis distance and
//!   the cell distance its bound, `enter_bound`) or passes it (the offset along its
//!   axis is restored: whatever the ascent left below was that level's far child).
//!   A near descent changes neither, and nor does a far child entered directly
//!   because the near one does not exist (a lower bound still; the software search
//!   does the same).
//! * `load` clears everything: the root's cell is all space.
//!
//! Three small LUT-RAMs (H − 1 entries each, as the QueryModule's path memory)
//! and four registers of distance bits. It is a block of its own so that the
//! traversals that do not use it (`remember`, `reread`) leave none of it behind:
//! the QueryModule builds it with one-entry, one-bit memories that are never
//! written, and its outputs unused.

use crate::hw::config::core_config::Dist;
use crate::hw::datapath::far_cell_dist::FarCellDist;
use crate::hw::primitives::lut_ram::{LutRam, RamIndex};
use rust_hdl::prelude::*;

#[derive(LogicBlock)]
pub struct CellBound {
    pub clock: Signal<In, Clock>,
    /// A new query: offsets and cell distance zero.
    pub load: Signal<In, bool>,
    /// A down visit of a photon with this axis and axis distance, remembered at
    /// level `write_index`.
    pub visit: Signal<In, bool>,
    pub axis: Signal<In, Bits<2>>,
    pub axis_dist: Signal<In, Dist>,
    pub write_index: Signal<In, RamIndex>,
    /// The distance from the query to the visited photon's far cell.
    pub far_cell_dist: Signal<Out, Dist>,
    /// An ascent step at the parent level `read_index`: entering its far child
    /// (`enter`, whose cell distance is `enter_bound`) or passing the level.
    pub step: Signal<In, bool>,
    pub enter: Signal<In, bool>,
    pub enter_bound: Signal<In, Dist>,
    pub read_index: Signal<In, RamIndex>,
    off_x: DFF<Dist>,
    off_y: DFF<Dist>,
    off_z: DFF<Dist>,
    cell_dist: DFF<Dist>,
    /// Per level: the photon's axis, the offset along it before the visit and in
    /// the far cell.
    level_axis: LutRam,
    old_off: LutRam,
    far_off: LutRam,
    dist_mask: Constant<Dist>,
    /// The visited photon's far cell from the current one.
    far_cell: FarCellDist,
    step_axis: Signal<Local, Bits<2>>,
    step_off: Signal<Local, Dist>,
}

impl CellBound {
    /// For a path memory of `levels` entries and distances of `dist_bits` bits,
    /// saturating if `saturate`.
    pub fn new(levels: usize, dist_bits: u32, saturate: bool) -> Self {
        CellBound {
            clock: Default::default(),
            load: Default::default(),
            visit: Default::default(),
            axis: Default::default(),
            axis_dist: Default::default(),
            write_index: Default::default(),
            far_cell_dist: Default::default(),
            step: Default::default(),
            enter: Default::default(),
            enter_bound: Default::default(),
            read_index: Default::default(),
            off_x: Default::default(),
            off_y: Default::default(),
            off_z: Default::default(),
            cell_dist: Default::default(),
            level_axis: LutRam::new(levels, 2),
            old_off: LutRam::new(levels, dist_bits),
            far_off: LutRam::new(levels, dist_bits),
            dist_mask: Constant::new(Dist::from((1u64 << dist_bits) - 1)),
            far_cell: FarCellDist::new(dist_bits, saturate),
            step_axis: Default::default(),
            step_off: Default::default(),
        }
    }
}

impl Logic for CellBound {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(self, clock, off_x, off_y, off_z, cell_dist);
        clock!(self, clock, level_axis, old_off, far_off);

        // A down visit: the offset along the photon's axis, and its far cell.
        self.far_cell.off_x.next = self.off_x.q.val();
        self.far_cell.off_y.next = self.off_y.q.val();
        self.far_cell.off_z.next = self.off_z.q.val();
        self.far_cell.cell_dist.next = self.cell_dist.q.val();
        self.far_cell.axis.next = self.axis.val();
        self.far_cell.axis_dist.next = self.axis_dist.val();
        self.far_cell_dist.next = self.far_cell.far_dist.val();
        self.level_axis.write_enable.next = self.visit.val();
        self.old_off.write_enable.next = self.visit.val();
        self.far_off.write_enable.next = self.visit.val();
        self.level_axis.write_index.next = self.write_index.val();
        self.old_off.write_index.next = self.write_index.val();
        self.far_off.write_index.next = self.write_index.val();
        self.level_axis.write_data.next = bit_cast::<32, 2>(self.axis.val());
        self.old_off.write_data.next = self.far_cell.axis_off.val() & self.dist_mask.val();
        self.far_off.write_data.next = self.axis_dist.val() & self.dist_mask.val();

        // An ascent step: the parent level's offset, entered or restored.
        self.level_axis.read_index.next = self.read_index.val();
        self.old_off.read_index.next = self.read_index.val();
        self.far_off.read_index.next = self.read_index.val();
        self.step_axis.next = bit_cast::<2, 32>(self.level_axis.read_data.val());
        if self.enter.val() {
            self.step_off.next = self.far_off.read_data.val() & self.dist_mask.val();
        } else {
            self.step_off.next = self.old_off.read_data.val() & self.dist_mask.val();
        }
        if self.step.val() {
            if self.step_axis.val() == 0 {
                self.off_x.d.next = self.step_off.val();
            }
            if self.step_axis.val() == 1 {
                self.off_y.d.next = self.step_off.val();
            }
            if self.step_axis.val() == 2 {
                self.off_z.d.next = self.step_off.val();
            }
            if self.enter.val() {
                self.cell_dist.d.next = self.enter_bound.val() & self.dist_mask.val();
            }
        }
        if self.load.val() {
            self.off_x.d.next = 0.into();
            self.off_y.d.next = 0.into();
            self.off_z.d.next = 0.into();
            self.cell_dist.d.next = 0.into();
        }
    }
}
