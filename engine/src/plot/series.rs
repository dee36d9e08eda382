//! Line charts over an index: shared chart setup, vertical marks, and the
//! rolling reinforcement picture (figures 5, 10 and 13).

use plotters::chart::SeriesAnno;
use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::render::{self, palette, runs, span, DrawResult, Figure, DASHED, DOTTED, LIGHT_MARK, MARK};

pub(super) type Chart<'a, DB> = ChartContext<'a, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

/// Trailing rolling mean over `window` values, same length as the input.
/// The first values average what is there so far; non-finite values are
/// skipped, and a window with no finite value gives NaN. A window of 0 is
/// taken as 1.
pub fn rolling_mean(values: &[f32], window: usize) -> Vec<f32> {
    let window = window.max(1);
    let (mut sum, mut n) = (0.0f64, 0usize);
    let mut out = Vec::with_capacity(values.len());
    for (i, &v) in values.iter().enumerate() {
        if v.is_finite() {
            sum += f64::from(v);
            n += 1;
        }
        if i >= window {
            let old = values[i - window];
            if old.is_finite() {
                sum -= f64::from(old);
                n -= 1;
            }
        }
        out.push(if n == 0 { f32::NAN } else { (sum / n as f64) as f32 });
    }
    out
}

/// Median of a slice of finite values (NaN for an empty one): the engine's
/// one median, `stats::median`.
pub(super) fn median(values: &[f64]) -> f64 {
    crate::stats::median(values).unwrap_or(f64::NAN)
}

/// A Cartesian chart with light grid, tick labels and axis names (when text
/// is drawn).
pub(super) fn line_chart<'a, DB: DrawingBackend>(
    area: &'a DrawingArea<DB, Shift>,
    x: (f64, f64),
    y: (f64, f64),
    text: bool,
    x_desc: &str,
    y_desc: &str,
) -> Result<Chart<'a, DB>, DrawingAreaErrorKind<DB::ErrorType>> {
    line_chart_labelled(area, x, y, text, (x_desc, 10, &render::tick), y_desc)
}

/// The x axis of a chart: its name, about how many ticks, and their labels.
pub(super) type XAxis<'f> = (&'f str, usize, &'f dyn Fn(&f64) -> String);

/// [`line_chart`] with the x axis's ticks (about `x_axis.1` of them) named
/// by `x_axis.2`.
pub(super) fn line_chart_labelled<'a, DB: DrawingBackend>(
    area: &'a DrawingArea<DB, Shift>,
    x: (f64, f64),
    y: (f64, f64),
    text: bool,
    x_axis: XAxis<'_>,
    y_desc: &str,
) -> Result<Chart<'a, DB>, DrawingAreaErrorKind<DB::ErrorType>> {
    let (x_desc, x_ticks, x_label) = x_axis;
    let mut chart = ChartBuilder::on(area)
        .margin_left(16)
        .margin_right(34)
        .margin_top(8)
        .margin_bottom(14)
        .x_label_area_size(if text { 52 } else { 0 })
        .y_label_area_size(if text { 78 } else { 0 })
        .build_cartesian_2d(x.0..x.1, y.0..y.1)?;
    let mut mesh = chart.configure_mesh();
    mesh.bold_line_style(render::GRID_BOLD)
        .light_line_style(render::GRID_LIGHT)
        .axis_style(render::INK)
        .x_labels(x_ticks)
        .y_labels(8)
        .x_label_formatter(x_label)
        .y_label_formatter(&render::tick);
    if text {
        mesh.label_style(render::label_style(15.0))
            .axis_desc_style(render::label_style(17.0))
            .x_desc(x_desc)
            .y_desc(y_desc);
    } else {
        mesh.disable_x_axis().disable_y_axis();
    }
    mesh.draw()?;
    Ok(chart)
}

/// A line through `run`, or a dot when it has a single point.
pub(super) fn draw_run<'a, 'c, DB: DrawingBackend + 'a>(
    chart: &'c mut Chart<'a, DB>,
    run: Vec<(f64, f64)>,
    style: ShapeStyle,
) -> Result<&'c mut SeriesAnno<'a, DB>, DrawingAreaErrorKind<DB::ErrorType>> {
    if let [p] = run[..] {
        let r = style.stroke_width + 1;
        chart.draw_series(std::iter::once(Circle::new(p, r, style.filled())))
    } else {
        chart.draw_series(LineSeries::new(run, style))
    }
}

