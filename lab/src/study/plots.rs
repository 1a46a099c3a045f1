//! The study's plots: the `--exact` series against m and the paper's Figs. 3–6
//! (the Pareto plot is `pareto`'s), drawn with plotters into an RGB buffer
//! and encoded with the `image` crate. The font is bundled (DejaVu Sans,
//! `assets/`), so the plots look the same on any machine.

use crate::study::exact_series::{ExactPoint, ExactSeries};
use crate::study::figures::{Breakdown, FigPoint, Figures, HW_PARTS, SW_PARTS};
use crate::study::plot_axes::{count, trim, Ticked};
use photon_fpga::host::error::{Error, Result};
use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;
use std::sync::Once;

pub type Area<'a> = DrawingArea<BitMapBackend<'a>, Shift>;
pub type Drawn = std::result::Result<(), Box<dyn std::error::Error>>;

/// The legend box every chart here draws.
pub fn legend<'a, CT: CoordTranslate>(
    chart: &mut ChartContext<'a, BitMapBackend<'a>, CT>,
    position: SeriesLabelPosition,
    size: u32,
) -> Drawn {
    chart
        .configure_series_labels()
        .position(position)
        .label_font((FONT, size))
        .background_style(WHITE.mix(0.9))
        .border_style(BLACK)
        .draw()?;
    Ok(())
}

pub const FONT: &str = "sans-serif";
pub const COLORS: [RGBColor; 4] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(255, 127, 14),
];

fn register_font() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        // The bundled TTF is valid; a failure would show as missing text only.
        let _ = plotters::style::register_font(
            FONT,
            FontStyle::Normal,
            include_bytes!("../../assets/DejaVuSans.ttf"),
        );
    });
}

/// A chart on `area` in the plots' style: `title` above, the margins and label
/// areas every panel here has; the caller builds its axes.
pub fn chart_on<'a, 'b>(
    area: &'a Area<'b>,
    title: &str,
) -> ChartBuilder<'a, 'a, BitMapBackend<'b>> {
    let mut b = ChartBuilder::on(area);
    b.caption(title, (FONT, 16))
        .margin(12)
        .x_label_area_size(45)
        .y_label_area_size(70);
    b
}

/// Draw a `w` x `h` PNG at `path`.
pub fn png(path: &Path, w: u32, h: u32, draw: impl FnOnce(&Area) -> Drawn) -> Result<()> {
    register_font();
    let fail = |e: &dyn std::fmt::Display| Error::new(format!("{}: {e}", path.display()));
    let mut buf = vec![255u8; (w * h * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| fail(&e))?;
        draw(&root).map_err(|e| fail(&e))?;
        root.present().map_err(|e| fail(&e))?;
    }
    let img = image::RgbImage::from_raw(w, h, buf).expect("buffer of w x h x 3");
    img.save_with_format(path, image::ImageFormat::Png)
        .map_err(|e| fail(&e))
}

/// A number of a point of the `--exact` series.
type Value<'a> = &'a dyn Fn(&ExactPoint) -> f64;

/// The series' points at `bits` coordinate bits by m (the chosen m is marked apart).
fn line_at(s: &ExactSeries, bits: u32) -> Vec<&ExactPoint> {
    let mut line: Vec<&ExactPoint> = s
        .points
        .iter()
        .filter(|p| p.bits == bits && !p.chosen)
        .collect();
    line.sort_by_key(|p| p.m);
    line
}

