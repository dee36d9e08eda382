//! Module activations over one test run (figure 11): one band per module,
//! filled where the module wins, plus the battery level and the object held.

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::render::{self, palette, DrawResult, Figure, INK, TITLE_H};
use super::ActivationTrace;

const BAND: u32 = 56;
const WIDTH: u32 = 1200;
const X_LABEL_H: u32 = 52;
const MARGIN_TOP: u32 = 8;
const MARGIN_BOTTOM: u32 = 14;
const BATTERY: RGBColor = RGBColor(60, 150, 60);

/// Checks that the trace's columns agree; the message names the mismatch.
pub(super) fn check(t: &ActivationTrace) -> Result<(), String> {
    let n = t.activations.len();
    if n == 0 {
        return Err("the trace has no actions".into());
    }
    if let Some((i, row)) = t.activations.iter().enumerate().find(|(_, r)| r.len() != t.modules.len()) {
        return Err(format!(
            "action {i} has {} activations but there are {} modules",
            row.len(),
            t.modules.len()
        ));
    }
    if t.winner.len() != n {
        return Err(format!("`winner` has {} actions but `activations` has {n}", t.winner.len()));
    }
    if !t.battery.is_empty() && t.battery.len() != n {
        return Err(format!("`battery` has {} actions but `activations` has {n}", t.battery.len()));
    }
    if !t.holding.is_empty() && t.holding.len() != n {
        return Err(format!("`holding` has {} actions but `activations` has {n}", t.holding.len()));
    }
    Ok(())
}

pub(super) struct Trace<'a> {
    pub title: &'a str,
    pub t: &'a ActivationTrace,
}

impl Trace<'_> {
    /// Width of the band names at the left: a generous guess from the
    /// longest name (about 9 px per character at 15 px), within 90..=300.
    fn label_w(&self) -> u32 {
        let longest = self.t.modules.iter().map(|m| m.chars().count()).chain([11]).max().unwrap_or(11);
        (longest as u32).saturating_mul(9).saturating_add(24).clamp(90, 300)
    }

    fn bands(&self) -> usize {
        self.t.modules.len()
            + usize::from(!self.t.battery.is_empty())
            + usize::from(!self.t.holding.is_empty())
    }
}

/// Consecutive index runs `[start, end]` where `f` holds.
fn index_runs(n: usize, f: impl Fn(usize) -> bool) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let mut start = None;
    for i in 0..n {
        match (f(i), start) {
            (true, None) => start = Some(i),
            (false, Some(s)) => {
                out.push((s, i - 1));
                start = None;
            }
            _ => {}
        }
    }
    if let Some(s) = start {
        out.push((s, n - 1));
    }
    out
}

fn level(v: f32) -> f64 {
    if v.is_finite() {
        f64::from(v).clamp(0.0, 1.0)
    } else {
        0.0
    }
}

/// A step-shaped filled area from `lo` up to `lo + h * value(i)` over `[s, e]`.
fn step_area(s: usize, e: usize, lo: f64, h: f64, value: impl Fn(usize) -> f64) -> Vec<(f64, f64)> {
    let mut poly = vec![(s as f64 - 0.5, lo)];
    for i in s..=e {
        let y = lo + h * value(i);
        poly.push((i as f64 - 0.5, y));
        poly.push((i as f64 + 0.5, y));
    }
    poly.push((e as f64 + 0.5, lo));
    poly
}

