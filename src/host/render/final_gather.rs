//! Indirect diffuse light of the two-pass method by final gathering (Jensen 1996;
//! Jensen, "Realistic Image Synthesis Using Photon Mapping", 2001, ch. 9, multiple
//! diffuse reflections): N cosine-weighted gather rays leave each shading point,
//! and the radiance each brings back is the global photon map's density estimate
//! at its first diffuse hit, a radius-capped k-nearest lookup through the gather
//! backend.
//!
//! Why gather instead of reading the map at the shading point: the density estimate
//! is blurred and blotchy at the scale of its gather radius; seen one diffuse bounce
//! away and averaged over N directions, that low-frequency error is integrated out,
//! which is what makes the photon map usable for final images.
//!
//! # The estimator
//! At a Lambertian point x (albedo ρ, normal n) the indirect term is
//! L_i(x) = ρ/π ∫ L(y(ω) → x) cos θ dω. With N directions ω_j drawn with pdf
//! cos θ / π, the estimate is L_i(x) ≈ ρ · (1/N) Σ_j L(y_j → x).
//!
//! What each gather ray counts, so that with the direct and caustic terms every
//! light path is counted exactly once (Jensen's split of the reflected radiance):
//! * it hits the light, directly or through mirrors and glass: 0. Directly, that is
//!   the direct term (shadow rays, `direct_light.rs`); through specular bounces,
//!   the L S+ D path is a caustic, the caustic map's term (`caustics.rs`).
//! * it hits a diffuse point y, directly or through mirrors and glass (which are
//!   white and Fresnel-sampled, so the throughput stays 1): the global map's
//!   estimate of all light leaving y toward x. All of it, the photons that came
//!   straight from the light included: every such path bounces diffusely at y
//!   before reaching x, so none of them is direct or caustic light at x.
//! * it escapes: 0.
//!
//! The estimate at y is either the global map's k-nearest density estimate
//! (Jensen) or the nearest precomputed irradiance point's (Christensen 1999,
//! `irradiance.rs`): [`GatherMap`].

use crate::host::error::Result;
use crate::host::gather::{GatherBackend, GatherParams};
use crate::host::render::irradiance::{irradiance_radiance, IrradianceMap, IRRADIANCE_K};
use crate::host::render::lookup::{gather_sorted, max_batch};
use crate::host::render::photons::{stream_rng, Photon};
use crate::host::render::renderer::{query_points, radiance, QueryPoint, MAX_EYE_DEPTH};
use crate::host::render::scene::{
    cosine_direction, facing, glass_scatter, reflect, Material, Ray, Scene, Surface,
};
use crate::host::stages::StageTimes;
use glam::Vec3;
use rand::Rng;
use rayon::prelude::*;

/// Seed-stream offset of the gather rays' RNGs (one stream per shading point),
/// apart from the photon, eye and shadow-ray streams.
const GATHER_STREAM: u64 = 0x6A7_0000_0000_0000;

/// What a gather ray's lookup reads at its diffuse hit, loaded in its backend.
#[derive(Clone, Copy)]
pub enum GatherMap<'a> {
    /// The global photon map: a radius-capped k-nearest density estimate
    /// (`GatherParams::k`) at each hit (Jensen).
    Photons(&'a dyn GatherBackend, &'a [Photon]),
    /// Precomputed irradiance points: the nearest one within the cap (Christensen).
    Irradiance(&'a dyn GatherBackend, &'a IrradianceMap),
}

impl GatherMap<'_> {
    fn backend(&self) -> &dyn GatherBackend {
        match *self {
            GatherMap::Photons(b, _) | GatherMap::Irradiance(b, _) => b,
        }
    }

    /// Neighbours each lookup asks for.
    fn k(&self, params: &GatherParams) -> usize {
        match self {
            GatherMap::Photons(..) => params.k,
            GatherMap::Irradiance(..) => IRRADIANCE_K,
        }
    }
}

/// What the final gather did, beside the radiance.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct GatherStats {
    /// Gather rays that reached a diffuse surface: one photon lookup each.
    pub lookups: u64,
    /// Photons the backend read over those lookups.
    pub visited: u64,
}

/// The first diffuse hit of a gather ray leaving `x` in direction `dir`, through
/// mirrors and glass; `None` if it meets the light or escapes (see the module
/// notes for why both count 0).
pub fn gather_hit(
    scene: &Scene,
    x: &QueryPoint,
    dir: Vec3,
    rng: &mut impl Rng,
) -> Option<DiffuseHit> {
    let mut ray = Ray::spawn(x.pos, x.normal, dir, scene.epsilon);
    for _ in 0..MAX_EYE_DEPTH {
        let hit = scene.intersect(&ray)?;
        let material = match hit.surface {
            Surface::Light => return None,
            Surface::Material(m) => scene.materials[m],
        };
        let new_dir = match material {
            Material::Diffuse { albedo } => {
                let normal = facing(hit.normal, ray.dir);
                return Some(DiffuseHit {
                    pos: hit.pos,
                    normal,
                    albedo,
                });
            }
            Material::Mirror => reflect(ray.dir, hit.normal),
            Material::Glass { ior } => glass_scatter(ray.dir, hit.normal, ior, rng.gen()),
        };
        ray = Ray::spawn(hit.pos, hit.normal, new_dir, scene.epsilon);
    }
    None
}

/// A gather ray's diffuse hit: where, facing the ray, and its albedo.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DiffuseHit {
    pub pos: Vec3,
    pub normal: Vec3,
    pub albedo: Vec3,
}

