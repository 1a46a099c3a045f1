//! The study's files: `study.csv` (every point), `STUDY.md` (the tables
//! with a provenance legend), `exact.csv` (the `--exact` series), `pareto.png`,
//! `exact.png` and `fig3.png`…`fig6.png`, written into
//! a staging directory beside the output and moved into place only when all of
//! them are done, so a failed study leaves nothing behind.

use crate::study::exact_report;
use crate::study::exact_series::ExactSeries;
use crate::study::figures::{Figures, FIG_BITS, FIG_K, FIG_METRIC, HW_PARTS, SW_PARTS};
use crate::study::plan::{Plan, HW_MAX_BITS};
use crate::study::sweep::{Row, Sweep};
use crate::study::{pareto, plots};
use photon_fpga::host::error::{Error, Result};
use photon_fpga::hw::config::controller::Controller;
use photon_fpga::hw::config::core_config::MAX_K;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// The files a study writes, in this order.
pub const FILES: [&str; 9] = [
    "study.csv",
    "STUDY.md",
    "exact.csv",
    "pareto.png",
    "exact.png",
    "fig3.png",
    "fig4.png",
    "fig5.png",
    "fig6.png",
];

/// The output directory, checked before any work, and the staging directory the
/// files are written to first.
pub struct OutDir {
    target: PathBuf,
    staging: tempfile::TempDir,
}

impl OutDir {
    /// `dir` is an existing directory or a new name in an existing one; a staging
    /// directory is made beside it (so the final renames stay on one file system).
    pub fn check(dir: &Path) -> Result<OutDir> {
        let err = |what: String| Error::new(format!("{}: {what}", dir.display()));
        match std::fs::metadata(dir) {
            Ok(m) if !m.is_dir() => return Err(err("exists and is not a directory".into())),
            Ok(_) => {}
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
            Err(e) => return Err(err(format!("cannot be used as output: {e}"))),
        }
        let parent = match dir.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        };
        let staging = tempfile::Builder::new()
            .prefix(".photon-fpga-study-")
            .tempdir_in(&parent)
            .map_err(|e| {
                err(format!(
                    "cannot write beside it in {}: {e}",
                    parent.display()
                ))
            })?;
        Ok(OutDir {
            target: dir.to_path_buf(),
            staging,
        })
    }

    pub fn staging(&self) -> &Path {
        self.staging.path()
    }

    /// Move the finished files into the output directory (made if new).
    pub fn commit(self) -> Result<()> {
        let err = |e: std::io::Error| Error::new(format!("{}: {e}", self.target.display()));
        std::fs::create_dir_all(&self.target).map_err(err)?;
        for f in FILES {
            std::fs::rename(self.staging.path().join(f), self.target.join(f)).map_err(err)?;
        }
        Ok(())
    }
}

/// Why a point has no hardware numbers.
fn no_hw(r: &Row) -> String {
    if r.bits > HW_MAX_BITS {
        format!("n/a: software only (> {HW_MAX_BITS} bits per axis)")
    } else if !r.hw_capable {
        format!(
            "n/a: software only (k = {} is above the study core's K; the barrel controller \
             holds up to {MAX_K})",
            r.k
        )
    } else {
        "n/a: not simulated".into()
    }
}

fn opt(v: Option<f64>, digits: usize, none: &str) -> String {
    v.map_or(none.to_string(), |x| format!("{x:.digits$}"))
}

/// `study.csv`: one line per point; the measured timing is the last column.
pub fn csv(path: &Path, rows: &[Row]) -> Result<()> {
    let fail = |e: &dyn std::fmt::Display| Error::new(format!("{}: {e}", path.display()));
    let mut w = csv::Writer::from_path(path).map_err(|e| fail(&e))?;
    w.write_record([
        "scene",
        "emitted",
        "stored",
        "queries",
        "metric",
        "k",
        "bits",
        "hw_capable",
        "rel_rmse_vs_float",
        "rel_rmse_vs_reference",
        "float_rel_rmse_vs_reference",
        "host_radius_rel_rmse_vs_float",
        "host_radius_rel_rmse_vs_reference",
        "recall_at_k",
        "radius_rel_error",
        "reads_per_query",
        "tests_per_query",
        "hw_reads_per_cycle",
        "hw_reads_source",
        "hw_queries_per_port",
        "fmax_mhz",
        "fmax_source",
        "hw_queries_per_s",
        "luts",
        "ffs",
        "area_source",
        "sw_queries_per_s_measured",
    ])
    .map_err(|e| fail(&e))?;
    for r in rows {
        let mut rec = vec![
            r.scene.clone(),
            r.emitted.to_string(),
            r.stored.to_string(),
            r.queries.to_string(),
            r.metric.to_string(),
            r.k.to_string(),
            r.bits.to_string(),
            r.hw_capable.to_string(),
            format!("{:.6e}", r.err_float),
            format!("{:.6e}", r.err_reference),
            format!("{:.6e}", r.float_err_reference),
            format!("{:.6e}", r.err_float_host),
            format!("{:.6e}", r.err_reference_host),
            format!("{:.6}", r.recall),
            format!("{:.6e}", r.radius_err),
            format!("{:.3}", r.reads_per_query),
            format!("{:.3}", r.tests_per_query),
        ];
        match &r.hw {
            Some(h) => rec.extend([
                format!("{:.4}", h.sim.reads_per_cycle()),
                h.sim.source(),
                h.sim.queries_per_port.to_string(),
                opt(h.cost.fmax_mhz, 1, "n/a: not in REPORT.md"),
                h.cost.fmax_source.clone(),
                opt(h.queries_per_s, 0, "n/a: no clock in REPORT.md"),
                h.cost.luts.clone(),
                h.cost.ffs.clone(),
                h.cost.area_source.clone(),
            ]),
            None => {
                let why = no_hw(r);
                rec.extend(std::iter::repeat_n(why, 9));
            }
        }
        rec.push(format!("{:.0}", r.sw_queries_per_s));
        w.write_record(&rec).map_err(|e| fail(&e))?;
    }
    w.flush().map_err(|e| fail(&e))
}

