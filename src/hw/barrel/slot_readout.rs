//! SlotReadout: a [`BarrelPort`](crate::hw::barrel::barrel_port::BarrelPort)'s result
//! stream. A finished slot's packet — a header (query id, found count, photon
//! reads), then its found photons in list-slot order, two a beat ([`ResultBeat`])
//! — through a [`ResultRegister`]; the slot is freed by its last beat.
//!
//! Where the data waits: the found photons (heap address and distance) in two
//! BlockRAMs, even and odd list entries, one pair of entries per word address, so
//! that a beat reads two photons (each BlockRAM has one read port); the query ids,
//! counts and reads in LUT-RAM, one entry per slot. The header's count and reads
//! are fetched into registers the cycle before the header (as the SearchPort
//! does: `last` and every sequencer decision then start from flip-flops), and the
//! BlockRAMs are addressed with the next pair while a beat leaves, so that their
//! registered read keeps up with one beat per cycle. A found photon is written a
//! cycle after it is offered (its entry comes from the slot state's asynchronous
//! read in the port's stage A; the BlockRAMs' write port is then not the end of
//! that path); its packet leaves cycles later, after the search's last stage.
//!
//! With found heaps (K above the comparator tree's) the BlockRAMs keep addresses
//! only and the entries' distances go out as zero: the heap's keys already hold
//! every distance, and storing them twice would double the read-out's BlockRAM
//! (16 slots × 512 entries × 22 bits per datapath). The host has the map and the
//! query, so the driver computes each entry's distance from its address
//! ([`CoreConfig::sends_distances`]).

use crate::hw::config::core_config::{
    bits_for, low_mask, CoreConfig, Count, Dist, Entry, ModuleIndex, ModuleMask, ReadCount,
};
use crate::hw::primitives::block_ram::{BlockRam, BramIndex, BramWord};
use crate::hw::primitives::lut_ram::{LutRam, RamIndex};
use crate::hw::primitives::priority_encoder::PriorityEncoder;
use crate::hw::primitives::register_slice::ResultRegister;
use crate::hw::primitives::stream::{ResultBeat, StreamOut};
use rust_hdl::prelude::*;

#[derive(LogicBlock)]
pub struct SlotReadout {
    pub clock: Signal<In, Clock>,
    pub reset: Signal<In, bool>,
    /// A query loaded into slot `id_slot` with this id.
    pub id_write: Signal<In, bool>,
    pub id_slot: Signal<In, ModuleIndex>,
    pub id: Signal<In, Bits<32>>,
    /// A photon entered entry `found_pos` of slot `found_slot`'s list.
    pub found_write: Signal<In, bool>,
    pub found_slot: Signal<In, ModuleIndex>,
    pub found_pos: Signal<In, Entry>,
    pub found_address: Signal<In, Bits<24>>,
    pub found_dist: Signal<In, Dist>,
    /// The search of slot `done_slot` ended with this count and photon reads.
    pub done: Signal<In, bool>,
    pub done_slot: Signal<In, ModuleIndex>,
    pub done_count: Signal<In, Count>,
    pub done_visited: Signal<In, ReadCount>,
    /// Result packets.
    pub result: StreamOut<ResultBeat>,
    /// The slot whose last beat left in this cycle (one-hot; zero: none).
    pub freed: Signal<Out, ModuleMask>,
    one_slot: Constant<ModuleMask>,
    dist_mask: Constant<Dist>,
    count_mask: Constant<Count>,
    visited_mask: Constant<ReadCount>,
    pair_shift: Constant<BramIndex>,
    pair_mask: Constant<RamIndex>,
    addr_shift: Constant<Bits<8>>,
    addr_mask: Constant<Bits<24>>,
    dist_mask_wide: Constant<BramWord>,
    addr_mask_wide: Constant<BramWord>,
    ids: LutRam,
    out_count_mem: LutRam,
    out_visited_mem: LutRam,
    /// Per (slot, pair of entries): heap address | distance << H.
    found_even: BlockRam,
    found_odd: BlockRam,
    result_register: ResultRegister,
    /// Slots whose search ended and whose packet has not left yet.
    finished: DFF<ModuleMask>,
    /// The found photon's write, registered: where, what, and into which BlockRAM.
    a_found_index: DFF<BramIndex>,
    a_found_entry: DFF<BramWord>,
    a_found_even: DFF<bool>,
    a_found_odd: DFF<bool>,
    done_bit: Signal<Local, ModuleMask>,
    result_fire: Signal<Local, bool>,
    /// The lowest finished slot: its packet leaves next.
    finished_pick: PriorityEncoder<32>,
    beat: Signal<Local, ResultBeat>,
    out_entry_next: Signal<Local, RamIndex>,
    out_found_index: Signal<Local, BramIndex>,
    out_active: DFF<bool>,
    out_fetch: DFF<bool>,
    out_header: DFF<bool>,
    out_index: DFF<ModuleIndex>,
    /// The pair of entries of the beat now, and the photons left.
    out_entry: DFF<RamIndex>,
    out_left: DFF<Count>,
    out_last: DFF<bool>,
    hdr_count: DFF<Count>,
    hdr_visited: DFF<ReadCount>,
    hdr_last: DFF<bool>,
}

