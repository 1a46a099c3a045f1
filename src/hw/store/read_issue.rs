//! ReadIssue: where a BarrelPort's photon read goes between stage F, which asks
//! for it, and the SearchModule, which takes its word.
//!
//! With one tree per core (no banks) it is wires: the read goes to the TreeModule
//! port in the cycle F asks and its word comes back the next, as the SearchModule
//! expects (paper §4.3, §4.5).
//!
//! With a banked store (`CoreConfig::banking`) a read of a node below the
//! replicated levels waits for its bank, so a slot's read may leave later than F
//! asked and other slots' reads may pass it ("a slot waits on a busy bank, the
//! other slots go on"). Each slot has at most one read in flight, so the waiting
//! reads are a bit per slot (`pending`) with the read's context in LUT-RAM,
//! written when F asks:
//! * **offer** — one read at a time is offered, from a register: to the local
//!   replica (a node above the banked levels: always taken) or to its bank
//!   through the [`BankCrossbar`](crate::hw::store::bank_crossbar::BankCrossbar). A
//!   refused offer stays until its bank takes it (in order: the lab's bank model
//!   measures it as good as sending a refused read to the back of the queue,
//!   docs/BANKING.md, and holding needs no second queue).
//!   The offer register is the output register of a [`RegisterSlice`] (the skid
//!   buffer of verilog-axis' `axis_register`): the next read enters the slice
//!   whenever its skid register is empty, a flip-flop, so the bank's answer
//!   ("taken", the end of the round trip through the crossbar's arbiters) only
//!   moves the slice's registers, which sit between the datapath and the
//!   crossbar, and never reaches the choice of the next read. The next read is
//!   the lowest pending slot, picked a cycle ahead ([`FreePick`]); with none
//!   pending, F's read enters at once. Its bank and row are computed
//!   ([`BankMap`]) for both candidates before the choice and registered with
//!   it, so the crossbar's arbitration starts from flip-flops.
//! * **grant** — a taken read (at most one a cycle) is registered with its slot,
//!   twice; its context is read back, and the SearchModule gets the read two
//!   cycles after it was taken and the word the cycle after that: the
//!   crossbar's answer (three cycles after its grant: the bank port's row
//!   register, the BlockRAM, the answer register) or the replica's word (read
//!   from the address registered once, like a bank port's row, and the word
//!   registered once, like the crossbar's answer).
//!
//! A slot's read thus costs its round trip three cycles more than with one tree
//! (14 cycles, which 16 slots cover), plus any wait for its bank.
//!
//! With external memory (`CoreConfig::memory`) where a read lives is the cache's
//! placement ([`ReadPlace`]), a deeper function of the address than a bank's, and
//! the offer is one cycle further on: the slice above registers the next read's
//! slot and address only (a stage), the placement is computed from that
//! register, and the read is offered from an [`OfferQueue`] to a crossbar whose
//! `ready` comes a cycle late (`BankCrossbar::with_late_ready`): the bank's
//! grant is registered at the crossbar, and the queue offers another read while
//! the one offered waits for it. So neither the pick's context read nor F's
//! address computation meets the placement in one cycle, and no cycle both
//! arbitrates and brings the grant back across the chip (docs/MEMORY_CORE.md,
//! "What fits"). A read to the replica is taken as surely, a cycle
//! late too.

use crate::hw::config::core_config::{
    bits_for, Addr, CoreConfig, Dist, ModuleIndex, ModuleMask, Word,
};
use crate::hw::config::memory_layout::MemoryLayout;
use crate::hw::many;
use crate::hw::primitives::bank_bus::{BankAnswerIn, BankRequester};
use crate::hw::primitives::block_ram::BramWord;
use crate::hw::primitives::free_pick::FreePick;
use crate::hw::primitives::lut_ram::LutRam;
use crate::hw::primitives::offer_queue::OfferQueue;
use crate::hw::primitives::register_slice::RegisterSlice;
use crate::hw::primitives::stream::ReadRequest;
use crate::hw::store::bank_crossbar::BankCrossbar;
use crate::hw::store::bank_map::BankMap;
use crate::hw::store::miss_park::MissPark;
use crate::hw::store::read_place::{OfferedRead, ReadPlace};
use rust_hdl::prelude::*;

