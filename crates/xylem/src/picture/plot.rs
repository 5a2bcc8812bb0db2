//! Small line plots as images (validation figures, the error-against-time curve): axes, one
//! polyline per series with optional point markers, the axis ranges printed at the corners, the
//! axis titles beside them and a legend of the labelled series in the top-right corner. Longer
//! captions live in the Markdown that embeds the plot.

use super::contact::draw_label;
use super::image::Rgb8;

/// One curve of a plot.
#[derive(Clone, Debug)]
pub struct Series {
    /// The (x, y) points, joined in order.
    pub points: Vec<(f64, f64)>,
    /// Line colour (8-bit sRGB).
    pub color: [u8; 3],
    /// Draw a small square on every point (for measurements, not sampled curves).
    pub markers: bool,
    /// Legend entry ("" for none: guides, reference lines).
    pub label: String,
}

/// Plot size and axis scaling.
#[derive(Clone, Copy, Debug)]
pub struct PlotOptions {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Logarithmic x axis (points with x ≤ 0 are left out).
    pub log_x: bool,
    /// Logarithmic y axis (points with y ≤ 0 are left out).
    pub log_y: bool,
    /// Title of the x axis, printed at the bottom between the range labels ("" for none).
    pub x_title: &'static str,
    /// Title of the y axis, printed at the top beside the largest value ("" for none).
    pub y_title: &'static str,
}

impl Default for PlotOptions {
    fn default() -> Self {
        PlotOptions {
            width: 480,
            height: 240,
            log_x: false,
            log_y: false,
            x_title: "",
            y_title: "",
        }
    }
}

/// Distinct colours for up to six series (cycled beyond).
pub const PALETTE: [[u8; 3]; 6] = [
    [31, 119, 180],
    [214, 39, 40],
    [44, 160, 44],
    [255, 127, 14],
    [148, 103, 189],
    [23, 190, 207],
];

/// A compact number label (the 3×5 font has digits, sign, point and `e`).
fn number_label(v: f64) -> String {
    let a = v.abs();
    if a != 0.0 && !(1e-2..1e4).contains(&a) {
        format!("{v:.0e}")
    } else if a >= 100.0 || v.fract() == 0.0 {
        format!("{v:.0}")
    } else {
        format!("{v:.2}")
    }
}

/// Draws the series; non-finite points (and non-positive ones on a log axis) are skipped.
pub fn line_plot(series: &[Series], opts: &PlotOptions) -> Rgb8 {
    let (w, h) = (opts.width.max(64), opts.height.max(48));
    let mut img = Rgb8::filled(w, h, [255, 255, 255]);
    let pts = axis_points(series, opts);
    let axes = Axes::new(&pts, w, h);
    let grey = [150, 150, 150];
    let (left, right, top, bottom) = (axes.left, axes.right, axes.top, axes.bottom);
    line(&mut img, left, bottom, right, bottom, grey);
    line(&mut img, left, top, left, bottom, grey);
    if axes.y0 < 0.0 && axes.y1 > 0.0 && !opts.log_y {
        let z = axes.py(0.0).round() as i64;
        line(&mut img, left, z, right, z, [220, 220, 220]);
    }
    for (s, p) in series.iter().zip(&pts) {
        draw_series(&mut img, &axes, s, p);
    }
    draw_axis_labels(&mut img, &axes, opts);
    draw_legend(&mut img, &axes, series);
    img
}

/// Each series' drawable points on the plot's axes: finite, positive on a log axis, and
/// `log10` of the value there.
fn axis_points(series: &[Series], opts: &PlotOptions) -> Vec<Vec<(f64, f64)>> {
    let tx = |v: f64| if opts.log_x { v.log10() } else { v };
    let ty = |v: f64| if opts.log_y { v.log10() } else { v };
    series
        .iter()
        .map(|s| {
            s.points
                .iter()
                .filter(|(x, y)| x.is_finite() && y.is_finite())
                .filter(|(x, _)| !opts.log_x || *x > 0.0)
                .filter(|(_, y)| !opts.log_y || *y > 0.0)
                .map(|&(x, y)| (tx(x), ty(y)))
                .collect()
        })
        .collect()
}

/// The data ranges (on the axes' scale) and the pixel box they map to.
struct Axes {
    x0: f64,
    x1: f64,
    y0: f64,
    y1: f64,
    left: i64,
    right: i64,
    top: i64,
    bottom: i64,
}

