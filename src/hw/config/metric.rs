//! The distance metric of the photon search, shared by the software search and the
//! hardware DistModule (full and split-axis distances) so both compute the very same integers.
//!
//! The paper (§4.4) keeps a 12-bit "absolute distance"; we read that as the L1
//! distance of 10-bit coordinates (max 3 x 1023 = 3069). Squared Euclidean is the
//! default because it is what Jensen's radiance estimate assumes.

use serde::{Deserialize, Serialize};
use std::fmt;

/// Distance metric on quantized integer coordinates (`--metric`, the core file's
/// `metric`); each variant's doc is its help text.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[serde(rename_all = "lowercase")]
pub enum Metric {
    /// Squared Euclidean distance (no square root in hardware).
    #[default]
    L2,
    /// Manhattan distance (the paper's 12-bit "absolute distance").
    L1,
}

impl Metric {
    /// Distance along one axis: |a-b|^2 for L2, |a-b| for L1.
    #[inline]
    pub fn axis_dist(self, a: u32, b: u32) -> u64 {
        let d = a.abs_diff(b) as u64;
        match self {
            Metric::L2 => d * d,
            Metric::L1 => d,
        }
    }

    /// Full distance: the sum of the axis distances.
    #[inline]
    pub fn dist(self, a: [u32; 3], b: [u32; 3]) -> u64 {
        self.axis_dist(a[0], b[0]) + self.axis_dist(a[1], b[1]) + self.axis_dist(a[2], b[2])
    }

    /// Largest distance between two points whose axes have the given widths.
    pub fn max_dist(self, bits: [u32; 3]) -> u64 {
        bits.iter()
            .map(|&b| {
                let m = (1u64 << b) - 1;
                self.axis_dist(0, m as u32)
            })
            .sum()
    }

    /// Bits needed to hold any distance between points of the given axis widths
    /// (L2 at 10 bits: 22; L1 at 10 bits: 12, the paper's width).
    pub fn dist_bits(self, bits: [u32; 3]) -> u32 {
        64 - self.max_dist(bits).leading_zeros()
    }

    /// Convert an integer distance back to world units given the grid step:
    /// sqrt(d)·step for L2, d·step for L1.
    pub fn to_world(self, d: u64, step: f64) -> f64 {
        match self {
            Metric::L2 => (d as f64).sqrt() * step,
            Metric::L1 => d as f64 * step,
        }
    }

    /// The integer bound for a world-space radius `r` (inclusive: a photon is in
    /// range iff its integer distance <= the bound), saturated at `max`.
    pub fn radius_bound(self, r: f64, step: f64, max: u64) -> u64 {
        let x = r / step;
        let v = match self {
            Metric::L2 => x * x,
            Metric::L1 => x,
        };
        if v.is_nan() || v >= max as f64 {
            max
        } else {
            self.radius_bound_wide(r, step).min(max as u128) as u64
        }
    }

    /// [`Metric::radius_bound`] unsaturated, for queries outside the photon box: the
    /// largest integer distance d with d <= (r/step)² (L2) or r/step (L1).
    pub fn radius_bound_wide(self, r: f64, step: f64) -> u128 {
        let x = r / step;
        let v = match self {
            Metric::L2 => x * x,
            Metric::L1 => x,
        };
        if v.is_nan() || v >= u128::MAX as f64 {
            return u128::MAX;
        }
        let mut b = v.floor() as u128;
        if v >= (1u64 << 53) as f64 {
            // Past 2^53 neighbouring integers share one f64: the floor is the bound.
            return b;
        }
        // floor, then fix the float rounding of x*x at exact integers.
        while self.grid_ok(b + 1, x) {
            b += 1;
        }
        while b > 0 && !self.grid_ok(b, x) {
            b -= 1;
        }
        b
    }

    fn grid_ok(self, d: u128, x: f64) -> bool {
        match self {
            Metric::L2 => (d as f64).sqrt() <= x,
            Metric::L1 => d as f64 <= x,
        }
    }
}

impl fmt::Display for Metric {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Metric::L2 => "l2",
            Metric::L1 => "l1",
        })
    }
}
