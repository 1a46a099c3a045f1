//! The sweep: for every scene, photon count, metric, k and
//! coordinate bits, the quantized search's image error, recall and radius error
//! against the float search on the same photons and queries, its reads and
//! distance tests per query, its measured speed, and the core's simulated reads
//! per cycle with the clock and area `synth/results.json` has.

use crate::study::hwcost::{self, Cost, HwSim, ReportRow};
use crate::study::metrics;
use crate::study::plan::Plan;
use indicatif::{ProgressBar, ProgressStyle};
use photon_fpga::host::error::{Error, Result};
use photon_fpga::host::gather::{
    FloatBackend, GatherBackend, GatherParams, Gathered, QuantizedMap,
};
use photon_fpga::host::map::knn;
use photon_fpga::host::map::quantize::{GridPoint, Point};
use photon_fpga::host::render::photons::{trace_photons, Photon};
use photon_fpga::host::render::scene::Scene;
use photon_fpga::host::render::{self, eye_queries, QueryPoint, RenderSettings};
use photon_fpga::hw::config::metric::Metric;
use rayon::prelude::*;
use std::collections::BTreeMap;
use std::hint::black_box;
use std::time::Instant;

/// The hardware side of a point the core can run.
#[derive(Clone, Debug, PartialEq)]
pub struct HwPoint {
    pub sim: HwSim,
    pub cost: Cost,
    /// reads/cycle (simulated) × fmax / reads per query (this point's), if a clock
    /// is known.
    pub queries_per_s: Option<f64>,
}

/// One point of the sweep. Everything but `sw_queries_per_s` is a pure function of
/// the plan and the seed.
#[derive(Clone, Debug, PartialEq)]
pub struct Row {
    pub scene: String,
    pub emitted: usize,
    pub stored: usize,
    pub queries: usize,
    pub metric: Metric,
    pub k: usize,
    pub bits: u32,
    pub hw_capable: bool,
    /// Image rel. RMSE (linear radiance) against the float render with the same
    /// photons and queries, and against the converged reference.
    pub err_float: f64,
    pub err_reference: f64,
    /// The float render's own error against the reference (photon noise and bias).
    pub float_err_reference: f64,
    /// The same, with the radius recomputed on the host from the gathered
    /// photons' float positions (`metrics::host_radius`).
    pub err_float_host: f64,
    pub err_reference_host: f64,
    pub recall: f64,
    pub radius_err: f64,
    pub reads_per_query: f64,
    pub tests_per_query: f64,
    pub max_finds_per_query: f64,
    pub climbs_per_query: f64,
    pub hw: Option<HwPoint>,
    /// Measured: the software search on one thread (timing, not compared by tests).
    pub sw_queries_per_s: f64,
}

/// The eye pass of one scene: queries and their world positions.
pub struct Eye {
    pub queries: Vec<QueryPoint>,
    pub points: Vec<Point>,
    pub pixels: usize,
}

pub fn eye(scene: &Scene, plan: &Plan) -> Eye {
    let settings = RenderSettings {
        width: plan.width,
        height: plan.height,
        spp: plan.spp,
        seed: plan.seed,
        ..RenderSettings::default()
    };
    let (queries, _) = eye_queries(scene, &settings);
    Eye {
        points: render::query_points(&queries),
        queries,
        pixels: (plan.width * plan.height) as usize,
    }
}

/// Photons traced from `emitted`, and their positions.
pub fn photons(scene: &Scene, emitted: usize, seed: u64) -> Result<(Vec<Photon>, Vec<Point>)> {
    let p = trace_photons(scene, emitted, seed, false);
    if p.is_empty() {
        return Err(Error::new("no photon reached a diffuse surface"));
    }
    let pts = render::photon_points(&p);
    Ok((p, pts))
}

/// The float render's gathers and linear image for `params` (no quantization).
pub fn float_render(
    eye: &Eye,
    photons: &[Photon],
    points: &[Point],
    params: &GatherParams,
) -> Result<(Vec<Gathered>, Vec<[f64; 3]>)> {
    let g = FloatBackend::new(points, params)?.gather(&eye.points)?;
    let l = render::radiance(&eye.queries, photons, &g, params.k, None, params.metric);
    Ok((g, metrics::gathered_image(eye.pixels, &eye.queries, &l)))
}