impl Axes {
    /// The ranges of `pts` (a unit square when empty; a degenerate range widened by ±0.5; y
    /// padded by 5 %, never below zero for data that has none) in a `w × h` image.
    fn new(pts: &[Vec<(f64, f64)>], w: u32, h: u32) -> Axes {
        let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
        for &(x, y) in pts.iter().flatten() {
            x0 = x0.min(x);
            x1 = x1.max(x);
            y0 = y0.min(y);
            y1 = y1.max(y);
        }
        if x0 > x1 {
            (x0, x1, y0, y1) = (0.0, 1.0, 0.0, 1.0);
        }
        if x1 - x0 < 1e-12 {
            (x0, x1) = (x0 - 0.5, x1 + 0.5);
        }
        if y1 - y0 < 1e-12 {
            (y0, y1) = (y0 - 0.5, y1 + 0.5);
        }
        let pad = 0.05 * (y1 - y0);
        // Pad the range, but never below zero for data that has none (radiance, errors).
        let (y0, y1) = (
            if y0 >= 0.0 {
                (y0 - pad).max(0.0)
            } else {
                y0 - pad
            },
            y1 + pad,
        );
        Axes {
            x0,
            x1,
            y0,
            y1,
            left: 8,
            right: w as i64 - 8,
            top: 14,
            bottom: h as i64 - 14,
        }
    }

    /// The pixel column of x.
    fn px(&self, x: f64) -> f64 {
        self.left as f64 + (x - self.x0) / (self.x1 - self.x0) * (self.right - self.left) as f64
    }

    /// The pixel row of y.
    fn py(&self, y: f64) -> f64 {
        self.bottom as f64 - (y - self.y0) / (self.y1 - self.y0) * (self.bottom - self.top) as f64
    }
}

/// One series' polyline through `p`, with a 5×5 square on every point if it has markers.
fn draw_series(img: &mut Rgb8, axes: &Axes, s: &Series, p: &[(f64, f64)]) {
    let at = |(x, y): (f64, f64)| (axes.px(x).round() as i64, axes.py(y).round() as i64);
    for pair in p.windows(2) {
        let ((ax, ay), (bx, by)) = (at(pair[0]), at(pair[1]));
        line(img, ax, ay, bx, by, s.color);
    }
    if s.markers {
        for &q in p {
            let (cx, cy) = at(q);
            for dy in -2..=2 {
                for dx in -2..=2 {
                    set(img, cx + dx, cy + dy, s.color);
                }
            }
        }
    }
}

/// Width in pixels of `t` in the 3×5 font.
fn text_width(t: &str) -> u32 {
    4 * t.chars().count() as u32 + 1
}

/// The axis ranges at the corners and the axis titles beside them.
fn draw_axis_labels(img: &mut Rgb8, axes: &Axes, opts: &PlotOptions) {
    let (w, h) = (img.width, img.height);
    let (left, right, bottom) = (axes.left as u32, axes.right as u32, axes.bottom as u32);
    let un = |v: f64, log: bool| if log { 10f64.powf(v) } else { v };
    let xl = number_label(un(axes.x0, opts.log_x));
    let xr = number_label(un(axes.x1, opts.log_x));
    draw_label(img, &xl, left, h - 8, 1);
    draw_label(
        img,
        &xr,
        right.saturating_sub(4 * xr.len() as u32 + 1),
        h - 8,
        1,
    );
    let y_max = number_label(un(axes.y1, opts.log_y));
    draw_label(img, &y_max, left + 2, 2, 1);
    let y_min = number_label(un(axes.y0, opts.log_y));
    draw_label(img, &y_min, left + 2, bottom - 8, 1);
    if !opts.x_title.is_empty() {
        let x = (w / 2).saturating_sub(text_width(opts.x_title) / 2);
        draw_label(img, opts.x_title, x, h - 8, 1);
    }
    if !opts.y_title.is_empty() {
        draw_label(img, opts.y_title, left + 6 + text_width(&y_max), 2, 1);
    }
}

/// The legend: a swatch and the label per labelled series, right-aligned, top down.
fn draw_legend(img: &mut Rgb8, axes: &Axes, series: &[Series]) {
    let mut row = axes.top as u32 + 2;
    for s in series.iter().filter(|s| !s.label.is_empty()) {
        let x = (axes.right as u32).saturating_sub(text_width(&s.label) + 8);
        for dy in 1..6 {
            for dx in 0..5 {
                set(img, (x + dx) as i64, (row + dy) as i64, s.color);
            }
        }
        draw_label(img, &s.label, x + 7, row, 1);
        row += 8;
    }
}

