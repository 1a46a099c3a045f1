//! The study's error measures, each a plain function of two results so
//! the tests can check it against an independent computation.

use glam::Vec3;
use photon_fpga::host::gather::{canonical_order, Gathered, Neighbour};
use photon_fpga::host::map::quantize::Point;
use photon_fpga::host::render::QueryPoint;
use photon_fpga::hw::config::metric::Metric;

/// Linear radiance image of the gathered (photon-mapped) light: per pixel the sum
/// of weight × radiance over the pixel's queries, summed in query order (so the
/// same inputs give the same bits whatever the thread count). The light's own
/// emission, identical in every render of a scene and 50x brighter than the walls,
/// is left out: it would swamp the error's denominator.
pub fn gathered_image(pixels: usize, queries: &[QueryPoint], radiance: &[Vec3]) -> Vec<[f64; 3]> {
    assert_eq!(queries.len(), radiance.len(), "one radiance per query");
    let mut img = vec![[0.0f64; 3]; pixels];
    for (q, l) in queries.iter().zip(radiance) {
        let c = q.weight * *l;
        let p = &mut img[q.pixel as usize];
        for a in 0..3 {
            p[a] += c[a] as f64;
        }
    }
    img
}

/// The same gathered photons with their distances recomputed on the host from the
/// float positions (`metric`'s world distance to the unquantized query): the core
/// returns photon indices only (paper §4), so the host can take the estimate's
/// radius from the exact positions and leave the core only the choice of photons.
pub fn host_radius(
    gathered: &[Gathered],
    queries: &[Point],
    photons: &[Point],
    metric: Metric,
) -> Vec<Gathered> {
    gathered
        .iter()
        .zip(queries)
        .map(|(g, q)| {
            let mut n: Vec<Neighbour> = g
                .neighbours
                .iter()
                .map(|x| {
                    let p = photons[x.photon as usize];
                    let d = [0, 1, 2].map(|a| (p[a] - q[a]).abs());
                    let distance = match metric {
                        Metric::L1 => d[0] + d[1] + d[2],
                        Metric::L2 => (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt(),
                    };
                    Neighbour {
                        photon: x.photon,
                        distance,
                    }
                })
                .collect();
            canonical_order(&mut n);
            Gathered {
                neighbours: n,
                visited: g.visited,
            }
        })
        .collect()
}

/// Relative RMSE of `got` against `want` over every pixel and channel:
/// sqrt(Σ (got − want)² / Σ want²). NaN if `want` is all black.
pub fn rel_rmse(got: &[[f64; 3]], want: &[[f64; 3]]) -> f64 {
    assert_eq!(got.len(), want.len(), "images of one size");
    let (mut num, mut den) = (0.0f64, 0.0f64);
    for (g, w) in got.iter().zip(want) {
        for a in 0..3 {
            num += (g[a] - w[a]).powi(2);
            den += w[a] * w[a];
        }
    }
    (num / den).sqrt()
}

/// Mean over queries of |found ∩ true| / |true| (photon indices): recall@k of a
/// gather against the exact kNN. Queries whose true set is empty are skipped; NaN
/// if all are.
pub fn recall(got: &[Gathered], truth: &[Gathered]) -> f64 {
    assert_eq!(got.len(), truth.len(), "one result per query");
    let (mut sum, mut n) = (0.0f64, 0usize);
    for (g, t) in got.iter().zip(truth) {
        if t.neighbours.is_empty() {
            continue;
        }
        let mut want: Vec<u32> = t.neighbours.iter().map(|x| x.photon).collect();
        want.sort_unstable();
        let hits = g
            .neighbours
            .iter()
            .filter(|x| want.binary_search(&x.photon).is_ok())
            .count();
        sum += hits as f64 / want.len() as f64;
        n += 1;
    }
    sum / n as f64
}

/// Mean over queries of |r − r_true| / r_true, r = the farthest gathered photon's
/// distance (the radius the density estimate divides by). Queries whose true
/// radius is 0 or that found nothing are skipped; NaN if all are.
pub fn radius_rel_error(got: &[Gathered], truth: &[Gathered]) -> f64 {
    assert_eq!(got.len(), truth.len(), "one result per query");
    let (mut sum, mut n) = (0.0f64, 0usize);
    for (g, t) in got.iter().zip(truth) {
        let (Some(rg), Some(rt)) = (g.neighbours.last(), t.neighbours.last()) else {
            continue;
        };
        if rt.distance > 0.0 {
            sum += (rg.distance - rt.distance).abs() / rt.distance;
            n += 1;
        }
    }
    sum / n as f64
}
