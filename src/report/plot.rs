//! PNG plots with plotters, text rendered with the committed DejaVu Sans font (no system
//! font needed).
//!
//! Axis ticks are chosen here, not by plotters: [`log_ticks`] and [`linear_ticks`] measure
//! every label with the font's glyph advances ([`text_size`], the metric plotters lays text
//! out with) and keep only tick sets whose labels leave a gap between them along the axis's
//! length in pixels. Legends and slope triangles go to the corner that hides the fewest data.

use crate::contact::Method;
use crate::error::{Error, Result};
use plotters::coord::Shift;
use plotters::coord::ranged1d::{DefaultFormatting, KeyPointHint, ValueFormatter};
use plotters::coord::types::RangedCoordf64;
use plotters::element::{Drawable, PointCollection};
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use plotters_backend::{BackendCoord, DrawingErrorKind};
use std::path::Path;
use std::sync::Once;

const FONT: &[u8] = include_bytes!("../../assets/fonts/DejaVuSans.ttf");

fn register() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, FONT);
    });
}

fn err<E: std::fmt::Display>(path: &Path) -> impl Fn(E) -> Error + '_ {
    move |e| Error::io(path, std::io::Error::other(e.to_string()))
}

/// A white figure of `dim` pixels to be written to `path`.
fn white_figure(path: &Path, dim: (u32, u32)) -> Result<DrawingArea<BitMapBackend<'_>, Shift>> {
    register();
    let root = BitMapBackend::new(path, dim).into_drawing_area();
    root.fill(&WHITE).map_err(err(path))?;
    Ok(root)
}

/// A white figure with `title` across its top: the area below the title.
fn titled_figure<'p>(
    path: &'p Path,
    dim: (u32, u32),
    title: &str,
) -> Result<DrawingArea<BitMapBackend<'p>, Shift>> {
    white_figure(path, dim)?
        .titled(title, ("sans-serif", 20))
        .map_err(err(path))
}

/// Colours of the series (colour-blind friendly: Okabe and Ito's palette). Seven, so that
/// the codes report's six series (three cones, three codes) never share a colour.
pub const COLORS: [RGBColor; 7] = [
    RGBColor(0, 114, 178),
    RGBColor(213, 94, 0),
    RGBColor(0, 0, 0),
    RGBColor(0, 158, 115),
    RGBColor(204, 121, 167),
    RGBColor(230, 159, 0),
    RGBColor(86, 180, 233),
];

/// Font size of the tick labels of [`loglog`] and [`lines`] (pixels).
pub const TICK_FONT_PX: f64 = 15.0;

// ---------------------------------------------------------------------------------------
// Text size and axis ticks

/// Width and height in pixels of `text` drawn `font_px` high in the committed font, as
/// plotters lays it out (and so places it): the sum of the glyphs' advance widths and
/// kerning, and `font_px / 1.24`.
pub fn text_size(text: &str, font_px: f64) -> (f64, f64) {
    register();
    let (w, h) = ("sans-serif", font_px)
        .into_font()
        .box_size(text)
        .unwrap_or((0, 0));
    (f64::from(w), f64::from(h))
}

/// The direction of an axis: the labels of a horizontal axis sit side by side (their widths
/// must not overlap), those of a vertical axis are stacked (their heights must not).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Side {
    /// An x axis.
    Horizontal,
    /// A y axis or a colour bar.
    Vertical,
}

/// The ticks of one axis.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Ticks {
    /// Labelled ticks: value (data units) and label, in increasing order.
    pub major: Vec<(f64, String)>,
    /// Unlabelled ticks (light grid lines), values in data units.
    pub minor: Vec<f64>,
}

impl Ticks {
    /// The label of the major tick nearest `v` (plotters hands its formatter back the values
    /// it was given).
    fn label(&self, v: f64) -> String {
        self.major
            .iter()
            .min_by(|a, b| (a.0 - v).abs().total_cmp(&(b.0 - v).abs()))
            .map(|t| t.1.clone())
            .unwrap_or_default()
    }

    fn values(&self) -> Vec<f64> {
        self.major.iter().map(|t| t.0).collect()
    }

    /// The labelled ticks alone (no light grid lines).
    fn without_minor(&self) -> Ticks {
        Ticks {
            major: self.major.clone(),
            minor: Vec::new(),
        }
    }
}

/// A decimal number `m` × 10^`e`: tick labels are written from it exactly.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Dec {
    m: i64,
    e: i32,
}

impl Dec {
    fn value(self) -> f64 {
        if self.e >= 0 {
            self.m as f64 * 10f64.powi(self.e)
        } else {
            self.m as f64 / 10f64.powi(-self.e)
        }
    }

    /// The same number with the trailing zeros of `m` moved into `e`.
    fn normalized(self) -> Dec {
        let mut d = self;
        while d.m != 0 && d.m % 10 == 0 {
            d.m /= 10;
            d.e += 1;
        }
        if d.m == 0 {
            d.e = 0;
        }
        d
    }
}

fn superscript(n: i32) -> String {
    const DIGITS: [char; 10] = ['⁰', '¹', '²', '³', '⁴', '⁵', '⁶', '⁷', '⁸', '⁹'];
    let mut s = String::new();
    if n < 0 {
        s.push('⁻');
    }
    for c in n.unsigned_abs().to_string().bytes() {
        s.push(DIGITS[(c - b'0') as usize]);
    }
    s
}

/// `d` with at least `decimals` digits after the point (more if `d` has them).
fn decimal_text(d: Dec, decimals: usize) -> String {
    let d = d.normalized();
    if d.m == 0 {
        return "0".into();
    }
    let decimals = decimals.max((-d.e).max(0) as usize);
    let shift = (decimals as i32 + d.e) as u32;
    let digits = (u128::from(d.m.unsigned_abs()) * 10u128.pow(shift)).to_string();
    let digits = format!("{digits:0>width$}", width = decimals + 1);
    let (int, frac) = digits.split_at(digits.len() - decimals);
    let sign = if d.m < 0 { "-" } else { "" };
    match decimals {
        0 => format!("{sign}{int}"),
        _ => format!("{sign}{int}.{frac}"),
    }
}

/// `d` in scientific notation: `10⁻³`, `2×10⁵`, `2.5×10⁻²`.
fn sci_text(d: Dec) -> String {
    let d = d.normalized();
    if d.m == 0 {
        return "0".into();
    }
    let digits = d.m.unsigned_abs().to_string();
    let exp = d.e + digits.len() as i32 - 1;
    let sign = if d.m < 0 { "-" } else { "" };
    match digits.len() {
        1 if digits == "1" => format!("{sign}10{}", superscript(exp)),
        1 => format!("{sign}{digits}×10{}", superscript(exp)),
        _ => format!(
            "{sign}{}.{}×10{}",
            &digits[..1],
            &digits[1..],
            superscript(exp)
        ),
    }
}

/// Labels of tick values: plain decimals (`uniform` digits after the point, at least) while
/// the values are moderate, else scientific. A log axis is moderate when every value is in
/// [1e-3, 1e5), a linear one when its largest magnitude is.
fn tick_labels(vals: &[Dec], uniform: usize, log: bool) -> Vec<String> {
    let mags = vals.iter().map(|d| d.value().abs()).filter(|v| *v > 0.0);
    let big = mags.clone().fold(0.0, f64::max);
    let small = mags.fold(f64::INFINITY, f64::min);
    let sci = big >= 1e5
        || if log {
            small < 1e-3
        } else {
            big < 1e-3 && big > 0.0
        };
    vals.iter()
        .map(|&d| match sci {
            true => sci_text(d),
            false => decimal_text(d, uniform),
        })
        .collect()
}

/// An axis the ticks are fitted on: data range, scale, length, label font and the widest a
/// label may be, in pixels.
struct Axis {
    lo: f64,
    hi: f64,
    log: bool,
    pixels: f64,
    font_px: f64,
    side: Side,
    max_width: f64,
}

type Kept = Vec<(Dec, String)>;

impl Axis {
    /// Pixels from the axis's start to `v`.
    fn pos(&self, v: f64) -> f64 {
        let f = match self.log {
            true => (v.ln() - self.lo.ln()) / (self.hi.ln() - self.lo.ln()),
            false => (v - self.lo) / (self.hi - self.lo),
        };
        f * self.pixels
    }

    /// The label's extent along the axis: its width on a horizontal axis, height on a vertical.
    fn extent(&self, label: &str) -> f64 {
        let (w, h) = text_size(label, self.font_px);
        match self.side {
            Side::Horizontal => w,
            Side::Vertical => h,
        }
    }

    /// The least gap between two labels (pixels).
    fn gap(&self) -> f64 {
        match self.side {
            Side::Horizontal => 0.6 * self.font_px,
            Side::Vertical => 0.4 * self.font_px,
        }
    }

    /// The ticks on the axis (those whose label, centred on the tick, is at most `max_width`
    /// wide and stays within the ends of a vertical axis, within half a font size of those
    /// of a horizontal one) with their labels by position, and whether none was too wide and
    /// every two neighbouring labels are at least [`Axis::gap`] apart.
    fn place(&self, vals: &[Dec], labels: &[String]) -> (Vec<(f64, f64, Dec, String)>, bool) {
        // A y label half past the bottom would sit on the x axis.
        let slack = match self.side {
            Side::Horizontal => 0.5 * self.font_px,
            Side::Vertical => 0.0,
        };
        let mut narrow = true;
        let mut on: Vec<(f64, f64, Dec, String)> = vals
            .iter()
            .zip(labels)
            .filter_map(|(d, l)| {
                let p = self.pos(d.value());
                let inside = p >= -1e-6 * self.pixels && p <= self.pixels * (1.0 + 1e-6);
                if !inside {
                    return None;
                }
                if text_size(l, self.font_px).0 > self.max_width {
                    narrow = false;
                    return None;
                }
                let half = 0.5 * self.extent(l);
                (p - half >= -slack && p + half <= self.pixels + slack)
                    .then(|| (p - half, p + half, *d, l.clone()))
            })
            .collect();
        on.sort_by(|a, b| a.0.total_cmp(&b.0));
        let clear = narrow && on.windows(2).all(|w| w[1].0 - w[0].1 >= self.gap());
        (on, clear)
    }

