//! Fitness per generation: one run (figures 4 and 9) or several seeds.

use std::collections::BTreeMap;

use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::element::EmptyElement;
use plotters::prelude::*;

use super::render::{self, fin, palette, runs, span, DrawResult, Figure, DASH_DOT};
use super::series::{draw_run, line_chart, marks, median, rolling_mean, MarkLine};
use super::GenPoint;

const SIZE: (u32, u32) = (1000, 600);

pub(super) struct Single<'a> {
    pub title: &'a str,
    pub gens: &'a [GenPoint],
    pub stages: &'a [(u32, String)],
    pub smooth: bool,
}

pub(super) struct Multi<'a> {
    pub title: &'a str,
    pub runs: &'a [Vec<GenPoint>],
    pub stages: &'a [(u32, String)],
}

fn best_colour() -> RGBColor {
    palette(0)
}

fn mean_colour() -> RGBColor {
    palette(1)
}

/// A legend glyph of the dash-dot line in colour `$c`.
macro_rules! dash_dot_glyph {
    ($c:expr) => {{
        let s = $c.stroke_width(2);
        move |(x, y): (i32, i32)| {
            EmptyElement::at((x, y))
                + PathElement::new(vec![(0, 0), (9, 0)], s)
                + PathElement::new(vec![(12, 0), (14, 0)], s)
                + PathElement::new(vec![(17, 0), (20, 0)], s)
        }
    }};
}

/// A legend glyph of a solid line in colour `$c`, `$w` pixels wide.
macro_rules! line_glyph {
    ($c:expr, $w:expr) => {{
        let s = $c.stroke_width($w);
        move |(x, y): (i32, i32)| PathElement::new(vec![(x, y), (x + 20, y)], s)
    }};
}

/// Draws a dash-dotted line through data points (pixel-space dashes).
fn dash_dot_line<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    chart: &ChartContext<'_, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>,
    pts: &[(f64, f64)],
    colour: RGBColor,
) -> DrawResult<DB> {
    let px: Vec<(i32, i32)> = pts.iter().map(|p| chart.backend_coord(p)).collect();
    render::draw_dashed(root, &px, &DASH_DOT, colour.stroke_width(2))
}

fn stage_marks(stages: &[(u32, String)]) -> Vec<MarkLine<'_>> {
    stages.iter().map(|(g, name)| MarkLine { x: f64::from(*g), label: name }).collect()
}

impl Figure for Single<'_> {
    fn size(&self, _text: bool) -> (u32, u32) {
        SIZE
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>, text: bool) -> DrawResult<DB> {
        let area = render::title_strip(root, self.title, text)?;
        let mut gens = self.gens.to_vec();
        gens.sort_by_key(|g| g.generation);
        let xs: Vec<f64> = gens.iter().map(|g| f64::from(g.generation)).collect();
        let (mut best, mut mean): (Vec<f32>, Vec<f32>) = gens.iter().map(|g| (g.best, g.mean)).unzip();
        if self.smooth {
            best = rolling_mean(&best, 3);
            mean = rolling_mean(&mean, 3);
        }
        let pts = |v: &[f32]| runs(xs.iter().zip(v).map(|(&x, &y)| fin(y).map(|y| (x, y))));
        let (best, mean) = (pts(&best), pts(&mean));

        let x = span(xs.iter().copied().chain(self.stages.iter().map(|s| f64::from(s.0))), 0.0, (0.0, 1.0));
        let ys = best.iter().chain(&mean).flatten().map(|p| p.1).chain([0.0]);
        let y = span(ys, 0.06, (0.0, 1.0));
        let y_desc = if self.smooth { "fitness (rolling mean over 3 generations)" } else { "fitness" };
        let mut chart = line_chart(&area, x, y, text, "generation", y_desc)?;

        marks(root, &chart, &stage_marks(self.stages), text)?;
        for (i, run) in best.iter().enumerate() {
            let s = draw_run(&mut chart, run.clone(), best_colour().stroke_width(3))?;
            if i == 0 && text {
                s.label("best individual").legend(line_glyph!(best_colour(), 3));
            }
        }
        for run in &mean {
            if let [p] = run[..] {
                chart.draw_series(std::iter::once(Circle::new(p, 3, mean_colour().filled())))?;
            }
            dash_dot_line(root, &chart, run, mean_colour())?;
        }
        if text {
            if !mean.is_empty() {
                chart
                    .draw_series(LineSeries::new(std::iter::empty(), mean_colour()))?
                    .label("population mean")
                    .legend(dash_dot_glyph!(mean_colour()));
            }
            render::series_legend(&mut chart)?;
        }
        Ok(())
    }
}

