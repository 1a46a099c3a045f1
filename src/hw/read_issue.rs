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
//!   replica (a node above the banked levels) or to its bank through the
//!   [`BankCrossbar`](crate::hw::bank_crossbar::BankCrossbar)'s request register
//!   ([`BankStore`](crate::hw::bank_store::BankStore)). A replica read is taken
//!   unless a bank read waits before the crossbar's arbiters (`waiting`): then
//!   that read may be granted this cycle and its word would meet the replica's
//!   at the SearchModule. A refused offer stays until it is taken (in order: the bank model,
//!   `host::banking`, measures 0.906 reads per cycle against 0.912 for a refused
//!   read going to the back of the queue, and holding needs no second queue).
//!   The next offer is the lowest pending slot, picked a cycle ahead
//!   ([`FreePick`]); with none pending, F's read goes to the offer register at
//!   once. Bank and row are registered with the offer; they are computed
//!   ([`BankMap`]) for both candidates — the picked waiting read and F's read —
//!   before the choice, so that "taken" (from the request register's flip-flops)
//!   only selects the offer registers' inputs.
//! * **grant** — the SearchModule gets a read the cycle before its word: a
//!   replica read the cycle after it was taken (registered with its slot; the
//!   word registered once more to line up), a bank read when the crossbar
//!   announces its answer (`granted`, with the slot as tag). Either way the
//!   read's context is read back by its slot.
//!
//! A slot's read thus costs its round trip three cycles more than with one tree
//! (14 cycles, which 16 slots cover), plus any wait for its bank.

use crate::hw::bank_crossbar::{BankAnswerIn, BankIndex, BankRequester, BankRow};
use crate::hw::bank_map::BankMap;
use crate::hw::config::{bits_for, Addr, CoreConfig, Dist, ModuleIndex, ModuleMask, Word};
use crate::hw::free_pick::FreePick;
use crate::hw::lut_ram::LutRam;
use crate::hw::stream::ReadRequest;
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
    /// Per slot: its read's address (twice: read by the next offer's pick and by
    /// the read going to the SearchModule), radius and full flag.
    ctx_address: LutRam,
    ctx_address_back: LutRam,
    ctx_radius: LutRam,
    ctx_full: LutRam,
    offer_valid: DFF<bool>,
    offer_slot: DFF<ModuleIndex>,
    offer_address: DFF<Addr>,
    offer_replica: DFF<bool>,
    offer_bank: DFF<BankIndex>,
    offer_row: DFF<BankRow>,
    /// Whether the offer moved this cycle, and whether F's read goes straight
    /// to the offer register.
    taken: Signal<Local, bool>,
    bypass: Signal<Local, bool>,
    /// A replica read taken last cycle, and its slot.
    grant_valid: DFF<bool>,
    grant_slot: DFF<ModuleIndex>,
    /// The slot whose read goes to the SearchModule this cycle (banked).
    back_slot: Signal<Local, ModuleIndex>,
    word_replica: DFF<bool>,
    replica_word: DFF<Word<W>>,
}