#[derive(LogicBlock)]
pub struct ReadIssue<const W: usize> {
    pub clock: Signal<In, Clock>,
    /// Drops every waiting read and the reads in flight.
    pub reset: Signal<In, bool>,
    /// Stage F's read: slot, address, the query's radius and full flag.
    pub push: Signal<In, bool>,
    pub push_slot: Signal<In, ModuleIndex>,
    pub push_address: Signal<In, Addr>,
    pub push_radius: Signal<In, Dist>,
    pub push_full: Signal<In, bool>,
    /// To the SearchModule: a read, and its word in the next cycle.
    pub request_valid: Signal<Out, bool>,
    pub request: Signal<Out, ReadRequest>,
    pub word: Signal<Out, Word<W>>,
    /// A read left for memory this cycle.
    pub reading: Signal<Out, bool>,
    /// The local TreeModule port (the whole map, or its replicated top levels):
    /// address now, word the next cycle.
    pub ram_address: Signal<Out, Addr>,
    pub ram_data: Signal<In, Word<W>>,
    /// The banks.
    pub bank: BankRequester,
    pub bank_answer: BankAnswerIn,
    banked: Constant<bool>,
    addr_mask: Constant<Addr>,
    one_slot: Constant<ModuleMask>,
    /// Where the picked waiting read and F's read live: the two candidates for
    /// the next offer.
    pick_map: BankMap,
    push_map: BankMap,
    /// The slots with a read waiting (not counting the offer) and the next offer.
    pending: DFF<ModuleMask>,
    pick: FreePick,
    /// Per slot: its read's address, radius and full flag.
    ctx_address: LutRam,
    ctx_radius: LutRam,
    ctx_full: LutRam,
    /// The next read (into the slice) and the offer (its output register).
    next_valid: Signal<Local, bool>,
    next: Signal<Local, OfferedRead>,
    offer: RegisterSlice<OfferedRead>,
    offered: Signal<Local, OfferedRead>,
    /// Whether the offer moved this cycle (with external memory: whether the
    /// previous cycle's offer was taken), and whether F's read goes straight to
    /// the slice.
    taken: Signal<Local, bool>,
    bypass: Signal<Local, bool>,
    grant_valid: DFF<bool>,
    grant_slot: DFF<ModuleIndex>,
    grant_address: DFF<Addr>,
    grant_replica: DFF<bool>,
    /// The taken read a cycle later: the SearchModule's request (with banks;
    /// none without).
    issue_valid: Vec<DFF<bool>>,
    issue_slot: Vec<DFF<ModuleIndex>>,
    issue_address: Vec<DFF<Addr>>,
    issue_replica: Vec<DFF<bool>>,
    word_replica: DFF<bool>,
    replica_word: DFF<Word<W>>,
    /// With external memory (`CoreConfig::memory`; empty otherwise): where the
    /// registered next read lives in the cache, the offer (after the slice,
    /// which is then a stage), whether the read offered was the replica's, the
    /// bit of a bank's miss flag, and the stage that parks a read that missed.
    place: Vec<ReadPlace>,
    queue: Vec<OfferQueue<OfferedRead>>,
    offered_replica: Vec<DFF<bool>>,
    miss_flag: Vec<Constant<BramWord>>,
    park: Vec<MissPark<W>>,
}

