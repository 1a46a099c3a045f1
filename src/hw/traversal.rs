//! How the kd-tree search climbs back up: the one switch the software search
//! (`host::map::knn`) and the hardware (QueryModule, NextIndexModule) share.
//!
//! The paper's search (§2.2, §4.3) keeps no stack: on the way back up it reads every
//! parent again, only to recompute the axis distance it already had on the way down
//! and decide whether to enter the far child. On the paper's workload (1023 photons,
//! k = 10) that is 152.8 TreeModule reads per query for 77.0 distance tests: half of
//! a port's one-read-per-cycle bandwidth goes to re-reads.
//!
//! [`Traversal::Remember`] keeps, for every level of the current path, the axis
//! distance of the node read there and whether its far child is still to be visited
//! (H entries of distance bits + 1 bit per QueryModule). The way up then costs no
//! read at all: a level whose far child is pruned (or done, or absent) is passed in
//! one QueryModule cycle, and a read is issued only when the search enters a far
//! child. Reads per query = distance tests.

use std::fmt;

/// The ascent of the kd-tree search.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default, clap::ValueEnum)]
pub enum Traversal {
    /// Remember each level's axis distance on the way down; the ascent reads nothing
    /// (reads per query = distance tests). The default.
    #[default]
    Remember,
    /// The paper's search: re-read every parent on the way up.
    Reread,
}

impl fmt::Display for Traversal {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Traversal::Remember => "remember",
            Traversal::Reread => "reread",
        })
    }
}
