//! MuxTrees: M multiplexers side by side, each one of 2^n inputs by its own binary
//! index, built as a balanced tree of 2:1 multiplexers (level `l` switched by bit
//! `l − 1` of the index). The bank crossbar's wide selections (each bank port's row
//! from the requester it granted, each requester's word from the bank port that
//! answered it) are made of these. Written as a chain of `if index == j` overrides,
//! as `#[hdl_gen]` code naturally reads, every output bit becomes a chain of one
//! 2:1 multiplexer per input that synthesis does not rebalance (about a LUT per
//! input per bit); as a tree it maps to 4:1 LUTs and the slices' wide-multiplexer
//! cells (MUXF7/MUXF8 on a Virtex-6, PFUMX/L6MUX on an ECP5), with n levels of logic
//! instead of 2^n.
//!
//! The M trees are one block, their signals in flat vectors (tree `m`'s input `i`
//! is `inputs[m * 2^n + i]`), because `#[hdl_gen]` reads only one index per
//! signal path (`self.trees[m].inputs[i]` does not translate).

use rust_hdl::prelude::*;

/// Levels a tree may have.
pub const MAX_MUX_LEVELS: u32 = 12;

#[derive(LogicBlock)]
pub struct MuxTrees<T: Synth, const I: usize> {
    /// M × 2^n inputs, tree by tree (`inputs[m * 2^n + i]`).
    pub inputs: Vec<Signal<In, T>>,
    /// Per tree: its I-bit index (bits above n ignored) and
    /// `inputs[m * 2^n + index]`.
    pub index: Vec<Signal<In, Bits<I>>>,
    pub output: Vec<Signal<Out, T>>,
    /// Level l: M × 2^(n−l) 2:1 multiplexers switched by index bit l − 1, tree by
    /// tree (no nested arrays in `#[hdl_gen]`: a field per level, those above n
    /// empty).
    l1: Vec<Signal<Local, T>>,
    l2: Vec<Signal<Local, T>>,
    l3: Vec<Signal<Local, T>>,
    l4: Vec<Signal<Local, T>>,
    l5: Vec<Signal<Local, T>>,
    l6: Vec<Signal<Local, T>>,
    l7: Vec<Signal<Local, T>>,
    l8: Vec<Signal<Local, T>>,
    l9: Vec<Signal<Local, T>>,
    l10: Vec<Signal<Local, T>>,
    l11: Vec<Signal<Local, T>>,
    l12: Vec<Signal<Local, T>>,
}

impl<T: Synth, const I: usize> MuxTrees<T, I> {
    /// `trees` (1..) trees of `inputs` inputs each, rounded up to a power of two
    /// (1..=2^12, at most 2^I: an I-bit index).
    pub fn new(trees: usize, inputs: usize) -> Self {
        let most = 1usize << MAX_MUX_LEVELS.min(I as u32);
        assert!(trees >= 1 && (1..=most).contains(&inputs));
        let leaves = inputs.next_power_of_two();
        let many =
            |n: usize| -> Vec<Signal<Local, T>> { (0..n).map(|_| Default::default()).collect() };
        let level = |l: u32| many(trees * (leaves >> l.min(usize::BITS - 1)));
        MuxTrees {
            inputs: (0..trees * leaves).map(|_| Default::default()).collect(),
            index: (0..trees).map(|_| Default::default()).collect(),
            output: (0..trees).map(|_| Default::default()).collect(),
            l1: level(1),
            l2: level(2),
            l3: level(3),
            l4: level(4),
            l5: level(5),
            l6: level(6),
            l7: level(7),
            l8: level(8),
            l9: level(9),
            l10: level(10),
            l11: level(11),
            l12: level(12),
        }
    }

    /// Inputs per tree (2^n).
    pub fn leaves(&self) -> usize {
        self.inputs.len() / self.output.len()
    }
}

// One loop nest per level, written once: the macro expands before `#[hdl_gen]`
// reads the function. In each nest a one-pass loop binds `w`, the level's width
// per tree, so that the flat indices are arithmetic on loop variables only (what
// rust-hdl's Verilog generator can evaluate; loop bounds are evaluated in Rust).
// A level above n is empty and its nest generates nothing.
macro_rules! mux_trees_update {
    ($(($level:ident, $below:ident, $bit:tt)),*) => {
        impl<T: Synth, const I: usize> Logic for MuxTrees<T, I> {
            #[hdl_gen]
            fn update(&mut self) {
                // Each level halves the candidates; the last level written holds
                // one signal per tree, the selected input (one input: no level).
                for m in 0..self.output.len() {
                    self.output[m].next = self.inputs[m].val();
                }
                $(
                    for w in (self.$level.len() / self.output.len())
                        ..(self.$level.len() / self.output.len() + 1)
                    {
                        for m in 0..self.$level.len().min(self.output.len()) {
                            for k in 0..(self.$level.len() / self.output.len()) {
                                if self.index[m].val().get_bit($bit) {
                                    self.$level[m * w + k].next =
                                        self.$below[m * w * 2 + k * 2 + 1].val();
                                } else {
                                    self.$level[m * w + k].next =
                                        self.$below[m * w * 2 + k * 2].val();
                                }
                            }
                            if w == 1 {
                                self.output[m].next = self.$level[m].val();
                            }
                        }
                    }
                )*
            }
        }
    };
}

mux_trees_update!(
    (l1, inputs, 0),
    (l2, l1, 1),
    (l3, l2, 2),
    (l4, l3, 3),
    (l5, l4, 4),
    (l6, l5, 5),
    (l7, l6, 6),
    (l8, l7, 7),
    (l9, l8, 8),
    (l10, l9, 9),
    (l11, l10, 10),
    (l12, l11, 11)
);
