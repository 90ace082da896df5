//! Axis tick labels never collide: over log and linear spans (narrow, within a decade,
//! across many), on the axis lengths the report figures have, the labels' pixel extents
//! (measured with the font the plots are drawn with) leave a gap, at least two remain and
//! each reads as its tick's value. And a map panel with a zero or round-off cell keeps its
//! colour scale for the other cells.

use contact_rates::report::plot::{self, GridPanel, Series, Side, Ticks};

/// The number a tick label writes: "0.05", "-1.5", "300", "10⁻³", "2×10⁵", "2.5×10⁻²".
fn parse(label: &str) -> f64 {
    const SUP: &str = "⁰¹²³⁴⁵⁶⁷⁸⁹";
    let (neg, body) = match label.strip_prefix('-') {
        Some(b) => (true, b),
        None => (false, label),
    };
    let v = match body.find(|c: char| c == '⁻' || SUP.contains(c)) {
        Some(at) => {
            let (head, exp) = body.split_at(at);
            let head = head
                .strip_suffix("10")
                .unwrap_or_else(|| panic!("{label}: no 10 before the exponent"));
            let mantissa = match head.strip_suffix('×') {
                Some(m) => m.parse::<f64>().unwrap(),
                None if head.is_empty() => 1.0,
                None => panic!("{label}: mantissa without ×"),
            };
            let (mut e, mut sign) = (0i32, 1i32);
            for c in exp.chars() {
                match c {
                    '⁻' => sign = -1,
                    d => e = 10 * e + SUP.chars().position(|s| s == d).unwrap() as i32,
                }
            }
            mantissa * 10f64.powi(sign * e)
        }
        None => body
            .parse::<f64>()
            .unwrap_or_else(|_| panic!("{label}: not a number")),
    };
    if neg { -v } else { v }
}

/// Assert the ticks of an axis over [lo, hi], `pixels` long: two labels or more, each on
/// the axis and reading as its value, no two the same, and between neighbours' extents (the
/// width across, the height up, centred on the tick) a gap of 0.4 font size at least.
fn check(
    t: &Ticks,
    lo: f64,
    hi: f64,
    log: bool,
    (pixels, font, side, max_width): (f64, f64, Side, f64),
) {
    let what = format!("{lo:e}..{hi:e} {side:?} {pixels} px: {:?}", t.major);
    assert!(t.major.len() >= 2, "fewer than two labels: {what}");
    let pos = |v: f64| match log {
        true => (v.ln() - lo.ln()) / (hi.ln() - lo.ln()) * pixels,
        false => (v - lo) / (hi - lo) * pixels,
    };
    let mut extents = Vec::new();
    for (v, label) in &t.major {
        let tol = 1e-9 * hi.abs().max(lo.abs());
        assert!(
            *v >= lo - tol && *v <= hi + tol,
            "{label} off the axis: {what}"
        );
        let read = parse(label);
        assert!(
            (read - v).abs() <= 1e-9 * v.abs().max(1e-300),
            "{label} reads {read}, the tick is at {v}: {what}"
        );
        let (w, h) = plot::text_size(label, font);
        assert!(w > 0.0 && h > 0.0, "{label} measured empty");
        assert!(
            w <= max_width,
            "{label} wider than {max_width} pixels: {what}"
        );
        let half = 0.5 * if side == Side::Horizontal { w } else { h };
        extents.push((pos(*v) - half, pos(*v) + half));
    }
    extents.sort_by(|a, b| a.0.total_cmp(&b.0));
    for w in extents.windows(2) {
        assert!(
            w[1].0 - w[0].1 >= 0.4 * font,
            "labels {:?} and {:?} (pixels) too close: {what}",
            w[0],
            w[1]
        );
    }
    let mut labels: Vec<&String> = t.major.iter().map(|t| &t.1).collect();
    labels.dedup();
    assert_eq!(labels.len(), t.major.len(), "a label twice: {what}");
}

const LOG_SPANS: [(f64, f64); 16] = [
    (0.06, 0.1),
    (0.061, 0.069),
    (1e-3, 1.0),
    (0.02, 0.5),
    (5.0, 3000.0),
    (0.0088, 0.29),
    (0.035, 0.29),
    (0.2, 0.3),
    (1.2e-12, 0.15),
    (150.0, 2.2e6),
    (1e-4, 1e4),
    (0.9, 1.1),
    (0.999, 1.001),
    (1e-11, 5e-11),
    (2.0, 2.0e5),
    (1e-30, 1e30),
];