impl SlotReadout {
    /// The found lists' BlockRAMs: (index bits, width) each.
    pub fn block_rams(&self) -> Vec<(u32, u32)> {
        BlockRam::shapes([&self.found_even, &self.found_odd])
    }

    pub fn new(cfg: &CoreConfig) -> Self {
        let q = cfg.queries_per_port;
        let db = if cfg.sends_distances() {
            cfg.dist_bits()
        } else {
            0
        };
        let slot_bits = bits_for(q.saturating_sub(1) as u64);
        let pair_bits = bits_for((cfg.k.saturating_sub(1) / 2) as u64);
        SlotReadout {
            clock: Default::default(),
            reset: Default::default(),
            id_write: Default::default(),
            id_slot: Default::default(),
            id: Default::default(),
            found_write: Default::default(),
            found_slot: Default::default(),
            found_pos: Default::default(),
            found_address: Default::default(),
            found_dist: Default::default(),
            done: Default::default(),
            done_slot: Default::default(),
            done_count: Default::default(),
            done_visited: Default::default(),
            result: Default::default(),
            freed: Default::default(),
            one_slot: Constant::new(ModuleMask::from(1u64)),
            dist_mask: Constant::new(Dist::from(cfg.dist_mask())),
            count_mask: Constant::new(Count::from(cfg.count_mask())),
            visited_mask: Constant::new(ReadCount::from(cfg.visited_mask())),
            pair_shift: Constant::new(BramIndex::from(pair_bits as u64)),
            pair_mask: Constant::new(RamIndex::from(low_mask(pair_bits))),
            addr_shift: Constant::new(Bits::<8>::from(cfg.address_bits as u64)),
            addr_mask: Constant::new(Bits::<24>::from(low_mask(cfg.address_bits))),
            dist_mask_wide: Constant::new(BramWord::from(low_mask(db))),
            addr_mask_wide: Constant::new(BramWord::from(low_mask(cfg.address_bits))),
            ids: LutRam::new(q, cfg.id_bits()),
            out_count_mem: LutRam::new(q, cfg.count_bits()),
            out_visited_mem: LutRam::new(q, cfg.visited_bits()),
            found_even: BlockRam::new(slot_bits + pair_bits, cfg.address_bits + db),
            found_odd: BlockRam::new(slot_bits + pair_bits, cfg.address_bits + db),
            result_register: ResultRegister::new(!cfg.pipelined),
            finished: Default::default(),
            a_found_index: Default::default(),
            a_found_entry: Default::default(),
            a_found_even: Default::default(),
            a_found_odd: Default::default(),
            done_bit: Default::default(),
            result_fire: Default::default(),
            finished_pick: PriorityEncoder::lowest(q),
            beat: Default::default(),
            out_entry_next: Default::default(),
            out_found_index: Default::default(),
            out_active: Default::default(),
            out_fetch: Default::default(),
            out_header: Default::default(),
            out_index: Default::default(),
            out_entry: Default::default(),
            out_left: Default::default(),
            out_last: Default::default(),
            hdr_count: Default::default(),
            hdr_visited: Default::default(),
            hdr_last: Default::default(),
        }
    }
}

