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
//! the bank's `second` port (what it buys is measured by the lab's bank model,
//! docs/BANKING.md). The granted row is registered at the bank port (`enable` and `row` are
//! flip-flops), so the arbitration and the row selection end at a register and
//! the wires out to a bank's BlockRAMs, which spread over the device, start at
//! one. The bank answers the registered row's word the next cycle (a BlockRAM's
//! registered read); the crossbar routes it back to the requester that asked and
//! registers it: the word and the tag appear on that requester's response three
//! cycles after its request moved ([`BankCrossbar::LATENCY`]), exactly once.
//! Requests may change while they wait: nothing is held for a requester that
//! withdraws. Under `reset` nothing is granted and
//! the reads in flight are dropped (their answers never appear); the round robin
//! keeps its turn.
//!
//! A crossbar built [`BankCrossbar::with_late_ready`] registers `ready`: it says
//! in the next cycle that the read offered in this one was taken, so that no
//! cycle both arbitrates and carries the grant back across the chip to the
//! requester (the offer, the bank compare and the round robin end at the grant's
//! register; the register's fanout to the requester is a cycle of its own). A
//! requester then must not offer a read again in the cycle after it offered it
//! (it might have been taken); [`OfferQueue`](crate::hw::primitives::offer_queue::OfferQueue)
//! offers another read meanwhile. The grant, the row at the bank port and the
//! answer keep their cycles. Under `reset` a late `ready` may still be high: it
//! tells of a grant in the cycle before, whose answer the reset drops.
//!
//! A refused read thus asks at most every other cycle, and a round robin over
//! three or more requesters can then pass it over forever (the others granted
//! in turn in the cycles it is away). Where a port serves more than two
//! requesters ([`BankCrossbar::masks_repeats`]) the requester offers a read
//! refused once in every cycle until it is taken (`OfferQueue::persistent`), and
//! the crossbar ignores a read offered again in the cycle after its grant: one
//! with the tag of the read granted in the previous cycle (a tag is a slot, and a
//! slot has one read in flight). With two requesters a port, the one refused is
//! granted the next time it asks, and neither is built.

use crate::hw::config::bank_config::BankPorts;
use crate::hw::config::core_config::ModuleMask;
use crate::hw::many;
use crate::hw::primitives::bank_bus::{
    BankAnswer, BankClient, BankIndex, BankPort, BankRow, BankTag,
};
use crate::hw::primitives::block_ram::BramWord;
use crate::hw::primitives::mux_trees::MuxTrees;
use crate::hw::primitives::port_arbiter::PortArbiter;
use crate::hw::primitives::priority_encoder::{EncodedIndex, PriorityEncoder};
use rust_hdl::prelude::*;

