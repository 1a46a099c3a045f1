//! The `--exact` series' files: `exact.csv` (every (bits, m) point) and its section
//! of `STUDY.md`, each number with where it comes from.

use crate::study::exact_series::{ExactPoint, ExactSeries};
use crate::study::sweep::Row;
use photon_fpga::host::error::{Error, Result};
use std::fmt::Write as _;
use std::path::Path;

fn mega(x: Option<f64>) -> String {
    x.map_or("n/a".into(), |q| format!("{:.2} M", q / 1e6))
}

/// `exact.csv`: one line per point of the series.
pub fn csv(path: &Path, s: &ExactSeries) -> Result<()> {
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
        "m",
        "m_chosen",
        "k_prime",
        "core_queries",
        "certified",
        "certified_fraction",
        "fallbacks",
        "core_reads_per_query",
        "fallback_reads_per_query",
        "reads_per_query",
        "answers_differing_from_float",
        "retry_k_prime",
        "retry_certified",
        "retry_reads_per_retried_query",
        "float_reads_per_fallback",
        "hw_reads_per_cycle",
        "hw_reads_source",
        "fmax_mhz",
        "fmax_source",
        "hw_queries_per_s",
    ])
    .map_err(|e| fail(&e))?;
    for p in &s.points {
        let mut rec = vec![
            s.scene.clone(),
            s.emitted.to_string(),
            s.stored.to_string(),
            p.queries.to_string(),
            s.metric.to_string(),
            p.k.to_string(),
            p.bits.to_string(),
            p.m.to_string(),
            p.chosen.to_string(),
            (p.k + p.m).to_string(),
            p.core_queries.to_string(),
            p.certified.to_string(),
            format!("{:.6}", p.certified_share()),
            p.fallbacks.to_string(),
            format!("{:.3}", p.core_reads),
            format!("{:.3}", p.host_reads),
            format!("{:.3}", p.reads()),
            p.differ.to_string(),
            p.retry_k.to_string(),
            p.retry_certified.to_string(),
            format!("{:.3}", p.retry_reads),
            format!("{:.3}", p.fallback_reads),
        ];
        match &p.hw {
            Some(h) => rec.extend([
                format!("{:.4}", h.reads_per_cycle),
                h.reads_source.clone(),
                h.cost
                    .fmax_mhz
                    .map_or("n/a: not in REPORT.md".into(), |f| format!("{f:.1}")),
                h.cost.fmax_source.clone(),
                p.hw_queries_per_s()
                    .map_or("n/a: no clock in REPORT.md".into(), |q| format!("{q:.0}")),
            ]),
            None => rec.extend(std::iter::repeat_n(
                "n/a: the sweep did not simulate this metric and k".to_string(),
                5,
            )),
        }
        w.write_record(&rec).map_err(|e| fail(&e))?;
    }
    w.flush().map_err(|e| fail(&e))
}

/// The series as a Markdown table.
pub fn markdown(points: &[ExactPoint]) -> String {
    let mut s = String::from(
        "| bits | k | m | certified | fallbacks | answers ≠ float | core reads/query | \
         fallback reads/query | reads/query | retry at the core's K: certifies / reads | \
         core reads/cycle [sim] | clock | queries/s |\n\
         |---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|---:|\n",
    );
    for p in points {
        let (rpc, clock) = match &p.hw {
            Some(h) => (
                format!("{:.3}", h.reads_per_cycle),
                h.cost.fmax_mhz.map_or("not in REPORT.md".into(), |f| {
                    format!("{f:.1} MHz {}", h.cost.clock_tag())
                }),
            ),
            None => ("n/a: not simulated".into(), String::new()),
        };
        let m = if p.chosen {
            format!("**{}** (chosen)", p.m)
        } else {
            p.m.to_string()
        };
        let _ = writeln!(
            s,
            "| {} | {} | {m} | {:.2} % | {} | {} | {:.1} | {:.2} | {:.1} | {} of {} / {:.1} | \
             {rpc} | {clock} | {} |",
            p.bits,
            p.k,
            100.0 * p.certified_share(),
            p.fallbacks,
            p.differ,
            p.core_reads,
            p.host_reads,
            p.reads(),
            p.retry_certified,
            p.fallbacks,
            p.retry_reads,
            mega(p.hw_queries_per_s()),
        );
    }
    s
}

