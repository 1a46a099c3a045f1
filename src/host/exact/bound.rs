//! The bound δ between a grid distance and the exact float distance, and the two
//! conversions the certificate needs: a grid distance to a lower bound on the float
//! distance, and the float gather's radius to a grid radius that loses no photon.
//!
//! # Where the grid error comes from
//! [`Quantizer`] maps a world coordinate `x` on axis `a` to
//! `g = round(fl(fl(x − o) / s))` with `o` the photon box minimum and `s` the grid
//! step (one isotropic step, the longest extent / (2^B − 1); paper §4). Photons and
//! queries inside the box go through the same rounding (`Quantizer::quantize` for
//! the packed tree, `Quantizer::grid` for the query the core receives); the clamp of
//! `quantize` never acts on a photon (`fl(x − o) <= fl(hi − o)` and the rounded
//! maximum fits the axis width), so in real arithmetic
//!
//! ```text
//! |g − (x − o)/s| <= 1/2 + |fl(fl(x − o)/s) − (x − o)/s| <= 1/2 + 2·2^-53·|(x − o)/s| + 2^-1074
//! ```
//!
//! (one rounding of the subtraction, one of the division, an underflow term for a
//! subnormal quotient). Inside the box `|(x − o)/s| < 2^17` (at most 16 coordinate
//! bits, an axis up to twice its extent wide), so each position is off by at most
//! `1/2 + 2^-35` steps per axis (the underflow term is far below 2^-35).
//!
//! # δ for each metric (in grid steps)
//! Write `p̂ = (p − o)/s`, `q̂ = (q − o)/s` for the exact real grid positions and `G`
//! for the core's integer distance between the photon's grid point `g` and the
//! query's `c` (`hw::config::metric::Metric::dist`, exact in u64). The photon's error is
//! known only to be at most `h = 1/2 + 2^-35` per axis; the query's is known: the
//! host holds `q` and `c`, and `v = fl(fl(q − o)/s)` is within 2^-35 of `q̂` per axis.
//! * **L1**: `D1/s = |p̂ − q̂|₁ >= |g − c|₁ − |g − p̂|₁ − |c − q̂|₁ >= G − 3h − ρ1`
//!   with `ρ1 = |c − v|₁ + 3·2^-35`: `δ1 = 3/2 + ρ1` (at most 3).
//! * **Squared Euclidean**: the core compares `G = |g − c|₂²`; by the triangle
//!   inequality in R³, `D2/s >= √G − |g − p̂|₂ − |c − q̂|₂ >= √G − √3·h − ρ2` with
//!   `ρ2 = |c − v|₂ + √3·2^-35`: `δ2 = √3/2 + ρ2` (at most √3).
//!
//! The worst case, a query on a cell corner, gives 3 and √3 steps; knowing the
//! query's own offset makes δ about a quarter smaller on average. [`DELTA_MARGIN`]
//! is added to the photon's part: besides the 2^-35 terms it absorbs evaluating
//! `|c − v|` and `√G − δ` in f64 (G < 2^34, so `√G` is off by at most 2^-36; `c − v`
//! is exact, the rest a few roundings of numbers below 2^18).
//!
//! # From real distances to the float backend's numbers
//! The float backend compares `d = fl(Σ|Δ|²)` (L2) or `fl(Σ|Δ|)` (L1) of the f64
//! positions (`Scalar::dist` for f64): at most five roundings, so for normal results
//! `D²(1 − ε)^5 <= d <= D²(1 + ε)^5` with ε = 2^-53. The lower bound `lb = s·(√G − δ)`
//! and its square are themselves computed with at most three roundings. The
//! certificate therefore asks `fl(lb²·(1 − 2^-40)) > t` (`lb·(1 − 2^-40)` for L1) for
//! a threshold `t` in the float backend's own distance numbers: `2^-40` exceeds the
//! eight roundings by a factor of 2^10, so the computed left side is below every
//! float distance `d` of a photon whose grid distance is `G` or more, and `d > t`
//! follows. Subnormal intermediates break relative bounds, so nothing below
//! [`CERT_FLOOR`] certifies (an absolute underflow error, ≤ 2^-1074 per operation, is
//! then below 2^-70 of the values compared), and a map whose grid step is below
//! [`MIN_STEP`] is not certified at all: its queries take the float search.
//!
//! # The radius
//! The float gather takes a photon iff `d <= r0` (`r0 = fl(r·r)` for L2). Such a photon
//! has `D <= √(max(r0, CERT_FLOOR)·(1 + 2^-40))` and so `√G <= D/s + δ2` (L2) or
//! `G <= D/s + δ1` (L1); [`Bound::grid_radius`] rounds that up with the same margins,
//! so the core's inclusive grid radius keeps every photon the float gather could take
//! (saturated at the largest distance inside the box, which keeps them all).

