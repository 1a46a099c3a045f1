//! Pass 2 of photon mapping (paper §1): eye rays find the query points, the photon
//! gather (software or FPGA, through `GatherBackend`) finds their neighbours, and
//! Jensen's density estimate turns those into pixel radiance.
//!
//! Everything is a pure function of its inputs and the seed: eye samples draw from a
//! per-pixel RNG, queries come out in pixel order, and radiance sums neighbours in
//! the gather's canonical order. Two backends that return the same neighbours
//! therefore produce bit-identical images, which is how the hardware is checked.

use crate::host::error::{Error, Result};
use crate::host::gather::{GatherBackend, GatherParams, Gathered};
use crate::host::map::quantize::Point;
use crate::host::output::Output;
use crate::host::render::photons::{stream_rng, Photon};
use crate::host::render::scene::{facing, glass_scatter, reflect, Material, Ray, Scene, Surface};
use crate::host::render::{l1_area::l1_section_area, lookup::gather_sorted};
use crate::host::stages::StageTimes;
use crate::hw::config::metric::Metric;
use glam::Vec3;
use rand::Rng;
use rayon::prelude::*;

/// Exposure of the default render: scales radiance before gamma. Chosen by eye for
/// the default Cornell box (light power 12 per channel): walls mid-to-light grey,
/// the caustic bright but not clipped over its whole area.
pub const DEFAULT_EXPOSURE: f32 = 0.35;

/// Eye-path bounces through mirrors and glass before giving up on a pixel sample.
pub const MAX_EYE_DEPTH: usize = 16;

/// Final-gather rays per shading point of the two-pass method: pbrt-v2's photon
/// map integrator defaults to 32; 16 with the default 4 samples per pixel gives 64
/// gather rays per pixel.
pub const DEFAULT_GATHER_RAYS: u32 = 16;

/// Seed-stream offset separating the eye pass's pixel RNGs from the photon pass's
/// per-photon RNGs, so pixel i never replays photon i's random numbers.
const EYE_STREAM: u64 = 0xE7E_0000_0000_0000;

/// How the eye pass turns photons into pixels.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
pub enum RenderMethod {
    /// The paper's method: the photon map seen directly, one k-nearest gather at
    /// each eye path's first diffuse hit.
    Direct,
    /// Jensen's two-pass method: direct light by shadow rays, caustics from a
    /// caustic map, indirect light by final gathering from the global map
    /// (docs/TWO_PASS.md).
    TwoPass,
    /// Two-pass with Christensen's precomputed irradiance: each gather ray reads
    /// the nearest of the irradiance estimates made once at a quarter of the photon
    /// positions, instead of k photons (docs/TWO_PASS.md). The default: of the
    /// three it gives the lowest error for the time (docs/two_pass.md).
    #[default]
    TwoPassIrradiance,
}

