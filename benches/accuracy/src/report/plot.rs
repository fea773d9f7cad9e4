//! A hand-written SVG scatter plot: failures (log scale, 0 at the bottom) against cost
//! (ns per ray, log scale), one numbered point per choice, and a legend under the plot
//! naming each number (points crowd at 0 failures, where long labels would overlap).

use std::fmt::Write;

/// One point of the plot.
pub struct Point {
    pub label: String,
    pub ns_per_ray: f64,
    pub failures: u64,
}

const WIDTH: f64 = 900.0;
/// The height of the plot itself; the legend adds a line per point below it.
const PLOT_HEIGHT: f64 = 560.0;
const LEFT: f64 = 80.0;
const RIGHT: f64 = 40.0;
const TOP: f64 = 50.0;
const BOTTOM: f64 = 70.0;
/// The "0 failures" row sits this many decades below 1, and the frame's bottom this many
/// more below it (room for labels under the points).
const ZERO_DECADES: f64 = 0.8;
const BELOW_ZERO_DECADES: f64 = 0.5;
/// A rough width of one character of the labels, for placing them.
const CHAR_WIDTH: f64 = 6.6;
const LABEL_HEIGHT: f64 = 14.0;

const LEGEND_LINE: f64 = 18.0;

/// Colours of the points, in order.
const COLOURS: [&str; 10] = [
    "#d62728", "#1f77b4", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b", "#e377c2", "#17becf",
    "#7f7f7f", "#bcbd22",
];

/// The plot's axes: decades shown on each.
struct Axes {
    x_decades: (i32, i32),
    y_top_decade: i32,
}

impl Axes {
    /// Decades wide enough for every point.
    fn fit(points: &[Point]) -> Self {
        let (lo, hi) = points
            .iter()
            .map(|p| p.ns_per_ray.max(1e-3))
            .fold((f64::INFINITY, 0.0f64), |(lo, hi), x| {
                (lo.min(x), hi.max(x))
            });
        let (lo, hi) = if lo <= hi { (lo, hi) } else { (1.0, 10.0) };
        let mut x_decades = (lo.log10().floor() as i32, hi.log10().ceil() as i32);
        if x_decades.0 == x_decades.1 {
            x_decades.1 += 1;
        }
        let most = points.iter().map(|p| p.failures).max().unwrap_or(0).max(1);
        Self {
            x_decades,
            y_top_decade: ((most as f64).log10().ceil() as i32).max(1),
        }
    }

    /// The horizontal position of a cost.
    fn x(&self, ns: f64) -> f64 {
        let (lo, hi) = (f64::from(self.x_decades.0), f64::from(self.x_decades.1));
        let f = (ns.max(1e-3).log10() - lo) / (hi - lo);
        LEFT + f * (WIDTH - LEFT - RIGHT)
    }

    /// The vertical position of a failure count; 0 on its own row at the bottom.
    fn y(&self, failures: u64) -> f64 {
        let decades = if failures == 0 {
            -ZERO_DECADES
        } else {
            (failures as f64).log10()
        };
        let bottom = -(ZERO_DECADES + BELOW_ZERO_DECADES);
        let f = (decades - bottom) / (f64::from(self.y_top_decade) - bottom);
        PLOT_HEIGHT - BOTTOM - f * (PLOT_HEIGHT - TOP - BOTTOM)
    }
}

