//! HeapStage: one level of the [`FoundHeap`](crate::hw::barrel::found_heap::FoundHeap)'s
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
//! level `s − 1`. Every level is read by one stage and written by one stage, so
//! operations of different slots follow each other every cycle.
//!
//! Why the write is always one stage late, for both operations: the pair an
//! operation writes is always the level `s − 1` pair it read in stage `s − 1`
//! (carried in [`HeapOp::pair`]) with one half changed — an insert's to the key it
//! kept there, a replace's to what settles on its node, known only once its
//! children are compared here. So the stage carries one pair and one kept key,
//! and the write's mux is shared: the pipeline registers and the muxes, not the
//! comparators, are most of a stage's logic.

use crate::hw::primitives::block_ram::{BramIndex, BramWord};
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
    /// The operation has settled: it passes the remaining stages without effect
    /// (an insert still writes what it kept in the stage before).
    pub done: bool,
    pub slot: Bits<8>,
    /// The key carried down.
    pub key: HeapKey,
    /// Insert: the position to fill (the size after the insert). Replace: the size.
    pub size: HeapPos,
    /// Insert: levels left to the position to fill (0: this stage's node).
    pub shift: Bits<8>,
    /// Insert: the rest of the path to the position, the next step (0 left, 1
    /// right) in the top bit.
    pub path: HeapPos,
    /// Insert: this stage's node. Replace: the node whose children this stage
    /// holds (the node the carried key sits on).
    pub node: HeapPos,
    /// Insert: the previous stage decided a write (its node keeps `kept`).
    pub write: bool,
    /// Insert: the key the previous stage kept at its node (after stage 0: the
    /// new root).
    pub kept: HeapKey,
    /// The level `s − 1` pair the previous stage read, written back by this stage
    /// with one half changed.
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
    /// The slot's new root, valid in stage 1 (insert: kept by stage 0; replace:
    /// what settles on the root now).
    pub max: Signal<Out, HeapKey>,
    /// Whether this is stage 0 (it holds the root's pair and writes nothing), and
    /// whether this stage's level exists (a replace's children are there).
    first: Constant<bool>,
    has_children: Constant<bool>,
    /// Where a node's pair is: slot << shift | (n >> 1) & mask, for the level above
    /// (`parent_*`, the pair this stage writes); a node's children's pair: slot <<
    /// level | n & child_mask.
    level: Constant<Bits<8>>,
    parent_shift: Constant<Bits<8>>,
    parent_mask: Constant<HeapPos>,
    child_mask: Constant<HeapPos>,
    low_half: Constant<BramWord>,
    high_half: Constant<BramWord>,
    /// The node whose half of `op.pair` this stage writes (a signal:
    /// Verilog-2005 cannot index a bit of a struct field's slice), and `op.node`.
    written: Signal<Local, HeapPos>,
    node: Signal<Local, HeapPos>,
    path: Signal<Local, HeapPos>,
    left: Signal<Local, HeapKey>,
    right: Signal<Local, HeapKey>,
    /// The right child is the larger (and exists); each child exceeds the
    /// carried key; the larger child does.
    right_wins: Signal<Local, bool>,
    left_above: Signal<Local, bool>,
    right_above: Signal<Local, bool>,
    bigger_above: Signal<Local, bool>,
    bigger: Signal<Local, HeapKey>,
    /// Insert: the carried key exceeds this node's (it stays, the node's goes on).
    key_above: Signal<Local, bool>,
    kept: Signal<Local, HeapKey>,
    /// Replace: what settles on `op.node` (the larger child moving up, or the key).
    settled: Signal<Local, HeapKey>,
    /// The value written into the written node's half.
    value: Signal<Local, HeapKey>,
    moves_up: Signal<Local, bool>,
    /// Insert: this node's key; the operation is still on its way down.
    cur: Signal<Local, HeapKey>,
    walks: Signal<Local, bool>,
    /// The node the operation moves to, and whose children's pair is read next.
    next_node: Signal<Local, HeapPos>,
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
            first: Constant::new(level == 0),
            has_children: Constant::new(level < levels),
            level: Constant::new((level as u64).into()),
            parent_shift: Constant::new((level.saturating_sub(2) as u64).into()),
            parent_mask: Constant::new(pair_mask(level.saturating_sub(1)).into()),
            child_mask: Constant::new(pair_mask(level + 1).into()),
            low_half: Constant::new(0xFFFF_FFFFu64.into()),
            high_half: Constant::new(0xFFFF_FFFF_0000_0000u64.into()),
            written: Default::default(),
            node: Default::default(),
            path: Default::default(),
            left: Default::default(),
            right: Default::default(),
            right_wins: Default::default(),
            left_above: Default::default(),
            right_above: Default::default(),
            bigger_above: Default::default(),
            bigger: Default::default(),
            key_above: Default::default(),
            kept: Default::default(),
            settled: Default::default(),
            value: Default::default(),
            moves_up: Default::default(),
            cur: Default::default(),
            walks: Default::default(),
            next_node: Default::default(),
            child: Default::default(),
        }
    }
}