    /// The share of the axis between the first and the last of `kept`.
    fn coverage(&self, kept: &Kept) -> f64 {
        match (kept.first(), kept.last()) {
            (Some(a), Some(b)) => (self.pos(b.0.value()) - self.pos(a.0.value())) / self.pixels,
            _ => 0.0,
        }
    }

    /// The ticks of `vals` and their labels if no two labels come closer than the gap.
    fn fit(&self, vals: &[Dec], labels: &[String]) -> Option<Kept> {
        let (on, clear) = self.place(vals, labels);
        clear.then(|| on.into_iter().map(|t| (t.2, t.3)).collect())
    }

    /// The ticks of `vals` kept one by one from the start, each one whose label clears the
    /// last kept (the fallback when no tick set fits whole).
    fn thin(&self, vals: &[Dec], labels: &[String]) -> Kept {
        let (on, _) = self.place(vals, labels);
        let mut kept: Vec<(f64, f64, Dec, String)> = Vec::new();
        for t in on {
            if kept.last().is_none_or(|k| t.0 - k.1 >= self.gap()) {
                kept.push(t);
            }
        }
        kept.into_iter().map(|t| (t.2, t.3)).collect()
    }

    /// The number of labels aimed at: one per 100 pixels across, per 60 pixels up, 3 to 10.
    fn target(&self) -> f64 {
        let per = match self.side {
            Side::Horizontal => 100.0,
            Side::Vertical => 60.0,
        };
        (self.pixels / per).clamp(3.0, 10.0)
    }

    fn finish(&self, major: Kept, minor: &[Dec]) -> Ticks {
        let on =
            |v: f64| self.pos(v) >= -1e-6 * self.pixels && self.pos(v) <= self.pixels * 1.000001;
        let majors: Vec<Dec> = major.iter().map(|t| t.0.normalized()).collect();
        Ticks {
            minor: minor
                .iter()
                .filter(|d| !majors.contains(&d.normalized()) && on(d.value()))
                .map(|d| d.value())
                .collect(),
            major: major.into_iter().map(|(d, l)| (d.value(), l)).collect(),
        }
    }
}

/// Evenly spaced tick sets on [lo, hi]: for each step 1, 2 or 5 × 10^j giving 2 to 40 ticks,
/// the multiples of the step, the minor ticks (a fifth of the step, a quarter for 2) and
/// the digits after the point the step needs.
fn even_candidates(lo: f64, hi: f64) -> Vec<(Vec<Dec>, Vec<Dec>, usize)> {
    let multiples = |m: i64, e: i32| -> Vec<Dec> {
        let step = Dec { m, e }.value();
        let (i0, i1) = ((lo / step - 1e-9).ceil(), (hi / step + 1e-9).floor());
        // Too many ticks, or multiples too large for exact integers (a span tiny beside
        // its values).
        if (i1 - i0).is_nan() || i1 - i0 >= 400.0 || i0.abs().max(i1.abs()) > 1e15 {
            return Vec::new();
        }
        (i0 as i64..=i1 as i64)
            .map(|i| Dec { m: i * m, e })
            .collect()
    };
    let j1 = (hi - lo).log10().floor() as i32;
    let mut out = Vec::new();
    for j in j1 - 2..=j1 {
        for m in [1, 2, 5] {
            let major = multiples(m, j);
            if !(2..=40).contains(&major.len()) {
                continue;
            }
            let minor = match m {
                1 => multiples(2, j - 1),
                2 => multiples(5, j - 1),
                _ => multiples(1, j),
            };
            out.push((major, minor, (-j).max(0) as usize));
        }
    }
    out
}

/// The evenly spaced tick set whose labels fit with the count nearest the target (fewer
/// among equals), at least `min` labels.
fn best_even(ax: &Axis, min: usize) -> Option<(Kept, Vec<Dec>)> {
    let mut best: Option<(f64, Kept, Vec<Dec>)> = None;
    for (major, minor, decimals) in even_candidates(ax.lo, ax.hi) {
        let labels = tick_labels(&major, decimals, ax.log);
        if let Some(kept) = ax.fit(&major, &labels).filter(|k| k.len() >= min) {
            let score = (kept.len() as f64 - ax.target()).abs() + 1e-3 * kept.len() as f64;
            if best.as_ref().is_none_or(|b| score < b.0) {
                best = Some((score, kept, minor));
            }
        }
    }
    best.map(|b| (b.1, b.2))
}

/// The candidate ticks of a log axis.
impl Axis {
    /// Every whole decade 10^e on the axis whose e is a multiple of `step`.
    fn decades(&self, step: i32) -> Vec<Dec> {
        self.exponents()
            .filter(|e| e.rem_euclid(step) == 0)
            .map(|e| Dec { m: 1, e })
            .filter(|d| self.on_axis(d))
            .collect()
    }

    /// m × 10^e on the axis for every mantissa m in `set`, decade by decade.
    fn per_decade(&self, set: &[i64]) -> Vec<Dec> {
        self.exponents()
            .flat_map(|e| set.iter().map(move |&m| Dec { m, e }))
            .filter(|d| self.on_axis(d))
            .collect()
    }

    /// The exponents of the decades around the axis, one beyond each end.
    fn exponents(&self) -> std::ops::RangeInclusive<i32> {
        self.lo.log10().floor() as i32 - 1..=self.hi.log10().ceil() as i32 + 1
    }

    fn on_axis(&self, d: &Dec) -> bool {
        d.value() >= self.lo * (1.0 - 1e-9) && d.value() <= self.hi * (1.0 + 1e-9)
    }

    /// The ticks of `vals` on a log axis, labelled, if they fit.
    fn fit_log(&self, vals: &[Dec]) -> Option<Kept> {
        self.fit(vals, &tick_labels(vals, 0, true))
    }
}

/// Ticks of a log axis over [lo, hi] (lo > 0) `pixels` long, labels `font_px` high and at
/// most `max_width` pixels wide, no two labels closer than 0.6 font size across (0.4 up).
/// Across a decade or more: whole decades when three or more are on the axis (every second,
/// third... decade if all do not fit; the others minor), else 1-2-5 or 1..9 per decade when
/// three labels fit (the other integer mantissas minor), else evenly spaced values. Within
/// a decade: whichever of 1-2-5, 1..9 and evenly spaced values has three labels or more
/// spread widest and nearest the target count. Failing all, the set with the most labels.
pub fn log_ticks(lo: f64, hi: f64, pixels: f64, font_px: f64, side: Side, max_width: f64) -> Ticks {
    if !(lo > 0.0 && hi > lo && hi.is_finite() && pixels > 0.0) {
        return Ticks::default();
    }
    let ax = Axis {
        lo,
        hi,
        log: true,
        pixels,
        font_px,
        side,
        max_width,
    };
    let mantissas = ax.per_decade(&[1, 2, 3, 4, 5, 6, 7, 8, 9]);
    let decade_px = pixels / (hi / lo).log10();
    if hi / lo < 10.0
        && let Some(ticks) = within_decade(&ax)
    {
        return ticks;
    }
    if ax.decades(1).len() >= 3 {
        for step in [1, 2, 3, 5, 10, 20, 50, 100] {
            let Some(major) = ax
                .fit_log(&ax.decades(step))
                .filter(|m| (2..=12).contains(&m.len()))
            else {
                continue;
            };
            let minor = match step {
                // Light lines at 2..9 only where a decade is wide enough not to turn grey.
                1 if decade_px >= 60.0 => mantissas.clone(),
                1 => Vec::new(),
                _ => ax.decades(1),
            };
            return ax.finish(major, &minor);
        }
    }
    for set in [&[1, 2, 5][..], &[1, 2, 3, 4, 5, 6, 7, 8, 9][..]] {
        if let Some(major) = ax.fit_log(&ax.per_decade(set)).filter(|m| m.len() >= 3) {
            return ax.finish(major, &mantissas);
        }
    }
    if let Some((major, minor)) = best_even(&ax, 3) {
        return ax.finish(major, &minor);
    }
    // Fewer than three labels fit: the set with the most.
    let mut sets: Vec<(Kept, Vec<Dec>)> =
        [ax.decades(1), ax.per_decade(&[1, 2, 5]), mantissas.clone()]
            .into_iter()
            .filter_map(|v| ax.fit_log(&v).map(|k| (k, mantissas.clone())))
            .collect();
    sets.extend(best_even(&ax, 2));
    match sets.into_iter().max_by_key(|s| s.0.len()) {
        Some((major, minor)) if !major.is_empty() => ax.finish(major, &minor),
        _ => {
            let labels = tick_labels(&mantissas, 0, true);
            ax.finish(ax.thin(&mantissas, &labels), &[])
        }
    }
}

/// The ticks of a log axis spanning less than a decade: of 1-2-5, 1..9 and the evenly spaced
/// sets that fit with three labels or more, the one spread widest and nearest the target
/// count (1-2-5 or 1..9 may label one end only); `None` if none has three.
fn within_decade(ax: &Axis) -> Option<Ticks> {
    let mantissas = ax.per_decade(&[1, 2, 3, 4, 5, 6, 7, 8, 9]);
    let mut sets: Vec<(Kept, Vec<Dec>)> = [ax.per_decade(&[1, 2, 5]), mantissas.clone()]
        .iter()
        .filter_map(|v| ax.fit_log(v).map(|k| (k, mantissas.clone())))
        .collect();
    for (major, minor, decimals) in even_candidates(ax.lo, ax.hi) {
        if let Some(k) = ax.fit(&major, &tick_labels(&major, decimals, true)) {
            sets.push((k, minor));
        }
    }
    let score = |k: &Kept| (k.len() as f64 - ax.target()).abs() + 4.0 * (1.0 - ax.coverage(k));
    let (major, minor) = sets
        .into_iter()
        .filter(|s| s.0.len() >= 3)
        .min_by(|a, b| score(&a.0).total_cmp(&score(&b.0)))?;
    Some(ax.finish(major, &minor))
}

