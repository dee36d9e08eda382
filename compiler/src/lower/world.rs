//! The world: arena, charger, battery, objects, body and start pose (one of
//! each), inner walls, cylinders, lamps and floor zones (any number), with
//! `world adds` and `world changes` checked against the inherited world.

use shaping_runtime::limits::{MAX_ACTIONS, MAX_ITEMS, MAX_OBJECTS, MAX_ROBOTS};
use shaping_runtime::program::*;
use shaping_runtime::sim::ir;
use shaping_runtime::world::{
    blocker, crowded, team_room, Blocker, Crowded, OBJECT_CLEARANCE, START_CLEARANCE,
};
use shaping_runtime::{bodies, catalog};

use super::*;
use crate::diag::{did_you_mean, Error};
use crate::syntax::ast::{self, Unit};

/// The settings of `body { }`.
pub(crate) const BODY_SETTINGS: [&str; 11] = [
    "radius",
    "wheel_base",
    "v_max",
    "action",
    "wheel_noise",
    "sensor_noise",
    "rab_range",
    "rab_noise",
    "rab_bearing_noise",
    "rab_occlusion",
    "rab_signals",
];

impl Lower<'_> {
    pub(super) fn world(&mut self, ws: &mut WorldSt, block: &ast::WorldBlock, stage: &str) {
        // Settings that are not lists: once per block.
        let mut seen: HashMap<&'static str, Span> = HashMap::new();
        for item in &block.items {
            if self.world_item_fits(ws, block, stage, item, &mut seen) {
                self.world_item(ws, block, stage, item);
            }
        }
    }

    /// Whether `item` may be lowered into the world so far: a setting that
    /// is not a list once per block (`seen`), an `adds` of what the world
    /// lacks and a `changes` of what it has; each mistake reported.
    fn world_item_fits(
        &mut self,
        ws: &WorldSt,
        block: &ast::WorldBlock,
        stage: &str,
        item: &ast::WorldItem,
        seen: &mut HashMap<&'static str, Span>,
    ) -> bool {
        use ast::WorldItem as W;
        let single = match item {
            W::Arena { .. } => Some("arena"),
            W::Charger { .. } => Some("charger"),
            W::Battery(..) => Some("battery"),
            W::Recharge(..) => Some("recharge"),
            W::Robots(..) => Some("robots"),
            W::Objects { .. } => Some("objects"),
            W::Body { .. } => Some("body"),
            W::Start { .. } => Some("start"),
            _ => None,
        };
        if let Some(key) = single {
            if let Some(first) = seen.get(key) {
                self.errors.push(Error::Duplicate {
                    span: item.span().into(),
                    first: (*first).into(),
                    what: "world setting",
                    name: key.into(),
                });
                return false;
            }
            seen.insert(key, item.span());
        }
        let key = match item {
            W::Charger { .. } => Some("charger"),
            W::Battery(..) | W::Recharge(..) => Some("battery"),
            W::Objects { .. } => Some("objects"),
            W::Start { .. } => Some("start"),
            _ => None,
        };
        if let Some(key) = key {
            let exists = match key {
                "charger" => ws.world.charger.is_some(),
                "battery" => ws.world.battery.is_some(),
                "start" => ws.world.items.start.is_some(),
                _ => ws.world.objects.is_some(),
            };
            match block.mode {
                ast::WorldMode::Adds if exists && !matches!(item, W::Recharge(..)) => {
                    let other = ws.spans.get(key).copied().unwrap_or(item.span());
                    self.errors.push(Error::Conflict {
                        span: item.span().into(),
                        other: other.into(),
                        message: format!(
                            "stage `{stage}` adds {}, but its world has one already",
                            key_desc(key)
                        ),
                        label: "added here".into(),
                        other_label: "already declared here".into(),
                    });
                    return false;
                }
                ast::WorldMode::Changes if !exists && !matches!(item, W::Recharge(..)) => {
                    self.value_error(
                        item.span(),
                        format!("stage `{stage}` changes {}, but its world has none", key_desc(key)),
                        "nothing to change",
                        Some("use `world adds { ... }` to add them".into()),
                    );
                    return false;
                }
                _ => {}
            }
        }
        true
    }

    /// Lowers one item of a world block into the world.
    fn world_item(&mut self, ws: &mut WorldSt, block: &ast::WorldBlock, stage: &str, item: &ast::WorldItem) {
        use ast::WorldItem as W;
        match item {
            W::Wall { .. }
            | W::Cylinder { .. }
            | W::Lamp { .. }
            | W::Zone { .. }
            | W::Start { .. }
            | W::Place { .. } => self.world_list_item(ws, block, stage, item),
            _ => self.world_setting(ws, block, item),
        }
    }

    /// Lowers a setting of a world block (its arena, charger, battery,
    /// robots, objects, body): one of each per world.
    fn world_setting(&mut self, ws: &mut WorldSt, block: &ast::WorldBlock, item: &ast::WorldItem) {
        use ast::WorldItem as W;
        match item {
            W::Arena { width, depth, span } => {
                let w = self.length(width, "the arena width");
                let d = self.length(depth, "the arena depth");
                if let (Some(w), Some(d)) = (w, d) {
                    ws.world.arena = [w, d];
                    ws.spans.insert("arena", *span);
                    ws.arena_bare = width.unit.is_none() && depth.unit.is_none();
                }
            }
            W::Charger { length, wall, lamp, span } => self.charger(ws, length, wall, lamp.as_ref(), *span),
            W::Battery(q, span) => {
                if let Some(c) = self.count(q, "the battery capacity", 1) {
                    let recharge = ws.world.battery.as_ref().map(|b| b.recharge).unwrap_or(DEFAULT_RECHARGE);
                    ws.world.battery = Some(Battery { capacity: c as u32, recharge });
                    ws.spans.insert("battery", *span);
                }
            }
            W::Recharge(q, span) => {
                if let Some(c) = self.count(q, "the recharge time", 1) {
                    match ws.world.battery.as_mut() {
                        Some(b) => b.recharge = c as u32,
                        None => {
                            // `recharge` before `battery` in the same block.
                            let has_battery = block.items.iter().any(|i| matches!(i, W::Battery(..)));
                            if has_battery {
                                ws.world.battery = Some(Battery { capacity: 200, recharge: c as u32 });
                            } else {
                                self.value_error(
                                    *span,
                                    "the world recharges a battery it does not have".into(),
                                    "no battery",
                                    Some("declare `battery N actions` too".into()),
                                );
                            }
                        }
                    }
                }
            }
            W::Robots(q, span) => {
                if let Some(n) = self.count_in(q, "the number of robots", 1, MAX_ROBOTS.into()) {
                    ws.world.robots = n as u32;
                    ws.spans.insert("robots", *span);
                }
            }
            // A role's robots: lowered with the stage's roles (`roles.rs`).
            W::RoleRobots { .. } => {}
            W::Objects { count, diameter, virtual_, span } => {
                let mut o =
                    ws.world.objects.clone().unwrap_or(Objects { count: 8, diameter: 25.0, virtual_: false });
                if let Some(c) = count
                    .as_ref()
                    .and_then(|q| self.count_in(q, "the number of objects", 0, MAX_OBJECTS.into()))
                {
                    o.count = c as u32;
                }
                if let Some(d) = diameter.as_ref().and_then(|q| self.length(q, "the object diameter")) {
                    o.diameter = d;
                }
                if let Some(v) = virtual_ {
                    o.virtual_ = *v;
                }
                ws.world.objects = Some(o);
                ws.spans.insert("objects", *span);
            }
            W::Body { preset, items, span } => {
                self.body(ws, preset.as_ref(), items, *span);
                ws.spans.insert("body", *span);
            }
            _ => {}
        }
    }

    /// `charger LENGTH on WALL wall [with lamp [HEIGHT]]`.
    fn charger(
        &mut self,
        ws: &mut WorldSt,
        length: &ast::Quantity,
        wall: &ast::Name,
        lamp: Option<&Option<ast::Quantity>>,
        span: Span,
    ) {
        let len = self.length(length, "the charger length");
        let w = match wall.text.as_str() {
            "north" => Some(Wall::North),
            "south" => Some(Wall::South),
            "east" => Some(Wall::East),
            "west" => Some(Wall::West),
            _ => {
                self.errors.push(Error::Unknown {
                    span: wall.span.into(),
                    what: "wall",
                    name: wall.text.clone(),
                    help: did_you_mean(&wall.text, ["north", "south", "east", "west"])
                        .or_else(|| Some("the walls are `north`, `south`, `east` and `west`".into())),
                });
                None
            }
        };
        let lamp_height = match lamp {
            None => Some(None),
            Some(None) => Some(Some(DEFAULT_LAMP_HEIGHT)),
            Some(Some(q)) => self.length(q, "the lamp height").map(Some),
        };
        if let (Some(length), Some(wall), Some(lamp_height)) = (len, w, lamp_height) {
            ws.world.charger = Some(Charger { wall, length, lamp_height });
            ws.spans.insert("charger", span);
        }
    }

    /// Lowers a list item of a world block (a wall, cylinder, lamp, zone,
    /// the start or a placement), named or not, added or changed.
    fn world_list_item(
        &mut self,
        ws: &mut WorldSt,
        block: &ast::WorldBlock,
        stage: &str,
        item: &ast::WorldItem,
    ) {
        use ast::WorldItem as W;
        match item {
            W::Wall { name, from, to, span } => {
                let (a, b) = (self.point(from, "a wall's end"), self.point(to, "a wall's end"));
                let (Some(from), Some(to)) = (a, b) else {
                    refuse(ws, "wall", name.as_ref());
                    return;
                };
                let wall = InnerWall { name: name.as_ref().map(|n| n.text.clone()), from, to };
                let place = self.place(ws, block, stage, "wall", name.as_ref(), *span);
                put(&mut ws.world.items.walls, place, wall);
            }
            W::Cylinder { name, at, diameter, span } => {
                let at = self.point(at, "a cylinder's centre");
                let d = self.length(diameter, "the cylinder diameter");
                let (Some(at), Some(diameter)) = (at, d) else {
                    refuse(ws, "cylinder", name.as_ref());
                    return;
                };
                let cyl = Cylinder { name: name.as_ref().map(|n| n.text.clone()), at, diameter };
                let place = self.place(ws, block, stage, "cylinder", name.as_ref(), *span);
                put(&mut ws.world.items.cylinders, place, cyl);
            }
            W::Lamp { name, at, height, intensity, switch, span } => {
                let at = self.point(at, "a lamp's position");
                let h = match height {
                    Some(q) => self.length(q, "the lamp height"),
                    None => Some(DEFAULT_LAMP_HEIGHT),
                };
                let k = match intensity {
                    Some(q) => self.plain(q, "the lamp intensity", 0.0, 1e6),
                    None => Some(1.0),
                };
                let sw = match switch {
                    Some((on, q)) => self
                        .count_in(q, "the action a lamp switches at", 1, MAX_ACTIONS.into())
                        .map(|n| Some(LampSwitch { on: *on, at: n as u32 })),
                    None => Some(None),
                };
                let (Some(at), Some(height), Some(intensity), Some(switch)) = (at, h, k, sw) else {
                    refuse(ws, "lamp", name.as_ref());
                    return;
                };
                let lamp =
                    Lamp { name: name.as_ref().map(|n| n.text.clone()), at, height, intensity, switch };
                let place = self.place(ws, block, stage, "lamp", name.as_ref(), *span);
                put(&mut ws.world.items.lamps, place, lamp);
            }
            W::Zone { name, from, to, grey, charger, span } => {
                let (a, b) = (self.point(from, "a zone's corner"), self.point(to, "a zone's corner"));
                let g = match grey {
                    Some(q) => self.plain(q, "the grey level", 0.0, 1.0),
                    None => Some(0.0),
                };
                let (Some(from), Some(to), Some(grey)) = (a, b, g) else {
                    refuse(ws, "zone", name.as_ref());
                    return;
                };
                let zone =
                    Zone { name: name.as_ref().map(|n| n.text.clone()), from, to, grey, charger: *charger };
                let place = self.place(ws, block, stage, "zone", name.as_ref(), *span);
                put(&mut ws.world.items.zones, place, zone);
            }
            W::Start { from, to, heading, span } => {
                let a = self.point(from, "the start position");
                let b = match to {
                    Some(p) => self.point(p, "the start region's corner"),
                    None => a,
                };
                let h = match heading {
                    Some(q) => self.heading(q).map(|d| Some(d.to_radians())),
                    None => Some(None),
                };
                let (Some(from), Some(to), Some(heading)) = (a, b, h) else { return };
                ws.world.items.start = Some(Start { from, to, heading });
                ws.spans.insert("start", *span);
            }
            W::Place { name, at, heading, after, span } => {
                let at = self.point(at, "the place");
                let h = self.heading(heading).map(|d| d.to_radians());
                let n = self.count_in(after, "the action a placement follows", 1, MAX_ACTIONS.into());
                let (Some(at), Some(heading), Some(n)) = (at, h, n) else {
                    refuse(ws, "place", name.as_ref());
                    return;
                };
                let p =
                    Placement { name: name.as_ref().map(|n| n.text.clone()), at, heading, after: n as u32 };
                let place = self.place(ws, block, stage, "place", name.as_ref(), *span);
                put(&mut ws.world.items.places, place, p);
            }
            _ => {}
        }
    }

    /// `X Y` in mm.
    fn point(&mut self, p: &ast::Point, what: &str) -> Option<[f32; 2]> {
        let x = self.coordinate(&p.x, what);
        let y = self.coordinate(&p.y, what);
        Some([x?, y?])
    }

    /// Where a list item of kind `kind` goes: `Some(i)` replaces item `i`
    /// (the item of that name), `None` appends, `Err` after an error
    /// (nothing changes). Records the item's span.
    fn place(
        &mut self,
        ws: &mut WorldSt,
        block: &ast::WorldBlock,
        stage: &str,
        kind: &'static str,
        name: Option<&ast::Name>,
        span: Span,
    ) -> Result<Option<usize>, ()> {
        let names: Vec<Option<&str>> = match kind {
            "wall" => ws.world.items.walls.iter().map(|x| x.name.as_deref()).collect(),
            "cylinder" => ws.world.items.cylinders.iter().map(|x| x.name.as_deref()).collect(),
            "lamp" => ws.world.items.lamps.iter().map(|x| x.name.as_deref()).collect(),
            "place" => ws.world.items.places.iter().map(|x| x.name.as_deref()).collect(),
            _ => ws.world.items.zones.iter().map(|x| x.name.as_deref()).collect(),
        };
        let spans = ws.item_spans.entry(kind).or_default();
        let existing = name.and_then(|n| names.iter().position(|m| *m == Some(n.text.as_str())));
        let here = |sp: Span| block.span.start <= sp.start && sp.end <= block.span.end;
        match (block.mode, existing) {
            (ast::WorldMode::Changes, None)
                if name.is_some_and(|n| ws.refused.contains(&(kind, n.text.clone()))) =>
            {
                // Its declaration was refused, and said so.
                Err(())
            }
            (ast::WorldMode::Changes, None) => {
                let help = match name {
                    Some(n) => did_you_mean(&n.text, names.iter().flatten().copied())
                        .or_else(|| Some(format!("use `world adds {{ {kind} ... }}` to add one"))),
                    None => Some(format!("name the {kind} when you declare it and when you change it")),
                };
                let what = match name {
                    Some(n) => format!("a {kind} `{}`", n.text),
                    None => format!("an unnamed {kind}"),
                };
                self.value_error(
                    span,
                    format!("stage `{stage}` changes {what}, but its world has none"),
                    "nothing to change",
                    help,
                );
                Err(())
            }
            (ast::WorldMode::Adds, Some(i)) => {
                let other = spans.get(i).copied().unwrap_or(span);
                self.errors.push(Error::Conflict {
                    span: span.into(),
                    other: other.into(),
                    message: format!(
                        "stage `{stage}` adds a {kind} `{}`, but its world has one already",
                        name.map_or("", |n| n.text.as_str())
                    ),
                    label: "added here".into(),
                    other_label: "already declared here".into(),
                });
                Err(())
            }
            (_, Some(i)) if spans.get(i).is_some_and(|&sp| here(sp)) => {
                self.errors.push(Error::Duplicate {
                    span: span.into(),
                    first: spans[i].into(),
                    what: kind,
                    name: name.map_or(String::new(), |n| n.text.clone()),
                });
                Err(())
            }
            (_, Some(i)) => {
                if let Some(sp) = spans.get_mut(i) {
                    *sp = span;
                }
                Ok(Some(i))
            }
            (_, None) => {
                if names.len() >= MAX_ITEMS {
                    self.value_error(
                        span,
                        format!("a world has at most {MAX_ITEMS} items of a kind ({kind})"),
                        "one too many",
                        None,
                    );
                    return Err(());
                }
                spans.push(span);
                Ok(None)
            }
        }
    }

    /// Walls and cylinders inside the arena, zones overlapping it, a start
    /// pose where the body fits; only for the items declared in `stage`
    /// (`decl` its span), so an error is reported once.
    pub(super) fn check_items(&mut self, ws: &WorldSt, decl: Span) {
        let [w, d] = ws.world.arena;
        let here = |sp: &Span| decl.start <= sp.start && sp.end <= decl.end;
        let inside = |p: [f32; 2]| p[0] >= 0.0 && p[1] >= 0.0 && p[0] <= w && p[1] <= d;
        let spans = |kind: &str| ws.item_spans.get(kind).cloned().unwrap_or_default();
        let items = &ws.world.items;
        for (wall, sp) in items.walls.iter().zip(spans("wall")) {
            if here(&sp) && !(inside(wall.from) && inside(wall.to)) {
                self.value_error(
                    sp,
                    format!("the wall{} is not inside the arena ({w} x {d} mm)", item_name(&wall.name)),
                    "outside the arena",
                    Some("coordinates are mm east and north of the arena's south-west corner".into()),
                );
            }
        }
        for (c, sp) in items.cylinders.iter().zip(spans("cylinder")) {
            if here(&sp) && !inside(c.at) {
                self.value_error(
                    sp,
                    format!("the cylinder{} stands outside the arena ({w} x {d} mm)", item_name(&c.name)),
                    "outside the arena",
                    Some("coordinates are mm east and north of the arena's south-west corner".into()),
                );
            }
        }
        for (z, sp) in items.zones.iter().zip(spans("zone")) {
            let (x0, x1) = (z.from[0].min(z.to[0]).max(0.0), z.from[0].max(z.to[0]).min(w));
            let (y0, y1) = (z.from[1].min(z.to[1]).max(0.0), z.from[1].max(z.to[1]).min(d));
            if here(&sp) && !(x0 < x1 && y0 < y1) {
                self.value_error(
                    sp,
                    format!(
                        "the zone{} overlaps nothing: no part of it is on the arena's floor ({w} x {d} mm)",
                        item_name(&z.name)
                    ),
                    "covers no floor",
                    Some("give two opposite corners inside the arena".into()),
                );
            }
        }
        self.check_places(ws, decl);
        self.check_start(ws, decl);
    }

    /// Placements (`place ... after N actions`) where the body fits: inside
    /// the arena's walls, clear of walls and cylinders, and in a world of
    /// one robot.
    fn check_places(&mut self, ws: &WorldSt, decl: Span) {
        let [w, d] = ws.world.arena;
        let here = |sp: &Span| decl.start <= sp.start && sp.end <= decl.end;
        let spans = |kind: &str| ws.item_spans.get(kind).cloned().unwrap_or_default();
        let items = &ws.world.items;
        let r = ws.world.body.radius;
        for (p, sp) in items.places.iter().zip(spans("place")) {
            if !here(&sp) {
                continue;
            }
            let name = item_name(&p.name);
            let fits = p.at[0] >= r && p.at[1] >= r && p.at[0] <= w - r && p.at[1] <= d - r;
            if !fits {
                self.errors.push(Error::PlaceOutside {
                    span: sp.into(),
                    name,
                    radius: r,
                    width: w,
                    depth: d,
                });
                continue;
            }
            let Some((what, other)) = blocking(ws, p.at, r) else { continue };
            self.errors.push(Error::PlaceBlocked {
                span: sp.into(),
                other: other.map(Into::into),
                name,
                what,
                radius: r,
            });
        }
        if ws.world.robots > 1 {
            let robots_span = ws.spans.get("robots").copied();
            let robots_here = robots_span.is_some_and(|sp| here(&sp));
            if let Some((p, sp)) =
                items.places.iter().zip(spans("place")).find(|(_, sp)| robots_here || here(sp))
            {
                self.errors.push(Error::PlaceTeam {
                    span: sp.into(),
                    robots_span: robots_span.map(Into::into),
                    name: item_name(&p.name),
                    robots: ws.world.robots,
                });
            }
        }
    }

    /// A start pose where the body fits: inside the arena's walls, and clear
    /// of walls and cylinders when the start is one point.
    fn check_start(&mut self, ws: &WorldSt, decl: Span) {
        let [w, d] = ws.world.arena;
        let here = |sp: &Span| decl.start <= sp.start && sp.end <= decl.end;
        let items = &ws.world.items;
        let r = ws.world.body.radius;
        let (Some(s), Some(sp)) = (&items.start, ws.spans.get("start")) else { return };
        if !here(sp) {
            return;
        }
        let fits = |p: [f32; 2]| p[0] >= r && p[1] >= r && p[0] <= w - r && p[1] <= d - r;
        if !(fits(s.from) && fits(s.to)) {
            self.value_error(
                *sp,
                format!("the start puts the body (radius {r} mm) across the arena's walls ({w} x {d} mm)"),
                "the robot does not fit here",
                Some(format!("keep the start at least {r} mm from every wall")),
            );
            return;
        }
        if s.from != s.to {
            return;
        }
        let Some((what, other)) = blocking(ws, s.from, r) else { return };
        self.errors.push(Error::Conflict {
            span: (*sp).into(),
            other: other.unwrap_or(*sp).into(),
            message: format!("the start puts the body inside {what}"),
            label: "the body overlaps it here".into(),
            other_label: "declared here".into(),
        });
    }

    /// Placements after the life's last action (`life` actions, set at
    /// `life_span` when this stage sets it): they never happen. Reported
    /// for the placements whose span `report` accepts (those declared in
    /// the stage or variant at hand, and all of them when the stage sets
    /// the life), so that each is reported once.
    pub(super) fn check_place_life(
        &mut self,
        ws: &WorldSt,
        stage: &str,
        life: u32,
        life_span: Option<Span>,
        report: &dyn Fn(Span) -> bool,
    ) {
        let spans = ws.item_spans.get("place").cloned().unwrap_or_default();
        for (p, sp) in ws.world.items.places.iter().zip(spans) {
            if p.after < life || !report(sp) {
                continue;
            }
            self.errors.push(Error::PlaceAfterLife {
                span: sp.into(),
                life_span: life_span.map(Into::into),
                name: item_name(&p.name),
                stage: stage.to_string(),
                after: p.after,
                life,
                last: life.saturating_sub(1),
            });
        }
    }

    /// A world whose objects or robot can never be placed, whatever the
    /// seed ([`crowded`]): reported in the stage that declares one of the
    /// parts it comes from (`decl` its span), so an inherited world's error
    /// is reported once.
    pub(super) fn check_crowded(&mut self, ws: &WorldSt, decl: Span) {
        let world = &ws.world;
        let [w, d] = world.arena;
        if 2.0 * world.body.radius >= w.min(d) {
            return; // `check_fit` says so
        }
        let Some(why) = crowded(world) else { return };
        if matches!(why, Crowded::StartCovered(_))
            && world.items.start.as_ref().is_some_and(|s| s.from == s.to)
        {
            return; // a fixed start: `check_items` names what it overlaps
        }
        let here = |sp: &Span| decl.start <= sp.start && sp.end <= decl.end;
        let item = |b: Blocker| match b {
            Blocker::Wall(i) => (
                format!("the wall{}", item_name(&world.items.walls[i].name)),
                ws.item_spans.get("wall").and_then(|s| s.get(i)).copied(),
            ),
            Blocker::Cylinder(i) => (
                format!("the cylinder{}", item_name(&world.items.cylinders[i].name)),
                ws.item_spans.get("cylinder").and_then(|s| s.get(i)).copied(),
            ),
        };
        let spans = |keys: &[&str]| keys.iter().filter_map(|k| ws.spans.get(k).copied()).collect::<Vec<_>>();
        let (mut at, message, label, help) = match why {
            Crowded::Objects { need, room } => {
                let o = world.objects.as_ref().map(|o| (o.count, o.diameter)).unwrap_or_default();
                (
                    spans(&["objects", "arena", "body"]),
                    format!("{} objects {} mm wide do not fit in an arena of {w} x {d} mm", o.0, o.1),
                    "too many or too large".to_string(),
                    format!(
                        "side by side they need {need:.0} mm² of floor and find {room:.0} mm² (objects keep {OBJECT_CLEARANCE} mm from the walls, and leave room for the robot): place fewer or smaller objects, or make the arena larger"
                    ),
                )
            }
            Crowded::ObjectsCovered(b) => {
                let (what, sp) = item(b);
                (
                    sp.into_iter().chain(spans(&["objects", "arena"])).collect(),
                    format!("{what} covers every place an object can be put"),
                    "leaves no room for the objects".to_string(),
                    format!("objects are placed at least {OBJECT_CLEARANCE} mm from the walls, off walls and cylinders"),
                )
            }
            Crowded::StartCovered(b) => {
                let (what, sp) = item(b);
                (
                    sp.into_iter().chain(spans(&["start", "arena", "body"])).collect(),
                    format!("{what} covers every place the robot can start"),
                    "leaves no room for the robot".to_string(),
                    if world.items.start.is_some() {
                        "the robot starts in the `start` region, off walls and cylinders".to_string()
                    } else {
                        format!("without `start`, the robot starts at least {START_CLEARANCE} mm from the arena's walls, off walls and cylinders")
                    },
                )
            }
        };
        at.retain(here);
        if let Some(sp) = at.first() {
            self.value_error(*sp, message, &label, Some(help));
        }
    }

    /// A team (`robots N`) larger than the start region holds
    /// ([`team_room`]): reported in the stage (or variant, `decl` its span)
    /// that declares the robots, the start, the arena or the body.
    pub(super) fn check_team(&mut self, ws: &WorldSt, decl: Span) {
        let world = &ws.world;
        let room = team_room(world);
        if world.robots <= room {
            return;
        }
        let here = |sp: &&Span| decl.start <= sp.start && sp.end <= decl.end;
        if !["robots", "start", "arena", "body"].iter().filter_map(|k| ws.spans.get(k)).any(|sp| here(&sp)) {
            return;
        }
        let Some(&robots) = ws.spans.get("robots") else { return };
        let spacing = 2.0 * world.body.radius + START_CLEARANCE;
        let (region_span, region) = match (&world.items.start, ws.spans.get("start")) {
            (Some(s), sp) if s.from == s.to => (sp.copied(), "a start point holds one robot".to_string()),
            (Some(_), sp) => (sp.copied(), format!("the start region, which holds {room}")),
            (None, _) => (
                ws.spans.get("arena").copied(),
                format!("the start region: the arena less {START_CLEARANCE} mm and a body's radius from the walls"),
            ),
        };
        let help = format!(
            "the region holds half the places of a square grid of {spacing} mm (a body's diameter and {START_CLEARANCE} mm): declare a larger `start from (X, Y) to (X, Y)` region (or none: the whole arena), or {}",
            if room == 1 { "one robot".to_string() } else { format!("at most {room} robots") }
        );
        self.errors.push(Error::TeamTooLarge {
            span: robots.into(),
            region_span: region_span.map(Into::into),
            robots: world.robots,
            room,
            region,
            help,
        });
    }

    /// The charger must fit on its wall.
    pub(super) fn check_charger(&mut self, ws: &WorldSt) {
        if let (Some(c), Some(sp)) = (&ws.world.charger, ws.spans.get("charger")) {
            let wall = match c.wall {
                Wall::North | Wall::South => ws.world.arena[0],
                Wall::East | Wall::West => ws.world.arena[1],
            };
            if c.length > wall {
                self.value_error(
                    *sp,
                    format!("the charger ({} mm) is longer than its wall ({} mm)", c.length, wall),
                    "does not fit",
                    None,
                );
            }
        }
    }

    /// A robot with several ground sensors needs the body to place them:
    /// reported at the stage that declares the sensors, or at the stage
    /// whose body places too few.
    /// The range-and-bearing board of stage `s`'s world: there when its
    /// robot has a `range_bearing` or `signal` sensor or a `broadcast`
    /// actuator (its sectors the sensor's count, 8 without one; its
    /// signals the actuator's count), else none (body settings for it are
    /// the warning `S0047`). A range beyond the arena's diagonal is
    /// `S0043`; a `signal` sensor that is not whole sectors of the values
    /// broadcast `S0044`; a broadcast that no robot hears the warning
    /// `S0045`; broadcasts silenced (`rab_signals off`) where the robot
    /// broadcasts nothing the warning `S0048`.
    pub(super) fn rab_board(&mut self, st: &mut StageSt, s: u16, stage: Span) {
        let sensor = |k| st.sensors.iter().find(|x| x.kind == k);
        let rab = sensor(catalog::SensorKind::RangeBearing);
        let heard = sensor(catalog::SensorKind::Signal);
        let broadcast = st.actuators.iter().find(|a| a.kind == catalog::ActuatorKind::Broadcast);
        let body_span = st.world.spans.get("body").copied().unwrap_or(stage);
        let world = &mut st.world.world;
        if rab.is_none() && heard.is_none() && broadcast.is_none() {
            if world.body.rab.take().is_some() {
                self.errors.push(Error::RabUnused {
                    span: body_span.into(),
                    message: "this body sets a range-and-bearing board, but the robot has none".into(),
                    help: "declare it in the robot: `sensor rab[8] range_bearing`, `sensor heard[8] signal`, `actuator signal broadcast`".into(),
                });
            }
            return;
        }
        let sectors = rab.map_or(catalog::RAB_SECTORS as u16, |r| r.count);
        let signals = broadcast.map_or(0, |a| a.count);
        let board = world.body.rab.get_or_insert(RangeBearing::DEFAULT);
        board.sectors = sectors as u8;
        board.signals = signals as u8;
        if board.silenced && signals == 0 && st.world.spans.contains_key("body") {
            self.errors.push(Error::SilencedNothing {
                span: body_span.into(),
                message: "`rab_signals off` silences the broadcasts, but the robot sends none".into(),
                help: "declare a `broadcast` actuator, or leave the setting out".into(),
            });
        }
        let diagonal = world.arena[0].hypot(world.arena[1]);
        if board.range > diagonal {
            self.errors.push(Error::RabRange {
                span: body_span.into(),
                message: format!(
                    "the range-and-bearing range, {} mm, is longer than the arena's diagonal, {diagonal:.0} mm",
                    board.range
                ),
                help: format!("every robot would perceive every other: give `rab_range` at most {diagonal:.0}mm"),
            });
        }
        if let Some(h) = heard {
            if h.stage == s && (signals == 0 || h.count % sectors != 0 || h.count > sectors * signals) {
                let message = if signals == 0 {
                    format!("sensor `{}` hears signals, but the robot broadcasts none", h.name)
                } else {
                    format!(
                        "sensor `{}` has {} elements, not whole sectors ({sectors}) of the {signals} broadcast value{}",
                        h.name,
                        h.count,
                        if signals == 1 { "" } else { "s" }
                    )
                };
                self.errors.push(Error::SignalChannels {
                    span: h.span.into(),
                    message,
                    help: format!(
                        "a `signal` sensor has one element per sector and broadcast value: `sensor {}[{}] signal`, with an `actuator NAME[{signals}] broadcast`",
                        h.name,
                        sectors * signals.max(1)
                    ),
                });
            }
        }
        if let Some(a) = broadcast.filter(|a| a.stage == s && heard.is_none()) {
            self.errors.push(Error::Unheard {
                span: a.span.into(),
                message: format!("actuator `{}` broadcasts, but no robot can hear it", a.name),
                help:
                    "give the robot a `signal` sensor (`sensor heard[8] signal`), or leave the actuator out"
                        .into(),
            });
        }
    }

    pub(super) fn check_ground(&mut self, st: &StageSt, s: u16, stage: Span) {
        if st.world.refused.contains(&("body", "ground".into())) {
            // A refused body or ground layout said so already.
            return;
        }
        let placed = st.world.world.body.ground.len();
        let here =
            st.world.spans.get("body.ground").filter(|sp| stage.start <= sp.start && sp.end <= stage.end);
        for d in st.sensors.iter().filter(|d| d.kind == SensorKind::Ground) {
            let n = usize::from(d.count);
            if n <= 1 || n <= placed {
                continue;
            }
            let (span, label) = match here {
                Some(sp) => (*sp, format!("places {placed}")),
                None if d.stage == s => (d.span, format!("{n} ground sensors")),
                None => continue,
            };
            self.value_error(
                span,
                format!(
                    "`{}` has {n} ground sensors, but the body places {placed}",
                    d.name
                ),
                &label,
                Some(
                    "say where each sits in the world's body: `body { ground at [(30mm, 10mm), (30mm, -10mm)] }` \
                     (mm ahead of the centre and to its left); one ground sensor alone sits under the centre"
                        .into(),
                ),
            );
        }
    }

    /// The body must fit in the arena: labelled on the arena, or on the
    /// body when only the body was declared by this stage (`within`).
    pub(super) fn check_fit(&mut self, ws: &WorldSt, stage: Span, within: Span) {
        let [w, d] = ws.world.arena;
        let diameter = 2.0 * ws.world.body.radius;
        if diameter >= w.min(d) {
            let here =
                |key: &str| ws.spans.get(key).filter(|s| within.start <= s.start && s.end <= within.end);
            let arena = ws.spans.get("arena");
            let (sp, label) = match (here("arena"), here("body"), arena) {
                (None, Some(body), _) => (*body, "too large for the arena"),
                (_, _, Some(arena)) => (*arena, "too small for the body"),
                (_, _, None) => (stage, "does not fit"),
            };
            // A bare arena read in the wrong unit: the larger unit in which it fits.
            let fits = |scale: f32| diameter < w.min(d) * scale;
            let help = if ws.arena_bare && arena.is_some() && fits(10.0) {
                format!(
                    "a length without a unit is in millimetres: for centimetres, write `arena {}cm x {}cm`",
                    w, d
                )
            } else if ws.arena_bare && arena.is_some() && fits(1000.0) {
                format!(
                    "a length without a unit is in millimetres: for metres, write `arena {}mm x {}mm`",
                    w * 1000.0,
                    d * 1000.0
                )
            } else {
                format!("the body is {diameter} mm wide (twice its `radius`); make the arena larger")
            };
            self.value_error(
                sp,
                format!("a body {diameter} mm wide does not fit in an arena of {w} x {d} mm"),
                label,
                Some(help),
            );
        }
    }

    /// A warning when a module this stage introduces senses ambient light
    /// while the stage's world and every variant's have no lamp (a
    /// charger's `with lamp` is one; a lamp intensity 0 is one, which a
    /// variant or a later stage may light): every reading is 0. Once per
    /// stage, at the first such module; not after a lamp refused with an error.
    pub(super) fn check_lamp(&mut self, st: &StageSt, stage: &Stage, s: u16) {
        let Some(light) = st.sensors.iter().find(|x| x.kind == catalog::SensorKind::Ambient) else { return };
        let lit = |w: &World| {
            !w.items.lamps.is_empty() || w.charger.as_ref().is_some_and(|c| c.lamp_height.is_some())
        };
        // A lamp refused with an error: the world without it is its consequence.
        let refused = st.world.refused.iter().any(|(kind, _)| *kind == "lamp");
        if refused || lit(&stage.world) || stage.variants.iter().flat_map(|v| &v.list).any(|v| lit(&v.world))
        {
            return;
        }
        let of_light =
            |chans: &[u16]| chans.iter().any(|c| (light.channel..light.channel + light.count).contains(c));
        let reads = st.modules.iter().filter(|m| m.stage == s).find_map(|m| {
            let neural = match &m.behavior {
                Some(Behavior::Neural(nb)) => of_light(&nb.inputs),
                _ => false,
            };
            match (of_light(&m.inputs), neural) {
                (true, _) => Some((m, m.inputs_span.unwrap_or(m.span))),
                (false, true) => Some((m, m.span)),
                _ => None,
            }
        });
        let Some((m, span)) = reads else { return };
        self.errors.push(Error::NoLamp {
            span: span.into(),
            stage: stage.name.clone(),
            sensor: light.name.clone(),
            module: m.name.clone(),
            help: format!(
                "`{}` is an `ambient` sensor, which reads the light of the world's lamps: add a lamp (`lamp at (X, Y)`, or a charger `with lamp`), or sense something else",
                light.name
            ),
        });
    }

    /// `body [PRESET] { ... }`: the preset (if any) replaces the whole body,
    /// then the settings and layouts change single values.
    pub(super) fn body(
        &mut self,
        ws: &mut WorldSt,
        preset: Option<&ast::Name>,
        items: &[ast::BodyItem],
        span: Span,
    ) {
        if let Some(p) = preset {
            match bodies::preset(&p.text) {
                Some(b) => {
                    ws.world.body = b;
                    ws.refused.remove(&("body", "ground".to_string()));
                }
                None => {
                    ws.refused.insert(("body", "ground".into()));
                    self.errors.push(Error::Unknown {
                        span: p.span.into(),
                        what: "body preset",
                        name: p.text.clone(),
                        help: did_you_mean(&p.text, bodies::PRESETS)
                            .or_else(|| Some("the presets are `khepera` (the default) and `e-puck`".into())),
                    })
                }
            }
        }
        let settings: Vec<&ast::Setting> = items
            .iter()
            .filter_map(|i| match i {
                ast::BodyItem::Setting(s) => Some(s),
                ast::BodyItem::Layout(_) => None,
            })
            .collect();
        let body = &mut ws.world.body;
        self.body_settings(body, &settings);
        let mut seen: HashMap<String, Span> = HashMap::new();
        for item in items {
            let ast::BodyItem::Layout(l) = item else { continue };
            if let Some(first) = seen.insert(l.kind.text.clone(), l.span) {
                self.errors.push(Error::Duplicate {
                    span: l.span.into(),
                    first: first.into(),
                    what: "sensor layout",
                    name: l.kind.text.clone(),
                });
                continue;
            }
            if l.kind.text == "ground" {
                match self.ground_layout(l, body.radius) {
                    Some(ground) => {
                        body.ground = ground;
                        ws.spans.insert("body.ground", l.span);
                        ws.refused.remove(&("body", "ground".to_string()));
                    }
                    None => {
                        ws.refused.insert(("body", "ground".into()));
                    }
                }
            } else if let Some(ir) = self.ir_layout(l, body.radius) {
                body.ir = Some(ir);
            }
        }
        self.check_sensor_places(body, span);
    }

    /// `ground at [(X, Y), ...]`: 1 to 4 points of the body frame.
    fn ground_layout(&mut self, l: &ast::SensorLayout, radius: f32) -> Option<Vec<[f32; 2]>> {
        if let Some((_, sp)) = &l.facing {
            self.value_error(
                *sp,
                "ground sensors look at the floor below them: they have no bearing".into(),
                "not for ground sensors",
                Some("write only where they sit: `ground at [(30mm, 10mm), (30mm, -10mm)]`".into()),
            );
        }
        let (list, sp) = l.at.as_ref()?;
        let max = catalog::GROUND_SENSORS;
        if list.len() > max {
            self.value_error(
                *sp,
                format!("a body has at most {max} ground sensors; this list places {}", list.len()),
                "too many",
                None,
            );
            return None;
        }
        let mut out = Vec::new();
        let mut ok = true;
        for spot in list {
            match spot {
                ast::Spot::Point(p) => match self.body_point(p, radius, "ground sensor") {
                    Some(q) => out.push(q),
                    None => ok = false,
                },
                ast::Spot::Angle(q) => {
                    self.value_error(
                        q.span,
                        "a ground sensor sits at a point of the body frame, not an angle".into(),
                        "not a point",
                        Some("write `(X, Y)`: mm ahead of the centre and to its left".into()),
                    );
                    ok = false;
                }
            }
        }
        ok.then_some(out)
    }

    /// `proximity at [...] facing [...]`: eight places and eight bearings.
    /// A missing list is derived from the other: a sensor looks straight
    /// out from where it sits, and sits on the rim where it looks.
    fn ir_layout(&mut self, l: &ast::SensorLayout, radius: f32) -> Option<IrLayout> {
        let n = ir::SENSORS;
        let count_ok = |me: &mut Self, len: usize, sp: Span, what: &str| {
            if len != n {
                me.value_error(
                    sp,
                    format!("the robot has exactly {n} proximity sensors, but this list {what} {len}"),
                    &format!("{len}, not {n}"),
                    Some(format!(
                        "give one value per sensor, in the order of `ir[0]` to `ir[{}]`; the count of \
                         proximity sensors is fixed",
                        n - 1
                    )),
                );
                false
            } else {
                true
            }
        };
        let mut at: Option<Vec<SensorSpot>> = None;
        let mut ok = true;
        if let Some((list, sp)) = &l.at {
            if count_ok(self, list.len(), *sp, "places") {
                let mut v = Vec::new();
                for spot in list {
                    match spot {
                        ast::Spot::Angle(q) => match self.bearing(q, "a sensor's angle on the rim") {
                            Some(d) => v.push(SensorSpot::Rim(d)),
                            None => ok = false,
                        },
                        ast::Spot::Point(p) => match self.body_point(p, radius, "proximity sensor") {
                            Some(q) => v.push(SensorSpot::Point(q)),
                            None => ok = false,
                        },
                    }
                }
                at = Some(v);
            } else {
                ok = false;
            }
        }
        let mut facing: Option<Vec<f32>> = None;
        if let Some((list, sp)) = &l.facing {
            if count_ok(self, list.len(), *sp, "gives") {
                let v: Vec<Option<f32>> = list.iter().map(|q| self.bearing(q, "a bearing")).collect();
                ok &= v.iter().all(Option::is_some);
                facing = Some(v.into_iter().flatten().collect());
            } else {
                ok = false;
            }
        }
        if !ok {
            return None;
        }
        let at: Vec<SensorSpot> = match (&at, &facing) {
            (Some(a), _) => a.clone(),
            (None, Some(f)) => f.iter().map(|&d| SensorSpot::Rim(d)).collect(),
            (None, None) => return None,
        };
        let facing: Vec<f32> = match facing {
            Some(f) => f,
            None => at
                .iter()
                .map(|s| match *s {
                    SensorSpot::Rim(d) => d,
                    SensorSpot::Point([x, y]) => {
                        let d = y.atan2(x).to_degrees();
                        if d.is_finite() {
                            d
                        } else {
                            0.0
                        }
                    }
                })
                .collect(),
        };
        Some(IrLayout { at: at.try_into().ok()?, facing: facing.try_into().ok()? })
    }

    /// An angle, in degrees: a bare number or `deg`, or `rad` (radians,
    /// converted). Any other unit is an error.
    fn degrees(&mut self, q: &ast::Quantity, what: &str) -> Option<f64> {
        match q.unit {
            None | Some(Unit::Deg) => Some(q.value),
            Some(Unit::Rad) => Some(q.value.to_degrees()),
            Some(u) => {
                self.errors.push(Error::Unit {
                    span: q.span.into(),
                    expected: "an angle",
                    found: unit_desc(u),
                    help: Some(format!(
                        "{what} is an angle in degrees (`90` or `90deg`) or in radians (`1.57rad`)"
                    )),
                });
                None
            }
        }
    }

    /// A start's `heading`: degrees (or `deg`, `rad`) counter-clockwise
    /// from east, -360..360.
    fn heading(&mut self, q: &ast::Quantity) -> Option<f32> {
        let d = self.degrees(q, "the heading")?;
        if !(-360.0..=360.0).contains(&d) {
            self.value_error(
                q.span,
                "the heading must be between -360 and 360 degrees (or -6.28rad and 6.28rad), counter-clockwise from east".into(),
                "out of range",
                Some("a bare number is in degrees: `heading 90` faces north; `robot.heading` reads radians".into()),
            );
            return None;
        }
        Some(d as f32)
    }

    /// An angle in degrees, counter-clockwise from the heading: -180..180.
    fn bearing(&mut self, q: &ast::Quantity, what: &str) -> Option<f32> {
        let value = self.degrees(q, what)?;
        if !(-180.0..=180.0).contains(&value) {
            self.value_error(
                q.span,
                format!("{what} must be between -180 and 180 degrees, counter-clockwise from the heading"),
                "out of range",
                Some("90 is the left side, -90 the right side, 180 straight back".into()),
            );
            return None;
        }
        Some(value as f32)
    }

    /// `(X, Y)` of the body frame, mm, on or inside the body of `radius`.
    fn body_point(&mut self, p: &ast::Point, radius: f32, what: &str) -> Option<[f32; 2]> {
        let x = self.coordinate(&p.x, "a sensor's place");
        let y = self.coordinate(&p.y, "a sensor's place");
        let q = [x?, y?];
        let d = q[0].hypot(q[1]);
        if d > radius {
            self.value_error(
                p.x.span.to(p.y.span),
                format!(
                    "this {what} is {d:.1} mm from the body centre, outside the body (radius {radius} mm)"
                ),
                "outside the body",
                Some(
                    "a sensor's place is mm ahead of the body centre and to its left, within the radius"
                        .into(),
                ),
            );
            return None;
        }
        Some(q)
    }

    /// The sensors this block did not place (inherited, or a preset's) lie
    /// on or inside the body, whose radius this block may have changed.
    fn check_sensor_places(&mut self, body: &Body, span: Span) {
        let r = body.radius;
        let points = body.ground.iter().chain(body.ir.iter().flat_map(|l| {
            l.at.iter().filter_map(|s| match s {
                SensorSpot::Point(p) => Some(p),
                SensorSpot::Rim(_) => None,
            })
        }));
        if let Some(p) = points.into_iter().find(|p| p[0].hypot(p[1]) > r) {
            self.value_error(
                span,
                format!("a sensor at ({}, {}) mm lies outside this body (radius {r} mm)", p[0], p[1]),
                "sensors outside the body",
                Some(
                    "place the sensors again for this radius (`proximity at [...]`, `ground at [...]`)"
                        .into(),
                ),
            );
        }
    }

    /// The range of `rab_range`, in mm (`S0043` for one under 1 mm: the
    /// board perceives nothing there).
    fn rab_range(&mut self, q: &ast::Quantity) -> Option<f32> {
        let help =
            "give the distance, body to body, within which robots perceive each other: `rab_range 300mm`";
        let message = if q.value <= 0.0 {
            "a range-and-bearing range of 0 perceives nothing"
        } else {
            match self.length(q, "the range-and-bearing range") {
                Some(v) if v >= 1.0 => return Some(v),
                Some(_) => "a range-and-bearing range under 1 mm perceives nothing",
                None => return None,
            }
        };
        self.errors.push(Error::RabRange { span: q.span.into(), message: message.into(), help: help.into() });
        None
    }

    fn body_settings(&mut self, body: &mut Body, settings: &[&ast::Setting]) {
        self.repeated("body setting", settings.iter().map(|s| (s.name.text.clone(), s.span)));
        for set in settings {
            let n = set.name.text.as_str();
            if n == "rab_occlusion" || n == "rab_signals" {
                let rab = body.rab.get_or_insert(RangeBearing::DEFAULT);
                match &set.value {
                    ast::SettingValue::Word(w) if w.text == "on" || w.text == "off" => {
                        if n == "rab_occlusion" {
                            rab.occlusion = w.text == "on"
                        } else {
                            rab.silenced = w.text == "off"
                        }
                    }
                    _ => self.value_error(
                        set.span,
                        format!("`{n}` is `on` or `off`"),
                        "not `on` or `off`",
                        None,
                    ),
                }
                continue;
            }
            let ast::SettingValue::Quantity(q) = &set.value else {
                if BODY_SETTINGS.contains(&n) {
                    self.value_error(set.span, format!("`{n}` needs a number"), "not a number", None);
                } else {
                    self.errors.push(Error::Unknown {
                        span: set.name.span.into(),
                        what: "body setting",
                        name: n.into(),
                        help: did_you_mean(n, BODY_SETTINGS),
                    });
                }
                continue;
            };
            match n {
                "radius" => body.radius = self.length(q, "the body radius").unwrap_or(body.radius),
                "wheel_base" => body.wheel_base = self.length(q, "the wheel base").unwrap_or(body.wheel_base),
                "v_max" => {
                    if q.unit.is_some() {
                        self.errors.push(Error::Unit {
                            span: q.span.into(),
                            expected: "a plain number",
                            found: unit_desc(q.unit.unwrap_or(Unit::Mm)),
                            help: Some(format!(
                                "`v_max` is a speed in mm/s, written without a unit: `v_max {}`",
                                q.value
                            )),
                        });
                    } else if let Some(v) = self.in_range(q.value, q.span, "`v_max` (mm/s)", 1e-3, 1e4) {
                        body.v_max = v;
                    }
                }
                "action" => {
                    if q.unit != Some(Unit::Ms) && q.unit.is_some() {
                        self.errors.push(Error::Unit {
                            span: q.span.into(),
                            expected: "a duration",
                            found: unit_desc(q.unit.unwrap_or(Unit::Ms)),
                            help: Some("the duration of an action is in `ms`".into()),
                        });
                    } else if let Some(v) = self.in_range(q.value, q.span, "the action duration", 1.0, 1e5) {
                        body.action_ms = v;
                    }
                }
                "wheel_noise" => {
                    body.wheel_noise = self.plain(q, "`wheel_noise`", 0.0, 1.0).unwrap_or(body.wheel_noise)
                }
                "sensor_noise" => {
                    body.sensor_noise = self.plain(q, "`sensor_noise`", 0.0, 1.0).unwrap_or(body.sensor_noise)
                }
                "rab_range" => {
                    let range = self.rab_range(q);
                    let rab = body.rab.get_or_insert(RangeBearing::DEFAULT);
                    rab.range = range.unwrap_or(rab.range);
                }
                "rab_noise" => {
                    let rab = body.rab.get_or_insert(RangeBearing::DEFAULT);
                    rab.range_noise = self.plain(q, "`rab_noise`", 0.0, 1.0).unwrap_or(rab.range_noise)
                }
                "rab_bearing_noise" => {
                    let rab = body.rab.get_or_insert(RangeBearing::DEFAULT);
                    rab.bearing_noise = self
                        .plain(q, "`rab_bearing_noise` (degrees)", 0.0, 180.0)
                        .unwrap_or(rab.bearing_noise)
                }
                _ => self.errors.push(Error::Unknown {
                    span: set.name.span.into(),
                    what: "body setting",
                    name: n.into(),
                    help: did_you_mean(n, BODY_SETTINGS),
                }),
            }
        }
    }
}

