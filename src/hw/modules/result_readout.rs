//! ResultReadout: the read-out sequencer of a port's result stream: the
//! SearchPort's (its finished QueryModules, one photon a beat); built for two
//! photons a beat it is the sequence of the BarrelPort's SlotReadout.
//!
//! A packet ([`ResultBeat`]): a header (query id, found count, photon reads), then
//! the found photons in list-slot order, `last` on the final beat. The sequencer
//! picks the lowest finished query ([`PriorityEncoder`]), spends one cycle
//! fetching its header (count and reads) into registers, then sends the header and
//! the entry beats through a [`ResultRegister`]. Why the fetch cycle: `last` and
//! every sequencer decision then start from flip-flops, not from the selected
//! query's count through the port's read-out multiplexer. The caller supplies the
//! selected query's id, header and photons (`id`, `count`, `visited`, `address`
//! ..., zero photons in the header beat); `entry` / `entry_next` say which entry (or
//! pair of entries) the beat now and the next one carry.

use crate::hw::config::core_config::{
    bits_for, low_mask, Addr, CoreConfig, Count, Dist, ModuleIndex, ModuleMask, QueryId, ReadCount,
};
use crate::hw::primitives::lut_ram::RamIndex;
use crate::hw::primitives::priority_encoder::PriorityEncoder;
use crate::hw::primitives::register_slice::ResultRegister;
use crate::hw::primitives::stream::{ResultBeat, StreamOut};
use rust_hdl::prelude::*;

#[derive(LogicBlock)]
pub struct ResultReadout {
    pub clock: Signal<In, Clock>,
    pub reset: Signal<In, bool>,
    /// The finished queries, one bit each (module or slot).
    pub finished: Signal<In, ModuleMask>,
    /// The selected query's header (read in the fetch cycle) and id.
    pub count: Signal<In, Count>,
    pub visited: Signal<In, ReadCount>,
    pub id: Signal<In, QueryId>,
    /// The photons of the entry beat now (zero in the header beat): one, or two
    /// with `pair`.
    pub address: Signal<In, Addr>,
    pub distance: Signal<In, Dist>,
    pub pair: Signal<In, bool>,
    pub address2: Signal<In, Addr>,
    pub distance2: Signal<In, Dist>,
    /// Result packets.
    pub result: StreamOut<ResultBeat>,
    /// The query being read out (one-hot, zero when none) and its index.
    pub select: Signal<Out, ModuleMask>,
    pub index: Signal<Out, ModuleIndex>,
    /// The query whose entries the beats now carry (one-hot, a flip-flop each:
    /// from the header's acceptance to the last beat).
    pub reading: Signal<Out, ModuleMask>,
    /// The entry (pair) of the beat now, and of the beat after this cycle.
    pub entry: Signal<Out, RamIndex>,
    pub entry_next: Signal<Out, RamIndex>,
    /// Photons left before the entry beat now.
    pub left: Signal<Out, Count>,
    /// The packet's last beat leaves in this cycle.
    pub done: Signal<Out, bool>,
    lowest_finished: PriorityEncoder<32>,
    result_register: ResultRegister,
    /// Photons per entry beat (1 or 2), and twice that.
    per_beat: Constant<Count>,
    two_beats: Constant<Count>,
    count_mask: Constant<Count>,
    entry_mask: Constant<RamIndex>,
    beat: Signal<Local, ResultBeat>,
    fire: Signal<Local, bool>,
    active: DFF<bool>,
    fetch: DFF<bool>,
    header: DFF<bool>,
    select_reg: DFF<ModuleMask>,
    index_reg: DFF<ModuleIndex>,
    reading_reg: DFF<ModuleMask>,
    entry_reg: DFF<RamIndex>,
    /// Photons left, and whether the entry beat now is the last.
    left_reg: DFF<Count>,
    entry_last: DFF<bool>,
    hdr_count: DFF<Count>,
    hdr_visited: DFF<ReadCount>,
    hdr_last: DFF<bool>,
}

impl ResultReadout {
    /// The sequencer of `cfg`'s port, `per_beat` (1 or 2) photons an entry beat.
    pub fn new(cfg: &CoreConfig, per_beat: usize) -> Self {
        assert!((1..=2).contains(&per_beat));
        let entry_bits = bits_for((cfg.k.saturating_sub(1) / per_beat) as u64);
        ResultReadout {
            clock: Default::default(),
            reset: Default::default(),
            finished: Default::default(),
            count: Default::default(),
            visited: Default::default(),
            id: Default::default(),
            address: Default::default(),
            distance: Default::default(),
            pair: Default::default(),
            address2: Default::default(),
            distance2: Default::default(),
            result: Default::default(),
            select: Default::default(),
            index: Default::default(),
            reading: Default::default(),
            entry: Default::default(),
            entry_next: Default::default(),
            left: Default::default(),
            done: Default::default(),
            lowest_finished: PriorityEncoder::lowest(cfg.queries_per_port),
            result_register: ResultRegister::new(!cfg.pipelined),
            per_beat: Constant::new(Count::from(per_beat as u64)),
            two_beats: Constant::new(Count::from(2 * per_beat as u64)),
            count_mask: Constant::new(Count::from(cfg.count_mask())),
            entry_mask: Constant::new(RamIndex::from(low_mask(entry_bits))),
            beat: Default::default(),
            fire: Default::default(),
            active: Default::default(),
            fetch: Default::default(),
            header: Default::default(),
            select_reg: Default::default(),
            index_reg: Default::default(),
            reading_reg: Default::default(),
            entry_reg: Default::default(),
            left_reg: Default::default(),
            entry_last: Default::default(),
            hdr_count: Default::default(),
            hdr_visited: Default::default(),
            hdr_last: Default::default(),
        }
    }
}

