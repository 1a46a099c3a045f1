//! One query's re-ranking: the core's k′ grid candidates by their exact float
//! distances, and the certificate that their k best are the float gather's answer.
//!
//! The float gather (`gather::FloatBackend`) answers the k photons of smallest float
//! distance `d` with `d <= r0`; where several photons tie at the k-th distance, which
//! of them it keeps depends on the order its own kd-tree visits them. So the
//! re-ranked answer is the float answer exactly when
//! 1. every photon the core did not return has `d` above the threshold `t` — the
//!    k-th exact distance among the candidates within `r0`, or `r0` itself if fewer
//!    than k of them are within it. The core's found list holds the k′ nearest on
//!    the grid, so a photon it did not return has a grid distance of at least the
//!    k′-th, `G'`; [`Bound::exceeds`]`(G', δ, t)` proves `d > t` for all of them. If
//!    the core returned fewer than k′, it returned every photon within its grid
//!    radius ([`Bound::grid_radius`] of `r0`), which holds every photon with
//!    `d <= r0`: nothing is missing (this covers k > photons and radius 0);
//! 2. no tie straddles rank k among the candidates within `r0` (the float search's
//!    choice among them is its traversal's, not a rule the host can replay).
//!
//! Otherwise the query is not certified and the caller asks the float search.

use super::bound::Bound;
use crate::host::gather::{canonical_order, Neighbour};
use crate::host::map::knn::{FloatDist, Scalar};
use crate::host::map::quantize::Point;
use crate::hw::config::metric::Metric;

/// What the re-ranking of one query concluded.
#[derive(Clone, Debug, PartialEq)]
pub enum Verdict {
    /// Certified: the float gather's neighbours, in its canonical order.
    Exact(Vec<Neighbour>),
    /// A photon the core did not return may be nearer than the k-th candidate.
    Uncertified,
    /// Candidates tie at rank k: the float search decides which it keeps.
    Tie,
}

/// One gather's fixed inputs to the re-ranking.
pub struct Rerank<'a> {
    /// The photons' world positions, indexed as the caller's list.
    pub photons: &'a [Point],
    pub metric: Metric,
    /// Photons asked for.
    pub k: usize,
    /// The float gather's inclusive bound (squared for L2), `+inf` if unbounded.
    pub r0: FloatDist,
    pub bound: Bound,
}

impl Rerank<'_> {
    /// Re-rank `found` — (photon index, grid distance) as the core returned them for a
    /// query at world position `q` (grid point `c`), asked for `k_prime` candidates.
    pub fn verdict(&self, q: Point, c: [u32; 3], found: &[(u32, u64)], k_prime: usize) -> Verdict {
        let mut exact: Vec<(FloatDist, u32)> = found
            .iter()
            .filter_map(|&(p, _)| {
                let d = f64::dist(self.metric, q, self.photons[p as usize]);
                (d <= self.r0).then_some((d, p))
            })
            .collect();
        exact.sort_unstable();
        let k = self.k;
        if exact.len() > k && exact[k - 1].0 == exact[k].0 {
            return Verdict::Tie;
        }
        if found.len() >= k_prime {
            let g = found.iter().map(|f| f.1).max().unwrap_or(0);
            let t = if exact.len() >= k {
                exact[k - 1].0
            } else {
                self.r0
            };
            if !self.bound.exceeds(g, self.bound.query_delta(q, c), t) {
                return Verdict::Uncertified;
            }
        }
        exact.truncate(k);
        let mut n: Vec<Neighbour> = exact
            .into_iter()
            .map(|(d, p)| Neighbour {
                photon: p,
                distance: match self.metric {
                    Metric::L2 => d.get().sqrt(),
                    Metric::L1 => d.get(),
                },
            })
            .collect();
        canonical_order(&mut n);
        Verdict::Exact(n)
    }
}
