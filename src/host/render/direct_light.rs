//! Direct illumination of the two-pass method (Jensen 1996; Jensen, "Realistic
//! Image Synthesis Using Photon Mapping", 2001, ch. 9 "A practical two-pass
//! algorithm", direct illumination): light arriving at a diffuse shading point
//! straight from the area light, by shadow rays to points sampled on the light.
//!
//! Why not from the photon map: direct light holds the sharpest features of the
//! image (shadow edges, the bright falloff under the light), which a density
//! estimate blurs over its gather radius; a few shadow rays resolve them exactly
//! in expectation, which is why photon mappers compute this term by ray tracing.
//!
//! The estimator, for a Lambertian point x of albedo ρ and normal n, a light quad
//! of area A, normal n_l and radiance L_e: with S points y_s on the light,
//! stratified over an s × s grid of its parameter square (pdf 1/A each),
//!
//!   L_d(x) = ρ/π · L_e · (A/S) · Σ_s V(x, y_s) · cos θ_x · cos θ_l / |y_s − x|²
//!
//! where cos θ_x = n·ω, cos θ_l = −n_l·ω (the light emits on its normal's side
//! only) and V is 1 when the first thing the shadow ray meets is the light. Glass
//! blocks shadow rays: light focused through it is the caustic map's term.

use crate::host::render::photons::stream_rng;
use crate::host::render::renderer::QueryPoint;
use crate::host::render::scene::{Ray, Scene, Surface};
use glam::Vec3;
use rand::Rng;
use rayon::prelude::*;

/// Strata per side of the light's parameter square: 2 × 2 = 4 shadow rays per
/// shading point; stratification keeps the penumbra's noise low for their cost.
pub const LIGHT_STRATA: u32 = 2;

/// Seed-stream offset of the shadow rays' RNGs (one stream per shading point),
/// apart from the photon, eye and final-gather streams.
const SHADOW_STREAM: u64 = 0x5AD_0000_0000_0000;

/// Direct radiance reflected toward the eye at each shading point, in `points`'
/// order; point i draws from its own RNG stream (seed, i), so the result does not
/// depend on the thread count.
pub fn direct_light(scene: &Scene, points: &[QueryPoint], seed: u64) -> Vec<Vec3> {
    points
        .par_iter()
        .enumerate()
        .map(|(i, q)| {
            let mut rng = stream_rng(seed ^ SHADOW_STREAM, i as u64);
            direct_at(scene, q, &mut rng)
        })
        .collect()
}

fn direct_at(scene: &Scene, q: &QueryPoint, rng: &mut impl Rng) -> Vec3 {
    let light = &scene.light;
    let strata = LIGHT_STRATA;
    let mut sum = 0.0f32;
    for j in 0..strata {
        for i in 0..strata {
            let s = (i as f32 + rng.gen::<f32>()) / strata as f32;
            let t = (j as f32 + rng.gen::<f32>()) / strata as f32;
            let y = light.quad.point(s, t);
            let to_light = y - q.pos;
            let d2 = to_light.length_squared();
            if d2 <= 0.0 {
                continue;
            }
            let w = to_light / d2.sqrt();
            let cos_x = q.normal.dot(w);
            let cos_l = -light.quad.normal.dot(w);
            if cos_x <= 0.0 || cos_l <= 0.0 {
                continue;
            }
            let ray = Ray::spawn(q.pos, q.normal, w, scene.epsilon);
            let visible = scene
                .intersect(&ray)
                .is_some_and(|h| h.surface == Surface::Light);
            if visible {
                sum += cos_x * cos_l / d2;
            }
        }
    }
    let samples = (strata * strata) as f32;
    q.albedo * light.radiance() * (std::f32::consts::FRAC_1_PI * light.quad.area * sum / samples)
}
