//! The two-pass render's photon lookups as batches for the gather backend: one
//! stage's query points (caustic lookups at the eye hits, or a block of
//! final-gather hits) sorted along a Morton curve of their positions, gathered as
//! one batch, and the answers put back in the renderer's order.
//!
//! Why sort: final-gather hits come out in pixel order but land all over the scene,
//! so consecutive queries would read unrelated parts of the kd-tree. Sorted along a
//! Z-order curve, neighbouring queries read mostly the same nodes, which is what a
//! cache or the core's shared BlockRAM rewards (the paper's §4.5 streams queries to
//! many controllers on one tree). Each query's answer depends only on the map and
//! the query (`gather.rs`), so the order changes the time, never the image.

use crate::host::error::Result;
use crate::host::gather::{GatherBackend, Gathered};
use crate::host::map::quantize::Point;

/// Most gathered photons held at once (16 bytes each: 128 MiB), whatever the image
/// size, the gather-ray count and k.
const MAX_NEIGHBOURS: usize = 1 << 23;

/// Most lookups in one batch of `k`-nearest gathers: [`MAX_NEIGHBOURS`] / k (2^18
/// at k = 32), at least one.
pub fn max_batch(k: usize) -> usize {
    (MAX_NEIGHBOURS / k.max(1)).max(1)
}

/// Morton code bits per axis (30-bit codes): finer than any image's hits need to
/// group them.
const MORTON_BITS: u32 = 10;

/// Spread the low 10 bits of `v` to every third bit.
fn spread(v: u32) -> u32 {
    let mut x = v & 0x3ff;
    x = (x | (x << 16)) & 0x030000ff;
    x = (x | (x << 8)) & 0x0300f00f;
    x = (x | (x << 4)) & 0x030c30c3;
    x = (x | (x << 2)) & 0x09249249;
    x
}

/// The Morton code of each point on a 2^10 grid over the points' bounding box.
pub fn morton_codes(points: &[Point]) -> Vec<u32> {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in points {
        for a in 0..3 {
            lo[a] = lo[a].min(p[a]);
            hi[a] = hi[a].max(p[a]);
        }
    }
    let cells = ((1u32 << MORTON_BITS) - 1) as f64;
    let scale: Vec<f64> = (0..3)
        .map(|a| {
            let extent = hi[a] - lo[a];
            if extent > 0.0 {
                cells / extent
            } else {
                0.0
            }
        })
        .collect();
    points
        .iter()
        .map(|p| {
            let c = |a: usize| (((p[a] - lo[a]) * scale[a]).round() as u32).min(cells as u32);
            spread(c(0)) | (spread(c(1)) << 1) | (spread(c(2)) << 2)
        })
        .collect()
}

/// Gather `points` through `backend` (whose gathers return at most `k` photons) in
/// Morton order (ties by position in `points`, so the order is a function of the
/// points alone), at most [`max_batch`] per backend call; the answers in `points`'
/// order.
pub fn gather_sorted(
    backend: &dyn GatherBackend,
    points: &[Point],
    k: usize,
) -> Result<Vec<Gathered>> {
    let codes = morton_codes(points);
    let mut order: Vec<u32> = (0..points.len() as u32).collect();
    order.sort_unstable_by_key(|&i| (codes[i as usize], i));
    let mut out = vec![Gathered::default(); points.len()];
    for chunk in order.chunks(max_batch(k)) {
        let batch: Vec<Point> = chunk.iter().map(|&i| points[i as usize]).collect();
        for (&i, g) in chunk.iter().zip(backend.gather(&batch)?) {
            out[i as usize] = g;
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::host::gather::{FloatBackend, GatherParams};

    #[test]
    fn spread_interleaves_bits() {
        assert_eq!(spread(0b1), 0b1);
        assert_eq!(spread(0b11), 0b1001);
        assert_eq!(spread(0x3ff), 0x09249249);
        // x, y, z of (1, 1, 1) at the lowest level are bits 0, 1, 2.
        assert_eq!(spread(1) | (spread(1) << 1) | (spread(1) << 2), 0b111);
    }

    #[test]
    fn sorted_gathers_come_back_in_the_callers_order() {
        let photons: Vec<Point> = (0..500)
            .map(|i| {
                let t = i as f64;
                [(t * 0.37).sin(), (t * 0.11).cos(), (t * 0.05).sin()]
            })
            .collect();
        let params = GatherParams {
            k: 5,
            ..GatherParams::default()
        };
        let backend = FloatBackend::new(&photons, &params).unwrap();
        let queries: Vec<Point> = (0..300)
            .map(|i| {
                let t = i as f64;
                [(t * 1.3).cos(), (t * 0.7).sin(), (t * 0.3).cos()]
            })
            .collect();
        let codes = morton_codes(&queries);
        assert!(codes.windows(2).any(|w| w[0] > w[1]), "already sorted");
        let want = backend.gather(&queries).unwrap();
        assert_eq!(gather_sorted(&backend, &queries, 5).unwrap(), want);
        // Many batches (k beyond the budget: one query each) give the same answers.
        assert_eq!(max_batch(usize::MAX), 1);
        assert_eq!(gather_sorted(&backend, &queries, usize::MAX).unwrap(), want);
    }
}