impl Figure for Trace<'_> {
    fn size(&self, text: bool) -> (u32, u32) {
        let labels = if text { X_LABEL_H } else { 0 };
        (WIDTH, TITLE_H + MARGIN_TOP + BAND * self.bands() as u32 + labels + MARGIN_BOTTOM)
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>, text: bool) -> DrawResult<DB> {
        let t = self.t;
        let area = render::title_strip(root, self.title, text)?;
        let n = t.activations.len();
        let nb = self.bands();
        let mut chart = ChartBuilder::on(&area)
            .margin_left(16)
            .margin_right(34)
            .margin_top(MARGIN_TOP)
            .margin_bottom(MARGIN_BOTTOM)
            .x_label_area_size(if text { X_LABEL_H } else { 0 })
            .y_label_area_size(if text { self.label_w() } else { 0 })
            .build_cartesian_2d(-0.5..(n as f64 - 0.5), 0.0..nb as f64)?;
        let mut mesh = chart.configure_mesh();
        mesh.disable_y_mesh()
            .disable_y_axis()
            .bold_line_style(render::GRID_BOLD)
            .light_line_style(render::GRID_LIGHT)
            .axis_style(INK)
            .x_labels(12)
            .x_label_formatter(&render::tick);
        if text {
            mesh.label_style(render::label_style(15.0))
                .axis_desc_style(render::label_style(17.0))
                .x_desc("action   (filled: the module controls the robot)");
        } else {
            mesh.disable_x_axis();
        }
        mesh.draw()?;

        let x0 = -0.5;
        let x1 = n as f64 - 0.5;
        // Band k counted from the top spans rows [nb-k-1, nb-k]; returns (bottom, height).
        let band = |k: usize| ((nb - k - 1) as f64 + 0.14, 0.76);
        let mut names: Vec<(String, RGBColor)> = Vec::with_capacity(nb);
        let mut k = 0;

        if !t.battery.is_empty() {
            let (lo, h) = band(k);
            chart.draw_series(std::iter::once(Rectangle::new(
                [(x0, lo), (x1, lo + h)],
                RGBColor(247, 247, 247).filled(),
            )))?;
            let line: Vec<(f64, f64)> =
                t.battery.iter().enumerate().map(|(i, &b)| (i as f64, lo + h * level(b))).collect();
            let mut poly = vec![(0.0, lo)];
            poly.extend(line.iter().copied());
            poly.push(((n - 1) as f64, lo));
            chart.draw_series(std::iter::once(Polygon::new(poly, BATTERY.mix(0.25).filled())))?;
            chart.draw_series(LineSeries::new(line, BATTERY.stroke_width(2)))?;
            names.push(("battery".into(), BATTERY));
            k += 1;
        }

        for (m, name) in t.modules.iter().enumerate() {
            let (lo, h) = band(k);
            let c = palette(m);
            let act = |i: usize| level(t.activations[i][m]);
            chart.draw_series(std::iter::once(Rectangle::new(
                [(x0, lo), (x1, lo + h)],
                RGBColor(247, 247, 247).filled(),
            )))?;
            for (s, e) in index_runs(n, |i| usize::from(t.winner[i]) == m) {
                let tint =
                    Rectangle::new([(s as f64 - 0.5, lo), (e as f64 + 0.5, lo + h)], c.mix(0.16).filled());
                chart.draw_series(std::iter::once(tint))?;
                chart.draw_series(std::iter::once(Polygon::new(
                    step_area(s, e, lo, h, act),
                    c.mix(0.85).filled(),
                )))?;
            }
            let line: Vec<(f64, f64)> = (0..n).map(|i| (i as f64, lo + h * act(i))).collect();
            chart.draw_series(LineSeries::new(line, c.stroke_width(1)))?;
            names.push((name.clone(), c));
            k += 1;
        }

        if !t.holding.is_empty() {
            let (lo, h) = band(k);
            chart.draw_series(std::iter::once(Rectangle::new(
                [(x0, lo), (x1, lo + h)],
                RGBColor(247, 247, 247).filled(),
            )))?;
            for (s, e) in index_runs(n, |i| t.holding[i]) {
                let r = Rectangle::new(
                    [(s as f64 - 0.5, lo), (e as f64 + 0.5, lo + h * 0.6)],
                    INK.mix(0.7).filled(),
                );
                chart.draw_series(std::iter::once(r))?;
            }
            names.push(("object held".into(), INK));
        }

        if text {
            for (k, (name, c)) in names.iter().enumerate() {
                let (lo, h) = band(k);
                let (px, py) = chart.backend_coord(&(x0, lo + h / 2.0));
                let style = render::label_style(15.0).pos(Pos::new(HPos::Right, VPos::Center)).color(c);
                root.draw_text(name, &style, (px - 10, py))?;
            }
        }
        Ok(())
    }
}
