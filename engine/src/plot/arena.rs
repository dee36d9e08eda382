//! Top view of the arena to scale with the robot's path.

use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::element::EmptyElement;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::render::{self, palette, ramp, DrawResult, Figure, INK, TITLE_H};
use super::TrajectoryScene;

/// Largest side of the arena view, pixels.
const MAX_PX: f64 = 640.0;
const MARGIN: u32 = 16;
const Y_LABEL_W: u32 = 64;
const X_LABEL_H: u32 = 48;
const LEGEND_W: u32 = 250;
/// Empty border around everything drawn, mm.
const PAD_MM: f64 = 12.0;

const FLOOR: RGBColor = RGBColor(252, 251, 246);
const BAR: RGBColor = RGBColor(70, 90, 115);
const CYLINDER: RGBColor = RGBColor(90, 90, 90);
const LAMP: RGBColor = RGBColor(255, 200, 0);
const OBJECT: RGBColor = RGBColor(200, 80, 40);
const VIRTUAL: RGBColor = RGBColor(148, 103, 189);
const COLLECTED: RGBColor = RGBColor(175, 175, 175);
const HEADING: RGBColor = RGBColor(214, 39, 40);
/// Number of colour steps along time; consecutive segments of one step are one line.
const TIME_STEPS: usize = 64;

/// Checks that the scene can be drawn; the message names the bad value.
pub(super) fn check(s: &TrajectoryScene) -> Result<(), String> {
    let finite = |v: &[f32]| v.iter().all(|x| x.is_finite());
    if !finite(&s.arena) || s.arena[0] <= 0.0 || s.arena[1] <= 0.0 {
        return Err(format!("the arena size must be positive, not {:?}", s.arena));
    }
    if !s.body_radius.is_finite() || s.body_radius < 0.0 {
        return Err(format!("the body radius must be a non-negative number, not {}", s.body_radius));
    }
    if let Some((a, b)) = s.bar {
        if !finite(&a) || !finite(&b) {
            return Err("the charger bar has a non-finite end".into());
        }
    }
    if s.lamp.is_some_and(|l| !finite(&l)) || s.lamps.iter().any(|l| !finite(l)) {
        return Err("a lamp has a non-finite position".into());
    }
    if s.walls.iter().any(|(a, b)| !finite(a) || !finite(b)) {
        return Err("an inner wall has a non-finite end".into());
    }
    if s.cylinders.iter().any(|c| !finite(c) || c[2] < 0.0) {
        return Err("a cylinder has a non-finite position or a bad radius".into());
    }
    if s.zones.iter().any(|(a, b, g, _)| !finite(a) || !finite(b) || !(0.0..=1.0).contains(g)) {
        return Err("a floor zone has a non-finite corner or a grey level outside 0..1".into());
    }
    if let Some(i) = s.objects.iter().position(|o| !finite(&[o.x, o.y, o.radius]) || o.radius < 0.0) {
        return Err(format!("object {i} has a non-finite position or a bad radius"));
    }
    if let Some(i) = s.path.iter().position(|p| !finite(p)) {
        return Err(format!("path point {i} is not finite"));
    }
    for (k, path) in s.others.iter().enumerate() {
        if let Some(i) = path.iter().position(|p| !finite(p)) {
            return Err(format!("point {i} of robot {}'s path is not finite", k + 1));
        }
    }
    if let Some(m) = &s.path_modules {
        if m.len() != s.path.len() {
            return Err(format!(
                "`path_modules` has {} entries but the path has {} points",
                m.len(),
                s.path.len()
            ));
        }
    }
    if let Some((i, label)) = s.marks.iter().find(|(i, _)| *i >= s.path.len()) {
        return Err(format!("mark `{label}` is at path index {i} but the path has {} points", s.path.len()));
    }
    Ok(())
}

pub(super) struct Arena<'a> {
    title: &'a str,
    s: &'a TrajectoryScene,
    /// Shown region, mm: x0, x1, y0, y1.
    view: [f64; 4],
}

