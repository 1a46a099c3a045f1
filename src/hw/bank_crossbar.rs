//! BankCrossbar: D requesters share B memory banks through a full crossbar, one
//! read per bank per cycle, round robin among the requesters asking for it. A
//! banked photon store spreads one kd-tree over many BlockRAMs so that many barrel
//! datapaths read it at once (QuickNN, Pinkham et al., HPCA 2020, and ParallelNN
//! keep the tree's top beside each query engine and spread the rest over banks or
//! channels); this is the network between the datapaths and the banks.
//!
//! A request names its bank, the row in the bank and a tag (the slot that asked).
//! In the cycle a request is offered, each bank's [`PortArbiter`] grants one of the
//! requesters asking for it; a granted request moves (`ready`) and its row goes to
//! the bank; a requester whose bank is busy waits (`ready` low) while the others
//! go on. A BlockRAM has two read ports: with two ports per bank, a second
//! arbiter per bank grants one of the requesters the first left waiting, through
//! the bank's `second` port (the bank model, `host::banking`, measures D = 16
//! datapaths on 64 banks at 0.91 reads per cycle each with one port, 0.99 with
//! two). The bank answers its row's word the next cycle (a BlockRAM's registered
//! read); the crossbar routes it back to the requester that asked and registers
//! it: the word and the tag appear on that requester's response two cycles after
//! its request moved, exactly once. Requests may change while they wait: nothing
//! is held for a requester that withdraws. Under `reset` nothing is granted and
//! the reads in flight are dropped (their answers never appear); the round robin
//! keeps its turn.

use crate::hw::block_ram::BramWord;
use crate::hw::config::Addr;
use crate::hw::config::ModuleMask;
use crate::hw::port_arbiter::PortArbiter;
use rust_hdl::prelude::*;

/// A bank's index (up to 1,024 banks).
pub type BankIndex = Bits<10>;
/// A row in a bank (a heap address's high bits: as wide as an address, so that
/// a bank is a [`TreeModule`](crate::hw::tree_module::TreeModule) without casts).
pub type BankRow = Addr;
/// The tag a requester gives a read, returned with its word (e.g. the slot).
pub type BankTag = Bits<8>;

/// One requester's read requests, a valid/ready stream: the bank, the row in it
/// and the requester's tag.
#[derive(LogicInterface, Default)]
#[join = "BankRequester"]
pub struct BankClient {
    pub valid: Signal<In, bool>,
    pub ready: Signal<Out, bool>,
    pub bank: Signal<In, BankIndex>,
    pub row: Signal<In, BankRow>,
    pub tag: Signal<In, BankTag>,
}

/// The requester's side of a [`BankClient`].
#[derive(LogicInterface, Default)]
#[join = "BankClient"]
pub struct BankRequester {
    pub valid: Signal<Out, bool>,
    pub ready: Signal<In, bool>,
    pub bank: Signal<Out, BankIndex>,
    pub row: Signal<Out, BankRow>,
    pub tag: Signal<Out, BankTag>,
}

/// One requester's answers (flip-flops; no back-pressure: the barrel datapath
/// takes a read's word in the cycle it arrives): a read's word and its request's
/// tag.
#[derive(LogicInterface, Default)]
#[join = "BankAnswerIn"]
pub struct BankAnswer {
    pub valid: Signal<Out, bool>,
    pub tag: Signal<Out, BankTag>,
    pub word: Signal<Out, BramWord>,
}

/// The requester's side of a [`BankAnswer`].
#[derive(LogicInterface, Default)]
#[join = "BankAnswer"]
pub struct BankAnswerIn {
    pub valid: Signal<In, bool>,
    pub tag: Signal<In, BankTag>,
    pub word: Signal<In, BramWord>,
}

/// One bank's read port, seen from the crossbar: a BlockRAM read (`word` is the
/// row enabled in the previous cycle).
#[derive(LogicInterface, Default)]
#[join = "BankMemoryPort"]
pub struct BankPort {
    pub enable: Signal<Out, bool>,
    pub row: Signal<Out, BankRow>,
    pub word: Signal<In, BramWord>,
}