/// The widest a y label may be in these tests (the log-log figures leave 67 pixels).
const Y_ROOM: f64 = 60.0;

#[test]
fn log_axis_labels_do_not_collide() {
    let (w, h) = plot::loglog_plot_area();
    let font = plot::TICK_FONT_PX;
    for &(a, b) in &LOG_SPANS {
        // The span itself, and padded as the plots pad their data (a factor 1.6 each side).
        for (lo, hi) in [(a, b), (a / 1.6, b * 1.6)] {
            for axis in [
                (f64::from(w), font, Side::Horizontal, f64::INFINITY),
                (f64::from(h), font, Side::Vertical, Y_ROOM),
                (400.0, font, Side::Horizontal, f64::INFINITY),
                (250.0, font, Side::Vertical, Y_ROOM),
            ] {
                let t = plot::log_ticks(lo, hi, axis.0, axis.1, axis.2, axis.3);
                check(&t, lo, hi, true, axis);
            }
        }
    }
}

#[test]
fn the_reported_collision_is_gone() {
    // reports/rates-exact-vp/error_vs_h.png: h from 0.0088 to 0.29, padded; its labels
    // between 0.06 and 0.1 ran into each other.
    let (w, _) = plot::loglog_plot_area();
    let (lo, hi) = (0.0088 / 1.6, 0.29 * 1.6);
    let axis = (
        f64::from(w),
        plot::TICK_FONT_PX,
        Side::Horizontal,
        f64::INFINITY,
    );
    let t = plot::log_ticks(lo, hi, axis.0, axis.1, axis.2, axis.3);
    check(&t, lo, hi, true, axis);
    let between = t.major.iter().filter(|m| m.0 > 0.055 && m.0 < 0.11).count();
    assert!(between <= 2, "{:?}", t.major);
}

#[test]
fn linear_axis_labels_do_not_collide() {
    let (w, h) = plot::lines_plot_area();
    let spans = [
        (0.0, 0.014),
        (-0.0012, 0.0004),
        (8.6, 10.7),
        (-0.55, 2.1),
        (0.0, 31.0),
        (-11.6, -8.8),
        (0.0, 1.0),
        (1e5, 3e5),
        (0.0, 5e-4),
        (-1.5, 1.5),
        (0.9999, 1.0001),
        (-1e-9, 1e-9),
    ];
    for &(lo, hi) in &spans {
        for axis in [
            (
                f64::from(w),
                plot::TICK_FONT_PX,
                Side::Horizontal,
                f64::INFINITY,
            ),
            (f64::from(h), plot::TICK_FONT_PX, Side::Vertical, Y_ROOM),
            (450.0, 12.0, Side::Horizontal, f64::INFINITY),
            (440.0, 13.0, Side::Vertical, 62.0),
        ] {
            let t = plot::linear_ticks(lo, hi, axis.0, axis.1, axis.2, axis.3);
            check(&t, lo, hi, false, axis);
        }
    }
}

#[test]
fn a_zero_cell_keeps_the_colour_scale_of_the_others() {
    let values = [0.0, 1e-17, 1e-4, 1e-3, 1e-2, 1e-1];
    let panel = GridPanel {
        title: "max_penetration".into(),
        cells: values
            .iter()
            .enumerate()
            .map(|(i, &v)| ((i % 3) as f64, (i / 3) as f64, v))
            .collect(),
        lines: Vec::new(),
        roundoff: 1e-10,
    };
    let shades = plot::cell_shades(&panel);
    assert_eq!(shades[0], None, "zero on the scale");
    assert_eq!(shades[1], None, "round-off on the scale");
    let t: Vec<f64> = shades[2..]
        .iter()
        .map(|s| s.expect("on the scale"))
        .collect();
    // The other four spread over the colour map, in order.
    assert!(t[0] < 0.1 && t[3] > 0.9, "{t:?}");
    assert!(t.windows(2).all(|w| w[1] - w[0] > 0.2), "{t:?}");
}

