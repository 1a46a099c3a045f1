//! HeapStage: one level of the [`FoundHeap`](crate::hw::found_heap::FoundHeap)'s
//! pipeline — the step of one heap operation at one level of one slot's max-heap.
//!
//! Both operations go top-down, one level a cycle, so that one pipeline serves
//! them and an operation never climbs back:
//! * **insert** (the found list is not full: paper §4.4's list grows by one): the
//!   new photon's key walks the path from the root to the next free position
//!   `size` (its bits give the path); at each node on the path the larger of the
//!   node's key and the carried key stays, the smaller goes on down, and the
//!   free position takes what arrives. The root becomes max(root, key) at once.
//! * **replace** (full: a nearer photon replaces the farthest, the root): the
//!   new key sifts down from the root; at each node the larger child moves up if
//!   it exceeds the carried key, else the key settles. The new root (the list's
//!   new maximum, the search's R) is known after the first level.
//!
//! Nodes are numbered from 1 (the root) as in an array heap; level `l` holds nodes
//! `2^l .. 2^(l+1)`, stored in pairs of siblings (node `n` in half `n & 1` of the
//! pair `n >> 1`), so a parent's two children are one BlockRAM read.
//!
//! In stage `s` an operation holds the pair read from level `s` (issued by stage
//! `s − 1`), issues the read of level `s + 1` (the children of its node) and writes
//! level `s − 1` (an insert the pair it decided in stage `s − 1`; a replace the pair
//! of its parent, decided now). Every level is read by one stage and written by one
//! stage, so operations of different slots follow each other every cycle.

use crate::hw::block_ram::{BramIndex, BramWord};
use rust_hdl::prelude::*;

/// A heap key: the found photon's distance (high bits) and its address (low bits),
/// so that no two photons of one query have equal keys.
pub type HeapKey = Bits<32>;
/// A node number (1 = the root) or a heap size.
pub type HeapPos = Bits<16>;

/// One operation as it passes a stage.
#[derive(Clone, Copy, Debug, PartialEq, Default, LogicStruct)]
pub struct HeapOp {
    pub valid: bool,
    /// Replace the root (else insert).
    pub replace: bool,
    /// The operation has settled: it passes the remaining stages without effect.
    pub done: bool,
    pub slot: Bits<8>,
    /// The key carried down.
    pub key: HeapKey,
    /// Insert: the position to fill (the size after the insert). Replace: the size.
    pub size: HeapPos,
    /// Insert: levels left to the position to fill (0: this stage's node).
    pub shift: Bits<8>,
    /// Insert: this stage's node. Replace: the node whose children this stage
    /// holds (the node the carried key sits on).
    pub node: HeapPos,
    /// Insert: the new root (from stage 0 on).
    pub root: HeapKey,
    /// Insert: the pair decided in the previous stage, written by this one.
    pub write: bool,
    pub write_index: BramIndex,
    pub write_pair: BramWord,
    /// Replace: the pair read by the previous stage (the one holding `node`).
    pub pair: BramWord,
}

