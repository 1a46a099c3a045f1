//! LineFill: brings blocks of the map from external memory into the cache's
//! lines, several at once. A fill names a block (`MemoryLayout`: one subtree of
//! `s` levels, one cache line) and the line it goes to; LineFill asks the memory
//! for the block as one AXI4 INCR burst and writes its beats into the line RAM as
//! they arrive, then reports the line filled. Up to `MAX_FILLS` bursts are in
//! flight, so the memory's latency is covered by several misses at once (the lab's
//! cycle model, docs/MEMORY.md: a missing read parks its slot and the others go
//! on). One AXI ID: the bursts return in order, so the lines in flight are a FIFO
//! (LUT-RAM) and the data needs no reorder buffer.
//!
//! The read data is never held back (`rready` is high): each beat is one write of
//! the line RAM, whose word is a beat (one or two photon words: the memory's data
//! width, `ExternalMemory::data_bits`, of the `D`-bit port). A burst answered with an error (`rresp` not OKAY) or whose
//! `rlast` does not fall on its last beat sets the sticky `error`.

use crate::hw::memory::block_map::MemoryWord;
use crate::hw::primitives::axi4_read::{AxiAddr, AxiReadMaster, BURST_INCR};
use crate::hw::primitives::block_ram::{BramIndex, BramWord};
use crate::hw::primitives::lut_ram::{LutRam, RamIndex};
use rust_hdl::prelude::*;

/// Bursts in flight at most (the pending lines' FIFO).
pub const MAX_FILLS: usize = 16;

/// A cache line's index.
pub type LineIndex = Bits<16>;

#[derive(LogicBlock)]
pub struct LineFill<const D: usize> {
    pub clock: Signal<In, Clock>,
    pub reset: Signal<In, bool>,
    /// A fill to start: the block to read and the line it goes to.
    pub fill_valid: Signal<In, bool>,
    pub fill_ready: Signal<Out, bool>,
    pub fill_block: Signal<In, MemoryWord>,
    pub fill_line: Signal<In, LineIndex>,
    /// The external memory's read channels.
    pub m_axi: AxiReadMaster<D>,
    /// The line RAM's write port: line × beats per line + beat.
    pub write_enable: Signal<Out, bool>,
    pub write_index: Signal<Out, BramIndex>,
    pub write_data: Signal<Out, BramWord>,
    /// A line whose last beat was written in the previous cycle (one cycle).
    pub filled_valid: Signal<Out, bool>,
    pub filled_line: Signal<Out, LineIndex>,
    /// A burst answered with an error or a misplaced `rlast` (until reset).
    pub error: Signal<Out, bool>,
    /// The image's base byte address, log2 of a block's bytes, the burst's
    /// `arlen` and `arsize`, log2 of the beats per line and the last beat.
    base: Constant<AxiAddr>,
    block_shift: Constant<AxiAddr>,
    arlen: Constant<Bits<8>>,
    arsize: Constant<Bits<3>>,
    beat_shift: Constant<BramIndex>,
    last_beat: Constant<Bits<8>>,
    most: Constant<Bits<8>>,
    fifo_mask: Constant<RamIndex>,
    arburst: Constant<Bits<2>>,
    ar_pending: DFF<bool>,
    ar_addr: DFF<AxiAddr>,
    /// The lines in flight, in the order their bursts were asked.
    lines: LutRam,
    head: DFF<RamIndex>,
    tail: DFF<RamIndex>,
    in_flight: DFF<Bits<8>>,
    beat: DFF<Bits<8>>,
    done_valid: DFF<bool>,
    done_line: DFF<LineIndex>,
    failed: DFF<bool>,
    take: Signal<Local, bool>,
    arrive: Signal<Local, bool>,
    finish: Signal<Local, bool>,
    head_line: Signal<Local, LineIndex>,
}

