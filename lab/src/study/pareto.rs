//! The Pareto plot: image error against the core's queries/s for every point of
//! the sweep the core can run (one series per metric and radius), the `--exact`
//! points at zero error on an explicit floor (a log axis cannot show 0), the
//! non-dominated front as a line, and labels placed so that none overlaps another.

use crate::study::exact_series::ExactSeries;
use crate::study::plot_axes::{count, log_ticks, percent, Placer, Ticked};
use crate::study::plots::{png, Area, Drawn, COLORS, FONT};
use crate::study::sweep::Row;
use photon_fpga::host::error::Result;
use photon_fpga::hw::config::metric::Metric;
use plotters::prelude::*;
use std::path::Path;

/// One point of the plot.
struct Dot {
    /// Series: 0..4 the sweep's (metric × radius), 4 the exact points.
    series: usize,
    qps: f64,
    /// Image rel. RMSE against float (%); 0 for the exact points.
    err: f64,
    label: String,
    /// Labelled even off the front (the m `--exact` chooses).
    key: bool,
}

const SWEEP_SERIES: [(Metric, bool); 4] = [
    (Metric::L1, false),
    (Metric::L2, false),
    (Metric::L1, true),
    (Metric::L2, true),
];

fn series_name(i: usize, exact: &ExactSeries) -> String {
    match SWEEP_SERIES.get(i) {
        Some((m, false)) => format!("{m}, the core's grid radius\n(labels: bits/k)"),
        Some((m, true)) => format!("{m}, radius recomputed on the host\n(labels: bits/k)"),
        None => format!(
            "--exact ({}): answers = float's,\nat zero error (labels: bits/k+m;\nfilled: the m it chooses)",
            exact.metric
        ),
    }
}

fn color(series: usize) -> RGBColor {
    COLORS.get(series).copied().unwrap_or(BLACK)
}

/// Indices of the non-dominated dots, fastest first: no other dot is at least as
/// fast and at least as accurate, and better in one.
fn front(dots: &[Dot]) -> Vec<usize> {
    let mut order: Vec<usize> = (0..dots.len()).collect();
    order.sort_by(|&a, &b| {
        dots[b]
            .qps
            .total_cmp(&dots[a].qps)
            .then(dots[a].err.total_cmp(&dots[b].err))
    });
    let mut best = f64::INFINITY;
    let mut out = vec![];
    for i in order {
        if dots[i].err < best {
            best = dots[i].err;
            out.push(i);
        }
    }
    out
}

/// The dots: every sweep point with a hardware queries/s (both radii), every exact
/// point with one whose answers all equal float's.
fn dots(rows: &[&Row], exact: &ExactSeries) -> Vec<Dot> {
    let mut out = vec![];
    for r in rows {
        let Some(q) = r.hw.as_ref().and_then(|h| h.queries_per_s) else {
            continue;
        };
        for (i, &(metric, host)) in SWEEP_SERIES.iter().enumerate() {
            if metric == r.metric {
                let err = if host { r.err_float_host } else { r.err_float };
                out.push(Dot {
                    series: i,
                    qps: q,
                    err: 100.0 * err.max(0.0),
                    label: format!("{}/{}", r.bits, r.k),
                    key: false,
                });
            }
        }
    }
    for p in exact.points.iter().filter(|p| p.differ == 0) {
        if let Some(q) = p.hw_queries_per_s() {
            out.push(Dot {
                series: SWEEP_SERIES.len(),
                qps: q,
                err: 0.0,
                label: format!("{}/{}+{}", p.bits, p.k, p.m),
                key: p.chosen,
            });
        }
    }
    out
}

/// The legend, in its own panel beside the chart (never over a point).
fn side_legend(area: &Area, entries: &[(String, ShapeStyle, bool)]) -> Drawn {
    let style = TextStyle::from((FONT, 13).into_font());
    let mut y = 80;
    for (name, shape, line) in entries {
        if *line {
            area.draw(&PathElement::new(vec![(8, y), (28, y)], *shape))?;
        } else {
            area.draw(&Circle::new((18, y), 5, *shape))?;
        }
        for text in name.lines() {
            area.draw(&Text::new(text.to_string(), (36, y - 7), style.clone()))?;
            y += 17;
        }
        y += 10;
    }
    Ok(())
}