impl<const W: usize> ReadIssue<W> {
    pub fn new(cfg: &CoreConfig) -> Self {
        let q = cfg.queries_per_port;
        let (levels, bank_bits) = cfg
            .banking
            .map_or((0, 0), |b| (b.replicated_levels, b.bank_bits));
        let db = cfg.dist_bits();
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
            pick_map: BankMap::new(levels, bank_bits, cfg.address_bits),
            push_map: BankMap::new(levels, bank_bits, cfg.address_bits),
            pending: Default::default(),
            pick: FreePick::new(q),
            ctx_address: LutRam::new(q, cfg.address_bits),
            ctx_address_back: LutRam::new(q, cfg.address_bits),
            ctx_radius: LutRam::new(q, db),
            ctx_full: LutRam::new(q, 1),
            offer_valid: Default::default(),
            offer_slot: Default::default(),
            offer_address: Default::default(),
            offer_replica: Default::default(),
            offer_bank: Default::default(),
            offer_row: Default::default(),
            taken: Default::default(),
            bypass: Default::default(),
            grant_valid: Default::default(),
            grant_slot: Default::default(),
            back_slot: Default::default(),
            word_replica: Default::default(),
            replica_word: Default::default(),
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
            offer_valid,
            offer_slot,
            offer_address,
            offer_replica,
            offer_bank,
            offer_row,
            grant_valid,
            grant_slot,
            word_replica,
            replica_word
        );
        clock!(
            self,
            clock,
            ctx_address,
            ctx_address_back,
            ctx_radius,
            ctx_full
        );
        self.pick.clock.next = self.clock.val();
        self.pick.reset.next = self.reset.val();
        // Every read's context, by slot.
        self.ctx_address.write_enable.next = self.push.val();
        self.ctx_address.write_index.next = self.push_slot.val();
        self.ctx_address.write_data.next = bit_cast::<32, 24>(self.push_address.val());
        self.ctx_address_back.write_enable.next = self.push.val();
        self.ctx_address_back.write_index.next = self.push_slot.val();
        self.ctx_address_back.write_data.next = bit_cast::<32, 24>(self.push_address.val());
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
        self.back_slot.next = self.bank_answer.granted_tag.val();
        if self.grant_valid.q.val() {
            self.back_slot.next = self.grant_slot.q.val();
        }
        self.ctx_address_back.read_index.next = self.back_slot.val();
        self.ctx_radius.read_index.next = self.back_slot.val();
        self.ctx_full.read_index.next = self.back_slot.val();

        // The offer: to the replica (taken unless a bank read may be granted now)
        // or to its bank (taken when the request register has room).
        self.bank.valid.next =
            self.banked.val() && self.offer_valid.q.val() && !self.offer_replica.q.val();
        self.bank.bank.next = self.offer_bank.q.val();
        self.bank.row.next = self.offer_row.q.val();
        self.bank.tag.next = self.offer_slot.q.val();
        if self.offer_replica.q.val() {
            self.taken.next = self.offer_valid.q.val() && !self.bank.waiting.val();
        } else {
            self.taken.next = self.offer_valid.q.val() && self.bank.ready.val();
        }
        // The next offer: the picked pending slot, else F's read at once (an
        // offer that stays keeps its registers).
        self.pick_map.address.next =
            bit_cast::<24, 32>(self.ctx_address.read_data.val()) & self.addr_mask.val();
        self.push_map.address.next = self.push_address.val();
        self.pick.free.next = self.pending.q.val();
        self.pick.take.next = false;
        self.bypass.next = false;
        if (!self.offer_valid.q.val()) || self.taken.val() {
            self.offer_valid.d.next = false;
            if self.pick.pick_valid.val() {
                self.pick.take.next = true;
                self.offer_valid.d.next = true;
                self.offer_slot.d.next = self.pick.pick_index.val();
                self.offer_address.d.next = self.pick_map.address.val();
                self.offer_replica.d.next = self.pick_map.replicated.val();
                self.offer_bank.d.next = self.pick_map.bank.val();
                self.offer_row.d.next = self.pick_map.row.val();
            } else if self.push.val() {
                self.bypass.next = true;
                self.offer_valid.d.next = true;
                self.offer_slot.d.next = self.push_slot.val();
                self.offer_address.d.next = self.push_address.val();
                self.offer_replica.d.next = self.push_map.replicated.val();
                self.offer_bank.d.next = self.push_map.bank.val();
                self.offer_row.d.next = self.push_map.row.val();
            }
        }
        self.pending.d.next = self.pick.still_free.val();
        if self.push.val() && !self.bypass.val() {
            self.pending.d.next =
                self.pick.still_free.val() | (self.one_slot.val() << self.push_slot.val());
        }

        // The taken replica read, then its word.
        self.grant_valid.d.next = self.taken.val() && self.offer_replica.q.val();
        self.grant_slot.d.next = self.offer_slot.q.val();
        self.word_replica.d.next = self.grant_valid.q.val();
        self.replica_word.d.next = self.ram_data.val();
        if self.reset.val() {
            self.pending.d.next = 0.into();
            self.offer_valid.d.next = false;
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
            self.ram_address.next = self.offer_address.q.val();
            self.request_valid.next = self.grant_valid.q.val() || self.bank_answer.granted.val();
            self.request.next.query_module = self.back_slot.val();
            self.request.next.address =
                bit_cast::<24, 32>(self.ctx_address_back.read_data.val()) & self.addr_mask.val();
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
    }
}
