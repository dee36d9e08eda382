//! The world: arena, charger, battery, objects and body, with `world adds` and
//! `world changes` checked against the inherited world.

use shaping_runtime::limits::MAX_OBJECTS;
use shaping_runtime::program::*;

use super::*;
use crate::diag::{did_you_mean, Error};
use crate::syntax::ast::{self, Unit};

impl Lower<'_> {
    pub(super) fn world(&mut self, ws: &mut WorldSt, block: &ast::WorldBlock, stage: &str) {
        use ast::WorldItem as W;
        for item in &block.items {
            let key = match item {
                W::Charger { .. } => Some("charger"),
                W::Battery(..) | W::Recharge(..) => Some("battery"),
                W::Objects { .. } => Some("objects"),
                _ => None,
            };
            if let Some(key) = key {
                let exists = match key {
                    "charger" => ws.world.charger.is_some(),
                    "battery" => ws.world.battery.is_some(),
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
                        continue;
                    }
                    ast::WorldMode::Changes if !exists && !matches!(item, W::Recharge(..)) => {
                        self.value_error(
                            item.span(),
                            format!("stage `{stage}` changes {}, but its world has none", key_desc(key)),
                            "nothing to change",
                            Some("use `world adds { ... }` to add them".into()),
                        );
                        continue;
                    }
                    _ => {}
                }
            }
            match item {
                W::Arena { width, depth, span } => {
                    let w = self.length(width, "the arena width");
                    let d = self.length(depth, "the arena depth");
                    if let (Some(w), Some(d)) = (w, d) {
                        ws.world.arena = [w, d];
                        ws.spans.insert("arena", *span);
                    }
                }
                W::Charger { length, wall, lamp, span } => {
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
                                help: did_you_mean(&wall.text, ["north", "south", "east", "west"]).or_else(
                                    || Some("the walls are `north`, `south`, `east` and `west`".into()),
                                ),
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
                        ws.spans.insert("charger", *span);
                    }
                }
                W::Battery(q, span) => {
                    if let Some(c) = self.count(q, "the battery capacity", 1) {
                        let recharge =
                            ws.world.battery.as_ref().map(|b| b.recharge).unwrap_or(DEFAULT_RECHARGE);
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
                W::Objects { count, diameter, virtual_, span } => {
                    let mut o = ws.world.objects.clone().unwrap_or(Objects {
                        count: 8,
                        diameter: 25.0,
                        virtual_: false,
                    });
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
                W::Body(settings, span) => {
                    self.body(&mut ws.world.body, settings);
                    ws.spans.insert("body", *span);
                }
            }
        }
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

    /// The body must fit in the arena.
    pub(super) fn check_fit(&mut self, ws: &WorldSt, stage: Span) {
        let [w, d] = ws.world.arena;
        let diameter = 2.0 * ws.world.body.radius;
        if diameter >= w.min(d) {
            let sp = ws.spans.get("body").or(ws.spans.get("arena")).copied().unwrap_or(stage);
            self.value_error(
                sp,
                format!("a body {diameter} mm wide does not fit in an arena of {w} x {d} mm"),
                "does not fit",
                None,
            );
        }
    }

    pub(super) fn body(&mut self, body: &mut Body, settings: &[ast::Setting]) {
        const NAMES: [&str; 6] = ["radius", "wheel_base", "v_max", "action", "wheel_noise", "sensor_noise"];
        self.repeated("body setting", settings.iter().map(|s| (s.name.text.clone(), s.span)));
        for set in settings {
            let n = set.name.text.as_str();
            let ast::SettingValue::Quantity(q) = &set.value else {
                if NAMES.contains(&n) {
                    self.value_error(set.span, format!("`{n}` needs a number"), "not a number", None);
                } else {
                    self.errors.push(Error::Unknown {
                        span: set.name.span.into(),
                        what: "body setting",
                        name: n.into(),
                        help: did_you_mean(n, NAMES),
                    });
                }
                continue;
            };
            match n {
                "radius" => body.radius = self.length(q, "the body radius").unwrap_or(body.radius),
                "wheel_base" => body.wheel_base = self.length(q, "the wheel base").unwrap_or(body.wheel_base),
                "v_max" => body.v_max = self.plain(q, "`v_max` (mm/s)", 1e-3, 1e4).unwrap_or(body.v_max),
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
                _ => self.errors.push(Error::Unknown {
                    span: set.name.span.into(),
                    what: "body setting",
                    name: n.into(),
                    help: did_you_mean(n, NAMES),
                }),
            }
        }
    }
}

pub(super) fn key_desc(key: &str) -> &'static str {
    match key {
        "charger" => "a charger",
        "battery" => "a battery",
        _ => "a set of objects",
    }
}