#[derive(LogicBlock)]
pub struct BankCrossbar {
    pub clock: Signal<In, Clock>,
    pub reset: Signal<In, bool>,
    /// Per requester: its read requests, and their answers.
    pub clients: Vec<BankClient>,
    pub answers: Vec<BankAnswer>,
    /// Per bank: its read port, and its second read port (none when the banks
    /// are single-ported): the row granted in the previous cycle, registered.
    pub banks: Vec<BankPort>,
    pub second: Vec<BankPort>,
    /// Per bank: who asks for it; who of them may use each port (`first_mask`,
    /// `second_mask`), and the round robin among them (for a shared second port,
    /// among those the first did not grant).
    asking: Vec<Signal<Local, ModuleMask>>,
    asking_first: Vec<Signal<Local, ModuleMask>>,
    arbiters: Vec<PortArbiter>,
    asking_second: Vec<Signal<Local, ModuleMask>>,
    arbiters_second: Vec<PortArbiter>,
    first_mask: Constant<ModuleMask>,
    second_mask: Constant<ModuleMask>,
    bank_id: Vec<Constant<BankIndex>>,
    /// Each bank port's row from the requester it granted (the grant's index,
    /// halved for split ports), bank ports first, then second ports: a
    /// [`MuxTrees`] per port over the requesters that may use it.
    grant_index: Vec<PriorityEncoder<32>>,
    row_shift: Constant<EncodedIndex>,
    row_select: MuxTrees<BankRow, 8>,
    /// Per bank port (bank ports first): the granted row, registered (none in
    /// the placeholder).
    port_enable: Vec<DFF<bool>>,
    port_row: Vec<DFF<BankRow>>,
    /// The widths in use (registers are loaded through them); whether a
    /// requester's word comes from either port of a bank (`Shared`).
    bank_mask: Constant<BankIndex>,
    tag_mask: Constant<BankTag>,
    word_mask: Constant<BramWord>,
    either_port: Constant<bool>,
    port_bit: Constant<BankIndex>,
    /// Per requester: the bank port granting its read this cycle (the bank, or
    /// bank × 2 + port when either port may answer), then the read in flight:
    /// its row at the bank port, then its bank answering...
    source: Vec<Signal<Local, BankIndex>>,
    flight_valid: Vec<DFF<bool>>,
    flight_source: Vec<DFF<BankIndex>>,
    flight_tag: Vec<DFF<BankTag>>,
    /// (none in the placeholder)
    bram_valid: Vec<DFF<bool>>,
    bram_source: Vec<DFF<BankIndex>>,
    bram_tag: Vec<DFF<BankTag>>,
    /// ... the answering port's word (a [`MuxTrees`] per requester over the
    /// ports that may answer it) and the answer, registered.
    word_select: MuxTrees<BramWord, 12>,
    answer_valid: Vec<DFF<bool>>,
    answer_tag: Vec<DFF<BankTag>>,
    answer_word: Vec<DFF<BramWord>>,
    /// The port sharing, as loop counts (1 or 0) selecting its wiring at
    /// elaboration: shared second ports, split ports.
    _shared: usize,
    _split: usize,
    /// 1, or 0 for the placeholder (the bank ports unregistered).
    _registered: usize,
    /// With a late `ready` (none otherwise), per requester: its read granted
    /// this cycle, and that registered: its `ready`.
    moving: Vec<Signal<Local, bool>>,
    late_ready: Vec<DFF<bool>>,
    /// Where repeats are masked (none otherwise), per requester: its read is
    /// the one granted in the previous cycle, offered again.
    repeated: Vec<Signal<Local, bool>>,
    /// 1 where repeats are masked, else 0.
    _masked: usize,
    /// Requesters per port (all, or half for split ports) and the stride
    /// between them.
    _per_port: usize,
    _stride: usize,
}

impl BankCrossbar {
    /// Cycles from a request moving to its answer: the bank port's row
    /// register, the BlockRAM's read, the answer register.
    pub const LATENCY: usize = 3;

    /// `requesters` (1..=32; even for split ports) requesters, `banks`
    /// (1..=1024) banks whose read ports are shared as `ports` says, of
    /// `word_bits` (1..=64) bits, tags of `tag_bits` (1..=8) bits.
    pub fn new(
        requesters: usize,
        banks: usize,
        ports: BankPorts,
        word_bits: u32,
        tag_bits: u32,
    ) -> Self {
        Self::build(requesters, banks, ports, word_bits, tag_bits, true, false)
    }

    /// The crossbar of [`BankCrossbar::new`] with `ready` registered: high in
    /// the cycle after the request was granted.
    pub fn with_late_ready(
        requesters: usize,
        banks: usize,
        ports: BankPorts,
        word_bits: u32,
        tag_bits: u32,
    ) -> Self {
        Self::build(requesters, banks, ports, word_bits, tag_bits, true, true)
    }

    /// Whether a crossbar with a late `ready` among `requesters` requesters
    /// sharing its ports as `ports` says ignores a read offered again in the
    /// cycle after its grant (a port serves more than two of them), so that its
    /// requesters must offer a refused read in every cycle (`OfferQueue::persistent`).
    pub fn masks_repeats(requesters: usize, ports: BankPorts) -> bool {
        let per_port = if ports == BankPorts::Split {
            requesters / 2
        } else {
            requesters
        };
        per_port > 2
    }

    /// The crossbar of a core without banks: one requester, one bank, nothing
    /// reading its outputs (rust-hdl's `#[hdl_gen]` cannot leave an optional
    /// block out, so it is there, inputs held at zero, and synthesis removes
    /// it). Its bank port is not registered, which keeps it (and so the exported
    /// Verilog of every core without banks) to the registers a crossbar needs at
    /// the least.
    pub fn placeholder(word_bits: u32, tag_bits: u32) -> Self {
        Self::build(1, 1, BankPorts::One, word_bits, tag_bits, false, false)
    }

