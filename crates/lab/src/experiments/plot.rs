//! The experiments' plots: PNG files drawn with plotters' bitmap backend, text in the DejaVu
//! Sans font shipped in `assets/fonts` (no system fonts, no system packages).
//!
//! Over 600 lines with its unit tests, which check each kind of plot is drawn and not blank.

use crate::error::LabError;
use plotters::prelude::*;
use plotters::style::{FontStyle, register_font};
use std::path::Path;
use std::sync::Once;

static FONT: &[u8] = include_bytes!("../../../../assets/fonts/DejaVuSans.ttf");

/// How a series is drawn.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Mark {
    /// A line through the points, with a dot at each.
    Line,
    /// A dashed line.
    Dashed,
    /// Triangles only (the paper's numbers).
    Points,
    /// Filled circles only: values of categories, which no line joins.
    Dots,
    /// Hollow circles only, beside `Dots` in the same categories.
    Rings,
}

impl Mark {
    /// Whether a line joins the points.
    fn joined(self) -> bool {
        matches!(self, Mark::Line | Mark::Dashed)
    }
}

/// One curve or set of points in a panel, with its legend label.
#[derive(Clone, Debug)]
pub struct Series {
    /// The series' name in the legend.
    pub label: String,
    /// The (x, y) points, in the panel's units.
    pub points: Vec<(f64, f64)>,
    /// Half-heights of vertical error bars, one per point.
    pub errors: Option<Vec<f64>>,
    /// Half-widths of horizontal error bars, one per point.
    pub x_errors: Option<Vec<f64>>,
    /// How the series is drawn: a line, a dashed line or points only.
    pub mark: Mark,
    /// Index into the palette.
    pub colour: usize,
}

impl Series {
    /// A series without error bars.
    pub fn new(label: impl Into<String>, points: Vec<(f64, f64)>, mark: Mark, colour: usize) -> Self {
        Self {
            label: label.into(),
            points,
            errors: None,
            x_errors: None,
            mark,
            colour,
        }
    }

    /// What the series draws: each point's error bars' ends (the point itself without them).
    fn reach(&self) -> impl Iterator<Item = (f64, f64)> + '_ {
        self.points.iter().enumerate().flat_map(|(i, &(x, y))| {
            let e = self.errors.as_ref().map_or(0.0, |e| e[i]);
            let f = self.x_errors.as_ref().map_or(0.0, |e| e[i]);
            [(x, y - e), (x, y + e), (x - f, y), (x + f, y)]
        })
    }
}

/// One chart: axes with their units, series, a legend.
#[derive(Clone, Debug, Default)]
pub struct Panel {
    /// The panel's title, above the chart.
    pub title: String,
    /// The x axis's caption, with its unit.
    pub x_label: String,
    /// The y axis's caption, with its unit.
    pub y_label: String,
    /// Whether the y axis is logarithmic (whole decades).
    pub log_y: bool,
    /// Names for whole-number x positions (a categorical axis), if any.
    pub x_names: Vec<String>,
    /// The series drawn, each in the legend.
    pub series: Vec<Series>,
    /// Labels written beside points: (x, y, text).
    pub notes: Vec<(f64, f64, String)>,
    /// Axes to scale: a metre across is as long as a metre up (spatial data, a path).
    pub to_scale: bool,
}

const PALETTE: [RGBColor; 9] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(255, 127, 14),
    RGBColor(148, 103, 189),
    RGBColor(90, 90, 90),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(188, 189, 34),
];

/// The palette index of the grey drawn for references (30 fps, the desired speed).
pub const REFERENCE: usize = 5;

/// One colour per level policy, the same in every figure. A budget used as a ceiling takes
/// [`BUDGET_CEILING`].
pub fn policy_colour(policy: simlod::lod::LevelPolicy) -> usize {
    use simlod::lod::LevelPolicy::*;
    match policy {
        Influence => 0,
        AllHybrid => 1,
        Budget => 2,
        AllRigid => 4,
        AllPointMass => 6,
        Camera => 7,
        Combined => 8,
    }
}

/// The budget policy as a ceiling (bought from a least benefit per ms).
pub const BUDGET_CEILING: usize = 3;

fn register() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        register_font("sans-serif", FontStyle::Normal, FONT)
            .unwrap_or_else(|_| panic!("the shipped font is a valid TrueType font"));
    });
}