impl<'a> Arena<'a> {
    pub(super) fn new(title: &'a str, s: &'a TrajectoryScene) -> Arena<'a> {
        let mut v = [0.0, f64::from(s.arena[0]), 0.0, f64::from(s.arena[1])];
        let mut cover = |x: f64, y: f64, r: f64| {
            v[0] = v[0].min(x - r);
            v[1] = v[1].max(x + r);
            v[2] = v[2].min(y - r);
            v[3] = v[3].max(y + r);
        };
        for o in &s.objects {
            cover(f64::from(o.x), f64::from(o.y), f64::from(o.radius));
        }
        for p in s.path.iter().chain(s.others.iter().flatten()) {
            cover(f64::from(p[0]), f64::from(p[1]), f64::from(s.body_radius));
        }
        if let Some((a, b)) = s.bar {
            cover(f64::from(a[0]), f64::from(a[1]), 0.0);
            cover(f64::from(b[0]), f64::from(b[1]), 0.0);
        }
        if let Some(l) = s.lamp {
            cover(f64::from(l[0]), f64::from(l[1]), 10.0);
        }
        for l in &s.lamps {
            cover(f64::from(l[0]), f64::from(l[1]), 10.0);
        }
        let view = [v[0] - PAD_MM, v[1] + PAD_MM, v[2] - PAD_MM, v[3] + PAD_MM];
        Arena { title, s, view }
    }

    /// Pixels per mm.
    fn scale(&self) -> f64 {
        let [x0, x1, y0, y1] = self.view;
        (MAX_PX / (x1 - x0)).min(MAX_PX / (y1 - y0))
    }

    /// Plot size in pixels and the widths of the label areas and legend.
    fn layout(&self, text: bool) -> ((u32, u32), u32, u32, u32) {
        let s = self.scale();
        let [x0, x1, y0, y1] = self.view;
        let plot = (((x1 - x0) * s).round() as u32, ((y1 - y0) * s).round() as u32);
        if text {
            (plot, Y_LABEL_W, X_LABEL_H, LEGEND_W)
        } else {
            (plot, 0, 0, 0)
        }
    }

    /// Colour key of the path segment ending at point `i`.
    fn segment_key(&self, i: usize) -> usize {
        match &self.s.path_modules {
            Some(m) => usize::from(m[i]),
            None => {
                let n = self.s.path.len().saturating_sub(1).max(1);
                (i * (TIME_STEPS - 1) + n / 2) / n
            }
        }
    }

    fn key_colour(&self, key: usize) -> RGBColor {
        match self.s.path_modules {
            Some(_) => palette(key),
            None => ramp(key as f64 / (TIME_STEPS - 1) as f64),
        }
    }
}