    fn build(
        requesters: usize,
        banks: usize,
        ports: BankPorts,
        word_bits: u32,
        tag_bits: u32,
        registered: bool,
        late: bool,
    ) -> Self {
        assert!((1..=32).contains(&requesters) && (1..=1024).contains(&banks));
        assert!(ports != BankPorts::Split || requesters.is_multiple_of(2));
        let seconds = if ports == BankPorts::One { 0 } else { banks };
        assert!((1..=64).contains(&word_bits) && (1..=8).contains(&tag_bits));
        let bank_bits = usize::BITS - (banks - 1).leading_zeros();
        let all = (1u64 << requesters) - 1;
        let even = all & 0x5555_5555;
        let split = ports == BankPorts::Split;
        let (first, second) = if split {
            (even, all & !even)
        } else {
            (all, all)
        };
        let stride = if split { 2 } else { 1 };
        let either = ports == BankPorts::Shared;
        let masked = late && Self::masks_repeats(requesters, ports);
        BankCrossbar {
            clock: Default::default(),
            reset: Default::default(),
            clients: many(requesters),
            answers: many(requesters),
            banks: many(banks),
            second: many(seconds),
            asking: many(banks),
            asking_first: many(banks),
            arbiters: (0..banks).map(|_| PortArbiter::new(requesters)).collect(),
            asking_second: many(seconds),
            arbiters_second: (0..seconds).map(|_| PortArbiter::new(requesters)).collect(),
            first_mask: Constant::new(first.into()),
            second_mask: Constant::new(second.into()),
            bank_id: (0..banks)
                .map(|j| Constant::new(BankIndex::from(j as u64)))
                .collect(),
            grant_index: (0..banks + seconds)
                .map(|_| PriorityEncoder::one_hot(requesters))
                .collect(),
            row_shift: Constant::new(EncodedIndex::from(stride as u64 - 1)),
            row_select: MuxTrees::new(banks + seconds, requesters / stride),
            port_enable: many(if registered { banks + seconds } else { 0 }),
            port_row: many(if registered { banks + seconds } else { 0 }),
            bank_mask: Constant::new(BankIndex::from((1u64 << bank_bits) - 1)),
            tag_mask: Constant::new(BankTag::from((1u64 << tag_bits) - 1)),
            word_mask: Constant::new(BramWord::from(u64::MAX >> (64 - word_bits))),
            either_port: Constant::new(either),
            port_bit: Constant::new(BankIndex::from(1u64)),
            source: many(requesters),
            flight_valid: many(requesters),
            flight_source: many(requesters),
            flight_tag: many(requesters),
            bram_valid: many(if registered { requesters } else { 0 }),
            bram_source: many(if registered { requesters } else { 0 }),
            bram_tag: many(if registered { requesters } else { 0 }),
            word_select: MuxTrees::new(requesters, banks * if either { 2 } else { 1 }),
            answer_valid: many(requesters),
            answer_tag: many(requesters),
            answer_word: many(requesters),
            _shared: usize::from(either),
            _split: usize::from(split),
            _registered: usize::from(registered),
            moving: many(if late { requesters } else { 0 }),
            late_ready: many(if late { requesters } else { 0 }),
            repeated: many(if masked { requesters } else { 0 }),
            _masked: usize::from(masked),
            _per_port: requesters / stride,
            _stride: stride,
        }
    }
}