/// The memory's side of a [`BankPort`].
#[derive(LogicInterface, Default)]
#[join = "BankPort"]
pub struct BankMemoryPort {
    pub enable: Signal<In, bool>,
    pub row: Signal<In, BankRow>,
    pub word: Signal<Out, BramWord>,
}

#[derive(LogicBlock)]
pub struct BankCrossbar {
    pub clock: Signal<In, Clock>,
    pub reset: Signal<In, bool>,
    /// Per requester: its read requests, and their answers.
    pub clients: Vec<BankClient>,
    pub answers: Vec<BankAnswer>,
    /// Per bank: its read port, and its second read port (none when the banks
    /// are single-ported).
    pub banks: Vec<BankPort>,
    pub second: Vec<BankPort>,
    /// Per bank: who asks for it, and the round robin among them; for the second
    /// port, those the first did not grant.
    asking: Vec<Signal<Local, ModuleMask>>,
    arbiters: Vec<PortArbiter>,
    asking_second: Vec<Signal<Local, ModuleMask>>,
    arbiters_second: Vec<PortArbiter>,
    bank_id: Vec<Constant<BankIndex>>,
    /// The widths in use (registers are loaded through them).
    bank_mask: Constant<BankIndex>,
    tag_mask: Constant<BankTag>,
    word_mask: Constant<BramWord>,
    /// Per requester: its read granted last cycle (its bank answers now)...
    flight_valid: Vec<DFF<bool>>,
    flight_bank: Vec<DFF<BankIndex>>,
    flight_tag: Vec<DFF<BankTag>>,
    flight_second: Vec<DFF<bool>>,
    /// ... and the answer, registered.
    word_sel: Vec<Signal<Local, BramWord>>,
    answer_valid: Vec<DFF<bool>>,
    answer_tag: Vec<DFF<BankTag>>,
    answer_word: Vec<DFF<BramWord>>,
}

impl BankCrossbar {
    /// `requesters` (1..=32) requesters, `banks` (1..=1024) banks with
    /// `ports_per_bank` (1 or 2) read ports of `word_bits` (1..=64) bits, tags of
    /// `tag_bits` (1..=8) bits.
    pub fn new(
        requesters: usize,
        banks: usize,
        ports_per_bank: usize,
        word_bits: u32,
        tag_bits: u32,
    ) -> Self {
        assert!((1..=32).contains(&requesters) && (1..=1024).contains(&banks));
        assert!((1..=2).contains(&ports_per_bank));
        let seconds = if ports_per_bank == 2 { banks } else { 0 };
        assert!((1..=64).contains(&word_bits) && (1..=8).contains(&tag_bits));
        let bank_bits = usize::BITS - (banks - 1).leading_zeros();
        fn many<T: Default>(n: usize) -> Vec<T> {
            (0..n).map(|_| T::default()).collect()
        }
        BankCrossbar {
            clock: Default::default(),
            reset: Default::default(),
            clients: many(requesters),
            answers: many(requesters),
            banks: many(banks),
            second: many(seconds),
            asking: many(banks),
            arbiters: (0..banks).map(|_| PortArbiter::new(requesters)).collect(),
            asking_second: many(seconds),
            arbiters_second: (0..seconds).map(|_| PortArbiter::new(requesters)).collect(),
            bank_id: (0..banks)
                .map(|j| Constant::new(BankIndex::from(j as u64)))
                .collect(),
            bank_mask: Constant::new(BankIndex::from((1u64 << bank_bits) - 1)),
            tag_mask: Constant::new(BankTag::from((1u64 << tag_bits) - 1)),
            word_mask: Constant::new(BramWord::from(u64::MAX >> (64 - word_bits))),
            flight_valid: many(requesters),
            flight_bank: many(requesters),
            flight_tag: many(requesters),
            flight_second: many(requesters),
            word_sel: many(requesters),
            answer_valid: many(requesters),
            answer_tag: many(requesters),
            answer_word: many(requesters),
        }
    }
}