/// One panel of the `--exact` figure: `value` of every point against m, a line per
/// coordinate width (and `dashed`, if given, as a dashed line of the same colour),
/// the m `--exact` chooses marked with a triangle.
fn exact_panel(
    area: &Area,
    title: &str,
    y_desc: &str,
    s: &ExactSeries,
    value: Value,
    dashed: Option<(&str, Value)>,
    y_range: (f64, f64),
) -> Drawn {
    let mut widths: Vec<u32> = s.points.iter().map(|p| p.bits).collect();
    widths.sort_unstable();
    widths.dedup();
    let mut ms: Vec<usize> = s.points.iter().filter(|p| !p.chosen).map(|p| p.m).collect();
    ms.sort_unstable();
    ms.dedup();
    let top = s.points.iter().map(|p| p.m).max().unwrap_or(1).max(1) as f64;
    let ticks: Vec<f64> = ms.iter().map(|&m| m as f64).collect();
    let mut chart = chart_on(area, title).build_cartesian_2d(
        Ticked::<RangedCoordf64>::new(-0.02 * top..top * 1.04, ticks, vec![]),
        y_range.0..y_range.1,
    )?;
    chart
        .configure_mesh()
        .x_label_formatter(&|x| trim(*x))
        .y_label_formatter(&|y| trim(*y))
        .x_desc(format!("m (the core searches k' = k + m = {} + m)", s.k))
        .y_desc(y_desc)
        .axis_desc_style((FONT, 13))
        .label_style((FONT, 12))
        .draw()?;
    for (i, &b) in widths.iter().enumerate() {
        let c = COLORS[i % COLORS.len()];
        let pts: Vec<(f64, f64)> = line_at(s, b)
            .iter()
            .map(|p| (p.m as f64, value(p)))
            .collect();
        chart
            .draw_series(LineSeries::new(pts.clone(), c.stroke_width(2)))?
            .label(format!("{b} bits"))
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], c.stroke_width(2)));
        chart.draw_series(pts.iter().map(|&p| Circle::new(p, 3, c.filled())))?;
    }
    if let Some((name, f)) = dashed {
        for (i, &b) in widths.iter().enumerate() {
            let c = COLORS[i % COLORS.len()];
            let d: Vec<(f64, f64)> = line_at(s, b).iter().map(|p| (p.m as f64, f(p))).collect();
            let series = chart.draw_series(DashedLineSeries::new(d, 6, 4, c.stroke_width(1)))?;
            if i == 0 {
                series.label(name).legend(|(x, y)| {
                    PathElement::new(vec![(x, y), (x + 16, y)], BLACK.stroke_width(1))
                });
            }
        }
    }
    let chosen: Vec<(usize, &ExactPoint)> = s
        .points
        .iter()
        .filter(|p| p.chosen)
        .map(|p| (widths.iter().position(|&b| b == p.bits).unwrap_or(0), p))
        .collect();
    chart
        .draw_series(chosen.iter().map(|&(i, p)| {
            TriangleMarker::new(
                (p.m as f64, value(p)),
                8,
                COLORS[i % COLORS.len()].stroke_width(2),
            )
        }))?
        .label("m chosen by --exact")
        .legend(|(x, y)| TriangleMarker::new((x + 8, y), 6, BLACK.stroke_width(2)));
    legend(&mut chart, SeriesLabelPosition::LowerRight, 12)?;
    Ok(())
}

/// The `--exact` series: the certified share and the photon reads per query (core
/// and float fallbacks) against m, a line per coordinate width.
pub fn exact(path: &Path, s: &ExactSeries) -> Result<()> {
    let shares = s.points.iter().map(|p| 100.0 * p.certified_share());
    let low = shares.fold(100.0f64, f64::min);
    let low = ((low - 5.0) / 10.0).floor().max(0.0) * 10.0;
    let reads = s.points.iter().map(|p| p.reads()).fold(0.0f64, f64::max);
    let what = format!(
        "{}, {} emitted photons, {}, k = {}",
        s.scene,
        count(s.emitted as f64),
        s.metric,
        s.k
    );
    png(path, 1200, 520, |root| {
        let (l, r) = root.split_horizontally(600);
        exact_panel(
            &l,
            &format!("--exact: certified queries ({what})"),
            "certified (% of the core's queries)",
            s,
            &|p| 100.0 * p.certified_share(),
            None,
            (low, 101.0),
        )?;
        exact_panel(
            &r,
            "--exact: photon reads per query, float fallbacks included",
            "photon reads / query",
            s,
            &|p| p.reads(),
            Some(("the core's reads alone (dashed)", &|p| p.core_reads)),
            (0.0, reads.max(1.0) * 1.15),
        )
    })
}

