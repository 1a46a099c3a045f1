//! PortArbiter (paper §4.5): Q QueryModules share one TreeModule port; one read is
//! granted per cycle, round-robin among the modules requesting. With Q at least the
//! issue interval of a QueryModule, the port reads a photon every cycle when all of
//! them are busy.
//!
//! Round robin on one-hot masks: requests above the last grant win first, else the
//! lowest request wraps around; both at once as the lowest set bit of one 2n-bit
//! word, `x & !(x - 1)` (see `update`). The turn moves
//! only when the user says the grant was used (`advance`, e.g. a stream beat moved),
//! as in verilog-axis' `arbiter` with ARB_BLOCK_ACK; `hold` keeps granting the last
//! grant (a packet in progress, [`crate::hw::top::packet_merge`]). The same block picks
//! the reading QueryModule of a port, the core or tree a query goes to
//! ([`crate::hw::top::dispatcher`]) and the source of the next result packet.

use crate::hw::config::core_config::ModuleMask;
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
    /// The last grant used (what `hold` grants), from its register.
    pub last_grant: Signal<Out, ModuleMask>,
    last: DFF<ModuleMask>,
    /// Every bit at or below the last grant, kept in a register beside it so that
    /// the grant starts from flip-flops, not from a subtraction (the arbiter → read
    /// address path bounds a port's clock).
    at_or_below_last: DFF<ModuleMask>,
    above_last: Signal<Local, ModuleMask>,
    /// {requests, above_last} (bits 2n-1..n, n-1..0), that minus one, its lowest
    /// set bit and every bit at or below that.
    both: Signal<Local, Bits<64>>,
    both_less: Signal<Local, Bits<64>>,
    lowest: Signal<Local, Bits<64>>,
    upto: Signal<Local, Bits<64>>,
    /// n, the requesters.
    n: Constant<Bits<6>>,
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
            last: Default::default(),
            last_grant: Default::default(),
            at_or_below_last: Default::default(),
            above_last: Default::default(),
            both: Default::default(),
            both_less: Default::default(),
            lowest: Default::default(),
            upto: Default::default(),
            n: Constant::new(Bits::<6>::from(n as u64)),
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
        dff_setup!(self, clock, last, at_or_below_last);
        self.above_last.next = self.requests.val() & (!self.at_or_below_last.q.val());
        // Round robin as one "lowest set bit" over 2n bits, {requests, above_last}:
        // one subtraction, where a mux between two lowest bits (selected by a
        // reduction over `above_last`) and a second subtraction for the next mask
        // would be a longer path. For x = that word, x & !(x - 1) is the lowest set
        // bit (in the low half if anything is above the last grant, else in the
        // high half: the grant is the OR of the halves) and x ^ (x - 1) every bit
        // at or below it; its bit n tells which half, and the next
        // `at_or_below_last` is that half (all ones when nothing is requested).
        self.both.next = (bit_cast::<64, 32>(self.requests.val()) << self.n.val())
            | bit_cast::<64, 32>(self.above_last.val());
        self.both_less.next = self.both.val() - 1;
        self.lowest.next = self.both.val() & (!self.both_less.val());
        self.upto.next = self.both.val() ^ self.both_less.val();
        if self.hold.val() {
            self.grant.next = self.last.q.val();
            self.next_at_or_below.next = (self.last.q.val() << 1) - 1;
        } else {
            self.grant.next = (bit_cast::<32, 64>(self.lowest.val()) & self.mask.val())
                | bit_cast::<32, 64>(self.lowest.val() >> self.n.val());
            if self.upto.val().get_bit(self.n.val().index()) {
                self.next_at_or_below.next = bit_cast::<32, 64>(self.upto.val() >> self.n.val());
            } else {
                self.next_at_or_below.next = bit_cast::<32, 64>(self.upto.val());
            }
        }
        self.granted.next = self.requests.val().any();
        self.last_grant.next = self.last.q.val();
        if self.advance.val() {
            self.last.d.next = self.grant.val() & self.mask.val();
            self.at_or_below_last.d.next = self.next_at_or_below.val() & self.mask.val();
        }
    }
}
