//! PNG plots with plotters, text rendered with the committed DejaVu Sans font (no system
//! font needed).

use crate::error::{Error, Result};
use plotters::prelude::*;
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

/// Colours of the series (colour-blind friendly).
pub const COLORS: [RGBColor; 4] = [
    RGBColor(0, 114, 178),
    RGBColor(213, 94, 0),
    RGBColor(0, 0, 0),
    RGBColor(0, 158, 115),
];

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

/// Draw every series (lines with their legend entry, markers of `radius` pixels, a marker
/// legend entry for marker-only series) on a chart with (f64, f64) data coordinates.
fn draw_series<'b, CT>(
    chart: &mut ChartContext<'_, BitMapBackend<'b>, CT>,
    series: &[Series],
    radius: u32,
    path: &Path,
) -> Result<()>
where
    CT: CoordTranslate<From = (f64, f64)>,
{
    for s in series {
        let c = COLORS[s.color % COLORS.len()];
        let style = if s.thin {
            c.stroke_width(1)
        } else {
            c.stroke_width(2)
        };
        if s.line {
            chart
                .draw_series(LineSeries::new(s.points.iter().copied(), style))
                .map_err(err(path))?
                .label(s.label.clone())
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], style));
        }
        if s.markers {
            let a = chart
                .draw_series(s.points.iter().map(|&p| Circle::new(p, radius, c.filled())))
                .map_err(err(path))?;
            if !s.line {
                a.label(s.label.clone())
                    .legend(move |(x, y)| Circle::new((x + 10, y), radius, c.filled()));
            }
        }
    }
    Ok(())
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
    register();
    let root = BitMapBackend::new(path, (900, 650)).into_drawing_area();
    root.fill(&WHITE).map_err(err(path))?;
    let ((x0, x1), (y0, y1)) = bounds(series, true);
    let mut chart = ChartBuilder::on(&root)
        .caption(title, ("sans-serif", 22))
        .margin(15)
        .x_label_area_size(50)
        .y_label_area_size(80)
        .build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())
        .map_err(err(path))?;
    chart
        .configure_mesh()
        .x_desc(xlabel)
        .y_desc(ylabel)
        .label_style(("sans-serif", 15))
        .x_label_formatter(&|v| format!("{v:.3}"))
        .y_label_formatter(&|v| format!("{v:.1e}"))
        .draw()
        .map_err(err(path))?;
    draw_series(&mut chart, series, 5, path)?;
    // Reference slope triangles in the lower right corner, stacked.
    let lx1 = x1 / 2.2;
    let lx0 = lx1 / 1.5;
    for (i, (slope, label)) in slopes.iter().enumerate() {
        let base = y0 * 1.15 * (y1 / y0).powf(0.09 * i as f64);
        let top = base * (lx1 / lx0).powf(*slope);
        let tri = vec![(lx0, base), (lx1, base), (lx1, top), (lx0, base)];
        chart
            .draw_series(std::iter::once(PathElement::new(
                tri,
                BLACK.stroke_width(1),
            )))
            .map_err(err(path))?;
        chart
            .draw_series(std::iter::once(Text::new(
                format!("slope {label}"),
                (lx1 * 1.05, (base * top).sqrt()),
                ("sans-serif", 14),
            )))
            .map_err(err(path))?;
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font(("sans-serif", 15))
        .position(SeriesLabelPosition::UpperLeft)
        .draw()
        .map_err(err(path))?;
    root.present().map_err(err(path))?;
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
    register();
    let root = BitMapBackend::new(path, (900, 550)).into_drawing_area();
    root.fill(&WHITE).map_err(err(path))?;
    let ((x0, x1), (y0, y1)) = bounds(series, false);
    let mut chart = ChartBuilder::on(&root)
        .caption(title, ("sans-serif", 20))
        .margin(15)
        .x_label_area_size(50)
        .y_label_area_size(90)
        .build_cartesian_2d(x0..x1, y0..y1)
        .map_err(err(path))?;
    chart
        .configure_mesh()
        .x_desc(xlabel)
        .y_desc(ylabel)
        .label_style(("sans-serif", 15))
        .y_label_formatter(&|v| format!("{v:.2e}"))
        .draw()
        .map_err(err(path))?;
    draw_series(&mut chart, series, 3, path)?;
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font(("sans-serif", 15))
        .draw()
        .map_err(err(path))?;
    root.present().map_err(err(path))?;
    Ok(())
}

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

type Square<'a, 'b> = ChartContext<
    'a,
    BitMapBackend<'b>,
    Cartesian2d<plotters::coord::types::RangedCoordf64, plotters::coord::types::RangedCoordf64>,
>;

