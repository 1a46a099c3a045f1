//! PriorityEncoder: the lowest set bit of a mask, one-hot and as an index — the
//! `priority_encoder.v` of verilog-axis, written once for every place that picks
//! "the lowest": a port's free QueryModule or slot ([`FreePick`]), the finished
//! query read out next ([`ResultReadout`]), the MaxFinder's slot among ties (paper
//! §4.4: the software search replaces the lowest list slot holding the maximum)
//! and a QueryModule's one-hot insertion slot as a LUT-RAM index.
//!
//! rust-hdl's `#[hdl_gen]` cannot call functions, so the rule is a block: the
//! lowest set bit is `mask & (!mask + 1)` (one carry chain), the index the OR of
//! the indices of the bits set in that one-hot word. Built with
//! [`PriorityEncoder::one_hot`], the mask is known to have at most one bit set and
//! only the index is encoded (no carry chain).
//!
//! [`FreePick`]: crate::hw::primitives::free_pick::FreePick
//! [`ResultReadout`]: crate::hw::modules::result_readout::ResultReadout

use rust_hdl::prelude::*;

/// An index out of a priority encoder (module, slot or found-list entry: < 64).
pub type EncodedIndex = Bits<8>;

#[derive(LogicBlock)]
pub struct PriorityEncoder<const N: usize> {
    pub mask: Signal<In, Bits<N>>,
    /// The lowest set bit of `mask` (zero if none).
    pub lowest: Signal<Out, Bits<N>>,
    /// Its index (0 if none), over the first `width` bits.
    pub index: Signal<Out, EncodedIndex>,
    /// Isolate the lowest bit (else `mask` is already one-hot).
    isolate: Constant<bool>,
    bit_index: Vec<Constant<EncodedIndex>>,
}

impl<const N: usize> PriorityEncoder<N> {
    fn build(width: usize, isolate: bool) -> Self {
        assert!((1..=N.min(64)).contains(&width));
        PriorityEncoder {
            mask: Default::default(),
            lowest: Default::default(),
            index: Default::default(),
            isolate: Constant::new(isolate),
            bit_index: (0..width)
                .map(|i| Constant::new(EncodedIndex::from(i as u64)))
                .collect(),
        }
    }

    /// The lowest of the first `width` bits of any mask.
    pub fn lowest(width: usize) -> Self {
        Self::build(width, true)
    }

    /// The index of a one-hot (or zero) mask of `width` bits.
    pub fn one_hot(width: usize) -> Self {
        Self::build(width, false)
    }
}

impl<const N: usize> Logic for PriorityEncoder<N> {
    #[hdl_gen]
    fn update(&mut self) {
        if self.isolate.val() {
            self.lowest.next = self.mask.val() & ((!self.mask.val()) + 1);
        } else {
            self.lowest.next = self.mask.val();
        }
        self.index.next = 0.into();
        for i in 0..self.bit_index.len() {
            if self.lowest.val().get_bit(i) {
                self.index.next = self.index.val() | self.bit_index[i].val();
            }
        }
    }
}
