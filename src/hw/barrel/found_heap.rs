//! FoundHeap: the found lists of a barrel datapath's query slots as one binary
//! max-heap per slot in BlockRAM (its small levels in LUT-RAM), for found lists of
//! hundreds of photons.
//!
//! Why a heap: the search needs the farthest found photon at all times (paper
//! §4.4: R, the pruning radius, and the entry a nearer photon replaces). The
//! paper's MaxFinder searches K bits bit-serially per query, and the barrel's
//! comparator tree over K entries (`FoundMax`) costs K − 1 comparators; both grow
//! with K. A heap finds the maximum at its root and restores itself in log2 K
//! steps of one comparison each, its entries in memory, not in logic: K = 512 is
//! ten levels, ten comparator stages and about 16 × 512 keys of BlockRAM per
//! datapath.
//!
//! Why this pipeline: both operations the search needs are top-down (an insert
//! walks from the root to the next free position, a replace sifts the new key
//! down from the root; [`HeapStage`]), so stage `s` of every operation touches
//! level `s` only and one operation can enter every cycle, from any slot. Each
//! level is its own BlockRAM of sibling pairs (one read gives a node's two
//! children), read by one stage and written by the next. The new root — the slot's
//! new R — comes out of stage 1, two cycles after the operation enters.
//!
//! Why the BlockRAM levels take two cycles: a DP16KD's read data comes out late in
//! the cycle (ECP5 BlockRAMs have no output register yosys maps to), and a level's
//! compare and the write of the level above would follow it in the same cycle, the
//! longest path of a heap core. So from level 2 on a level in BlockRAM has its read
//! registered once more (beside the BlockRAM, in the fabric) and its stage runs a
//! cycle later; the LUT-RAM levels and the root's pair stay one cycle each, so the
//! new root still comes out two cycles after the operation enters.
//!
//! The one rule for the user: two operations of one slot enter at least
//! [`MIN_SPACING`] cycles apart ([`FoundHeap::min_spacing`] for one heap). With
//! `d_l` the cycles from the read of level `l` to its stage (1, or 2 registered),
//! an operation writes level `l` `d_l + d_(l+1)` cycles after it read it (one
//! stage later, a level down), so the next operation of the slot must read it
//! later than that: the operations of one slot follow each other down the levels
//! as a wavefront. The barrel datapath meets it by construction: a slot has one
//! event in flight and comes back every slot loop (eleven cycles). Operations of
//! different slots never share an entry (the slot is the high part of every
//! address).

use crate::hw::barrel::heap_stage::{HeapKey, HeapOp, HeapPos, HeapStage};
use crate::hw::primitives::block_ram::{BlockRam, BramWord};
use rust_hdl::prelude::*;

/// Levels of fewer than `2^DISTRIBUTED_BELOW_BITS` pairs are distributed RAM.
///
/// Why: a pair is 64 bits, two DP16KD (ECP5) or a RAMB36 (Virtex-6) wide, and a
/// BlockRAM is 512 words deep at that width, so a level of 64 pairs (16 slots,
/// level 3) takes two DP16KD to hold 4 Kbit, an eighth of them. With 16 slots
/// levels 3 and 4 would take four DP16KD, where BlockRAM is what a device of many
/// K = 500 datapaths runs out of first. LUT-RAM is no bargain either: on the ECP5
/// a 16 × 4-bit DPR16X4 takes a slice's four LUT4 sites, so from 256 pairs on a
/// level would cost more LUTs than a full device can spare for its two DP16KD; it
/// stays in BlockRAM.
pub const DISTRIBUTED_BELOW_BITS: u32 = 8;

/// The fewest cycles between two operations of one slot, for every heap (two
/// registered levels in a row; [`FoundHeap::min_spacing`]).
pub const MIN_SPACING: usize = 5;

/// The first level whose BlockRAM read is registered again: the root's pair and
/// level 1 answer in one cycle, so that the new root keeps its latency.
const FIRST_REGISTERED_LEVEL: usize = 2;

#[derive(LogicBlock)]
pub struct FoundHeap {
    pub clock: Signal<In, Clock>,
    /// An operation (`valid`, `replace`, `slot`, `key`, `size`; the other fields
    /// are the pipeline's). Insert: `size` is the position to fill (the list's
    /// size after it, 1 for the first photon). Replace: `size` is the list's size.
    pub op: Signal<In, HeapOp>,
    /// The new root (maximum) of the slot of the operation that entered two
    /// cycles ago.
    pub max_valid: Signal<Out, bool>,
    pub max_slot: Signal<Out, Bits<8>>,
    pub max: Signal<Out, HeapKey>,
    levels: Vec<BlockRam>,
    stages: Vec<HeapStage>,
    regs: Vec<DFF<HeapOp>>,
    /// Per level: its read is registered again (a BlockRAM level from
    /// [`FIRST_REGISTERED_LEVEL`] on), the register, and the operation's register
    /// beside it (unused levels' registers have no load and vanish in synthesis).
    registered: Vec<Constant<bool>>,
    data_regs: Vec<DFF<BramWord>>,
    op_delay: Vec<DFF<HeapOp>>,
    /// Loop constants: bit numbers for the depth of an insert's position, and the
    /// shifts that put the bit below a leading one at the top of the path.
    bit_number: Vec<Constant<Bits<8>>>,
    path_shift: Vec<Constant<Bits<8>>>,
    depth: Signal<Local, Bits<8>>,
    path: Signal<Local, HeapPos>,
    /// `op.size` (a signal: Verilog-2005 cannot index a bit of a struct field's
    /// slice).
    size: Signal<Local, HeapPos>,
    no_data: Constant<BramWord>,
}