/// Ticks of a linear axis over [lo, hi] `pixels` long, labels `font_px` high and at most
/// `max_width` pixels wide: the step 1, 2 or 5 × 10^j whose labels fit (no two closer than
/// 0.6 font size across, 0.4 up) with the count nearest one label per 100 pixels across (60
/// up, 3 to 10), every label with the step's digits after the point.
pub fn linear_ticks(
    lo: f64,
    hi: f64,
    pixels: f64,
    font_px: f64,
    side: Side,
    max_width: f64,
) -> Ticks {
    if !(hi > lo && lo.is_finite() && hi.is_finite() && pixels > 0.0) {
        return Ticks::default();
    }
    let ax = Axis {
        lo,
        hi,
        log: false,
        pixels,
        font_px,
        side,
        max_width,
    };
    if let Some((major, minor)) = best_even(&ax, 2) {
        return ax.finish(major, &minor);
    }
    // Not even two labels fit whole: the coarsest set thinned.
    match even_candidates(lo, hi).into_iter().next() {
        Some((major, _, decimals)) => {
            let labels = tick_labels(&major, decimals, false);
            ax.finish(ax.thin(&major, &labels), &[])
        }
        None => Ticks::default(),
    }
}

/// A linear f64 axis with given ticks (plotters' own linear axes choose theirs).
#[derive(Clone)]
struct LinearAxis {
    inner: RangedCoordf64,
    major: Vec<f64>,
    minor: Vec<f64>,
}

impl LinearAxis {
    fn new(lo: f64, hi: f64, ticks: &Ticks) -> Self {
        LinearAxis {
            inner: (lo..hi).into(),
            major: ticks.values(),
            minor: ticks.minor.clone(),
        }
    }
}

impl Ranged for LinearAxis {
    type FormatOption = DefaultFormatting;
    type ValueType = f64;

    fn map(&self, value: &f64, limit: (i32, i32)) -> i32 {
        self.inner.map(value, limit)
    }

    fn key_points<H: KeyPointHint>(&self, hint: H) -> Vec<f64> {
        match hint.weight().allow_light_points() {
            true => self.minor.clone(),
            false => self.major.clone(),
        }
    }

    fn range(&self) -> std::ops::Range<f64> {
        self.inner.range()
    }
}

// ---------------------------------------------------------------------------------------
// Layout

/// Where a chart sits in its drawing area: margins (top, bottom, left, right), the title's
/// font size (0 for no title) and the label areas (below, left, right), all pixels.
#[derive(Clone, Copy)]
struct Layout {
    margin: [u32; 4],
    title_px: f64,
    x_label_px: u32,
    y_label_px: u32,
    right_label_px: u32,
}

impl Layout {
    /// The widest a left (or right) axis's tick label may be: the label area less the gap
    /// to the axis (plotters: twice the 5-pixel tick) and the rotated axis description (a
    /// line of `font_px`) with a 6-pixel gap.
    fn label_room(&self, area_px: u32, font_px: f64) -> f64 {
        f64::from(area_px) - 10.0 - text_size("x", font_px).1 - 6.0
    }

    fn builder<'a, 'b, DB: DrawingBackend>(
        &self,
        area: &'a DrawingArea<DB, Shift>,
        title: &str,
    ) -> ChartBuilder<'a, 'b, DB> {
        let mut b = ChartBuilder::on(area);
        b.margin_top(self.margin[0])
            .margin_bottom(self.margin[1])
            .margin_left(self.margin[2])
            .margin_right(self.margin[3])
            .x_label_area_size(self.x_label_px)
            .y_label_area_size(self.y_label_px)
            .right_y_label_area_size(self.right_label_px);
        if self.title_px > 0.0 {
            b.caption(title, ("sans-serif", self.title_px));
        }
        b
    }

    /// The plotting area's size (pixels) on a drawing area of `dim` pixels: the same chart
    /// built on a scratch image (the title's height does not depend on its text).
    fn plot_dim(&self, dim: (u32, u32)) -> (u32, u32) {
        register();
        let mut buf = vec![0u8; 3 * dim.0 as usize * dim.1 as usize];
        let root = BitMapBackend::with_buffer(&mut buf, dim).into_drawing_area();
        self.builder(&root, "x")
            .build_cartesian_2d(0f64..1f64, 0f64..1f64)
            .map(|c| c.plotting_area().dim_in_pixel())
            .unwrap_or((1, 1))
    }
}

const LOGLOG_SIZE: (u32, u32) = (900, 650);
const LOGLOG: Layout = Layout {
    margin: [15; 4],
    title_px: 22.0,
    x_label_px: 50,
    y_label_px: 95,
    right_label_px: 0,
};
const LINES_SIZE: (u32, u32) = (900, 550);
const LINES: Layout = Layout {
    margin: [15; 4],
    title_px: 20.0,
    x_label_px: 50,
    y_label_px: 90,
    right_label_px: 0,
};

/// The plotting area (width, height) of a [`loglog`] figure in pixels: the lengths its x and
/// y tick labels are fitted on.
pub fn loglog_plot_area() -> (u32, u32) {
    LOGLOG.plot_dim(LOGLOG_SIZE)
}

/// The plotting area (width, height) of a [`lines`] figure in pixels.
pub fn lines_plot_area() -> (u32, u32) {
    LINES.plot_dim(LINES_SIZE)
}

/// A rectangle in pixels, (x0, y0) its upper left corner.
#[derive(Clone, Copy, Debug)]
struct Rect {
    x0: f64,
    y0: f64,
    x1: f64,
    y1: f64,
}

impl Rect {
    /// The box reaching `hw` either side of `c` across and `hh` up and down.
    fn around(c: (f64, f64), hw: f64, hh: f64) -> Rect {
        Rect {
            x0: c.0 - hw,
            y0: c.1 - hh,
            x1: c.0 + hw,
            y1: c.1 + hh,
        }
    }

    fn contains(&self, p: (f64, f64), pad: f64) -> bool {
        p.0 >= self.x0 - pad && p.0 <= self.x1 + pad && p.1 >= self.y0 - pad && p.1 <= self.y1 + pad
    }

    fn area(&self) -> f64 {
        (self.x1 - self.x0) * (self.y1 - self.y0)
    }

    fn overlap(&self, o: &Rect) -> f64 {
        let w = self.x1.min(o.x1) - self.x0.max(o.x0);
        let h = self.y1.min(o.y1) - self.y0.max(o.y0);
        w.max(0.0) * h.max(0.0)
    }
}

/// Where plotters puts a box of `size` at `pos` inside an area of `dim` pixels, `inset`
/// from its edges (plotters' legend uses 5).
fn corner_rect(pos: &SeriesLabelPosition, size: (f64, f64), dim: (f64, f64), inset: f64) -> Rect {
    use SeriesLabelPosition::*;
    let x = match pos {
        UpperLeft | MiddleLeft | LowerLeft => inset,
        UpperMiddle | MiddleMiddle | LowerMiddle => ((dim.0 - size.0) / 2.0).floor(),
        UpperRight | MiddleRight | LowerRight => dim.0 - size.0 - inset,
        Coordinate(x, _) => f64::from(*x),
    };
    let y = match pos {
        UpperLeft | UpperMiddle | UpperRight => inset,
        MiddleLeft | MiddleMiddle | MiddleRight => ((dim.1 - size.1) / 2.0).floor(),
        LowerLeft | LowerMiddle | LowerRight => dim.1 - size.1 - inset,
        Coordinate(_, y) => f64::from(*y),
    };
    Rect {
        x0: x,
        y0: y,
        x1: x + size.0,
        y1: y + size.1,
    }
}

const LEGEND_ORDER: [SeriesLabelPosition; 8] = [
    SeriesLabelPosition::UpperLeft,
    SeriesLabelPosition::UpperRight,
    SeriesLabelPosition::LowerLeft,
    SeriesLabelPosition::LowerRight,
    SeriesLabelPosition::MiddleLeft,
    SeriesLabelPosition::MiddleRight,
    SeriesLabelPosition::UpperMiddle,
    SeriesLabelPosition::LowerMiddle,
];

const SLOPE_ORDER: [SeriesLabelPosition; 8] = [
    SeriesLabelPosition::LowerRight,
    SeriesLabelPosition::UpperLeft,
    SeriesLabelPosition::LowerLeft,
    SeriesLabelPosition::UpperRight,
    SeriesLabelPosition::MiddleRight,
    SeriesLabelPosition::MiddleLeft,
    SeriesLabelPosition::LowerMiddle,
    SeriesLabelPosition::UpperMiddle,
];

/// Of the positions in `order`, the one where a box of `size` covers the least weight of
/// `samples` (pixel position, weight) and no `taken` box; the first among equals.
fn place_box(
    size: (f64, f64),
    dim: (f64, f64),
    samples: &[((f64, f64), f64)],
    taken: &[Rect],
    inset: f64,
    order: &[SeriesLabelPosition],
) -> (SeriesLabelPosition, Rect) {
    let mut best: Option<(f64, SeriesLabelPosition, Rect)> = None;
    for pos in order {
        let r = corner_rect(pos, size, dim, inset);
        let covered: f64 = samples
            .iter()
            .filter(|s| r.contains(s.0, 4.0))
            .map(|s| s.1)
            .sum();
        let clash: f64 = taken.iter().map(|t| t.overlap(&r)).sum();
        let score = covered + 1e3 * clash;
        if best.as_ref().is_none_or(|b| score < b.0) {
            best = Some((score, pos.clone(), r));
        }
    }
    let b = best.expect("positions to choose from");
    (b.1, b.2)
}

/// The pixel of `p` on `area`, counted from the area's upper left corner.
fn relative_px<DB: DrawingBackend, CT: CoordTranslate<From = (f64, f64)>>(
    area: &DrawingArea<DB, CT>,
    p: (f64, f64),
) -> (f64, f64) {
    let q = area.map_coordinate(&p);
    let base = area.get_base_pixel();
    (f64::from(q.0 - base.0), f64::from(q.1 - base.1))
}