/// The diffuse hits of the `rays` gather rays of shading point `index`, in ray
/// order (`None` for the rays that count 0), from the point's own RNG stream.
fn trace_gather_rays(
    scene: &Scene,
    x: &QueryPoint,
    index: usize,
    rays: u32,
    seed: u64,
) -> Vec<Option<DiffuseHit>> {
    let mut rng = stream_rng(seed ^ GATHER_STREAM, index as u64);
    (0..rays)
        .map(|_| {
            let dir = cosine_direction(x.normal, rng.gen(), rng.gen());
            gather_hit(scene, x, dir, &mut rng)
        })
        .collect()
}

/// Indirect radiance reflected toward the eye at each shading point, in `points`'
/// order, from `rays` gather rays each; the lookups go through `map`'s backend
/// (built with `params`, its k [`GatherMap`]'s) in Morton-sorted batches of at
/// most [`max_batch`]. Ray tracing is charged to "ray emission", the lookups to
/// "kd-tree search", the estimates to "other" (paper Fig. 2's stages).
///
/// Deterministic for any thread count: each point's rays come from its own RNG
/// stream, the blocks of points are fixed, and each point sums its rays in ray
/// order.
#[allow(clippy::too_many_arguments)]
pub fn indirect_light(
    scene: &Scene,
    points: &[QueryPoint],
    rays: u32,
    seed: u64,
    map: GatherMap,
    params: &GatherParams,
    times: &mut StageTimes,
) -> Result<(Vec<Vec3>, GatherStats)> {
    let mut out = Vec::with_capacity(points.len());
    let mut stats = GatherStats::default();
    if rays == 0 {
        return Ok((vec![Vec3::ZERO; points.len()], stats));
    }
    let k = map.k(params);
    let block = (max_batch(k) / rays as usize).max(1);
    for (b, chunk) in points.chunks(block).enumerate() {
        let first = b * block;
        let hits: Vec<Vec<Option<DiffuseHit>>> = times.time("ray emission", || {
            chunk
                .par_iter()
                .enumerate()
                .map(|(i, x)| trace_gather_rays(scene, x, first + i, rays, seed))
                .collect()
        });
        // The lookups of this block as query points (`radiance` reads their
        // position, normal and albedo), and for each ray its lookup, if any.
        let mut lookups = Vec::new();
        let mut slot: Vec<Option<usize>> = Vec::with_capacity(chunk.len() * rays as usize);
        for (x, ray_hits) in chunk.iter().zip(&hits) {
            for h in ray_hits {
                slot.push(h.map(|h| {
                    lookups.push(QueryPoint {
                        pixel: x.pixel,
                        pos: h.pos,
                        normal: h.normal,
                        albedo: h.albedo,
                        weight: Vec3::ONE,
                    });
                    lookups.len() - 1
                }));
            }
        }
        if lookups.is_empty() {
            out.extend(std::iter::repeat_n(Vec3::ZERO, chunk.len()));
            continue;
        }
        let gathered = times.time("kd-tree search", || {
            gather_sorted(map.backend(), &query_points(&lookups), k)
        })?;
        stats.lookups += lookups.len() as u64;
        stats.visited += gathered.iter().map(|g| g.visited as u64).sum::<u64>();
        times.time("other", || {
            let l = match map {
                GatherMap::Photons(_, photons) => radiance(
                    &lookups,
                    photons,
                    &gathered,
                    params.k,
                    params.radius,
                    params.metric,
                ),
                GatherMap::Irradiance(_, irradiance) => {
                    irradiance_radiance(&lookups, irradiance, &gathered)
                }
            };
            let inv_n = 1.0 / rays as f32;
            for (x, rays_of_x) in chunk.iter().zip(slot.chunks(rays as usize)) {
                let mut sum = Vec3::ZERO;
                for s in rays_of_x.iter().flatten() {
                    sum += l[*s];
                }
                out.push(x.albedo * sum * inv_n);
            }
        });
    }
    Ok((out, stats))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::host::render::photons::stream_rng;

    fn floor_point(x: f32, z: f32) -> QueryPoint {
        QueryPoint {
            pixel: 0,
            pos: Vec3::new(x, 0.0, z),
            normal: Vec3::Y,
            albedo: Vec3::splat(0.75),
            weight: Vec3::ONE,
        }
    }

    #[test]
    fn gather_rays_end_at_diffuse_surfaces_and_count_nothing_from_the_light() {
        let scene = Scene::cornell_box();
        let mut rng = stream_rng(1, 0);
        // Straight up from under the light: the light, which is the direct term.
        let under = floor_point(0.5, 0.5);
        assert_eq!(gather_hit(&scene, &under, Vec3::Y, &mut rng), None);
        // Straight up elsewhere: the ceiling, its normal turned toward the ray.
        let aside = floor_point(0.1, 0.9);
        let hit = gather_hit(&scene, &aside, Vec3::Y, &mut rng).unwrap();
        assert!(
            (hit.pos - Vec3::new(0.1, 1.0, 0.9)).length() < 1e-4,
            "{hit:?}"
        );
        assert_eq!(hit.normal, -Vec3::Y);
        assert_eq!(hit.albedo, Vec3::splat(0.75));
        // At the mirror sphere's centre: reflected straight back to the floor point.
        let (mirror, _) = scene.spheres[0];
        let x = floor_point(mirror.center.x + 0.3, mirror.center.z);
        let dir = (mirror.center - x.pos).normalize();
        let back = gather_hit(&scene, &x, dir, &mut rng).unwrap();
        assert!((back.pos - x.pos).length() < 1e-3, "{back:?}");
        assert_eq!(back.normal, Vec3::Y);
    }
}