impl Logic for HeapStage {
    #[hdl_gen]
    fn update(&mut self) {
        self.node.next = self.op.val().node;
        self.path.next = self.op.val().path;
        self.left.next = bit_cast::<32, 64>(self.data.val());
        self.right.next = bit_cast::<32, 64>(self.data.val() >> 32);
        // Insert: this node's key, its half of the pair.
        self.cur.next = self.left.val();
        if self.node.val().get_bit(0) {
            self.cur.next = self.right.val();
        }
        // The three comparisons side by side, then selected: the larger child
        // against the carried key would be a second comparison behind the first,
        // between the level's BlockRAM read and the next level's address.
        self.right_wins.next = (((self.op.val().node << 1) | 1) <= self.op.val().size)
            && (self.right.val() > self.left.val());
        self.left_above.next = self.left.val() > self.op.val().key;
        self.right_above.next = self.right.val() > self.op.val().key;
        self.bigger.next = self.left.val();
        self.bigger_above.next = self.left_above.val();
        if self.right_wins.val() {
            self.bigger.next = self.right.val();
            self.bigger_above.next = self.right_above.val();
        }
        // Replace: the larger child moves up if it exceeds the key, else the key
        // settles here.
        self.moves_up.next = self.has_children.val()
            && ((self.op.val().node << 1) <= self.op.val().size)
            && self.bigger_above.val();
        self.settled.next = self.op.val().key;
        if self.moves_up.val() {
            self.settled.next = self.bigger.val();
        }
        // Insert: the larger of the node's key and the carried key stays, the
        // smaller goes on down (the same comparisons: keys of one list are
        // distinct, and of two equal keys either may stay).
        self.key_above.next = !self.left_above.val();
        if self.node.val().get_bit(0) {
            self.key_above.next = !self.right_above.val();
        }
        self.walks.next = !self.op.val().replace && (self.op.val().shift != 0);
        self.kept.next = self.op.val().key;
        if self.walks.val() && !self.key_above.val() {
            self.kept.next = self.cur.val();
        }
        // The write of level s − 1: the pair read there, one half changed.
        self.written.next = self.op.val().node;
        self.value.next = self.settled.val();
        if !self.op.val().replace {
            self.written.next = self.op.val().node >> 1;
            self.value.next = self.op.val().kept;
        }
        self.write_index.next = (bit_cast::<16, 8>(self.op.val().slot) << self.parent_shift.val())
            | ((self.written.val() >> 1) & self.parent_mask.val());
        self.write_data.next =
            (self.op.val().pair & self.high_half.val()) | bit_cast::<64, 32>(self.value.val());
        if self.written.val().get_bit(0) {
            self.write_data.next = (self.op.val().pair & self.low_half.val())
                | (bit_cast::<64, 32>(self.value.val()) << 32);
        }
        self.max.next = self.value.val();
        // The step down: the larger child (replace) or the path's next bit (insert).
        self.next_node.next = self.op.val().node << 1;
        if (self.op.val().replace && self.right_wins.val())
            || (!self.op.val().replace && self.path.val().get_bit(15))
        {
            self.next_node.next = (self.op.val().node << 1) | 1;
        }
        self.out_op.next = self.op.val();
        self.out_op.next.write = false;
        self.out_op.next.pair = self.data.val();
        if self.walks.val() && self.key_above.val() {
            self.out_op.next.key = self.cur.val();
        }
        self.write_enable.next = false;
        self.child.next = self.op.val().node;
        if self.op.val().valid && self.op.val().replace && !self.op.val().done && !self.first.val()
        {
            // Stage 0 only issues the read of the root's children.
            self.write_enable.next = true;
            self.out_op.next.done = !self.moves_up.val();
            self.out_op.next.node = self.next_node.val();
            self.child.next = self.next_node.val();
        }
        if self.op.val().valid && !self.op.val().replace {
            self.write_enable.next = self.op.val().write && !self.first.val();
            if !self.op.val().done {
                self.out_op.next.done = self.op.val().shift == 0;
                self.out_op.next.write = true;
                self.out_op.next.kept = self.kept.val();
                self.out_op.next.shift = self.op.val().shift - 1;
                self.out_op.next.path = self.op.val().path << 1;
                self.out_op.next.node = self.next_node.val();
            }
        }
        // The next level's pair: the children of `child` (the next stage's pair).
        self.read_index.next = (bit_cast::<16, 8>(self.op.val().slot) << self.level.val())
            | (self.child.val() & self.child_mask.val());
    }
}
