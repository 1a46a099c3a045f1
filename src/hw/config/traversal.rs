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
//!
//! [`Traversal::Cell`] is `Remember` with a tighter pruning bound: the distance from
//! the query to the far child's whole cell (Arya and Mount's incremental distance,
//! "Algorithms for fast vector quantization", DCC 1993), not just to its splitting
//! plane. Both metrics are sums over the axes, so the cell distance is the sum of
//! the query's per-axis offsets from the cell, and entering a far child changes one
//! of them: `rd_far = rd - off[a] + axis_dist`. The QueryModule keeps the three
//! offsets and `rd`, and remembers per level `rd_far`, the replaced offset (restored
//! on the way up) and the axis distance (the new offset on entry). On the paper's
//! workload (1023 uniform photons, 10 bits, L1, k = 10, unbounded R) a query reads
//! 81.8 photons instead of 142.9; with squared L2, 64.7 instead of 77.2 (the axis
//! distance is a far poorer bound on an L1 ball, a sum of three axes). A far child
//! entered directly because the near one does not exist (at most one node of a
//! heap-ordered tree) is tested on its axis distance and leaves the offsets as they
//! are (a lower bound still), as the SearchModule decides it alone.

use serde::{Deserialize, Serialize};
use std::fmt;

/// The ascent of the kd-tree search (`--traversal`, the core file's `traversal`);
/// each variant's doc is its help text.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[serde(rename_all = "lowercase")]
pub enum Traversal {
    /// Remember each level's axis distance on the way down: the ascent reads
    /// nothing (reads per query = distance tests).
    #[default]
    Remember,
    /// The paper's search: re-read every parent on the way up.
    Reread,
    /// Remember the path and prune on the distance to the far child's cell
    /// (Arya and Mount): fewest reads.
    Cell,
}

impl Traversal {
    /// The ascent reads nothing: a path memory per QueryModule.
    pub fn remembers(self) -> bool {
        self != Traversal::Reread
    }
}

impl fmt::Display for Traversal {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Traversal::Remember => "remember",
            Traversal::Reread => "reread",
            Traversal::Cell => "cell",
        })
    }
}