impl Figure for Arena<'_> {
    fn size(&self, text: bool) -> (u32, u32) {
        let ((pw, ph), yl, xl, legend) = self.layout(text);
        (2 * MARGIN + yl + pw + legend, TITLE_H + 2 * MARGIN + xl + ph)
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>, text: bool) -> DrawResult<DB> {
        let s = self.s;
        let area = render::title_strip(root, self.title, text)?;
        let ((pw, _), yl, xl, _) = self.layout(text);
        let (left, legend) = area.split_horizontally(2 * MARGIN + yl + pw);
        let [x0, x1, y0, y1] = self.view;
        let mut chart = ChartBuilder::on(&left)
            .margin(MARGIN)
            .x_label_area_size(xl)
            .y_label_area_size(yl)
            .build_cartesian_2d(x0..x1, y0..y1)?;
        let mut mesh = chart.configure_mesh();
        mesh.disable_mesh().axis_style(INK).x_labels(8).y_labels(8);
        mesh.x_label_formatter(&render::tick).y_label_formatter(&render::tick);
        if text {
            mesh.label_style(render::label_style(14.0))
                .axis_desc_style(render::label_style(16.0))
                .x_desc("x (mm)")
                .y_desc("y (mm)");
        } else {
            mesh.disable_x_axis().disable_y_axis();
        }
        mesh.draw()?;

        let scale = self.scale();
        let px = |mm: f32| ((f64::from(mm) * scale).round() as i32).max(2);
        let (w, h) = (f64::from(s.arena[0]), f64::from(s.arena[1]));
        chart.draw_series(std::iter::once(Rectangle::new([(0.0, 0.0), (w, h)], FLOOR.filled())))?;
        chart.draw_series(std::iter::once(Rectangle::new([(0.0, 0.0), (w, h)], INK.stroke_width(3))))?;
        let xy = |p: [f32; 2]| (f64::from(p[0]), f64::from(p[1]));
        for &(a, b, grey, charger) in &s.zones {
            // The floor is white (grey 1); a zone is drawn at its grey level.
            let v = (155.0 + 100.0 * grey).round() as u8;
            chart.draw_series(std::iter::once(Rectangle::new([xy(a), xy(b)], RGBColor(v, v, v).filled())))?;
            if charger {
                chart.draw_series(std::iter::once(Rectangle::new([xy(a), xy(b)], BAR.stroke_width(3))))?;
            }
        }
        for &(a, b) in &s.walls {
            chart.draw_series(std::iter::once(PathElement::new(vec![xy(a), xy(b)], INK.stroke_width(4))))?;
        }
        for c in &s.cylinders {
            let at = (f64::from(c[0]), f64::from(c[1]));
            chart.draw_series(std::iter::once(Circle::new(at, px(c[2]), CYLINDER.filled())))?;
        }
        if let Some((a, b)) = s.bar {
            let line = vec![(f64::from(a[0]), f64::from(a[1])), (f64::from(b[0]), f64::from(b[1]))];
            chart.draw_series(std::iter::once(PathElement::new(line, BAR.stroke_width(7))))?;
        }
        let lamps = s.lamp.iter().map(|l| (l, true));
        for (l, on) in lamps.chain(s.lamps.iter().enumerate().map(|(i, l)| (l, !s.dark_lamps.contains(&i)))) {
            draw_lamp(chart.plotting_area(), (f64::from(l[0]), f64::from(l[1])), on)?;
        }
        for o in &s.objects {
            let c = (f64::from(o.x), f64::from(o.y));
            let style = match (o.collected, o.virtual_) {
                (true, _) => COLLECTED.filled(),
                (false, true) => VIRTUAL.stroke_width(2),
                (false, false) => OBJECT.filled(),
            };
            chart.draw_series(std::iter::once(Circle::new(c, px(o.radius), style)))?;
            if o.collected && o.virtual_ {
                chart.draw_series(std::iter::once(Circle::new(c, px(o.radius), VIRTUAL.stroke_width(1))))?;
            }
        }

        // A team's other robots under robot 0: each path one colour, its
        // start numbered, its body at the end.
        for (k, path) in s.others.iter().enumerate() {
            let colour = self.robot_colour(self.other_robot(k));
            let line: Vec<(f64, f64)> = path.iter().map(|p| (f64::from(p[0]), f64::from(p[1]))).collect();
            let style = colour.stroke_width(2);
            chart.draw_series(unmitered(&line).into_iter().map(|l| PathElement::new(l, style)))?;
            if let Some(&start) = line.first() {
                let ring = RGBColor(150, 150, 150).stroke_width(1);
                chart.draw_series(std::iter::once(Circle::new(start, px(s.body_radius), ring)))?;
            }
            if let Some(last) = path.last() {
                self.body(&mut chart, *last, colour)?;
            }
        }
        let pts: Vec<(f64, f64)> = s.path.iter().map(|p| (f64::from(p[0]), f64::from(p[1]))).collect();
        if let Some(&start) = pts.first() {
            let body = px(s.body_radius);
            chart.draw_series(std::iter::once(Circle::new(
                start,
                body,
                RGBColor(150, 150, 150).stroke_width(2),
            )))?;
        }
        let mut i = 1;
        while i < pts.len() {
            let key = self.segment_key(i);
            let mut line = vec![pts[i - 1]];
            while i < pts.len() && self.segment_key(i) == key {
                line.push(pts[i]);
                i += 1;
            }
            let style = self.key_colour(key).stroke_width(2);
            chart.draw_series(unmitered(&line).into_iter().map(|l| PathElement::new(l, style)))?;
        }
        for (i, label) in &s.marks {
            let dot = EmptyElement::at(pts[*i]) + Circle::new((0, 0), 4, INK.filled());
            chart.draw_series(std::iter::once(dot))?;
            if text && !label.is_empty() {
                let style = render::label_style(13.0).pos(Pos::new(HPos::Left, VPos::Bottom));
                let (w, h) = root.estimate_text_size(label, &style)?;
                let (w, h) = (w as i32, h as i32);
                let back = Rectangle::new([(4, -h - 6), (w + 9, -2)], WHITE.mix(0.8).filled());
                let t = EmptyElement::at(pts[*i]) + back + Text::new(label.clone(), (6, -4), style);
                chart.draw_series(std::iter::once(t))?;
            }
        }
        if let Some(last) = s.path.last() {
            let outline = if s.roles.is_empty() { INK } else { self.robot_colour(s.robot) };
            self.body(&mut chart, *last, outline)?;
        }
        if text && !s.others.is_empty() {
            // Every robot's number beside its start.
            let style = render::label_style(13.0).pos(Pos::new(HPos::Center, VPos::Center));
            let starts = s.path.first().map(|p| (s.robot, p)).into_iter();
            let others =
                s.others.iter().enumerate().filter_map(|(k, p)| Some((self.other_robot(k), p.first()?)));
            for (k, p) in starts.chain(others) {
                let at = (f64::from(p[0]), f64::from(p[1]));
                let label = EmptyElement::at(at)
                    + Circle::new((0, 0), 8, WHITE.mix(0.85).filled())
                    + Text::new(k.to_string(), (0, 0), style.clone());
                chart.draw_series(std::iter::once(label))?;
            }
        }
        if text {
            self.legend(&legend)?;
        }
        Ok(())
    }
}

