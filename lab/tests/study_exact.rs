//! The study's `--exact` series: the quick study's exact.csv and STUDY.md section
//! (called from `study`'s quick run) and the plots' readable ticks and labels that
//! never overlap.

use photon_fpga_lab::study::plot_axes::{count, log_ticks, percent, Placer};
use rand::{Rng, SeedableRng};
use std::collections::BTreeMap;
use std::path::Path;

type Record = BTreeMap<String, String>;

fn read_csv(path: &Path) -> Vec<Record> {
    let mut r = csv::Reader::from_path(path).unwrap();
    let header: Vec<String> = r.headers().unwrap().iter().map(String::from).collect();
    r.records()
        .map(|rec| {
            header
                .iter()
                .cloned()
                .zip(rec.unwrap().iter().map(String::from))
                .collect()
        })
        .collect()
}

fn num(row: &Record, col: &str) -> f64 {
    row[col]
        .parse()
        .unwrap_or_else(|_| panic!("{col} = {:?}", row[col]))
}

/// The quick study's `--exact` series (exact.csv and its STUDY.md section): every
/// width and m of the plan, certified share non-decreasing in m, every answer the
/// float search's, the counts adding up, queries/s the CSV's own reads per cycle x
/// clock over reads per query.
pub(crate) fn check_exact_series(out: &Path, md: &str) {
    let rows = read_csv(&out.join("exact.csv"));
    let ms = [0, 4, 8, 12, 16, 24, 32];
    for bits in ["8", "10", "12"] {
        let mut given: Vec<&Record> = rows
            .iter()
            .filter(|r| r["bits"] == bits && r["m_chosen"] == "false")
            .collect();
        given.sort_by_key(|r| num(r, "m") as usize);
        let got: Vec<usize> = given.iter().map(|r| num(r, "m") as usize).collect();
        assert_eq!(got, ms, "{bits} bits");
        let chosen: Vec<_> = rows
            .iter()
            .filter(|r| r["bits"] == bits && r["m_chosen"] == "true")
            .collect();
        assert_eq!(chosen.len(), 1, "{bits} bits: one chosen m");
        assert!(
            num(chosen[0], "m") <= num(chosen[0], "k"),
            "{:?}",
            chosen[0]
        );
        for w in given.windows(2) {
            assert!(
                num(w[1], "certified") >= num(w[0], "certified"),
                "{bits} bits: certified falls from m = {} to m = {}",
                w[0]["m"],
                w[1]["m"]
            );
        }
        // More candidates certify more: the largest m certifies more than m = 0.
        assert!(num(given[6], "certified") > num(given[0], "certified"));
    }
    for r in &rows {
        assert_eq!(r["answers_differing_from_float"], "0", "{r:?}");
        let (core, cert, fall) = (
            num(r, "core_queries"),
            num(r, "certified"),
            num(r, "fallbacks"),
        );
        assert_eq!(cert + fall, core, "{r:?}");
        assert!((num(r, "certified_fraction") - cert / core).abs() < 1e-6);
        assert_eq!(num(r, "k_prime"), num(r, "k") + num(r, "m"));
        let reads = num(r, "reads_per_query");
        let parts = num(r, "core_reads_per_query") + num(r, "fallback_reads_per_query");
        assert!((reads - parts).abs() < 2e-3, "{r:?}");
        assert!(r["hw_reads_source"].starts_with("simulated"), "{r:?}");
        let qps = num(r, "hw_reads_per_cycle") * num(r, "fmax_mhz") * 1e6 / reads;
        let rel = (num(r, "hw_queries_per_s") - qps).abs() / qps;
        assert!(rel < 1e-3, "{r:?}: queries/s {qps}");
    }
    assert!(
        md.contains("## `--exact`: zero error against float"),
        "{md}"
    );
    assert!(
        md.contains("At 10 bits, k = 10: `--exact` (m = ") && md.contains("(exact.png)"),
        "{md}"
    );
}

