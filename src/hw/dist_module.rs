//! DistModule (paper §4.3): the full query-photon distance in the search metric
//! (sum of the three axis distances: squared L2 or L1, no square root) and the
//! in-range test against the radius of the QueryModule that issued the read.
//! Before the found list is full the initial radius is inclusive (`d <= R`); once
//! full, R is the list maximum and only a strictly nearer photon enters (`d < R`),
//! the boundary rules of knn.rs. It runs in parallel with AxisDist/NextIndex.

use crate::hw::config::{Coord, Dist};
use crate::hw::metric::Metric;
use rust_hdl::prelude::*;

#[derive(LogicBlock)]
pub struct DistModule {
    pub query_x: Signal<In, Coord>,
    pub query_y: Signal<In, Coord>,
    pub query_z: Signal<In, Coord>,
    pub photon_x: Signal<In, Coord>,
    pub photon_y: Signal<In, Coord>,
    pub photon_z: Signal<In, Coord>,
    /// The requesting QueryModule's current radius R and its list-full flag.
    pub radius: Signal<In, Dist>,
    pub full: Signal<In, bool>,
    pub distance: Signal<Out, Dist>,
    pub in_range: Signal<Out, bool>,
    metric_is_l2: Constant<bool>,
    delta_x: Signal<Local, Coord>,
    delta_y: Signal<Local, Coord>,
    delta_z: Signal<Local, Coord>,
    term_x: Signal<Local, Dist>,
    term_y: Signal<Local, Dist>,
    term_z: Signal<Local, Dist>,
}

impl DistModule {
    pub fn new(metric: Metric) -> Self {
        DistModule {
            query_x: Default::default(),
            query_y: Default::default(),
            query_z: Default::default(),
            photon_x: Default::default(),
            photon_y: Default::default(),
            photon_z: Default::default(),
            radius: Default::default(),
            full: Default::default(),
            distance: Default::default(),
            in_range: Default::default(),
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
        if self.query_x.val() >= self.photon_x.val() {
            self.delta_x.next = self.query_x.val() - self.photon_x.val();
        } else {
            self.delta_x.next = self.photon_x.val() - self.query_x.val();
        }
        if self.query_y.val() >= self.photon_y.val() {
            self.delta_y.next = self.query_y.val() - self.photon_y.val();
        } else {
            self.delta_y.next = self.photon_y.val() - self.query_y.val();
        }
        if self.query_z.val() >= self.photon_z.val() {
            self.delta_z.next = self.query_z.val() - self.photon_z.val();
        } else {
            self.delta_z.next = self.photon_z.val() - self.query_z.val();
        }
        if self.metric_is_l2.val() {
            self.term_x.next = self.delta_x.val() * self.delta_x.val();
            self.term_y.next = self.delta_y.val() * self.delta_y.val();
            self.term_z.next = self.delta_z.val() * self.delta_z.val();
        } else {
            self.term_x.next = bit_cast::<32, 16>(self.delta_x.val());
            self.term_y.next = bit_cast::<32, 16>(self.delta_y.val());
            self.term_z.next = bit_cast::<32, 16>(self.delta_z.val());
        }
        // CoreConfig::validate guarantees the sum fits the distance width.
        self.distance.next = self.term_x.val() + self.term_y.val() + self.term_z.val();
        if self.full.val() {
            self.in_range.next = self.distance.val() < self.radius.val();
        } else {
            self.in_range.next = self.distance.val() <= self.radius.val();
        }
    }
}
