//! Software k-nearest-neighbour search: the reference every simulated hardware gather
//! is checked against.
//!
//! * [`brute_force`] on quantized integer coordinates is the ground truth.
//! * [`search`] is the paper's search (§2.2) on the packed tree, step for step what
//!   a hardware QueryModule does, so its found set and its photon-read count are the
//!   hardware's too.
//! * The same [`search`] over `f64` coordinates is the float accuracy baseline.
//!
//! # Traversal (shared with the hardware NextIndexModule and QueryModule)
//! Every read is a *down* visit of the photon at `address` (one TreeModule read;
//! "photons visited" counts these reads). With `a` = the photon's split axis,
//! `near` = right if q[a] >= p[a] else left, a down visit tests the photon against
//! the found list, then goes to the near child if it exists; else to the far child
//! if it exists and the axis distance is within R; else up. How the search goes up
//! is the [`Traversal`]:
//! * [`Traversal::Remember`] (default): a down visit that goes to the near child
//!   records, for its level, the axis distance and whether the far child exists
//!   ("pending"). Going up from a node to its parent reads nothing: if the parent's
//!   level is pending and its recorded axis distance is within R *as R is now*
//!   (after every insertion so far), the pending mark is cleared and the search
//!   reads the far child (the sibling of the node it came from); otherwise it climbs
//!   on. Reads per query = distance tests.
//! * [`Traversal::Reread`] (the paper's): going up reads the parent again. If we
//!   came from the near child, the far child exists and the axis distance is within
//!   R (R as at that re-read), go down into the far child; else up. State: (address,
//!   direction, came-from bit).
//! * Up from the root ends the search.
//!
//! # Boundary rules (shared with the hardware)
//! * While the list holds fewer than k photons, a photon is in range iff
//!   `d <= R0` (the initial radius is inclusive), and a subtree is pruned iff its
//!   axis distance `> R0`.
//! * Once the list holds k photons, R is the list maximum and a photon enters iff
//!   `d < R` (strict: a photon equal to the current maximum is not taken); it
//!   replaces the entry holding the maximum, the lowest list slot among ties (the
//!   MaxFinder's priority encoder); a subtree is pruned iff its axis distance `>= R`.
//! * The pruning test of a step uses R as it was when the photon was read, i.e.
//!   before that photon's own insertion (the hardware's SearchModule computes the
//!   next address in parallel with the distance), which only ever explores more.

use crate::host::map::kdtree::{KdTree, PackedTree};
pub use crate::host::map::scalar::{FloatDist, Scalar};
use crate::hw::config::core_config::ReadProfile;
use crate::hw::config::metric::Metric;
pub use crate::hw::config::traversal::Traversal;
use std::cmp::Reverse;
use std::collections::BinaryHeap;

/// Where the search reads its photons: a decoded tree or the packed words.
pub trait NodeSource<C> {
    /// Number of photons N; heap addresses run 1..=N.
    fn len(&self) -> usize;
    fn is_empty(&self) -> bool {
        self.len() == 0
    }
    /// Coordinates and split axis of the photon at `addr`.
    fn node(&self, addr: usize) -> ([C; 3], u8);
}

impl<C: Scalar> NodeSource<C> for KdTree<C> {
    fn len(&self) -> usize {
        KdTree::len(self)
    }
    #[inline]
    fn node(&self, addr: usize) -> ([C; 3], u8) {
        (self.coords[addr], self.axis[addr])
    }
}

impl NodeSource<u32> for PackedTree {
    fn len(&self) -> usize {
        PackedTree::len(self)
    }
    #[inline]
    fn node(&self, addr: usize) -> ([u32; 3], u8) {
        PackedTree::node(self, addr)
    }
}

/// The packed tree's grid coordinates widened to `i64`, for queries outside the
/// photon box (the host's exact path for them; see `gather::GridPoint`).
pub struct WideNodes<'a>(pub &'a PackedTree);

