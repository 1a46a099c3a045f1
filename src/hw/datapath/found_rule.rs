//! FoundRule: where a photon in range enters a query's found list, and what that
//! does to the list — knn.rs's `FoundList` step, shared by a QueryModule (paper
//! §4.2, slots one-hot) and a BarrelPort slot (entries by index).
//!
//! While the list is not full the photon is appended at `count` and the count goes
//! up; the append that makes `count + 1 == k` fills the list. Once full, the photon
//! replaces the maximum's entry. Filling the list or replacing in it means a new
//! maximum, the new radius R: the MaxFinder (§4.4) or FoundMax runs (`run_max`).
//! `T` is how an entry is named: a one-hot slot mask or an entry index.

use crate::hw::config::core_config::{CoreConfig, Count};
use rust_hdl::prelude::*;

#[derive(LogicBlock)]
pub struct FoundRule<T: Synth> {
    /// A photon in range enters the list in this cycle.
    pub insert: Signal<In, bool>,
    /// The list as it is: full, its count, its k, the entry after the last
    /// (`count`'s) and the maximum's entry (valid when full).
    pub full: Signal<In, bool>,
    pub count: Signal<In, Count>,
    pub k: Signal<In, Count>,
    pub append_at: Signal<In, T>,
    pub max_at: Signal<In, T>,
    /// The entry the photon goes to.
    pub at: Signal<Out, T>,
    /// The photon is appended: the count becomes `next_count`.
    pub appends: Signal<Out, bool>,
    pub next_count: Signal<Out, Count>,
    /// The append fills the list.
    pub fills: Signal<Out, bool>,
    /// A new maximum is to be found (the list fills or was full).
    pub run_max: Signal<Out, bool>,
    /// The next append will fill the list (`count + 2 == k`): for a controller
    /// that registers the decision a photon ahead.
    pub fills_next: Signal<Out, bool>,
    count_mask: Constant<Count>,
}

impl<T: Synth> FoundRule<T> {
    pub fn new(cfg: &CoreConfig) -> Self {
        FoundRule {
            insert: Default::default(),
            full: Default::default(),
            count: Default::default(),
            k: Default::default(),
            append_at: Default::default(),
            max_at: Default::default(),
            at: Default::default(),
            appends: Default::default(),
            next_count: Default::default(),
            fills: Default::default(),
            run_max: Default::default(),
            fills_next: Default::default(),
            count_mask: Constant::new(Count::from(cfg.count_mask())),
        }
    }
}

impl<T: Synth> Logic for FoundRule<T> {
    #[hdl_gen]
    fn update(&mut self) {
        if self.full.val() {
            self.at.next = self.max_at.val();
        } else {
            self.at.next = self.append_at.val();
        }
        self.appends.next = self.insert.val() && (!self.full.val());
        self.next_count.next = (self.count.val() + 1) & self.count_mask.val();
        self.fills.next = self.appends.val() && ((self.count.val() + 1) == self.k.val());
        self.run_max.next = self.fills.val() || (self.insert.val() && self.full.val());
        self.fills_next.next = (self.count.val() + 2) == self.k.val();
    }
}
