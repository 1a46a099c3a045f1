//! The order in which the host sends an image's queries. Coherent orders put
//! queries that read the same part of the tree close together in time, which a
//! cache wants (Heinzle et al., Graphics Hardware 2008; Steinhurst et al., TVCG
//! 2008, with a Hilbert-ordered query stream) but which may also send several
//! datapaths to the same bank at once; the bank model measures which wins.

use super::stream::ImageQuery;
use rand::seq::SliceRandom;
use rand::SeedableRng;
use rand_pcg::Pcg64Mcg;

/// A query order.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum QueryOrder {
    /// The renderer's: pixel by pixel, row by row, a pixel's samples together.
    Raster,
    /// 8 × 8-pixel tiles, tiles and the pixels inside them in raster order.
    Tile,
    /// Z-order (Morton) of the queries' grid points.
    Morton,
    /// Hilbert order of the queries' grid points.
    Hilbert,
    /// A fixed pseudo-random shuffle: no coherence at all.
    Shuffled,
}

impl QueryOrder {
    pub const ALL: [QueryOrder; 5] = [
        QueryOrder::Raster,
        QueryOrder::Tile,
        QueryOrder::Morton,
        QueryOrder::Hilbert,
        QueryOrder::Shuffled,
    ];

    pub fn name(self) -> &'static str {
        match self {
            QueryOrder::Raster => "raster",
            QueryOrder::Tile => "tile 8x8",
            QueryOrder::Morton => "Morton",
            QueryOrder::Hilbert => "Hilbert",
            QueryOrder::Shuffled => "shuffled",
        }
    }

    /// The queries' indices in this order (a permutation of `0..queries.len()`;
    /// ties keep the renderer's order). `bits`: the grid's coordinate bits.
    pub fn permutation(self, queries: &[ImageQuery], width: u32, bits: u32) -> Vec<usize> {
        let mut idx: Vec<usize> = (0..queries.len()).collect();
        match self {
            QueryOrder::Raster => {}
            QueryOrder::Tile => idx.sort_by_key(|&i| {
                let (x, y) = (queries[i].pixel % width, queries[i].pixel / width);
                ((y / 8) * width.div_ceil(8) + x / 8, queries[i].pixel)
            }),
            QueryOrder::Morton => idx.sort_by_key(|&i| morton(queries[i].coords, bits)),
            QueryOrder::Hilbert => idx.sort_by_key(|&i| hilbert(queries[i].coords, bits)),
            QueryOrder::Shuffled => idx.shuffle(&mut Pcg64Mcg::seed_from_u64(0x5eed)),
        }
        idx
    }
}

/// The Morton (Z-order) key of a point with `bits`-bit coordinates: bits
/// interleaved from the most significant, x first.
pub fn morton(c: [u32; 3], bits: u32) -> u64 {
    let mut key = 0u64;
    for b in (0..bits).rev() {
        for v in c {
            key = (key << 1) | ((v >> b) & 1) as u64;
        }
    }
    key
}

/// The Hilbert key of a point with `bits`-bit coordinates (Skilling, "Programming
/// the Hilbert curve", AIP Conf. Proc. 707, 2004: axes to transposed index, then
/// the bits interleaved as for [`morton`]).
pub fn hilbert(c: [u32; 3], bits: u32) -> u64 {
    let mut x = c;
    if bits == 0 {
        return 0;
    }
    let m = 1u32 << (bits - 1);
    let mut q = m;
    while q > 1 {
        let p = q - 1;
        for i in 0..3 {
            if x[i] & q != 0 {
                x[0] ^= p;
            } else {
                let t = (x[0] ^ x[i]) & p;
                x[0] ^= t;
                x[i] ^= t;
            }
        }
        q >>= 1;
    }
    for i in 1..3 {
        x[i] ^= x[i - 1];
    }
    let mut t = 0;
    let mut q = m;
    while q > 1 {
        if x[2] & q != 0 {
            t ^= q - 1;
        }
        q >>= 1;
    }
    for v in &mut x {
        *v ^= t;
    }
    morton(x, bits)
}

/// The order in which the queries go to the core (and to kiddo): the workload's
/// own, or sorted along a space-filling curve of their grid points, which a cache
/// of the map rewards (docs/MEMORY.md).
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum StreamOrder {
    /// As the workload makes them (an image's in pixel order).
    Given,
    /// Z-order of the grid points.
    Morton,
    /// Hilbert order of the grid points.
    Hilbert,
}

/// Put `queries` (grid points of `bits`-bit coordinates) in `order`; ties keep
/// the given order.
pub fn order_queries(queries: &mut [[u32; 3]], order: StreamOrder, bits: u32) {
    match order {
        StreamOrder::Given => {}
        StreamOrder::Morton => queries.sort_by_key(|&c| morton(c, bits)),
        StreamOrder::Hilbert => queries.sort_by_key(|&c| hilbert(c, bits)),
    }
}