impl<const D: usize> LineFill<D> {
    /// Fills of `block_bytes`-byte blocks (a power of two, a whole number of
    /// `beat_bytes`-byte beats, at most 256 beats) from the image at byte `base`;
    /// a beat is the memory's data width, at most the port's `D` bits.
    pub fn new(base: u64, block_bytes: u64, beat_bytes: u64) -> Self {
        assert!(
            D <= 64 && beat_bytes.is_power_of_two() && beat_bytes * 8 <= D as u64,
            "a beat of 1 to 8 bytes (one line RAM word), within the port"
        );
        assert!(block_bytes.is_power_of_two() && block_bytes >= beat_bytes);
        let beats = block_bytes / beat_bytes;
        assert!(beats <= 256, "one AXI4 burst is at most 256 beats");
        assert!(
            base.is_multiple_of(block_bytes),
            "blocks aligned to their size"
        );
        LineFill {
            clock: Default::default(),
            reset: Default::default(),
            fill_valid: Default::default(),
            fill_ready: Default::default(),
            fill_block: Default::default(),
            fill_line: Default::default(),
            m_axi: Default::default(),
            write_enable: Default::default(),
            write_index: Default::default(),
            write_data: Default::default(),
            filled_valid: Default::default(),
            filled_line: Default::default(),
            error: Default::default(),
            base: Constant::new(AxiAddr::from(base)),
            block_shift: Constant::new(AxiAddr::from(u64::from(block_bytes.trailing_zeros()))),
            arlen: Constant::new(Bits::<8>::from(beats - 1)),
            arsize: Constant::new(Bits::<3>::from(u64::from(beat_bytes.trailing_zeros()))),
            beat_shift: Constant::new(BramIndex::from(u64::from(beats.trailing_zeros()))),
            last_beat: Constant::new(Bits::<8>::from(beats - 1)),
            most: Constant::new(Bits::<8>::from(MAX_FILLS as u64)),
            fifo_mask: Constant::new(RamIndex::from(MAX_FILLS as u64 - 1)),
            arburst: Constant::new(Bits::<2>::from(BURST_INCR)),
            ar_pending: Default::default(),
            ar_addr: Default::default(),
            lines: LutRam::new(MAX_FILLS, 16),
            head: Default::default(),
            tail: Default::default(),
            in_flight: Default::default(),
            beat: Default::default(),
            done_valid: Default::default(),
            done_line: Default::default(),
            failed: Default::default(),
            take: Default::default(),
            arrive: Default::default(),
            finish: Default::default(),
            head_line: Default::default(),
        }
    }
}

impl<const D: usize> Logic for LineFill<D> {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(
            self, clock, ar_pending, ar_addr, head, tail, in_flight, beat, done_valid, done_line,
            failed
        );
        self.lines.clock.next = self.clock.val();
        // Read address: one burst asked at a time from a register; a new fill is
        // taken once the previous burst's address was accepted and a FIFO entry is free.
        self.m_axi.arvalid.next = self.ar_pending.q.val();
        self.m_axi.araddr.next = self.ar_addr.q.val();
        self.m_axi.arlen.next = self.arlen.val();
        self.m_axi.arsize.next = self.arsize.val();
        self.m_axi.arburst.next = self.arburst.val();
        self.fill_ready.next = (!self.ar_pending.q.val())
            && (self.in_flight.q.val() < self.most.val())
            && (!self.reset.val());
        self.take.next = self.fill_valid.val() && self.fill_ready.val();
        self.ar_pending.d.next =
            (self.ar_pending.q.val() && (!self.m_axi.arready.val())) || self.take.val();
        if self.take.val() {
            self.ar_addr.d.next =
                self.base.val() + (self.fill_block.val() << self.block_shift.val());
            self.tail.d.next = self.tail.q.val() + 1;
        }
        self.lines.write_enable.next = self.take.val();
        self.lines.write_index.next = self.tail.q.val() & self.fifo_mask.val();
        self.lines.write_data.next = bit_cast::<32, 16>(self.fill_line.val());
        self.lines.read_index.next = self.head.q.val() & self.fifo_mask.val();
        self.head_line.next = bit_cast::<16, 32>(self.lines.read_data.val());
        // Read data: every beat written into the head line, in order.
        self.m_axi.rready.next = true;
        self.arrive.next = self.m_axi.rvalid.val();
        self.finish.next = self.arrive.val() && self.m_axi.rlast.val();
        self.write_enable.next = self.arrive.val();
        self.write_index.next = (bit_cast::<16, 16>(self.head_line.val()) << self.beat_shift.val())
            + bit_cast::<16, 8>(self.beat.q.val());
        self.write_data.next = bit_cast::<64, D>(self.m_axi.rdata.val());
        if self.arrive.val() {
            self.beat.d.next = self.beat.q.val() + 1;
            if (self.m_axi.rresp.val() != 0)
                || (self.m_axi.rlast.val() != (self.beat.q.val() == self.last_beat.val()))
                || (self.in_flight.q.val() == 0)
            {
                self.failed.d.next = true;
            }
        }
        if self.finish.val() {
            self.beat.d.next = 0.into();
            self.head.d.next = self.head.q.val() + 1;
        }
        self.done_valid.d.next = self.finish.val();
        self.done_line.d.next = self.head_line.val();
        // A fill counts from its acceptance to its last beat.
        if self.take.val() && (!self.finish.val()) {
            self.in_flight.d.next = self.in_flight.q.val() + 1;
        }
        if self.finish.val() && (!self.take.val()) {
            self.in_flight.d.next = self.in_flight.q.val() - 1;
        }
        self.filled_valid.next = self.done_valid.q.val();
        self.filled_line.next = self.done_line.q.val();
        self.error.next = self.failed.q.val();
        if self.reset.val() {
            self.ar_pending.d.next = false;
            self.head.d.next = 0.into();
            self.tail.d.next = 0.into();
            self.in_flight.d.next = 0.into();
            self.beat.d.next = 0.into();
            self.done_valid.d.next = false;
            self.failed.d.next = false;
        }
    }
}