impl Arena<'_> {
    /// The team's number of `others[k]`.
    fn other_robot(&self, k: usize) -> usize {
        if k < self.s.robot {
            k
        } else {
            k + 1
        }
    }

    /// The role robot `i` plays (0 without roles, and past their count).
    fn role_of(&self, i: usize) -> usize {
        let mut end = 0usize;
        for (r, (_, robots)) in self.s.roles.iter().enumerate() {
            end += *robots as usize;
            if i < end {
                return r;
            }
        }
        self.s.roles.len().saturating_sub(1)
    }

    /// The colour of robot `i` of a team: its role's in a team of roles,
    /// else its own ([`team_colour`]; robot 0's path is coloured by its
    /// modules or by time, its body outlined in its role's colour).
    fn robot_colour(&self, i: usize) -> RGBColor {
        if self.s.roles.is_empty() {
            team_colour(i.saturating_sub(1))
        } else {
            role_colour(self.role_of(i))
        }
    }
}

/// The colour of role `r`: strong hues, apart from the greys of the
/// clones' team colours and from the headings' red (the report's page
/// draws a team's roles in the same colours).
pub(super) fn role_colour(r: usize) -> RGBColor {
    const C: [RGBColor; 6] = [
        RGBColor(40, 110, 200),
        RGBColor(220, 130, 0),
        RGBColor(40, 150, 70),
        RGBColor(140, 70, 170),
        RGBColor(0, 150, 160),
        RGBColor(150, 100, 50),
    ];
    C[r % C.len()]
}

/// The colour of a team's robot `k + 1` (robot 0's path is coloured by its
/// modules or by time).
pub(super) fn team_colour(k: usize) -> RGBColor {
    const C: [RGBColor; 8] = [
        RGBColor(96, 110, 130),
        RGBColor(166, 120, 60),
        RGBColor(70, 130, 110),
        RGBColor(150, 90, 130),
        RGBColor(110, 110, 60),
        RGBColor(60, 110, 160),
        RGBColor(160, 80, 80),
        RGBColor(100, 90, 160),
    ];
    C[k % C.len()]
}

impl Arena<'_> {
    /// A robot's body at `pose` `[x, y, theta]`: a pale disc outlined in
    /// `outline`, its heading in red.
    fn body<DB: DrawingBackend>(
        &self,
        chart: &mut ChartContext<'_, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>,
        pose: [f32; 3],
        outline: RGBColor,
    ) -> DrawResult<DB> {
        let s = self.s;
        let px = ((f64::from(s.body_radius) * self.scale()).round() as i32).max(2);
        let c = (f64::from(pose[0]), f64::from(pose[1]));
        let r = f64::from(s.body_radius);
        let (dx, dy) = (r * f64::from(pose[2]).cos(), r * f64::from(pose[2]).sin());
        chart.draw_series(std::iter::once(Circle::new(c, px, WHITE.mix(0.6).filled())))?;
        chart.draw_series(std::iter::once(Circle::new(c, px, outline.stroke_width(2))))?;
        chart.draw_series(std::iter::once(PathElement::new(
            vec![c, (c.0 + dx, c.1 + dy)],
            HEADING.stroke_width(3),
        )))?;
        Ok(())
    }
}

