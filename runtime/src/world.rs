//! What a declared world allows, whatever simulates it: where objects and
//! the robot may be placed, and what makes every placement fail. The
//! compiler checks a world with these before a program exists, the
//! validation checks a loaded program with them, and the simulator places
//! by the same clearances.

use nalgebra::Point2;

use crate::limits::MAX_OBJECTS;
use crate::program::{ItemKind, Items, Target, World};

/// Minimum clearance between the body and the walls at the start, mm.
pub const START_CLEARANCE: f32 = 40.0;
/// Minimum clearance between objects and the walls when placed, mm.
pub const OBJECT_CLEARANCE: f32 = 30.0;

/// Squared distance from `p` to the segment `a`..`b`.
pub(crate) fn segment_distance2(p: &Point2<f32>, a: &Point2<f32>, b: &Point2<f32>) -> f32 {
    let ap = p - a;
    let ab = b - a;
    let len2 = ab.norm_squared();
    let t = if len2 > 0.0 { (ap.dot(&ab) / len2).clamp(0.0, 1.0) } else { 0.0 };
    (ap - ab * t).norm_squared()
}

/// What a disc overlaps among a world's declared items.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Blocker {
    /// `Items::walls[i]`.
    Wall(usize),
    /// `Items::cylinders[i]`.
    Cylinder(usize),
}

/// The first inner wall or cylinder of `items` that a disc of `radius`
/// centred at `at` overlaps (what the simulator's collision test finds).
pub fn blocker(items: &Items, at: [f32; 2], radius: f32) -> Option<Blocker> {
    blocking_all(items, &[at], radius)
}

/// The first inner wall or cylinder of `items` that overlaps a disc of
/// `radius` centred at each of `centres`.
fn blocking_all(items: &Items, centres: &[[f32; 2]], radius: f32) -> Option<Blocker> {
    let pt = |q: [f32; 2]| Point2::new(q[0], q[1]);
    if let Some(i) = items.walls.iter().position(|w| {
        centres.iter().all(|&c| segment_distance2(&pt(c), &pt(w.from), &pt(w.to)) < radius * radius)
    }) {
        return Some(Blocker::Wall(i));
    }
    items
        .cylinders
        .iter()
        .position(|cyl| {
            let reach = radius + cyl.diameter / 2.0;
            centres.iter().all(|&c| (pt(cyl.at) - pt(c)).norm_squared() < reach * reach)
        })
        .map(Blocker::Cylinder)
}

/// Why no episode of a world can place its objects or its robot whatever
/// the seed ([`crowded`]). The simulator draws places at random and, after
/// a number of tries, keeps the last one, overlapping: a world that can
/// never succeed is refused before it runs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Crowded {
    /// The objects' discs (with the body's, or with their clearance from
    /// the walls) need `need` mm² of floor where there are `room`.
    Objects { need: f32, room: f32 },
    /// An inner wall or a cylinder covers every place an object can be drawn.
    ObjectsCovered(Blocker),
    /// An inner wall or a cylinder covers every place the robot can start.
    StartCovered(Blocker),
}

/// What makes every placement of `world` fail, if anything certainly does
/// (a sufficient condition only: a world may still be too crowded for the
/// random placement without this saying so). Objects: their discs, pairwise
/// disjoint, lie [`OBJECT_CLEARANCE`] inside the walls, and with the body's
/// disc inside the arena; the body and the objects cannot overlap the inner
/// walls and cylinders, which overlap a disc wherever in a rectangle it is
/// when they do at its four corners (the distance to a segment or a point
/// is convex).
pub fn crowded(world: &World) -> Option<Crowded> {
    use std::f32::consts::PI;
    let [w, d] = world.arena;
    let body = world.body.radius;
    let items = &world.items;
    // The interval `uniform` draws from: the middle when it is empty.
    let span = |lo: f32, hi: f32| if hi > lo { (lo, hi) } else { ((lo + hi) / 2.0, (lo + hi) / 2.0) };
    if let Some(o) = world.objects.as_ref().filter(|o| o.count > 0) {
        let r = o.diameter / 2.0;
        let discs = o.count.min(MAX_OBJECTS) as f32 * PI * r * r;
        let (need, room) = (discs + PI * body * body, w * d);
        if need > room {
            return Some(Crowded::Objects { need, room });
        }
        let (iw, id) = (w - 2.0 * OBJECT_CLEARANCE, d - 2.0 * OBJECT_CLEARANCE);
        if iw >= 2.0 * r && id >= 2.0 * r && discs > iw * id {
            return Some(Crowded::Objects { need: discs, room: iw * id });
        }
        let m = r + OBJECT_CLEARANCE;
        if let Some(b) = covering(items, span(m, w - m), span(m, d - m), r) {
            return Some(Crowded::ObjectsCovered(b));
        }
    }
    let (x, y) = match &items.start {
        Some(s) => (
            (s.from[0].min(s.to[0]), s.from[0].max(s.to[0])),
            (s.from[1].min(s.to[1]), s.from[1].max(s.to[1])),
        ),
        None => {
            let m = body + START_CLEARANCE;
            (span(m, w - m), span(m, d - m))
        }
    };
    covering(items, x, y, body).map(Crowded::StartCovered)
}