/// Image error against hardware queries/s: `rows` are the sweep's points to show
/// (one scene, one photon count), `exact` the `--exact` series on the same photons.
pub fn pareto(path: &Path, rows: &[&Row], exact: &ExactSeries, title: &str) -> Result<()> {
    let dots = dots(rows, exact);
    let positive = dots.iter().map(|d| d.err).filter(|e| *e > 0.0);
    let lowest = positive.clone().fold(f64::INFINITY, f64::min);
    let highest = positive.fold(0.0f64, f64::max);
    let (lowest, highest) = if lowest.is_finite() {
        (lowest, highest)
    } else {
        (1.0, 10.0)
    };
    // Zero error sits on a floor a third of a decade and more below the least error.
    let floor = lowest / 3.0;
    let (y0, y1) = (floor / 1.6, highest * 1.5);
    let qps = dots.iter().map(|d| d.qps).filter(|q| *q > 0.0);
    let (x0, x1) = qps
        .clone()
        .fold((f64::INFINITY, 0.0f64), |(l, h), q| (l.min(q), h.max(q)));
    let (x0, x1) = if x0 <= x1 {
        (x0 / 1.15, x1 * 1.15)
    } else {
        (1e5, 1e7)
    };
    let (xb, xl) = log_ticks(x0, x1);
    let (mut yb, yl) = log_ticks(floor * 1.8, y1);
    yb.insert(0, floor);
    let at_floor = move |y: f64| (y / floor - 1.0).abs() < 1e-9;
    let y = move |d: &Dot| if d.err > 0.0 { d.err } else { floor };
    let on_front = front(&dots);
    png(path, 1300, 720, |root| {
        let (left, right) = root.split_horizontally(960);
        let mut chart = ChartBuilder::on(&left)
            .caption(title, (FONT, 20))
            .margin(15)
            .x_label_area_size(50)
            .y_label_area_size(90)
            .build_cartesian_2d(
                Ticked::<LogCoord<f64>>::new((x0..x1).log_scale(), xb, xl),
                Ticked::<LogCoord<f64>>::new((y0..y1).log_scale(), yb, yl),
            )?;
        chart
            .configure_mesh()
            .x_label_formatter(&|x| count(*x))
            .y_label_formatter(&|v| {
                if at_floor(*v) {
                    "0 (exact)".into()
                } else {
                    percent(*v)
                }
            })
            .x_desc("hardware queries/s per core (simulated reads/cycle x clock, see STUDY.md)")
            .y_desc("image rel. RMSE vs float render")
            .axis_desc_style((FONT, 15))
            .label_style((FONT, 13))
            .draw()?;
        // The floor: zero error, which a log axis cannot show, drawn as a line.
        chart.draw_series(DashedLineSeries::new(
            [(x0, floor), (x1, floor)],
            8,
            5,
            BLACK.stroke_width(1),
        ))?;
        let front_pts: Vec<(f64, f64)> = on_front
            .iter()
            .map(|&i| (dots[i].qps, y(&dots[i])))
            .collect();
        chart.draw_series(LineSeries::new(front_pts, BLACK.stroke_width(2)))?;
        for d in &dots {
            let c = color(d.series);
            let style = if d.series < SWEEP_SERIES.len() || d.key {
                c.filled()
            } else {
                c.stroke_width(2)
            };
            chart.draw_series([Circle::new((d.qps, y(d)), 4, style)])?;
        }
        // Labels: the front's first, then the chosen exact points, then the rest;
        // each where it overlaps no label, no point and no edge, or not at all.
        let px: Vec<(i32, i32)> = dots
            .iter()
            .map(|d| chart.backend_coord(&(d.qps, y(d))))
            .collect();
        let (xr, yr) = chart.plotting_area().get_pixel_range();
        let mut placer = Placer::new((xr.start, yr.start, xr.end, yr.end), &px, 5);
        let floor_text = "floor: 0 % error (--exact; a log axis cannot show 0)";
        let note = TextStyle::from((FONT, 12).into_font());
        let floor_px = chart.backend_coord(&(x0, floor));
        let size = left.estimate_text_size(floor_text, &note)?;
        if let Some((dx, dy)) = placer.place((xr.start, floor_px.1), size) {
            left.draw(&Text::new(
                floor_text,
                (xr.start + dx, floor_px.1 + dy),
                note,
            ))?;
        }
        let mut order: Vec<usize> = on_front.clone();
        order.extend((0..dots.len()).filter(|i| dots[*i].key && !on_front.contains(i)));
        order.extend((0..dots.len()).filter(|i| {
            !dots[*i].key && !on_front.contains(i) && dots[*i].series < SWEEP_SERIES.len()
        }));
        let font = TextStyle::from((FONT, 10).into_font());
        for i in order {
            let size = left.estimate_text_size(&dots[i].label, &font)?;
            if let Some((dx, dy)) = placer.place(px[i], size) {
                let at = (px[i].0 + dx, px[i].1 + dy);
                left.draw(&Text::new(dots[i].label.clone(), at, font.clone()))?;
            }
        }
        let mut entries: Vec<(String, ShapeStyle, bool)> = (0..=SWEEP_SERIES.len())
            .filter(|s| dots.iter().any(|d| d.series == *s))
            .map(|s| (series_name(s, exact), color(s).filled(), false))
            .collect();
        entries.push((
            "non-dominated front (no point is\nboth faster and more accurate)".into(),
            BLACK.stroke_width(2),
            true,
        ));
        entries.push((
            "the floor: zero error against float".into(),
            BLACK.stroke_width(1),
            true,
        ));
        side_legend(&right, &entries)
    })
}