/// A labelled vertical line at `x`.
pub(super) struct MarkLine<'a> {
    pub x: f64,
    pub label: &'a str,
}

/// Dashed vertical lines across the plot with their label at the top,
/// drawn in backend pixels on the unsplit `root`; a mark with an empty label
/// is a light dotted line (the start of a life within a test stage's world).
pub(super) fn marks<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    chart: &Chart<'_, DB>,
    marks: &[MarkLine<'_>],
    text: bool,
) -> DrawResult<DB> {
    let (x0, x1) = (chart.x_range().start, chart.x_range().end);
    let (y0, y1) = (chart.y_range().start, chart.y_range().end);
    let right_edge = chart.backend_coord(&(x1, y1)).0;
    let left = render::label_style(14.0).pos(Pos::new(HPos::Left, VPos::Top)).color(&MARK);
    let right = render::label_style(14.0).pos(Pos::new(HPos::Right, VPos::Top)).color(&MARK);
    for m in marks.iter().filter(|m| m.x.is_finite() && m.x >= x0 && m.x <= x1) {
        let top = chart.backend_coord(&(m.x, y1));
        let bottom = chart.backend_coord(&(m.x, y0));
        if m.label.is_empty() {
            render::draw_dashed(root, &[top, bottom], &DOTTED, LIGHT_MARK.stroke_width(1))?;
            continue;
        }
        render::draw_dashed(root, &[top, bottom], &DASHED, MARK.stroke_width(2))?;
        if text {
            // Put the label left of the line when it would run past the plot.
            let (w, _) = root.estimate_text_size(m.label, &left)?;
            if top.0 + 6 + w as i32 > right_edge {
                root.draw_text(m.label, &right, (top.0 - 6, top.1 + 6))?;
            } else {
                root.draw_text(m.label, &left, (top.0 + 6, top.1 + 6))?;
            }
        }
    }
    Ok(())
}

pub(super) struct Reinforcement<'a> {
    pub title: &'a str,
    pub series: &'a [(String, Vec<f32>)],
    pub window: usize,
    pub marks: &'a [(u32, String)],
}

impl Figure for Reinforcement<'_> {
    fn size(&self, _text: bool) -> (u32, u32) {
        (1000, 560)
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>, text: bool) -> DrawResult<DB> {
        let area = render::title_strip(root, self.title, text)?;
        let len = self.series.iter().map(|s| s.1.len()).max().unwrap_or(0);
        let marks_x = self.marks.iter().map(|m| f64::from(m.0));
        let x = span([0.0, len.saturating_sub(1) as f64].into_iter().chain(marks_x), 0.0, (0.0, 1.0));
        let y_desc = if self.window > 1 {
            format!("reinforcement (rolling mean over {} actions)", self.window)
        } else {
            "reinforcement".to_string()
        };
        let mut chart = line_chart(&area, x, (-1.0, 1.0), text, "action", &y_desc)?;
        chart.draw_series(std::iter::once(PathElement::new(
            vec![(x.0, 0.0), (x.1, 0.0)],
            render::INK.stroke_width(1),
        )))?;
        let lines: Vec<MarkLine<'_>> = self
            .marks
            .iter()
            .map(|(x, label)| MarkLine { x: f64::from(*x), label: label.as_str() })
            .collect();
        marks(root, &chart, &lines, text)?;

        for (k, (name, values)) in self.series.iter().enumerate() {
            let c = palette(k);
            let smooth = rolling_mean(values, self.window);
            // Only full windows, unless the series is shorter than one window.
            let skip = if values.len() >= self.window { self.window - 1 } else { 0 };
            let pts = smooth
                .iter()
                .enumerate()
                .skip(skip)
                .map(|(i, &v)| render::fin(v).map(|v| (i as f64, v.clamp(-1.0, 1.0))));
            for (i, run) in runs(pts).into_iter().enumerate() {
                let s = draw_run(&mut chart, run, c.stroke_width(2))?;
                if i == 0 && text && !name.is_empty() {
                    s.label(name.as_str())
                        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], c.stroke_width(3)));
                }
            }
        }
        if text && self.series.iter().any(|s| !s.0.is_empty()) {
            render::series_legend(&mut chart)?;
        }
        Ok(())
    }
}
