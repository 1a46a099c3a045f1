//! FarCellDist: the distance from the query to a visited photon's far cell
//! (`Traversal::Cell`, Arya and Mount's incremental distance; see `hw::config::traversal`),
//! the pruning bound that both controllers remember for the level (the
//! QueryModule's [`CellBound`](crate::hw::datapath::cell_bound::CellBound), the barrel's
//! stage B).
//!
//! The far cell is the current one with the offset along the photon's axis
//! replaced by the axis distance (never smaller: the split lies inside the cell),
//! so its distance is `cell_dist − off[axis] + axis_dist`. The current cell was
//! entered within R, so its distance and offsets are exact even when distances
//! saturate (`CoreConfig::radius_bits`); only the axis distance may have saturated,
//! and then the sum saturates too: a saturated bound is above every R and prunes,
//! as the true one would. Combinational.

use crate::hw::config::core_config::{low_mask, CoreConfig, Dist};
use rust_hdl::prelude::*;

#[derive(LogicBlock)]
pub struct FarCellDist {
    /// The current cell: the query's offset from it along each axis, and its
    /// distance (their sum).
    pub off_x: Signal<In, Dist>,
    pub off_y: Signal<In, Dist>,
    pub off_z: Signal<In, Dist>,
    pub cell_dist: Signal<In, Dist>,
    /// The visited photon's split axis (1 = y, 2 = z, else x) and axis distance.
    pub axis: Signal<In, Bits<2>>,
    pub axis_dist: Signal<In, Dist>,
    /// The current cell's offset along `axis`.
    pub axis_off: Signal<Out, Dist>,
    /// The far cell's distance, saturated at the distance bits.
    pub far_dist: Signal<Out, Dist>,
    dist_mask: Constant<Dist>,
    saturate: Constant<bool>,
    sum: Signal<Local, Dist>,
    /// Saturating distances of at most [`NARROW_BITS`] bits: the saturation test
    /// on the sum taken at 16 bits (one mask and one sum, else none). Debian yosys
    /// keeps a sum of 32-bit operands 32 bits wide, so the test would be an OR
    /// over every bit above the distance's behind a 32-bit carry chain; at 16 bits
    /// it is one LUT behind a chain half as long. The output is written into every
    /// level's bound and the far-cell offsets in the same cycle.
    narrow_mask: Vec<Constant<Bits<16>>>,
    narrow_sum: Vec<Signal<Local, Bits<16>>>,
}

/// The widest saturating distance the 16-bit sum holds: `cell_dist − off + axis_dist`
/// of `b`-bit terms is below `2^(b + 1)`.
pub const NARROW_BITS: u32 = 15;

impl FarCellDist {
    /// For `dist_bits`-bit distances, saturating if `saturate`.
    pub fn new(dist_bits: u32, saturate: bool) -> Self {
        let narrow = (saturate && dist_bits <= NARROW_BITS) as usize;
        FarCellDist {
            off_x: Default::default(),
            off_y: Default::default(),
            off_z: Default::default(),
            cell_dist: Default::default(),
            axis: Default::default(),
            axis_dist: Default::default(),
            axis_off: Default::default(),
            far_dist: Default::default(),
            dist_mask: Constant::new(Dist::from(low_mask(dist_bits))),
            saturate: Constant::new(saturate),
            sum: Default::default(),
            narrow_mask: (0..narrow)
                .map(|_| Constant::new(Bits::<16>::from(low_mask(dist_bits))))
                .collect(),
            narrow_sum: (0..narrow).map(|_| Default::default()).collect(),
        }
    }

    /// For the distances of `cfg`.
    pub fn for_config(cfg: &CoreConfig) -> Self {
        Self::new(cfg.dist_bits(), cfg.saturates())
    }
}

impl Logic for FarCellDist {
    #[hdl_gen]
    fn update(&mut self) {
        self.axis_off.next = self.off_x.val();
        if self.axis.val() == 1 {
            self.axis_off.next = self.off_y.val();
        }
        if self.axis.val() == 2 {
            self.axis_off.next = self.off_z.val();
        }
        self.sum.next = (self.cell_dist.val() - self.axis_off.val()) + self.axis_dist.val();
        self.far_dist.next = self.sum.val() & self.dist_mask.val();
        if self.saturate.val() && (self.sum.val() & !self.dist_mask.val()).any() {
            self.far_dist.next = self.dist_mask.val();
        }
        for i in 0..self.narrow_sum.len() {
            self.narrow_sum[i].next = (bit_cast::<16, 32>(self.cell_dist.val())
                - bit_cast::<16, 32>(self.axis_off.val()))
                + bit_cast::<16, 32>(self.axis_dist.val());
            // The low bits are the wide sum's (synthesis trims its unused upper
            // bits); only the test for saturation reads the narrow sum's top.
            self.far_dist.next = self.sum.val() & self.dist_mask.val();
            if (self.narrow_sum[i].val() & !self.narrow_mask[i].val()).any() {
                self.far_dist.next = self.dist_mask.val();
            }
        }
    }
}