/// The range of the values, padded; on a log axis, whole decades around them.
fn range(values: impl Iterator<Item = f64>, log: bool) -> (f64, f64) {
    let (lo, hi) = values
        .filter(|v| v.is_finite() && (!log || *v > 0.0))
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| (a.min(v), b.max(v)));
    if !lo.is_finite() {
        return if log { (0.1, 10.0) } else { (0.0, 1.0) };
    }
    if log {
        // Whole decades, with a point near a decade's edge moved off the axis's edge.
        let (lo, hi) = (lo.log10() - 0.05, hi.log10() + 0.05);
        (10f64.powf(lo.floor()), 10f64.powf(hi.ceil().max(lo.floor() + 1.0)))
    } else {
        let pad = ((hi - lo) * 0.08).max(hi.abs().max(1.0) * 0.05);
        (lo - pad, hi + pad)
    }
}

/// A tick label: at most three decimals, no trailing zeros; a small number as a power of ten
/// (the log axis of Table 1 reaches 1e-4).
fn tidy(x: f64) -> String {
    if x.abs() < 1e-12 {
        // A tick at zero, computed with a rounding error.
        return "0".into();
    }
    if x.abs() < 1e-3 {
        return format!("{x:e}");
    }
    let s = format!("{x:.3}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" { "0".into() } else { s.into() }
}

/// The banner over a smoke test's plot: its figures are not findings.
pub const SMOKE_TEST_BANNER: &str = "SMOKE TEST (--quick): checks the pipeline; not a result";

/// Draws `panels` side by side into a PNG of `width` by `height` pixels; a `smoke_test`'s
/// plot says so in a banner over them.
/// Where a panel's parts landed, in the figure's pixels: what a test of its layout reads.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PanelLayout {
    /// The plotting area inside the axes.
    pub plot: Rect,
    /// The legend's box, as the legend's corner and its measured share of the plot give it.
    pub legend: Rect,
    /// Each note's box.
    pub labels: Vec<Rect>,
    /// Each data point's marker, centre.
    pub markers: Vec<(i32, i32)>,
}

impl PanelLayout {
    /// What is wrong with the layout inside a `width` by `height` figure: a label or the
    /// legend outside it, a label over another label or a marker, the legend over a marker.
    pub fn problems(&self, (width, height): (u32, u32)) -> Vec<String> {
        let figure = (0, 0, width as i32, height as i32);
        let inside = |r: Rect| r.0 >= figure.0 && r.1 >= figure.1 && r.2 <= figure.2 && r.3 <= figure.3;
        let marker = |&(x, y): &(i32, i32)| (x - MARKER_PX, y - MARKER_PX, x + MARKER_PX, y + MARKER_PX);
        let mut problems = Vec::new();
        if !inside(self.legend) {
            problems.push(format!("the legend {:?} is outside the figure", self.legend));
        }
        if let Some(m) = self.markers.iter().find(|m| overlap(self.legend, marker(m))) {
            problems.push(format!("the legend covers the marker at {m:?}"));
        }
        for (i, &r) in self.labels.iter().enumerate() {
            if !inside(r) {
                problems.push(format!("label {i} {r:?} is outside the figure"));
            }
            if self.labels[..i].iter().any(|&o| overlap(r, o)) {
                problems.push(format!("label {i} {r:?} covers another label"));
            }
            if let Some(m) = self.markers.iter().find(|m| overlap(r, marker(m))) {
                problems.push(format!("label {i} {r:?} covers the marker at {m:?}"));
            }
        }
        problems
    }
}

/// Draws the panels side by side into a PNG of `width` by `height` pixels, and says where
/// their parts landed.
pub fn draw(
    path: &Path,
    width: u32,
    height: u32,
    panels: &[Panel],
    smoke_test: bool,
) -> Result<Vec<PanelLayout>, LabError> {
    register();
    let fail = |e: &dyn std::fmt::Display| LabError::Invalid(format!("cannot draw {}: {e}", path.display()));
    let root = BitMapBackend::new(path, (width, height)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| fail(&e))?;
    let area = if smoke_test {
        let banner = ("sans-serif", TITLE_PT).into_font().color(&RED);
        root.titled(SMOKE_TEST_BANNER, banner).map_err(|e| fail(&e))?
    } else {
        root.clone()
    };
    let layouts: Vec<PanelLayout> = area
        .split_evenly((1, panels.len().max(1)))
        .iter()
        .zip(panels)
        .map(|(area, panel)| draw_panel(area, panel).map_err(|e| fail(&e)))
        .collect::<Result<_, _>>()?;
    root.present().map_err(|e| fail(&e))?;
    // A figure still worth having is kept, and what would mislead a reader is said.
    for problem in layouts.iter().flat_map(|l: &PanelLayout| l.problems((width, height))) {
        eprintln!("warning: the layout of {}: {problem}", path.display());
    }
    Ok(layouts)
}

