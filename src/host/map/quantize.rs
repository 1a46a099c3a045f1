//! Quantization of world positions onto the isotropic integer grid the hardware
//! searches (paper §4: a 1000³ space, 10-bit coordinates).
//!
//! One step length serves all three axes (longest extent / (2^B − 1)), so distances
//! stay isotropic; each axis then gets only the bits its own extent needs, which is
//! how a flat or long scene packs into a narrower photon word.

use crate::host::error::{Error, Result};
use crate::hw::config::photon_word::{PhotonLayout, MAX_COORD_BITS};

/// A world position.
pub type Point = [f64; 3];

/// Largest distance, in grid steps, of a query from the photon box on any axis:
/// keeps its grid coordinates in `i64` and its distances exact in `u128`.
pub const MAX_QUERY_GRID: f64 = (1u64 << 62) as f64;

/// Where a world position falls on the photons' grid.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GridPoint {
    /// Inside the photon box: what the core (and the packed search) takes.
    Inside([u32; 3]),
    /// Outside it on some axis: signed grid coordinates, for the host's exact path.
    Outside([i64; 3]),
}

/// Maps world positions to integer grid coordinates and back.
#[derive(Clone, Debug, PartialEq)]
pub struct Quantizer {
    /// World position of grid coordinate (0, 0, 0): the bounding box minimum.
    pub origin: Point,
    /// Grid step in world units, the same on every axis.
    pub step: f64,
    /// Per-axis coordinate widths of the photon word.
    pub layout: PhotonLayout,
}

/// The photons' bounding box (lowest and highest corner); none for an empty set.
fn bounding_box(points: &[Point]) -> Result<(Point, Point)> {
    let Some(first) = points.first() else {
        return Err(Error::new("the photon set is empty"));
    };
    let (mut lo, mut hi) = (*first, *first);
    for p in points {
        for a in 0..3 {
            lo[a] = lo[a].min(p[a]);
            hi[a] = hi[a].max(p[a]);
        }
    }
    Ok((lo, hi))
}

impl Quantizer {
    /// A grid over the bounding box of `points` with `bits` on the longest axis.
    pub fn from_points(points: &[Point], bits: u32) -> Result<Self> {
        if !(1..=MAX_COORD_BITS).contains(&bits) {
            return Err(Error::new(format!(
                "--bits {bits} is out of range (1..={MAX_COORD_BITS})"
            )));
        }
        let (lo, hi) = bounding_box(points)?;
        let ext = [hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]];
        let longest = ext.iter().cloned().fold(0.0, f64::max);
        let top = ((1u64 << bits) - 1) as f64;
        // All photons at one point: any positive step maps them all to 0.
        let step = if longest > 0.0 { longest / top } else { 1.0 };
        if !step.is_normal() {
            return Err(Error::new(format!(
                "the photons span only {longest:e} world units: too little for a {bits}-bit grid in f64"
            )));
        }
        let mut axis_bits = [1u32; 3];
        for a in 0..3 {
            let qmax = (ext[a] / step).round().min(top) as u64;
            axis_bits[a] = (64 - qmax.leading_zeros()).max(1);
        }
        Ok(Quantizer {
            origin: lo,
            step,
            layout: PhotonLayout::new(axis_bits),
        })
    }

    /// A grid over the bounding box of `points` with exactly `layout`'s widths: a
    /// fixed core's (`--core`). The one step is the smallest that fits every axis
    /// of the box into its own width, so any photon map quantizes onto the core.
    pub fn for_layout(points: &[Point], layout: PhotonLayout) -> Result<Self> {
        let (lo, hi) = bounding_box(points)?;
        let step = (0..3)
            .map(|a| (hi[a] - lo[a]) / layout.coord_max(a) as f64)
            .fold(0.0, f64::max);
        // All photons at one point: any positive step maps them all to 0.
        let step = if step > 0.0 { step } else { 1.0 };
        if !step.is_normal() {
            return Err(Error::new(format!(
                "the photons span too little ({:e} world units per grid step) for a grid in f64",
                step
            )));
        }
        Ok(Quantizer {
            origin: lo,
            step,
            layout,
        })
    }

    /// Per-axis coordinate widths.
    pub fn axis_bits(&self) -> [u32; 3] {
        self.layout.bits
    }

    /// Grid coordinates of a world position: rounded to the nearest grid point and
    /// clamped onto the grid (a query outside the photons' box is moved onto it).
    pub fn quantize(&self, p: Point) -> [u32; 3] {
        let mut q = [0u32; 3];
        for a in 0..3 {
            let v = ((p[a] - self.origin[a]) / self.step).round();
            q[a] = v.clamp(0.0, self.layout.coord_max(a) as f64) as u32;
        }
        q
    }

    /// Grid coordinates of a world position without clamping: inside the photon box
    /// (rounded to the nearest grid point), or outside it; `Err` with the distance in
    /// grid steps if that exceeds [`MAX_QUERY_GRID`].
    pub fn grid(&self, p: Point) -> std::result::Result<GridPoint, f64> {
        let mut g = [0i64; 3];
        let mut inside = true;
        for a in 0..3 {
            let v = ((p[a] - self.origin[a]) / self.step).round();
            if v.is_nan() || v.abs() >= MAX_QUERY_GRID {
                return Err(v.abs());
            }
            g[a] = v as i64;
            inside &= g[a] >= 0 && g[a] <= self.layout.coord_max(a) as i64;
        }
        Ok(if inside {
            GridPoint::Inside(g.map(|c| c as u32))
        } else {
            GridPoint::Outside(g)
        })
    }

    /// World position of a grid point.
    pub fn dequantize(&self, q: [u32; 3]) -> Point {
        [0, 1, 2].map(|a| self.origin[a] + q[a] as f64 * self.step)
    }
}