/// Per-query search statistics: reads, distance tests, MaxFinder runs, climbs.
pub type Counts = [u32; 4];

/// The quantized search over every query, as the `sw` backend runs it, keeping the
/// search's own counts.
pub fn quantized_gather(m: &QuantizedMap, queries: &[Point]) -> Result<Vec<(Gathered, Counts)>> {
    let p = &m.params;
    queries
        .par_iter()
        .map(|&q| match m.locate(q).map_err(Error::new)? {
            GridPoint::Inside(c) => {
                let f = knn::search_with(&m.tree, c, p.k, m.radius_bound, p.metric, p.traversal);
                let counts = [f.visited, f.tested, f.max_finds, f.climbs];
                let g = Gathered {
                    neighbours: m.neighbours(&f.slots),
                    visited: f.visited,
                };
                Ok((g, counts))
            }
            GridPoint::Outside(g) => {
                let r = m.search_outside(g);
                let v = r.visited;
                Ok((r, [v, v, 0, 0]))
            }
        })
        .collect()
}

/// Grid coordinates of every `step`-th query inside the photon box.
pub fn grid_sample(m: &QuantizedMap, queries: &[Point], n: usize) -> Vec<[u32; 3]> {
    let inside: Vec<[u32; 3]> = queries
        .iter()
        .filter_map(|&q| match m.locate(q) {
            Ok(GridPoint::Inside(c)) => Some(c),
            _ => None,
        })
        .collect();
    let step = inside.len().div_ceil(n.max(1)).max(1);
    inside.into_iter().step_by(step).collect()
}

/// Seconds for one thread to search `queries` (best of three rounds: another
/// process only ever slows a round down).
pub fn time_search(m: &QuantizedMap, queries: &[[u32; 3]]) -> f64 {
    let p = &m.params;
    (0..3)
        .map(|_| {
            let t = Instant::now();
            for &c in queries {
                black_box(knn::search_with(
                    &m.tree,
                    c,
                    p.k,
                    m.radius_bound,
                    p.metric,
                    p.traversal,
                ));
            }
            t.elapsed().as_secs_f64()
        })
        .fold(f64::INFINITY, f64::min)
}

/// The whole study's measurements.
pub struct Sweep {
    pub rows: Vec<Row>,
    /// Simulations by (scene, metric, k, bits), at the base photon count.
    pub sims: BTreeMap<(String, String, usize, u32), HwSim>,
}

fn mean(v: impl Iterator<Item = u32>, n: usize) -> f64 {
    v.map(|x| x as f64).sum::<f64>() / n.max(1) as f64
}