use crate::host::map::knn::FloatDist;
use crate::host::map::quantize::{Point, Quantizer};
use crate::hw::config::metric::Metric;

/// Added to δ (grid steps): the per-axis rounding beyond a half step, and the f64
/// evaluation of the lower bound.
pub const DELTA_MARGIN: f64 = 1.0 / (1u64 << 20) as f64;
/// Relative margin for the float roundings of distances and bounds.
const REL: f64 = 1.0 / (1u64 << 40) as f64;
/// Smallest float distance (squared for L2) a certificate compares: below it,
/// subnormal roundings are not relative.
pub const CERT_FLOOR: f64 = 1e-300;
/// Smallest grid step the certificate serves: `CERT_FLOOR`'s square root is then a
/// small fraction of a step, so the radius conversion stays tight.
pub const MIN_STEP: f64 = 1e-140;

/// The certificate's arithmetic for one quantized map.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bound {
    pub metric: Metric,
    /// Grid origin and step in world units (the quantizer's).
    pub origin: Point,
    pub step: f64,
    /// The photon's part of δ in grid steps, with the margin (`3h` for L1, `√3·h`
    /// for L2; see the module docs); [`Bound::new`] sets the derived value.
    pub delta: f64,
    /// Whether the grid step is in the range the derivation covers.
    pub usable: bool,
}

impl Bound {
    /// The derived δ for `metric` on `quant`'s grid.
    pub fn new(metric: Metric, quant: &Quantizer) -> Self {
        let delta = match metric {
            Metric::L1 => 1.5,
            Metric::L2 => 3f64.sqrt() / 2.0,
        } + DELTA_MARGIN;
        Bound {
            metric,
            origin: quant.origin,
            step: quant.step,
            delta,
            usable: quant.step >= MIN_STEP && quant.step.is_finite(),
        }
    }

    /// δ for the query at world position `q` whose grid point is `c`: the photon's
    /// part and the query's own rounding `ρ`.
    pub fn query_delta(&self, q: Point, c: [u32; 3]) -> f64 {
        let off = [0, 1, 2].map(|a| (c[a] as f64 - (q[a] - self.origin[a]) / self.step).abs());
        let rho = match self.metric {
            Metric::L1 => off[0] + off[1] + off[2],
            Metric::L2 => (off[0] * off[0] + off[1] * off[1] + off[2] * off[2]).sqrt(),
        };
        self.delta + rho
    }

    /// The largest [`Bound::query_delta`] of any query (one on a cell corner).
    fn worst_delta(&self) -> f64 {
        2.0 * self.delta
    }

    /// Whether every photon whose grid distance from a query is `g` or more has a
    /// float distance (the float backend's own number, squared for L2) strictly
    /// above `t`; `delta` is the query's [`Bound::query_delta`].
    pub fn exceeds(&self, g: u64, delta: f64, t: FloatDist) -> bool {
        if !self.usable {
            return false;
        }
        let steps = match self.metric {
            Metric::L1 => g as f64 - delta,
            Metric::L2 => (g as f64).sqrt() - delta,
        };
        if steps <= 0.0 {
            return false;
        }
        let lb = self.step * steps;
        let lhs = match self.metric {
            Metric::L1 => lb * (1.0 - REL),
            Metric::L2 => lb * lb * (1.0 - REL),
        };
        lhs >= CERT_FLOOR && lhs > t.get()
    }

    /// An inclusive grid radius that keeps every photon whose float distance is
    /// `<= r0` (the float gather's bound, squared for L2), saturated at `max`.
    pub fn grid_radius(&self, r0: FloatDist, max: u64) -> u64 {
        let r0 = r0.get().max(CERT_FLOOR) * (1.0 + REL);
        let d = match self.metric {
            Metric::L1 => r0,
            Metric::L2 => r0.sqrt(),
        };
        let steps = (d / self.step) * (1.0 + REL) + self.worst_delta();
        let g = match self.metric {
            Metric::L1 => steps,
            Metric::L2 => steps * steps * (1.0 + REL),
        };
        if !g.is_finite() || g >= max as f64 {
            max
        } else {
            (g.ceil() as u64).saturating_add(1).min(max)
        }
    }
}