impl<const W: usize> ReadIssue<W> {
    pub fn new(cfg: &CoreConfig) -> Self {
        let q = cfg.queries_per_port;
        let (levels, bank_bits) = cfg
            .banking
            .map_or((0, 0), |b| (b.replicated_levels, b.bank_bits));
        let db = cfg.dist_bits();
        let stages = usize::from(cfg.banking.is_some());
        // The external memory's placement and the cache's bank bits.
        let memory: Vec<(MemoryLayout, u32)> = cfg
            .memory
            .zip(cfg.banking)
            .map(|(m, b)| {
                let layout =
                    MemoryLayout::new(cfg.address_bits, b.replicated_levels, m.block_levels)
                        .expect("a validated core's layout");
                (layout, b.bank_bits)
            })
            .into_iter()
            .collect();
        // Where the crossbar ignores repeats, a refused read is offered in every
        // cycle until it is taken.
        let repeats_masked = cfg
            .banking
            .is_some_and(|b| BankCrossbar::masks_repeats(cfg.datapaths(), b.ports));
        ReadIssue {
            clock: Default::default(),
            reset: Default::default(),
            push: Default::default(),
            push_slot: Default::default(),
            push_address: Default::default(),
            push_radius: Default::default(),
            push_full: Default::default(),
            request_valid: Default::default(),
            request: Default::default(),
            word: Default::default(),
            reading: Default::default(),
            ram_address: Default::default(),
            ram_data: Default::default(),
            bank: Default::default(),
            bank_answer: Default::default(),
            banked: Constant::new(cfg.banking.is_some()),
            addr_mask: Constant::new(Addr::from(cfg.addr_mask())),
            one_slot: Constant::new(ModuleMask::from(1u64)),
            pick_map: BankMap::new(levels, bank_bits, cfg.address_bits, cfg.bank_mapping()),
            push_map: BankMap::new(levels, bank_bits, cfg.address_bits, cfg.bank_mapping()),
            pending: Default::default(),
            pick: FreePick::new(q),
            ctx_address: LutRam::new(q, cfg.address_bits),
            ctx_radius: LutRam::new(q, db),
            ctx_full: LutRam::new(q, 1),
            next_valid: Default::default(),
            next: Default::default(),
            offer: RegisterSlice::new(false),
            offered: Default::default(),
            taken: Default::default(),
            bypass: Default::default(),
            grant_valid: Default::default(),
            grant_slot: Default::default(),
            grant_address: Default::default(),
            grant_replica: Default::default(),
            issue_valid: many(stages),
            issue_slot: many(stages),
            issue_address: many(stages),
            issue_replica: many(stages),
            word_replica: Default::default(),
            replica_word: Default::default(),
            place: memory.iter().map(|(l, b)| ReadPlace::new(l, *b)).collect(),
            queue: memory
                .iter()
                .map(|_| {
                    if repeats_masked {
                        OfferQueue::persistent()
                    } else {
                        OfferQueue::new()
                    }
                })
                .collect(),
            offered_replica: many(memory.len()),
            miss_flag: memory
                .iter()
                .map(|_| Constant::new(BramWord::from(1u64 << cfg.layout.word_bits())))
                .collect(),
            park: memory.iter().map(|_| MissPark::new()).collect(),
        }
    }

    /// Bits of a bank tag: a slot index.
    pub fn tag_bits(cfg: &CoreConfig) -> u32 {
        bits_for(cfg.queries_per_port.saturating_sub(1) as u64)
    }
}

impl<const W: usize> Logic for ReadIssue<W> {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(
            self,
            clock,
            pending,
            grant_valid,
            grant_slot,
            grant_address,
            grant_replica,
            word_replica,
            replica_word
        );
        clock!(self, clock, ctx_address, ctx_radius, ctx_full);
        self.pick.clock.next = self.clock.val();
        self.pick.reset.next = self.reset.val();
        self.offer.clock.next = self.clock.val();
        self.offer.reset.next = self.reset.val();
        // Every read's context, by slot.
        self.ctx_address.write_enable.next = self.push.val();
        self.ctx_address.write_index.next = self.push_slot.val();
        self.ctx_address.write_data.next = bit_cast::<32, 24>(self.push_address.val());
        self.ctx_radius.write_enable.next = self.push.val();
        self.ctx_radius.write_index.next = self.push_slot.val();
        self.ctx_radius.write_data.next = self.push_radius.val();
        self.ctx_full.write_enable.next = self.push.val();
        self.ctx_full.write_index.next = self.push_slot.val();
        self.ctx_full.write_data.next = 0.into();
        if self.push_full.val() {
            self.ctx_full.write_data.next = 1.into();
        }
        self.ctx_address.read_index.next = self.pick.pick_index.val();
        self.ctx_radius.read_index.next = self.grant_slot.q.val();
        self.ctx_full.read_index.next = self.grant_slot.q.val();

