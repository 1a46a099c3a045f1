//! An independent reference for the renders: a plain path tracer with next-event
//! estimation on the area light, no photons, no density estimation (unbiased; it
//! converges to the scene's true radiance as samples grow). It shares only the
//! scene's intersection and the specular scattering with the renderer under test.
//! Beside it, the comparisons against it: the error measure, the reflected part of
//! a render, and the paper's direct render at matched lookups.

use glam::Vec3;
use photon_fpga::host::gather::{FloatBackend, GatherParams};
use photon_fpga::host::render::photons::Photon;
use photon_fpga::host::render::scene::{glass_scatter, reflect, Material, Ray, Scene, Surface};
use photon_fpga::host::render::{
    eye_queries, photon_points, render_image, RenderMethod, RenderSettings,
};
use photon_fpga::host::stages::StageTimes;
use rand::{Rng, SeedableRng};
use rayon::prelude::*;

/// Uniform-disk-projected cosine direction around `n` (written here, not taken from
/// the renderer).
fn cosine_dir(n: Vec3, rng: &mut impl Rng) -> Vec3 {
    let a = if n.x.abs() > 0.9 { Vec3::Y } else { Vec3::X };
    let t = n.cross(a).normalize();
    let b = n.cross(t);
    let (u1, u2): (f32, f32) = (rng.gen(), rng.gen());
    let r = u1.sqrt();
    let phi = std::f32::consts::TAU * u2;
    (t * (r * phi.cos()) + b * (r * phi.sin()) + n * (1.0 - u1).max(0.0).sqrt()).normalize()
}

/// Light reaching diffuse point `x` (normal `n`) straight from one uniform point of
/// the light, as outgoing radiance per unit albedo.
fn next_event(scene: &Scene, x: Vec3, n: Vec3, rng: &mut impl Rng) -> Vec3 {
    let light = &scene.light;
    let y = light.quad.point(rng.gen(), rng.gen());
    let d = y - x;
    let d2 = d.length_squared();
    let w = d / d2.sqrt();
    let (cos_x, cos_l) = (n.dot(w), -light.quad.normal.dot(w));
    if cos_x <= 0.0 || cos_l <= 0.0 {
        return Vec3::ZERO;
    }
    let ray = Ray::spawn(x, n, w, scene.epsilon);
    match scene.intersect(&ray) {
        Some(h) if h.surface == Surface::Light => {
            light.radiance() * (cos_x * cos_l * light.quad.area / d2 / std::f32::consts::PI)
        }
        _ => Vec3::ZERO,
    }
}

/// One path's reflected radiance. Emission is counted where next-event estimation
/// could not have found it: after a diffuse vertex and then a mirror or glass
/// bounce (glass and mirrors block or redirect shadow rays).
fn radiance(scene: &Scene, mut ray: Ray, max_diffuse: usize, rng: &mut impl Rng) -> Vec3 {
    // The emission seen along the eye path before any diffuse vertex is left out:
    // it is the renderers' `emitted`, the same in every method, and its
    // antialiasing noise at the light's edges would swamp the comparison.
    let (mut l, mut thr) = (Vec3::ZERO, Vec3::ONE);
    let mut count_emission = false;
    let mut diffuse = 0;
    for depth in 0..64 {
        let Some(hit) = scene.intersect(&ray) else {
            break;
        };
        let m = match hit.surface {
            Surface::Light => {
                if count_emission && ray.dir.dot(scene.light.quad.normal) < 0.0 {
                    l += thr * scene.light.radiance();
                }
                break;
            }
            Surface::Material(m) => scene.materials[m],
        };
        let dir = match m {
            Material::Diffuse { albedo } => {
                let n = if hit.normal.dot(ray.dir) < 0.0 {
                    hit.normal
                } else {
                    -hit.normal
                };
                l += thr * albedo * next_event(scene, hit.pos, n, rng);
                diffuse += 1;
                if diffuse == max_diffuse {
                    break;
                }
                // Cosine sampling: f·cos/pdf = albedo.
                thr *= albedo;
                if depth >= 3 {
                    let p = thr.max_element().min(0.95);
                    if p <= 0.0 || rng.gen::<f32>() >= p {
                        break;
                    }
                    thr /= p;
                }
                count_emission = false;
                cosine_dir(n, rng)
            }
            Material::Mirror => {
                count_emission = diffuse > 0;
                reflect(ray.dir, hit.normal)
            }
            Material::Glass { ior } => {
                count_emission = diffuse > 0;
                glass_scatter(ray.dir, hit.normal, ior, rng.gen())
            }
        };
        ray = Ray::spawn(hit.pos, hit.normal, dir, scene.epsilon);
    }
    l
}