/// The whole pixel nearest `p`.
fn nearest_px(p: (f64, f64)) -> (i32, i32) {
    (p.0.round() as i32, p.1.round() as i32)
}

/// A size in pixels as f64.
fn pixels_f64(dim: (u32, u32)) -> (f64, f64) {
    (f64::from(dim.0), f64::from(dim.1))
}

/// Pixel positions (relative to the plotting area) along every series: its points and,
/// where a line joins them, a sample every 4 pixels along each segment; weight 1 each.
fn data_samples<DB: DrawingBackend, CT: CoordTranslate<From = (f64, f64)>>(
    chart: &ChartContext<'_, DB, CT>,
    series: &[Series],
    log: bool,
) -> Vec<((f64, f64), f64)> {
    let area = chart.plotting_area();
    let px = |p: &(f64, f64)| relative_px(area, *p);
    let mut out = Vec::new();
    for s in series {
        let pts: Vec<(f64, f64)> = s
            .points
            .iter()
            .filter(|p| p.0.is_finite() && p.1.is_finite() && (!log || (p.0 > 0.0 && p.1 > 0.0)))
            .map(px)
            .collect();
        out.extend(pts.iter().map(|&p| (p, 1.0)));
        if s.line {
            for w in pts.windows(2) {
                let n = ((w[1].0 - w[0].0).hypot(w[1].1 - w[0].1) / 4.0)
                    .ceil()
                    .min(2000.0);
                for k in 1..n as usize {
                    let t = k as f64 / n;
                    let p = (
                        w[0].0 + t * (w[1].0 - w[0].0),
                        w[0].1 + t * (w[1].1 - w[0].1),
                    );
                    out.push((p, 1.0));
                }
            }
        }
    }
    out
}

/// The size of plotters' legend box for these entries: the widest label plus 30 pixels of
/// symbol and 10 of margin each side; lines 1.25 font sizes apart.
fn legend_size(labels: &[&str], font_px: f64) -> (f64, f64) {
    let w = labels
        .iter()
        .map(|l| text_size(l, font_px).0)
        .fold(0.0, f64::max);
    let h = text_size("x", font_px).1;
    (
        w + 30.0 + 20.0,
        ((labels.len().max(1) - 1) as f64 * font_px * 1.25).round() + h + 20.0,
    )
}

// ---------------------------------------------------------------------------------------
// Line charts

/// One series of a plot.
pub struct Series {
    /// Legend label.
    pub label: String,
    /// Points (x, y).
    pub points: Vec<(f64, f64)>,
    /// Draw markers.
    pub markers: bool,
    /// Draw a line through the points.
    pub line: bool,
    /// Colour index into [`COLORS`].
    pub color: usize,
    /// Dashed (thin) line.
    pub thin: bool,
    /// The markers' shape; None: the shape of the colour index ([`Shape::of`]), so that
    /// series told apart by colour are told apart by shape as well.
    pub shape: Option<Shape>,
}

impl Series {
    /// One method's errors in one quantity on a plot of several quantities: colour the
    /// quantity (colour index `quantity`), marker the method (`method`, the method's colour
    /// index on the plots of one quantity), a line through the points, thin where `thin`.
    pub fn of_quantity(
        label: String,
        points: Vec<(f64, f64)>,
        quantity: usize,
        method: usize,
        thin: bool,
    ) -> Series {
        Series {
            label,
            points,
            markers: true,
            line: true,
            color: quantity,
            thin,
            shape: Some(Shape::of(method)),
        }
    }
}

/// A method's colour and marker index on every plot of one quantity: its place in
/// [`Method::ALL`] (mortar, nts, lac), so a method looks the same in every report; a graded
/// code takes the next index.
pub fn method_style(method: Method) -> usize {
    Method::ALL.iter().position(|&m| m == method).unwrap_or(0)
}

/// Whether a method's lines are drawn thin and dashed on the plots of several quantities
/// (nts, so that its lines stay told apart from mortar's where they overlap).
pub fn method_dashed(method: Method) -> bool {
    method == Method::Nts
}

/// A marker's shape.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Shape {
    /// A disc.
    Circle,
    /// A triangle pointing up.
    Triangle,
    /// A square.
    Square,
    /// A diamond.
    Diamond,
    /// A triangle pointing down.
    InvertedTriangle,
    /// A cross.
    Cross,
}

impl Shape {
    /// The shapes in order of colour index.
    pub const ALL: [Shape; 6] = [
        Shape::Circle,
        Shape::Triangle,
        Shape::Square,
        Shape::Diamond,
        Shape::InvertedTriangle,
        Shape::Cross,
    ];

    /// The shape of colour index `i` (mortar, nts, lac, then the codes in report order).
    pub fn of(i: usize) -> Shape {
        Shape::ALL[i % Shape::ALL.len()]
    }

    /// Its outline around (0, 0), `r` pixels from the centre to the corners (the disc's
    /// as a 20-gon); a cross is two strokes.
    fn vertices(self, r: i32) -> Vec<(i32, i32)> {
        // About the disc's area: a square of side 1.8 r, a triangle of side 2.7 r.
        let q = (0.9 * r as f64).round() as i32;
        let t = (1.35 * r as f64).round() as i32;
        match self {
            Shape::Circle => (0..20)
                .map(|k| {
                    let a = std::f64::consts::TAU * k as f64 / 20.0;
                    (
                        (r as f64 * a.cos()).round() as i32,
                        (r as f64 * a.sin()).round() as i32,
                    )
                })
                .collect(),
            Shape::Square => vec![(-q, -q), (q, -q), (q, q), (-q, q)],
            Shape::Diamond => vec![(0, -t), (t, 0), (0, t), (-t, 0)],
            Shape::Triangle => vec![(0, -t), (t, 4 * t / 5), (-t, 4 * t / 5)],
            Shape::InvertedTriangle => vec![(0, t), (t, -4 * t / 5), (-t, -4 * t / 5)],
            Shape::Cross => vec![(-q, -q), (q, q), (0, 0), (q, -q), (-q, q)],
        }
    }

    /// The marker at `at` ([`Mark`]).
    fn at<C>(
        self,
        at: C,
        r: i32,
        color: RGBColor,
        ring: Option<u32>,
        line: Option<ShapeStyle>,
    ) -> Mark<C> {
        Mark {
            at,
            shape: self,
            r,
            color,
            ring,
            line,
        }
    }
}

/// A marker drawn at one point: its shape `r` pixels from the centre to the corners,
/// filled or an outline `ring` pixels wide, and, in a legend entry of a series drawn with a
/// line, a 24-pixel stroke of `line` through it. An element of its own (plotters composes
/// elements only for one backend's lifetime, and a legend entry must outlive it).
struct Mark<C> {
    at: C,
    shape: Shape,
    r: i32,
    color: RGBColor,
    ring: Option<u32>,
    line: Option<ShapeStyle>,
}

impl<'a, C> PointCollection<'a, C> for &'a Mark<C> {
    type Point = &'a C;
    type IntoIter = std::iter::Once<&'a C>;
    fn point_iter(self) -> Self::IntoIter {
        std::iter::once(&self.at)
    }
}

impl<C, DB: DrawingBackend> Drawable<DB> for Mark<C> {
    fn draw<I: Iterator<Item = BackendCoord>>(
        &self,
        mut points: I,
        backend: &mut DB,
        _: (u32, u32),
    ) -> std::result::Result<(), DrawingErrorKind<DB::ErrorType>> {
        let Some((x, y)) = points.next() else {
            return Ok(());
        };
        if let Some(line) = self.line {
            backend.draw_line((x - 12, y), (x + 12, y), &line)?;
        }
        let pts: Vec<(i32, i32)> = self
            .shape
            .vertices(self.r)
            .into_iter()
            .map(|(dx, dy)| (x + dx, y + dy))
            .collect();
        match (self.shape, self.ring) {
            (Shape::Cross, ring) => {
                backend.draw_path(pts, &self.color.stroke_width(ring.unwrap_or(2)))
            }
            (_, Some(w)) => {
                let mut closed = pts.clone();
                closed.push(pts[0]);
                backend.draw_path(closed, &self.color.stroke_width(w))
            }
            (_, None) => backend.fill_polygon(pts, &self.color.filled()),
        }
    }
}

/// The fitted line exp(intercept) x^rate drawn across the span of `xs` (the fitted levels'
/// h or k), labelled `label`; None with fewer than two.
pub fn fit_line(
    label: String,
    rate: f64,
    intercept: f64,
    xs: &[f64],
    color: usize,
) -> Option<Series> {
    if xs.len() < 2 {
        return None;
    }
    let ends = [
        xs.iter().copied().fold(f64::INFINITY, f64::min),
        xs.iter().copied().fold(0.0, f64::max),
    ];
    Some(Series {
        label,
        points: ends
            .iter()
            .map(|&x| (x, (intercept + rate * x.ln()).exp()))
            .collect(),
        markers: false,
        line: true,
        color,
        thin: false,
        shape: None,
    })
}

fn range(points: impl Iterator<Item = f64>, log: bool) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in points.filter(|v| v.is_finite() && (!log || *v > 0.0)) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if !lo.is_finite() {
        return (1.0, 10.0);
    }
    if log {
        (lo / 1.6, hi * 1.6)
    } else {
        let pad = 0.05 * (hi - lo).max(1e-12 * hi.abs().max(1.0));
        (lo - pad, hi + pad)
    }
}

/// The x and y ranges of all series' points (padded; positive values only when `log`).
fn bounds(series: &[Series], log: bool) -> ((f64, f64), (f64, f64)) {
    (
        range(
            series.iter().flat_map(|s| s.points.iter().map(|p| p.0)),
            log,
        ),
        range(
            series.iter().flat_map(|s| s.points.iter().map(|p| p.1)),
            log,
        ),
    )
}

/// The legend labels of `series`, in the order [`draw_series`] registers them.
fn legend_labels(series: &[Series]) -> Vec<&str> {
    series
        .iter()
        .filter(|s| s.line || s.markers)
        .map(|s| s.label.as_str())
        .collect()
}

