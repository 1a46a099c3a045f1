//! DistModule (paper §4.3): the full query-photon distance in the search metric
//! (sum of the three axis distances: squared L2 or L1, no square root), and the
//! paper's AxisDistModule beside it: the distance along the photon's split axis
//! and which child is the near one, for NextIndexModule's pruning. The split
//! axis's distance is one of the three terms of the sum, so it is selected from
//! them, not computed again (a second difference, its comparison and, for L2, a
//! fourth multiplier in series with the axis multiplexer). The in-range test
//! against the radius of the QueryModule that issued the read is the
//! SearchModule's next stage, on the registered distance, so this stage ends after
//! one carry chain.
//!
//! A core built for a scene's largest radius (`CoreConfig::radius_bits`) keeps
//! distances in fewer bits than the grid's diagonal needs. The split-axis distance
//! is stored (the level's pruning bound, the far cell's offsets), so a larger one
//! saturates at the all-ones value, still above every radius it is compared with.
//! The full distance is not saturated: it leaves as wide as the grid's diagonal,
//! the in-range test (the SearchModule's next stage) is exact on it, and only a
//! photon in range, whose distance fits, is stored. (Saturating it put an OR over
//! its upper bits and a multiplexer behind the three-term sum, on the critical
//! path of a banked core.)
//!
//! `registered`: the three axis differences (with their signs and the split axis)
//! are registered before the squares and the sum, and the inputs come a cycle
//! early (the SearchModule feeds them from the BlockRAM's word as it arrives,
//! where a pipelined core registers the word anyway): the difference, the
//! multiplier and the sum in one cycle are the critical path of a squared-L2
//! barrel datapath on the ECP5.

use crate::hw::config::core_config::{bits_for, low_mask, Coord, Dist};
use crate::hw::config::metric::Metric;
use rust_hdl::prelude::*;

#[derive(LogicBlock)]
pub struct DistModule {
    pub clock: Signal<In, Clock>,
    pub query_x: Signal<In, Coord>,
    pub query_y: Signal<In, Coord>,
    pub query_z: Signal<In, Coord>,
    pub photon_x: Signal<In, Coord>,
    pub photon_y: Signal<In, Coord>,
    pub photon_z: Signal<In, Coord>,
    /// Split axis of the photon: 0 = x, 1 = y, 2 = z (3 never occurs; it reads as z).
    pub axis: Signal<In, Bits<2>>,
    pub distance: Signal<Out, Dist>,
    /// Distance along the split axis in the search metric (|dq|^2 for L2, |dq| for
    /// L1), exactly `Metric::axis_dist` of the software search.
    pub axis_dist: Signal<Out, Dist>,
    /// The near child is the right one iff `q[a] >= p[a]` (knn.rs traversal rule).
    pub near_right: Signal<Out, bool>,
    metric_is_l2: Constant<bool>,
    /// The configured widths ("only what the scene needs"): each axis's coordinate
    /// bits and the metric's distance bits. The differences and the sum are masked
    /// so that synthesis drops the datapath bits above them.
    mask_x: Constant<Coord>,
    mask_y: Constant<Coord>,
    mask_z: Constant<Coord>,
    dist_mask: Constant<Dist>,
    /// The full distance's bits: the grid's diagonal in the metric.
    full_mask: Constant<Dist>,
    axis_mask: Constant<Dist>,
    /// The distance bits are fewer than the grid's diagonal needs: the split-axis
    /// distance saturates.
    saturate: Constant<bool>,
    /// The sum and the split axis's term before saturation.
    sum: Signal<Local, Dist>,
    axis_term: Signal<Local, Dist>,
    /// Per axis (bit 0 = x): the query is at or above the photon (the difference's sign).
    ge: Signal<Local, Bits<3>>,
    delta_x: Signal<Local, Coord>,
    delta_y: Signal<Local, Coord>,
    delta_z: Signal<Local, Coord>,
    /// The differences as the terms take them: registered or not.
    registered: Constant<bool>,
    reg_x: DFF<Coord>,
    reg_y: DFF<Coord>,
    reg_z: DFF<Coord>,
    reg_ge: DFF<Bits<3>>,
    reg_axis: DFF<Bits<2>>,
    used_ge: Signal<Local, Bits<3>>,
    used_axis: Signal<Local, Bits<2>>,
    used_x: Signal<Local, Coord>,
    used_y: Signal<Local, Coord>,
    used_z: Signal<Local, Coord>,
    term_x: Signal<Local, Dist>,
    term_y: Signal<Local, Dist>,
    term_z: Signal<Local, Dist>,
}

impl DistModule {
    /// Full-width datapath (15-bit coordinates, 32-bit distances).
    pub fn new(metric: Metric) -> Self {
        Self::with_widths(metric, [15; 3], 32)
    }

    /// A datapath for `coord_bits` per axis and `dist_bits`-bit distances.
    pub fn with_widths(metric: Metric, coord_bits: [u32; 3], dist_bits: u32) -> Self {
        Self::pipelined(metric, coord_bits, dist_bits, false)
    }