/// Run the sweep of `plan`; `report` is synth/results.json's rows for the study.
pub fn run(plan: &Plan, report: &[ReportRow], bar: &ProgressBar) -> Result<Sweep> {
    let per_scene = plan.photons.len() * plan.metrics.len() * plan.ks.len() * plan.bits.len();
    bar.set_length((plan.scenes.len() * per_scene) as u64);
    bar.set_style(
        ProgressStyle::with_template("{msg:40} [{bar:30}] {pos}/{len} points, {elapsed}")
            .expect("a valid template"),
    );
    let mut rows = vec![];
    let mut sims = BTreeMap::new();
    for (name, scene) in &plan.scenes {
        bar.set_message(format!("{name}: reference"));
        let eye = eye(scene, plan);
        let (rp, rpts) = photons(scene, plan.reference_photons, plan.seed ^ 0x5EF)?;
        let ref_params = GatherParams {
            k: plan.reference_k,
            metric: Metric::L2,
            // The float search has no photon-word limit: the reference may exceed
            // the core's 2^20 photons.
            capacity: rpts.len(),
            ..GatherParams::default()
        };
        let (_, reference) = float_render(&eye, &rp, &rpts, &ref_params)?;
        drop((rp, rpts));
        for (pi, &emitted) in plan.photons.iter().enumerate() {
            let (ph, pts) = photons(scene, emitted, plan.seed)?;
            for &metric in &plan.metrics {
                for &k in &plan.ks {
                    bar.set_message(format!("{name}: {emitted} photons, {metric}, k = {k}"));
                    let fparams = GatherParams {
                        k,
                        metric,
                        ..GatherParams::default()
                    };
                    let (fg, fimg) = float_render(&eye, &ph, &pts, &fparams)?;
                    let float_err_reference = metrics::rel_rmse(&fimg, &reference);
                    for &bits in &plan.bits {
                        let params = GatherParams {
                            bits,
                            traversal: plan.traversal,
                            core: plan.core,
                            ..fparams.clone()
                        };
                        let m = QuantizedMap::new(&pts, &params)?;
                        let res = quantized_gather(&m, &eye.points)?;
                        let (g, counts): (Vec<Gathered>, Vec<Counts>) = res.into_iter().unzip();
                        let l = render::radiance(&eye.queries, &ph, &g, k, None, metric);
                        let img = metrics::gathered_image(eye.pixels, &eye.queries, &l);
                        let gh = metrics::host_radius(&g, &eye.points, &pts, metric);
                        let lh = render::radiance(&eye.queries, &ph, &gh, k, None, metric);
                        let img_host = metrics::gathered_image(eye.pixels, &eye.queries, &lh);
                        let n = counts.len();
                        let sample = grid_sample(&m, &eye.points, plan.timing_sample);
                        let secs = time_search(&m, &sample);
                        let hw_capable = plan.hw_capable(k, bits);
                        if hw_capable && pi == 0 && plan.hw_bits.contains(&bits) {
                            bar.set_message(format!(
                                "{name}: simulating {metric} k={k} {bits} bits"
                            ));
                            let sim = hwcost::simulate(
                                &pts,
                                &eye.points,
                                &params,
                                emitted,
                                plan.hw_sample,
                                plan.engine,
                            )?;
                            sims.insert((name.clone(), metric.to_string(), k, bits), sim);
                        }
                        rows.push(Row {
                            scene: name.clone(),
                            emitted,
                            stored: ph.len(),
                            queries: n,
                            metric,
                            k,
                            bits,
                            hw_capable,
                            err_float: metrics::rel_rmse(&img, &fimg),
                            err_reference: metrics::rel_rmse(&img, &reference),
                            float_err_reference,
                            err_float_host: metrics::rel_rmse(&img_host, &fimg),
                            err_reference_host: metrics::rel_rmse(&img_host, &reference),
                            recall: metrics::recall(&g, &fg),
                            radius_err: metrics::radius_rel_error(&g, &fg),
                            reads_per_query: mean(counts.iter().map(|c| c[0]), n),
                            tests_per_query: mean(counts.iter().map(|c| c[1]), n),
                            max_finds_per_query: mean(counts.iter().map(|c| c[2]), n),
                            climbs_per_query: mean(counts.iter().map(|c| c[3]), n),
                            hw: None,
                            sw_queries_per_s: sample.len() as f64 / secs.max(1e-12),
                        });
                        bar.inc(1);
                    }
                }
            }
        }
    }
    attach_hw(&mut rows, &sims, report);
    Ok(Sweep { rows, sims })
}

/// Give every point the core can run the simulation of its scene, metric and k at
/// the nearest simulated bits, and REPORT.md's clock and area for it.
fn attach_hw(
    rows: &mut [Row],
    sims: &BTreeMap<(String, String, usize, u32), HwSim>,
    report: &[ReportRow],
) {
    for r in rows.iter_mut().filter(|r| r.hw_capable) {
        let nearest = sims
            .iter()
            .filter(|((s, m, k, _), _)| *s == r.scene && *m == r.metric.to_string() && *k == r.k)
            .min_by_key(|((.., b), _)| (*b as i64 - r.bits as i64).abs());
        let Some((_, sim)) = nearest else { continue };
        let cost = hwcost::cost(report, r.k, r.bits, r.metric);
        let queries_per_s = cost
            .fmax_mhz
            .map(|f| sim.reads_per_cycle() * f * 1e6 / r.reads_per_query.max(1e-12));
        r.hw = Some(HwPoint {
            sim: sim.clone(),
            cost,
            queries_per_s,
        });
    }
}
