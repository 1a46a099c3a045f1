//! CachePort: one read port of a [`CacheBank`](crate::hw::memory::cache_bank::CacheBank)
//! with its own copy of the bank's words and tags (BlockRAMs: every copy takes
//! every write). A row now, the word the next cycle with the miss flag in bit
//! `W`: set unless the line was valid, not being filled, not written in the
//! read's cycle, and holds the row's tag. A read that missed names its block and
//! line, for the bank's fill request.
//!
//! The words' RAM is written a memory beat at a time (`LineFill`): with two
//! photon words a beat, each RAM word holds a pair (the even word in the low
//! lane), the read takes the pair and picks its lane the next cycle, so a fill
//! takes one write a beat and the RAM's depth halves as its width doubles (the
//! same BlockRAMs).
//!
//! The tags are BlockRAM (LUT-RAM up to 32 lines, where yosys puts so small a
//! memory), or LUT-RAM at any depth and only as wide as the map's largest tag
//! ([`TagShape`], `CacheTags`): the same registered read either way, so the
//! port behaves the same cycle for cycle.

use crate::hw::config::core_config::{bits_for, Addr};
use crate::hw::config::memory_config::CacheTags;
pub use crate::hw::config::memory_config::MAX_BANK_LINES;
use crate::hw::memory::block_map::MemoryWord;
use crate::hw::primitives::block_ram::{BlockRam, BramIndex, BramWord};
use rust_hdl::prelude::*;

/// Width of a line's tag memory: the block number above the line's index (the
/// map's address bits above a block's and the line's, with room to spare).
pub const TAG_BITS: u32 = 24;

/// One bit per line of a bank.
pub type LineMask = Bits<MAX_BANK_LINES>;

/// What a cache line holds and how it is written: a block of `block_levels`
/// levels of `word_bits`-bit photon words (below 64), written a memory beat of
/// `2^lane_shift` words (1 or 2) at a time, each word in a `lane_bits`-bit lane
/// of the beat (the image's word width).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LineShape {
    pub block_levels: u32,
    pub word_bits: u32,
    pub lane_shift: u32,
    pub lane_bits: u32,
}

impl LineShape {
    /// Levels of a block's beats: log2 of the beats a line.
    pub fn beat_levels(self) -> u32 {
        self.block_levels - self.lane_shift
    }
}

/// A bank's tag memory: its width, and whether it is LUT-RAM at any depth.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TagShape {
    pub bits: u32,
    pub lut_ram: bool,
}

impl TagShape {
    /// The tags of a cache of `blocks` blocks over `2^bank_bits` banks of
    /// `2^line_bits` lines, kept in `tags`: [`TAG_BITS`] wide in BlockRAM; in
    /// LUT-RAM, where each bit costs logic, the bits of the largest tag only.
    pub fn new(tags: CacheTags, blocks: u32, bank_bits: u32, line_bits: u32) -> Self {
        match tags {
            CacheTags::BlockRam => TagShape {
                bits: TAG_BITS,
                lut_ram: false,
            },
            CacheTags::LutRam => TagShape {
                bits: bits_for(u64::from(blocks.saturating_sub(1)) >> (bank_bits + line_bits)),
                lut_ram: true,
            },
        }
    }
}

#[derive(LogicBlock)]
pub struct CachePort {
    pub clock: Signal<In, Clock>,
    /// The crossbar's read: the row (`tag | line in bank | word in block`) now, the
    /// word (and the miss flag) the next cycle.
    pub enable: Signal<In, bool>,
    pub row: Signal<In, Addr>,
    pub word: Signal<Out, BramWord>,
    /// The bank's valid and filling bits, and the line whose fill finishes this
    /// cycle (its valid bit is set): a read of it, or of the line whose tag is
    /// written this cycle, misses.
    pub valid: Signal<In, LineMask>,
    pub filling: Signal<In, LineMask>,
    pub done: Signal<In, bool>,
    pub done_line: Signal<In, Addr>,
    /// The writes every copy takes: a word, a line's tag.
    pub word_write: Signal<In, bool>,
    /// The beat's index in this bank's RAM (line in bank × beats a line + beat).
    pub word_index: Signal<In, BramIndex>,
    pub word_data: Signal<In, BramWord>,
    pub tag_write: Signal<In, bool>,
    pub tag_line: Signal<In, Addr>,
    pub tag_data: Signal<In, Addr>,
    /// The previous cycle's read hit, or missed: its block, its line in the bank
    /// and its tag.
    pub hit: Signal<Out, bool>,
    pub missed: Signal<Out, bool>,
    pub miss_block: Signal<Out, MemoryWord>,
    pub miss_line: Signal<Out, Addr>,
    pub miss_tag: Signal<Out, Addr>,
    /// The bank's index, log2 of its lines and of the banks, `s`, masks of the
    /// row's fields, the miss flag's bit, log2 of the words a beat, the lane's
    /// width and mask, and a word's mask.
    bank: Constant<Addr>,
    line_bits: Constant<Addr>,
    bank_bits: Constant<Addr>,
    block_levels: Constant<Addr>,
    line_mask: Constant<Addr>,
    index_mask: Constant<Addr>,
    miss_bit: Constant<BramWord>,
    lane_shift: Constant<Addr>,
    lane_bits: Constant<BramWord>,
    lane_mask: Constant<Addr>,
    word_mask: Constant<BramWord>,
    words: BlockRam,
    tags: BlockRam,
    line: Signal<Local, Addr>,
    read_enable: DFF<bool>,
    read_ok: DFF<bool>,
    read_tag: DFF<Addr>,
    read_line: DFF<Addr>,
    read_lane: DFF<Addr>,
    lane_word: Signal<Local, BramWord>,
    found: Signal<Local, bool>,
    blocked: Signal<Local, bool>,
}