fn pct(x: f64) -> String {
    format!("{:.3} %", 100.0 * x)
}

fn si(x: f64) -> String {
    if x >= 1e6 {
        format!("{:.2} M", x / 1e6)
    } else {
        format!("{:.0} K", x / 1e3)
    }
}

/// The image error of a point against float: with the core's grid radius, or
/// (`host`) with the radius recomputed on the host.
pub fn err(r: &Row, host: bool) -> f64 {
    if host {
        r.err_float_host
    } else {
        r.err_float
    }
}

/// The fastest point of `rows` (one scene, base photons) the core can run with an
/// image error against float of at most `limit`: among the points within 1 % of
/// the highest hardware queries/s (a few more bits leave the reads per query all
/// but unchanged), the fewest coordinate bits, then the fastest. Fastest, not
/// narrowest: once the core holds k = 500 the narrowest word that meets a bound is
/// a deep list's, ten times slower than a short list's at a few more bits.
pub fn best_within<'a>(rows: &[&'a Row], limit: f64, host: bool) -> Option<&'a Row> {
    let q = |r: &Row| r.hw.as_ref().and_then(|h| h.queries_per_s).unwrap_or(0.0);
    let within: Vec<&Row> = rows
        .iter()
        .copied()
        .filter(|r| {
            err(r, host) <= limit && r.hw.as_ref().is_some_and(|h| h.queries_per_s.is_some())
        })
        .collect();
    let top = within.iter().map(|r| q(r)).fold(0.0, f64::max);
    within
        .into_iter()
        .filter(|r| q(r) >= 0.99 * top)
        .min_by(|a, b| a.bits.cmp(&b.bits).then(q(b).total_cmp(&q(a))))
}

fn table(out: &mut String, rows: &[&Row]) {
    out.push_str(
        "| metric | k | bits | rel. RMSE vs float | vs reference (float's own) | vs float, host radius | recall@k | radius rel. error | reads / query | distance tests / query | core reads / cycle [sim] | Q / port | clock | core queries/s | LUTs / FFs | sw queries/s [meas] |\n\
         |---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|---:|---|---:|\n",
    );
    for r in rows {
        let hw = match &r.hw {
            Some(h) => {
                let tag = if h.cost.fmax_source.starts_with("placed") {
                    "[P&R]"
                } else if h.cost.fmax_source.starts_with("assumed") {
                    "[assumed]"
                } else {
                    ""
                };
                let area = if h.cost.area_source.starts_with("synth") {
                    format!("{} / {} [syn]", h.cost.luts, h.cost.ffs)
                } else {
                    h.cost.area_source.clone()
                };
                format!(
                    "{:.3} | 2 x {} | {} {tag} | {} | {area}",
                    h.sim.reads_per_cycle(),
                    h.sim.queries_per_port,
                    h.cost
                        .fmax_mhz
                        .map_or("not in REPORT.md".into(), |f| format!("{f:.1} MHz")),
                    h.queries_per_s.map_or("n/a: no clock".into(), si),
                )
            }
            None => {
                let why = no_hw(r);
                format!("{why} | | | | ")
            }
        };
        let _ = writeln!(
            out,
            "| {} | {} | {} | {} | {} ({}) | {} | {:.4} | {:.2e} | {:.1} | {:.1} | {hw} | {} |",
            r.metric,
            r.k,
            r.bits,
            pct(r.err_float),
            pct(r.err_reference),
            pct(r.float_err_reference),
            pct(r.err_float_host),
            r.recall,
            r.radius_err,
            r.reads_per_query,
            r.tests_per_query,
            si(r.sw_queries_per_s),
        );
    }
}

