//! The measured points: the streams (map × k), their query orders, and every
//! point of the report run through the trace model (`trace`) or the cycle model
//! (`sim`) in parallel, each checked to have counted every read exactly once.

use super::layout::BlockLayout;
use super::memories::Memory;
use super::sim::{self, Machine};
use super::trace::{replay, Counts, Replay};
use crate::banking::order::QueryOrder;
use crate::banking::stream::ImageStream;
use crate::banking::sweep::{BARREL_LOOP, INTERCONNECT_CYCLES};
use rayon::prelude::*;

/// A barrel slot's loop with the interconnect's registers (the bank model's):
/// a cache hit comes back as a read of the banked store does.
pub const LOOP: u64 = BARREL_LOOP + INTERCONNECT_CYCLES;

/// One measured read stream: a map, k, and its queries in every order.
pub struct Stream {
    /// "1M emitted, k = 32".
    pub label: String,
    pub emitted: usize,
    pub k: usize,
    pub image: ImageStream,
    orders: Vec<(QueryOrder, Vec<usize>)>,
}

impl Stream {
    pub fn new(emitted: usize, k: usize, image: ImageStream) -> Self {
        let bits = image.tree.layout.bits.into_iter().max().unwrap_or(1);
        let orders = QueryOrder::ALL
            .iter()
            .map(|&o| (o, o.permutation(&image.queries, image.width, bits)))
            .collect();
        Stream {
            label: format!("{} emitted, k = {k}", count(emitted)),
            emitted,
            k,
            image,
            orders,
        }
    }

    /// H, the tree's levels.
    pub fn levels(&self) -> u32 {
        self.image.tree.address_bits()
    }

    pub fn order(&self, o: QueryOrder) -> &[usize] {
        &self.orders.iter().find(|(x, _)| *x == o).unwrap().1
    }

    pub fn queries(&self) -> usize {
        self.image.queries.len()
    }

    pub fn reads_per_query(&self) -> f64 {
        self.image.total_reads() as f64 / self.queries().max(1) as f64
    }

    /// The layout of this map for `m`'s memory: T on-chip levels, s a block.
    pub fn layout(&self, m: &Memory, on_chip: u32, block_levels: u32) -> BlockLayout {
        let word_bytes = self.image.tree.layout.word_bits().div_ceil(8);
        BlockLayout::new(
            self.levels(),
            on_chip,
            block_levels,
            word_bytes,
            m.burst_bytes,
        )
    }
}

/// 1000000 → "1M", 100000 → "100K", 3000 → "3K", 500 → "500".
pub fn count(n: usize) -> String {
    match n {
        n if n >= 1_000_000 && n % 100_000 == 0 => {
            format!("{}M", n as f64 / 1e6).replace(".0M", "M")
        }
        n if n >= 1_000 && n % 1_000 == 0 => format!("{}K", n / 1_000),
        n => n.to_string(),
    }
}

/// The trace model on every point (a replay and a query order).
pub fn replays(s: &Stream, points: &[(Replay, QueryOrder)]) -> Vec<Counts> {
    let total = s.image.total_reads();
    points
        .par_iter()
        .map(|(r, o)| {
            let c = replay(r, &s.image.reads, s.order(*o));
            assert_eq!(c.reads, total, "a read lost or counted twice");
            assert_eq!(c.reads, c.on_chip + c.hits + c.misses);
            c
        })
        .collect()
}

/// The cycle model on every point.
pub fn timed(s: &Stream, points: &[(Machine, QueryOrder)]) -> Vec<sim::Measured> {
    let total = s.image.total_reads();
    points
        .par_iter()
        .map(|(m, o)| {
            let r = sim::run(m, &s.image.reads, s.order(*o));
            assert_eq!(r.reads, total, "a read lost or counted twice");
            assert_eq!(r.reads, r.on_chip + r.hits + r.misses + r.merged);
            r
        })
        .collect()
}
