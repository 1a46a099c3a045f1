//! CacheBank: one bank of the on-chip cache of the map's lower levels (the
//! external-memory store, `hw::memory`'s module notes): the lines whose index is
//! this bank's modulo B, each one block (`MemoryLayout`: a subtree of `s`
//! levels). Direct-mapped, as the lab's cache model chose (docs/MEMORY.md: more
//! ways gain under half a point of hit rate at the device's budget).
//!
//! Seen from the crossbar it is a bank: a read port ([`CachePort`]) takes a row in
//! one cycle and answers its word the next, as a BlockRAM bank does. The row
//! carries the block's tag in its high bits (`tag | line in bank | word in
//! block`); the answer carries a miss flag in bit `W`, above the word: the line is
//! not there, is being filled, or had its tag or valid bit written in the cycle of
//! the read (so a read never sees a tag and a valid bit of two different blocks).
//! A miss waits one cycle in a register, then becomes the bank's fill request (a
//! second register, held until the
//! [`FillArbiter`](crate::hw::memory::fill_arbiter::FillArbiter) takes it) if
//! that register is free and its line is neither being filled nor holding a
//! block not read yet; else it is dropped and its reader misses again (a miss
//! kept longer could ask for a block that has arrived meanwhile, and that line
//! would then hold a block nobody reads). The line's tag is written in the cycle
//! after the request was taken (the arbiter's registered grant) and its valid bit
//! set when the fill is done, so a line being filled always misses. Requests go
//! out of registers and grants come in to registers: a bank's cycle never waits
//! for the arbitration among banks.
//! A line just filled is not replaced before it has been read once: two readers
//! of two blocks that share a line would otherwise take it from each other
//! forever (each fill replaced before its reader's next try), and the reader of a
//! filled line always comes back for it (its slot wakes when the fill is done).
//!
//! The valid, filling and used bits are flip-flops (a bank holds at most
//! [`MAX_BANK_LINES`] lines); the bits of lines the bank does not have are held at
//! 0 on their inputs, so synthesis drops them and the logic that reads them (the
//! masks' width is fixed, the bank's lines are not). Each port has its own copy
//! of the words and tags.

use crate::hw::config::core_config::Addr;
use crate::hw::memory::block_map::MemoryWord;
use crate::hw::memory::cache_port::{CachePort, LineMask, LineShape, TagShape, MAX_BANK_LINES};
use crate::hw::memory::line_fill::LineIndex;
use crate::hw::primitives::bank_bus::BankMemoryPort;
use crate::hw::primitives::block_ram::{BramIndex, BramWord};
use rust_hdl::prelude::*;

#[derive(LogicBlock)]
pub struct CacheBank {
    pub clock: Signal<In, Clock>,
    pub reset: Signal<In, bool>,
    /// The read port and the second read port (with one port, its word is 0):
    /// row now, word (and miss flag) the next cycle.
    pub read: BankMemoryPort,
    pub second: BankMemoryPort,
    /// A block to fetch (the request, from registers): its block number and its
    /// (global) line; `fill_taken`: the request was taken in the previous cycle.
    pub fill_valid: Signal<Out, bool>,
    pub fill_taken: Signal<In, bool>,
    pub fill_block: Signal<Out, MemoryWord>,
    pub fill_line: Signal<Out, LineIndex>,
    /// `LineFill`'s writes (global line × beats a line + beat) and its filled
    /// lines: those of this bank are taken.
    pub write_enable: Signal<In, bool>,
    pub write_index: Signal<In, BramIndex>,
    pub write_data: Signal<In, BramWord>,
    pub filled_valid: Signal<In, bool>,
    pub filled_line: Signal<In, LineIndex>,
    /// This bank's index, `b` (B = 2^b banks), log2 of a line's beats, masks of
    /// a global line's bank and of a line in the bank and of a beat in a line.
    bank: Constant<Addr>,
    bank_bits: Constant<Addr>,
    beat_levels: Constant<Addr>,
    bank_mask: Constant<Addr>,
    line_mask: Constant<Addr>,
    beat_mask: Constant<Addr>,
    /// One bit for each line the bank has.
    lines_held: Constant<LineMask>,
    ports: Vec<CachePort>,
    valid: DFF<LineMask>,
    filling: DFF<LineMask>,
    /// Read since its fill was done (a line not read yet is kept).
    used: DFF<LineMask>,
    /// The one miss waiting to become the request.
    miss_valid: DFF<bool>,
    miss_block: DFF<MemoryWord>,
    miss_line: DFF<Addr>,
    miss_tag: DFF<Addr>,
    /// The fill request presented to the arbiter.
    request_valid: DFF<bool>,
    request_block: DFF<MemoryWord>,
    request_line: DFF<Addr>,
    request_tag: DFF<Addr>,
    take: Signal<Local, bool>,
    /// The waiting miss may become the request: the request's register is free
    /// (empty, or taken now) and its line is neither filling nor holding a block
    /// not read yet, nor taken for a fill this cycle.
    moving: Signal<Local, bool>,
    eligible: Signal<Local, bool>,
    next_valid: Signal<Local, LineMask>,
    next_filling: Signal<Local, LineMask>,
    next_used: Signal<Local, LineMask>,
    next_miss: Signal<Local, bool>,
    write_line: Signal<Local, Addr>,
    word_index: Signal<Local, Addr>,
    mine_write: Signal<Local, bool>,
    done: Signal<Local, bool>,
    done_global: Signal<Local, Addr>,
    done_line: Signal<Local, Addr>,
}