impl NodeSource<i64> for WideNodes<'_> {
    fn len(&self) -> usize {
        self.0.len()
    }
    #[inline]
    fn node(&self, addr: usize) -> ([i64; 3], u8) {
        let (c, ax) = self.0.node(addr);
        (c.map(i64::from), ax)
    }
}

/// What one search found.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Found<D> {
    /// (heap address, distance) in found-list slot order (the hardware's order).
    pub slots: Vec<(u32, D)>,
    /// Photon reads issued (down visits, plus up re-reads with [`Traversal::Reread`]):
    /// the hardware's read count.
    pub visited: u32,
    /// Distance tests (down visits only): what the paper's C code counts as
    /// "photons processed", every photon at most once.
    pub tested: u32,
    /// Insertions that set a new R (the list became or was full): each costs the
    /// QueryModule a MaxFinder run, one cycle per distance bit.
    pub max_finds: u32,
    /// Levels climbed without a read ([`Traversal::Remember`]): a QueryModule cycle
    /// each.
    pub climbs: u32,
}

impl<D> Found<D> {
    /// What this search costs a QueryModule, for `CoreConfig::fit_queries_per_port`.
    pub fn read_profile(&self) -> ReadProfile {
        ReadProfile {
            reads: self.visited as u64,
            max_finds: self.max_finds as u64,
            climbs: self.climbs as u64,
        }
    }
}

impl<D: Ord + Copy> Found<D> {
    /// The found distances, nearest first.
    pub fn sorted_dists(&self) -> Vec<D> {
        let mut d: Vec<D> = self.slots.iter().map(|s| s.1).collect();
        d.sort();
        d
    }
}

/// The found list: k slots, and once full a max-heap over (distance, lowest slot)
/// so that finding the maximum costs O(log k), not O(k) (paper Fig. 5/6 show the
/// linear max search dominating at large k; the hardware answers with §4.4's
/// bit-serial MaxFinder instead).
struct FoundList<D> {
    k: usize,
    slots: Vec<(u32, D)>,
    heap: BinaryHeap<(D, Reverse<u32>)>,
}

impl<D: Ord + Copy> FoundList<D> {
    fn new(k: usize) -> Self {
        FoundList {
            k,
            slots: Vec::with_capacity(k.min(1 << 16)),
            heap: BinaryHeap::new(),
        }
    }

    fn full(&self) -> bool {
        self.slots.len() == self.k
    }

    /// Insert a photon that passed the in-range test; returns the new R once full.
    fn insert(&mut self, addr: u32, d: D) -> Option<D> {
        if !self.full() {
            self.slots.push((addr, d));
            if !self.full() {
                return None;
            }
            let keyed: Vec<_> = (0..self.k as u32)
                .map(|s| (self.slots[s as usize].1, Reverse(s)))
                .collect();
            self.heap = BinaryHeap::from(keyed);
        } else {
            let mut top = self.heap.peek_mut().expect("full list has a maximum");
            let slot = top.1;
            self.slots[slot.0 as usize] = (addr, d);
            *top = (d, slot);
        }
        self.heap.peek().map(|t| t.0)
    }
}

/// The kd-tree search for the k nearest photons to `q` within `r0` (inclusive), on
/// any node source, with the default [`Traversal`]. `k` must be >= 1.
pub fn search<C: Scalar, S: NodeSource<C> + ?Sized>(
    tree: &S,
    q: [C; 3],
    k: usize,
    r0: C::Dist,
    metric: Metric,
) -> Found<C::Dist> {
    search_with(tree, q, k, r0, metric, Traversal::default())
}