        // The offer: to the replica (taken) or to its bank (taken if granted).
        self.offered.next = self.offer.outbound.data.val();
        self.bank.valid.next =
            self.banked.val() && self.offer.outbound.valid.val() && !self.offered.val().replica;
        self.bank.bank.next = self.offered.val().bank;
        self.bank.row.next = self.offered.val().row;
        self.bank.tag.next = self.offered.val().slot;
        self.offer.outbound.ready.next = self.offered.val().replica || self.bank.ready.val();
        self.taken.next = self.offer.outbound.valid.val() && self.offer.outbound.ready.val();
        // With external memory the slice is a stage and the offer comes after
        // it: the next read is registered with its slot and address only, where
        // it lives in the cache is computed from that register, and the read is
        // offered from an OfferQueue. The crossbar says a cycle later whether it
        // took the read (its grant registered), as the replica does (always), so
        // here `taken` is the previous cycle's offer's.
        for m in 0..self.queue.len() {
            self.queue[m].clock.next = self.clock.val();
            self.queue[m].reset.next = self.reset.val();
            self.offered_replica[m].clock.next = self.clock.val();
            self.place[m].read.next = self.offer.outbound.data.val();
            self.queue[m].inbound.valid.next = self.offer.outbound.valid.val();
            self.queue[m].inbound.data.next = self.place[m].placed.val();
            self.offer.outbound.ready.next = self.queue[m].inbound.ready.val();
            self.offered.next = self.queue[m].offer.val();
            self.bank.valid.next = self.queue[m].offer_valid.val() && !self.offered.val().replica;
            self.bank.bank.next = self.offered.val().bank;
            self.bank.row.next = self.offered.val().row;
            self.bank.tag.next = self.offered.val().slot;
            self.offered_replica[m].d.next =
                self.queue[m].offer_valid.val() && self.offered.val().replica && !self.reset.val();
            self.taken.next = self.offered_replica[m].q.val() || self.bank.ready.val();
            self.queue[m].taken.next = self.taken.val();
        }
        // The next read, whenever the slice has room: the picked pending slot,
        // else F's read at once.
        self.pick_map.address.next =
            bit_cast::<24, 32>(self.ctx_address.read_data.val()) & self.addr_mask.val();
        self.push_map.address.next = self.push_address.val();
        self.pick.free.next = self.pending.q.val();
        self.pick.take.next = false;
        self.bypass.next = false;
        self.next_valid.next = false;
        self.next.next.slot = self.pick.pick_index.val();
        self.next.next.address = self.pick_map.address.val();
        self.next.next.replica = self.pick_map.replicated.val();
        self.next.next.bank = self.pick_map.bank.val();
        self.next.next.row = self.pick_map.row.val();
        if self.offer.inbound.ready.val() {
            if self.pick.pick_valid.val() {
                self.pick.take.next = true;
                self.next_valid.next = true;
            } else if self.push.val() {
                self.bypass.next = true;
                self.next_valid.next = true;
                self.next.next.slot = self.push_slot.val();
                self.next.next.address = self.push_address.val();
                self.next.next.replica = self.push_map.replicated.val();
                self.next.next.bank = self.push_map.bank.val();
                self.next.next.row = self.push_map.row.val();
            }
        }
        self.offer.inbound.valid.next = self.banked.val() && self.next_valid.val();
        self.offer.inbound.data.next = self.next.val();
        self.pending.d.next = self.pick.still_free.val();
        if self.push.val() && !self.bypass.val() {
            self.pending.d.next =
                self.pick.still_free.val() | (self.one_slot.val() << self.push_slot.val());
        }

        // The taken read, then its word (with external memory the grant
        // registers hold the offer whose verdict `taken` brings a cycle later,
        // and `grant_valid` is unused).
        self.grant_valid.d.next = self.taken.val();
        self.grant_slot.d.next = self.offered.val().slot;
        self.grant_address.d.next = self.offered.val().address;
        self.grant_replica.d.next = self.offered.val().replica;
        self.word_replica.d.next = self.grant_replica.q.val();
        self.replica_word.d.next = self.ram_data.val();
        if self.reset.val() {
            self.pending.d.next = 0.into();
            self.grant_valid.d.next = false;
        }

