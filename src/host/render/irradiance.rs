//! Precomputed irradiance for final gathering (Christensen, "Faster Photon Map
//! Global Illumination", Journal of Graphics Tools 4(3), 1999): the alternative to
//! a k-nearest density estimate at every gather-ray hit
//! (`render --method two-pass-irradiance`).
//!
//! Before the eye pass, irradiance is estimated once at a subset of the photon
//! positions (every [`IRRADIANCE_STRIDE`]-th photon) from the global map, with the
//! surface normal there: a radius-capped k-nearest lookup each. Each gather ray
//! then reads the *nearest* of those irradiance points (a radius-capped 1-nearest
//! lookup) instead of k photons, and its radiance is the hit's albedo times that
//! point's E / π.
//!
//! Why it can pay: a final gather makes tens of lookups per shading point, far more
//! than there are photons, and each k-nearest lookup reads ~100 photons; the
//! precomputation makes one k-nearest lookup per irradiance point, and the gather's
//! 1-nearest lookups read a fraction of that. What it costs: the irradiance is
//! piecewise constant over the irradiance points' Voronoi cells (Christensen's
//! approximation), one diffuse bounce away from the eye, where the final gather
//! averages it over many rays.
//!
//! Every lookup (the precomputation's and the gather's) goes through the chosen
//! gather backend in Morton-sorted batches (`lookup.rs`), as every other lookup of
//! the two-pass render.

use crate::host::error::Result;
use crate::host::gather::{GatherBackend, GatherParams, Gathered};
use crate::host::map::quantize::Point;
use crate::host::render::lookup::gather_sorted;
use crate::host::render::photons::Photon;
use crate::host::render::renderer::{query_points, radiance, QueryPoint};
use crate::host::render::scene::{facing, Material, Ray, Scene};
use crate::host::stages::StageTimes;
use glam::Vec3;
use rayon::prelude::*;

/// Irradiance is precomputed at every this-many-th photon of the global map (a
/// quarter of them): Christensen precomputes at a subset of the photon positions,
/// dense enough that the nearest one stands for a gather hit.
pub const IRRADIANCE_STRIDE: usize = 4;

/// Irradiance points a gather lookup asks for: the nearest one (Christensen).
pub const IRRADIANCE_K: usize = 1;

/// The precomputed irradiance: per point (a photon position) its position, the
/// unit normal of the surface there (on the side the photons arrived from), and
/// E / π, the radiance a white Lambertian surface there reflects.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct IrradianceMap {
    pub points: Vec<Point>,
    pub normals: Vec<Vec3>,
    pub radiosity: Vec<Vec3>,
}

/// The normal of the surface photon `p` is stored on, turned toward the side it
/// arrived from: the photon record keeps position, power and direction only
/// (Jensen's), so the surface is found again by stepping back along the photon's
/// flight and re-hitting the diffuse surfaces (photons are stored on no other).
/// Of those, the one hit nearest the photon: where another surface touches the
/// photon's (a sphere resting on the floor), the first one hit may not be it.
/// `None` if no diffuse surface is hit there.
pub fn photon_normal(scene: &Scene, p: &Photon) -> Option<Vec3> {
    let back = 8.0 * scene.epsilon;
    let ray = Ray {
        origin: p.pos - p.dir * back,
        dir: p.dir,
        eps: scene.epsilon,
    };
    let diffuse = |m: usize| matches!(scene.materials[m], Material::Diffuse { .. });
    let reach = 2.0 * back;
    let quads = scene
        .quads
        .iter()
        .filter(|(_, m)| diffuse(*m))
        .filter_map(|(q, _)| {
            let t = q.intersect(&ray, reach)?;
            Some((ray.at(t), q.normal))
        });
    let spheres = scene
        .spheres
        .iter()
        .filter(|(_, m)| diffuse(*m))
        .filter_map(|(s, _)| {
            let t = s.intersect(&ray, reach)?;
            let at = ray.at(t);
            Some((at, s.normal_at(at)))
        });
    quads
        .chain(spheres)
        .map(|(at, n)| ((at - p.pos).length(), n))
        .filter(|(d, _)| *d <= back)
        .min_by(|a, b| a.0.total_cmp(&b.0))
        .map(|(_, n)| facing(n, p.dir))
}