impl Logic for SlotReadout {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(
            self,
            clock,
            a_found_index,
            a_found_entry,
            a_found_even,
            a_found_odd,
            finished,
            out_active,
            out_fetch,
            out_header,
            out_index,
            out_entry,
            out_left,
            out_last,
            hdr_count,
            hdr_visited,
            hdr_last
        );
        clock!(
            self,
            clock,
            ids,
            out_count_mem,
            out_visited_mem,
            found_even,
            found_odd
        );
        // The writes: ids at the load, photons as they enter, headers at the end.
        self.ids.write_enable.next = self.id_write.val();
        self.ids.write_index.next = self.id_slot.val();
        self.ids.write_data.next = self.id.val();
        self.a_found_index.d.next = (bit_cast::<16, 8>(self.found_slot.val())
            << self.pair_shift.val())
            | (self.found_pos.val() >> 1);
        self.a_found_entry.d.next =
            bit_cast::<64, 24>(self.found_address.val() & self.addr_mask.val())
                | (bit_cast::<64, 32>(self.found_dist.val() & self.dist_mask.val())
                    << self.addr_shift.val());
        self.a_found_even.d.next = self.found_write.val() && !self.found_pos.val().get_bit(0);
        self.a_found_odd.d.next = self.found_write.val() && self.found_pos.val().get_bit(0);
        self.found_even.write_enable.next = self.a_found_even.q.val();
        self.found_odd.write_enable.next = self.a_found_odd.q.val();
        self.found_even.write_index.next = self.a_found_index.q.val();
        self.found_odd.write_index.next = self.a_found_index.q.val();
        self.found_even.write_data.next = self.a_found_entry.q.val();
        self.found_odd.write_data.next = self.a_found_entry.q.val();
        self.out_count_mem.write_enable.next = self.done.val();
        self.out_visited_mem.write_enable.next = self.done.val();
        self.out_count_mem.write_index.next = self.done_slot.val();
        self.out_visited_mem.write_index.next = self.done_slot.val();
        self.out_count_mem.write_data.next = bit_cast::<32, 16>(self.done_count.val());
        self.out_visited_mem.write_data.next = self.done_visited.val();
        self.done_bit.next = 0.into();
        if self.done.val() {
            self.done_bit.next = self.one_slot.val() << self.done_slot.val();
        }