/// Draw every series (a line, markers of `radius` pixels in the series' shape, or both), one
/// legend entry each. A series whose every point lands within 2 pixels of an earlier
/// series' points is drawn with outlined markers 3 pixels wider (so both show), and its
/// legend says which one it coincides with and to what relative difference
/// ([`coincidence`], against `floor`: 0 on log axes, the largest |y| on linear ones).
fn draw_series<'b, CT>(
    chart: &mut ChartContext<'_, BitMapBackend<'b>, CT>,
    series: &[Series],
    (radius, floor): (u32, f64),
    path: &Path,
) -> Result<()>
where
    CT: CoordTranslate<From = (f64, f64)>,
{
    let pixels: Vec<Vec<(i32, i32)>> = series
        .iter()
        .map(|s| {
            s.points
                .iter()
                .map(|p| chart.plotting_area().map_coordinate(p))
                .collect()
        })
        .collect();
    let near = |p: &(i32, i32), q: &(i32, i32)| (p.0 - q.0).abs() <= 2 && (p.1 - q.1).abs() <= 2;
    let covered_by = |i: usize| {
        // Markers against markers, lines against lines (a fit line lies on its own points).
        (0..i).find(|&j| {
            series[j].markers == series[i].markers
                && series[j].line == series[i].line
                && !pixels[i].is_empty()
                && pixels[i]
                    .iter()
                    .all(|p| pixels[j].iter().any(|q| near(p, q)))
        })
    };
    for (i, s) in series.iter().enumerate() {
        let c = COLORS[s.color % COLORS.len()];
        let style = if s.thin {
            c.stroke_width(1)
        } else {
            c.stroke_width(2)
        };
        let shape = s.shape.unwrap_or(Shape::of(s.color));
        let covered = covered_by(i);
        // Half or more of its points under a later series' (drawn over it).
        // (Not where the later one lies wholly on this one: its legend says so.)
        let partly_under = (i + 1..series.len()).find(|&k| {
            covered_by(k) != Some(i)
                && series[k].markers == s.markers
                && series[k].line == s.line
                && 2 * pixels[i]
                    .iter()
                    .filter(|p| pixels[k].iter().any(|q| near(p, q)))
                    .count()
                    >= pixels[i].len().max(1)
        });
        let label = match (covered, partly_under) {
            (Some(j), _) => format!("{}{}", s.label, coincidence(s, &series[j], floor)),
            (None, Some(k)) => format!(
                "{} (partly under {})",
                s.label,
                first_word(&series[k].label)
            ),
            (None, None) => s.label.clone(),
        };
        let (r, ring) = match covered {
            Some(_) => ((radius + 3) as i32, Some(2)),
            None => (radius as i32, None),
        };
        if s.line {
            let a = chart
                .draw_series(LineSeries::new(s.points.iter().copied(), style))
                .map_err(err(path))?;
            if !s.markers {
                a.label(label.clone())
                    .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], style));
            }
        }
        if s.markers {
            let line = s.line.then_some(style);
            let a = chart
                .draw_series(s.points.iter().map(|&p| shape.at(p, r, c, ring, None)))
                .map_err(err(path))?;
            a.label(label)
                .legend(move |(x, y)| shape.at((x + 10, y), r, c, ring, line));
        }
    }
    Ok(())
}

/// A legend label's first word: the method or code it names.
fn first_word(label: &str) -> &str {
    label.split([' ', ',', ':', '(']).next().unwrap_or("")
}

/// What a series that lies on `under` adds to its legend: " (= mortar to 1e-4)", the first
/// word of `under`'s label and the largest relative difference of their values at the same
/// abscissae, rounded up to one significant digit; " (under mortar)" where the abscissae differ.
/// A difference is relative to the larger of the two values and `floor`: on a log axis
/// (`floor` 0) each value is its own scale; on a linear one a profile through zero (a gap
/// that closes) is read against the axis' scale, its largest |y|, not against round-off.
pub fn coincidence(s: &Series, under: &Series, floor: f64) -> String {
    let name = first_word(&under.label);
    let mut largest: Option<f64> = Some(0.0);
    for p in &s.points {
        match under
            .points
            .iter()
            .find(|q| (q.0 - p.0).abs() <= 1e-12 * p.0.abs().max(1.0))
        {
            Some(q) => {
                let scale = p.1.abs().max(q.1.abs()).max(floor);
                let d = (p.1 - q.1).abs() / scale.max(f64::MIN_POSITIVE);
                largest = largest.map(|l| l.max(d));
            }
            None => largest = None,
        }
    }
    match largest {
        Some(d) if d == 0.0 => format!(" (= {name})"),
        Some(d) => {
            // Rounded up to one significant digit: "to 3e-5", never below the difference.
            let e = d.log10().floor();
            let m = (d / 10f64.powf(e)).ceil();
            format!(" (= {name} to {:.0e})", m * 10f64.powf(e))
        }
        None => format!(" (under {name})"),
    }
}

/// The legend at `pos`, labels `font_px` high on white of the given opacity, framed black.
fn draw_legend<'a, 'b: 'a, CT: CoordTranslate>(
    chart: &mut ChartContext<'a, BitMapBackend<'b>, CT>,
    pos: SeriesLabelPosition,
    font_px: f64,
    opacity: f64,
    path: &Path,
) -> Result<()> {
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(opacity))
        .border_style(BLACK)
        .label_font(("sans-serif", font_px))
        .position(pos)
        .draw()
        .map_err(err(path))
}

/// The x and y ticks of a chart laid out by `layout` on a figure of `size` pixels over the
/// data ranges `x` and `y`, fitted by `fit` ([`log_ticks`] or [`linear_ticks`]) to its
/// plotting area with labels [`TICK_FONT_PX`] high.
fn fitted_ticks(
    layout: &Layout,
    size: (u32, u32),
    x: (f64, f64),
    y: (f64, f64),
    fit: fn(f64, f64, f64, f64, Side, f64) -> Ticks,
) -> (Ticks, Ticks) {
    let (pw, ph) = pixels_f64(layout.plot_dim(size));
    let room = layout.label_room(layout.y_label_px, TICK_FONT_PX);
    (
        fit(x.0, x.1, pw, TICK_FONT_PX, Side::Horizontal, f64::INFINITY),
        fit(y.0, y.1, ph, TICK_FONT_PX, Side::Vertical, room),
    )
}

/// The grid, axis descriptions and tick labels of a [`loglog`] or [`lines`] chart.
fn draw_axes<X, Y>(
    chart: &mut ChartContext<'_, BitMapBackend<'_>, Cartesian2d<X, Y>>,
    (xlabel, ylabel): (&str, &str),
    (xt, yt): (&Ticks, &Ticks),
    path: &Path,
) -> Result<()>
where
    X: Ranged<ValueType = f64> + ValueFormatter<f64>,
    Y: Ranged<ValueType = f64> + ValueFormatter<f64>,
{
    chart
        .configure_mesh()
        .x_desc(xlabel)
        .y_desc(ylabel)
        .label_style(("sans-serif", TICK_FONT_PX))
        .x_label_formatter(&|v| xt.label(*v))
        .y_label_formatter(&|v| yt.label(*v))
        .draw()
        .map_err(err(path))
}

/// Where the legend of `labels` covers the fewest `samples` in the plotting area of `chart`
/// (`None` without labels).
fn legend_place<DB: DrawingBackend, CT: CoordTranslate>(
    chart: &ChartContext<'_, DB, CT>,
    labels: &[&str],
    samples: &[((f64, f64), f64)],
) -> Option<(SeriesLabelPosition, Rect)> {
    let dim = pixels_f64(chart.plotting_area().dim_in_pixel());
    let size = legend_size(labels, TICK_FONT_PX);
    (!labels.is_empty()).then(|| place_box(size, dim, samples, &[], 5.0, &LEGEND_ORDER))
}

/// A log-log plot with optional reference slope triangles (slopes given with labels).
pub fn loglog(
    path: &Path,
    title: &str,
    xlabel: &str,
    ylabel: &str,
    series: &[Series],
    slopes: &[(f64, &str)],
) -> Result<()> {
    let root = white_figure(path, LOGLOG_SIZE)?;
    let ((x0, x1), (y0, y1)) = bounds(series, true);
    let (xt, yt) = fitted_ticks(&LOGLOG, LOGLOG_SIZE, (x0, x1), (y0, y1), log_ticks);
    let mut chart = LOGLOG
        .builder(&root, title)
        .build_cartesian_2d(
            (x0..x1)
                .log_scale()
                .with_key_points(xt.values())
                .with_light_points(xt.minor.clone()),
            (y0..y1)
                .log_scale()
                .with_key_points(yt.values())
                .with_light_points(yt.minor.clone()),
        )
        .map_err(err(path))?;
    draw_axes(&mut chart, (xlabel, ylabel), (&xt, &yt), path)?;
    draw_series(&mut chart, series, (5, 0.0), path)?;
    let samples = data_samples(&chart, series, true);
    let legend = legend_place(&chart, &legend_labels(series), &samples);
    if !slopes.is_empty() {
        let taken: Vec<Rect> = legend.iter().map(|l| l.1).collect();
        slope_triangles(&chart, ((x0, x1), (y0, y1)), &samples, &taken, slopes, path)?;
    }
    if let Some((pos, _)) = legend {
        draw_legend(&mut chart, pos, TICK_FONT_PX, 0.85, path)?;
    }
    root.present().map_err(err(path))?;
    Ok(())
}