/// One panel: `series` of (name, points) against x.
pub fn line_panel(
    area: &Area,
    title: &str,
    x_desc: &str,
    y_desc: &str,
    series: &[(&str, Vec<(f64, f64)>)],
) -> Drawn {
    // A non-finite point has no place on an axis (and would make the tick search
    // of an infinite range run forever): such points are left out.
    let series: Vec<(&str, Vec<(f64, f64)>)> = series
        .iter()
        .map(|(n, pts)| {
            let finite = pts
                .iter()
                .copied()
                .filter(|p| p.0.is_finite() && p.1.is_finite());
            (*n, finite.collect())
        })
        .collect();
    let xs = series.iter().flat_map(|s| s.1.iter().map(|p| p.0));
    let x1 = xs.clone().fold(0.0f64, f64::max) * 1.05;
    let y1 = series
        .iter()
        .flat_map(|s| s.1.iter().map(|p| p.1))
        .fold(0.0f64, f64::max)
        * 1.15;
    let mut chart = ChartBuilder::on(area)
        .caption(title, (FONT, 16))
        .margin(12)
        .x_label_area_size(45)
        .y_label_area_size(70)
        .build_cartesian_2d(0.0..x1.max(1e-9), 0.0..y1.max(1e-12))?;
    chart
        .configure_mesh()
        .x_desc(x_desc)
        .y_desc(y_desc)
        .axis_desc_style((FONT, 13))
        .label_style((FONT, 12))
        .draw()?;
    for (i, (name, pts)) in series.iter().enumerate() {
        let c = COLORS[i % COLORS.len()];
        chart
            .draw_series(LineSeries::new(pts.clone(), c.stroke_width(2)))?
            .label(*name)
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], c.stroke_width(2)));
        chart.draw_series(pts.iter().map(|&p| Circle::new(p, 3, c.filled())))?;
    }
    legend(&mut chart, SeriesLabelPosition::UpperLeft, 12)?;
    Ok(())
}

/// Figs. 3–5: time (software measured, core from simulated reads/cycle) and photon
/// reads per query against `x_desc`.
pub fn time_and_reads(path: &Path, title: &str, x_desc: &str, pts: &[FigPoint]) -> Result<()> {
    let sw: Vec<(f64, f64)> = pts.iter().map(|p| (p.x, p.seconds)).collect();
    let hw: Vec<(f64, f64)> = pts
        .iter()
        .filter_map(|p| Some((p.x, p.hw_seconds?)))
        .collect();
    let reads: Vec<(f64, f64)> = pts.iter().map(|p| (p.x, p.reads_per_query)).collect();
    png(path, 1200, 500, |root| {
        let (l, r) = root.split_horizontally(600);
        let mut time = vec![("software search, 1 thread (measured)", sw)];
        if !hw.is_empty() {
            time.push(("one core (simulated reads/cycle x clock)", hw));
        }
        line_panel(&l, &format!("{title}: time"), x_desc, "seconds", &time)?;
        line_panel(
            &r,
            &format!("{title}: photons read per query"),
            x_desc,
            "photon reads / query (software = core)",
            &[("reads per query", reads)],
        )
    })
}

