//! Who runs a port's queries: the paper's QueryModules or one shared datapath.
//!
//! The paper (§4.2, §4.5) gives each of a port's Q queries its own QueryModule —
//! controller, MaxFinder, found list — so that one of them can use the port in
//! every cycle while the others wait. [`Controller::Barrel`] keeps the Q queries as
//! slots in memory and runs them through one pipelined datapath per port
//! ([`BarrelPort`](crate::hw::barrel::barrel_port::BarrelPort)): the same reads, a
//! fraction of the logic (a core's QueryModules hold nearly all of its LUTs).

use std::fmt;

/// The controller of a port's queries.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum Controller {
    /// Q QueryModules per port, a round-robin arbiter (the paper's). The default.
    #[default]
    Modules,
    /// Q query slots in LUT-RAM and BlockRAM behind one pipelined datapath per
    /// port. Needs a traversal that remembers the path (`remember`, `cell`).
    Barrel,
}

impl fmt::Display for Controller {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Controller::Modules => "modules",
            Controller::Barrel => "barrel",
        })
    }
}