impl Logic for BankCrossbar {
    #[hdl_gen]
    fn update(&mut self) {
        // A read offered again in the cycle after its grant (its tag is the one
        // granted then): not asking.
        for i in 0..self.repeated.len() {
            self.repeated[i].next = self.late_ready[i].q.val()
                && ((self.clients[i].tag.val() & self.tag_mask.val())
                    == self.flight_tag[i].q.val());
        }
        // Who asks for each bank, and each port's grant among those it serves.
        for j in 0..self.banks.len() {
            self.arbiters[j].clock.next = self.clock.val();
            self.asking[j].next = 0.into();
            for i in 0..self.clients.len() {
                if self.clients[i].valid.val()
                    && (self.clients[i].bank.val() == self.bank_id[j].val())
                {
                    self.asking[j].next = self.asking[j].val().replace_bit(i, true);
                    for _m in 0..self._masked {
                        if self.repeated[i].val() {
                            self.asking[j].next = self.asking[j].val().replace_bit(i, false);
                        }
                    }
                }
            }
            self.asking_first[j].next = self.asking[j].val() & self.first_mask.val();
            self.arbiters[j].requests.next = self.asking_first[j].val();
            self.arbiters[j].hold.next = false;
            self.arbiters[j].advance.next = self.asking_first[j].val().any() && (!self.reset.val());
        }
        for j in 0..self.second.len() {
            self.arbiters_second[j].clock.next = self.clock.val();
            self.asking_second[j].next =
                self.asking[j].val() & self.second_mask.val() & (!self.arbiters[j].grant.val());
            self.arbiters_second[j].requests.next = self.asking_second[j].val();
            self.arbiters_second[j].hold.next = false;
            self.arbiters_second[j].advance.next =
                self.asking_second[j].val().any() && (!self.reset.val());
        }
        // A granted request moves, and its row goes to its bank: the row of the
        // grant's index, through a tree per bank port (n: its inputs, sr the
        // stride between the requesters it serves).
        for i in 0..self.clients.len() {
            self.clients[i].ready.next = false;
        }
        for j in 0..self.banks.len() {
            self.grant_index[j].mask.next = self.arbiters[j].grant.val();
            for i in 0..self.clients.len() {
                if self.arbiters[j].grant.val().get_bit(i) {
                    self.clients[i].ready.next = true;
                }
            }
        }
        for nb in (self.banks.len())..(self.banks.len() + 1) {
            for j in 0..self.second.len() {
                self.grant_index[nb + j].mask.next = self.arbiters_second[j].grant.val();
                for i in 0..self.clients.len() {
                    if self.arbiters_second[j].grant.val().get_bit(i) {
                        self.clients[i].ready.next = true;
                    }
                }
            }
        }
        // Reset withholds the grants here, after the arbiters, not from their
        // requests: the reset register's wide fanout then meets the grant at its
        // last gate instead of starting the request-grant-taken round trip.
        if self.reset.val() {
            for i in 0..self.clients.len() {
                self.clients[i].ready.next = false;
            }
        }
        for n in (self.row_select.leaves())..(self.row_select.leaves() + 1) {
            for sr in (self._stride)..(self._stride + 1) {
                for p in 0..self.grant_index.len() {
                    self.row_select.index[p].next =
                        self.grant_index[p].index.val() >> self.row_shift.val();
                    for k in (self._per_port)..(self.row_select.leaves()) {
                        self.row_select.inputs[p * n + k].next = 0.into();
                    }
                }
                for j in 0..self.banks.len() {
                    for k in 0..self._per_port {
                        self.row_select.inputs[j * n + k].next = self.clients[k * sr].row.val();
                    }
                }
                for nb in (self.banks.len())..(self.banks.len() + 1) {
                    for ob in (self._split)..(self._split + 1) {
                        for j in 0..self.second.len() {
                            for k in 0..self._per_port {
                                self.row_select.inputs[(nb + j) * n + k].next =
                                    self.clients[k * sr + ob].row.val();
                            }
                        }
                    }
                }
            }
        }
        // Each bank port's grant (the placeholder's, unregistered).
        for j in 0..self.banks.len() {
            self.banks[j].enable.next = self.asking_first[j].val().any() && (!self.reset.val());
            self.banks[j].row.next = self.row_select.output[j].val();
        }
        for nb in (self.banks.len())..(self.banks.len() + 1) {
            for j in 0..self.second.len() {
                self.second[j].enable.next =
                    self.asking_second[j].val().any() && (!self.reset.val());
                self.second[j].row.next = self.row_select.output[nb + j].val();
            }
        }
        // The read in flight, then the answering port's word back to its
        // requester (the placeholder's; a registered crossbar inserts a stage
        // below).
        for i in 0..self.clients.len() {
            self.flight_valid[i].clock.next = self.clock.val();
            self.flight_source[i].clock.next = self.clock.val();
            self.flight_tag[i].clock.next = self.clock.val();
            self.answer_valid[i].clock.next = self.clock.val();
            self.answer_tag[i].clock.next = self.clock.val();
            self.answer_word[i].clock.next = self.clock.val();
            self.source[i].next = self.clients[i].bank.val() & self.bank_mask.val();
            if self.either_port.val() {
                self.source[i].next = self.source[i].val() << 1;
                for j in 0..self.second.len() {
                    if self.arbiters_second[j].grant.val().get_bit(i) {
                        self.source[i].next = self.source[i].val() | self.port_bit.val();
                    }
                }
            }
            self.flight_valid[i].d.next =
                self.clients[i].valid.val() && self.clients[i].ready.val();
            self.flight_source[i].d.next = self.source[i].val();
            self.flight_tag[i].d.next = self.clients[i].tag.val() & self.tag_mask.val();
            self.word_select.index[i].next = self.flight_source[i].q.val();
            self.answer_valid[i].d.next = self.flight_valid[i].q.val();
            self.answer_tag[i].d.next = self.flight_tag[i].q.val();
            self.answer_word[i].d.next = self.word_select.output[i].val() & self.word_mask.val();
            if self.reset.val() {
                self.flight_valid[i].d.next = false;
                self.answer_valid[i].d.next = false;
            }
            self.answers[i].valid.next = self.answer_valid[i].q.val();
            self.answers[i].tag.next = self.answer_tag[i].q.val();
            self.answers[i].word.next = self.answer_word[i].q.val();
        }
        // The registered crossbar: each bank port's granted row and enable
        // registered on the way to its bank (the wires out to a bank's
        // BlockRAMs, spread over the device, start at a flip-flop), and the read
        // in flight a stage longer, so that its word is selected as its bank
        // answers.
        for _on in 0..self._registered {
            for p in 0..self.port_row.len() {
                self.port_enable[p].clock.next = self.clock.val();
                self.port_row[p].clock.next = self.clock.val();
                self.port_row[p].d.next = self.row_select.output[p].val();
            }
            for j in 0..self.banks.len() {
                self.port_enable[j].d.next =
                    self.asking_first[j].val().any() && (!self.reset.val());
                self.banks[j].enable.next = self.port_enable[j].q.val();
                self.banks[j].row.next = self.port_row[j].q.val();
            }
            for nb in (self.banks.len())..(self.banks.len() + 1) {
                for j in 0..self.second.len() {
                    self.port_enable[nb + j].d.next =
                        self.asking_second[j].val().any() && (!self.reset.val());
                    self.second[j].enable.next = self.port_enable[nb + j].q.val();
                    self.second[j].row.next = self.port_row[nb + j].q.val();
                }
            }
            for i in 0..self.clients.len() {
                self.bram_valid[i].clock.next = self.clock.val();
                self.bram_source[i].clock.next = self.clock.val();
                self.bram_tag[i].clock.next = self.clock.val();
                self.bram_valid[i].d.next = self.flight_valid[i].q.val();
                self.bram_source[i].d.next = self.flight_source[i].q.val();
                self.bram_tag[i].d.next = self.flight_tag[i].q.val();
                self.word_select.index[i].next = self.bram_source[i].q.val();
                self.answer_valid[i].d.next = self.bram_valid[i].q.val();
                self.answer_tag[i].d.next = self.bram_tag[i].q.val();
                if self.reset.val() {
                    self.bram_valid[i].d.next = false;
                    self.answer_valid[i].d.next = false;
                }
            }
        }
        // A late `ready`: each requester's grant, registered (the read in flight
        // starts from the grant itself, as above). The grant's OR is spelled
        // again here rather than read back from `ready`, which this block
        // overrides, so that a crossbar without a late `ready` exports as before.
        for i in 0..self.moving.len() {
            self.late_ready[i].clock.next = self.clock.val();
            self.moving[i].next = false;
            for j in 0..self.banks.len() {
                if self.arbiters[j].grant.val().get_bit(i) {
                    self.moving[i].next = true;
                }
            }
            for j in 0..self.second.len() {
                if self.arbiters_second[j].grant.val().get_bit(i) {
                    self.moving[i].next = true;
                }
            }
            self.late_ready[i].d.next = self.moving[i].val() && (!self.reset.val());
            self.flight_valid[i].d.next =
                self.clients[i].valid.val() && self.moving[i].val() && (!self.reset.val());
            self.clients[i].ready.next = self.late_ready[i].q.val();
        }
        // The words each requester's tree chooses from (w: its inputs): every
        // bank's first port; with shared ports, each bank's two ports side by
        // side (bank × 2 + port); with split ports, the odd requesters' from the
        // second ports instead.
        for w in (self.word_select.leaves())..(self.word_select.leaves() + 1) {
            for s in (1 + self._shared)..(2 + self._shared) {
                for i in 0..self.clients.len() {
                    for j in 0..self.banks.len() {
                        self.word_select.inputs[i * w + j * s].next = self.banks[j].word.val();
                    }
                    for _on in 0..self._shared {
                        for j in 0..self.second.len() {
                            self.word_select.inputs[i * w + j * s + 1].next =
                                self.second[j].word.val();
                        }
                    }
                }
            }
            for _on in 0..self._split {
                for k in 0..self._per_port {
                    for j in 0..self.second.len() {
                        self.word_select.inputs[(k * 2 + 1) * w + j].next =
                            self.second[j].word.val();
                    }
                }
            }
        }
    }
}
