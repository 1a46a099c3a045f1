//! The measured workloads, built one way for every benchmark and report: the
//! paper's (§3: photons uniform on the 10-bit grid, uniform queries) and a
//! Cornell-box photon map queried at the renderer's eye-ray hits.

use photon_fpga::host::map::kdtree::{KdTree, PackedTree};
use photon_fpga::host::map::quantize::{GridPoint, Point, Quantizer};
use photon_fpga::host::render::photons::trace_photons;
use photon_fpga::host::render::scene::Scene;
use photon_fpga::host::render::{self, eye_queries, RenderSettings};
use photon_fpga::hw::config::photon_word::PhotonLayout;
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;

/// Grid points, the packed tree built from them and grid queries.
pub struct Workload {
    pub points: Vec<[u32; 3]>,
    pub tree: PackedTree,
    pub queries: Vec<[u32; 3]>,
    /// World units per grid step (1 for a workload made on the grid): a gather
    /// radius in world units becomes a bound on the grid with it.
    pub step: f64,
}

/// `photons` points uniform on `layout`'s grid and `queries` uniform queries.
pub fn uniform(layout: PhotonLayout, photons: usize, queries: usize, seed: u64) -> Workload {
    let mut r = Pcg64Mcg::seed_from_u64(seed);
    let mut point = |_| [0, 1, 2].map(|a| r.gen_range(0..=layout.coord_max(a)));
    let points: Vec<[u32; 3]> = (0..photons).map(&mut point).collect();
    let queries = (0..queries).map(&mut point).collect();
    Workload {
        tree: PackedTree::from_tree(&KdTree::build(&points), layout),
        points,
        queries,
        step: 1.0,
    }
}

/// The built-in Cornell box: the photons stored from `emitted` emitted ones (at most
/// `max_photons` of them), on a `bits`-bit grid, queried at the first diffuse hits
/// of a `side` × `side` image's eye rays (one per pixel), in pixel order. Queries
/// outside the photons' box (none in this scene) are left out.
pub fn cornell(emitted: usize, max_photons: usize, bits: u32, side: u32, seed: u64) -> Workload {
    let settings = RenderSettings {
        width: side,
        height: side,
        spp: 1,
        seed,
        ..RenderSettings::default()
    };
    cornell_image(emitted, max_photons, bits, &settings)
}

/// [`cornell`] for any image: every eye-ray query of `settings` (size, samples
/// per pixel, seed), e.g. the direct render's whole stream.
pub fn cornell_image(
    emitted: usize,
    max_photons: usize,
    bits: u32,
    settings: &RenderSettings,
) -> Workload {
    cornell_image_pixels(emitted, max_photons, bits, settings).0
}

/// [`cornell_image`] and the pixel of each of its queries (the bank model replays
/// the stream in image orders).
pub fn cornell_image_pixels(
    emitted: usize,
    max_photons: usize,
    bits: u32,
    settings: &RenderSettings,
) -> (Workload, Vec<u32>) {
    cornell_on(emitted, max_photons, settings, |world| {
        Quantizer::from_points(world, bits)
    })
}

/// [`cornell_image`] quantized onto exactly `layout` (a fixed core's grid,
/// `Quantizer::for_layout`).
pub fn cornell_image_on(
    emitted: usize,
    layout: PhotonLayout,
    settings: &RenderSettings,
) -> Workload {
    cornell_on(emitted, usize::MAX, settings, |world| {
        Quantizer::for_layout(world, layout)
    })
    .0
}

fn cornell_on(
    emitted: usize,
    max_photons: usize,
    settings: &RenderSettings,
    grid: impl FnOnce(&[Point]) -> photon_fpga::host::error::Result<Quantizer>,
) -> (Workload, Vec<u32>) {
    let scene = Scene::cornell_box();
    let mut photons = trace_photons(&scene, emitted, settings.seed, false);
    photons.truncate(max_photons);
    let world = render::photon_points(&photons);
    let quant = grid(&world).expect("a Cornell-box photon map");
    let (eye, _) = eye_queries(&scene, settings);
    let (w, kept) = on_grid(&world, &quant, &render::query_points(&eye));
    let pixels = kept.into_iter().map(|i| eye[i].pixel).collect();
    (w, pixels)
}

/// The photons `world` and the `queries` on `quant`'s grid: the packed tree, and
/// the queries inside the photons' box (none of the renderer's fall outside it)
/// with the index in `queries` of each one kept.
pub fn on_grid(world: &[Point], quant: &Quantizer, queries: &[Point]) -> (Workload, Vec<usize>) {
    let points: Vec<[u32; 3]> = world.iter().map(|&p| quant.quantize(p)).collect();
    let (queries, kept) = queries
        .iter()
        .enumerate()
        .filter_map(|(i, &q)| match quant.grid(q) {
            Ok(GridPoint::Inside(c)) => Some((c, i)),
            _ => None,
        })
        .unzip();
    let w = Workload {
        tree: PackedTree::from_tree(&KdTree::build(&points), quant.layout),
        points,
        queries,
        step: quant.step,
    };
    (w, kept)
}