/// The lamp: a yellow disc with rays, in pixels around `at`.
/// Splits a polyline into pieces that a wide stroke can join safely:
/// repeated points are dropped and the line is cut wherever it turns by more
/// than 90 degrees (a blocked robot backing off), because the bitmap backend
/// miters such a join into a long spike.
pub(super) fn unmitered(line: &[(f64, f64)]) -> Vec<Vec<(f64, f64)>> {
    let mut pieces = Vec::new();
    let mut cur: Vec<(f64, f64)> = Vec::new();
    for &p in line {
        match cur.as_slice() {
            [.., last] if *last == p => continue,
            [.., a, b] if (b.0 - a.0) * (p.0 - b.0) + (b.1 - a.1) * (p.1 - b.1) < 0.0 => {
                let b = *b;
                pieces.push(std::mem::replace(&mut cur, vec![b]));
            }
            _ => {}
        }
        cur.push(p);
    }
    if cur.len() == 1 && pieces.is_empty() {
        // A single point (e.g. a robot that never moved) is still drawn.
        cur.push(cur[0]);
    }
    if cur.len() > 1 {
        pieces.push(cur);
    }
    pieces
}

fn draw_lamp<DB: DrawingBackend, CT: CoordTranslate>(
    area: &DrawingArea<DB, CT>,
    at: CT::From,
    on: bool,
) -> DrawResult<DB>
where
    CT::From: Clone,
{
    if !on {
        // Off: a dark disc without rays.
        area.draw(
            &(EmptyElement::at(at.clone()) + Circle::new((0, 0), 7, RGBColor(120, 120, 120).filled())),
        )?;
        area.draw(&(EmptyElement::at(at) + Circle::new((0, 0), 7, INK.stroke_width(1))))?;
        return Ok(());
    }
    for k in 0..8 {
        let a = std::f64::consts::FRAC_PI_4 * f64::from(k);
        let p = |r: f64| ((r * a.cos()).round() as i32, (r * a.sin()).round() as i32);
        let ray = EmptyElement::at(at.clone())
            + PathElement::new(vec![p(9.0), p(14.0)], RGBColor(210, 150, 0).stroke_width(2));
        area.draw(&ray)?;
    }
    area.draw(&(EmptyElement::at(at.clone()) + Circle::new((0, 0), 7, LAMP.filled())))?;
    area.draw(&(EmptyElement::at(at) + Circle::new((0, 0), 7, RGBColor(210, 150, 0).stroke_width(1))))?;
    Ok(())
}