/// A chart with equal aspect ratio around the triangles (the shorter range padded).
fn square_chart<'a, 'b>(
    area: &'a DrawingArea<BitMapBackend<'b>, plotters::coord::Shift>,
    title: &str,
    size: u32,
    triangles: &[[[f64; 2]; 3]],
    path: &Path,
) -> Result<Square<'a, 'b>> {
    let (x0, x1) = range(triangles.iter().flat_map(|t| t.iter().map(|v| v[0])), false);
    let (y0, y1) = range(triangles.iter().flat_map(|t| t.iter().map(|v| v[1])), false);
    let (cx, cy) = (0.5 * (x0 + x1), 0.5 * (y0 + y1));
    let half = 0.5 * (x1 - x0).max(y1 - y0);
    let mut chart = ChartBuilder::on(area)
        .caption(title, ("sans-serif", size))
        .margin(10)
        .x_label_area_size(30)
        .y_label_area_size(40)
        .build_cartesian_2d(cx - half..cx + half, cy - half..cy + half)
        .map_err(err(path))?;
    chart
        .configure_mesh()
        .disable_mesh()
        .label_style(("sans-serif", 12))
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

/// Panels side by side sharing one colour bar.
pub fn field_panels(path: &Path, title: &str, bar_label: &str, panels: &[Panel]) -> Result<()> {
    register();
    let w = (560 * panels.len() as u32 + 140).max(1000);
    let root = BitMapBackend::new(path, (w, 640)).into_drawing_area();
    root.fill(&WHITE).map_err(err(path))?;
    let root = root.titled(title, ("sans-serif", 20)).map_err(err(path))?;
    let (vmin, vmax) = range(panels.iter().flat_map(|p| p.values.iter().copied()), false);
    let (main, bar) = root.split_horizontally(w - 140);
    let areas = main.split_evenly((1, panels.len()));
    for (p, area) in panels.iter().zip(areas.iter()) {
        let mut chart = square_chart(area, &p.title, 17, &p.triangles, path)?;
        for (i, t) in p.triangles.iter().enumerate() {
            let c = colormap((p.values[i] - vmin) / (vmax - vmin).max(f64::MIN_POSITIVE));
            let pts: Vec<(f64, f64)> = t.iter().map(|v| (v[0], v[1])).collect();
            chart
                .draw_series(std::iter::once(Polygon::new(pts.clone(), c.filled())))
                .map_err(err(path))?;
            let edge = if p.body[i] == 1 {
                BLACK.mix(0.35)
            } else {
                RGBColor(90, 90, 90).mix(0.35)
            };
            let mut closed = pts;
            closed.push(closed[0]);
            chart
                .draw_series(std::iter::once(PathElement::new(
                    closed,
                    edge.stroke_width(1),
                )))
                .map_err(err(path))?;
        }
        for s in &p.highlight {
            chart
                .draw_series(std::iter::once(PathElement::new(
                    vec![(s[0][0], s[0][1]), (s[1][0], s[1][1])],
                    RED.stroke_width(3),
                )))
                .map_err(err(path))?;
        }
    }
    // Colour bar.
    let mut cb = ChartBuilder::on(&bar)
        .margin_top(60)
        .margin_bottom(60)
        .margin_right(70)
        .y_label_area_size(0)
        .right_y_label_area_size(60)
        .build_cartesian_2d(0.0..1.0, vmin..vmax)
        .map_err(err(path))?;
    cb.configure_mesh()
        .disable_mesh()
        .disable_x_axis()
        .y_desc(bar_label)
        .label_style(("sans-serif", 13))
        .y_label_formatter(&|v| format!("{v:.2}"))
        .draw()
        .map_err(err(path))?;
    let n = 100;
    for k in 0..n {
        let a = vmin + (vmax - vmin) * k as f64 / n as f64;
        let b = vmin + (vmax - vmin) * (k + 1) as f64 / n as f64;
        cb.draw_series(std::iter::once(Rectangle::new(
            [(0.0, a), (1.0, b)],
            colormap((k as f64 + 0.5) / n as f64).filled(),
        )))
        .map_err(err(path))?;
    }
    root.present().map_err(err(path))?;
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
    /// Undeformed outline segments to draw dashed (empty for none).
    pub outline: Vec<[[f64; 2]; 2]>,
}

/// Mesh panels side by side.
pub fn mesh_panels(path: &Path, title: &str, panels: &[MeshPanel]) -> Result<()> {
    register();
    let w = 600 * panels.len() as u32;
    let root = BitMapBackend::new(path, (w, 640)).into_drawing_area();
    root.fill(&WHITE).map_err(err(path))?;
    let root = root.titled(title, ("sans-serif", 20)).map_err(err(path))?;
    let areas = root.split_evenly((1, panels.len()));
    let fills = [RGBColor(198, 219, 239), RGBColor(253, 208, 162)];
    for (p, area) in panels.iter().zip(areas.iter()) {
        let mut chart = square_chart(area, &p.title, 16, &p.triangles, path)?;
        for (i, t) in p.triangles.iter().enumerate() {
            let pts: Vec<(f64, f64)> = t.iter().map(|v| (v[0], v[1])).collect();
            let fill = fills[(p.body[i].max(1) - 1) as usize % 2];
            chart
                .draw_series(std::iter::once(Polygon::new(pts.clone(), fill.filled())))
                .map_err(err(path))?;
            let mut closed = pts;
            closed.push(closed[0]);
            chart
                .draw_series(std::iter::once(PathElement::new(
                    closed,
                    BLACK.mix(0.5).stroke_width(1),
                )))
                .map_err(err(path))?;
        }
        for s in &p.outline {
            chart
                .draw_series(std::iter::once(PathElement::new(
                    vec![(s[0][0], s[0][1]), (s[1][0], s[1][1])],
                    RGBColor(120, 120, 120).stroke_width(1),
                )))
                .map_err(err(path))?;
        }
        for s in &p.highlight {
            chart
                .draw_series(std::iter::once(PathElement::new(
                    vec![(s[0][0], s[0][1]), (s[1][0], s[1][1])],
                    RED.stroke_width(2),
                )))
                .map_err(err(path))?;
        }
        chart
            .draw_series(
                p.nodes[0]
                    .iter()
                    .map(|v| Circle::new((v[0], v[1]), 4, COLORS[0].stroke_width(2))),
            )
            .map_err(err(path))?
            .label("body 1 interface nodes")
            .legend(|(x, y)| Circle::new((x + 8, y), 4, COLORS[0].stroke_width(2)));
        chart
            .draw_series(
                p.nodes[1]
                    .iter()
                    .map(|v| Cross::new((v[0], v[1]), 4, COLORS[1].stroke_width(2))),
            )
            .map_err(err(path))?
            .label("body 2 interface nodes")
            .legend(|(x, y)| Cross::new((x + 8, y), 4, COLORS[1].stroke_width(2)));
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.9))
            .border_style(BLACK)
            .label_font(("sans-serif", 13))
            .position(SeriesLabelPosition::LowerRight)
            .draw()
            .map_err(err(path))?;
    }
    root.present().map_err(err(path))?;
    Ok(())
}