type Area<'a> = DrawingArea<BitMapBackend<'a>, plotters::coord::Shift>;

/// A panel's frame around its plot, in pixels: the margin on every side, the title's and the
/// axes' label areas; and the fonts' sizes.
const MARGIN_PX: u32 = 12;
const X_LABELS_PX: u32 = 45;
const Y_LABELS_PX: u32 = 70;
const TITLE_PT: u32 = 20;
const LEGEND_PT: u32 = 14;
const NOTE_PT: u32 = 13;
/// Half the side of the box a marker takes, and the gap between a label and its point.
const MARKER_PX: i32 = 7;
const NOTE_GAP_PX: i32 = 5;

/// A rectangle in pixels: left, top, right, bottom.
pub type Rect = (i32, i32, i32, i32);

fn overlap(a: Rect, b: Rect) -> bool {
    a.0 < b.2 && b.0 < a.2 && a.1 < b.3 && b.1 < a.3
}

/// The top-left corner of each label of `sizes` beside its anchor: of ten places around it
/// (right, left, above, below, the diagonals, a row further up and down), the first inside `bounds` that covers no
/// label placed before, no marker and no error bar; where none is free, the one that covers the fewest.
fn place_labels(
    anchors: &[(i32, i32)],
    sizes: &[(u32, u32)],
    markers: &[(i32, i32)],
    bars: &[Rect],
    bounds: Rect,
) -> Vec<(i32, i32)> {
    let marker_boxes: Vec<Rect> = markers
        .iter()
        .map(|&(x, y)| (x - MARKER_PX, y - MARKER_PX, x + MARKER_PX, y + MARKER_PX))
        .chain(bars.iter().copied())
        .collect();
    let mut placed: Vec<Rect> = Vec::with_capacity(anchors.len());
    for (&(x, y), &(w, h)) in anchors.iter().zip(sizes) {
        let (w, h, g) = (w as i32, h as i32, MARKER_PX + NOTE_GAP_PX);
        // Beside, above, below, then the diagonals; then a row further up and down.
        let (up, down, up2, down2) = (y - g - h, y + g, y - g - 2 * h - 2, y + g + h + 2);
        let places = [
            (x + g, y - h / 2),
            (x - g - w, y - h / 2),
            (x - w / 2, up),
            (x - w / 2, down),
            (x + g, up),
            (x + g, down),
            (x - g - w, up),
            (x - g - w, down),
            (x - w / 2, up2),
            (x - w / 2, down2),
        ];
        let covered = |(left, top): (i32, i32)| {
            let r = (left, top, left + w, top + h);
            let outside = r.0 < bounds.0 || r.1 < bounds.1 || r.2 > bounds.2 || r.3 > bounds.3;
            usize::from(outside) * 1000 + placed.iter().chain(&marker_boxes).filter(|&&b| overlap(r, b)).count()
        };
        let best = places.into_iter().min_by_key(|&q| covered(q)).expect("ten places");
        placed.push((best.0, best.1, best.0 + w, best.1 + h));
    }
    placed.iter().map(|r| (r.0, r.1)).collect()
}

/// The legend's share of the plot's width and height: its longest label and its rows measured
/// in its font, with plotters' marker column and padding around them.
fn legend_share(area: &Area, p: &Panel) -> (f64, f64) {
    let (plot_w, plot_h) = plot_size(area);
    let font: TextStyle = ("sans-serif", LEGEND_PT).into();
    let (widest, tallest) = p
        .series
        .iter()
        .filter_map(|s| area.estimate_text_size(&s.label, &font).ok())
        .fold((0, 0), |(w, h), (tw, th)| (w.max(tw), h.max(th)));
    let rows = p.series.len() as u32;
    (
        (f64::from(widest + 50) / f64::from(plot_w)).min(1.0),
        (f64::from(rows * (tallest + 6) + 14) / f64::from(plot_h)).min(0.9),
    )
}