impl CachePort {
    /// A port of bank `bank` of `2^bank_bits`, `2^line_bits` lines of `shape`,
    /// their tags in `tags`.
    pub fn new(
        bank: u32,
        bank_bits: u32,
        line_bits: u32,
        shape: LineShape,
        tags: TagShape,
    ) -> Self {
        let LineShape {
            block_levels,
            word_bits,
            lane_shift,
            lane_bits,
        } = shape;
        let index_bits = line_bits + block_levels;
        assert!((1..=16).contains(&index_bits) && word_bits < 64);
        assert!(lane_shift <= 1 && lane_shift < index_bits && word_bits <= lane_bits);
        let ram_bits = (lane_bits << lane_shift) - lane_bits + word_bits;
        assert!(ram_bits <= 64, "a beat fits one RAM word");
        assert!((1..=TAG_BITS).contains(&tags.bits));
        CachePort {
            clock: Default::default(),
            enable: Default::default(),
            row: Default::default(),
            word: Default::default(),
            valid: Default::default(),
            filling: Default::default(),
            done: Default::default(),
            done_line: Default::default(),
            word_write: Default::default(),
            word_index: Default::default(),
            word_data: Default::default(),
            tag_write: Default::default(),
            tag_line: Default::default(),
            tag_data: Default::default(),
            hit: Default::default(),
            missed: Default::default(),
            miss_block: Default::default(),
            miss_line: Default::default(),
            miss_tag: Default::default(),
            bank: Constant::new(Addr::from(u64::from(bank))),
            line_bits: Constant::new(Addr::from(u64::from(line_bits))),
            bank_bits: Constant::new(Addr::from(u64::from(bank_bits))),
            block_levels: Constant::new(Addr::from(u64::from(block_levels))),
            line_mask: Constant::new(Addr::from((1u64 << line_bits) - 1)),
            index_mask: Constant::new(Addr::from((1u64 << index_bits) - 1)),
            miss_bit: Constant::new(BramWord::from(1u64 << word_bits)),
            lane_shift: Constant::new(Addr::from(u64::from(lane_shift))),
            lane_bits: Constant::new(BramWord::from(u64::from(lane_bits))),
            lane_mask: Constant::new(Addr::from((1u64 << lane_shift) - 1)),
            word_mask: Constant::new(BramWord::from((1u64 << word_bits) - 1)),
            words: BlockRam::new(index_bits - lane_shift, ram_bits),
            tags: if tags.lut_ram {
                BlockRam::distributed(line_bits.max(1), tags.bits)
            } else {
                BlockRam::new(line_bits.max(1), tags.bits)
            },
            line: Default::default(),
            read_enable: Default::default(),
            read_ok: Default::default(),
            read_tag: Default::default(),
            read_line: Default::default(),
            read_lane: Default::default(),
            lane_word: Default::default(),
            found: Default::default(),
            blocked: Default::default(),
        }
    }
}

impl Logic for CachePort {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(
            self,
            clock,
            read_enable,
            read_ok,
            read_tag,
            read_line,
            read_lane
        );
        self.words.clock.next = self.clock.val();
        self.tags.clock.next = self.clock.val();
        self.words.write_enable.next = self.word_write.val();
        self.words.write_index.next = self.word_index.val();
        self.words.write_data.next = self.word_data.val();
        self.tags.write_enable.next = self.tag_write.val();
        self.tags.write_index.next = bit_cast::<16, 24>(self.tag_line.val());
        self.tags.write_data.next = bit_cast::<64, 24>(self.tag_data.val());
        // The read: word and tag now; the line's bits now, registered.
        self.line.next = (self.row.val() >> self.block_levels.val()) & self.line_mask.val();
        self.words.read_index.next =
            bit_cast::<16, 24>((self.row.val() & self.index_mask.val()) >> self.lane_shift.val());
        self.read_lane.d.next = self.row.val() & self.lane_mask.val();
        self.tags.read_index.next = bit_cast::<16, 24>(self.line.val());
        self.read_enable.d.next = self.enable.val();
        self.read_tag.d.next = self.row.val() >> self.line_bits.val() >> self.block_levels.val();
        self.read_line.d.next = self.line.val();
        // Being filled, or its tag or valid bit written now: the read misses.
        self.blocked.next = self.filling.val().get_bit(self.line.val().index())
            || (self.tag_write.val() && (self.tag_line.val() == self.line.val()))
            || (self.done.val() && (self.done_line.val() == self.line.val()));
        self.read_ok.d.next =
            self.valid.val().get_bit(self.line.val().index()) && !self.blocked.val();
        // The next cycle: the word, flagged unless it is the row's block's.
        self.found.next = self.read_ok.q.val()
            && (bit_cast::<24, 64>(self.tags.read_data.val()) == self.read_tag.q.val());
        // The row's word of the pair (its lane), then the flag.
        self.lane_word.next = self.words.read_data.val();
        if self.read_lane.q.val().any() {
            self.lane_word.next = self.words.read_data.val() >> self.lane_bits.val();
        }
        self.word.next = self.lane_word.val() & self.word_mask.val();
        if !self.found.val() {
            self.word.next = (self.lane_word.val() & self.word_mask.val()) | self.miss_bit.val();
        }
        self.hit.next = self.read_enable.q.val() && self.found.val();
        self.missed.next = self.read_enable.q.val() && !self.found.val();
        self.miss_line.next = self.read_line.q.val();
        self.miss_tag.next = self.read_tag.q.val();
        self.miss_block.next = bit_cast::<32, 24>(
            (((self.read_tag.q.val() << self.line_bits.val()) | self.read_line.q.val())
                << self.bank_bits.val())
                | self.bank.val(),
        );
    }
}
