//! MissPark: the external-memory core's stage between a read's answer and the
//! SearchModule (`ReadIssue` with `CoreConfig::memory`). A read answered by a
//! cache bank with the miss flag set never reaches the SearchModule: its slot is
//! parked while the other slots go on ("a slot waits on a busy bank", now on a
//! block in flight from memory), and after [`RETRY_CYCLES`] its read is offered
//! again (its context stays in the read issue's LUT-RAM), by when the block's
//! burst has most likely arrived; a retry that misses again parks again. A hit
//! goes on as the banked core's read does, one cycle later: the request in the
//! cycle the answer arrives, the word registered for the next.
//!
//! The parked slots are a FIFO in LUT-RAM (slot and the cycle it missed): at most
//! one answer arrives a cycle, each slot has at most one read, and every slot
//! waits as long, so the oldest is always the first due.

use crate::hw::config::core_config::{Addr, ModuleIndex, Word};
use crate::hw::config::memory_config::RETRY_CYCLES;
use crate::hw::primitives::lut_ram::{LutRam, RamIndex};
use rust_hdl::prelude::*;

/// FIFO entries: at least the slots of a datapath.
const PARKED: usize = 32;

#[derive(LogicBlock)]
pub struct MissPark<const W: usize> {
    pub clock: Signal<In, Clock>,
    /// Drops the parked slots and the read in the stage.
    pub reset: Signal<In, bool>,
    /// A read whose answer arrives the next cycle: its slot and address.
    pub read_valid: Signal<In, bool>,
    pub read_slot: Signal<In, ModuleIndex>,
    pub read_address: Signal<In, Addr>,
    /// The answer of the read in the stage: its word, and whether it missed.
    pub answer: Signal<In, Word<W>>,
    pub missed: Signal<In, bool>,
    /// A read that hit, for the SearchModule; its word in the next cycle.
    pub request_valid: Signal<Out, bool>,
    pub request_slot: Signal<Out, ModuleIndex>,
    pub request_address: Signal<Out, Addr>,
    pub word: Signal<Out, Word<W>>,
    /// A parked slot whose wait is over: its read is to be offered again.
    pub retry_valid: Signal<Out, bool>,
    pub retry_slot: Signal<Out, ModuleIndex>,
    stage_valid: DFF<bool>,
    stage_slot: DFF<ModuleIndex>,
    stage_address: DFF<Addr>,
    answer_word: DFF<Word<W>>,
    /// The parked slots: slot in bits 0–7, the cycle it parked in bits 8–15.
    parked: LutRam,
    head: DFF<RamIndex>,
    tail: DFF<RamIndex>,
    now: DFF<Bits<8>>,
    retry_after: Constant<Bits<8>>,
    index_mask: Constant<RamIndex>,
    miss: Signal<Local, bool>,
    head_entry: Signal<Local, Bits<32>>,
    /// Cycles since the head parked, modulo 256 (a local of 8 bits, so that the
    /// exported subtraction wraps as the simulation's does).
    age: Signal<Local, Bits<8>>,
    due: Signal<Local, bool>,
}

impl<const W: usize> MissPark<W> {
    pub fn new() -> Self {
        MissPark {
            clock: Default::default(),
            reset: Default::default(),
            read_valid: Default::default(),
            read_slot: Default::default(),
            read_address: Default::default(),
            answer: Default::default(),
            missed: Default::default(),
            request_valid: Default::default(),
            request_slot: Default::default(),
            request_address: Default::default(),
            word: Default::default(),
            retry_valid: Default::default(),
            retry_slot: Default::default(),
            stage_valid: Default::default(),
            stage_slot: Default::default(),
            stage_address: Default::default(),
            answer_word: Default::default(),
            parked: LutRam::new(PARKED, 16),
            head: Default::default(),
            tail: Default::default(),
            now: Default::default(),
            retry_after: Constant::new(Bits::<8>::from(u64::from(RETRY_CYCLES))),
            index_mask: Constant::new(RamIndex::from(PARKED as u64 - 1)),
            miss: Default::default(),
            head_entry: Default::default(),
            age: Default::default(),
            due: Default::default(),
        }
    }
}

impl<const W: usize> Default for MissPark<W> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const W: usize> Logic for MissPark<W> {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(
            self,
            clock,
            stage_valid,
            stage_slot,
            stage_address,
            answer_word,
            head,
            tail,
            now
        );
        self.parked.clock.next = self.clock.val();
        self.now.d.next = self.now.q.val() + 1;
        // The read in the stage meets its answer.
        self.stage_valid.d.next = self.read_valid.val() && !self.reset.val();
        self.stage_slot.d.next = self.read_slot.val();
        self.stage_address.d.next = self.read_address.val();
        self.answer_word.d.next = self.answer.val();
        self.miss.next = self.stage_valid.q.val() && self.missed.val();
        self.request_valid.next = self.stage_valid.q.val() && !self.missed.val();
        self.request_slot.next = self.stage_slot.q.val();
        self.request_address.next = self.stage_address.q.val();
        self.word.next = self.answer_word.q.val();
        // A miss parks its slot at the tail, stamped with the cycle.
        self.parked.write_enable.next = self.miss.val();
        self.parked.write_index.next = self.tail.q.val() & self.index_mask.val();
        self.parked.write_data.next =
            bit_cast::<32, 8>(self.stage_slot.q.val()) | (bit_cast::<32, 8>(self.now.q.val()) << 8);
        if self.miss.val() {
            self.tail.d.next = self.tail.q.val() + 1;
        }
        // The head leaves once it has waited its cycles.
        self.parked.read_index.next = self.head.q.val() & self.index_mask.val();
        self.head_entry.next = self.parked.read_data.val();
        self.age.next = self.now.q.val() - bit_cast::<8, 32>(self.head_entry.val() >> 8);
        self.due.next =
            (self.head.q.val() != self.tail.q.val()) && (self.age.val() >= self.retry_after.val());
        self.retry_valid.next = self.due.val();
        self.retry_slot.next = bit_cast::<8, 32>(self.head_entry.val());
        if self.due.val() {
            self.head.d.next = self.head.q.val() + 1;
        }
        if self.reset.val() {
            self.head.d.next = 0.into();
            self.tail.d.next = 0.into();
        }
    }
}
