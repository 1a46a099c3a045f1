//! Who runs a port's queries: the paper's QueryModules or one shared datapath.
//!
//! The paper (§4.2, §4.5) gives each of a port's Q queries its own QueryModule —
//! controller, MaxFinder, found list — so that one of them can use the port in
//! every cycle while the others wait. [`Controller::Barrel`] keeps the Q queries as
//! slots in memory and runs them through one pipelined datapath per port
//! ([`BarrelPort`](crate::hw::barrel::barrel_port::BarrelPort)): the same reads, a
//! fraction of the logic (a core's QueryModules hold nearly all of its LUTs).

use crate::hw::config::traversal::Traversal;
use serde::{Deserialize, Serialize};
use std::fmt;

/// The controller of a port's queries (`--controller`, the core file's
/// `controller`); each variant's doc is its help text.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[serde(rename_all = "lowercase")]
pub enum Controller {
    /// Q QueryModules per port behind a round-robin arbiter (the paper's, §4.2).
    #[default]
    Modules,
    /// Q query slots in memory behind one pipelined datapath per port: about a
    /// fifth of the LUTs for nearly the same queries/s. Needs a traversal that
    /// remembers the path (remember, cell).
    Barrel,
}

impl Controller {
    /// The traversal a core of this controller has unless one is chosen: the cell
    /// bound for the barrel controller (the best core measured), else
    /// [`Traversal::default`].
    pub fn default_traversal(self) -> Traversal {
        match self {
            Controller::Barrel => Traversal::Cell,
            Controller::Modules => Traversal::default(),
        }
    }
}

impl fmt::Display for Controller {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Controller::Modules => "modules",
            Controller::Barrel => "barrel",
        })
    }
}