    /// The same, with the differences registered when `registered` (the distance
    /// then belongs to the inputs of the previous cycle).
    pub fn pipelined(
        metric: Metric,
        coord_bits: [u32; 3],
        dist_bits: u32,
        registered: bool,
    ) -> Self {
        let coord = |a: usize| Constant::new(Coord::from(low_mask(coord_bits[a])));
        let widest = coord_bits.iter().copied().max().unwrap_or(0);
        let axis_bits = bits_for(metric.axis_dist(0, low_mask(widest) as u32));
        DistModule {
            clock: Default::default(),
            registered: Constant::new(registered),
            reg_x: Default::default(),
            reg_y: Default::default(),
            reg_z: Default::default(),
            reg_ge: Default::default(),
            reg_axis: Default::default(),
            used_ge: Default::default(),
            used_axis: Default::default(),
            used_x: Default::default(),
            used_y: Default::default(),
            used_z: Default::default(),
            mask_x: coord(0),
            mask_y: coord(1),
            mask_z: coord(2),
            dist_mask: Constant::new(Dist::from(low_mask(dist_bits))),
            full_mask: Constant::new(Dist::from(low_mask(metric.dist_bits(coord_bits)))),
            axis_mask: Constant::new(Dist::from(low_mask(axis_bits))),
            saturate: Constant::new(dist_bits < metric.dist_bits(coord_bits)),
            sum: Default::default(),
            axis_term: Default::default(),
            ge: Default::default(),
            query_x: Default::default(),
            query_y: Default::default(),
            query_z: Default::default(),
            photon_x: Default::default(),
            photon_y: Default::default(),
            photon_z: Default::default(),
            axis: Default::default(),
            distance: Default::default(),
            axis_dist: Default::default(),
            near_right: Default::default(),
            metric_is_l2: Constant::new(metric == Metric::L2),
            delta_x: Default::default(),
            delta_y: Default::default(),
            delta_z: Default::default(),
            term_x: Default::default(),
            term_y: Default::default(),
            term_z: Default::default(),
        }
    }
}

impl Logic for DistModule {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(self, clock, reg_x, reg_y, reg_z, reg_ge, reg_axis);
        self.ge.next = 0.into();
        self.ge.next = self
            .ge
            .val()
            .replace_bit(0, self.query_x.val() >= self.photon_x.val());
        self.ge.next = self
            .ge
            .val()
            .replace_bit(1, self.query_y.val() >= self.photon_y.val());
        self.ge.next = self
            .ge
            .val()
            .replace_bit(2, self.query_z.val() >= self.photon_z.val());
        if self.ge.val().get_bit(0) {
            self.delta_x.next = (self.query_x.val() - self.photon_x.val()) & self.mask_x.val();
        } else {
            self.delta_x.next = (self.photon_x.val() - self.query_x.val()) & self.mask_x.val();
        }
        if self.ge.val().get_bit(1) {
            self.delta_y.next = (self.query_y.val() - self.photon_y.val()) & self.mask_y.val();
        } else {
            self.delta_y.next = (self.photon_y.val() - self.query_y.val()) & self.mask_y.val();
        }
        if self.ge.val().get_bit(2) {
            self.delta_z.next = (self.query_z.val() - self.photon_z.val()) & self.mask_z.val();
        } else {
            self.delta_z.next = (self.photon_z.val() - self.query_z.val()) & self.mask_z.val();
        }
        self.reg_x.d.next = self.delta_x.val();
        self.reg_y.d.next = self.delta_y.val();
        self.reg_z.d.next = self.delta_z.val();
        self.reg_ge.d.next = self.ge.val();
        self.reg_axis.d.next = self.axis.val();
        self.used_x.next = self.delta_x.val();
        self.used_y.next = self.delta_y.val();
        self.used_z.next = self.delta_z.val();
        self.used_ge.next = self.ge.val();
        self.used_axis.next = self.axis.val();
        if self.registered.val() {
            self.used_x.next = self.reg_x.q.val();
            self.used_y.next = self.reg_y.q.val();
            self.used_z.next = self.reg_z.q.val();
            self.used_ge.next = self.reg_ge.q.val();
            self.used_axis.next = self.reg_axis.q.val();
        }
        if self.metric_is_l2.val() {
            self.term_x.next = self.used_x.val() * self.used_x.val();
            self.term_y.next = self.used_y.val() * self.used_y.val();
            self.term_z.next = self.used_z.val() * self.used_z.val();
        } else {
            self.term_x.next = bit_cast::<32, 16>(self.used_x.val());
            self.term_y.next = bit_cast::<32, 16>(self.used_y.val());
            self.term_z.next = bit_cast::<32, 16>(self.used_z.val());
        }
        // CoreConfig::validate guarantees the sum fits the datapath's 32 bits.
        self.sum.next = self.term_x.val() + self.term_y.val() + self.term_z.val();
        // The split axis's term and sign (AxisDistModule, §4.3).
        self.axis_term.next = self.term_z.val() & self.axis_mask.val();
        self.near_right.next = self.used_ge.val().get_bit(2);
        if self.used_axis.val() == 0 {
            self.axis_term.next = self.term_x.val() & self.axis_mask.val();
            self.near_right.next = self.used_ge.val().get_bit(0);
        }
        if self.used_axis.val() == 1 {
            self.axis_term.next = self.term_y.val() & self.axis_mask.val();
            self.near_right.next = self.used_ge.val().get_bit(1);
        }
        self.distance.next = self.sum.val() & self.full_mask.val();
        self.axis_dist.next = self.axis_term.val() & self.dist_mask.val();
        if self.saturate.val() && (self.axis_term.val() & !self.dist_mask.val()).any() {
            self.axis_dist.next = self.dist_mask.val();
        }
    }
}
