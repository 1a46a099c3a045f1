//! The lookups of Jensen's two-pass render (`render --method two-pass`) as a
//! measured workload: the final gathers that dominate it (Fig. 2's search stage,
//! tens of lookups per shading point), recorded as the renderer asks them and put on
//! the global map's grid, so the core is measured on the stream a photon mapper
//! really gives it rather than on eye-ray hits alone; and the 1-nearest lookups of
//! its precomputed-irradiance variant (`render --method two-pass-irradiance`).

use crate::workload::{on_grid, Workload};
use photon_fpga::host::error::Result;
use photon_fpga::host::gather::{make_backend, BackendKind, GatherBackend, GatherParams, Gathered};
use photon_fpga::host::map::quantize::{Point, Quantizer};
use photon_fpga::host::render::final_gather::{indirect_light, GatherMap};
use photon_fpga::host::render::irradiance::{irradiance_params, precompute_irradiance};
use photon_fpga::host::render::photons::{trace_photons, Photon};
use photon_fpga::host::render::scene::Scene;
use photon_fpga::host::render::two_pass::default_radius;
use photon_fpga::host::render::{self, eye_queries, RenderSettings};
use photon_fpga::host::stages::StageTimes;
use photon_fpga::hw::sim::native::SimOptions;
use std::sync::Mutex;

/// A gather backend that answers as `inner` and keeps every query it was asked,
/// in the order asked.
struct Recorder {
    inner: Box<dyn GatherBackend>,
    asked: Mutex<Vec<Point>>,
}

impl GatherBackend for Recorder {
    fn name(&self) -> &'static str {
        self.inner.name()
    }
    fn gather(&self, queries: &[Point]) -> Result<Vec<Gathered>> {
        self.asked
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .extend_from_slice(queries);
        self.inner.gather(queries)
    }
}

/// The Cornell box's global map of `emitted` emitted photons (the render's photon
/// pass, seeded as `settings`), their positions, and the render's radius-capped
/// `k`-nearest gather parameters (its default cap, `two_pass::default_radius`).
fn global_map(
    emitted: usize,
    settings: &RenderSettings,
    k: usize,
) -> (Scene, Vec<Photon>, Vec<Point>, GatherParams) {
    let scene = Scene::cornell_box();
    let photons = trace_photons(&scene, emitted, settings.seed, false);
    let world = render::photon_points(&photons);
    let params = GatherParams {
        k,
        radius: Some(default_radius(&photons)),
        ..GatherParams::default()
    };
    (scene, photons, world, params)
}

/// The queries `recorder` was asked, on the grid of `bits` bits over `points`.
fn asked_on_grid(recorder: Recorder, points: &[Point], bits: u32) -> Result<Workload> {
    let quant = Quantizer::from_points(points, bits)?;
    let asked = recorder
        .asked
        .into_inner()
        .unwrap_or_else(|e| e.into_inner());
    Ok(on_grid(points, &quant, &asked).0)
}

/// The Cornell box's final-gather lookups: `gather_rays` per eye hit of
/// `settings`' image (as `render --method two-pass --gather-rays N` asks them, in
/// its batches' Morton order), on a `bits`-bit grid over the global map of
/// `emitted` emitted photons; and the render's lookup radius in world units (its
/// default cap, `two_pass::default_radius`).
pub fn cornell_final_gathers(
    emitted: usize,
    bits: u32,
    settings: &RenderSettings,
    gather_rays: u32,
    k: usize,
) -> Result<(Workload, f64)> {
    let (scene, photons, world, params) = global_map(emitted, settings, k);
    let recorder = Recorder {
        inner: make_backend(BackendKind::Sw, &world, &params, &SimOptions::default())?,
        asked: Mutex::new(Vec::new()),
    };
    let (eye, _) = eye_queries(&scene, settings);
    let mut times = StageTimes::default();
    indirect_light(
        &scene,
        &eye,
        gather_rays,
        settings.seed,
        GatherMap::Photons(&recorder, &photons),
        &params,
        &mut times,
    )?;
    let radius = params.radius.unwrap_or_default();
    Ok((asked_on_grid(recorder, &world, bits)?, radius))
}

/// The Cornell box's final-gather lookups as `render --method two-pass-irradiance
/// --gather-rays N` asks them: irradiance precomputed at every 4th photon of the
/// global map of `emitted` emitted photons (radius-capped `k`-nearest lookups, the
/// render's k), then `gather_rays` 1-nearest lookups per eye hit of `settings`'
/// image in those irradiance points (Christensen 1999), on a `bits`-bit grid over
/// the irradiance points; and the render's lookup radius in world units.
pub fn cornell_irradiance_gathers(
    emitted: usize,
    bits: u32,
    settings: &RenderSettings,
    gather_rays: u32,
    k: usize,
) -> Result<(Workload, f64)> {
    let (scene, photons, world, params) = global_map(emitted, settings, k);
    let sim = SimOptions::default();
    let global = make_backend(BackendKind::Sw, &world, &params, &sim)?;
    let mut times = StageTimes::default();
    let (map, _) = precompute_irradiance(&scene, &photons, global.as_ref(), &params, &mut times)?;
    let recorder = Recorder {
        inner: make_backend(
            BackendKind::Sw,
            &map.points,
            &irradiance_params(&params),
            &sim,
        )?,
        asked: Mutex::new(Vec::new()),
    };
    let (eye, _) = eye_queries(&scene, settings);
    indirect_light(
        &scene,
        &eye,
        gather_rays,
        settings.seed,
        GatherMap::Irradiance(&recorder, &map),
        &params,
        &mut times,
    )?;
    let radius = params.radius.unwrap_or_default();
    Ok((asked_on_grid(recorder, &map.points, bits)?, radius))
}