impl CacheBank {
    /// Bank `bank` of `2^bank_bits`, holding `lines` lines (a power of two, at
    /// most [`MAX_BANK_LINES`]) of `shape` (bit `word_bits` of an answer is the
    /// miss flag), their tags in `tags`, with `ports` read ports (1 or 2).
    pub fn new(
        bank: u32,
        bank_bits: u32,
        lines: usize,
        ports: usize,
        shape: LineShape,
        tags: TagShape,
    ) -> Self {
        assert!(lines.is_power_of_two() && lines <= MAX_BANK_LINES);
        assert!((1..=2).contains(&ports) && bank_bits <= 10 && bank < (1 << bank_bits));
        let line_bits = lines.trailing_zeros();
        CacheBank {
            clock: Default::default(),
            reset: Default::default(),
            read: Default::default(),
            second: Default::default(),
            fill_valid: Default::default(),
            fill_taken: Default::default(),
            fill_block: Default::default(),
            fill_line: Default::default(),
            write_enable: Default::default(),
            write_index: Default::default(),
            write_data: Default::default(),
            filled_valid: Default::default(),
            filled_line: Default::default(),
            bank: Constant::new(Addr::from(u64::from(bank))),
            bank_bits: Constant::new(Addr::from(u64::from(bank_bits))),
            beat_levels: Constant::new(Addr::from(u64::from(shape.beat_levels()))),
            bank_mask: Constant::new(Addr::from((1u64 << bank_bits) - 1)),
            line_mask: Constant::new(Addr::from((lines as u64) - 1)),
            beat_mask: Constant::new(Addr::from((1u64 << shape.beat_levels()) - 1)),
            lines_held: Constant::new(
                (0..lines).fold(LineMask::default(), |m, i| m.replace_bit(i, true)),
            ),
            ports: (0..ports)
                .map(|_| CachePort::new(bank, bank_bits, line_bits, shape, tags))
                .collect(),
            valid: Default::default(),
            filling: Default::default(),
            used: Default::default(),
            miss_valid: Default::default(),
            miss_block: Default::default(),
            miss_line: Default::default(),
            miss_tag: Default::default(),
            request_valid: Default::default(),
            request_block: Default::default(),
            request_line: Default::default(),
            request_tag: Default::default(),
            take: Default::default(),
            moving: Default::default(),
            eligible: Default::default(),
            next_valid: Default::default(),
            next_filling: Default::default(),
            next_used: Default::default(),
            next_miss: Default::default(),
            write_line: Default::default(),
            word_index: Default::default(),
            mine_write: Default::default(),
            done: Default::default(),
            done_global: Default::default(),
            done_line: Default::default(),
        }
    }
}