/// One panel of a map over a grid of (x, y) cells: a value per cell, lines on top.
pub struct GridPanel {
    /// Panel title.
    pub title: String,
    /// Cells: (x, y, value); each cell is drawn as the unit square centred at (x, y).
    pub cells: Vec<(f64, f64, f64)>,
    /// Polylines to draw over the cells (e.g. the iso-dofs lines), with a label each.
    pub lines: Vec<(String, Vec<(f64, f64)>)>,
}

/// Maps side by side (two per row), each with its own colour scale on log10 of the values,
/// the value written in every cell.
pub fn grid_panels(
    path: &Path,
    title: &str,
    xlabel: &str,
    ylabel: &str,
    panels: &[GridPanel],
) -> Result<()> {
    register();
    let rows = panels.len().div_ceil(2) as u32;
    let root = BitMapBackend::new(path, (1100, 520 * rows + 40)).into_drawing_area();
    root.fill(&WHITE).map_err(err(path))?;
    let root = root.titled(title, ("sans-serif", 20)).map_err(err(path))?;
    let areas = root.split_evenly((rows as usize, 2));
    for (p, area) in panels.iter().zip(areas.iter()) {
        let (x0, x1) = range(p.cells.iter().map(|c| c.0), false);
        let (y0, y1) = range(p.cells.iter().map(|c| c.1), false);
        let logs: Vec<f64> = p.cells.iter().map(|c| c.2.max(1e-300).log10()).collect();
        let (v0, v1) = range(logs.iter().copied(), false);
        let mut chart = ChartBuilder::on(area)
            .caption(&p.title, ("sans-serif", 16))
            .margin(10)
            .x_label_area_size(35)
            .y_label_area_size(45)
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
        for (c, l) in p.cells.iter().zip(&logs) {
            let t = (l - v0) / (v1 - v0).max(f64::MIN_POSITIVE);
            chart
                .draw_series(std::iter::once(Rectangle::new(
                    [(c.0 - 0.5, c.1 - 0.5), (c.0 + 0.5, c.1 + 0.5)],
                    colormap(t).filled(),
                )))
                .map_err(err(path))?;
            let ink = if t > 0.6 { BLACK } else { WHITE };
            chart
                .draw_series(std::iter::once(Text::new(
                    format!("{:.2e}", c.2),
                    (c.0 - 0.38, c.1 + 0.08),
                    ("sans-serif", 12).into_font().color(&ink),
                )))
                .map_err(err(path))?;
        }
        for (label, pts) in &p.lines {
            let style = ShapeStyle::from(&RED).stroke_width(2);
            chart
                .draw_series(LineSeries::new(pts.iter().copied(), style))
                .map_err(err(path))?;
            if let Some(&last) = pts
                .iter()
                .filter(|q| q.1 <= y1 + 0.5 && q.0 <= x1 + 0.5)
                .last()
            {
                chart
                    .draw_series(std::iter::once(Text::new(
                        label.clone(),
                        (last.0 - 0.45, last.1 - 0.1),
                        ("sans-serif", 11).into_font().color(&RED),
                    )))
                    .map_err(err(path))?;
            }
        }
    }
    root.present().map_err(err(path))?;
    Ok(())
}