#[derive(LogicBlock)]
pub struct HeapStage {
    /// The operation in this stage and the pair read for it from this level
    /// (zero past the last level).
    pub op: Signal<In, HeapOp>,
    pub data: Signal<In, BramWord>,
    /// The operation for the next stage.
    pub out_op: Signal<Out, HeapOp>,
    /// The read of the next level's pair (the children of the next node).
    pub read_index: Signal<Out, BramIndex>,
    /// The write of the previous level (none in stage 0).
    pub write_enable: Signal<Out, bool>,
    pub write_index: Signal<Out, BramIndex>,
    pub write_data: Signal<Out, BramWord>,
    /// The slot's new root, valid in stage 1 (insert: from stage 0; replace: now).
    pub max: Signal<Out, HeapKey>,
    /// This stage's level, and whether it exists (a replace's children are there).
    level: Constant<Bits<8>>,
    has_children: Constant<bool>,
    /// Where a node's pair is: slot << shift | (n >> 1) & mask, for this level
    /// (`own_*`, an insert's node) and the one above (`parent_*`, a replace's);
    /// a node's children's pair: slot << level | n & child_mask.
    own_shift: Constant<Bits<8>>,
    own_mask: Constant<HeapPos>,
    parent_shift: Constant<Bits<8>>,
    parent_mask: Constant<HeapPos>,
    child_mask: Constant<HeapPos>,
    low_half: Constant<BramWord>,
    high_half: Constant<BramWord>,
    /// `op.node` (a signal: Verilog-2005 cannot index a bit of a struct field's
    /// slice).
    node: Signal<Local, HeapPos>,
    node_pair: Signal<Local, BramIndex>,
    parent_pair: Signal<Local, BramIndex>,
    cur: Signal<Local, HeapKey>,
    kept: Signal<Local, HeapKey>,
    left: Signal<Local, HeapKey>,
    right: Signal<Local, HeapKey>,
    /// The right child is the larger (and exists); each child exceeds the
    /// carried key; the larger child does.
    right_wins: Signal<Local, bool>,
    left_above: Signal<Local, bool>,
    right_above: Signal<Local, bool>,
    bigger_above: Signal<Local, bool>,
    bigger: Signal<Local, HeapKey>,
    bigger_pos: Signal<Local, HeapPos>,
    moves_up: Signal<Local, bool>,
    settled: Signal<Local, HeapKey>,
    child: Signal<Local, HeapPos>,
}

/// Pair-index bits of level `l` (`2^(l−1)` pairs; the root's pair is alone).
fn pair_mask(l: usize) -> u64 {
    if l == 0 {
        0
    } else {
        (1u64 << (l - 1)) - 1
    }
}

impl HeapStage {
    /// Stage `level` (0..=levels) of a heap of `levels` levels; stage `levels`
    /// only writes the last level.
    pub fn new(level: usize, levels: usize) -> Self {
        HeapStage {
            op: Default::default(),
            data: Default::default(),
            out_op: Default::default(),
            read_index: Default::default(),
            write_enable: Default::default(),
            write_index: Default::default(),
            write_data: Default::default(),
            max: Default::default(),
            level: Constant::new((level as u64).into()),
            has_children: Constant::new(level < levels),
            own_shift: Constant::new((level.saturating_sub(1) as u64).into()),
            own_mask: Constant::new(pair_mask(level).into()),
            parent_shift: Constant::new((level.saturating_sub(2) as u64).into()),
            parent_mask: Constant::new(pair_mask(level.saturating_sub(1)).into()),
            child_mask: Constant::new(pair_mask(level + 1).into()),
            low_half: Constant::new(0xFFFF_FFFFu64.into()),
            high_half: Constant::new(0xFFFF_FFFF_0000_0000u64.into()),
            node: Default::default(),
            node_pair: Default::default(),
            parent_pair: Default::default(),
            cur: Default::default(),
            kept: Default::default(),
            left: Default::default(),
            right: Default::default(),
            right_wins: Default::default(),
            left_above: Default::default(),
            right_above: Default::default(),
            bigger_above: Default::default(),
            bigger: Default::default(),
            bigger_pos: Default::default(),
            moves_up: Default::default(),
            settled: Default::default(),
            child: Default::default(),
        }
    }
}

