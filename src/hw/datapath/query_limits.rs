//! QueryLimits: a query's radius and k as the controller keeps them — what a
//! QueryModule (paper §4.2) or a BarrelPort slot loads when it takes a query.
//!
//! The radius register holds distance bits only ([`CoreConfig::dist_mask`]): a
//! radius beyond every possible distance is the largest one, which keeps the same
//! photons within it. k is kept in count bits (1..=K).

use crate::hw::config::core_config::{CoreConfig, Count, Dist};
use crate::hw::primitives::stream::QueryBeat;
use rust_hdl::prelude::*;

#[derive(LogicBlock)]
pub struct QueryLimits {
    pub query: Signal<In, QueryBeat>,
    /// The initial radius R, clamped to the distance bits.
    pub radius: Signal<Out, Dist>,
    /// k, in count bits.
    pub k: Signal<Out, Count>,
    dist_mask: Constant<Dist>,
    count_mask: Constant<Count>,
}

impl QueryLimits {
    pub fn new(cfg: &CoreConfig) -> Self {
        QueryLimits {
            query: Default::default(),
            radius: Default::default(),
            k: Default::default(),
            dist_mask: Constant::new(Dist::from(cfg.dist_mask())),
            count_mask: Constant::new(Count::from(cfg.count_mask())),
        }
    }
}

impl Logic for QueryLimits {
    #[hdl_gen]
    fn update(&mut self) {
        if (self.query.val().radius & (!self.dist_mask.val())).any() {
            self.radius.next = self.dist_mask.val();
        } else {
            self.radius.next = self.query.val().radius & self.dist_mask.val();
        }
        self.k.next = self.query.val().k & self.count_mask.val();
    }
}