impl FoundHeap {
    /// Heaps of up to `2^levels − 1` keys (levels 1..=13) for `2^slot_bits` slots
    /// (a level's pair index, slot over pair, fits the 16-bit BlockRAM index).
    pub fn new(levels: usize, slot_bits: u32) -> Self {
        assert!((1..=13).contains(&levels) && (1..=8).contains(&slot_bits));
        assert!(slot_bits as usize + levels - 1 <= 16);
        // Level l's pair-index bits (the root's pair and level 1: one pair a slot).
        let bits = |l: usize| slot_bits + (l.max(1) as u32 - 1);
        let in_blockram = |l: usize| bits(l) >= DISTRIBUTED_BELOW_BITS;
        FoundHeap {
            clock: Default::default(),
            op: Default::default(),
            max_valid: Default::default(),
            max_slot: Default::default(),
            max: Default::default(),
            levels: (0..levels)
                .map(|l| {
                    if in_blockram(l) {
                        BlockRam::new(bits(l), 64)
                    } else {
                        BlockRam::distributed(bits(l), 64)
                    }
                })
                .collect(),
            registered: (0..levels)
                .map(|l| Constant::new(in_blockram(l) && l >= FIRST_REGISTERED_LEVEL))
                .collect(),
            data_regs: (0..levels).map(|_| Default::default()).collect(),
            op_delay: (0..levels).map(|_| Default::default()).collect(),
            stages: (0..=levels).map(|s| HeapStage::new(s, levels)).collect(),
            regs: (0..=levels).map(|_| Default::default()).collect(),
            bit_number: (0..16).map(|b| Constant::new((b as u64).into())).collect(),
            path_shift: (0..16)
                .map(|b| Constant::new((16 - b as u64).into()))
                .collect(),
            depth: Default::default(),
            path: Default::default(),
            size: Default::default(),
            no_data: Constant::new(0u64.into()),
        }
    }

    /// The levels held in BlockRAM: (index bits, width) each.
    pub fn block_rams(&self) -> Vec<(u32, u32)> {
        BlockRam::shapes(&self.levels)
    }

    /// The fewest cycles between two operations of one slot in this heap: one
    /// more than the most cycles, over the levels, from a level's read to the
    /// write of it one stage later (the last level is written by a stage that
    /// reads nothing, one cycle after its own).
    pub fn min_spacing(&self) -> usize {
        let d = |l: usize| {
            if self.registered.get(l).is_some_and(|r| r.val()) {
                2
            } else {
                1
            }
        };
        (0..self.levels.len())
            .map(|l| d(l) + d(l + 1) + 1)
            .max()
            .unwrap()
    }
}

impl Logic for FoundHeap {
    #[hdl_gen]
    fn update(&mut self) {
        for s in 0..self.regs.len() {
            self.regs[s].clock.next = self.clock.val();
        }
        for l in 0..self.levels.len() {
            self.levels[l].clock.next = self.clock.val();
        }
        // An insert's path: the position's bits below its leading one, from the top
        // (one shifter here, not one per stage).
        self.depth.next = 0.into();
        self.path.next = 0.into();
        self.size.next = self.op.val().size;
        for b in 1..self.bit_number.len() {
            if self.size.val().get_bit(b) {
                self.depth.next = self.bit_number[b].val();
                self.path.next = self.size.val() << self.path_shift[b].val();
            }
        }
        self.regs[0].d.next = self.op.val();
        self.regs[0].d.next.done = false;
        self.regs[0].d.next.write = false;
        self.regs[0].d.next.node = 1.into();
        self.regs[0].d.next.shift = self.depth.val();
        self.regs[0].d.next.path = self.path.val();
        // Stage 0 reads the root's pair; stage s reads level s + 1, writes level
        // s − 1.
        self.levels[0].read_index.next = bit_cast::<16, 8>(self.op.val().slot);
        for s in 0..self.stages.len() {
            self.stages[s].op.next = self.regs[s].q.val();
            // The last stage has no level below: it only writes.
            self.stages[s].data.next = self.no_data.val();
        }
        for s in 0..self.levels.len() {
            self.data_regs[s].clock.next = self.clock.val();
            self.op_delay[s].clock.next = self.clock.val();
            self.data_regs[s].d.next = self.levels[s].read_data.val();
            self.op_delay[s].d.next = self.regs[s].q.val();
            self.stages[s].data.next = self.levels[s].read_data.val();
            if self.registered[s].val() {
                // The level's read a cycle later, and the operation with it.
                self.stages[s].op.next = self.op_delay[s].q.val();
                self.stages[s].data.next = self.data_regs[s].q.val();
            }
        }
        for s in 1..self.stages.len() {
            self.regs[s].d.next = self.stages[s - 1].out_op.val();
            self.levels[s - 1].write_enable.next = self.stages[s].write_enable.val();
            self.levels[s - 1].write_index.next = self.stages[s].write_index.val();
            self.levels[s - 1].write_data.next = self.stages[s].write_data.val();
        }
        for l in 1..self.levels.len() {
            self.levels[l].read_index.next = self.stages[l - 1].read_index.val();
        }
        self.max_valid.next = self.regs[1].q.val().valid;
        self.max_slot.next = self.regs[1].q.val().slot;
        self.max.next = self.stages[1].max.val();
    }
}