impl Logic for ResultReadout {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(
            self,
            clock,
            active,
            fetch,
            header,
            select_reg,
            index_reg,
            reading_reg,
            entry_reg,
            left_reg,
            entry_last,
            hdr_count,
            hdr_visited,
            hdr_last
        );
        self.lowest_finished.mask.next = self.finished.val();
        self.fire.next = self.active.q.val()
            && (!self.fetch.q.val())
            && self.result_register.inbound.ready.val();
        // The beat: the caller's photons, the header fields from the registers.
        self.beat.next.address = self.address.val();
        self.beat.next.distance = self.distance.val();
        self.beat.next.pair = self.pair.val();
        self.beat.next.address2 = self.address2.val();
        self.beat.next.distance2 = self.distance2.val();
        self.beat.next.header = self.header.q.val();
        self.beat.next.id = 0.into();
        if self.active.q.val() {
            self.beat.next.id = self.id.val();
        }
        self.beat.next.count = self.hdr_count.q.val();
        self.beat.next.visited = self.hdr_visited.q.val();
        if self.header.q.val() {
            self.beat.next.last = self.hdr_last.q.val();
        } else {
            self.beat.next.last = self.entry_last.q.val();
        }
        self.done.next = self.fire.val() && self.beat.val().last;
        // The entry of the next beat.
        self.entry_next.next = self.entry_reg.q.val();
        if self.fire.val() && (!self.header.q.val()) {
            self.entry_next.next = (self.entry_reg.q.val() + 1) & self.entry_mask.val();
        }
        self.entry_reg.d.next = self.entry_next.val();
        // Pick a finished query, fetch its header, send the header, then the entries.
        if !self.active.q.val() {
            if self.finished.val().any() {
                self.active.d.next = true;
                self.fetch.d.next = true;
                self.select_reg.d.next = self.lowest_finished.lowest.val();
                self.index_reg.d.next = self.lowest_finished.index.val();
                self.entry_reg.d.next = 0.into();
            }
        } else if self.fetch.q.val() {
            self.fetch.d.next = false;
            self.header.d.next = true;
            self.hdr_count.d.next = self.count.val();
            self.hdr_visited.d.next = self.visited.val();
            self.hdr_last.d.next = self.count.val() == 0;
        } else if self.fire.val() {
            if self.header.q.val() {
                self.header.d.next = false;
                self.reading_reg.d.next = self.select_reg.q.val();
                self.left_reg.d.next = self.hdr_count.q.val();
                self.entry_last.d.next = self.hdr_count.q.val() <= self.per_beat.val();
            } else {
                // (Not the last beat: more than one beat's photons were left.)
                self.left_reg.d.next =
                    (self.left_reg.q.val() - self.per_beat.val()) & self.count_mask.val();
                self.entry_last.d.next = self.left_reg.q.val() <= self.two_beats.val();
            }
            if self.beat.val().last {
                self.active.d.next = false;
                self.select_reg.d.next = 0.into();
                self.index_reg.d.next = 0.into();
                self.reading_reg.d.next = 0.into();
            }
        }
        if self.reset.val() {
            self.active.d.next = false;
            self.fetch.d.next = false;
            self.header.d.next = false;
            self.select_reg.d.next = 0.into();
            self.index_reg.d.next = 0.into();
            self.reading_reg.d.next = 0.into();
        }
        self.select.next = self.select_reg.q.val();
        self.index.next = self.index_reg.q.val();
        self.reading.next = self.reading_reg.q.val();
        self.entry.next = self.entry_reg.q.val();
        self.left.next = self.left_reg.q.val();
        // The beat leaves through the ResultRegister.
        self.result_register.clock.next = self.clock.val();
        self.result_register.reset.next = self.reset.val();
        self.result_register.inbound.valid.next = self.active.q.val() && (!self.fetch.q.val());
        self.result_register.inbound.data.next = self.beat.val();
        self.result_register.outbound.ready.next = self.result.ready.val();
        self.result.valid.next = self.result_register.outbound.valid.val();
        self.result.data.next = self.result_register.outbound.data.val();
    }
}