impl Logic for CacheBank {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(
            self,
            clock,
            valid,
            filling,
            used,
            miss_valid,
            miss_block,
            miss_line,
            miss_tag,
            request_valid,
            request_block,
            request_line,
            request_tag
        );
        // The fills' beats and finished lines that are this bank's.
        self.write_line.next = bit_cast::<24, 16>(self.write_index.val()) >> self.beat_levels.val();
        self.mine_write.next = self.write_enable.val()
            && ((self.write_line.val() & self.bank_mask.val()) == self.bank.val());
        self.word_index.next = (((self.write_line.val() >> self.bank_bits.val())
            & self.line_mask.val())
            << self.beat_levels.val())
            | (bit_cast::<24, 16>(self.write_index.val()) & self.beat_mask.val());
        self.done_global.next = bit_cast::<24, 16>(self.filled_line.val());
        self.done.next = self.filled_valid.val()
            && ((self.done_global.val() & self.bank_mask.val()) == self.bank.val());
        self.done_line.next =
            (self.done_global.val() >> self.bank_bits.val()) & self.line_mask.val();
        // The request, from its registers; taken in the previous cycle, it is
        // started now.
        self.fill_valid.next = self.request_valid.q.val();
        self.fill_block.next = self.request_block.q.val();
        self.fill_line.next = bit_cast::<16, 24>(
            (self.request_line.q.val() << self.bank_bits.val()) | self.bank.val(),
        );
        self.take.next = self.fill_taken.val() && self.request_valid.q.val();
        // The waiting miss becomes the request unless its line is being filled
        // (or starts to be now: another miss of it was taken first) or holds a
        // block not read yet: then it is dropped, and its reader misses again
        // until that fill is done.
        self.moving.next =
            self.miss_valid.q.val() && (!self.request_valid.q.val() || self.take.val());
        self.eligible.next = !self.filling.q.val().get_bit(self.miss_line.q.val().index())
            && (self.used.q.val().get_bit(self.miss_line.q.val().index())
                || !self.valid.q.val().get_bit(self.miss_line.q.val().index()))
            && (!self.take.val() || (self.request_line.q.val() != self.miss_line.q.val()));
        self.request_valid.d.next = self.request_valid.q.val() && !self.take.val();
        if self.moving.val() && self.eligible.val() {
            self.request_valid.d.next = true;
            self.request_block.d.next = self.miss_block.q.val();
            self.request_line.d.next = self.miss_line.q.val();
            self.request_tag.d.next = self.miss_tag.q.val();
        }
        // Next cycle's bits and miss, built up in locals (a DFF's input is only
        // written here, never read back).
        self.next_filling.next = self.filling.q.val();
        if self.take.val() {
            self.next_filling.next = self
                .filling
                .q
                .val()
                .replace_bit(self.request_line.q.val().index(), true);
        }
        self.next_valid.next = self.valid.q.val();
        self.next_used.next = self.used.q.val();
        if self.done.val() {
            self.next_used.next = self
                .used
                .q
                .val()
                .replace_bit(self.done_line.val().index(), false);
            self.next_filling.next = self
                .next_filling
                .val()
                .replace_bit(self.done_line.val().index(), false);
            self.next_valid.next = self
                .valid
                .q
                .val()
                .replace_bit(self.done_line.val().index(), true);
        }
        // A waiting miss has moved on or is dropped.
        self.next_miss.next = false;
        // Port 0 is the read port, port 1 (if any) the second.
        self.ports[0].enable.next = self.read.enable.val();
        self.ports[0].row.next = self.read.row.val();
        self.read.word.next = self.ports[0].word.val();
        self.second.word.next = 0.into();
        for p in 1..self.ports.len() {
            self.ports[p].enable.next = self.second.enable.val();
            self.ports[p].row.next = self.second.row.val();
            self.second.word.next = self.ports[p].word.val();
        }
        for p in 0..self.ports.len() {
            self.ports[p].clock.next = self.clock.val();
            self.ports[p].valid.next = self.valid.q.val();
            self.ports[p].filling.next = self.filling.q.val();
            self.ports[p].done.next = self.done.val();
            self.ports[p].done_line.next = self.done_line.val();
            self.ports[p].word_write.next = self.mine_write.val();
            self.ports[p].word_index.next = bit_cast::<16, 24>(self.word_index.val());
            self.ports[p].word_data.next = self.write_data.val();
            self.ports[p].tag_write.next = self.take.val();
            self.ports[p].tag_line.next = self.request_line.q.val();
            self.ports[p].tag_data.next = self.request_tag.q.val();
            if self.ports[p].hit.val() {
                self.next_used.next = self
                    .next_used
                    .val()
                    .replace_bit(self.ports[p].miss_line.val().index(), true);
            }
            // The first port whose read missed gives the waiting miss.
            if self.ports[p].missed.val() && !self.next_miss.val() {
                self.next_miss.next = true;
                self.miss_line.d.next = self.ports[p].miss_line.val();
                self.miss_block.d.next = self.ports[p].miss_block.val();
                self.miss_tag.d.next = self.ports[p].miss_tag.val();
            }
        }
        self.valid.d.next = self.next_valid.val() & self.lines_held.val();
        self.filling.d.next = self.next_filling.val() & self.lines_held.val();
        self.used.d.next = self.next_used.val() & self.lines_held.val();
        self.miss_valid.d.next = self.next_miss.val();
        if self.reset.val() {
            self.valid.d.next = 0.into();
            self.filling.d.next = 0.into();
            self.miss_valid.d.next = false;
            self.request_valid.d.next = false;
        }
    }
}
