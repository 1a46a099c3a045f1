//! FillArbiter: the cache banks' fill requests, one taken a cycle in round robin
//! ([`PortArbiter`]), for the one [`LineFill`](crate::hw::memory::line_fill::LineFill).
//!
//! Registered on both sides and between, so that no cycle both arbitrates and
//! crosses the chip (the banks sit beside their datapaths' crossbar ports, the
//! fill beside the memory port, and §4.5's round robin is a compare over every
//! requester): a bank presents its request from its own
//! registers and holds it until taken. In one cycle the round robin picks one
//! request into a one-hot register (`choice`); in the next, that bank's block and
//! line, multiplexed by the registered choice, go into the fill register (for
//! LineFill's handshake) and the bank into a one-hot register (`taken`), which
//! that bank sees the cycle after and only then writes its line's tag and marks
//! it filling. A request chosen or taken is still presented and is not picked
//! again. A fill costs one cycle more than a pick straight into the fill
//! register; a pick a cycle stays.

use crate::hw::config::core_config::ModuleMask;
use crate::hw::memory::block_map::MemoryWord;
use crate::hw::memory::line_fill::LineIndex;
use crate::hw::primitives::port_arbiter::PortArbiter;
use rust_hdl::prelude::*;

#[derive(LogicBlock)]
pub struct FillArbiter {
    pub clock: Signal<In, Clock>,
    pub reset: Signal<In, bool>,
    /// Bit j: bank j presents a fill request (from its registers).
    pub requests: Signal<In, ModuleMask>,
    /// The request picked in the previous cycle (one-hot, a register; zero when
    /// none) and, from outside, that bank's block and line.
    pub choice: Signal<Out, ModuleMask>,
    pub chosen_block: Signal<In, MemoryWord>,
    pub chosen_line: Signal<In, LineIndex>,
    /// The bank whose request was taken in the previous cycle (one-hot, a register).
    pub taken: Signal<Out, ModuleMask>,
    /// The fill to start, from registers (LineFill's handshake).
    pub fill_valid: Signal<Out, bool>,
    pub fill_ready: Signal<In, bool>,
    pub fill_block: Signal<Out, MemoryWord>,
    pub fill_line: Signal<Out, LineIndex>,
    turn: PortArbiter,
    chosen: DFF<ModuleMask>,
    /// `chosen` holds a request (is not zero), kept in its own flip-flop so that
    /// the pick does not wait for an OR over the banks.
    chosen_valid: DFF<bool>,
    taken_bank: DFF<ModuleMask>,
    stage_valid: DFF<bool>,
    stage_block: DFF<MemoryWord>,
    stage_line: DFF<LineIndex>,
    /// The fill register is free (empty, or LineFill takes it this cycle) and a
    /// request is chosen: it moves into the fill register.
    move_on: Signal<Local, bool>,
    /// The choice register is free (empty, or moving on) and a request is there:
    /// one is picked.
    pick: Signal<Local, bool>,
}

impl FillArbiter {
    /// The requests of `banks` (1..=32) cache banks.
    pub fn new(banks: usize) -> Self {
        FillArbiter {
            clock: Default::default(),
            reset: Default::default(),
            requests: Default::default(),
            choice: Default::default(),
            chosen_block: Default::default(),
            chosen_line: Default::default(),
            taken: Default::default(),
            fill_valid: Default::default(),
            fill_ready: Default::default(),
            fill_block: Default::default(),
            fill_line: Default::default(),
            turn: PortArbiter::new(banks),
            chosen: Default::default(),
            chosen_valid: Default::default(),
            taken_bank: Default::default(),
            stage_valid: Default::default(),
            stage_block: Default::default(),
            stage_line: Default::default(),
            move_on: Default::default(),
            pick: Default::default(),
        }
    }
}

impl Logic for FillArbiter {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(
            self,
            clock,
            chosen,
            chosen_valid,
            taken_bank,
            stage_valid,
            stage_block,
            stage_line
        );
        self.turn.clock.next = self.clock.val();
        self.turn.requests.next =
            self.requests.val() & !self.taken_bank.q.val() & !self.chosen.q.val();
        self.turn.hold.next = false;
        self.move_on.next =
            (!self.stage_valid.q.val() || self.fill_ready.val()) && self.chosen_valid.q.val();
        self.pick.next =
            (!self.chosen_valid.q.val() || self.move_on.val()) && self.turn.granted.val();
        self.turn.advance.next = self.pick.val();
        // The pick, into the choice register.
        self.chosen_valid.d.next = self.chosen_valid.q.val() && !self.move_on.val();
        if self.move_on.val() {
            self.chosen.d.next = 0.into();
        }
        if self.pick.val() {
            self.chosen.d.next = self.turn.grant.val();
            self.chosen_valid.d.next = true;
        }
        // The choice, into the fill register; its bank is told.
        self.taken_bank.d.next = 0.into();
        self.stage_valid.d.next = self.stage_valid.q.val() && !self.fill_ready.val();
        if self.move_on.val() {
            self.taken_bank.d.next = self.chosen.q.val();
            self.stage_valid.d.next = true;
            self.stage_block.d.next = self.chosen_block.val();
            self.stage_line.d.next = self.chosen_line.val();
        }
        if self.reset.val() {
            self.chosen.d.next = 0.into();
            self.chosen_valid.d.next = false;
            self.taken_bank.d.next = 0.into();
            self.stage_valid.d.next = false;
        }
        self.choice.next = self.chosen.q.val();
        self.taken.next = self.taken_bank.q.val();
        self.fill_valid.next = self.stage_valid.q.val();
        self.fill_block.next = self.stage_block.q.val();
        self.fill_line.next = self.stage_line.q.val();
    }
}
