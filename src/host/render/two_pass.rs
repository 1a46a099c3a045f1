//! Jensen's two-pass photon mapping (Jensen 1996, "Global illumination using photon
//! maps"; Jensen, "Realistic Image Synthesis Using Photon Mapping", 2001, ch. 9 "A
//! practical two-pass algorithm"), the method photon mappers use for final images,
//! beside the paper's direct visualization of the map (`renderer.rs`).
//!
//! Pass 1 is the same photon trace (`photons.rs`): all stored photons form the
//! global map, the specular-only ones also the caustic map. Pass 2 traces the same
//! eye paths through mirrors and glass to their first diffuse point x
//! (`renderer::eye_queries`) and splits the radiance reflected at x into terms each
//! light path falls in exactly once:
//!
//! * emission seen along the eye path (as in the direct method);
//! * direct light, L D E: shadow rays to the area light (`direct_light.rs`);
//! * caustics, L S+ D E: the caustic map looked up at x (`caustics.rs`);
//! * indirect diffuse light, L (S|D)* D (S)* D E: final gathering from the global map
//!   (`final_gather.rs`), its rays counting 0 where they meet the light; each ray's
//!   hit reads either k photons of the global map (`--method two-pass`) or the
//!   nearest irradiance point precomputed from it (Christensen 1999,
//!   `irradiance.rs`, `--method two-pass-irradiance`).
//!
//! Every photon lookup (caustic, gather and irradiance precomputation) goes through
//! the chosen gather backend, as Morton-sorted batches (`lookup.rs`): the workload a
//! photon mapper gives the core. Lookups are radius-capped k-nearest searches
//! (`GatherParams::radius`), as Jensen's, pbrt's and Mitsuba's photon mappers use
//! them; a lookup with no photon inside the cap returns nothing and its estimate is
//! 0.

use crate::host::error::{Error, Result};
use crate::host::gather::{GatherBackend, GatherParams};
use crate::host::map::quantize::Point;
use crate::host::render::caustics::{caustic_light, caustic_photons};
use crate::host::render::direct_light::direct_light;
use crate::host::render::final_gather::{indirect_light, GatherMap};
use crate::host::render::irradiance::{irradiance_params, precompute_irradiance, IrradianceMap};
use crate::host::render::photons::Photon;
use crate::host::render::renderer::{
    encode, eye_queries, photon_points, pixel_radiance, render_image, EyePass, RenderMethod,
    RenderSettings,
};
use crate::host::render::scene::Scene;
use crate::host::stages::StageTimes;

/// The lookup cap of the two-pass method when none is given, as a fraction of the
/// photon map's longest extent. It bounds how far a caustic estimate reaches: the
/// caustic map is sparse away from its caustics, and an uncapped k-nearest lookup
/// there would spread their power over the whole scene. In the global map (denser,
/// k = 32 photons lie within ~0.02 of the Cornell box at 200,000 photons) it binds
/// only in the darkest corners.
pub const DEFAULT_RADIUS_REL: f64 = 0.05;

/// [`DEFAULT_RADIUS_REL`] of the longest extent of `photons`' bounding box.
pub fn default_radius(photons: &[Photon]) -> f64 {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in photons {
        for (a, c) in p.pos.to_array().into_iter().enumerate() {
            lo[a] = lo[a].min(c as f64);
            hi[a] = hi[a].max(c as f64);
        }
    }
    let extent = (0..3).map(|a| hi[a] - lo[a]).fold(0.0, f64::max);
    DEFAULT_RADIUS_REL * extent
}

/// The photon maps of pass 2, each loaded in its gather backend (built with the
/// same [`GatherParams`]).
pub struct PhotonMaps<'a> {
    /// Every stored photon.
    pub global: (&'a dyn GatherBackend, &'a [Photon]),
    /// The specular-only photons (`caustics::caustic_photons`); `None` if there
    /// are none.
    pub caustic: Option<(&'a dyn GatherBackend, &'a [Photon])>,
    /// Precomputed irradiance points (`irradiance.rs`), loaded in their backend
    /// (built with `irradiance::irradiance_params`): when given, the final gather
    /// reads them instead of the global map.
    pub irradiance: Option<(&'a dyn GatherBackend, &'a IrradianceMap)>,
}

/// What the two-pass eye pass did, beside the image.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct TwoPassStats {
    /// Photons in the caustic map.
    pub caustic_photons: u64,
    /// Shading points (eye paths that reached a diffuse surface).
    pub shading_points: u64,
    /// Caustic-map lookups (one per shading point when there is a caustic map).
    pub caustic_lookups: u64,
    /// Final-gather lookups (gather rays that reached a diffuse surface): in the
    /// global map, or in the irradiance points when there are some.
    pub gather_lookups: u64,
    /// Irradiance points precomputed (one global-map lookup each); 0 without.
    pub irradiance_points: u64,
}