/// Puts a list item where [`Lower::place`] said.
fn put<T>(list: &mut Vec<T>, place: Result<Option<usize>, ()>, item: T) {
    match place {
        Ok(Some(i)) => list[i] = item,
        Ok(None) => list.push(item),
        Err(()) => {}
    }
}

/// What a body of radius `r` at `at` overlaps: the wall or cylinder in
/// words, and where it is declared.
fn blocking(ws: &WorldSt, at: [f32; 2], r: f32) -> Option<(String, Option<Span>)> {
    let items = &ws.world.items;
    let span = |kind: &str, i: usize| ws.item_spans.get(kind).and_then(|s| s.get(i)).copied();
    Some(match blocker(items, at, r)? {
        Blocker::Wall(i) => (format!("the wall{}", item_name(&items.walls[i].name)), span("wall", i)),
        Blocker::Cylinder(i) => {
            (format!("the cylinder{}", item_name(&items.cylinders[i].name)), span("cylinder", i))
        }
    })
}

/// ` `name`` for a named item, else nothing.
fn item_name(name: &Option<String>) -> String {
    name.as_ref().map_or(String::new(), |n| format!(" `{n}`"))
}

pub(super) fn key_desc(key: &str) -> &'static str {
    match key {
        "charger" => "a charger",
        "battery" => "a battery",
        "start" => "a start pose",
        _ => "a set of objects",
    }
}

/// Remembers that an item of `kind` was refused with an error (an unnamed
/// one under the empty name, which no change names).
fn refuse(ws: &mut WorldSt, kind: &'static str, name: Option<&ast::Name>) {
    ws.refused.insert((kind, name.map(|n| n.text.clone()).unwrap_or_default()));
}
