//! PortArbiter (paper §4.5): Q QueryModules share one TreeModule port; one read is
//! granted per cycle, round-robin among the modules requesting. With Q at least the
//! issue interval of a QueryModule, the port reads a photon every cycle when all of
//! them are busy.
//!
//! Round robin on one-hot masks: requests above the last grant win first, else the
//! lowest request wraps around; "lowest set bit" is `x & (!x + 1)`. The turn moves
//! only when the user says the grant was used (`advance`, e.g. a stream beat moved),
//! as in verilog-axis' `arbiter` with ARB_BLOCK_ACK; `hold` keeps granting the last
//! grant (a packet in progress, [`crate::hw::packet_merge`]). The same block picks
//! the reading QueryModule of a port, the core or tree a query goes to
//! ([`crate::hw::dispatcher`]) and the source of the next result packet.

use crate::hw::config::ModuleMask;
use rust_hdl::prelude::*;

#[derive(LogicBlock)]
pub struct PortArbiter {
    pub clock: Signal<In, Clock>,
    /// Bit i: QueryModule i requests a read.
    pub requests: Signal<In, ModuleMask>,
    /// The grant was used this cycle: the next turn starts after it.
    pub advance: Signal<In, bool>,
    /// Grant the last grant again, whatever the requests.
    pub hold: Signal<In, bool>,
    /// One-hot grant (zero when nobody requests).
    pub grant: Signal<Out, ModuleMask>,
    pub granted: Signal<Out, bool>,
    last_grant: DFF<ModuleMask>,
    /// Every bit at or below the last grant, kept in a register beside it so that
    /// the grant starts from flip-flops, not from a subtraction (issue 11: the
    /// arbiter → read address path limits a port's clock).
    at_or_below_last: DFF<ModuleMask>,
    above_last: Signal<Local, ModuleMask>,
    above_less: Signal<Local, ModuleMask>,
    requests_less: Signal<Local, ModuleMask>,
    /// Every bit at or below `grant` (all bits when nothing is granted).
    next_at_or_below: Signal<Local, ModuleMask>,
    /// The `n` requesters that exist: the registers' other bits are constant zero,
    /// which synthesis sees only through this mask.
    mask: Constant<ModuleMask>,
}

impl PortArbiter {
    /// An arbiter among `n` (1..=32) requesters.
    pub fn new(n: usize) -> Self {
        assert!((1..=32).contains(&n));
        PortArbiter {
            clock: Default::default(),
            requests: Default::default(),
            advance: Default::default(),
            hold: Default::default(),
            grant: Default::default(),
            granted: Default::default(),
            last_grant: Default::default(),
            at_or_below_last: Default::default(),
            above_last: Default::default(),
            above_less: Default::default(),
            requests_less: Default::default(),
            next_at_or_below: Default::default(),
            mask: Constant::new(ModuleMask::from(u64::MAX >> (64 - n))),
        }
    }
}

impl Default for PortArbiter {
    /// Among 32 requesters, the widest.
    fn default() -> Self {
        Self::new(32)
    }
}

impl Logic for PortArbiter {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(self, clock, last_grant, at_or_below_last);
        self.above_last.next = self.requests.val() & (!self.at_or_below_last.q.val());
        // For a mask x, x - 1 gives both the lowest set bit, x & !(x - 1), and every
        // bit at or below it, x ^ (x - 1) (all bits when x = 0): the next
        // `at_or_below_last` comes from the same carry chain as the grant, beside
        // it, not from a second subtraction after it (issue 11: request → grant →
        // `(grant << 1) - 1` was two carry chains in series, a port's critical path).
        self.above_less.next = self.above_last.val() - 1;
        self.requests_less.next = self.requests.val() - 1;
        if self.hold.val() {
            self.grant.next = self.last_grant.q.val();
            self.next_at_or_below.next = (self.last_grant.q.val() << 1) - 1;
        } else if self.above_last.val().any() {
            self.grant.next = self.above_last.val() & (!self.above_less.val());
            self.next_at_or_below.next = self.above_last.val() ^ self.above_less.val();
        } else {
            self.grant.next = self.requests.val() & (!self.requests_less.val());
            self.next_at_or_below.next = self.requests.val() ^ self.requests_less.val();
        }
        self.granted.next = self.requests.val().any();
        if self.advance.val() {
            self.last_grant.d.next = self.grant.val() & self.mask.val();
            self.at_or_below_last.d.next = self.next_at_or_below.val() & self.mask.val();
        }
    }
}