/// Linear reflected radiance (no emission seen before the first diffuse vertex) of each pixel, row by row, from `spp` jittered paths, each
/// ended after its `max_diffuse`-th diffuse vertex.
pub fn path_trace(
    scene: &Scene,
    w: u32,
    h: u32,
    spp: u32,
    seed: u64,
    max_diffuse: usize,
) -> Vec<Vec3> {
    let aspect = w as f32 / h as f32;
    (0..w * h)
        .into_par_iter()
        .map(|p| {
            let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(seed.wrapping_mul(1 << 32) ^ p as u64);
            let (x, y) = (p % w, p / w);
            let mut sum = Vec3::ZERO;
            for _ in 0..spp {
                let fx = (x as f32 + rng.gen::<f32>()) / w as f32;
                let fy = (y as f32 + rng.gen::<f32>()) / h as f32;
                sum += radiance(
                    scene,
                    scene.camera.ray(fx, fy, aspect),
                    max_diffuse,
                    &mut rng,
                );
            }
            sum / spp as f32
        })
        .collect()
}

/// Relative RMS error of linear radiance against `reference`, over all channels.
pub fn rel_rmse(img: &[Vec3], reference: &[Vec3]) -> f64 {
    let (mut err, mut norm) = (0.0f64, 0.0f64);
    for (a, b) in img.iter().zip(reference) {
        for c in 0..3 {
            err += ((a[c] - b[c]) as f64).powi(2);
            norm += (b[c] as f64).powi(2);
        }
    }
    (err / norm).sqrt()
}

/// Each pixel's reflected radiance: `linear` less the emission its eye paths saw
/// before any diffuse point (the same in every method; the reference leaves it out,
/// since the light's antialiasing noise at its edges would swamp the comparison).
pub fn reflected(scene: &Scene, settings: &RenderSettings, linear: &[Vec3]) -> Vec<Vec3> {
    let (_, emitted) = eye_queries(scene, settings);
    linear.iter().zip(&emitted).map(|(l, e)| *l - *e).collect()
}

/// The paper's direct render of `photons` (k = 32 unbounded float gathers, seed
/// 2) at no fewer eye queries than `lookups` (eye samples that escape make no
/// query: a few more samples than lookups): its rel. RMSE against `reference`
/// and its samples per pixel.
pub fn direct_error_at(
    scene: &Scene,
    photons: &[Photon],
    (w, h): (u32, u32),
    lookups: u64,
    reference: &[Vec3],
) -> (f64, u32) {
    let spp = (1.05 * lookups as f64 / (w * h) as f64).ceil() as u32;
    let direct = RenderSettings {
        width: w,
        height: h,
        spp,
        seed: 2,
        method: RenderMethod::Direct,
        ..RenderSettings::default()
    };
    let unbounded = GatherParams {
        k: 32,
        ..GatherParams::default()
    };
    let map = FloatBackend::new(&photon_points(photons), &unbounded).unwrap();
    let mut t = StageTimes::default();
    let pass = render_image(scene, &direct, photons, &map, &unbounded, &mut t).unwrap();
    assert!(
        pass.queries as u64 >= lookups,
        "{} < {lookups}",
        pass.queries
    );
    let e = rel_rmse(&reflected(scene, &direct, &pass.linear), reference);
    (e, spp)
}

/// An image's total light (the sum of every pixel's channels).
pub fn total_light(v: &[Vec3]) -> f64 {
    v.iter().map(|c| c.element_sum() as f64).sum()
}