/// [`search`] with the ascent chosen: the found slots are the same set of distances
/// either way (both are exact); the read counts differ.
pub fn search_with<C: Scalar, S: NodeSource<C> + ?Sized>(
    tree: &S,
    q: [C; 3],
    k: usize,
    r0: C::Dist,
    metric: Metric,
    traversal: Traversal,
) -> Found<C::Dist> {
    assert!(k >= 1, "k must be at least 1");
    match traversal {
        Traversal::Remember => search_remember::<false, C, S>(tree, q, k, r0, metric),
        Traversal::Cell => search_remember::<true, C, S>(tree, q, k, r0, metric),
        Traversal::Reread => search_reread(tree, q, k, r0, metric),
    }
}

/// The found list and the radius R of one search: the boundary rules in one place.
struct Radius<D> {
    list: FoundList<D>,
    r: D,
    max_finds: u32,
}

impl<D: Ord + Copy> Radius<D> {
    fn new(k: usize, r0: D) -> Self {
        Radius {
            list: FoundList::new(k),
            r: r0,
            max_finds: 0,
        }
    }

    /// A distance within R: `<= R0` while the list fills, `< max` once it is full.
    fn within(&self, d: D) -> bool {
        if self.list.full() {
            d < self.r
        } else {
            d <= self.r
        }
    }

    /// The distance test of a down visit: a photon in range enters the list.
    fn test(&mut self, addr: usize, d: D) {
        if self.within(d) {
            if let Some(max) = self.list.insert(addr as u32, d) {
                self.r = max;
                self.max_finds += 1;
            }
        }
    }
}

/// One photon read: its coordinates, its children toward and away from the query,
/// and its axis distance.
struct Read<C: Scalar> {
    p: [C; 3],
    axis: usize,
    near_bit: usize,
    near: usize,
    far: usize,
    axis_dist: C::Dist,
}

fn read<C: Scalar, S: NodeSource<C> + ?Sized>(
    tree: &S,
    q: [C; 3],
    addr: usize,
    metric: Metric,
) -> Read<C> {
    let (p, ax) = tree.node(addr);
    let ax = ax as usize;
    let near_bit = C::total_cmp(q[ax], p[ax]).is_ge() as usize;
    Read {
        p,
        axis: ax,
        near_bit,
        near: 2 * addr + near_bit,
        far: 2 * addr + 1 - near_bit,
        axis_dist: C::axis_dist(metric, q[ax], p[ax]),
    }
}

/// One level of the current path ([`Traversal::Remember`], [`Traversal::Cell`]): the
/// pruning bound of the far child of the node read there (its axis distance, or with
/// `Cell` the distance to its cell), whether that child is still to be visited, and
/// for `Cell` the node's axis, the offset along it before and inside the far cell.
#[derive(Clone, Copy)]
struct Level<D> {
    bound: D,
    pending: bool,
    axis: usize,
    old_off: D,
    far_off: D,
}