/// Reference slope triangles on a log-log chart, stacked bottom-up (legs of equal width,
/// each height the slope's rise on screen) with "slope LABEL" right of each, in the corner
/// that covers the fewest `samples` and no `taken` box.
fn slope_triangles<'b, CT: CoordTranslate<From = (f64, f64)>>(
    chart: &ChartContext<'_, BitMapBackend<'b>, CT>,
    ((x0, x1), (y0, y1)): ((f64, f64), (f64, f64)),
    samples: &[((f64, f64), f64)],
    taken: &[Rect],
    slopes: &[(f64, &str)],
    path: &Path,
) -> Result<()> {
    const FONT_PX: f64 = 14.0;
    let area = chart.plotting_area();
    let (pw, ph) = area.dim_in_pixel();
    let (pw, ph) = (f64::from(pw), f64::from(ph));
    // Pixels per y decade over pixels per x decade: a slope s rises s * ratio pixels per pixel.
    let ratio = (ph / (y1 / y0).log10()) / (pw / (x1 / x0).log10());
    let steepest = slopes.iter().map(|s| s.0.abs()).fold(0.0, f64::max);
    let dx = (70.0f64)
        .min(70.0 / (steepest * ratio).max(1e-12))
        .max(20.0);
    let heights: Vec<f64> = slopes.iter().map(|s| s.0.abs() * dx * ratio).collect();
    let labels: Vec<String> = slopes.iter().map(|s| format!("slope {}", s.1)).collect();
    let label_w = labels
        .iter()
        .map(|l| text_size(l, FONT_PX).0)
        .fold(0.0, f64::max);
    let rows: Vec<f64> = heights.iter().map(|h| h.max(FONT_PX + 2.0)).collect();
    let gap = 10.0;
    let size = (
        dx + 6.0 + label_w,
        rows.iter().sum::<f64>() + gap * (rows.len() as f64 - 1.0),
    );
    let (_, r) = place_box(size, (pw, ph), samples, taken, 12.0, &SLOPE_ORDER);
    let to_data = |px: f64, py: f64| (x0 * (x1 / x0).powf(px / pw), y1 * (y0 / y1).powf(py / ph));
    let style = TextStyle::from(("sans-serif", FONT_PX).into_font())
        .pos(Pos::new(HPos::Left, VPos::Center));
    let mut bottom = r.y1;
    for ((h, row), label) in heights.iter().zip(&rows).zip(&labels) {
        let base = bottom - 0.5 * (row - h);
        let (left, right) = (r.x0, r.x0 + dx);
        let tri = vec![
            to_data(left, base),
            to_data(right, base),
            to_data(right, base - h),
            to_data(left, base),
        ];
        area.draw(&PathElement::new(tri, BLACK.stroke_width(1)))
            .map_err(err(path))?;
        area.draw(&Text::new(
            label.clone(),
            to_data(right + 6.0, base - 0.5 * h),
            style.clone(),
        ))
        .map_err(err(path))?;
        bottom -= row + gap;
    }
    Ok(())
}

/// A linear x-y plot of lines.
pub fn lines(
    path: &Path,
    title: &str,
    xlabel: &str,
    ylabel: &str,
    series: &[Series],
) -> Result<()> {
    let root = white_figure(path, LINES_SIZE)?;
    let ((x0, x1), (y0, y1)) = bounds(series, false);
    let (xt, yt) = fitted_ticks(&LINES, LINES_SIZE, (x0, x1), (y0, y1), linear_ticks);
    let mut chart = LINES
        .builder(&root, title)
        .build_cartesian_2d(LinearAxis::new(x0, x1, &xt), LinearAxis::new(y0, y1, &yt))
        .map_err(err(path))?;
    draw_axes(&mut chart, (xlabel, ylabel), (&xt, &yt), path)?;
    let largest = series
        .iter()
        .flat_map(|s| s.points.iter().map(|p| p.1.abs()))
        .filter(|v| v.is_finite())
        .fold(0.0, f64::max);
    draw_series(&mut chart, series, (3, largest), path)?;
    let samples = data_samples(&chart, series, false);
    if let Some((pos, _)) = legend_place(&chart, &legend_labels(series), &samples) {
        draw_legend(&mut chart, pos, TICK_FONT_PX, 0.85, path)?;
    }
    root.present().map_err(err(path))?;
    Ok(())
}

// ---------------------------------------------------------------------------------------
// Field, mesh and grid maps

/// Viridis-like colour map on [0, 1].
pub fn colormap(t: f64) -> RGBColor {
    const STOPS: [(f64, [f64; 3]); 5] = [
        (0.0, [68.0, 1.0, 84.0]),
        (0.25, [59.0, 82.0, 139.0]),
        (0.5, [33.0, 145.0, 140.0]),
        (0.75, [94.0, 201.0, 98.0]),
        (1.0, [253.0, 231.0, 37.0]),
    ];
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        0.0
    };
    let k = STOPS.iter().position(|s| s.0 >= t).unwrap_or(4).max(1);
    let (a, b) = (STOPS[k - 1], STOPS[k]);
    let w = (t - a.0) / (b.0 - a.0);
    let c = |i: usize| (a.1[i] + w * (b.1[i] - a.1[i])).round() as u8;
    RGBColor(c(0), c(1), c(2))
}

/// A linear colour scale: `lo` at the bottom of [`colormap`], `hi` at its top (data units,
/// or log10 of them).
#[derive(Clone, Copy, Debug)]
struct ColourScale {
    lo: f64,
    hi: f64,
}

impl ColourScale {
    /// The range of the finite `values` ([0, 1] if none); one value gets a scale 2% wide
    /// around it.
    fn spanning(values: impl Iterator<Item = f64>) -> ColourScale {
        let (mut lo, mut hi) = values
            .filter(|v| v.is_finite())
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
                (a.min(v), b.max(v))
            });
        if lo > hi {
            (lo, hi) = (0.0, 1.0);
        }
        if hi - lo <= 1e-9 * hi.abs().max(lo.abs()) {
            let d = if hi == 0.0 { 1.0 } else { 0.01 * hi.abs() };
            (lo, hi) = (lo - d, hi + d);
        }
        ColourScale { lo, hi }
    }

    /// Where `v` falls on [`colormap`]'s [0, 1] (outside it beyond the scale's ends).
    fn fraction(&self, v: f64) -> f64 {
        (v - self.lo) / (self.hi - self.lo)
    }

    fn colour(&self, v: f64) -> RGBColor {
        colormap(self.fraction(v))
    }
}

type Square<'a, 'b> = ChartContext<'a, BitMapBackend<'b>, Cartesian2d<LinearAxis, LinearAxis>>;

/// A chart with equal aspect ratio around the triangles (the shorter range padded), its
/// ticks fitted to its plotting area.
fn square_chart<'a, 'b>(
    area: &'a DrawingArea<BitMapBackend<'b>, Shift>,
    title: &str,
    size: u32,
    triangles: &[[[f64; 2]; 3]],
    path: &Path,
) -> Result<Square<'a, 'b>> {
    const FONT_PX: f64 = 12.0;
    let layout = Layout {
        margin: [10; 4],
        title_px: f64::from(size),
        x_label_px: 30,
        y_label_px: 40,
        right_label_px: 0,
    };
    let (x0, x1) = range(triangles.iter().flat_map(|t| t.iter().map(|v| v[0])), false);
    let (y0, y1) = range(triangles.iter().flat_map(|t| t.iter().map(|v| v[1])), false);
    let (cx, cy) = (0.5 * (x0 + x1), 0.5 * (y0 + y1));
    let half = 0.5 * (x1 - x0).max(y1 - y0);
    let (xr, yr) = ((cx - half, cx + half), (cy - half, cy + half));
    let (pw, ph) = layout.plot_dim(area.dim_in_pixel());
    // No axis description on the left: the label area less the gap to the axis.
    let room = f64::from(layout.y_label_px) - 10.0;
    let xt = linear_ticks(
        xr.0,
        xr.1,
        f64::from(pw),
        FONT_PX,
        Side::Horizontal,
        f64::INFINITY,
    );
    let yt = linear_ticks(yr.0, yr.1, f64::from(ph), FONT_PX, Side::Vertical, room);
    let mut chart = layout
        .builder(area, title)
        .build_cartesian_2d(
            LinearAxis::new(xr.0, xr.1, &xt.without_minor()),
            LinearAxis::new(yr.0, yr.1, &yt.without_minor()),
        )
        .map_err(err(path))?;
    chart
        .configure_mesh()
        .disable_mesh()
        .label_style(("sans-serif", FONT_PX))
        .x_label_formatter(&|v| xt.label(*v))
        .y_label_formatter(&|v| yt.label(*v))
        .draw()
        .map_err(err(path))?;
    Ok(chart)
}

/// One panel of a field plot: triangles coloured by a value.
pub struct Panel {
    /// Panel title.
    pub title: String,
    /// Triangles (deformed coordinates).
    pub triangles: Vec<[[f64; 2]; 3]>,
    /// Value per triangle.
    pub values: Vec<f64>,
    /// Body per triangle (edges of body 2 drawn in grey, body 1 in black).
    pub body: Vec<u8>,
    /// Segments to highlight (the contact line).
    pub highlight: Vec<[[f64; 2]; 2]>,
}

/// Panels side by side sharing one colour bar, which spans the values' range exactly.
pub fn field_panels(path: &Path, title: &str, bar_label: &str, panels: &[Panel]) -> Result<()> {
    let w = (560 * panels.len() as u32 + 140).max(1000);
    let root = titled_figure(path, (w, 640), title)?;
    let scale = ColourScale::spanning(panels.iter().flat_map(|p| p.values.iter().copied()));
    let (main, bar) = root.split_horizontally(w - 140);
    let areas = main.split_evenly((1, panels.len()));
    for (p, area) in panels.iter().zip(areas.iter()) {
        let mut chart = square_chart(area, &p.title, 17, &p.triangles, path)?;
        for (i, t) in p.triangles.iter().enumerate() {
            let c = scale.colour(p.values[i]);
            let edge = match p.body[i] {
                1 => BLACK.mix(0.35),
                _ => RGBColor(90, 90, 90).mix(0.35),
            };
            // The fill leaves some boundary pixels out: outline in the fill's colour first.
            let outlines = [c.stroke_width(1), edge.stroke_width(1)];
            draw_triangle(&mut chart, t, c, &outlines, path)?;
        }
        draw_segments(&mut chart, &p.highlight, RED.stroke_width(3), path)?;
    }
    colour_bar(&bar, scale, bar_label, path)?;
    root.present().map_err(err(path))
}

