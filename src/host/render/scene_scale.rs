//! The scale of a scene, and what f32 geometry can hold: every tolerance of the ray
//! tracer is relative to the scene's size, and a scene too large or too small for
//! f32 arithmetic is refused with that reason (not with whatever check its
//! overflowed or underflowed numbers would trip first).
//!
//! The ray tracer squares lengths (normals, areas, sphere discriminants), so
//! coordinates must stay within ±1e15 (squares below f32's 3.4e38) and the scene
//! must span at least 1e-12 (squares above f32's smallest normal, 1.2e-38).

use std::ops::Range;

/// Largest coordinate magnitude of the scene (camera included).
pub const MAX_COORD: f64 = 1e15;
/// Smallest extent of the scene's geometry.
pub const MIN_SIZE: f64 = 1e-12;
/// The ray epsilon relative to the scene's size: the Cornell box (size 1) keeps the
/// 1e-4 that is far above the f32 rounding of its hit points (~1e-7) and far below
/// any of its features.
pub const RAY_EPSILON_REL: f32 = 1e-4;

/// One point of the scene file: what it is, where it is, its value.
pub struct Located<'a> {
    pub what: &'a str,
    pub span: Range<usize>,
    pub value: [f64; 3],
}

/// Check `points` (every position the file gives, the camera's too) and `geometry`
/// (the corners of quads and the light, spheres' bounding boxes); the ray epsilon of
/// the scene, or the span and message of what is wrong.
pub fn ray_epsilon(
    points: &[Located],
    geometry: &[[f64; 3]],
) -> Result<f32, (Option<Range<usize>>, String)> {
    for p in points {
        if p.value.iter().any(|c| c.abs() > MAX_COORD) {
            return Err((
                Some(p.span.clone()),
                format!(
                    "{} {:?} lies beyond ±{MAX_COORD:e}: the f32 ray tracer squares lengths, \
                     which must stay finite; scale the scene down",
                    p.what, p.value
                ),
            ));
        }
    }
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    let mut max_abs = 0.0f64;
    for g in geometry {
        for a in 0..3 {
            lo[a] = lo[a].min(g[a]);
            hi[a] = hi[a].max(g[a]);
            max_abs = max_abs.max(g[a].abs());
        }
    }
    let extent = (0..3).map(|a| hi[a] - lo[a]).fold(0.0, f64::max);
    if extent.is_nan() || extent < MIN_SIZE {
        return Err((
            None,
            format!(
                "the scene's geometry spans only {extent:e} world units: the f32 ray tracer \
                 needs at least {MIN_SIZE:e} (squared lengths must not underflow); scale the \
                 scene up"
            ),
        ));
    }
    // The size that sets the epsilon: the extent, or the distance from the origin if
    // larger (f32 rounds a hit point relative to its own magnitude).
    let size = extent.max(max_abs);
    Ok(RAY_EPSILON_REL * size as f32)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn at(what: &'static str, value: [f64; 3]) -> Located<'static> {
        Located {
            what,
            span: 0..1,
            value,
        }
    }

    #[test]
    fn epsilon_follows_the_scene_size() {
        let unit = [[0.0; 3], [1.0, 1.0, 1.0]];
        assert_eq!(ray_epsilon(&[], &unit).unwrap(), 1e-4);
        let big = unit.map(|p| p.map(|c| c * 1e12));
        assert_eq!(ray_epsilon(&[], &big).unwrap(), 1e-4 * 1e12);
        let small = unit.map(|p| p.map(|c| c * 1e-4));
        assert_eq!(ray_epsilon(&[], &small).unwrap(), 1e-4 * 1e-4_f64 as f32);
    }

    #[test]
    fn too_large_or_too_small_says_why() {
        let (span, e) = ray_epsilon(&[at("camera position", [0.0, 1e30, 0.0])], &[]).unwrap_err();
        assert!(
            span.is_some() && e.contains("camera position") && e.contains("scale the scene down")
        );
        let tiny = [[0.0; 3], [1e-30, 1e-30, 1e-30]];
        let (_, e) = ray_epsilon(&[], &tiny).unwrap_err();
        assert!(e.contains("scale the scene up"), "{e}");
    }
}
