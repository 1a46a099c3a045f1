//! Caustics of the two-pass method (Jensen 1996; Jensen, "Realistic Image Synthesis
//! Using Photon Mapping", 2001, ch. 9): light that reached a diffuse point from the
//! light through mirrors and glass only (L S+ D paths), read from a caustic photon
//! map at the eye's shading points with a radius-capped k-nearest lookup.
//!
//! Why a map of its own, looked up directly: caustics are focused, high-frequency
//! light that neither shadow rays (glass blocks them) nor final gathering (a gather
//! ray would have to hit the small light through the glass) can find; photons
//! traced from the light find them, and since they are dense where the caustic is
//! bright, a k-nearest estimate there is sharp. The caustic map holds the photons of
//! the same trace as the global map whose path was specular-only
//! (`photons::trace_photon_paths`); each keeps the power it was stored with, so the
//! caustic term is the global map's estimate restricted to those paths.

use crate::host::error::Result;
use crate::host::gather::{GatherBackend, GatherParams};
use crate::host::render::lookup::gather_sorted;
use crate::host::render::photons::Photon;
use crate::host::render::renderer::{query_points, radiance, QueryPoint};
use crate::host::stages::StageTimes;
use glam::Vec3;

/// The caustic map: the photons flagged caustic, in trace order.
pub fn caustic_photons(photons: &[Photon], caustic: &[bool]) -> Vec<Photon> {
    assert_eq!(photons.len(), caustic.len(), "one flag per photon");
    photons
        .iter()
        .zip(caustic)
        .filter(|(_, &c)| c)
        .map(|(p, _)| *p)
        .collect()
}

/// Caustic radiance reflected toward the eye at each shading point, in `points`'
/// order: one lookup per point through `backend` (the caustic map over `photons`,
/// built with `params`), in Morton-sorted batches; and the photons the backend read.
/// `None` (no caustic photon in the scene) is zero everywhere.
pub fn caustic_light(
    points: &[QueryPoint],
    map: Option<(&dyn GatherBackend, &[Photon])>,
    params: &GatherParams,
    times: &mut StageTimes,
) -> Result<(Vec<Vec3>, u64)> {
    let Some((backend, photons)) = map else {
        return Ok((vec![Vec3::ZERO; points.len()], 0));
    };
    if points.is_empty() {
        return Ok((Vec::new(), 0));
    }
    let gathered = times.time("kd-tree search", || {
        gather_sorted(backend, &query_points(points), params.k)
    })?;
    let visited = gathered.iter().map(|g| g.visited as u64).sum();
    let l = times.time("other", || {
        radiance(
            points,
            photons,
            &gathered,
            params.k,
            params.radius,
            params.metric,
        )
    });
    Ok((l, visited))
}
