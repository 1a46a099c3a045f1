//! `photon-fpga render` (the default command): a scene rendered with photon mapping,
//! its gathers on the chosen backend.

use crate::cli::gather_opts::GatherOpts;
use crate::cli::set_threads;
use crate::host::error::{Error, Result};
use crate::host::gather::GatherRequest;
use crate::host::limits::{self, MAX_EMITTED};
use crate::host::output::Output;
use crate::host::render::photons;
use crate::host::render::scene::Scene;
use crate::host::render::two_pass;
use crate::host::render::RenderMethod;
use crate::host::render::{self, RenderSettings};
use crate::host::stages::StageTimes;
use crate::hw::config::core_spec::DEFAULT_K;
use clap::{Args, Parser};
use std::path::PathBuf;

/// `WxH`, e.g. `256x256`.
pub fn parse_size(s: &str) -> std::result::Result<(u32, u32), String> {
    let bad = || format!("invalid size '{s}' (expected WxH, e.g. 256x256)");
    let (w, h) = s.split_once(['x', 'X']).ok_or_else(bad)?;
    let (w, h): (u32, u32) = (w.parse().map_err(|_| bad())?, h.parse().map_err(|_| bad())?);
    if w == 0 || h == 0 || w > 16384 || h > 16384 {
        return Err(bad());
    }
    Ok((w, h))
}

#[derive(Args)]
pub struct RenderArgs {
    /// Scene file (TOML); the built-in Cornell box if absent.
    #[arg(long)]
    pub scene: Option<PathBuf>,
    /// Photons emitted from the light.
    #[arg(long, default_value_t = 200_000)]
    pub photons: usize,
    #[command(flatten)]
    pub opts: GatherOpts,
    /// Image size.
    #[arg(long, default_value = "256x256", value_parser = parse_size)]
    pub size: (u32, u32),
    /// Eye samples per pixel.
    #[arg(long, default_value_t = 4)]
    pub spp: u32,
    /// How photons become pixels. With the two-pass methods and no --radius, every
    /// lookup is capped at 5 % of the photon map's longest extent.
    #[arg(long, value_enum, default_value_t = RenderMethod::default())]
    pub method: RenderMethod,
    /// With the two-pass methods: final-gather rays per shading point, 1..=4096
    /// [default: 16].
    #[arg(long)]
    pub gather_rays: Option<u32>,
    /// Seed of every random choice; the same seed gives the same image.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Exposure multiplier applied before tone mapping.
    #[arg(long, allow_negative_numbers = true)]
    pub exposure: Option<f32>,
    /// Output PNG; a name ending in .pfm writes linear radiance (PFM) instead.
    #[arg(long, default_value = "render.png")]
    pub out: PathBuf,
}

/// `render`'s options alone, to read their defaults.
#[derive(Parser)]
struct RenderDefaults {
    #[command(flatten)]
    args: RenderArgs,
}

impl Default for RenderArgs {
    /// The defaults clap gives a bare `render`.
    fn default() -> Self {
        RenderDefaults::parse_from(["photon-fpga"]).args
    }
}