/// Per generation: (median, min, max) of best and of mean over the runs that have it.
type Summary = (f64, [(f64, f64, f64); 2]);

fn summarise(runs: &[Vec<GenPoint>]) -> (Vec<Summary>, usize) {
    let mut by_gen: BTreeMap<u32, [Vec<f64>; 2]> = BTreeMap::new();
    let mut seeds = 0;
    for run in runs.iter().filter(|r| !r.is_empty()) {
        seeds += 1;
        for g in run {
            let e = by_gen.entry(g.generation).or_default();
            if let Some(b) = fin(g.best) {
                e[0].push(b);
            }
            if let Some(m) = fin(g.mean) {
                e[1].push(m);
            }
        }
    }
    let out = by_gen
        .into_iter()
        .filter(|(_, v)| !v[0].is_empty() && !v[1].is_empty())
        .map(|(g, v)| {
            let stat = |s: &[f64]| {
                let lo = s.iter().copied().fold(f64::INFINITY, f64::min);
                let hi = s.iter().copied().fold(f64::NEG_INFINITY, f64::max);
                (median(s), lo, hi)
            };
            (f64::from(g), [stat(&v[0]), stat(&v[1])])
        })
        .collect();
    (out, seeds)
}

impl Figure for Multi<'_> {
    fn size(&self, _text: bool) -> (u32, u32) {
        SIZE
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>, text: bool) -> DrawResult<DB> {
        let area = render::title_strip(root, self.title, text)?;
        let (sum, seeds) = summarise(self.runs);
        let x =
            span(sum.iter().map(|s| s.0).chain(self.stages.iter().map(|s| f64::from(s.0))), 0.0, (0.0, 1.0));
        let ys = sum.iter().flat_map(|s| [s.1[0].1, s.1[0].2, s.1[1].1, s.1[1].2]).chain([0.0]);
        let y = span(ys, 0.06, (0.0, 1.0));
        let mut chart = line_chart(&area, x, y, text, "generation", "fitness")?;
        marks(root, &chart, &stage_marks(self.stages), text)?;

        let names = [("best", best_colour()), ("mean", mean_colour())];
        for (k, (name, c)) in names.into_iter().enumerate().filter(|_| !sum.is_empty()) {
            let mut poly: Vec<(f64, f64)> = sum.iter().map(|s| (s.0, s.1[k].2)).collect();
            poly.extend(sum.iter().rev().map(|s| (s.0, s.1[k].1)));
            let a = chart.draw_series(std::iter::once(Polygon::new(poly, c.mix(0.18).filled())))?;
            if text {
                a.label(format!("{name}: min–max over {seeds} seeds")).legend(move |(x, y)| {
                    Rectangle::new([(x, y - 5), (x + 20, y + 5)], c.mix(0.25).filled())
                });
            }
        }
        let best: Vec<(f64, f64)> = sum.iter().map(|s| (s.0, s.1[0].0)).collect();
        let mean: Vec<(f64, f64)> = sum.iter().map(|s| (s.0, s.1[1].0)).collect();
        let s = chart.draw_series(LineSeries::new(best, best_colour().stroke_width(3)))?;
        if text {
            s.label("best individual: median").legend(line_glyph!(best_colour(), 3));
        }
        dash_dot_line(root, &chart, &mean, mean_colour())?;
        if text {
            chart
                .draw_series(LineSeries::new(std::iter::empty(), mean_colour()))?
                .label("population mean: median")
                .legend(dash_dot_glyph!(mean_colour()));
            render::series_legend(&mut chart)?;
        }
        Ok(())
    }
}