/// Ticks a person reads, and labels that never overlap.
#[test]
fn plot_ticks_read_well_and_labels_never_overlap() {
    assert_eq!(count(1e6), "1 M");
    assert_eq!(count(2.5e6), "2.5 M");
    assert_eq!(count(5e5), "500 K");
    assert_eq!(count(1.2e9), "1.2 G");
    assert_eq!(percent(0.5), "0.5 %");
    assert_eq!(percent(20.0), "20 %");
    // 1, 2, 5 per decade; every digit on a short axis; powers of ten on a long one.
    let (bold, light) = log_ticks(0.7, 120.0);
    assert_eq!(bold, vec![1.0, 2.0, 5.0, 10.0, 20.0, 50.0, 100.0]);
    assert!(light.contains(&3.0) && !light.contains(&2.0));
    assert_eq!(log_ticks(1.2e6, 4.4e6).0, vec![2e6, 3e6, 4e6]);
    assert_eq!(log_ticks(1e-3, 1e5).0.len(), 9);
    // Labels at random points: each placed one inside the bounds and clear of every
    // other label and every marker, checked pair by pair.
    let mut r = rand_pcg::Pcg64Mcg::seed_from_u64(9);
    let bounds = (0, 0, 600, 400);
    let pts: Vec<(i32, i32)> = (0..300)
        .map(|_| (r.gen_range(0..600), r.gen_range(0..400)))
        .collect();
    let mut placer = Placer::new(bounds, &pts, 4);
    let mut placed = vec![];
    for &p in &pts {
        let size = (r.gen_range(10..60), r.gen_range(8..14));
        if let Some((dx, dy)) = placer.place(p, size) {
            let (x, y) = (p.0 + dx, p.1 + dy);
            placed.push((x, y, x + size.0 as i32, y + size.1 as i32));
        }
    }
    assert!(placed.len() > 30, "only {} placed", placed.len());
    let overlap = |a: (i32, i32, i32, i32), b: (i32, i32, i32, i32)| {
        a.0 < b.2 && b.0 < a.2 && a.1 < b.3 && b.1 < a.3
    };
    for (i, &a) in placed.iter().enumerate() {
        assert!(a.0 >= 0 && a.1 >= 0 && a.2 <= 600 && a.3 <= 400, "{a:?}");
        for &b in &placed[i + 1..] {
            assert!(!overlap(a, b), "{a:?} {b:?}");
        }
        for &(x, y) in &pts {
            assert!(
                !overlap(a, (x - 4, y - 4, x + 4, y + 4)),
                "{a:?} over {x},{y}"
            );
        }
    }
}

/// The study's series on a small Cornell box: a certified query stays certified at a
/// larger m (its k′-th grid distance only grows and its threshold only falls), the
/// counts add up, and the table has a row per point.
#[test]
fn exact_series_is_monotone_in_m() {
    use photon_fpga::host::gather::GatherParams;
    use photon_fpga::host::render::renderer::{eye_queries, photon_points, query_points};
    use photon_fpga::host::render::{photons::trace_photons, scene::Scene, RenderSettings};
    use photon_fpga::hw::config::metric::Metric;
    use photon_fpga_lab::study::{exact_report, exact_series};
    let scene = Scene::cornell_box();
    let photons = photon_points(&trace_photons(&scene, 8000, 3, false));
    let settings = RenderSettings {
        width: 24,
        height: 18,
        spp: 1,
        ..RenderSettings::default()
    };
    let queries = query_points(&eye_queries(&scene, &settings).0);
    let base = GatherParams {
        k: 16,
        bits: 10,
        metric: Metric::L2,
        ..GatherParams::default()
    };
    let ms = [Some(0), Some(4), Some(8), Some(16), None];
    let pts = exact_series::run(&photons, &queries, &base, &[8, 10], &ms).unwrap();
    assert_eq!(pts.len(), 10);
    for w in pts.chunks(ms.len()) {
        assert!(w[4].chosen && !w[0].chosen);
        let w = &w[..4];
        for p in w {
            assert_eq!(p.certified + p.fallbacks, p.core_queries, "{p:?}");
            assert!(p.retry_certified <= p.fallbacks);
        }
        for pair in w.windows(2) {
            assert!(pair[1].certified >= pair[0].certified, "{pair:?}");
            assert!(pair[1].core_reads >= pair[0].core_reads, "{pair:?}");
        }
        assert!(w[3].certified > w[0].certified, "{w:?}");
    }
    let table = format!(
        "{}{}",
        exact_report::headline(&pts, 10, None),
        exact_report::markdown(&pts)
    );
    let rows = table
        .lines()
        .filter(|l| l.starts_with("| 10 ") || l.starts_with("| 8 "));
    assert_eq!(rows.count(), 10, "{table}");
    assert!(
        table.starts_with("At 10 bits, k = 16: `--exact` (m = "),
        "{table}"
    );
}