/// The plot's size inside a panel's frame, in pixels.
fn plot_size(area: &Area) -> (u32, u32) {
    let (w, h) = area.dim_in_pixel();
    (
        w.saturating_sub(2 * MARGIN_PX + Y_LABELS_PX).max(1),
        h.saturating_sub(2 * MARGIN_PX + X_LABELS_PX + 2 * TITLE_PT).max(1),
    )
}

/// The ranges widened, each about its middle, until a unit is as long on both axes of a plot
/// `w` by `h` pixels.
fn to_scale((x0, x1): (f64, f64), (y0, y1): (f64, f64), (w, h): (u32, u32)) -> ((f64, f64), (f64, f64)) {
    let per_px = ((x1 - x0) / f64::from(w)).max((y1 - y0) / f64::from(h));
    let about = |lo: f64, hi: f64, px: u32| {
        let (mid, half) = ((lo + hi) / 2.0, per_px * f64::from(px) / 2.0);
        (mid - half, mid + half)
    };
    (about(x0, x1, w), about(y0, y1, h))
}

/// Where `v` lies between `lo` and `hi` on the axis, 0 to 1.
fn fraction(v: f64, lo: f64, hi: f64, log: bool) -> f64 {
    if log {
        (v.ln() - lo.ln()) / (hi.ln() - lo.ln())
    } else {
        (v - lo) / (hi - lo)
    }
}

/// The corner for the legend that hides the fewest points and error bars' ends (upper right
/// unless data lie there), and how many it hides.
fn legend_corner(
    p: &Panel,
    (w, h): (f64, f64),
    (x0, x1): (f64, f64),
    (y0, y1): (f64, f64),
) -> (SeriesLabelPosition, usize) {
    let points: Vec<(f64, f64)> = p
        .series
        .iter()
        .flat_map(Series::reach)
        .map(|(x, y)| (fraction(x, x0, x1, false), fraction(y, y0, y1, p.log_y)))
        .collect();
    let hidden = |right: bool, upper: bool| {
        points
            .iter()
            .filter(|(x, y)| (if right { *x > 1.0 - w } else { *x < w }) && (if upper { *y > 1.0 - h } else { *y < h }))
            .count()
    };
    [
        (SeriesLabelPosition::UpperRight, true, true),
        (SeriesLabelPosition::UpperLeft, false, true),
        (SeriesLabelPosition::LowerRight, true, false),
        (SeriesLabelPosition::LowerLeft, false, false),
    ]
    .into_iter()
    .map(|(corner, right, upper)| (corner, hidden(right, upper)))
    .min_by_key(|(_, n)| *n)
    .unwrap_or((SeriesLabelPosition::UpperRight, 0))
}

/// The top of a y axis from `y0` to `y1` raised so that the legend's share `h` of its height
/// and a gap of 5 % lie above every point: where every corner has data, the legend goes over
/// empty room.
fn room_for_legend((y0, y1): (f64, f64), h: f64, log: bool) -> f64 {
    let scale = 1.0 / (1.0 - h - 0.05).max(0.05);
    if log {
        (y0.ln() + (y1.ln() - y0.ln()) * scale).exp()
    } else {
        y0 + (y1 - y0) * scale
    }
}

