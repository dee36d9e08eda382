//! The points of a sweep: per evolved stage, the median chosen best over the
//! seeds of each point, with its min–max range as a bar.

use plotters::coord::Shift;
use plotters::prelude::*;

use super::render::{self, palette, span, DrawResult, Figure};
use super::series::line_chart_labelled;
use super::SweepSeries;

const SIZE: (u32, u32) = (1000, 600);

pub(super) struct Points<'a> {
    pub title: &'a str,
    pub points: usize,
    pub series: &'a [SweepSeries],
    /// What the points set (the x axis's name), and what each point sets,
    /// in order (its tick).
    pub axis: &'a str,
    pub labels: &'a [String],
}

impl Figure for Points<'_> {
    fn size(&self, _text: bool) -> (u32, u32) {
        SIZE
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>, text: bool) -> DrawResult<DB> {
        let area = render::title_strip(root, self.title, text)?;
        let values = self.series.iter().flat_map(|s| s.values.iter().flatten().flat_map(|v| [v.1, v.2]));
        let y = span(values.chain([0.0]), 0.06, (0.0, 1.0));
        let x = (0.5, self.points as f64 + 0.5);
        // Each point named by its values, at whole x only.
        let name = |x: &f64| {
            let i = x.round();
            if (x - i).abs() > 1e-6 || i < 1.0 {
                return String::new();
            }
            self.labels.get(i as usize - 1).cloned().unwrap_or_default()
        };
        let axis = (self.axis, self.points.min(12), &name as &dyn Fn(&f64) -> String);
        let mut chart = line_chart_labelled(&area, x, y, text, axis, "chosen best")?;
        let n = self.series.len().max(1) as f64;
        for (k, s) in self.series.iter().enumerate() {
            let c = palette(k);
            // Side by side within a point, so the bars of the stages do not overlap.
            let dx = (k as f64 - (n - 1.0) / 2.0) * 0.12;
            let at = |i: usize| i as f64 + 1.0 + dx;
            for (i, v) in s.values.iter().enumerate() {
                if let Some((_, lo, hi)) = *v {
                    chart.draw_series(std::iter::once(PathElement::new(
                        vec![(at(i), lo), (at(i), hi)],
                        c.stroke_width(2),
                    )))?;
                }
            }
            let medians: Vec<(f64, f64)> =
                s.values.iter().enumerate().filter_map(|(i, v)| v.map(|v| (at(i), v.0))).collect();
            chart.draw_series(LineSeries::new(medians.clone(), c.mix(0.5).stroke_width(1)))?;
            let a = chart.draw_series(medians.into_iter().map(|p| Circle::new(p, 5, c.filled())))?;
            if text {
                a.label(format!("{}: median, min–max over seeds", s.stage))
                    .legend(move |(x, y)| Circle::new((x + 10, y), 5, c.filled()));
            }
        }
        if text {
            render::series_legend(&mut chart)?;
        }
        Ok(())
    }
}