fn set(img: &mut Rgb8, x: i64, y: i64, c: [u8; 3]) {
    if x >= 0 && y >= 0 && (x as u32) < img.width && (y as u32) < img.height {
        let i = (y as usize * img.width as usize + x as usize) * 3;
        img.data[i..i + 3].copy_from_slice(&c);
    }
}

/// Bresenham's line between two pixel positions (inclusive).
fn line(img: &mut Rgb8, mut x0: i64, mut y0: i64, x1: i64, y1: i64, c: [u8; 3]) {
    let (dx, dy) = ((x1 - x0).abs(), -(y1 - y0).abs());
    let (sx, sy) = (if x0 < x1 { 1 } else { -1 }, if y0 < y1 { 1 } else { -1 });
    let mut err = dx + dy;
    loop {
        set(img, x0, y0, c);
        if x0 == x1 && y0 == y1 {
            break;
        }
        let e2 = 2 * err;
        if e2 >= dy {
            err += dy;
            x0 += sx;
        }
        if e2 <= dx {
            err += dx;
            y0 += sy;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_rising_line_runs_from_lower_left_to_upper_right() {
        let s = Series {
            points: vec![(0.0, 0.0), (1.0, 1.0)],
            color: [255, 0, 0],
            markers: false,
            label: String::new(),
        };
        let img = line_plot(&[s], &PlotOptions::default());
        let red = |x: u32, y: u32| {
            let i = (y * img.width + x) as usize * 3;
            img.data[i..i + 3] == [255, 0, 0]
        };
        let (w, h) = (img.width, img.height);
        // Some red pixel near each end, none in the opposite corners.
        let near = |cx: u32, cy: u32| {
            (cx.saturating_sub(12)..(cx + 12).min(w))
                .any(|x| (cy.saturating_sub(12)..(cy + 12).min(h)).any(|y| red(x, y)))
        };
        assert!(near(8, h - 14) && near(w - 8, 14));
        assert!(!near(w - 20, h - 20) && !near(20, 20));
    }

    #[test]
    fn log_axes_and_bad_points_do_not_panic() {
        let s = Series {
            points: vec![(0.0, 1.0), (1.0, f64::NAN), (10.0, 1e-3), (100.0, -1.0)],
            color: [0, 0, 255],
            label: String::new(),
            markers: true,
        };
        let opts = PlotOptions {
            log_x: true,
            log_y: true,
            ..Default::default()
        };
        let img = line_plot(&[s], &opts);
        assert_eq!(img.data.len(), (img.width * img.height * 3) as usize);
        assert_eq!(number_label(1e-3), "1e-3");
        assert_eq!(number_label(-60.0), "-60");
    }

    /// A labelled series gets a swatch of its colour in the top-right legend and axis titles are
    /// drawn; the same plot without label or titles (the control) has neither.
    #[test]
    fn legend_and_axis_titles_are_drawn_only_when_given() {
        let plot = |label: &str, titles: bool| {
            let s = Series {
                points: vec![(0.0, 0.0), (1.0, 0.0)],
                color: [0, 160, 0],
                markers: false,
                label: label.into(),
            };
            let opts = PlotOptions {
                x_title: if titles { "cpu s" } else { "" },
                y_title: if titles { "rel mse" } else { "" },
                ..PlotOptions::default()
            };
            line_plot(&[s], &opts)
        };
        let count = |img: &Rgb8, c: [u8; 3], xs: std::ops::Range<u32>, ys: std::ops::Range<u32>| {
            ys.flat_map(|y| xs.clone().map(move |x| (x, y)))
                .filter(|&(x, y)| {
                    let i = (y * img.width + x) as usize * 3;
                    img.data[i..i + 3] == c
                })
                .count()
        };
        let (with, without) = (plot("model", true), plot("", false));
        let (w, h) = (with.width, with.height);
        let legend = |img: &Rgb8| count(img, [0, 160, 0], w - 60..w, 0..30);
        assert_eq!(legend(&with), 25, "one 5 × 5 swatch");
        assert_eq!(legend(&without), 0);
        let black = |img: &Rgb8| count(img, [0, 0, 0], w / 2 - 12..w / 2 + 12, h - 8..h - 1);
        assert!(black(&with) > 10 && black(&without) == 0);
    }
}