/// `STUDY.md`.
pub fn markdown(
    plan: &Plan,
    sweep: &Sweep,
    exact: &ExactSeries,
    figs: &Figures,
    command: &str,
) -> String {
    let mut o = String::new();
    let _ = writeln!(o, "# Speed against error: the study\n");
    let _ = writeln!(
        o,
        "Regenerate: `{command}`. Image {}x{}, {} eye sample(s) per pixel, seed {}; \
         converged reference: float search, squared L2, k = {}, {} emitted photons (independent of the swept photons). \
         Squared L2 is listed as `l2`; distances and radii are Euclidean.\n",
        plan.width, plan.height, plan.spp, plan.seed, plan.reference_k, plan.reference_photons
    );
    let (controller_name, sim_when, sim_q) = match plan.core.chosen_controller() {
        Controller::Modules => (
            "QueryModule",
            "while every QueryModule is busy",
            "Q fitted to the sample as the rtl backend does.",
        ),
        Controller::Barrel => (
            "barrel",
            "over the whole run from the first query (fill and drain included: a barrel port refills a \
             slot as it frees, so all slots busy at once is not its steady state)",
            "Q = the query slots per port.",
        ),
    };
    let _ = write!(
        o,
        "## Provenance\n\n\
         * **rel. RMSE**: sqrt(Σ(img − ref)²/Σref²) over pixels and channels of the linear radiance of the \
         gathered light (the light's own emission, identical in both, left out), against the float render with the \
         *same* photons, queries and k (quantization error alone) and against the converged reference \
         (quantization + photon noise + bias; the float render's own figure in brackets). Deterministic. \
         **host radius**: the same photons (the core returns indices only, paper §4) with the estimate's radius \
         recomputed on the host from their float positions and the exact query: the core then only chooses the \
         photons, and the grid's rounding of query and photons no longer enters the density's area.\n\
         * **recall@k**: mean |found ∩ float kNN| / k; **radius rel. error**: mean |r − r_float| / r_float of the \
         farthest gathered photon's distance (the estimate's radius). Deterministic.\n\
         * **reads / query, distance tests / query**: the software search's counts over every query; the core makes \
         the very same reads (checked query by query on the simulated sample). Deterministic.\n\
         * **[sim]** core reads per cycle (both ports), {sim_when}, simulated cycle-accurately \
         on a sample of the study's own queries (every answer checked against the software search); {sim_q} \
         The sample, engine and bits of each simulation are listed below; \
         points at other bits or photon counts use their scene/metric/k's simulation. Deterministic.\n\
         * **[P&R]** clock placed and routed (nextpnr ECP5-85k) in synth/REPORT.md for this very configuration, or \
         for the smallest K above the point's k at the same bits and metric (a core of K answers every k up to K; \
         the point names the row and says so); \
         **[assumed]** the configuration is not in synth/REPORT.md, so the clock of the placed-and-routed row \
         nearest in K is assumed for it (its real clock is unknown: a wider distance or larger K is likely slower). \
         **[syn]** LUTs (+ LUT-RAM) / FFs synthesised by yosys for Virtex-6 (REPORT.md, its row's Q).\n\
         * **core queries/s** = reads/cycle [sim] × clock / reads per query: one core.\n\
         * **[meas]** software search's queries/s, measured on one thread of this 2-core machine (best of three \
         rounds over a sample of the queries); varies run to run, never compared by tests.\n\
         * **n/a**: software only: k > {max_k} (the {controller} core's K) or more than {HW_MAX_BITS} bits per \
         axis (the core's word).\n\n",
        max_k = plan.hw_max_k(),
        controller = controller_name,
    );
    o.push_str("Simulations:\n\n");
    for ((scene, metric, k, _), sim) in &sweep.sims {
        let _ = writeln!(
            o,
            "* {scene}, {metric}, k = {k}: {} → {:.4} reads/cycle ({} cycles{})",
            sim.source(),
            sim.reads_per_cycle(),
            sim.cycles,
            if sim.controller == Controller::Modules {
                format!(", {} busy", sim.busy_cycles)
            } else {
                String::new()
            }
        );
    }
    o.push('\n');
    for (name, _) in &plan.scenes {
        for (i, &emitted) in plan.photons.iter().enumerate() {
            let rows: Vec<&Row> = sweep
                .rows
                .iter()
                .filter(|r| &r.scene == name && r.emitted == emitted)
                .collect();
            let Some(first) = rows.first() else { continue };
            let _ = writeln!(
                o,
                "## {name}, {emitted} emitted photons ({} stored), {} queries\n",
                first.stored, first.queries
            );
            if i == 0 {
                for host in [false, true] {
                    for limit in [0.01, 0.001] {
                        let radius = if host {
                            "radius recomputed on the host"
                        } else {
                            "the core's grid radius"
                        };
                        match best_within(&rows, limit, host) {
                            Some(b) => {
                                let h = b.hw.as_ref().expect("best has hw");
                                let _ = writeln!(
                                    o,
                                    "Fastest core configuration (the fewest bits within 1 % of the fastest) with rel. RMSE vs float ≤ {} \
                                     ({radius}): **{}, k = {}, {} bits**: {} ({} vs reference), {} queries/s per core \
                                     ({:.1} MHz, {}), area {} / {} ({}).\n",
                                    pct(limit), b.metric, b.k, b.bits, pct(err(b, host)),
                                    pct(if host { b.err_reference_host } else { b.err_reference }),
                                    si(h.queries_per_s.unwrap_or(0.0)), h.cost.fmax_mhz.unwrap_or(0.0),
                                    h.cost.fmax_source, h.cost.luts, h.cost.ffs, h.cost.area_source
                                );
                            }
                            None => {
                                let _ = writeln!(
                                    o,
                                    "No core configuration reaches ≤ {} ({radius}) here.\n",
                                    pct(limit)
                                );
                            }
                        }
                    }
                }
            }
            table(&mut o, &rows);
            o.push('\n');
        }
    }
    let series_rows: Vec<&Row> = sweep
        .rows
        .iter()
        .filter(|r| r.scene == exact.scene && r.emitted == exact.emitted)
        .collect();
    o.push_str(&exact_report::section(exact, &series_rows));
    o.push('\n');
    let _ = writeln!(
        o,
        "## The paper's figures (§3), from this run\n\n\
         {} scene, {} emitted photons, {FIG_METRIC}, {FIG_BITS}-bit, k = {FIG_K} unless k is the axis. \
         Software: measured on one thread (best of three). Core: the same reads at the simulated reads per cycle × \
         the clock of the matching point above ([P&R] or [assumed]), where the sweep simulated that k.\n\n\
         ![pareto](pareto.png)\n\n![fig3](fig3.png)\n\n![fig4](fig4.png)\n\n![fig5](fig5.png)\n\n![fig6](fig6.png)\n\n\
         Fig. 6, software: the counts of the search (photon fetches and axis distances per read, distances per \
         test, max finding per insertion into a full list) × unit costs measured by micro-benchmark on the same \
         map; the cross is the measured whole search (the rest is traversal control). Parts: {}. \
         Core: the cycles a QueryModule spends per query ({}), from the core's cycle costs \
         (`CoreConfig::issue_interval`, `mean_read_interval`) on the search's counts: a model, not a count of \
         simulated cycles.\n",
        figs.scene,
        plan.photons[0],
        SW_PARTS.join(", "),
        HW_PARTS.join(", "),
    );
    o.push_str("\n| k | sw ns/query (axis, dist, fetch, max) | measured ns/query | core cycles/query (read, wait, max, climb) |\n|---:|---|---:|---|\n");
    for b in &figs.fig6 {
        let hw = b.hw_cycles.map_or("n/a: k > 64".into(), |c| {
            format!("{:.0}, {:.0}, {:.0}, {:.0}", c[0], c[1], c[2], c[3])
        });
        let s = b.sw_ns;
        let _ = writeln!(
            o,
            "| {} | {:.0}, {:.0}, {:.0}, {:.0} | {:.0} | {hw} |",
            b.k, s[0], s[1], s[2], s[3], b.sw_measured_ns
        );
    }
    o
}

/// Every file of the study into `dir` (the staging directory).
pub fn write_all(
    dir: &Path,
    plan: &Plan,
    sweep: &Sweep,
    exact: &ExactSeries,
    figs: &Figures,
    command: &str,
) -> Result<()> {
    csv(&dir.join("study.csv"), &sweep.rows)?;
    exact_report::csv(&dir.join("exact.csv"), exact)?;
    let md = markdown(plan, sweep, exact, figs, command);
    let path = dir.join("STUDY.md");
    std::fs::write(&path, md).map_err(|e| Error::new(format!("{}: {e}", path.display())))?;
    let (name, _) = &plan.scenes[0];
    let base: Vec<&Row> = sweep
        .rows
        .iter()
        .filter(|r| &r.scene == name && r.emitted == plan.photons[0])
        .collect();
    pareto::pareto(
        &dir.join("pareto.png"),
        &base,
        exact,
        &format!(
            "{name}, {} emitted photons: image error against core throughput",
            plan.photons[0]
        ),
    )?;
    plots::exact(&dir.join("exact.png"), exact)?;
    plots::figures(dir, figs)
}