/// The first inner wall or cylinder of `items` that a disc of `radius`
/// overlaps wherever in the rectangle `x` by `y` its centre is.
/// How many robots the start region holds: half the places of a square
/// grid whose spacing is a body and [`START_CLEARANCE`] (random placement
/// jams at about half the densest packing). The region is the declared
/// start's (a point holds one robot) or the arena less the clearance.
/// A team (`World::robots`) larger than this is refused.
pub fn team_room(world: &World) -> u32 {
    let [w, d] = world.arena;
    let body = world.body.radius;
    let m = body + START_CLEARANCE;
    let ((x0, x1), (y0, y1)) = match &world.items.start {
        Some(s) => ((s.from[0], s.to[0]), (s.from[1], s.to[1])),
        None => ((m, w - m), (m, d - m)),
    };
    let spacing = 2.0 * body + START_CLEARANCE;
    let places = |a: f32, b: f32| {
        let n = ((a - b).abs() / spacing).floor();
        if n.is_finite() {
            n.min(1.0e5) as u64 + 1
        } else {
            1
        }
    };
    let grid = places(x0, x1) * places(y0, y1);
    if grid <= 1 {
        return 1;
    }
    u32::try_from(grid / 2).unwrap_or(u32::MAX).max(1)
}

fn covering(items: &Items, x: (f32, f32), y: (f32, f32), radius: f32) -> Option<Blocker> {
    blocking_all(items, &[[x.0, y.0], [x.0, y.1], [x.1, y.0], [x.1, y.1]], radius)
}

/// Where a target item (`distance_to(NAME)`) is, in one world.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Place {
    /// A segment (an inner wall).
    Segment([f32; 2], [f32; 2]),
    /// A point (a lamp, seen from above; a cylinder's centre) and a radius
    /// (a cylinder's; 0 for a lamp).
    Disc([f32; 2], f32),
    /// A rectangle (a floor zone): south-west and north-east corners.
    Rect([f32; 2], [f32; 2]),
}

impl Place {
    /// Where the item of `target`'s kind and name is in `world`, if it has one.
    pub fn of(world: &World, target: &Target) -> Option<Place> {
        let items = &world.items;
        let named = |n: &Option<String>| n.as_deref() == Some(target.name.as_str());
        match target.kind {
            ItemKind::Wall => {
                items.walls.iter().find(|w| named(&w.name)).map(|w| Place::Segment(w.from, w.to))
            }
            ItemKind::Cylinder => {
                items.cylinders.iter().find(|c| named(&c.name)).map(|c| Place::Disc(c.at, c.diameter / 2.0))
            }
            ItemKind::Lamp => items.lamps.iter().find(|l| named(&l.name)).map(|l| Place::Disc(l.at, 0.0)),
            ItemKind::Zone => items.zones.iter().find(|z| named(&z.name)).map(|z| {
                let lo = [z.from[0].min(z.to[0]), z.from[1].min(z.to[1])];
                let hi = [z.from[0].max(z.to[0]), z.from[1].max(z.to[1])];
                Place::Rect(lo, hi)
            }),
        }
    }

    /// The distance from the point `p` (mm) to the item, seen from above:
    /// to the segment, to the disc's edge, to the rectangle (0 on or inside
    /// them).
    pub fn distance(&self, p: [f32; 2]) -> f32 {
        let pt = Point2::new(p[0], p[1]);
        match *self {
            Place::Segment(a, b) => {
                segment_distance2(&pt, &Point2::new(a[0], a[1]), &Point2::new(b[0], b[1])).sqrt()
            }
            Place::Disc(c, r) => ((p[0] - c[0]).hypot(p[1] - c[1]) - r).max(0.0),
            Place::Rect(lo, hi) => {
                let dx = (lo[0] - p[0]).max(p[0] - hi[0]).max(0.0);
                let dy = (lo[1] - p[1]).max(p[1] - hi[1]).max(0.0);
                dx.hypot(dy)
            }
        }
    }
}