        // The packet of the lowest finished slot.
        self.finished_pick.mask.next = self.finished.q.val();
        self.result_fire.next = self.out_active.q.val()
            && (!self.out_fetch.q.val())
            && self.result_register.inbound.ready.val();
        self.ids.read_index.next = self.out_index.q.val();
        self.out_count_mem.read_index.next = self.out_index.q.val();
        self.out_visited_mem.read_index.next = self.out_index.q.val();
        self.beat.next.header = self.out_header.q.val();
        self.beat.next.id = 0.into();
        if self.out_active.q.val() {
            self.beat.next.id = self.ids.read_data.val();
        }
        self.beat.next.count = self.hdr_count.q.val();
        self.beat.next.visited = self.hdr_visited.q.val();
        self.beat.next.address = 0.into();
        self.beat.next.distance = 0.into();
        self.beat.next.pair = false;
        self.beat.next.address2 = 0.into();
        self.beat.next.distance2 = 0.into();
        if self.out_header.q.val() {
            self.beat.next.last = self.hdr_last.q.val();
        } else {
            self.beat.next.last = self.out_last.q.val();
            if self.out_active.q.val() && (!self.out_fetch.q.val()) {
                // Two photons a beat while two are left.
                self.beat.next.address =
                    bit_cast::<24, 64>(self.found_even.read_data.val() & self.addr_mask_wide.val());
                self.beat.next.distance = bit_cast::<32, 64>(
                    (self.found_even.read_data.val() >> self.addr_shift.val())
                        & self.dist_mask_wide.val(),
                );
                if self.out_left.q.val() > 1 {
                    self.beat.next.pair = true;
                    self.beat.next.address2 = bit_cast::<24, 64>(
                        self.found_odd.read_data.val() & self.addr_mask_wide.val(),
                    );
                    self.beat.next.distance2 = bit_cast::<32, 64>(
                        (self.found_odd.read_data.val() >> self.addr_shift.val())
                            & self.dist_mask_wide.val(),
                    );
                }
            }
        }
        // The entry beat now is pair `out_entry`; the BlockRAMs read the next one.
        self.out_entry_next.next = self.out_entry.q.val();
        if self.result_fire.val() && (!self.out_header.q.val()) {
            self.out_entry_next.next = (self.out_entry.q.val() + 1) & self.pair_mask.val();
        }
        self.out_found_index.next = (bit_cast::<16, 8>(self.out_index.q.val())
            << self.pair_shift.val())
            | bit_cast::<16, 8>(self.out_entry_next.val());
        self.found_even.read_index.next = self.out_found_index.val();
        self.found_odd.read_index.next = self.out_found_index.val();
        self.out_entry.d.next = self.out_entry_next.val() & self.pair_mask.val();
        self.result_register.clock.next = self.clock.val();
        self.result_register.reset.next = self.reset.val();
        self.result_register.inbound.valid.next =
            self.out_active.q.val() && (!self.out_fetch.q.val());
        self.result_register.inbound.data.next = self.beat.val();
        self.result_register.outbound.ready.next = self.result.ready.val();
        self.result.valid.next = self.result_register.outbound.valid.val();
        self.result.data.next = self.result_register.outbound.data.val();
        self.freed.next = 0.into();
        if !self.out_active.q.val() {
            if self.finished.q.val().any() {
                self.out_active.d.next = true;
                self.out_fetch.d.next = true;
                self.out_index.d.next = self.finished_pick.index.val();
                self.out_entry.d.next = 0.into();
            }
        } else if self.out_fetch.q.val() {
            self.out_fetch.d.next = false;
            self.out_header.d.next = true;
            self.hdr_count.d.next =
                bit_cast::<16, 32>(self.out_count_mem.read_data.val()) & self.count_mask.val();
            self.hdr_visited.d.next =
                self.out_visited_mem.read_data.val() & self.visited_mask.val();
            self.hdr_last.d.next = (bit_cast::<16, 32>(self.out_count_mem.read_data.val())
                & self.count_mask.val())
                == 0;
        } else if self.result_fire.val() {
            if self.out_header.q.val() {
                self.out_header.d.next = false;
                self.out_left.d.next = self.hdr_count.q.val();
                self.out_last.d.next = self.hdr_count.q.val() <= 2;
            } else {
                // (Not the last beat: more than two were left.)
                self.out_left.d.next = (self.out_left.q.val() - 2) & self.count_mask.val();
                self.out_last.d.next = self.out_left.q.val() <= 4;
            }
            if self.beat.val().last {
                self.out_active.d.next = false;
                self.freed.next = self.one_slot.val() << self.out_index.q.val();
            }
        }

        self.finished.d.next = (self.finished.q.val() | self.done_bit.val()) & (!self.freed.val());
        if self.reset.val() {
            self.finished.d.next = 0.into();
            self.out_active.d.next = false;
            self.out_fetch.d.next = false;
            self.out_header.d.next = false;
        }
    }
}