/// One headline per width: the exact configuration with the m the backend chooses
/// against the unrefined core, the sweep's point of the same metric, k and bits
/// (`unrefined`) where there is one, else the m = 0 point's core reads at the same
/// rate (the same search at k′ = k, without re-ranking).
pub fn headline(points: &[ExactPoint], bits: u32, unrefined: Option<&Row>) -> String {
    let at = |chosen: bool, m: Option<usize>| {
        points
            .iter()
            .find(|p| p.bits == bits && p.chosen == chosen && m.is_none_or(|m| p.m == m))
    };
    let Some(e) = at(true, None) else {
        return String::new();
    };
    let rate = e.hw.as_ref().and_then(|h| h.reads_per_s());
    let (reads, qps, err) = match (unrefined, at(false, Some(0))) {
        (Some(r), _) => (
            r.reads_per_query,
            r.hw.as_ref().and_then(|h| h.queries_per_s),
            Some(r.err_float),
        ),
        (None, Some(u)) => (u.core_reads, rate.map(|r| r / u.core_reads.max(1.0)), None),
        (None, None) => return String::new(),
    };
    let err = err.map_or(String::new(), |e| {
        format!(" at {:.2} % image error against float", 100.0 * e)
    });
    format!(
        "At {bits} bits, k = {}: `--exact` (m = {} chosen, {:.2} % certified, {} answers \
         differing from float) reads {:.1} photons per query with its fallbacks, {} \
         queries/s; the unrefined core reads {reads:.1}, {} queries/s{err}.\n",
        e.k,
        e.m,
        100.0 * e.certified_share(),
        e.differ,
        e.reads(),
        mega(e.hw_queries_per_s()),
        mega(qps),
    )
}

/// The section of `STUDY.md`: provenance, a headline per width, the table.
/// `rows`: the sweep's points of the series' scene and photon count.
pub fn section(s: &ExactSeries, rows: &[&Row]) -> String {
    let mut o = String::new();
    let _ = writeln!(
        o,
        "## `--exact`: zero error against float ({}, {} emitted photons, {}, k = {})\n",
        s.scene, s.emitted, s.metric, s.k
    );
    o.push_str(
        "The core searches k′ = k + m grid candidates; the host re-ranks them by exact f64 \
         distance and keeps the k best where the certificate proves them the float k nearest \
         (`src/host/exact/`); the float search answers the rest and the queries outside the \
         photon box. Every eye query of the scene, with the software model of the core (the \
         simulated core returns the same candidates, read for read).\n\n\
         * **certified**: share of the core's queries (inside the photon box) the certificate \
         proves. **fallbacks**: the others (uncertified or tied at rank k). **answers ≠ float**: \
         queries whose photons or distances differ from `--backend float`'s bit for bit (0: the \
         image error against float is exactly 0). Deterministic.\n\
         * **reads/query**: the core's photon reads (its search at K = k′) plus the float \
         fallbacks', over all queries. **retry**: the fallbacks searched again on the core at \
         K = 64 (its largest found list) instead: how many that certifies, and its reads \
         per retried query (on top of the first pass). Deterministic.\n\
         * **queries/s** = core reads/cycle [sim] × clock / reads per query, fallbacks included \
         (as if the fallbacks' reads ran at the core's rate). Reads per cycle: the sweep's \
         simulation of this scene, metric and k (K = k, listed above) at the nearest simulated \
         bits; clock: the K = k′ core's row of synth/results.json, [P&R], or [assumed] from \
         another row where it has none.\n\
         * **chosen**: the m `--exact` picks without `--refine` (the fewest reads, core and \
         fallbacks, on a sample of the queries).\n\n",
    );
    let mut widths: Vec<u32> = s.points.iter().map(|p| p.bits).collect();
    widths.dedup();
    for b in widths {
        let unrefined = rows
            .iter()
            .find(|r| r.metric == s.metric && r.k == s.k && r.bits == b)
            .copied();
        o.push_str(&headline(&s.points, b, unrefined));
    }
    o.push('\n');
    o.push_str(&markdown(&s.points));
    o.push_str("\n![exact](exact.png)\n");
    o
}
