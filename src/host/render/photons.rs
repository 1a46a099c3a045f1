//! Pass 1 of photon mapping (Jensen 1996; paper §1): shoot photons from the area
//! light, follow them through mirror and glass, and store one at every diffuse hit.
//!
//! The photon map must be bit-identical for a given seed whatever the rayon thread
//! count, because the FPGA search is checked against the software one photon index
//! by photon index. So every emitted photon draws from its own RNG, seeded from
//! (seed, photon number), and photons are traced in fixed-size chunks whose results
//! are concatenated in chunk order: scheduling can change only *when* a chunk is
//! traced, never what it produces or where it lands.

use crate::host::render::scene::{
    cosine_direction, facing, glass_scatter, reflect, Material, Ray, Scene, Surface,
};
use glam::Vec3;
use indicatif::{ProgressBar, ProgressStyle};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;
use rayon::prelude::*;

/// One stored photon.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Photon {
    pub pos: Vec3,
    /// Flux carried, per channel.
    pub power: Vec3,
    /// Incoming travel direction (unit), pointing *into* the surface.
    pub dir: Vec3,
}

/// Bounces followed per photon. Russian roulette ends diffuse paths long before
/// this; the bound catches paths trapped by total internal reflection.
pub const MAX_PHOTON_DEPTH: usize = 16;

/// Emitted photons per parallel work item: large enough to amortize scheduling,
/// small enough to balance two cores and tick the progress bar.
const CHUNK: usize = 4096;

