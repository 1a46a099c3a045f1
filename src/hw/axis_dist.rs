//! AxisDistModule (paper §4.3): the distance between query and photon along the
//! photon's split axis, and which child is the near one. NextIndexModule prunes the
//! far subtree with it, so it is measured in the search metric (|dq|^2 for L2,
//! |dq| for L1), exactly `Metric::axis_dist` of the software search.

use crate::hw::config::{low_mask, Coord, Dist};
use crate::hw::metric::Metric;
use rust_hdl::prelude::*;

#[derive(LogicBlock)]
pub struct AxisDistModule {
    pub query_x: Signal<In, Coord>,
    pub query_y: Signal<In, Coord>,
    pub query_z: Signal<In, Coord>,
    pub photon_x: Signal<In, Coord>,
    pub photon_y: Signal<In, Coord>,
    pub photon_z: Signal<In, Coord>,
    /// Split axis of the photon: 0 = x, 1 = y, 2 = z.
    pub axis: Signal<In, Bits<2>>,
    /// Distance along the split axis in the search metric.
    pub axis_dist: Signal<Out, Dist>,
    /// The near child is the right one iff `q[a] >= p[a]` (knn.rs traversal rule).
    pub near_right: Signal<Out, bool>,
    metric_is_l2: Constant<bool>,
    dist_mask: Constant<Dist>,
    query_on_axis: Signal<Local, Coord>,
    photon_on_axis: Signal<Local, Coord>,
    axis_delta: Signal<Local, Coord>,
}

impl AxisDistModule {
    /// Full-width datapath (32-bit distances).
    pub fn new(metric: Metric) -> Self {
        Self::with_widths(metric, 32)
    }

    /// A datapath whose axis distance has `dist_bits` (masked, so
    /// synthesis drops the bits above).
    pub fn with_widths(metric: Metric, dist_bits: u32) -> Self {
        AxisDistModule {
            dist_mask: Constant::new(Dist::from(low_mask(dist_bits))),
            query_x: Default::default(),
            query_y: Default::default(),
            query_z: Default::default(),
            photon_x: Default::default(),
            photon_y: Default::default(),
            photon_z: Default::default(),
            axis: Default::default(),
            axis_dist: Default::default(),
            near_right: Default::default(),
            metric_is_l2: Constant::new(metric == Metric::L2),
            query_on_axis: Default::default(),
            photon_on_axis: Default::default(),
            axis_delta: Default::default(),
        }
    }
}

impl Logic for AxisDistModule {
    #[hdl_gen]
    fn update(&mut self) {
        // Select the split axis (axis code 3 never occurs; it reads as z).
        self.query_on_axis.next = self.query_z.val();
        self.photon_on_axis.next = self.photon_z.val();
        if self.axis.val() == 0 {
            self.query_on_axis.next = self.query_x.val();
            self.photon_on_axis.next = self.photon_x.val();
        }
        if self.axis.val() == 1 {
            self.query_on_axis.next = self.query_y.val();
            self.photon_on_axis.next = self.photon_y.val();
        }
        self.near_right.next = self.query_on_axis.val() >= self.photon_on_axis.val();
        if self.near_right.val() {
            self.axis_delta.next = self.query_on_axis.val() - self.photon_on_axis.val();
        } else {
            self.axis_delta.next = self.photon_on_axis.val() - self.query_on_axis.val();
        }
        if self.metric_is_l2.val() {
            self.axis_dist.next =
                (self.axis_delta.val() * self.axis_delta.val()) & self.dist_mask.val();
        } else {
            self.axis_dist.next = bit_cast::<32, 16>(self.axis_delta.val()) & self.dist_mask.val();
        }
    }
}
