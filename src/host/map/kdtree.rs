//! The photon kd-tree of paper §2.2, stored as a 1-based heap (children of node i at
//! 2i and 2i+1) and left-balanced, so any photon count N >= 1 fills addresses 1..=N
//! with no padding entry that a search could ever return.
//!
//! Build: split on the axis of largest extent; the median photon becomes the node
//! and records its axis; smaller photons go left, larger right. "Median" is the
//! position that keeps the heap left-balanced, and ties on the split coordinate are
//! broken by photon index, so left <= node <= right holds on the split axis and the
//! build is deterministic.

use crate::host::map::quantize::Quantizer;
use crate::host::map::scalar::Scalar;
use crate::hw::config::photon_word::{PhotonLayout, TreeImage};

/// A kd-tree over points with coordinates of type `C`.
#[derive(Clone, Debug)]
pub struct KdTree<C> {
    /// Node coordinates by heap address; index 0 is unused.
    pub coords: Vec<[C; 3]>,
    /// Split axis by heap address; index 0 is unused.
    pub axis: Vec<u8>,
    /// Original point index by heap address; index 0 is unused.
    pub perm: Vec<u32>,
}

impl<C: Scalar> KdTree<C> {
    /// Build the left-balanced tree over `points` (must be non-empty).
    pub fn build(points: &[[C; 3]]) -> Self {
        assert!(!points.is_empty(), "kd-tree over an empty point set");
        let n = points.len();
        let mut tree = KdTree {
            coords: vec![points[0]; n + 1],
            axis: vec![0; n + 1],
            perm: vec![0; n + 1],
        };
        let mut idx: Vec<u32> = (0..n as u32).collect();
        tree.build_rec(points, &mut idx, 1);
        tree
    }

    fn build_rec(&mut self, pts: &[[C; 3]], idx: &mut [u32], addr: usize) {
        if idx.is_empty() {
            return;
        }
        let ax = largest_extent_axis(pts, idx);
        let left = left_subtree_size(idx.len());
        idx.select_nth_unstable_by(left, |&a, &b| {
            C::total_cmp(pts[a as usize][ax], pts[b as usize][ax]).then(a.cmp(&b))
        });
        let m = idx[left] as usize;
        self.coords[addr] = pts[m];
        self.axis[addr] = ax as u8;
        self.perm[addr] = m as u32;
        let (l, r) = idx.split_at_mut(left);
        self.build_rec(pts, l, 2 * addr);
        self.build_rec(pts, &mut r[1..], 2 * addr + 1);
    }

    /// Number of points (= the highest heap address).
    pub fn len(&self) -> usize {
        self.coords.len() - 1
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// The axis over which `idx`'s points spread furthest (ties: the lowest axis).
fn largest_extent_axis<C: Scalar>(pts: &[[C; 3]], idx: &[u32]) -> usize {
    let p0 = pts[idx[0] as usize];
    let (mut lo, mut hi) = (p0, p0);
    for &i in idx {
        let p = pts[i as usize];
        for a in 0..3 {
            if C::total_cmp(p[a], lo[a]).is_lt() {
                lo[a] = p[a];
            }
            if C::total_cmp(p[a], hi[a]).is_gt() {
                hi[a] = p[a];
            }
        }
    }
    let ext = [0, 1, 2].map(|a| C::extent(lo[a], hi[a]));
    let mut best = 0;
    for a in 1..3 {
        if ext[a] > ext[best] {
            best = a;
        }
    }
    best
}

/// Size of the left subtree of a left-balanced (complete) binary tree of n nodes.
pub fn left_subtree_size(n: usize) -> usize {
    if n <= 1 {
        return 0;
    }
    // Levels 0..h-1 are full (2^h − 1 nodes); the last level holds the rest,
    // filled from the left.
    let h = usize::BITS - 1 - (n + 1).leading_zeros(); // 2^h − 1 <= n < 2^(h+1) − 1
    let full = 1usize << h;
    let last = n - (full - 1);
    (full / 2 - 1) + last.min(full / 2)
}

/// The tree image the hardware TreeModule loads: one packed photon word per heap
/// address (address 0 unused), plus the address → photon-index table the host keeps
/// (the FPGA returns tree addresses, never photon data; paper §4).
#[derive(Clone, Debug)]
pub struct PackedTree {
    pub layout: PhotonLayout,
    /// Photon words by heap address; `words[0]` is unused (zero).
    pub words: Vec<u64>,
    /// Original photon index by heap address; `perm[0]` is unused.
    pub perm: Vec<u32>,
    shifts: [u32; 4],
    masks: [u64; 3],
}

impl PackedTree {
    /// Quantize `points` with `quant`, build the tree and pack it.
    pub fn build(points: &[crate::host::map::quantize::Point], quant: &Quantizer) -> Self {
        let q: Vec<[u32; 3]> = points.iter().map(|&p| quant.quantize(p)).collect();
        Self::from_tree(&KdTree::build(&q), quant.layout)
    }

    /// Pack an integer tree whose coordinates fit `layout`.
    pub fn from_tree(tree: &KdTree<u32>, layout: PhotonLayout) -> Self {
        // Address 0 is unused: the heap is 1-based.
        let words = (0..tree.coords.len())
            .map(|a| match a {
                0 => 0,
                _ => layout.pack(tree.coords[a], tree.axis[a]),
            })
            .collect();
        Self::from_words(layout, words, tree.perm.clone())
    }

    /// Wrap already-packed words (address 0 unused).
    pub fn from_words(layout: PhotonLayout, words: Vec<u64>, perm: Vec<u32>) -> Self {
        let shifts = [
            layout.offset(0),
            layout.offset(1),
            layout.offset(2),
            layout.axis_offset(),
        ];
        let masks = [0, 1, 2].map(|a| layout.coord_max(a) as u64);
        PackedTree {
            layout,
            words,
            perm,
            shifts,
            masks,
        }
    }

    /// Number of photons N (= the highest heap address).
    pub fn len(&self) -> usize {
        self.words.len() - 1
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Tree height = address width H: addresses 1..=N fit in H bits, and the
    /// TreeModule holds 2^H words.
    /// The packed words as the hardware loads them.
    pub fn image(&self) -> TreeImage<'_> {
        TreeImage {
            layout: self.layout,
            words: &self.words,
        }
    }

    pub fn address_bits(&self) -> u32 {
        usize::BITS - self.len().leading_zeros()
    }

    /// Decode the photon at heap address `addr`.
    #[inline]
    pub fn node(&self, addr: usize) -> ([u32; 3], u8) {
        let w = self.words[addr];
        (
            [
                ((w >> self.shifts[0]) & self.masks[0]) as u32,
                ((w >> self.shifts[1]) & self.masks[1]) as u32,
                ((w >> self.shifts[2]) & self.masks[2]) as u32,
            ],
            ((w >> self.shifts[3]) & 3) as u8,
        )
    }
}