/// Text safe inside SVG.
fn escape(text: &str) -> String {
    text.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

/// `10^k` as a tick label.
fn decade_label(k: i32) -> String {
    match k {
        0 => "1".to_string(),
        1 => "10".to_string(),
        2 => "100".to_string(),
        _ => format!("1e{k}"),
    }
}

/// Grid lines, tick labels and axis titles.
fn draw_axes(svg: &mut String, axes: &Axes) -> std::fmt::Result {
    let (x0, x1) = (LEFT, WIDTH - RIGHT);
    let (y0, y1) = (TOP, PLOT_HEIGHT - BOTTOM);
    for k in axes.x_decades.0..=axes.x_decades.1 {
        let x = axes.x(10f64.powi(k));
        writeln!(
            svg,
            r##"<line x1="{x:.1}" y1="{y0}" x2="{x:.1}" y2="{y1}" stroke="#ddd"/><text x="{x:.1}" y="{:.1}" text-anchor="middle">{}</text>"##,
            y1 + 18.0,
            decade_label(k)
        )?;
    }
    for k in 0..=axes.y_top_decade {
        let y = axes.y(10u64.pow(k as u32));
        writeln!(
            svg,
            r##"<line x1="{x0}" y1="{y:.1}" x2="{x1}" y2="{y:.1}" stroke="#ddd"/><text x="{:.1}" y="{:.1}" text-anchor="end">{}</text>"##,
            x0 - 8.0,
            y + 4.0,
            decade_label(k)
        )?;
    }
    let zero = axes.y(0);
    let gap = (zero + axes.y(1)) / 2.0;
    writeln!(
        svg,
        r##"<line x1="{x0}" y1="{gap:.1}" x2="{x1}" y2="{gap:.1}" stroke="#999" stroke-dasharray="4 4"/><text x="{:.1}" y="{:.1}" text-anchor="end">0</text>"##,
        x0 - 8.0,
        zero + 4.0
    )?;
    writeln!(
        svg,
        r##"<rect x="{x0}" y="{y0}" width="{}" height="{}" fill="none" stroke="#333"/>"##,
        x1 - x0,
        y1 - y0
    )?;
    writeln!(
        svg,
        r##"<text x="{:.1}" y="{:.1}" text-anchor="middle">cost: ns per ray (log scale; each row's own workload)</text>"##,
        (x0 + x1) / 2.0,
        PLOT_HEIGHT - 20.0
    )?;
    writeln!(
        svg,
        r##"<text transform="translate(22 {:.1}) rotate(-90)" text-anchor="middle">failures, all workloads (log scale; 0 at the bottom)</text>"##,
        (y0 + y1) / 2.0
    )
}

/// A label's box: left, top, right, bottom.
type Rect = (f64, f64, f64, f64);

fn overlaps(a: &Rect, b: &Rect) -> bool {
    a.0 < b.2 && b.0 < a.2 && a.1 < b.3 && b.1 < a.3
}

/// Where to put a label for the point at `(x, y)`: the first candidate position (right,
/// left, then further up and down) that overlaps nothing placed and stays in the plot.
fn place_label(x: f64, y: f64, text: &str, placed: &[Rect]) -> (f64, f64, &'static str, Rect) {
    let width = text.chars().count() as f64 * CHAR_WIDTH;
    let mut fallback = None;
    for step in 0..12 {
        let dy = f64::from((step + 1) / 2) * LABEL_HEIGHT * if step % 2 == 0 { 1.0 } else { -1.0 };
        for right in [true, false] {
            let (left_edge, anchor, tx) = if right {
                (x + 8.0, "start", x + 8.0)
            } else {
                (x - 8.0 - width, "end", x - 8.0)
            };
            let ty = y + 4.0 + dy;
            let rect = (
                left_edge,
                ty - LABEL_HEIGHT + 3.0,
                left_edge + width,
                ty + 3.0,
            );
            let inside = rect.0 >= 0.0
                && rect.2 <= WIDTH
                && rect.1 >= TOP - 20.0
                && rect.3 <= PLOT_HEIGHT - BOTTOM;
            if inside && !placed.iter().any(|p| overlaps(p, &rect)) {
                return (tx, ty, anchor, rect);
            }
            fallback.get_or_insert((tx, ty, anchor, rect));
        }
    }
    fallback.unwrap_or((x + 8.0, y + 4.0, "start", (x, y, x, y)))
}

/// The whole SVG document.
pub fn svg(points: &[Point], title: &str) -> String {
    let axes = Axes::fit(points);
    let mut svg = String::new();
    // Writing to a String cannot fail.
    let _ = write_document(&mut svg, points, title, &axes);
    svg
}

fn write_document(
    svg: &mut String,
    points: &[Point],
    title: &str,
    axes: &Axes,
) -> std::fmt::Result {
    let height = PLOT_HEIGHT + LEGEND_LINE * points.len() as f64 + 10.0;
    writeln!(
        svg,
        r##"<svg xmlns="http://www.w3.org/2000/svg" width="{WIDTH}" height="{height}" viewBox="0 0 {WIDTH} {height}" font-family="sans-serif" font-size="12">"##
    )?;
    writeln!(svg, r##"<rect width="100%" height="100%" fill="white"/>"##)?;
    writeln!(
        svg,
        r##"<text x="{:.1}" y="28" text-anchor="middle" font-size="15">{}</text>"##,
        WIDTH / 2.0,
        escape(title)
    )?;
    draw_axes(svg, axes)?;
    draw_points(svg, points, axes)?;
    draw_legend(svg, points)?;
    writeln!(svg, "</svg>")
}

/// The points, each with its number beside it.
fn draw_points(svg: &mut String, points: &[Point], axes: &Axes) -> std::fmt::Result {
    // The dashed line above the zero row is in the way of labels too.
    let gap = (axes.y(0) + axes.y(1)) / 2.0;
    let mut placed: Vec<Rect> = vec![(LEFT, gap - 2.0, WIDTH - RIGHT, gap + 2.0)];
    for p in points {
        let (x, y) = (axes.x(p.ns_per_ray), axes.y(p.failures));
        placed.push((x - 5.0, y - 5.0, x + 5.0, y + 5.0));
    }
    for (i, p) in points.iter().enumerate() {
        let (x, y) = (axes.x(p.ns_per_ray), axes.y(p.failures));
        let colour = COLOURS[i % COLOURS.len()];
        writeln!(
            svg,
            r##"<circle cx="{x:.1}" cy="{y:.1}" r="5" fill="{colour}"/>"##
        )?;
        let number = (i + 1).to_string();
        let (tx, ty, anchor, rect) = place_label(x, y, &number, &placed);
        placed.push(rect);
        writeln!(
            svg,
            r##"<text x="{tx:.1}" y="{ty:.1}" text-anchor="{anchor}" fill="{colour}" font-weight="bold">{number}</text>"##
        )?;
    }
    Ok(())
}

/// One line per point under the plot: its number, choice, failures and cost.
fn draw_legend(svg: &mut String, points: &[Point]) -> std::fmt::Result {
    for (i, p) in points.iter().enumerate() {
        let y = PLOT_HEIGHT + LEGEND_LINE * i as f64 + 4.0;
        writeln!(
            svg,
            r##"<text x="{LEFT}" y="{y:.1}" fill="{}"><tspan font-weight="bold">{}</tspan>  {}: {} failures, {:.1} ns per ray</text>"##,
            COLOURS[i % COLOURS.len()],
            i + 1,
            escape(&p.label),
            p.failures,
            p.ns_per_ray
        )?;
    }
    Ok(())
}