/// A vertical colour bar of `scale` filling `area`, its ticks and `label` on its right.
fn colour_bar(
    area: &DrawingArea<BitMapBackend<'_>, Shift>,
    scale: ColourScale,
    label: &str,
    path: &Path,
) -> Result<()> {
    const FONT_PX: f64 = 13.0;
    const LAYOUT: Layout = Layout {
        margin: [60, 60, 0, 40],
        title_px: 0.0,
        x_label_px: 0,
        y_label_px: 0,
        right_label_px: 90,
    };
    let (lo, hi) = (scale.lo, scale.hi);
    let (_, bar_px) = LAYOUT.plot_dim(area.dim_in_pixel());
    let room = LAYOUT.label_room(LAYOUT.right_label_px, FONT_PX);
    let ticks = linear_ticks(lo, hi, f64::from(bar_px), FONT_PX, Side::Vertical, room);
    let mut cb = LAYOUT
        .builder(area, "")
        .build_cartesian_2d(0.0..1.0, LinearAxis::new(lo, hi, &ticks))
        .map_err(err(path))?;
    cb.configure_mesh()
        .disable_mesh()
        .disable_x_axis()
        .y_desc(label)
        // The bar is narrower than plotters' 5% tick default can see: ticks 5 pixels long.
        .set_tick_mark_size(LabelAreaPosition::Right, 5)
        .label_style(("sans-serif", FONT_PX))
        .y_label_formatter(&|v| ticks.label(*v))
        .draw()
        .map_err(err(path))?;
    let n = 100;
    for k in 0..n {
        let a = lo + (hi - lo) * k as f64 / n as f64;
        let b = lo + (hi - lo) * (k + 1) as f64 / n as f64;
        cb.draw_series(std::iter::once(Rectangle::new(
            [(0.0, a), (1.0, b)],
            colormap((k as f64 + 0.5) / n as f64).filled(),
        )))
        .map_err(err(path))?;
    }
    Ok(())
}

/// A triangle filled with `fill`, then its outline in each of `outlines` in turn.
fn draw_triangle(
    chart: &mut Square<'_, '_>,
    t: &[[f64; 2]; 3],
    fill: RGBColor,
    outlines: &[ShapeStyle],
    path: &Path,
) -> Result<()> {
    let pts: Vec<(f64, f64)> = t.iter().map(|v| (v[0], v[1])).collect();
    let mut closed = pts.clone();
    closed.push(closed[0]);
    chart
        .draw_series(std::iter::once(Polygon::new(pts, fill.filled())))
        .map_err(err(path))?;
    for style in outlines {
        chart
            .draw_series(std::iter::once(PathElement::new(closed.clone(), *style)))
            .map_err(err(path))?;
    }
    Ok(())
}

/// Each of `segments` as a line in `style`.
fn draw_segments(
    chart: &mut Square<'_, '_>,
    segments: &[[[f64; 2]; 2]],
    style: ShapeStyle,
    path: &Path,
) -> Result<()> {
    for s in segments {
        chart
            .draw_series(std::iter::once(PathElement::new(
                vec![(s[0][0], s[0][1]), (s[1][0], s[1][1])],
                style,
            )))
            .map_err(err(path))?;
    }
    Ok(())
}

/// One panel of a mesh plot: the two bodies filled in two light colours, edges thin, the
/// contact line highlighted and the interface nodes of each body marked.
pub struct MeshPanel {
    /// Panel title.
    pub title: String,
    /// Triangles (coordinates, possibly deformed).
    pub triangles: Vec<[[f64; 2]; 3]>,
    /// Body per triangle (1 or 2).
    pub body: Vec<u8>,
    /// Contact-line segments to highlight.
    pub highlight: Vec<[[f64; 2]; 2]>,
    /// Interface nodes of body 1 (drawn as circles) and body 2 (drawn as crosses).
    pub nodes: [Vec<[f64; 2]>; 2],
    /// Undeformed outline segments, drawn thin and grey (empty for none).
    pub outline: Vec<[[f64; 2]; 2]>,
}

/// The legend entries of a [`MeshPanel`]'s interface nodes.
const NODE_LABELS: [&str; 2] = ["body 1 interface nodes", "body 2 interface nodes"];

/// Mesh panels side by side; each legend where it covers the least mesh (the contact line
/// and interface nodes counting most).
pub fn mesh_panels(path: &Path, title: &str, panels: &[MeshPanel]) -> Result<()> {
    let root = titled_figure(path, (600 * panels.len() as u32, 640), title)?;
    let areas = root.split_evenly((1, panels.len()));
    for (p, area) in panels.iter().zip(areas.iter()) {
        let mut chart = square_chart(area, &p.title, 16, &p.triangles, path)?;
        draw_mesh(&mut chart, p, path)?;
        mesh_legend(&mut chart, p, path)?;
    }
    root.present().map_err(err(path))
}

/// The cells filled by body with thin edges, the undeformed outline, the contact line and
/// the interface nodes (with their legend entries) of one mesh panel.
fn draw_mesh(chart: &mut Square<'_, '_>, p: &MeshPanel, path: &Path) -> Result<()> {
    let fills = [RGBColor(198, 219, 239), RGBColor(253, 208, 162)];
    for (i, t) in p.triangles.iter().enumerate() {
        let fill = fills[(p.body[i].max(1) - 1) as usize % 2];
        draw_triangle(chart, t, fill, &[BLACK.mix(0.5).stroke_width(1)], path)?;
    }
    let grey = RGBColor(120, 120, 120);
    draw_segments(chart, &p.outline, grey.stroke_width(1), path)?;
    draw_segments(chart, &p.highlight, RED.stroke_width(2), path)?;
    let (circle, cross) = (COLORS[0].stroke_width(2), COLORS[1].stroke_width(2));
    chart
        .draw_series(
            p.nodes[0]
                .iter()
                .map(|v| Circle::new((v[0], v[1]), 4, circle)),
        )
        .map_err(err(path))?
        .label(NODE_LABELS[0])
        .legend(move |(x, y)| Circle::new((x + 8, y), 4, circle));
    chart
        .draw_series(
            p.nodes[1]
                .iter()
                .map(|v| Cross::new((v[0], v[1]), 4, cross)),
        )
        .map_err(err(path))?
        .label(NODE_LABELS[1])
        .legend(move |(x, y)| Cross::new((x + 8, y), 4, cross));
    Ok(())
}

/// The node legend of a mesh panel in the lower or upper corner where it covers the least
/// weight: 1 per triangle vertex, 50 per interface node and per ninth of a contact segment.
fn mesh_legend<'a, 'b: 'a>(chart: &mut Square<'a, 'b>, p: &MeshPanel, path: &Path) -> Result<()> {
    const FONT_PX: f64 = 13.0;
    const ORDER: [SeriesLabelPosition; 4] = [
        SeriesLabelPosition::LowerRight,
        SeriesLabelPosition::LowerLeft,
        SeriesLabelPosition::UpperRight,
        SeriesLabelPosition::UpperLeft,
    ];
    let plot = chart.plotting_area();
    let px = |x: f64, y: f64| relative_px(plot, (x, y));
    let mut samples: Vec<((f64, f64), f64)> = p
        .triangles
        .iter()
        .flat_map(|t| t.iter().map(|v| (px(v[0], v[1]), 1.0)))
        .collect();
    for s in &p.highlight {
        for k in 0..=8 {
            let t = f64::from(k) / 8.0;
            let q = px(
                s[0][0] + t * (s[1][0] - s[0][0]),
                s[0][1] + t * (s[1][1] - s[0][1]),
            );
            samples.push((q, 50.0));
        }
    }
    samples.extend(p.nodes.iter().flatten().map(|v| (px(v[0], v[1]), 50.0)));
    let size = legend_size(&NODE_LABELS, FONT_PX);
    let dim = pixels_f64(plot.dim_in_pixel());
    let (pos, _) = place_box(size, dim, &samples, &[], 5.0, &ORDER);
    draw_legend(chart, pos, FONT_PX, 0.9, path)
}

/// One panel of a map over a grid of (x, y) cells: a value per cell, lines on top.
pub struct GridPanel {
    /// Panel title.
    pub title: String,
    /// Cells: (x, y, value); each cell is drawn as the unit square centred at (x, y).
    pub cells: Vec<(f64, f64, f64)>,
    /// Polylines to draw over the cells (e.g. the iso-dofs lines), with a label each.
    pub lines: Vec<(String, Vec<(f64, f64)>)>,
    /// Values at or below this (zero, round-off) stay off the log colour scale: their cells
    /// are hatched grey and the panel notes "0 / round-off" (same units as the values).
    pub roundoff: f64,
}

/// Where each cell of `panel` falls on [`colormap`]: its log10 value's place between the
/// smallest and largest (padded 5%) of the cells above the round-off level; `None` for a
/// cell at zero or round-off, which stays off the scale.
pub fn cell_shades(panel: &GridPanel) -> Vec<Option<f64>> {
    let above = |v: f64| v > panel.roundoff || v.is_nan();
    // `range` pads, so the scale's span is never zero.
    let (lo, hi) = range(
        panel
            .cells
            .iter()
            .filter(|c| above(c.2))
            .map(|c| c.2.log10()),
        false,
    );
    let scale = ColourScale { lo, hi };
    panel
        .cells
        .iter()
        .map(|c| above(c.2).then(|| scale.fraction(c.2.log10())))
        .collect()
}

/// Hatched grey: the cells of a [`GridPanel`] at zero or round-off.
const ROUNDOFF_FILL: RGBColor = RGBColor(215, 215, 215);
const ROUNDOFF_HATCH: RGBColor = RGBColor(150, 150, 150);

/// Font sizes of a [`GridPanel`]'s cell values (and round-off note) and line labels.
const CELL_FONT_PX: f64 = 12.0;
const LINE_FONT_PX: f64 = 11.0;