impl Logic for BankCrossbar {
    #[hdl_gen]
    fn update(&mut self) {
        // Who asks for each bank, and each bank's grant.
        for j in 0..self.banks.len() {
            self.arbiters[j].clock.next = self.clock.val();
            self.asking[j].next = 0.into();
            for i in 0..self.clients.len() {
                if self.clients[i].valid.val()
                    && (!self.reset.val())
                    && (self.clients[i].bank.val() == self.bank_id[j].val())
                {
                    self.asking[j].next = self.asking[j].val().replace_bit(i, true);
                }
            }
            self.arbiters[j].requests.next = self.asking[j].val();
            self.arbiters[j].hold.next = false;
            self.arbiters[j].advance.next = self.asking[j].val().any();
        }
        for j in 0..self.second.len() {
            self.arbiters_second[j].clock.next = self.clock.val();
            self.asking_second[j].next = self.asking[j].val() & (!self.arbiters[j].grant.val());
            self.arbiters_second[j].requests.next = self.asking_second[j].val();
            self.arbiters_second[j].hold.next = false;
            self.arbiters_second[j].advance.next = self.asking_second[j].val().any();
        }
        // A granted request moves, and its row goes to its bank.
        for i in 0..self.clients.len() {
            self.clients[i].ready.next = false;
        }
        for j in 0..self.banks.len() {
            self.banks[j].enable.next = self.asking[j].val().any();
            self.banks[j].row.next = 0.into();
            for i in 0..self.clients.len() {
                if self.arbiters[j].grant.val().get_bit(i) {
                    self.clients[i].ready.next = true;
                    self.banks[j].row.next = self.clients[i].row.val();
                }
            }
        }
        for j in 0..self.second.len() {
            self.second[j].enable.next = self.asking_second[j].val().any();
            self.second[j].row.next = 0.into();
            for i in 0..self.clients.len() {
                if self.arbiters_second[j].grant.val().get_bit(i) {
                    self.clients[i].ready.next = true;
                    self.second[j].row.next = self.clients[i].row.val();
                }
            }
        }
        // The read in flight, then its bank's word back to its requester.
        for i in 0..self.clients.len() {
            self.flight_valid[i].clock.next = self.clock.val();
            self.flight_bank[i].clock.next = self.clock.val();
            self.flight_tag[i].clock.next = self.clock.val();
            self.flight_second[i].clock.next = self.clock.val();
            self.answer_valid[i].clock.next = self.clock.val();
            self.answer_tag[i].clock.next = self.clock.val();
            self.answer_word[i].clock.next = self.clock.val();
            self.flight_valid[i].d.next =
                self.clients[i].valid.val() && self.clients[i].ready.val();
            self.flight_bank[i].d.next = self.clients[i].bank.val() & self.bank_mask.val();
            self.flight_tag[i].d.next = self.clients[i].tag.val() & self.tag_mask.val();
            self.flight_second[i].d.next = false;
            for j in 0..self.second.len() {
                if self.arbiters_second[j].grant.val().get_bit(i) {
                    self.flight_second[i].d.next = true;
                }
            }
            self.word_sel[i].next = 0.into();
            for j in 0..self.banks.len() {
                if self.flight_bank[i].q.val() == self.bank_id[j].val() {
                    self.word_sel[i].next = self.banks[j].word.val();
                }
            }
            for j in 0..self.second.len() {
                if self.flight_second[i].q.val()
                    && (self.flight_bank[i].q.val() == self.bank_id[j].val())
                {
                    self.word_sel[i].next = self.second[j].word.val();
                }
            }
            self.answer_valid[i].d.next = self.flight_valid[i].q.val();
            self.answer_tag[i].d.next = self.flight_tag[i].q.val();
            self.answer_word[i].d.next = self.word_sel[i].val() & self.word_mask.val();
            if self.reset.val() {
                self.flight_valid[i].d.next = false;
                self.answer_valid[i].d.next = false;
            }
            self.answers[i].valid.next = self.answer_valid[i].q.val();
            self.answers[i].tag.next = self.answer_tag[i].q.val();
            self.answers[i].word.next = self.answer_word[i].q.val();
        }
    }
}