fn draw_panel(area: &Area, p: &Panel) -> Result<PanelLayout, Box<dyn std::error::Error>> {
    let mut layout = PanelLayout::default();
    let xs = p.series.iter().flat_map(Series::reach).map(|q| q.0);
    let (mut x0, mut x1) = range(xs, false);
    if !p.x_names.is_empty() {
        (x0, x1) = (-0.5, p.x_names.len() as f64 - 0.5);
    }
    let (mut y0, mut y1) = range(p.series.iter().flat_map(Series::reach).map(|q| q.1), p.log_y);
    if p.to_scale {
        ((x0, x1), (y0, y1)) = to_scale((x0, x1), (y0, y1), plot_size(area));
    }
    let share = legend_share(area, p);
    // A marker half under the legend is hidden too: its reach counts.
    let (plot_w, plot_h) = plot_size(area);
    let guarded = (
        share.0 + f64::from(MARKER_PX) / f64::from(plot_w),
        share.1 + f64::from(MARKER_PX) / f64::from(plot_h),
    );
    let (mut legend, hidden) = legend_corner(p, guarded, (x0, x1), (y0, y1));
    if hidden > 0 {
        y1 = room_for_legend((y0, y1), guarded.1, p.log_y);
        legend = SeriesLabelPosition::UpperRight;
    }
    let mut builder = ChartBuilder::on(area);
    builder
        .caption(&p.title, ("sans-serif", TITLE_PT))
        .margin(MARGIN_PX)
        .x_label_area_size(X_LABELS_PX)
        .y_label_area_size(Y_LABELS_PX);
    let names = p.x_names.clone();
    let x_fmt = move |x: &f64| {
        if names.is_empty() {
            tidy(*x)
        } else if (x - x.round()).abs() < 1e-6 {
            names.get(x.round() as usize).cloned().unwrap_or_default()
        } else {
            String::new()
        }
    };
    macro_rules! body {
        ($chart:expr) => {{
            let mut chart = $chart;
            let mut mesh = chart.configure_mesh();
            mesh.x_desc(&p.x_label)
                .y_desc(&p.y_label)
                .label_style(("sans-serif", 14))
                .axis_desc_style(("sans-serif", 16))
                .x_label_formatter(&x_fmt)
                .y_label_formatter(&|y: &f64| tidy(*y));
            if !p.x_names.is_empty() {
                mesh.x_labels(p.x_names.len() * 2 + 1);
            }
            mesh.draw()?;
            for s in &p.series {
                let colour = PALETTE[s.colour % PALETTE.len()];
                let style = ShapeStyle::from(&colour).stroke_width(2);
                let points = s.points.clone();
                let ring = ShapeStyle::from(&colour).stroke_width(2);
                let anno = match s.mark {
                    Mark::Line => chart.draw_series(LineSeries::new(points.clone(), style))?,
                    Mark::Dashed => chart.draw_series(DashedLineSeries::new(points.clone(), 8, 5, style))?,
                    Mark::Points => {
                        chart.draw_series(points.iter().map(|&q| TriangleMarker::new(q, 7, colour.filled())))?
                    }
                    Mark::Dots => chart.draw_series(points.iter().map(|&q| Circle::new(q, 6, colour.filled())))?,
                    Mark::Rings => chart.draw_series(points.iter().map(|&q| Circle::new(q, 6, ring)))?,
                };
                let anno = anno.label(&s.label);
                match s.mark {
                    Mark::Points => anno.legend(move |(x, y)| TriangleMarker::new((x + 10, y), 6, colour.filled())),
                    Mark::Dots => anno.legend(move |(x, y)| Circle::new((x + 10, y), 5, colour.filled())),
                    Mark::Rings => anno.legend(move |(x, y)| Circle::new((x + 10, y), 5, ring)),
                    Mark::Line => anno.legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], style)),
                    Mark::Dashed => anno.legend(move |(x, y)| {
                        EmptyElement::at((x, y))
                            + PathElement::new(vec![(0, 0), (7, 0)], style)
                            + PathElement::new(vec![(13, 0), (20, 0)], style)
                    }),
                };
                if s.mark.joined() && points.len() <= 40 {
                    chart.draw_series(points.iter().map(|&q| Circle::new(q, 3, colour.filled())))?;
                }
                if let Some(errors) = &s.errors {
                    chart.draw_series(
                        points.iter().zip(errors).map(|(&(x, y), &e)| {
                            ErrorBar::new_vertical(x, y - e, y, y + e, colour.stroke_width(2), 10)
                        }),
                    )?;
                }
                if let Some(errors) = &s.x_errors {
                    chart.draw_series(points.iter().zip(errors).map(|(&(x, y), &e)| {
                        ErrorBar::new_horizontal(y, x - e, x, x + e, colour.stroke_width(2), 10)
                    }))?;
                }
            }
            // Each label beside its point, where it covers no other label and no marker.
            let font: TextStyle = ("sans-serif", NOTE_PT).into();
            let anchors: Vec<(i32, i32)> = p.notes.iter().map(|(x, y, _)| chart.backend_coord(&(*x, *y))).collect();
            let markers: Vec<(i32, i32)> = p
                .series
                .iter()
                .flat_map(|s| s.points.iter().map(|q| chart.backend_coord(q)))
                .collect();
            let sizes: Vec<(u32, u32)> = p
                .notes
                .iter()
                .map(|(_, _, text)| area.estimate_text_size(text, &font))
                .collect::<Result<_, _>>()?;
            let (xs, ys) = chart.plotting_area().get_pixel_range();
            let plot = (xs.start, ys.start, xs.end, ys.end);
            // Error bars, as thin boxes a label should not cross.
            let bars: Vec<Rect> = p
                .series
                .iter()
                .flat_map(|s| {
                    s.points.iter().enumerate().flat_map(move |(i, &(x, y))| {
                        let e = s.errors.as_ref().map_or(0.0, |e| e[i]);
                        let f = s.x_errors.as_ref().map_or(0.0, |e| e[i]);
                        [((x, y - e), (x, y + e)), ((x - f, y), (x + f, y))]
                    })
                })
                .map(|(a, b)| {
                    let (a, b) = (chart.backend_coord(&a), chart.backend_coord(&b));
                    (a.0.min(b.0) - 2, a.1.min(b.1) - 2, a.0.max(b.0) + 2, a.1.max(b.1) + 2)
                })
                .collect();
            let placed = place_labels(&anchors, &sizes, &markers, &bars, plot);
            let base = area.get_base_pixel();
            for (((_, _, text), corner), &(w, h)) in p.notes.iter().zip(&placed).zip(&sizes) {
                area.draw(&Text::new(
                    text.clone(),
                    (corner.0 - base.0, corner.1 - base.1),
                    font.clone(),
                ))?;
                layout
                    .labels
                    .push((corner.0, corner.1, corner.0 + w as i32, corner.1 + h as i32));
            }
            // The legend's box as `legend_corner` reckons it.
            let (lw, lh) = (
                (share.0 * f64::from(plot.2 - plot.0)) as i32,
                (share.1 * f64::from(plot.3 - plot.1)) as i32,
            );
            let (right, upper) = match legend {
                SeriesLabelPosition::UpperLeft => (false, true),
                SeriesLabelPosition::LowerRight => (true, false),
                SeriesLabelPosition::LowerLeft => (false, false),
                _ => (true, true),
            };
            let left = if right { plot.2 - lw } else { plot.0 };
            let top = if upper { plot.1 } else { plot.3 - lh };
            layout.legend = (left, top, left + lw, top + lh);
            layout.plot = plot;
            layout.markers = markers;
            chart
                .configure_series_labels()
                .background_style(WHITE.mix(0.85))
                .border_style(BLACK)
                .label_font(("sans-serif", LEGEND_PT))
                .position(legend)
                .draw()?;
        }};
    }
    if p.log_y {
        // A hair beyond the decades, so that plotters labels the decades at both ends.
        body!(builder.build_cartesian_2d(x0..x1, (y0 * 0.97..y1 * 1.03).log_scale())?);
    } else {
        body!(builder.build_cartesian_2d(x0..x1, y0..y1)?);
    }
    Ok(layout)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A legend over 45 % of a plot's width and 35 % of its height.
    const SHARE: (f64, f64) = (0.45, 0.35);

    fn panel(points: Vec<(f64, f64)>) -> Panel {
        Panel {
            series: vec![Series::new("data", points, Mark::Line, 0)],
            ..Panel::default()
        }
    }

    #[test]
    fn the_legend_takes_a_corner_without_data() {
        let p = panel(vec![(0.0, 0.0), (1.0, 1.0)]);
        let (corner, hidden) = legend_corner(&p, SHARE, (0.0, 1.0), (0.0, 1.0));
        assert_eq!(hidden, 0);
        assert!(matches!(
            corner,
            SeriesLabelPosition::UpperLeft | SeriesLabelPosition::LowerRight
        ));
    }

    #[test]
    fn an_error_bar_reaching_into_a_corner_keeps_the_legend_out_of_it() {
        let mut p = panel(vec![(0.0, 0.0), (1.0, 0.5)]);
        assert_eq!(legend_corner(&p, SHARE, (0.0, 1.0), (0.0, 1.0)).1, 0);
        p.series[0].errors = Some(vec![0.0, 0.5]);
        let (corner, hidden) = legend_corner(&p, SHARE, (0.0, 1.0), (0.0, 1.0));
        assert_eq!(hidden, 0);
        assert!(!matches!(corner, SeriesLabelPosition::UpperRight));
    }

    #[test]
    fn axes_to_scale_give_a_metre_the_same_pixels_across_and_up_and_keep_every_point() {
        let ((x0, x1), (y0, y1)) = to_scale((0.0, 12.0), (-3.0, 3.0), (600, 500));
        assert!(((x1 - x0) / 600.0 - (y1 - y0) / 500.0).abs() < 1e-12);
        assert!(x0 <= 0.0 && x1 >= 12.0 && y0 <= -3.0 && y1 >= 3.0);
    }

    #[test]
    fn a_log_axis_takes_whole_decades_with_no_point_on_its_edge() {
        assert_eq!(range([0.001, 0.5].into_iter(), true), (1e-4, 1.0));
        assert_eq!(range([0.002, 2.4].into_iter(), true), (1e-3, 10.0));
    }

    #[test]
    fn a_tick_below_a_thousandth_keeps_its_value() {
        assert_eq!(tidy(0.0001), "1e-4");
        assert_eq!(tidy(0.001), "0.001");
        assert_eq!(tidy(2.5), "2.5");
        assert_eq!(tidy(0.0), "0");
        assert_eq!(tidy(-2.7e-17), "0", "a zero tick with a rounding error");
    }

    #[test]
    fn labels_beside_crowded_points_cover_no_other_label_and_no_marker() {
        // Six points in a tight row, with room around: each label finds a free place.
        let anchors: Vec<(i32, i32)> = (0..6).map(|i| (100 + 25 * i, 200 + 6 * (i % 2))).collect();
        let sizes = vec![(60, 14); anchors.len()];
        let bounds = (0, 0, 600, 400);
        let placed = place_labels(&anchors, &sizes, &anchors, &[], bounds);
        let rects: Vec<Rect> = placed.iter().map(|&(x, y)| (x, y, x + 60, y + 14)).collect();
        for (i, r) in rects.iter().enumerate() {
            assert!(r.0 >= 0 && r.1 >= 0 && r.2 <= 600 && r.3 <= 400, "label {i} inside");
            for other in &rects[..i] {
                assert!(!overlap(*r, *other), "label {i} covers another");
            }
            for &(x, y) in &anchors {
                assert!(!overlap(
                    *r,
                    (x - MARKER_PX, y - MARKER_PX, x + MARKER_PX, y + MARKER_PX)
                ));
            }
        }
        // A horizontal error bar through a point sends its label above or below it.
        let bar = (40, 198, 160, 202);
        let over_bar = place_labels(&[(100, 200)], &[(60, 14)], &[(100, 200)], &[bar], bounds);
        assert!(!overlap(
            (over_bar[0].0, over_bar[0].1, over_bar[0].0 + 60, over_bar[0].1 + 14),
            bar
        ));
        // A point at the right edge is labelled on its left.
        let edge = place_labels(&[(590, 200)], &[(60, 14)], &[], &[], bounds);
        assert!(edge[0].0 + 60 <= 590);
    }

    #[test]
    fn a_layout_with_a_label_on_a_marker_or_off_the_figure_is_named() {
        let good = PanelLayout {
            plot: (50, 50, 550, 350),
            legend: (400, 50, 550, 120),
            labels: vec![(112, 190, 170, 204)],
            markers: vec![(100, 200)],
        };
        assert!(good.problems((600, 400)).is_empty(), "{:?}", good.problems((600, 400)));
        let on_marker = PanelLayout {
            labels: vec![(95, 195, 150, 209)],
            ..good.clone()
        };
        assert_eq!(on_marker.problems((600, 400)).len(), 1);
        let outside = PanelLayout {
            labels: vec![(580, 10, 640, 24)],
            ..good.clone()
        };
        assert_eq!(outside.problems((600, 400)).len(), 1);
        let legend_on_data = PanelLayout {
            markers: vec![(100, 200), (500, 80)],
            ..good
        };
        assert_eq!(legend_on_data.problems((600, 400)).len(), 1);
    }

    #[test]
    fn where_every_corner_has_data_the_axis_grows_until_the_legend_hides_none() {
        for (log, (lo, hi)) in [(false, (0.0, 1.0)), (true, (0.1, 10.0))] {
            let p = Panel {
                log_y: log,
                ..panel(vec![(0.0, lo), (1.0, hi), (0.0, hi), (1.0, lo)])
            };
            assert!(legend_corner(&p, SHARE, (0.0, 1.0), (lo, hi)).1 > 0);
            let grown = room_for_legend((lo, hi), SHARE.1, log);
            let (corner, hidden) = legend_corner(&p, SHARE, (0.0, 1.0), (lo, grown));
            assert_eq!(hidden, 0, "log axis: {log}");
            assert!(matches!(corner, SeriesLabelPosition::UpperRight));
        }
    }
}