/// SplitMix64 finalizer: decorrelates nearby seeds (photon i and i+1, or seed s and
/// s+1) before they seed the per-photon PCG.
pub fn splitmix64(mut x: u64) -> u64 {
    x = x.wrapping_add(0x9E37_79B9_7F4A_7C15);
    x = (x ^ (x >> 30)).wrapping_mul(0xBF58_476D_1CE5_E9B9);
    x = (x ^ (x >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    x ^ (x >> 31)
}

/// The RNG of stream `index` under `seed` (photon number, or pixel number for the
/// eye pass). Mixing the seed first keeps (seed, i) and (seed ^ 1, i ^ 1) apart.
pub fn stream_rng(seed: u64, index: u64) -> Pcg64Mcg {
    Pcg64Mcg::seed_from_u64(splitmix64(splitmix64(seed) ^ index))
}

/// Trace `emitted` photons from the scene's light; returns the photon map in a
/// deterministic order (by emitted photon, then by bounce).
///
/// Each photon starts at a uniform point of the light with a cosine-weighted
/// direction (the light is Lambertian) and power = light power / `emitted`, so the
/// map's total first-hit power is the light's power that reaches diffuse surfaces.
pub fn trace_photons(scene: &Scene, emitted: usize, seed: u64, progress: bool) -> Vec<Photon> {
    trace_photons_capped(scene, emitted, seed, progress, usize::MAX).expect("no cap")
}

/// [`trace_photons`] that gives up (`None`) as soon as more than `cap` photons are
/// stored, so an absurd `--photons` costs neither the memory nor the time of the
/// whole trace. Below the cap the map is exactly [`trace_photons`]'s.
pub fn trace_photons_capped(
    scene: &Scene,
    emitted: usize,
    seed: u64,
    progress: bool,
    cap: usize,
) -> Option<Vec<Photon>> {
    trace_photon_paths(scene, emitted, seed, progress, cap).map(|(photons, _)| photons)
}

/// [`trace_photons_capped`] with, per stored photon, whether it is a caustic photon:
/// one that reached this diffuse surface from the light through one or more mirror
/// or glass bounces and no diffuse one (Jensen's L S+ D paths, the caustic photon
/// map of the two-pass method). The photons are [`trace_photons_capped`]'s, bit for
/// bit: the flag is only recorded, it draws no random number.
pub fn trace_photon_paths(
    scene: &Scene,
    emitted: usize,
    seed: u64,
    progress: bool,
    cap: usize,
) -> Option<(Vec<Photon>, Vec<bool>)> {
    use std::sync::atomic::{AtomicUsize, Ordering};
    let stored_so_far = AtomicUsize::new(0);
    let chunks = emitted.div_ceil(CHUNK);
    let bar = if progress {
        // ProgressBar::new draws on stderr and hides itself when that is not a
        // terminal, so piping the output stays clean.
        let bar = ProgressBar::new(emitted as u64);
        bar.set_style(
            ProgressStyle::with_template("tracing photons {bar:40} {pos}/{len} [{elapsed}<{eta}]")
                .expect("valid template"),
        );
        bar
    } else {
        ProgressBar::hidden()
    };
    let power = scene.light.power / emitted.max(1) as f32;
    let per_chunk: Vec<(Vec<Photon>, Vec<bool>)> = (0..chunks)
        .into_par_iter()
        .map(|c| {
            let range = c * CHUNK..((c + 1) * CHUNK).min(emitted);
            if stored_so_far.load(Ordering::Relaxed) > cap {
                return (Vec::new(), Vec::new());
            }
            let mut stored = Vec::with_capacity(range.len() * 2);
            let mut caustic = Vec::with_capacity(range.len() * 2);
            for i in range.clone() {
                let mut rng = stream_rng(seed, i as u64);
                trace_one(scene, power, &mut rng, &mut stored, &mut caustic);
            }
            stored_so_far.fetch_add(stored.len(), Ordering::Relaxed);
            bar.inc(range.len() as u64);
            (stored, caustic)
        })
        .collect();
    bar.finish_and_clear();
    if stored_so_far.into_inner() > cap {
        return None;
    }
    let (photons, caustic): (Vec<Vec<Photon>>, Vec<Vec<bool>>) = per_chunk.into_iter().unzip();
    Some((photons.concat(), caustic.concat()))
}

/// Follow one photon, appending a photon to `stored` at every diffuse hit and to
/// `caustic` whether its path so far was specular only (see [`trace_photon_paths`]).
fn trace_one(
    scene: &Scene,
    mut power: Vec3,
    rng: &mut Pcg64Mcg,
    stored: &mut Vec<Photon>,
    caustic: &mut Vec<bool>,
) {
    let light = &scene.light;
    let origin = light.quad.point(rng.gen(), rng.gen());
    let dir = cosine_direction(light.quad.normal, rng.gen(), rng.gen());
    let mut ray = Ray::spawn(origin, light.quad.normal, dir, scene.epsilon);
    // (specular bounce seen, diffuse bounce seen) since the light.
    let (mut specular, mut diffuse) = (false, false);
    for _ in 0..MAX_PHOTON_DEPTH {
        let Some(hit) = scene.intersect(&ray) else {
            // Escaped through the open side of the scene.
            return;
        };
        let material = match hit.surface {
            // The light's housing absorbs: a one-sided emitter has a black back,
            // and its front neither reflects nor re-emits.
            Surface::Light => return,
            Surface::Material(m) => scene.materials[m],
        };
        let new_dir = match material {
            Material::Diffuse { albedo } => {
                stored.push(Photon {
                    pos: hit.pos,
                    power,
                    dir: ray.dir,
                });
                caustic.push(specular && !diffuse);
                diffuse = true;
                // Russian roulette: survive with p = max albedo and divide by p,
                // which keeps the expected reflected flux at albedo × power while
                // ending paths early where the surface absorbs much.
                let survive = albedo.max_element();
                if survive <= 0.0 || rng.gen::<f32>() >= survive {
                    return;
                }
                power *= albedo / survive;
                // Diffuse bounce leaves on the side the photon arrived from.
                let n = facing(hit.normal, ray.dir);
                cosine_direction(n, rng.gen(), rng.gen())
            }
            Material::Mirror => {
                specular = true;
                reflect(ray.dir, hit.normal)
            }
            Material::Glass { ior } => {
                specular = true;
                glass_scatter(ray.dir, hit.normal, ior, rng.gen())
            }
        };
        ray = Ray::spawn(hit.pos, hit.normal, new_dir, scene.epsilon);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A closed unit box of one diffuse material, light just below the ceiling,
    /// with an optional sphere of another material in the middle.
    fn closed_box(albedo: f64, sphere: Option<&str>) -> Scene {
        let mut text = format!(
            r#"
[camera]
position = [0.5, 0.5, 0.9]
look_at = [0.5, 0.5, 0.0]
up = [0.0, 1.0, 0.0]
fov_deg = 60.0
[materials.wall]
type = "diffuse"
rgb = [{albedo}, {albedo}, {albedo}]
[materials.mirror]
type = "mirror"
[materials.glass]
type = "glass"
ior = 1.5
[light]
corner = [0.4, 0.99, 0.4]
edge_u = [0.2, 0.0, 0.0]
edge_v = [0.0, 0.0, 0.2]
power = [3.0, 2.0, 1.0]
"#
        );
        let faces = [
            ([0, 0, 0], [1, 0, 0], [0, 0, 1]),
            ([0, 1, 0], [1, 0, 0], [0, 0, 1]),
            ([0, 0, 0], [1, 0, 0], [0, 1, 0]),
            ([0, 0, 1], [1, 0, 0], [0, 1, 0]),
            ([0, 0, 0], [0, 0, 1], [0, 1, 0]),
            ([1, 0, 0], [0, 0, 1], [0, 1, 0]),
        ];
        // Integer coordinates on purpose: the format accepts them as floats.
        for (c, u, v) in faces {
            text += &format!(
                "[[quad]]\ncorner = {c:?}\nedge_u = {u:?}\nedge_v = {v:?}\nmaterial = \"wall\"\n"
            );
        }
        if let Some(m) = sphere {
            text += &format!(
                "[[sphere]]\ncenter = [0.5, 0.3, 0.5]\nradius = 0.25\nmaterial = \"{m}\"\n"
            );
        }
        Scene::from_toml_str(&text, "box.toml").unwrap()
    }

    fn total_power(photons: &[Photon]) -> [f64; 3] {
        let mut sum = [0.0f64; 3];
        for p in photons {
            for (s, c) in sum.iter_mut().zip(p.power.to_array()) {
                *s += c as f64;
            }
        }
        sum
    }

    fn bits(photons: &[Photon]) -> Vec<[u32; 9]> {
        photons
            .iter()
            .map(|p| {
                let mut b = [0u32; 9];
                for (i, v) in p
                    .pos
                    .to_array()
                    .into_iter()
                    .chain(p.power.to_array())
                    .chain(p.dir.to_array())
                    .enumerate()
                {
                    b[i] = v.to_bits();
                }
                b
            })
            .collect()
    }

    #[test]
    fn same_seed_same_photons_for_any_thread_count() {
        let scene = Scene::cornell_box();
        // Not a multiple of the chunk size, so the short last chunk is covered.
        let n = 3 * CHUNK + 123;
        let run = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            pool.install(|| trace_photons(&scene, n, 42, false))
        };
        let one = run(1);
        let two = run(2);
        let three = run(3);
        assert!(one.len() > n / 2);
        assert_eq!(bits(&one), bits(&two));
        assert_eq!(bits(&one), bits(&three));
        // A different seed gives a different map.
        let other = trace_photons(&scene, n, 43, false);
        assert_ne!(bits(&one), bits(&other));
    }

    #[test]
    fn black_box_stores_exactly_the_light_power_once() {
        // Albedo 0: every photon is stored at its first hit and absorbed; in a
        // closed box every photon hits a wall, so the map holds the full power.
        let scene = closed_box(0.0, None);
        let n = 20_000;
        let photons = trace_photons(&scene, n, 7, false);
        assert_eq!(photons.len(), n);
        let total = total_power(&photons);
        for (t, p) in total.iter().zip([3.0, 2.0, 1.0]) {
            assert!((t - p).abs() < 1e-4 * p, "{total:?}");
        }
        // Every photon travels away from the light (downward) on its first flight
        // or sideways; none can arrive from above the light plane.
        assert!(photons.iter().all(|p| p.dir.y <= 0.0));
    }

    #[test]
    fn grey_box_stores_geometric_series_of_bounces() {
        // Walls of albedo a in a closed box: the light's power P arrives once, a·P
        // after one bounce, a²·P after two, ... (minus what the small light's
        // housing absorbs, a fraction of its area 0.04 out of the box's ~6), so the
        // stored total is P / (1 − a) up to that and Monte Carlo noise.
        let a = 0.5;
        let scene = closed_box(a, None);
        let photons = trace_photons(&scene, 40_000, 11, false);
        let total = total_power(&photons);
        for (t, p) in total.iter().zip([3.0, 2.0, 1.0]) {
            let expected = p / (1.0 - a);
            assert!(
                (t - expected).abs() < 0.03 * expected,
                "{t} vs {expected} ({total:?})"
            );
        }
    }

    #[test]
    fn specular_spheres_conserve_power() {
        // With black walls, whatever passes through or bounces off a mirror or
        // glass sphere must still land on a wall exactly once: lossless specular
        // transport keeps the total at the light's power.
        for m in ["mirror", "glass"] {
            let scene = closed_box(0.0, Some(m));
            let n = 20_000;
            let photons = trace_photons(&scene, n, 3, false);
            let total = total_power(&photons);
            // A photon may be lost only to the light's housing or the depth bound.
            assert!(photons.len() <= n);
            assert!(
                photons.len() as f64 > 0.98 * n as f64,
                "{m}: {}",
                photons.len()
            );
            for (t, p) in total.iter().zip([3.0, 2.0, 1.0]) {
                assert!((t - p).abs() < 0.02 * p, "{m}: {total:?}");
            }
        }
    }

    #[test]
    fn light_emits_cosine_weighted_downward() {
        // In the black box every stored photon is a first hit, so its direction is
        // the emitted one; the mean cosine to the light normal of a cosine-weighted
        // hemisphere is 2/3 (∫cos²/∫cos over the hemisphere).
        let scene = closed_box(0.0, None);
        let photons = trace_photons(&scene, 20_000, 5, false);
        let mean_cos: f64 =
            photons.iter().map(|p| -p.dir.y as f64).sum::<f64>() / photons.len() as f64;
        assert!((mean_cos - 2.0 / 3.0).abs() < 0.01, "{mean_cos}");
    }
}