/// One stacked-bar panel: per k, the parts of `values`; `total` marks measured totals.
fn bars(
    area: &Area,
    title: &str,
    y_desc: &str,
    ks: &[usize],
    parts: &[&str],
    values: &[[f64; 4]],
    total: Option<&[f64]>,
) -> Drawn {
    let top = values
        .iter()
        .map(|v| v.iter().sum::<f64>())
        .chain(total.into_iter().flatten().copied())
        .fold(0.0f64, f64::max)
        * 1.3;
    let n = ks.len();
    let mut chart = ChartBuilder::on(area)
        .caption(title, (FONT, 16))
        .margin(12)
        .x_label_area_size(45)
        .y_label_area_size(70)
        .build_cartesian_2d(-0.5f64..n as f64 - 0.5, 0.0..top.max(1e-9))?;
    chart
        .configure_mesh()
        .x_labels(n)
        .x_label_formatter(&|x| {
            let i = x.round() as usize;
            if (x - x.round()).abs() < 0.01 && i < ks.len() {
                format!("k = {}", ks[i])
            } else {
                String::new()
            }
        })
        .y_desc(y_desc)
        .axis_desc_style((FONT, 13))
        .label_style((FONT, 12))
        .draw()?;
    for (p, name) in parts.iter().enumerate() {
        let c = COLORS[p % COLORS.len()];
        chart
            .draw_series(values.iter().enumerate().map(|(i, v)| {
                let below: f64 = v[..p].iter().sum();
                let x = i as f64;
                Rectangle::new([(x - 0.3, below), (x + 0.3, below + v[p])], c.filled())
            }))?
            .label(*name)
            .legend(move |(x, y)| Rectangle::new([(x, y - 5), (x + 12, y + 5)], c.filled()));
    }
    if let Some(t) = total {
        chart
            .draw_series(
                t.iter()
                    .enumerate()
                    .map(|(i, &v)| Cross::new((i as f64, v), 6, BLACK.stroke_width(2))),
            )?
            .label("measured whole search")
            .legend(|(x, y)| Cross::new((x + 6, y), 5, BLACK.stroke_width(2)));
    }
    legend(&mut chart, SeriesLabelPosition::UpperLeft, 12)?;
    Ok(())
}

/// Fig. 6: the search's breakdown per query against k, software and core.
pub fn breakdown(path: &Path, b: &[Breakdown]) -> Result<()> {
    let ks: Vec<usize> = b.iter().map(|x| x.k).collect();
    let sw: Vec<[f64; 4]> = b.iter().map(|x| x.sw_ns).collect();
    let measured: Vec<f64> = b.iter().map(|x| x.sw_measured_ns).collect();
    let hw_rows: Vec<&Breakdown> = b.iter().filter(|x| x.hw_cycles.is_some()).collect();
    let hw_ks: Vec<usize> = hw_rows.iter().map(|x| x.k).collect();
    let hw: Vec<[f64; 4]> = hw_rows.iter().filter_map(|x| x.hw_cycles).collect();
    png(path, 1200, 520, |root| {
        let (l, r) = root.split_horizontally(600);
        bars(
            &l,
            "Fig. 6, software: ns per query (counts x unit cost)",
            "ns per query",
            &ks,
            &SW_PARTS,
            &sw,
            Some(&measured),
        )?;
        bars(
            &r,
            "Fig. 6, core: QueryModule cycles per query (model)",
            "cycles per query",
            &hw_ks,
            &HW_PARTS,
            &hw,
            None,
        )
    })
}

/// Figs. 3–6 into `dir`.
pub fn figures(dir: &Path, f: &Figures) -> Result<()> {
    let t = |n: u32, what: &str| format!("Fig. {n} ({}, L1, 10-bit{what})", f.scene);
    time_and_reads(&dir.join("fig3.png"), &t(3, ", k = 10"), "queries", &f.fig3)?;
    time_and_reads(
        &dir.join("fig4.png"),
        &t(4, ", k = 10"),
        "emitted photons",
        &f.fig4,
    )?;
    time_and_reads(
        &dir.join("fig5.png"),
        &t(5, ""),
        "k (photons searched)",
        &f.fig5,
    )?;
    breakdown(&dir.join("fig6.png"), &f.fig6)
}