pub fn render(args: &RenderArgs) -> Result<()> {
    set_threads(args.opts.threads)?;
    // A radiance estimate wants more photons than a plain gather.
    let mut request = args.opts.request(DEFAULT_K)?;
    // Everything that can be refused is refused before any photon is traced.
    check_photons_and_spp(args.photons, args.spp)?;
    let gather_rays = check_method(args, &request)?;
    limits::check_photon_memory(request.params.capacity)?;
    if let Some(e) = args.exposure {
        limits::check_positive("--exposure", e as f64)?;
    }
    let (w, h) = args.size;
    limits::check_gather_memory(
        w as u64 * h as u64 * args.spp as u64,
        request.gathered_k,
        request.params.capacity as u64,
        &format!("--size {w}x{h} × --spp {}", args.spp),
    )?;
    // The scene and the core file are inputs: no output may replace them.
    let mut inputs: Vec<&std::path::Path> = args.scene.iter().map(|p| p.as_path()).collect();
    inputs.extend(args.opts.core_file.file.as_deref());
    let out = Output::check(&args.out, &inputs)?;
    request.stage_waveform(&inputs)?;
    let scene = match &args.scene {
        Some(p) => Scene::from_file(p)?,
        None => Scene::cornell_box(),
    };
    let mut settings = RenderSettings {
        width: w,
        height: h,
        spp: args.spp,
        seed: args.seed,
        ..RenderSettings::default()
    };
    if let Some(e) = args.exposure {
        settings.exposure = e;
    }
    settings.method = args.method;
    settings.gather_rays = gather_rays;
    let mut t = StageTimes::default();
    let (photons, caustic) = t
        .time("photon emission", || {
            photons::trace_photon_paths(
                &scene,
                args.photons,
                args.seed,
                true,
                request.params.capacity,
            )
        })
        .ok_or_else(|| {
            let params = &request.params;
            Error::new(match &params.fixed {
                Some(f) if f.max_photons() == params.capacity => format!(
                    "{} emitted photons store more than {}; tracing stopped early",
                    args.photons,
                    f.photon_limit()
                ),
                _ => format!(
                    "{} emitted photons store more than --capacity {} photons (stopped early)",
                    args.photons, params.capacity
                ),
            })
        })?;
    if photons.is_empty() {
        return Err(Error::new("no photon reached a diffuse surface"));
    }
    if args.method.is_two_pass() && request.params.radius.is_none() {
        request.params.radius = Some(two_pass::default_radius(&photons));
    }
    let positions = render::photon_points(&photons);
    let backend = t.time("kd-tree build", || request.backend(&positions))?;
    let params = &request.params;
    let (pass, two_pass) = two_pass::render_method(
        &scene,
        &settings,
        &photons,
        &caustic,
        backend.as_ref(),
        &|p, prm| request.other_backend(p, prm),
        params,
        &mut t,
    )?;
    if let Some(s) = two_pass {
        println!(
            "two-pass: {} shading points; {} caustic photons, {} caustic lookups; \
             {gather_rays} gather rays per point, {} final-gather lookups; lookup radius cap \
             {:.6}",
            s.shading_points,
            s.caustic_photons,
            s.caustic_lookups,
            s.gather_lookups,
            params.radius.unwrap_or(f64::INFINITY)
        );
        if s.irradiance_points > 0 {
            println!(
                "irradiance: {} points precomputed (one lookup each), the final gather's \
                 lookups 1-nearest",
                s.irradiance_points
            );
        }
    }
    t.time("other", || match render::pfm::is_pfm(&args.out) {
        true => render::pfm::save_pfm(w, h, &pass.linear, &out),
        false => render::save_png(&pass.image, &out),
    })?;
    let k = params.k;
    request.finish()?;
    println!(
        "{} photons stored from {} emitted; {} queries; backend {}; k = {}",
        photons.len(),
        args.photons,
        pass.queries,
        backend.name(),
        k
    );
    if let Some(info) = backend.describe() {
        println!("{info}");
    }
    println!(
        "photons visited per query: {:.1}",
        pass.visited as f64 / pass.queries.max(1) as f64
    );
    println!("{t}");
    println!("wrote {}", args.out.display());
    Ok(())
}

/// `--method` and `--gather-rays`: the final-gather rays per shading point of a
/// two-pass render; refused before any photon is traced.
fn check_method(args: &RenderArgs, request: &GatherRequest) -> Result<u32> {
    match (args.method, args.gather_rays) {
        (RenderMethod::Direct, Some(_)) => Err(Error::new(
            "--gather-rays sets the final gather of --method two-pass or \
             two-pass-irradiance; --method direct gathers none",
        )),
        (RenderMethod::Direct, None) => Ok(render::DEFAULT_GATHER_RAYS),
        (RenderMethod::TwoPass | RenderMethod::TwoPassIrradiance, n) => {
            let n = n.unwrap_or(render::DEFAULT_GATHER_RAYS);
            if !(1..=4096).contains(&n) {
                return Err(Error::new(format!(
                    "--gather-rays must be in 1..=4096, got {n}"
                )));
            }
            if request.records_waveform() {
                return Err(Error::new(
                    "--vcd (or PHOTON_FPGA_VCD) records one simulation of one map; --method \
                     two-pass gathers from several maps in many batches (give --method direct)",
                ));
            }
            Ok(n)
        }
    }
}

/// `--photons` and `--spp` of a traced scene (render, banking): refused before any
/// photon is traced.
pub fn check_photons_and_spp(photons: usize, spp: u32) -> Result<()> {
    if photons == 0 || photons > MAX_EMITTED {
        return Err(Error::new(format!(
            "--photons must be in 1..={MAX_EMITTED}, got {photons}"
        )));
    }
    if spp == 0 {
        return Err(Error::new("--spp must be at least 1, got 0"));
    }
    Ok(())
}