impl Logic for HeapStage {
    #[hdl_gen]
    fn update(&mut self) {
        self.out_op.next = self.op.val();
        self.out_op.next.write = false;
        self.write_enable.next = false;
        self.write_index.next = self.op.val().write_index;
        self.write_data.next = self.op.val().write_pair;
        self.max.next = self.op.val().root;
        self.node.next = self.op.val().node;
        self.node_pair.next = (bit_cast::<16, 8>(self.op.val().slot) << self.own_shift.val())
            | ((self.op.val().node >> 1) & self.own_mask.val());
        self.parent_pair.next = (bit_cast::<16, 8>(self.op.val().slot) << self.parent_shift.val())
            | ((self.op.val().node >> 1) & self.parent_mask.val());
        // The key of this stage's node (insert) in the pair read for it.
        self.left.next = bit_cast::<32, 64>(self.data.val());
        self.right.next = bit_cast::<32, 64>(self.data.val() >> 32);
        if self.node.val().get_bit(0) {
            self.cur.next = self.right.val();
        } else {
            self.cur.next = self.left.val();
        }
        // The larger child (replace): the pair read is the node's two children.
        // The three comparisons side by side, then selected: the larger child
        // against the carried key would be a second comparison behind the first,
        // between the level's BlockRAM read and the next level's address and this
        // level's write.
        self.right_wins.next = (((self.op.val().node << 1) | 1) <= self.op.val().size)
            && (self.right.val() > self.left.val());
        self.left_above.next = self.left.val() > self.op.val().key;
        self.right_above.next = self.right.val() > self.op.val().key;
        self.bigger.next = self.left.val();
        self.bigger_pos.next = self.op.val().node << 1;
        self.bigger_above.next = self.left_above.val();
        if self.right_wins.val() {
            self.bigger.next = self.right.val();
            self.bigger_pos.next = (self.op.val().node << 1) | 1;
            self.bigger_above.next = self.right_above.val();
        }
        self.moves_up.next = self.has_children.val()
            && ((self.op.val().node << 1) <= self.op.val().size)
            && self.bigger_above.val();
        self.kept.next = self.op.val().key;
        self.settled.next = self.op.val().key;
        self.child.next = self.op.val().node;
        if self.op.val().valid && (!self.op.val().done) && self.op.val().replace {
            // Stage 0 only issues the read of the root's children.
            if self.level.val() != 0 {
                if self.moves_up.val() {
                    self.settled.next = self.bigger.val();
                }
                // The parent's pair (read by the previous stage) with the parent's
                // half set to what settles there.
                self.write_enable.next = true;
                self.write_index.next = self.parent_pair.val();
                if self.node.val().get_bit(0) {
                    self.write_data.next = (self.op.val().pair & self.low_half.val())
                        | (bit_cast::<64, 32>(self.settled.val()) << 32);
                } else {
                    self.write_data.next = (self.op.val().pair & self.high_half.val())
                        | bit_cast::<64, 32>(self.settled.val());
                }
                self.max.next = self.settled.val();
                self.out_op.next.done = !self.moves_up.val();
                self.out_op.next.node = self.bigger_pos.val();
                self.child.next = self.bigger_pos.val();
            }
            self.out_op.next.pair = self.data.val();
        }
        if self.op.val().valid && (!self.op.val().replace) {
            // Insert: the write this operation decided in the previous stage.
            self.write_enable.next = self.op.val().write;
            if !self.op.val().done {
                // The larger key stays on the path, the smaller goes on down.
                if self.op.val().shift == 0 {
                    self.out_op.next.done = true;
                } else if self.op.val().key > self.cur.val() {
                    self.out_op.next.key = self.cur.val();
                } else {
                    self.kept.next = self.cur.val();
                }
                if self.level.val() == 0 {
                    self.out_op.next.root = self.kept.val();
                }
                // Written by the next stage: this node's pair with its half set.
                self.out_op.next.write = true;
                self.out_op.next.write_index = self.node_pair.val();
                if self.node.val().get_bit(0) {
                    self.out_op.next.write_pair = (self.data.val() & self.low_half.val())
                        | (bit_cast::<64, 32>(self.kept.val()) << 32);
                } else {
                    self.out_op.next.write_pair = (self.data.val() & self.high_half.val())
                        | bit_cast::<64, 32>(self.kept.val());
                }
                self.out_op.next.shift = self.op.val().shift - 1;
                self.out_op.next.node = (self.op.val().node << 1)
                    | ((self.op.val().size >> (self.op.val().shift - 1)) & 1);
            }
        }
        // The next level's pair: the children of `child` (the next stage's pair).
        self.read_index.next = (bit_cast::<16, 8>(self.op.val().slot) << self.level.val())
            | (self.child.val() & self.child_mask.val());
    }
}