impl RenderMethod {
    /// Whether this is a two-pass method (shadow rays, caustic map, final gather).
    pub fn is_two_pass(self) -> bool {
        self != RenderMethod::Direct
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct RenderSettings {
    pub width: u32,
    pub height: u32,
    /// Eye samples per pixel.
    pub spp: u32,
    pub seed: u64,
    /// Linear scale on radiance before clamping and gamma.
    pub exposure: f32,
    pub method: RenderMethod,
    /// Final-gather rays per shading point (the two-pass methods).
    pub gather_rays: u32,
}

impl Default for RenderSettings {
    fn default() -> Self {
        RenderSettings {
            width: 256,
            height: 256,
            spp: 4,
            seed: 1,
            exposure: DEFAULT_EXPOSURE,
            method: RenderMethod::default(),
            gather_rays: DEFAULT_GATHER_RAYS,
        }
    }
}

/// Where an eye path ended on a diffuse surface: one photon gather.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct QueryPoint {
    /// Pixel index, `y * width + x`.
    pub pixel: u32,
    pub pos: Vec3,
    /// Unit surface normal on the side the eye ray arrived from.
    pub normal: Vec3,
    pub albedo: Vec3,
    /// Path throughput divided by the samples per pixel: the query's share of its
    /// pixel.
    pub weight: Vec3,
}

/// Trace `spp` jittered eye paths per pixel through mirrors and glass to their first
/// diffuse hit. Returns the queries in pixel order and, per pixel, the radiance
/// seen directly when a path reaches the light's front (already weighted; zero for
/// paths that escape or end elsewhere).
pub fn eye_queries(scene: &Scene, settings: &RenderSettings) -> (Vec<QueryPoint>, Vec<Vec3>) {
    let (w, h) = (settings.width, settings.height);
    let spp = settings.spp.max(1);
    let aspect = w as f32 / h.max(1) as f32;
    let sample_weight = 1.0 / spp as f32;
    let per_pixel: Vec<(Vec<QueryPoint>, Vec3)> = (0..w * h)
        .into_par_iter()
        .map(|pixel| {
            let mut rng = stream_rng(settings.seed ^ EYE_STREAM, pixel as u64);
            let (x, y) = (pixel % w, pixel / w);
            let mut queries = Vec::with_capacity(spp as usize);
            let mut emitted = Vec3::ZERO;
            for _ in 0..spp {
                let fx = (x as f32 + rng.gen::<f32>()) / w as f32;
                let fy = (y as f32 + rng.gen::<f32>()) / h as f32;
                let mut ray = scene.camera.ray(fx, fy, aspect);
                // Mirrors and glass are white and glass is sampled in proportion to
                // Fresnel, so the throughput stays the sample weight.
                let throughput = Vec3::splat(sample_weight);
                for _ in 0..MAX_EYE_DEPTH {
                    let Some(hit) = scene.intersect(&ray) else {
                        break;
                    };
                    let material = match hit.surface {
                        Surface::Light => {
                            if ray.dir.dot(scene.light.quad.normal) < 0.0 {
                                emitted += throughput * scene.light.radiance();
                            }
                            break;
                        }
                        Surface::Material(m) => scene.materials[m],
                    };
                    let new_dir = match material {
                        Material::Diffuse { albedo } => {
                            let normal = facing(hit.normal, ray.dir);
                            queries.push(QueryPoint {
                                pixel,
                                pos: hit.pos,
                                normal,
                                albedo,
                                weight: throughput,
                            });
                            break;
                        }
                        Material::Mirror => reflect(ray.dir, hit.normal),
                        Material::Glass { ior } => {
                            glass_scatter(ray.dir, hit.normal, ior, rng.gen())
                        }
                    };
                    ray = Ray::spawn(hit.pos, hit.normal, new_dir, scene.epsilon);
                }
            }
            (queries, emitted)
        })
        .collect();
    let mut queries = Vec::with_capacity(per_pixel.iter().map(|p| p.0.len()).sum());
    let mut emitted = Vec::with_capacity(per_pixel.len());
    for (q, e) in per_pixel {
        queries.extend(q);
        emitted.push(e);
    }
    (queries, emitted)
}

/// Photon positions as the gather backends take them.
pub fn photon_points(photons: &[Photon]) -> Vec<Point> {
    photons
        .iter()
        .map(|p| p.pos.as_dvec3().to_array())
        .collect()
}

/// Query positions as the gather backends take them.
pub fn query_points(queries: &[QueryPoint]) -> Vec<Point> {
    queries
        .iter()
        .map(|q| q.pos.as_dvec3().to_array())
        .collect()
}

/// Reflected radiance at each query from its gathered photons (Jensen's density
/// estimate): L = albedo/π · Σ Φ_p / A, where A is the area of the gather region on
/// the surface.
///
/// The region's radius is the farthest gathered photon's distance when all `k` were
/// found (the search shrank to exactly that), else `radius` when the search was
/// bounded (the region searched is the full disk even though it held fewer
/// photons), else the farthest distance. For `Metric::L2` the region cut by a plane
/// is a disk, A = πr². For `Metric::L1` the region is an octahedron, whose section
/// by the query's tangent plane is a polygon (`l1_area::l1_section_area`): the
/// diamond 2r² on axis-aligned surfaces such as the Cornell box's walls, down to
/// the regular hexagon (3√3/4)·r² ≈ 1.30·r² for the normal (1,1,1)/√3; with 2r²
/// everywhere would bias tilted surfaces dark by up to 35 %.
///
/// Only photons arriving from the query's side count (dot(dir, normal) < 0): photons
/// hitting the other face of a thin wall, or another surface behind, must not leak
/// through. Power is summed in the neighbours' canonical order, so equal gathers
/// give bit-equal radiance.
pub fn radiance(
    queries: &[QueryPoint],
    photons: &[Photon],
    gathered: &[Gathered],
    k: usize,
    radius: Option<f64>,
    metric: Metric,
) -> Vec<Vec3> {
    assert_eq!(queries.len(), gathered.len(), "one gather result per query");
    queries
        .par_iter()
        .zip(gathered)
        .map(|(q, g)| {
            let Some(farthest) = g.neighbours.last().map(|n| n.distance) else {
                return Vec3::ZERO;
            };
            let r = match radius {
                Some(r) if g.neighbours.len() < k => r,
                _ => farthest,
            };
            if r.is_nan() || r <= 0.0 {
                return Vec3::ZERO;
            }
            let area = match metric {
                Metric::L2 => std::f64::consts::PI * r * r,
                Metric::L1 => l1_section_area(q.normal.as_dvec3()) * r * r,
            };
            let mut flux = Vec3::ZERO;
            for n in &g.neighbours {
                let p = &photons[n.photon as usize];
                if p.dir.dot(q.normal) < 0.0 {
                    flux += p.power;
                }
            }
            // A region too small for f32 (area below ~1e-38) is as degenerate as
            // r = 0 (all k photons at one point): black, never inf or NaN.
            let l = q.albedo * flux * (std::f32::consts::FRAC_1_PI / area as f32);
            if l.is_finite() {
                l
            } else {
                Vec3::ZERO
            }
        })
        .collect()
}

/// Accumulate weighted query radiance and direct emission per pixel, apply
/// exposure, clamp, and encode with gamma 2.2 into 8-bit RGB.
pub fn resolve(
    width: u32,
    height: u32,
    queries: &[QueryPoint],
    radiance: &[Vec3],
    emitted: &[Vec3],
    exposure: f32,
) -> image::RgbImage {
    encode(
        width,
        height,
        &pixel_radiance(width, height, queries, radiance, emitted),
        exposure,
    )
}

/// Each pixel's linear radiance: its emission plus its queries' weighted radiance.
pub fn pixel_radiance(
    width: u32,
    height: u32,
    queries: &[QueryPoint],
    radiance: &[Vec3],
    emitted: &[Vec3],
) -> Vec<Vec3> {
    let pixels = (width * height) as usize;
    assert_eq!(emitted.len(), pixels, "one emitted value per pixel");
    assert_eq!(queries.len(), radiance.len(), "one radiance per query");
    let mut sum = emitted.to_vec();
    // Sequential, in query order: a pixel's sum has a fixed order of additions.
    for (q, l) in queries.iter().zip(radiance) {
        sum[q.pixel as usize] += q.weight * *l;
    }
    sum
}

/// Linear pixel radiance to 8-bit RGB: exposure, clamp, gamma 2.2.
pub fn encode(width: u32, height: u32, sum: &[Vec3], exposure: f32) -> image::RgbImage {
    let encode = |c: f32| {
        let v = (c * exposure).clamp(0.0, 1.0).powf(1.0 / 2.2);
        (v * 255.0 + 0.5) as u8
    };
    image::RgbImage::from_fn(width, height, |x, y| {
        let c = sum[(y * width + x) as usize];
        image::Rgb([encode(c.x), encode(c.y), encode(c.z)])
    })
}

/// What the eye pass made, beside the image.
pub struct EyePass {
    pub image: image::RgbImage,
    /// Each pixel's linear radiance, row by row (what `image` encodes).
    pub linear: Vec<Vec3>,
    /// Query points gathered (eye samples that reached a diffuse surface).
    pub queries: usize,
    /// Photons the backend read, summed over all queries.
    pub visited: u64,
}

/// The whole eye pass for a photon map already loaded into `backend`: queries,
/// gathers, radiance, image, each charged to its paper Fig. 2 stage in `times`.
/// `params` must be what the backend was built with.
pub fn render_image(
    scene: &Scene,
    settings: &RenderSettings,
    photons: &[Photon],
    backend: &dyn GatherBackend,
    params: &GatherParams,
    times: &mut StageTimes,
) -> Result<EyePass> {
    let (queries, emitted) = times.time("ray emission", || eye_queries(scene, settings));
    // Morton order, which a cache of the map rewards (`lookup.rs`); answers in pixel order.
    let points = query_points(&queries);
    let gathered = times.time("kd-tree search", || {
        gather_sorted(backend, &points, params.k)
    })?;
    let linear = times.time("other", || {
        let radiance = radiance(
            &queries,
            photons,
            &gathered,
            params.k,
            params.radius,
            params.metric,
        );
        pixel_radiance(
            settings.width,
            settings.height,
            &queries,
            &radiance,
            &emitted,
        )
    });
    let image = times.time("other", || {
        encode(settings.width, settings.height, &linear, settings.exposure)
    });
    Ok(EyePass {
        image,
        linear,
        queries: queries.len(),
        visited: gathered.iter().map(|g| g.visited as u64).sum(),
    })
}

/// Encode a PNG and write it to `out` (atomically for a file; see [`Output`]).
pub fn save_png(img: &image::RgbImage, out: &Output) -> Result<()> {
    let mut png = std::io::Cursor::new(Vec::new());
    img.write_to(&mut png, image::ImageFormat::Png)
        .map_err(|e| Error::new(format!("{}: cannot encode PNG: {e}", out.path().display())))?;
    out.write(|w| w.write_all(png.get_ref()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::host::gather::{FloatBackend, GatherParams, Neighbour, SwBackend};
    use crate::host::render::scene::Scene;

    /// Photons on a square grid of spacing `h` over [-1, 1]² in the plane z = 0,
    /// each of power `phi`, arriving from +z.
    fn photon_grid(h: f32, phi: Vec3) -> Vec<Photon> {
        let n = (2.0 / h).round() as i32;
        let mut v = Vec::new();
        for i in 0..=n {
            for j in 0..=n {
                v.push(Photon {
                    pos: Vec3::new(-1.0 + i as f32 * h, -1.0 + j as f32 * h, 0.0),
                    power: phi,
                    dir: Vec3::new(0.3, 0.0, -1.0).normalize(),
                });
            }
        }
        v
    }

    fn plane_queries() -> Vec<QueryPoint> {
        // Off-grid positions away from the grid's border.
        [(0.0031, 0.0047), (0.25, -0.33), (-0.5, 0.123)]
            .iter()
            .enumerate()
            .map(|(i, &(x, y))| QueryPoint {
                pixel: i as u32,
                pos: Vec3::new(x, y, 0.0),
                normal: Vec3::Z,
                albedo: Vec3::new(0.8, 0.5, 0.2),
                weight: Vec3::ONE,
            })
            .collect()
    }

    /// Radiance of a Lambertian plane under uniform irradiance E = Φ/h²:
    /// L = albedo · E / π.
    fn analytic(q: &QueryPoint, h: f32, phi: Vec3) -> Vec3 {
        q.albedo * phi / (h * h) / std::f32::consts::PI
    }

    fn assert_close(got: Vec3, want: Vec3, tol: f32) {
        let rel = ((got - want) / want).abs().max_element();
        assert!(rel < tol, "got {got}, want {want} (rel error {rel})");
    }

    fn check_uniform_plane(backend_kind: &str, metric: Metric) {
        let (h, phi) = (0.01, Vec3::new(1e-4, 2e-4, 3e-4));
        let photons = photon_grid(h, phi);
        let queries = plane_queries();
        let params = GatherParams {
            k: 400,
            metric,
            ..GatherParams::default()
        };
        let points = photon_points(&photons);
        let backend: Box<dyn GatherBackend> = match backend_kind {
            "float" => Box::new(FloatBackend::new(&points, &params).unwrap()),
            _ => Box::new(SwBackend::new(&points, &params).unwrap()),
        };
        let gathered = backend.gather(&query_points(&queries)).unwrap();
        let l = radiance(&queries, &photons, &gathered, params.k, None, metric);
        for (q, got) in queries.iter().zip(l) {
            assert_close(got, analytic(q, h, phi), 0.04);
        }
    }

    #[test]
    fn uniform_plane_radiance_l2_float() {
        check_uniform_plane("float", Metric::L2);
    }

    #[test]
    fn uniform_plane_radiance_l2_quantized() {
        check_uniform_plane("sw", Metric::L2);
    }

    #[test]
    fn uniform_plane_radiance_l1_diamond() {
        check_uniform_plane("float", Metric::L1);
    }

    #[test]
    fn photons_from_behind_are_ignored() {
        // Interleave a second grid arriving from −z (the back face): the k nearest
        // are half front, half back photons; counting only the front half over the
        // same disk gives the front grid's irradiance again. Counting both would
        // double it.
        let (h, phi) = (0.01, Vec3::splat(1e-4));
        let mut photons = photon_grid(h, phi);
        let back: Vec<Photon> = photons
            .iter()
            .map(|p| Photon {
                pos: p.pos + Vec3::new(0.5 * h, 0.5 * h, 0.0),
                dir: Vec3::Z,
                ..*p
            })
            .collect();
        photons.extend(back);
        let queries = plane_queries();
        let params = GatherParams {
            k: 800,
            ..GatherParams::default()
        };
        let backend = FloatBackend::new(&photon_points(&photons), &params).unwrap();
        let gathered = backend.gather(&query_points(&queries)).unwrap();
        let l = radiance(&queries, &photons, &gathered, params.k, None, Metric::L2);
        for (q, got) in queries.iter().zip(l) {
            assert_close(got, analytic(q, h, phi), 0.04);
        }
    }

    #[test]
    fn bounded_radius_with_few_photons_uses_the_radius() {
        // k larger than what the radius holds: the estimate divides by the search
        // disk π·R², not by the farthest photon's disk.
        let (h, phi) = (0.01, Vec3::splat(1e-4));
        let photons = photon_grid(h, phi);
        let queries = plane_queries();
        let params = GatherParams {
            k: 100_000,
            radius: Some(0.1),
            ..GatherParams::default()
        };
        let backend = FloatBackend::new(&photon_points(&photons), &params).unwrap();
        let gathered = backend.gather(&query_points(&queries)).unwrap();
        assert!(gathered.iter().all(|g| g.neighbours.len() < params.k));
        let l = radiance(
            &queries,
            &photons,
            &gathered,
            params.k,
            Some(0.1),
            Metric::L2,
        );
        for (q, got) in queries.iter().zip(l) {
            assert_close(got, analytic(q, h, phi), 0.03);
        }
    }

    #[test]
    fn empty_or_zero_radius_gathers_give_black() {
        let photons = photon_grid(0.5, Vec3::ONE);
        let queries = plane_queries();
        let gathered = vec![
            Gathered::default(),
            Gathered {
                neighbours: vec![Neighbour {
                    photon: 0,
                    distance: 0.0,
                }],
                visited: 1,
            },
            Gathered::default(),
        ];
        let l = radiance(&queries, &photons, &gathered, 1, None, Metric::L2);
        assert!(l.iter().all(|c| *c == Vec3::ZERO));
    }

    #[test]
    fn resolve_accumulates_weights_and_encodes_gamma() {
        let q = |pixel, w: f32| QueryPoint {
            pixel,
            pos: Vec3::ZERO,
            normal: Vec3::Z,
            albedo: Vec3::ONE,
            weight: Vec3::splat(w),
        };
        let queries = [q(0, 0.5), q(0, 0.5), q(1, 0.25)];
        let rad = [
            Vec3::new(0.2, 0.0, 4.0),
            Vec3::new(0.2, 0.0, 0.0),
            Vec3::ONE,
        ];
        let emitted = [Vec3::ZERO, Vec3::new(0.0, 0.5, 0.0)];
        let img = resolve(2, 1, &queries, &rad, &emitted, 2.0);
        // Pixel 0: red 0.2·2 = 0.4 → 0.4^(1/2.2) = 0.6589 → 168; blue 2·2 clamps.
        assert_eq!(img.get_pixel(0, 0).0, [168, 0, 255]);
        // Pixel 1: 0.25·2 = 0.5 → 0.7297 → 186; green adds emission 0.5 → 1.0.
        assert_eq!(img.get_pixel(1, 0).0, [186, 255, 186]);
    }

    #[test]
    fn eye_queries_are_thread_count_independent() {
        let scene = Scene::cornell_box();
        let settings = RenderSettings {
            width: 40,
            height: 30,
            spp: 3,
            ..RenderSettings::default()
        };
        let run = |threads| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| eye_queries(&scene, &settings))
        };
        let (q1, e1) = run(1);
        let (q2, e2) = run(2);
        assert_eq!(q1, q2);
        assert_eq!(e1, e2);
        // Pixel order, at most spp queries per pixel, normals face the camera side.
        assert!(q1.windows(2).all(|w| w[0].pixel <= w[1].pixel));
        assert!(q1.len() <= (40 * 30 * 3) as usize && q1.len() > 40 * 30);
        // The light is visible from the camera at the top of the image.
        assert!(e1.iter().any(|e| e.max_element() > 0.0));
    }

    #[test]
    fn save_png_is_atomic_and_reports_path() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out.png");
        // A user's own `out.png.tmp` is never touched.
        std::fs::write(dir.path().join("out.png.tmp"), "mine").unwrap();
        let img = image::RgbImage::from_pixel(3, 2, image::Rgb([10, 20, 30]));
        save_png(&img, &Output::check(&path, &[]).unwrap()).unwrap();
        let back = image::open(&path).unwrap().to_rgb8();
        assert_eq!(back, img);
        assert_eq!(
            std::fs::read_to_string(dir.path().join("out.png.tmp")).unwrap(),
            "mine"
        );
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 2);
        let bad = dir.path().join("missing-dir").join("x.png");
        let err = Output::check(&bad, &[]).unwrap_err().to_string();
        assert!(err.contains(&bad.display().to_string()), "{err}");
    }
}