/// [`Traversal::Remember`] (`CELL` false) and [`Traversal::Cell`]: the ascent reads
/// nothing; see the module docs and `hw::config::traversal`. `CELL` is a constant so that
/// the default traversal's hot loop carries none of the offset bookkeeping.
fn search_remember<const CELL: bool, C: Scalar, S: NodeSource<C> + ?Sized>(
    tree: &S,
    q: [C; 3],
    k: usize,
    r0: C::Dist,
    metric: Metric,
) -> Found<C::Dist> {
    let n = tree.len();
    let mut st = Radius::new(k, r0);
    let mut visited = 0u32;
    let zero = C::ZERO_DIST;
    // One entry per tree level (the root is level 0): at most 64 levels of `usize`.
    let mut path = [Level {
        bound: r0,
        pending: false,
        axis: 0,
        old_off: zero,
        far_off: zero,
    }; 64];
    // `Cell`: the query's offsets from the current node's cell along each axis (zero
    // at the root: the root's cell is all space).
    let mut off = [zero; 3];
    let (mut addr, mut level) = (1usize, 0usize);
    let mut climbs = 0u32;
    'descend: loop {
        let rd = read(tree, q, addr, metric);
        visited += 1;
        let axis = rd.axis;
        // The down step's far test uses R as read with the photon (before its own
        // insertion), as the SearchModule computes it in parallel with the distance.
        let within = st.within(rd.axis_dist);
        st.test(addr, C::dist(metric, q, rd.p));
        // The far cell is this cell with the offset along `axis` replaced by the
        // axis distance (never smaller: the split lies inside the cell); its distance
        // is the sum of the offsets, added in the order `dist` adds the axes (so a
        // float bound is never above a float distance: rounding is monotonic). The
        // hardware adds incrementally, `rd - off[a] + axis_dist`: the same integer.
        let bound = if CELL {
            let mut far = off;
            far[axis] = rd.axis_dist;
            C::dist_sum(far)
        } else {
            rd.axis_dist
        };
        path[level] = Level {
            bound,
            pending: rd.near <= n && rd.far <= n,
            axis,
            old_off: off[axis],
            far_off: rd.axis_dist,
        };
        if rd.near <= n || (rd.far <= n && within) {
            // (A far child entered here keeps the offsets: a lower bound still.)
            addr = if rd.near <= n { rd.near } else { rd.far };
            level += 1;
            continue;
        }
        // Up without reads: R is now as it stands after this photon's insertion.
        while addr != 1 {
            let from = addr;
            addr >>= 1;
            climbs += 1;
            level -= 1;
            let l = path[level];
            if l.pending && st.within(l.bound) {
                path[level].pending = false;
                if CELL {
                    off[l.axis] = l.far_off;
                }
                addr = from ^ 1;
                level += 1;
                continue 'descend;
            }
            // Leaving this level's far (or near) child: its offset as it was.
            if CELL {
                off[l.axis] = l.old_off;
            }
        }
        break;
    }
    Found {
        slots: st.list.slots,
        visited,
        tested: visited,
        max_finds: st.max_finds,
        climbs,
    }
}

/// [`Traversal::Reread`]: the paper's search, every parent read again on the way up.
fn search_reread<C: Scalar, S: NodeSource<C> + ?Sized>(
    tree: &S,
    q: [C; 3],
    k: usize,
    r0: C::Dist,
    metric: Metric,
) -> Found<C::Dist> {
    let n = tree.len();
    let mut st = Radius::new(k, r0);
    let mut visited = 0u32;
    let mut tested = 0u32;
    let (mut addr, mut up, mut from) = (1usize, false, 0usize);
    loop {
        let rd = read(tree, q, addr, metric);
        visited += 1;
        // R as read with the photon (before this photon's own insertion).
        let within = st.within(rd.axis_dist);
        let mut next_down = None;
        if !up {
            tested += 1;
            st.test(addr, C::dist(metric, q, rd.p));
            if rd.near <= n {
                next_down = Some(rd.near);
            } else if rd.far <= n && within {
                next_down = Some(rd.far);
            }
        } else if from == rd.near_bit && rd.far <= n && within {
            next_down = Some(rd.far);
        }
        match next_down {
            Some(child) => {
                addr = child;
                up = false;
            }
            None if addr == 1 => break,
            None => {
                from = addr & 1;
                addr >>= 1;
                up = true;
            }
        }
    }
    Found {
        slots: st.list.slots,
        visited,
        tested,
        max_finds: st.max_finds,
        climbs: 0,
    }
}

/// Ground truth: every point's distance, those `<= r0` sorted by (distance, index),
/// the first k. Returns (point index, distance).
pub fn brute_force<C: Scalar>(
    points: &[[C; 3]],
    q: [C; 3],
    k: usize,
    r0: C::Dist,
    metric: Metric,
) -> Vec<(u32, C::Dist)> {
    let mut all: Vec<(C::Dist, u32)> = points
        .iter()
        .enumerate()
        .map(|(i, &p)| (C::dist(metric, q, p), i as u32))
        .filter(|&(d, _)| d <= r0)
        .collect();
    all.sort_unstable();
    all.truncate(k);
    all.into_iter().map(|(d, i)| (i, d)).collect()
}
