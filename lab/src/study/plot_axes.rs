//! What the study's plots need beyond plotters: tick positions and labels a person
//! reads on log axes (1, 2, 5 per decade; `2 M`, not `2000000.0`), and point labels
//! placed so that no two overlap (each tries a few offsets around its point and is
//! left out if none is free).

use plotters::coord::ranged1d::{DefaultFormatting, KeyPointHint, Ranged};
use std::ops::Range;

/// `x` with at most three significant digits and no trailing zeros: `2.5`, `1`,
/// `0.05`, `120`.
pub fn trim(x: f64) -> String {
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    let digits = (2 - x.abs().log10().floor() as i32).max(0) as usize;
    let s = format!("{x:.digits$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

/// A count with its SI suffix: `500 K`, `1 M`, `2.5 M`, `1.2 G`; below 1000 as is.
pub fn count(x: f64) -> String {
    let (unit, s) = [(1e9, " G"), (1e6, " M"), (1e3, " K")]
        .into_iter()
        .find(|(u, _)| x.abs() >= *u)
        .unwrap_or((1.0, ""));
    format!("{}{s}", trim(x / unit))
}

/// A percentage: `0.5 %`, `10 %`.
pub fn percent(x: f64) -> String {
    format!("{} %", trim(x))
}

/// Ticks of a log axis over `lo..hi` (both > 0): the labelled ones (1, 2 and 5 ×
/// 10^n; every digit when that gives fewer than three, powers of ten only when it
/// gives more than ten) and the unlabelled grid lines between them (every digit).
pub fn log_ticks(lo: f64, hi: f64) -> (Vec<f64>, Vec<f64>) {
    let (lo, hi) = (lo.min(hi), lo.max(hi));
    if !(lo > 0.0 && hi.is_finite()) {
        return (vec![], vec![]);
    }
    let decades = lo.log10().floor() as i32..=hi.log10().ceil() as i32;
    let at = |mantissas: &[f64]| -> Vec<f64> {
        decades
            .clone()
            .flat_map(|d| mantissas.iter().map(move |m| m * 10f64.powi(d)))
            // 10^d as a float may sit a hair beside the axis' end.
            .filter(|&v| v >= lo * (1.0 - 1e-9) && v <= hi * (1.0 + 1e-9))
            .collect()
    };
    let all = at(&[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0]);
    let mut bold = at(&[1.0, 2.0, 5.0]);
    if bold.len() < 3 {
        bold = all.clone();
    } else if bold.len() > 10 {
        bold = at(&[1.0]);
    }
    let light = all.into_iter().filter(|v| !bold.contains(v)).collect();
    (bold, light)
}

/// A pixel rectangle: left, top, right, bottom.
type Rect = (i32, i32, i32, i32);

fn overlap(a: Rect, b: Rect) -> bool {
    a.0 < b.2 && b.0 < a.2 && a.1 < b.3 && b.1 < a.3
}

/// Places point labels so that none overlaps another label, a marker or the edge
/// of the plotting area.
pub struct Placer {
    bounds: Rect,
    taken: Vec<Rect>,
}

impl Placer {
    /// Labels inside `bounds` (pixels), clear of markers of `radius` at `markers`.
    pub fn new(bounds: Rect, markers: &[(i32, i32)], radius: i32) -> Placer {
        let taken = markers
            .iter()
            .map(|&(x, y)| (x - radius, y - radius, x + radius, y + radius))
            .collect();
        Placer { bounds, taken }
    }

    /// Where a label of `size` (pixels) for the point at `at` goes: its top-left
    /// corner's offset from the point (right, above, below, left, then farther out),
    /// or `None` if every place is taken.
    pub fn place(&mut self, at: (i32, i32), size: (u32, u32)) -> Option<(i32, i32)> {
        let (w, h) = (size.0 as i32, size.1 as i32);
        let offsets = [
            (6, -h - 2),
            (6, 2),
            (-w / 2, -h - 6),
            (-w / 2, 6),
            (-w - 6, -h - 2),
            (-w - 6, 2),
            (6, -h / 2),
            (-w - 6, -h / 2),
            (10, -2 * h - 2),
            (10, h + 2),
            (-w - 10, -2 * h - 2),
            (-w - 10, h + 2),
        ];
        let b = self.bounds;
        for (dx, dy) in offsets {
            let r = (at.0 + dx, at.1 + dy, at.0 + dx + w, at.1 + dy + h);
            let inside = r.0 >= b.0 && r.1 >= b.1 && r.2 <= b.2 && r.3 <= b.3;
            if inside && !self.taken.iter().any(|&t| overlap(t, r)) {
                self.taken.push(r);
                return Some((dx, dy));
            }
        }
        None
    }
}

/// An axis with the given ticks: `bold` labelled, `light` grid lines only (plotters'
/// own `with_key_points` keeps the linear f64 axis's formatting, which a label
/// formatter cannot replace).
pub struct Ticked<R: Ranged> {
    inner: R,
    bold: Vec<R::ValueType>,
    light: Vec<R::ValueType>,
}

impl<R: Ranged> Ticked<R> {
    pub fn new(inner: impl Into<R>, bold: Vec<R::ValueType>, light: Vec<R::ValueType>) -> Self {
        Ticked {
            inner: inner.into(),
            bold,
            light,
        }
    }
}

impl<R: Ranged> Ranged for Ticked<R>
where
    R::ValueType: Clone,
{
    type FormatOption = DefaultFormatting;
    type ValueType = R::ValueType;

    fn map(&self, value: &Self::ValueType, limit: (i32, i32)) -> i32 {
        self.inner.map(value, limit)
    }

    fn key_points<H: KeyPointHint>(&self, hint: H) -> Vec<Self::ValueType> {
        if hint.weight().allow_light_points() {
            self.light.clone()
        } else {
            self.bold.clone()
        }
    }

    fn range(&self) -> Range<Self::ValueType> {
        self.inner.range()
    }

    fn axis_pixel_range(&self, limit: (i32, i32)) -> Range<i32> {
        self.inner.axis_pixel_range(limit)
    }
}