impl Arena<'_> {
    /// The legend panel at the right: what each mark means and the path colours.
    fn legend<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>) -> DrawResult<DB> {
        let s = self.s;
        let text = render::label_style(15.0).pos(Pos::new(HPos::Left, VPos::Center));
        let head = render::label_style(15.0).pos(Pos::new(HPos::Left, VPos::Center)).color(&INK);
        let (gx, tx) = (8, 46);
        let mut y = MARGIN as i32 + 14;
        let step = 26;
        let entry = |area: &DrawingArea<DB, Shift>, y: &mut i32, label: &str| -> DrawResult<DB> {
            area.draw_text(label, &text, (tx, *y))?;
            *y += step;
            Ok(())
        };
        area.draw(&PathElement::new(vec![(gx, y), (gx + 28, y)], INK.stroke_width(3)))?;
        entry(area, &mut y, "wall")?;
        if s.bar.is_some() {
            area.draw(&PathElement::new(vec![(gx, y), (gx + 28, y)], BAR.stroke_width(7)))?;
            entry(area, &mut y, "charger bar")?;
        }
        if s.lamp.is_some() {
            draw_lamp(area, (gx + 14, y), true)?;
            entry(area, &mut y, "lamp")?;
        }
        let has = |f: &dyn Fn(&super::SceneObject) -> bool| s.objects.iter().any(f);
        if has(&|o| !o.collected && !o.virtual_) {
            area.draw(&Circle::new((gx + 14, y), 6, OBJECT.filled()))?;
            entry(area, &mut y, "object")?;
        }
        if has(&|o| !o.collected && o.virtual_) {
            area.draw(&Circle::new((gx + 14, y), 6, VIRTUAL.stroke_width(2)))?;
            entry(area, &mut y, "virtual object")?;
        }
        if has(&|o| o.collected) {
            area.draw(&Circle::new((gx + 14, y), 6, COLLECTED.filled()))?;
            entry(area, &mut y, "collected object")?;
        }
        if s.path.is_empty() {
            return Ok(());
        }
        area.draw(&Circle::new((gx + 14, y), 10, RGBColor(150, 150, 150).stroke_width(2)))?;
        entry(area, &mut y, "start")?;
        area.draw(&Circle::new((gx + 14, y), 10, INK.stroke_width(2)))?;
        area.draw(&PathElement::new(vec![(gx + 14, y), (gx + 24, y)], HEADING.stroke_width(3)))?;
        entry(area, &mut y, "final pose and heading")?;
        if !s.others.is_empty() {
            let n = s.others.len() + 1;
            if s.roles.is_empty() {
                area.draw(&PathElement::new(vec![(gx, y), (gx + 28, y)], team_colour(0).stroke_width(2)))?;
                let who = if s.robot == 0 { format!("robots 1 to {}", n - 1) } else { "other robots".into() };
                entry(area, &mut y, &format!("{who}: paths"))?;
            }
            let style = render::label_style(13.0).pos(Pos::new(HPos::Center, VPos::Center));
            area.draw(&(EmptyElement::at((gx + 14, y)) + Text::new(s.robot.to_string(), (0, 0), style)))?;
            entry(area, &mut y, &format!("robot at its start (of {n})"))?;
            let mut first = 0;
            for (name, robots) in &s.roles {
                let last = first + robots.saturating_sub(1);
                let who =
                    if *robots == 1 { format!("robot {first}") } else { format!("robots {first} to {last}") };
                // The role's colour: its robots' paths and outlines (robot
                // 0's path keeps its modules' colours).
                let c = role_colour(self.role_of(first as usize));
                area.draw(&PathElement::new(vec![(gx, y), (gx + 28, y)], c.stroke_width(3)))?;
                entry(area, &mut y, &format!("role {name}: {who}"))?;
                first = last + 1;
            }
        }
        if !s.marks.is_empty() {
            area.draw(&Circle::new((gx + 14, y), 4, INK.filled()))?;
            entry(area, &mut y, "event")?;
        }
        y += step / 2;
        match &s.path_modules {
            Some(mods) => {
                area.draw_text("path: winning module", &head, (gx, y))?;
                y += step;
                let mut used: Vec<u16> = mods.clone();
                used.sort_unstable();
                used.dedup();
                for m in used {
                    let c = palette(usize::from(m));
                    area.draw(&PathElement::new(vec![(gx, y), (gx + 28, y)], c.stroke_width(3)))?;
                    let name =
                        s.module_names.get(usize::from(m)).cloned().unwrap_or_else(|| format!("module {m}"));
                    entry(area, &mut y, &name)?;
                }
            }
            None => {
                area.draw_text("path: colour is time", &head, (gx, y))?;
                y += step;
                let width = 200;
                for k in 0..width {
                    let c = ramp(f64::from(k) / f64::from(width - 1));
                    area.draw(&Rectangle::new([(gx + k, y - 8), (gx + k + 1, y + 8)], c.filled()))?;
                }
                y += 22;
                let last = s.path.len() - 1;
                let left = render::label_style(13.0).pos(Pos::new(HPos::Left, VPos::Center));
                let right = render::label_style(13.0).pos(Pos::new(HPos::Right, VPos::Center));
                area.draw_text("action 0", &left, (gx, y))?;
                area.draw_text(&format!("action {last}"), &right, (gx + width, y))?;
            }
        }
        Ok(())
    }
}