/// Estimate the irradiance at every [`IRRADIANCE_STRIDE`]-th photon of `photons`
/// (the global map, loaded in `global` with `params`): one radius-capped
/// k-nearest lookup each through `global`, in Morton-sorted batches (charged to
/// "kd-tree search"; the normals and estimates to "other"). Returns the map and
/// the photons the backend read.
pub fn precompute_irradiance(
    scene: &Scene,
    photons: &[Photon],
    global: &dyn GatherBackend,
    params: &GatherParams,
    times: &mut StageTimes,
) -> Result<(IrradianceMap, u64)> {
    let sites: Vec<QueryPoint> = times.time("other", || {
        photons
            .par_iter()
            .step_by(IRRADIANCE_STRIDE)
            .filter_map(|p| {
                photon_normal(scene, p).map(|normal| QueryPoint {
                    pixel: 0,
                    pos: p.pos,
                    normal,
                    albedo: Vec3::ONE,
                    weight: Vec3::ONE,
                })
            })
            .collect()
    });
    if sites.is_empty() {
        return Ok((IrradianceMap::default(), 0));
    }
    let points = query_points(&sites);
    let gathered = times.time("kd-tree search", || {
        gather_sorted(global, &points, params.k)
    })?;
    let visited = gathered.iter().map(|g| g.visited as u64).sum();
    // With albedo 1, Jensen's estimate ρ/π · ΣΦ/A is E/π.
    let radiosity = times.time("other", || {
        radiance(
            &sites,
            photons,
            &gathered,
            params.k,
            params.radius,
            params.metric,
        )
    });
    let map = IrradianceMap {
        points,
        normals: sites.iter().map(|s| s.normal).collect(),
        radiosity,
    };
    Ok((map, visited))
}

/// The gather parameters of the irradiance points' map: `params` (the global
/// map's: radius cap, grid, metric, core) asking for the [`IRRADIANCE_K`] nearest.
pub fn irradiance_params(params: &GatherParams) -> GatherParams {
    GatherParams {
        k: IRRADIANCE_K,
        ..params.clone()
    }
}

/// Radiance leaving each gather hit `hits[i]` toward the gather's origin from its
/// 1-nearest lookup `gathered[i]` in `map`: the hit's albedo times the nearest
/// irradiance point's E / π; 0 if no point lies within the cap, or the nearest
/// faces away from the hit (the other side of a thin wall: its light never
/// reaches this side, as `radiance` ignores photons arriving from behind).
pub fn irradiance_radiance(
    hits: &[QueryPoint],
    map: &IrradianceMap,
    gathered: &[Gathered],
) -> Vec<Vec3> {
    assert_eq!(hits.len(), gathered.len(), "one lookup per hit");
    hits.iter()
        .zip(gathered)
        .map(|(h, g)| match g.neighbours.first() {
            Some(n) if map.normals[n.photon as usize].dot(h.normal) >= 0.0 => {
                h.albedo * map.radiosity[n.photon as usize]
            }
            _ => Vec3::ZERO,
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::host::render::photons::trace_photons;

    /// Every photon of the Cornell box lies on a surface whose normal is found
    /// again, facing the photon's arrival.
    #[test]
    fn photon_normals_are_found_on_the_stored_surface() {
        let scene = Scene::cornell_box();
        let photons = trace_photons(&scene, 2000, 3, false);
        for p in &photons {
            let n = photon_normal(&scene, p).expect("a stored photon lies on a surface");
            assert!((n.length() - 1.0).abs() < 1e-4, "{n}");
            assert!(n.dot(p.dir) < 0.0, "{n} against {}", p.dir);
        }
    }
}
