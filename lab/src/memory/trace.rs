//! The functional cache model: the image's read streams interleaved as the barrel
//! datapaths issue them, and every read below the on-chip levels looked up in its
//! datapath's cache. No timing: the order of the reads is that of D datapaths each
//! reading one node a cycle from its S slots in turn (the barrel's rotation, paper
//! §4.5 multiplexing), the order the cycle model (`sim`) also produces when no
//! read waits on memory. Cheap enough to sweep layouts, sizes, associativity,
//! replacement, sharing and query orders on the whole stream; `sim` then times the
//! chosen points.

use super::cache::{Cache, CacheConfig};
use super::layout::{BlockLayout, Place};

/// Who shares a cache.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Sharing {
    /// One cache for all D datapaths.
    Shared,
    /// One cache per two datapaths (one BlockRAM port each), the capacity split.
    PerPair,
}

impl Sharing {
    pub const ALL: [Sharing; 2] = [Sharing::Shared, Sharing::PerPair];
    pub fn name(self) -> &'static str {
        match self {
            Sharing::Shared => "shared by all",
            Sharing::PerPair => "one per datapath pair",
        }
    }
    /// Caches for `datapaths` datapaths.
    pub fn caches(self, datapaths: usize) -> usize {
        match self {
            Sharing::Shared => 1,
            Sharing::PerPair => datapaths.div_ceil(2),
        }
    }
    /// The cache datapath `d` uses.
    pub fn cache_of(self, d: usize) -> usize {
        match self {
            Sharing::Shared => 0,
            Sharing::PerPair => d / 2,
        }
    }
}

/// What a replay counted.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Counts {
    pub queries: u64,
    /// Every read of every query.
    pub reads: u64,
    /// Reads of the on-chip levels.
    pub on_chip: u64,
    /// Reads below them, found in the cache / not found (each miss one burst).
    pub hits: u64,
    pub misses: u64,
}

impl Counts {
    /// Hits / reads that went to the cache.
    pub fn hit_rate(&self) -> f64 {
        self.hits as f64 / (self.hits + self.misses).max(1) as f64
    }
    /// Misses / all reads (what the cycle model's slots wait on).
    pub fn misses_per_read(&self) -> f64 {
        self.misses as f64 / self.reads.max(1) as f64
    }
    /// Memory bytes per query, `block_bytes` a miss.
    pub fn bytes_per_query(&self, block_bytes: u32) -> f64 {
        self.misses as f64 * f64::from(block_bytes) / self.queries.max(1) as f64
    }
}

/// The machine replayed: its datapaths, slots, caches.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Replay {
    pub datapaths: usize,
    pub slots: usize,
    pub layout: BlockLayout,
    /// The cache of the whole core (split evenly under [`Sharing::PerPair`]).
    pub cache: CacheConfig,
    pub sharing: Sharing,
}

impl Replay {
    /// Each cache's shape: the total lines split among the caches, each a whole
    /// number of sets.
    pub fn cache_each(&self) -> CacheConfig {
        let n = self.sharing.caches(self.datapaths);
        let ways = self.cache.ways.unwrap_or(1);
        let lines = (self.cache.lines / n / ways).max(1) * ways;
        CacheConfig {
            lines,
            ..self.cache
        }
    }
}

/// Replay every query of `reads` (per query, its heap addresses), in `order`.
/// Queries enter free slots in order; each datapath in turn issues its next
/// slot's next read.
pub fn replay(m: &Replay, reads: &[Vec<u32>], order: &[usize]) -> Counts {
    assert!(m.datapaths >= 1 && m.slots >= 1);
    let blocks = m.layout.blocks() as usize;
    let each = m.cache_each();
    let mut caches: Vec<Cache> = (0..m.sharing.caches(m.datapaths))
        .map(|_| Cache::new(each, blocks))
        .collect();
    let mut out = Counts::default();
    // Per datapath and slot: (query, next read).
    let mut slots: Vec<Vec<Option<(usize, usize)>>> = vec![vec![None; m.slots]; m.datapaths];
    let mut turn = vec![0usize; m.datapaths];
    let mut next = order.iter().copied().filter(|&q| !reads[q].is_empty());
    let mut live = 0usize;
    let mut exhausted = false;
    loop {
        for (d, dp) in slots.iter_mut().enumerate() {
            // Fill free slots with the next queries (one dispatcher, in order).
            if !exhausted {
                for s in dp.iter_mut().filter(|s| s.is_none()) {
                    match next.next() {
                        Some(q) => {
                            *s = Some((q, 0));
                            live += 1;
                            out.queries += 1;
                        }
                        None => {
                            exhausted = true;
                            break;
                        }
                    }
                }
            }
            // This datapath's read of this cycle: the next live slot in rotation.
            let n = dp.len();
            let Some(i) = (0..n).map(|j| (turn[d] + j) % n).find(|&i| dp[i].is_some()) else {
                continue;
            };
            turn[d] = (i + 1) % n;
            let (q, pos) = dp[i].unwrap();
            let a = reads[q][pos];
            out.reads += 1;
            match m.layout.place(a) {
                Place::OnChip => out.on_chip += 1,
                Place::External { block, .. } => {
                    if caches[m.sharing.cache_of(d)].access(block) {
                        out.hits += 1;
                    } else {
                        out.misses += 1;
                    }
                }
            }
            dp[i] = if pos + 1 == reads[q].len() {
                live -= 1;
                None
            } else {
                Some((q, pos + 1))
            };
        }
        if exhausted && live == 0 {
            break;
        }
    }
    out
}

/// Distinct blocks the reads of `reads` touch (a fully associative cache as large
/// as the map misses exactly once on each).
pub fn distinct_blocks(layout: &BlockLayout, reads: &[Vec<u32>]) -> u64 {
    let mut seen = vec![false; layout.blocks() as usize];
    let mut n = 0;
    for &a in reads.iter().flatten() {
        if let Place::External { block, .. } = layout.place(a) {
            if !seen[block as usize] {
                seen[block as usize] = true;
                n += 1;
            }
        }
    }
    n
}