        // The request as the SearchModule takes it (it looks up the coordinates).
        self.request.next.up = false;
        self.request.next.came_from_right = false;
        self.request.next.x = 0.into();
        self.request.next.y = 0.into();
        self.request.next.z = 0.into();
        if self.banked.val() {
            self.reading.next = self.taken.val();
            self.ram_address.next = self.offered.val().address;
            self.request_valid.next = self.grant_valid.q.val();
            self.request.next.query_module = self.grant_slot.q.val();
            self.request.next.address = self.grant_address.q.val();
            self.request.next.radius = bit_cast::<32, 32>(self.ctx_radius.read_data.val());
            self.request.next.full = self.ctx_full.read_data.val().get_bit(0);
            if self.word_replica.q.val() {
                self.word.next = self.replica_word.q.val();
            } else {
                self.word.next = bit_cast::<W, 64>(self.bank_answer.word.val());
            }
        } else {
            self.reading.next = self.push.val();
            self.ram_address.next = self.push_address.val();
            self.request_valid.next = self.push.val();
            self.request.next.query_module = self.push_slot.val();
            self.request.next.address = self.push_address.val();
            self.request.next.radius = self.push_radius.val();
            self.request.next.full = self.push_full.val();
            self.word.next = self.ram_data.val();
        }
        // With banks the taken read is registered once more before it is the
        // SearchModule's request, and the replica is read from the registered
        // address, so that both words arrive as the crossbar's answer does (a
        // bank port's row register, the BlockRAM, the answer register).
        for b in 0..self.issue_valid.len() {
            self.issue_valid[b].clock.next = self.clock.val();
            self.issue_slot[b].clock.next = self.clock.val();
            self.issue_address[b].clock.next = self.clock.val();
            self.issue_replica[b].clock.next = self.clock.val();
            self.issue_valid[b].d.next = self.grant_valid.q.val() && !self.reset.val();
            self.issue_slot[b].d.next = self.grant_slot.q.val();
            self.issue_address[b].d.next = self.grant_address.q.val();
            self.issue_replica[b].d.next = self.grant_replica.q.val();
            self.word_replica.d.next = self.issue_replica[b].q.val();
            self.ctx_radius.read_index.next = self.issue_slot[b].q.val();
            self.ctx_full.read_index.next = self.issue_slot[b].q.val();
            self.ram_address.next = self.grant_address.q.val();
            self.request_valid.next = self.issue_valid[b].q.val();
            self.request.next.query_module = self.issue_slot[b].q.val();
            self.request.next.address = self.issue_address[b].q.val();
        }
        // With external memory: the answer (the replica's or a bank's) meets a
        // stage that parks a miss; a hit is the SearchModule's read a cycle later
        // than with banks on chip, and a parked slot's retry joins the waiting reads.
        // The verdict on the previous cycle's offer comes with the grant
        // registers' copy of that offer, so the taken read is the issue stage's.
        for m in 0..self.park.len() {
            self.issue_valid[m].d.next = self.taken.val() && !self.reset.val();
            self.park[m].clock.next = self.clock.val();
            self.park[m].reset.next = self.reset.val();
            self.park[m].read_valid.next = self.issue_valid[m].q.val();
            self.park[m].read_slot.next = self.issue_slot[m].q.val();
            self.park[m].read_address.next = self.issue_address[m].q.val();
            self.park[m].answer.next = bit_cast::<W, 64>(self.bank_answer.word.val());
            if self.word_replica.q.val() {
                self.park[m].answer.next = self.replica_word.q.val();
            }
            self.park[m].missed.next = (!self.word_replica.q.val())
                && ((self.bank_answer.word.val() & self.miss_flag[m].val()) != 0);
            self.request_valid.next = self.park[m].request_valid.val();
            self.request.next.query_module = self.park[m].request_slot.val();
            self.request.next.address = self.park[m].request_address.val();
            self.ctx_radius.read_index.next = self.park[m].request_slot.val();
            self.ctx_full.read_index.next = self.park[m].request_slot.val();
            self.word.next = self.park[m].word.val();
            self.reading.next = self.park[m].request_valid.val();
            self.pending.d.next = self.pick.still_free.val();
            if self.push.val() && !self.bypass.val() {
                self.pending.d.next =
                    self.pick.still_free.val() | (self.one_slot.val() << self.push_slot.val());
                if self.park[m].retry_valid.val() {
                    self.pending.d.next = self.pick.still_free.val()
                        | (self.one_slot.val() << self.push_slot.val())
                        | (self.one_slot.val() << self.park[m].retry_slot.val());
                }
            } else if self.park[m].retry_valid.val() {
                self.pending.d.next = self.pick.still_free.val()
                    | (self.one_slot.val() << self.park[m].retry_slot.val());
            }
            if self.reset.val() {
                self.pending.d.next = 0.into();
            }
        }
    }
}