/// Diagonal hatching of the box [x0, x1] × [y0, y1] (pixels or data units alike): segments
/// of the lines y - y0 = (x - x0) + c, c a multiple of `pitch`, inside the box.
fn hatch(x0: f64, x1: f64, y0: f64, y1: f64, pitch: f64) -> Vec<[(f64, f64); 2]> {
    let (w, h) = (x1 - x0, y1 - y0);
    let n = ((w + h) / pitch).ceil() as i64;
    (-n..=n)
        .filter_map(|k| {
            // Along u = x - x0 in [0, w]: v = u + c must be in [0, h].
            let c = k as f64 * pitch;
            let (u0, u1) = ((-c).max(0.0), (h - c).min(w));
            (u1 > u0).then_some([(x0 + u0, y0 + u0 + c), (x0 + u1, y0 + u1 + c)])
        })
        .collect()
}

/// The box from pixel `a` to pixel `b` of `area` filled grey and hatched, lines `pitch`
/// pixels apart: the mark of zero or round-off.
fn draw_roundoff_box(
    area: &DrawingArea<BitMapBackend<'_>, Shift>,
    a: (f64, f64),
    b: (f64, f64),
    pitch: f64,
    path: &Path,
) -> Result<()> {
    area.draw(&Rectangle::new(
        [nearest_px(a), nearest_px(b)],
        ROUNDOFF_FILL.filled(),
    ))
    .map_err(err(path))?;
    for s in hatch(a.0, b.0, a.1, b.1, pitch) {
        area.draw(&PathElement::new(
            vec![nearest_px(s[0]), nearest_px(s[1])],
            ROUNDOFF_HATCH.stroke_width(1),
        ))
        .map_err(err(path))?;
    }
    Ok(())
}

/// The plotting area of a grid panel, in cell coordinates.
type GridArea<'b> = DrawingArea<BitMapBackend<'b>, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

/// A cell's value as it is to be written: text, centre and the box of its patch (pixels
/// from the plotting area's corner), patch and ink colours.
struct CellText {
    text: String,
    centre: (f64, f64),
    rect: Rect,
    fill: RGBColor,
    ink: RGBColor,
}

/// Maps side by side (two per row), each with its own colour scale on log10 of the values
/// above the panel's round-off level, the value written in every cell; cells at zero or
/// round-off hatched grey (noted above the panel), the lines labelled where the label
/// covers no cell's value.
pub fn grid_panels(
    path: &Path,
    title: &str,
    xlabel: &str,
    ylabel: &str,
    panels: &[GridPanel],
) -> Result<()> {
    let rows = panels.len().div_ceil(2) as u32;
    let root = titled_figure(path, (1100, 520 * rows + 40), title)?;
    let areas = root.split_evenly((rows as usize, 2));
    for (p, area) in panels.iter().zip(areas.iter()) {
        let data = grid_axes(area, p, (xlabel, ylabel), path)?;
        // The cells, then the lines, then each value on a patch of its cell's colour (the
        // lines pass under the numbers), then the lines' labels clear of the values.
        let values = draw_cells(&data, p, path)?;
        for (_, pts) in &p.lines {
            data.draw(&PathElement::new(
                pts.clone(),
                ShapeStyle::from(&RED).stroke_width(2),
            ))
            .map_err(err(path))?;
        }
        let taken = write_values(&data.strip_coord_spec(), values, path)?;
        label_lines(&data, &p.lines, taken, path)?;
        if p.cells.iter().any(|c| c.2 <= p.roundoff) {
            roundoff_note(area, p.roundoff, path)?;
        }
    }
    root.present().map_err(err(path))
}

/// The axes of a grid panel, a tick at every whole x and y its cells span; its plotting area.
fn grid_axes<'b>(
    area: &DrawingArea<BitMapBackend<'b>, Shift>,
    p: &GridPanel,
    (xlabel, ylabel): (&str, &str),
    path: &Path,
) -> Result<GridArea<'b>> {
    const LAYOUT: Layout = Layout {
        margin: [10; 4],
        title_px: 16.0,
        x_label_px: 35,
        y_label_px: 45,
        right_label_px: 0,
    };
    let (x0, x1) = range(p.cells.iter().map(|c| c.0), false);
    let (y0, y1) = range(p.cells.iter().map(|c| c.1), false);
    let mut chart = LAYOUT
        .builder(area, &p.title)
        .build_cartesian_2d(x0 - 0.5..x1 + 0.5, y0 - 0.5..y1 + 0.5)
        .map_err(err(path))?;
    chart
        .configure_mesh()
        .disable_mesh()
        .x_desc(xlabel)
        .y_desc(ylabel)
        .x_labels((x1 - x0) as usize + 1)
        .y_labels((y1 - y0) as usize + 1)
        .x_label_formatter(&|v| format!("{v:.0}"))
        .y_label_formatter(&|v| format!("{v:.0}"))
        .label_style(("sans-serif", 12))
        .draw()
        .map_err(err(path))?;
    Ok(chart.plotting_area().clone())
}

/// The cells of `p` in their colours (zero or round-off hatched grey); their values, still
/// to be written.
fn draw_cells(data: &GridArea<'_>, p: &GridPanel, path: &Path) -> Result<Vec<CellText>> {
    let plot = data.strip_coord_spec();
    let px = |x: f64, y: f64| relative_px(data, (x, y));
    let mut values = Vec::new();
    for (c, shade) in p.cells.iter().zip(cell_shades(p)) {
        let (a, b) = (px(c.0 - 0.5, c.1 + 0.5), px(c.0 + 0.5, c.1 - 0.5));
        let (fill, ink) = match shade {
            Some(t) => (colormap(t), if t > 0.6 { BLACK } else { WHITE }),
            None => (ROUNDOFF_FILL, BLACK),
        };
        match shade {
            Some(_) => plot
                .draw(&Rectangle::new(
                    [nearest_px(a), nearest_px(b)],
                    fill.filled(),
                ))
                .map_err(err(path))?,
            None => draw_roundoff_box(&plot, a, b, 12.0, path)?,
        }
        let text = match c.2 {
            0.0 => "0".to_string(),
            v => format!("{v:.2e}"),
        };
        let (tw, th) = text_size(&text, CELL_FONT_PX);
        let centre = px(c.0, c.1);
        let rect = Rect::around(centre, 0.5 * tw + 2.0, 0.5 * th + 2.0);
        values.push(CellText {
            text,
            centre,
            rect,
            fill,
            ink,
        });
    }
    Ok(values)
}

/// Each cell's value on a patch of its cell's colour; the patches, which line labels must
/// not cover.
fn write_values(
    plot: &DrawingArea<BitMapBackend<'_>, Shift>,
    values: Vec<CellText>,
    path: &Path,
) -> Result<Vec<Rect>> {
    let mut taken = Vec::new();
    for v in values {
        let style = centred(CELL_FONT_PX).color(&v.ink);
        draw_text_patch(plot, v.text, v.centre, v.rect, v.fill.filled(), style, path)?;
        taken.push(v.rect);
    }
    Ok(taken)
}

/// Each line's label on the line, nearest its end, where it covers none of the `taken`
/// boxes (nor another label) and stays inside the plot.
fn label_lines(
    data: &GridArea<'_>,
    lines: &[(String, Vec<(f64, f64)>)],
    mut taken: Vec<Rect>,
    path: &Path,
) -> Result<()> {
    let plot = data.strip_coord_spec();
    let (dw, dh) = pixels_f64(plot.dim_in_pixel());
    let inside = Rect {
        x0: 0.0,
        y0: 0.0,
        x1: dw,
        y1: dh,
    };
    for (label, pts) in lines {
        let (tw, th) = text_size(label, LINE_FONT_PX);
        let (hw, hh) = (0.5 * tw + 3.0, 0.5 * th + 2.0);
        let best = pts
            .iter()
            .map(|q| relative_px(data, *q))
            .map(|c| {
                let r = Rect::around(c, hw, hh);
                let out = r.area() - r.overlap(&inside);
                let covered: f64 = taken.iter().map(|t| t.overlap(&r)).sum();
                (covered + 1e3 * out, c, r)
            })
            .rev()
            .min_by(|a, b| a.0.total_cmp(&b.0));
        if let Some((_, c, r)) = best {
            let style = centred(LINE_FONT_PX).color(&RED);
            let fill = WHITE.mix(0.85).filled();
            draw_text_patch(&plot, label.clone(), c, r, fill, style, path)?;
            taken.push(r);
        }
    }
    Ok(())
}

/// The round-off note in a grid panel's title row, right-aligned: a hatched swatch and its
/// meaning.
fn roundoff_note(
    area: &DrawingArea<BitMapBackend<'_>, Shift>,
    roundoff: f64,
    path: &Path,
) -> Result<()> {
    let note = format!("0 / round-off (≤ {roundoff:.0e})");
    let (tw, th) = text_size(&note, CELL_FONT_PX);
    let (aw, _) = area.dim_in_pixel();
    let x = f64::from(aw) - tw - 14.0;
    let (s0, s1) = ((x - 22.0, 8.0), (x - 6.0, 8.0 + 16.0));
    draw_roundoff_box(area, s0, s1, 6.0, path)?;
    area.draw(&Rectangle::new(
        [nearest_px(s0), nearest_px(s1)],
        BLACK.stroke_width(1),
    ))
    .map_err(err(path))?;
    area.draw(&Text::new(
        note,
        nearest_px((x, 8.0 + 8.0 - 0.5 * th)),
        ("sans-serif", CELL_FONT_PX).into_font(),
    ))
    .map_err(err(path))?;
    Ok(())
}

/// A text style `font_px` high centred on its position.
fn centred(font_px: f64) -> TextStyle<'static> {
    TextStyle::from(("sans-serif", font_px).into_font()).pos(Pos::new(HPos::Center, VPos::Center))
}

/// `text` centred at `centre` on the box `r` filled in `fill` (pixels of `area`).
fn draw_text_patch(
    area: &DrawingArea<BitMapBackend<'_>, Shift>,
    text: String,
    centre: (f64, f64),
    r: Rect,
    fill: ShapeStyle,
    style: TextStyle<'_>,
    path: &Path,
) -> Result<()> {
    let corners = [nearest_px((r.x0, r.y0)), nearest_px((r.x1, r.y1))];
    area.draw(&Rectangle::new(corners, fill))
        .map_err(err(path))?;
    area.draw(&Text::new(text, nearest_px(centre), style))
        .map_err(err(path))?;
    Ok(())
}
