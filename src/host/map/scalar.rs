//! The coordinate types the kd-tree and the search work on (`Scalar`): `u32` grid
//! coordinates (the hardware's), `i64` grid coordinates of queries beyond the photon
//! box, and `f64` world coordinates (the float reference), each with its exact,
//! totally ordered distance type.

use crate::hw::config::metric::Metric;
use std::cmp::Ordering;

/// A coordinate type the kd-tree and the search work on: `u32` grid coordinates or
/// `f64` world coordinates.
pub trait Scalar: Copy + Send + Sync + std::fmt::Debug + 'static {
    /// Distance values; totally ordered.
    type Dist: Copy + Ord + Send + Sync + std::fmt::Debug;
    /// The largest distance (an unbounded radius).
    const MAX_DIST: Self::Dist;
    /// Distance zero.
    const ZERO_DIST: Self::Dist;
    fn total_cmp(a: Self, b: Self) -> Ordering;
    /// hi − lo as f64, to pick the split axis.
    fn extent(lo: Self, hi: Self) -> f64;
    fn axis_dist(metric: Metric, a: Self, b: Self) -> Self::Dist;
    fn dist(metric: Metric, a: [Self; 3], b: [Self; 3]) -> Self::Dist;
    /// The sum of three axis distances, added as `dist` adds them.
    fn dist_sum(d: [Self::Dist; 3]) -> Self::Dist;
}

impl Scalar for u32 {
    type Dist = u64;
    const MAX_DIST: u64 = u64::MAX;
    const ZERO_DIST: u64 = 0;
    fn total_cmp(a: u32, b: u32) -> Ordering {
        a.cmp(&b)
    }
    fn extent(lo: u32, hi: u32) -> f64 {
        (hi - lo) as f64
    }
    #[inline]
    fn axis_dist(metric: Metric, a: u32, b: u32) -> u64 {
        metric.axis_dist(a, b)
    }
    #[inline]
    fn dist(metric: Metric, a: [u32; 3], b: [u32; 3]) -> u64 {
        metric.dist(a, b)
    }
    #[inline]
    fn dist_sum(d: [u64; 3]) -> u64 {
        d[0] + d[1] + d[2]
    }
}

/// Grid coordinates beyond the photon box (a query outside it, `gather::GridPoint`):
/// signed, |c| < 2^62, with exact `u128` distances (3 × (2^63)² < 2^128).
impl Scalar for i64 {
    type Dist = u128;
    const MAX_DIST: u128 = u128::MAX;
    const ZERO_DIST: u128 = 0;
    fn total_cmp(a: i64, b: i64) -> Ordering {
        a.cmp(&b)
    }
    fn extent(lo: i64, hi: i64) -> f64 {
        hi as f64 - lo as f64
    }
    #[inline]
    fn axis_dist(metric: Metric, a: i64, b: i64) -> u128 {
        let d = a.abs_diff(b) as u128;
        match metric {
            Metric::L2 => d * d,
            Metric::L1 => d,
        }
    }
    #[inline]
    fn dist(metric: Metric, a: [i64; 3], b: [i64; 3]) -> u128 {
        (0..3).map(|i| Self::axis_dist(metric, a[i], b[i])).sum()
    }
    #[inline]
    fn dist_sum(d: [u128; 3]) -> u128 {
        d[0] + d[1] + d[2]
    }
}

/// A non-negative float distance, ordered by its bit pattern (monotonic for
/// non-negative IEEE values).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct FloatDist(u64);

impl FloatDist {
    pub fn new(d: f64) -> Self {
        debug_assert!(d >= 0.0);
        FloatDist((d + 0.0).to_bits())
    }
    pub fn get(self) -> f64 {
        f64::from_bits(self.0)
    }
}

impl Scalar for f64 {
    type Dist = FloatDist;
    const MAX_DIST: FloatDist = FloatDist(0x7ff0_0000_0000_0000); // +inf
    const ZERO_DIST: FloatDist = FloatDist(0);
    fn total_cmp(a: f64, b: f64) -> Ordering {
        a.total_cmp(&b)
    }
    fn extent(lo: f64, hi: f64) -> f64 {
        hi - lo
    }
    #[inline]
    fn axis_dist(metric: Metric, a: f64, b: f64) -> FloatDist {
        let d = (a - b).abs();
        FloatDist::new(match metric {
            Metric::L2 => d * d,
            Metric::L1 => d,
        })
    }
    #[inline]
    fn dist(metric: Metric, a: [f64; 3], b: [f64; 3]) -> FloatDist {
        let d = [0, 1, 2].map(|i| (a[i] - b[i]).abs());
        FloatDist::new(match metric {
            Metric::L2 => d[0] * d[0] + d[1] * d[1] + d[2] * d[2],
            Metric::L1 => d[0] + d[1] + d[2],
        })
    }
    #[inline]
    fn dist_sum(d: [FloatDist; 3]) -> FloatDist {
        FloatDist::new(d[0].get() + d[1].get() + d[2].get())
    }
}