/// The two-pass eye pass: image, lookups and the photons the backends read, each
/// part charged to its paper Fig. 2 stage in `times` (eye, shadow and gather rays to
/// "ray emission", lookups to "kd-tree search", estimates and the image to
/// "other"). `params` must be what the backends were built with.
pub fn render_two_pass(
    scene: &Scene,
    settings: &RenderSettings,
    maps: &PhotonMaps,
    params: &GatherParams,
    times: &mut StageTimes,
) -> Result<(EyePass, TwoPassStats)> {
    let (points, emitted) = times.time("ray emission", || eye_queries(scene, settings));
    let direct = times.time("ray emission", || {
        direct_light(scene, &points, settings.seed)
    });
    let (caustic, caustic_visited) = caustic_light(&points, maps.caustic, params, times)?;
    let gather_map = match maps.irradiance {
        Some((backend, irradiance)) => GatherMap::Irradiance(backend, irradiance),
        None => GatherMap::Photons(maps.global.0, maps.global.1),
    };
    let (indirect, gather) = indirect_light(
        scene,
        &points,
        settings.gather_rays,
        settings.seed,
        gather_map,
        params,
        times,
    )?;
    let linear = times.time("other", || {
        // Per point, the terms in a fixed order: equal inputs, bit-equal pixels.
        let total: Vec<_> = direct
            .iter()
            .zip(&caustic)
            .zip(&indirect)
            .map(|((d, c), i)| *d + *c + *i)
            .collect();
        pixel_radiance(settings.width, settings.height, &points, &total, &emitted)
    });
    let image = times.time("other", || {
        encode(settings.width, settings.height, &linear, settings.exposure)
    });
    let stats = TwoPassStats {
        caustic_photons: maps.caustic.map_or(0, |c| c.1.len() as u64),
        shading_points: points.len() as u64,
        caustic_lookups: if maps.caustic.is_some() {
            points.len() as u64
        } else {
            0
        },
        gather_lookups: gather.lookups,
        irradiance_points: 0,
    };
    Ok((
        EyePass {
            image,
            linear,
            // The photon lookups, what the direct method's queries are.
            queries: (stats.caustic_lookups + stats.gather_lookups) as usize,
            visited: caustic_visited + gather.visited,
        },
        stats,
    ))
}

/// Loads a photon map (positions) into a gather backend with the given parameters,
/// as the caller's options build them.
pub type BuildBackend<'a> = dyn Fn(&[Point], &GatherParams) -> Result<Box<dyn GatherBackend>> + 'a;

/// Pass 2 by `settings.method` on the photon map `photons` (already loaded in
/// `global`; `caustic` flags its specular-only photons): the direct method's
/// [`render_image`], or the two-pass render with a caustic map that `build` loads
/// into a backend like `global` (charged to "kd-tree build"), and its statistics.
/// `two-pass-irradiance` first precomputes the irradiance points through `global`
/// and loads them with `build` too; their lookups count among the pass's.
#[allow(clippy::too_many_arguments)]
pub fn render_method(
    scene: &Scene,
    settings: &RenderSettings,
    photons: &[Photon],
    caustic: &[bool],
    global: &dyn GatherBackend,
    build: &BuildBackend,
    params: &GatherParams,
    times: &mut StageTimes,
) -> Result<(EyePass, Option<TwoPassStats>)> {
    if settings.method == RenderMethod::Direct {
        let pass = render_image(scene, settings, photons, global, params, times)?;
        return Ok((pass, None));
    }
    let caustic = caustic_photons(photons, caustic);
    let caustic_map = match caustic.is_empty() {
        true => None,
        false => Some(times.time("kd-tree build", || build(&photon_points(&caustic), params))?),
    };
    let (irradiance, precomputed) = match settings.method {
        RenderMethod::TwoPassIrradiance => {
            let (map, visited) = precompute_irradiance(scene, photons, global, params, times)?;
            if map.points.is_empty() {
                return Err(Error::new(
                    "no photon lies on a surface of the scene: no irradiance to precompute",
                ));
            }
            let backend = times.time("kd-tree build", || {
                build(&map.points, &irradiance_params(params))
            })?;
            (Some((backend, map)), visited)
        }
        _ => (None, 0),
    };
    let maps = PhotonMaps {
        global: (global, photons),
        caustic: caustic_map.as_deref().map(|b| (b, caustic.as_slice())),
        irradiance: irradiance.as_ref().map(|(b, m)| (b.as_ref(), m)),
    };
    let (mut pass, mut stats) = render_two_pass(scene, settings, &maps, params, times)?;
    if let Some((_, map)) = &irradiance {
        stats.irradiance_points = map.points.len() as u64;
        pass.queries += map.points.len();
        pass.visited += precomputed;
    }
    Ok((pass, Some(stats)))
}
