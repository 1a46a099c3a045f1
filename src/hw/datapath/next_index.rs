//! NextIndexModule (paper §4.3): the kd-tree traversal step of knn.rs, in logic.
//! State = (address, up/down, came-from bit). With `near` = the right child iff
//! `q[a] >= p[a]` and children at 2i / 2i+1 existing iff their address <= N:
//! * down: go to the near child if it exists, else to the far child if it exists and
//!   the axis distance is within_radius R, else up;
//! * up (re-read of a parent): go down into the far child if we came from the near
//!   child, it exists and the axis distance is within_radius R, else up;
//! * up from the root is the end of the search.
//!
//! `within_radius` is `ad < R` once the found list is full and `ad <= R` before (the initial
//! radius is inclusive), with R as it was when the photon was read.
//!
//! With [`Traversal::Remember`](crate::hw::config::traversal::Traversal) every read is a down
//! visit (`up` is never set) and an "up" result hands the ascent to the QueryModule;
//! `far_pending` tells it to remember that this level's far child is still to be
//! visited (the search goes to the near child and the far child exists).

use crate::hw::config::core_config::{Addr, Dist};
use rust_hdl::prelude::*;

#[derive(LogicBlock)]
pub struct NextIndexModule {
    /// Address of the photon just read, and how we got there.
    pub address: Signal<In, Addr>,
    pub up: Signal<In, bool>,
    pub came_from_right: Signal<In, bool>,
    /// From DistModule (the paper's AxisDistModule).
    pub near_right: Signal<In, bool>,
    pub axis_dist: Signal<In, Dist>,
    /// The requesting QueryModule's radius and full flag.
    pub radius: Signal<In, Dist>,
    pub full: Signal<In, bool>,
    /// Number of photons N: the highest valid heap address.
    pub photon_count: Signal<In, Addr>,
    pub next_address: Signal<Out, Addr>,
    pub next_up: Signal<Out, bool>,
    pub next_came_from_right: Signal<Out, bool>,
    /// The search is over (up from the root).
    pub done: Signal<Out, bool>,
    /// A down visit that goes to the near child while the far child exists.
    pub far_pending: Signal<Out, bool>,
    /// H+1 address bits hold every child address 2i+1 <= 2N+1 < 2^(H+1); masking
    /// with it tells synthesis that the upper bits of the 24-bit datapath are zero.
    address_mask: Constant<Addr>,
    near_child: Signal<Local, Addr>,
    far_child: Signal<Local, Addr>,
    within_radius: Signal<Local, bool>,
    go_far: Signal<Local, bool>,
}

impl NextIndexModule {
    /// For a TreeModule of 2^`address_bits` words.
    pub fn new(address_bits: u32) -> Self {
        NextIndexModule {
            address: Default::default(),
            up: Default::default(),
            came_from_right: Default::default(),
            near_right: Default::default(),
            axis_dist: Default::default(),
            radius: Default::default(),
            full: Default::default(),
            photon_count: Default::default(),
            next_address: Default::default(),
            next_up: Default::default(),
            next_came_from_right: Default::default(),
            done: Default::default(),
            far_pending: Default::default(),
            address_mask: Constant::new(Addr::from((1u64 << (address_bits + 1)) - 1)),
            near_child: Default::default(),
            far_child: Default::default(),
            within_radius: Default::default(),
            go_far: Default::default(),
        }
    }
}

impl Logic for NextIndexModule {
    #[hdl_gen]
    fn update(&mut self) {
        if self.near_right.val() {
            self.near_child.next = ((self.address.val() << 1) + 1) & self.address_mask.val();
            self.far_child.next = (self.address.val() << 1) & self.address_mask.val();
        } else {
            self.near_child.next = (self.address.val() << 1) & self.address_mask.val();
            self.far_child.next = ((self.address.val() << 1) + 1) & self.address_mask.val();
        }
        if self.full.val() {
            self.within_radius.next = self.axis_dist.val() < self.radius.val();
        } else {
            self.within_radius.next = self.axis_dist.val() <= self.radius.val();
        }
        // The far subtree is entered on the way down when there is no near child,
        // or on the way back up from the near child.
        if self.up.val() {
            self.go_far.next = (self.came_from_right.val() == self.near_right.val())
                && (self.far_child.val() <= self.photon_count.val())
                && self.within_radius.val();
        } else {
            self.go_far.next = (self.near_child.val() > self.photon_count.val())
                && (self.far_child.val() <= self.photon_count.val())
                && self.within_radius.val();
        }
        self.far_pending.next = (!self.up.val())
            && (self.near_child.val() <= self.photon_count.val())
            && (self.far_child.val() <= self.photon_count.val());
        self.done.next = false;
        self.next_up.next = false;
        self.next_came_from_right.next = false;
        if (!self.up.val()) && (self.near_child.val() <= self.photon_count.val()) {
            self.next_address.next = self.near_child.val();
        } else if self.go_far.val() {
            self.next_address.next = self.far_child.val();
        } else {
            self.next_address.next = self.address.val() >> 1;
            self.next_up.next = true;
            self.next_came_from_right.next = self.address.val().get_bit(0);
            self.done.next = self.address.val() == 1;
        }
    }
}