#[test]
fn figures_render() {
    // Written where PLOT_TICKS_OUT says (to look at them), else to a temporary folder.
    let tmp = tempfile::tempdir().unwrap();
    let dir = std::env::var_os("PLOT_TICKS_OUT")
        .map(std::path::PathBuf::from)
        .unwrap_or_else(|| tmp.path().to_path_buf());
    std::fs::create_dir_all(&dir).unwrap();
    let hs = [0.0088, 0.0176, 0.035, 0.07, 0.14, 0.29];
    let series = vec![
        Series {
            label: "mortar".into(),
            points: hs.iter().map(|&h| (h, 0.9 * h)).collect(),
            markers: true,
            line: true,
            color: 0,
            thin: false,
            shape: None,
        },
        Series {
            label: "nts".into(),
            points: hs.iter().map(|&h| (h, 0.02 * h.sqrt())).collect(),
            markers: true,
            line: true,
            color: 1,
            thin: true,
            shape: None,
        },
    ];
    let slopes = [(0.5, "1/2"), (1.0, "1")];
    let loglog = dir.join("loglog.png");
    plot::loglog(&loglog, "error against h", "h", "error", &series, &slopes).unwrap();
    let lines = dir.join("lines.png");
    plot::lines(&lines, "lines", "x", "y", &series).unwrap();
    let grid = dir.join("grid.png");
    let cells = |zero: bool| {
        (0..16)
            .map(|i| {
                let (x, y) = ((i % 4) as f64, (i / 4) as f64);
                let v = if zero && i == 2 {
                    0.0
                } else {
                    0.3 * 0.3f64.powi(i)
                };
                (x, y, v)
            })
            .collect()
    };
    let line = |l: f64| {
        (0..=30)
            .map(|k| {
                let x = -0.5 + 4.0 * f64::from(k) / 30.0;
                (x, l - 0.8 * x)
            })
            .filter(|p| p.1 >= -0.5 && p.1 <= 3.5)
            .collect()
    };
    let panels: Vec<GridPanel> = [false, true]
        .iter()
        .map(|&zero| GridPanel {
            title: format!("zero cell: {zero}"),
            cells: cells(zero),
            lines: vec![
                ("122 dofs".into(), line(1.0)),
                ("471 dofs".into(), line(3.0)),
            ],
            roundoff: 1e-10,
        })
        .collect();
    plot::grid_panels(&grid, "map", "slave level", "master level", &panels).unwrap();
    for f in [loglog, lines, grid] {
        let bytes = std::fs::read(&f).unwrap();
        assert_eq!(&bytes[1..4], b"PNG", "{}", f.display());
    }
}

/// Reference: issue 74 (no line hidden under another without saying so in the legend).
/// Goal: a series that lies on an earlier one says which, and to what relative difference
/// (rounded up to one significant digit); equal data say "="; other abscissae say "under";
/// on a linear axis the difference is read against the axis' largest |y| (a gap profile
/// through zero), on a log axis against each value.
#[test]
fn a_hidden_series_says_what_it_lies_on() {
    let at = |points: Vec<(f64, f64)>, label: &str| Series {
        label: label.into(),
        points,
        markers: true,
        line: false,
        color: 0,
        thin: false,
        shape: None,
    };
    let hs = [0.1, 0.05, 0.025];
    let mortar = at(
        hs.iter().map(|&h| (h, h)).collect(),
        "mortar (theorem norm)",
    );
    let close = at(hs.iter().map(|&h| (h, h * (1.0 + 3e-5))).collect(), "nts");
    let same = at(hs.iter().map(|&h| (h, h)).collect(), "lac");
    let shifted = at(hs.iter().map(|&h| (1.01 * h, h)).collect(), "code");
    assert_eq!(
        plot::coincidence(&close, &mortar, 0.0),
        " (= mortar to 3e-5)"
    );
    assert_eq!(plot::coincidence(&same, &mortar, 0.0), " (= mortar)");
    assert_eq!(plot::coincidence(&shifted, &mortar, 0.0), " (under mortar)");
    // A profile through zero on a linear axis (a gap closed to round-off, 0.016 where it
    // opens): +-1e-9 about zero is 2e-9 of the axis' 0.016, not a difference of 2.
    let gap = |zero: f64| at(vec![(0.1, zero), (0.5, 0.004), (0.9, 0.016)], "lac");
    let (mortar_gap, lac_gap) = (gap(1e-9), gap(-1e-9));
    assert_eq!(
        plot::coincidence(&lac_gap, &mortar_gap, 0.0),
        " (= lac to 2e0)"
    );
    assert_eq!(
        plot::coincidence(&lac_gap, &mortar_gap, 0.016),
        " (= lac to 2e-7)"
    );
}
