//! Several robots in one world: a team of `World::robots` bodies that see
//! and block each other, share the world's objects and take turns at the
//! charger.
//!
//! Each robot is a [`Sim`] of its own (pose, battery, gripper, random
//! stream), all made from the same world: robot 0 is exactly the one robot
//! [`Sim::new`] makes with the episode's seed; robot `i` copies its world
//! (the objects where robot 0's seed put them) and is placed in the start
//! region with its own seed ([`robot_seed`]), clear of the robots placed
//! before it.
//!
//! What the team keeps in step:
//! - **the other bodies**: before robot `i` acts, [`Team::prepare`] writes
//!   into its `Sim` the centres of the robots within reach
//!   (the IR range and two moves), found in a uniform grid
//!   rebuilt at the start of each action ([`Team::begin_action`]), so the
//!   cost per robot does not grow with the team;
//! - **the objects**: a robot whose action gripped or released one passes
//!   its objects to every other robot ([`Team::step`]);
//! - **the charger**: it serves one robot at a time. The robot that
//!   charges while no other does holds it until it stops charging or its
//!   battery is full; meanwhile the others cannot charge.
//! - **the range-and-bearing board** (when the body has one,
//!   `Body::rab`): after every robot acted ([`Team::end_action`]), each
//!   robot's readings of the others within range and of what they
//!   broadcast, all measured on one snapshot, so the order in which the
//!   robots act changes nothing of them; [`Team::sense`] hands each robot
//!   the last measurement. Without the board none of it runs.

use nalgebra::Point2;
use rand::SeedableRng;

use super::rng::Xoshiro256pp;
use super::{Command, Outcome, Sim, CHANNELS};
use crate::catalog::{CH_RAB, RAB_SECTORS, SIGNALS};
use crate::program::{RangeBearing, World};
use crate::state::{TeamReads, TEAM_SLOTS};

/// The channels of the range-and-bearing board, from [`CH_RAB`]: the
/// sectors, then the heard signals.
pub const RAB_CHANNELS: usize = RAB_SECTORS + RAB_SECTORS * SIGNALS;

/// A team's range-and-bearing board.
#[derive(Clone, Debug)]
struct Rab {
    spec: RangeBearing,
    /// Each robot's broadcast values now (its last command that set them).
    signal: Vec<[f32; SIGNALS]>,
    /// Each robot's readings, measured after the last action.
    read: Vec<[f32; RAB_CHANNELS]>,
}

/// The seed of robot `i`'s simulator and controller in the episode of
/// seed `seed`: `seed` itself for robot 0 (a team's first robot is the
/// one robot of the same seed), a SplitMix64 mix for the others.
pub fn robot_seed(seed: u64, i: usize) -> u64 {
    if i == 0 {
        return seed;
    }
    let mut z = seed ^ (i as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// The robots of one episode in one world.
#[derive(Clone, Debug)]
pub struct Team {
    sims: Vec<Sim>,
    /// Each robot's centre now.
    at: Vec<Point2<f32>>,
    grid: Grid,
    /// Centre distance within which another robot is seen or blocks, mm.
    reach: f32,
    /// The robot the charger serves.
    charger: Option<usize>,
    /// [`Team::groups`]' scratch, sized once: each robot's group (a union-find
    /// parent) and each group's size.
    group: Vec<u32>,
    size: Vec<u32>,
    /// The range-and-bearing board, if the robots have one.
    rab: Option<Rab>,
    /// Centre distance within which `team.connected` links two robots, mm:
    /// the bodies within the board's range (or [`crate::state::LINK_RANGE`]).
    link: f32,
}

impl Team {
    /// The `world.robots` robots of the episode of seed `seed` (at least one).
    pub fn new(world: &World, seed: u64) -> Team {
        let n = world.robots.max(1) as usize;
        let first = Sim::new(world, seed);
        let mut at = vec![first.centre()];
        let mut sims = Vec::with_capacity(n);
        sims.push(first);
        for i in 1..n {
            let mut sim = sims[0].clone();
            let mut rng = Xoshiro256pp::seed_from_u64(robot_seed(seed, i));
            // Robot 0's placement failures are the world's; count this one's own.
            sim.placement_failures = 0;
            sim.place_start(&world.items.start, &mut rng, &at);
            sim.rng = rng;
            at.push(sim.centre());
            sims.push(sim);
        }
        let s = &sims[0];
        // A body is seen up to the IR range from the surface; a robot moves
        // at most one action's travel (with wheel noise) before the next
        // grid, so the grid's cells hold everything within reach.
        let travel = s.travel * (1.0 + s.wheel_noise);
        let reach = 2.0 * s.radius + super::ir::RANGE + 2.0 * travel + 1.0;
        // The board measures on a grid built for it: its cells hold every
        // robot within its range (centre to centre) without a move.
        let rab = world.body.rab.clone().map(|spec| Rab {
            spec,
            signal: vec![[0.0; SIGNALS]; n],
            read: vec![[0.0; RAB_CHANNELS]; n],
        });
        let rab_reach = rab.as_ref().map_or(0.0, |r| 2.0 * s.radius + r.spec.range.max(0.0) + 1.0);
        let grid = Grid::new(s.width, s.depth, (reach + 2.0 * travel).max(rab_reach), n);
        // Room for every body that fits within reach, and for a row of
        // three cells more (`prepare` writes a row's candidates before it
        // keeps those within reach), so `prepare` never allocates. Bodies
        // that do not overlap cover at most the area around their centres
        // grown by a radius: `area / (pi r^2)` bounds their number.
        let r = s.radius;
        let link_range = rab.as_ref().map_or(crate::state::LINK_RANGE, |b| b.spec.range.max(0.0));
        let link = 2.0 * r + link_range;
        let bodies = |area: f32| (area / (std::f32::consts::PI * r * r)).ceil();
        let c = grid.cell;
        let bound = bodies(std::f32::consts::PI * (reach + r).powi(2))
            + bodies((3.0 * c + 2.0 * r) * (c + 2.0 * r))
            + 1.0;
        let room = if bound.is_finite() { (bound as usize).min(n) } else { n };
        for sim in &mut sims {
            sim.others.reserve_exact(room);
        }
        let mut team =
            Team { sims, at, grid, reach, charger: None, group: vec![0; n], size: vec![0; n], rab, link };
        team.end_action();
        team.begin_action();
        team
    }

    /// Robots in the team.
    pub fn len(&self) -> usize {
        self.sims.len()
    }

    /// A team has at least one robot.
    pub fn is_empty(&self) -> bool {
        self.sims.is_empty()
    }

    /// Robot `i`'s simulator.
    pub fn sim(&self, i: usize) -> &Sim {
        &self.sims[i]
    }

    /// Every robot's simulator, in order.
    pub fn sims(&self) -> &[Sim] {
        &self.sims
    }

    /// Starts an action: the grid of the robots' centres now.
    pub fn begin_action(&mut self) {
        self.grid.build(&self.at);
    }

    /// Writes into robot `i`'s simulator the centres of the other robots
    /// within reach, where they are now. Call before robot `i` senses or
    /// acts; no allocation once the lists have grown to their size.
    pub fn prepare(&mut self, i: usize) {
        let p = self.at[i];
        let reach2 = self.reach * self.reach;
        let others = &mut self.sims[i].others;
        others.clear();
        let me = i as u32;
        // Without a branch per robot (which a predictor cannot learn):
        // every candidate written in order, the list's end moved on past
        // those within reach only.
        self.grid.near(p, |run| {
            let mut end = others.len();
            others.resize(end + run.len(), p);
            for e in run {
                others[end] = e.at;
                end += usize::from((e.robot != me) & ((e.at - p).norm_squared() <= reach2));
            }
            others.truncate(end);
        });
    }

    /// Robot `i` senses ([`Sim::sense`]); [`Team::prepare`] it first.
    /// With a range-and-bearing board, its channels are the measurement
    /// after the last action every robot finished ([`Team::end_action`]).
    pub fn sense(&mut self, i: usize, out: &mut [f32; CHANNELS]) {
        self.sims[i].sense(out);
        if let Some(rab) = &self.rab {
            out[CH_RAB..CH_RAB + RAB_CHANNELS].copy_from_slice(&rab.read[i]);
        }
    }

    /// Ends an action every robot has acted in: with a range-and-bearing
    /// board, measures every robot's readings on where the robots are and
    /// what they broadcast now (a robot whose battery is empty is seen
    /// and broadcasts 0; with the broadcasts silenced, `rab_signals off`,
    /// every value is heard as 0). Nothing without a board.
    pub fn end_action(&mut self) {
        let Some(rab) = &mut self.rab else { return };
        self.grid.build(&self.at);
        for (sim, signal) in self.sims.iter().zip(rab.signal.iter_mut()) {
            if !sim.alive() {
                *signal = [0.0; SIGNALS];
            }
        }
        let Rab { spec, signal, read } = rab;
        let sectors = usize::from(spec.sectors).clamp(1, RAB_SECTORS);
        let signals = if spec.silenced { 0 } else { usize::from(spec.signals).min(SIGNALS) };
        let width = std::f32::consts::TAU / sectors as f32;
        let range = spec.range.max(f32::MIN_POSITIVE);
        let apart = 2.0 * self.sims[0].radius;
        let reach = apart + range;
        let (noise, turn) = (spec.range_noise, spec.bearing_noise.to_radians());
        for i in 0..self.at.len() {
            let p = self.at[i];
            let sim = &mut self.sims[i];
            let heading = sim.pose().theta;
            let occluded = spec.occlusion && sim.shades;
            let out = &mut read[i];
            *out = [0.0; RAB_CHANNELS];
            self.grid.near(p, |run| {
                for e in run {
                    let d = e.at - p;
                    let dist2 = d.norm_squared();
                    if e.robot as usize == i || dist2 > reach * reach {
                        continue;
                    }
                    if occluded && sim.shaded(&p, &e.at) {
                        continue;
                    }
                    let gap = (dist2.sqrt() - apart).max(0.0);
                    let (mut prox, mut bearing) = (1.0 - gap / range, d.y.atan2(d.x) - heading);
                    if noise > 0.0 || turn > 0.0 {
                        let (a, b) = super::noise_pair(&mut sim.rng, 1.0);
                        prox += a * noise;
                        bearing += b * turn;
                    }
                    let prox = prox.clamp(0.0, 1.0);
                    let s = ((bearing / width + 0.5).floor() as i64).rem_euclid(sectors as i64) as usize;
                    out[s] = out[s].max(prox);
                    let heard = &signal[e.robot as usize];
                    for (k, &v) in heard.iter().enumerate().take(signals) {
                        let c = RAB_SECTORS + k * sectors + s;
                        out[c] = out[c].max(v);
                    }
                }
            });
        }
    }

    /// What robot `i` broadcasts now (zeros without a board).
    pub fn signal(&self, i: usize) -> [f32; SIGNALS] {
        self.rab.as_ref().map_or([0.0; SIGNALS], |r| r.signal[i])
    }

    /// Robot `i` executes one action ([`Sim::step`]) among the others
    /// ([`Team::prepare`] it first): the charger only if it is free or
    /// robot `i`'s, and the objects passed on if the action gripped or
    /// released one.
    pub fn step(&mut self, i: usize, cmd: &Command) -> Outcome {
        let sim = &mut self.sims[i];
        sim.charger_free = self.charger.is_none_or(|h| h == i);
        let held = sim.held;
        let out = sim.step(cmd);
        if let (Some(rab), Some(v)) = (&mut self.rab, cmd.signal) {
            rab.signal[i] = v.map(|x| if x.is_nan() { 0.0 } else { x.clamp(0.0, 1.0) });
        }
        if sim.charging && sim.battery() < 1.0 {
            self.charger = Some(i);
        } else if self.charger == Some(i) {
            self.charger = None;
        }
        self.at[i] = sim.centre();
        self.grid.moved(i, self.at[i]);
        // Objects change only by a grip or a release, which changes `held`
        // (a release outside too, whether the object leaves or comes back).
        if sim.held != held {
            let (before, rest) = self.sims.split_at_mut(i);
            let (me, after) = rest.split_first_mut().expect("robot i exists");
            for other in before.iter_mut().chain(after) {
                other.objects.clone_from(&me.objects);
            }
        }
        out
    }

    /// Puts robot `i` at `pose` (for tests and tools), as [`Sim::set_pose`]
    /// does, and also refuses a pose overlapping another robot.
    pub fn place(&mut self, i: usize, pose: super::Pose) -> bool {
        let p = Point2::new(pose.x, pose.y);
        let apart = 2.0 * self.sims[i].radius;
        if self.at.iter().enumerate().any(|(j, q)| j != i && (q - p).norm_squared() < apart * apart) {
            return false;
        }
        if !self.sims[i].set_pose(pose) {
            return false;
        }
        self.at[i] = self.sims[i].centre();
        self.begin_action();
        true
    }

    /// The robot the charger serves now, if any.
    pub fn charger_holder(&self) -> Option<usize> {
        self.charger
    }

    /// The team's state as expressions read it: `[team.spread,
    /// team.grouped, team.largest, team.nearest, team.order,
    /// team.connected]`, each measure but the spread measured only when
    /// `reads` has it (a team of one's value otherwise: nothing reads it).
    /// Without allocating.
    pub fn state(&mut self, reads: TeamReads) -> [f32; TEAM_SLOTS] {
        let mut s = crate::state::TEAM_OF_ONE;
        s[0] = self.spread();
        if reads.nearest || reads.connected {
            // The searches beyond the 3 x 3 cells around a robot need each
            // robot in the cell of where it is now.
            self.grid.build(&self.at);
        }
        if reads.groups {
            (s[1], s[2]) = self.groups(crate::state::NEIGHBOUR_GAP);
        }
        if reads.nearest {
            s[3] = self.nearest();
        }
        if reads.order {
            s[4] = self.order();
        }
        if reads.connected {
            s[5] = self.connected();
        }
        s
    }

    /// The mean over the robots of the distance from each one's centre to
    /// the nearest other robot's centre, mm (0 for one robot): found in
    /// the grid (built where the robots are), ring after ring of cells
    /// around each robot until no robot beyond can be nearer.
    pub fn nearest(&self) -> f32 {
        let n = self.at.len();
        if n < 2 {
            return 0.0;
        }
        let rings = self.grid.cols.max(self.grid.rows);
        let mut sum = 0.0f64;
        for (i, &p) in self.at.iter().enumerate() {
            let mut best = f32::INFINITY;
            for k in 0..=rings {
                self.grid.ring(p, k, |run| {
                    for e in run {
                        let d2 = (e.at - p).norm_squared();
                        if e.robot as usize != i && d2 < best {
                            best = d2;
                        }
                    }
                });
                // Every robot not seen yet is in a cell at least `k` cells away.
                let beyond = k as f32 * self.grid.cell;
                if best <= beyond * beyond {
                    break;
                }
            }
            if best.is_finite() {
                sum += f64::from(best.sqrt());
            }
        }
        (sum / n as f64) as f32
    }

    /// The length of the mean of the robots' unit heading vectors: 1 when
    /// they all head one way, 0 when their headings cancel out (1 for one
    /// robot).
    pub fn order(&self) -> f32 {
        let (sx, sy) = self.sims.iter().fold((0.0f64, 0.0f64), |(x, y), s| {
            let t = f64::from(s.pose().theta);
            (x + t.cos(), y + t.sin())
        });
        (sx.hypot(sy) / self.sims.len() as f64) as f32
    }

    /// The share of the robots in the largest group connected by links of
    /// the board's range (robots whose centres are within [`Team::link`]'s
    /// distance, and the robots linked to those; 1 for one robot): found
    /// in the grid (built where the robots are), without allocating.
    pub fn connected(&mut self) -> f32 {
        let n = self.at.len();
        let link2 = self.link * self.link;
        let rings = ((self.link / self.grid.cell).ceil() as usize).min(self.grid.cols.max(self.grid.rows));
        for (i, g) in self.group.iter_mut().enumerate() {
            *g = i as u32;
        }
        self.size.fill(0);
        for i in 0..n {
            let p = self.at[i];
            let group = &mut self.group;
            for k in 0..=rings {
                self.grid.ring(p, k, |run| {
                    for e in run {
                        // Each pair once, from its higher robot.
                        if (e.robot as usize) < i && (e.at - p).norm_squared() <= link2 {
                            let (a, b) = (root(group, i as u32), root(group, e.robot));
                            if a != b {
                                group[a.max(b) as usize] = a.min(b);
                            }
                        }
                    }
                });
            }
        }
        let mut largest = 0;
        for i in 0..n {
            let r = root(&mut self.group, i as u32) as usize;
            self.size[r] += 1;
            largest = largest.max(self.size[r]);
        }
        largest as f32 / n as f32
    }

    /// Centre distance within which `team.connected` links two robots, mm.
    pub fn link(&self) -> f32 {
        self.link
    }

    /// The share of the robots whose body is within `gap` mm of another's,
    /// and the share in the largest group (robots joined by such pairs,
    /// and the robots joined to those): `(0, 1)` for one robot. Found in
    /// the grid (`gap` is at most the IR range), without allocating.
    pub fn groups(&mut self, gap: f32) -> (f32, f32) {
        let n = self.at.len();
        let near = 2.0 * self.sims[0].radius + gap.clamp(0.0, super::ir::RANGE);
        let near2 = near * near;
        for (i, g) in self.group.iter_mut().enumerate() {
            *g = i as u32;
        }
        self.size.fill(0);
        let mut with = 0;
        for i in 0..n {
            let p = self.at[i];
            let mut found = false;
            let group = &mut self.group;
            self.grid.near(p, |run| {
                for e in run {
                    if e.robot as usize != i && (e.at - p).norm_squared() <= near2 {
                        found = true;
                        let (a, b) = (root(group, i as u32), root(group, e.robot));
                        if a != b {
                            group[a.max(b) as usize] = a.min(b);
                        }
                    }
                }
            });
            with += usize::from(found);
        }
        let mut largest = 0;
        for i in 0..n {
            let r = root(&mut self.group, i as u32) as usize;
            self.size[r] += 1;
            largest = largest.max(self.size[r]);
        }
        (with as f32 / n as f32, largest as f32 / n as f32)
    }

    /// The mean distance of the robots' centres to their mean, mm (0 for one).
    pub fn spread(&self) -> f32 {
        let n = self.at.len() as f64;
        let (sx, sy) =
            self.at.iter().fold((0.0f64, 0.0f64), |(x, y), p| (x + f64::from(p.x), y + f64::from(p.y)));
        let c = Point2::new((sx / n) as f32, (sy / n) as f32);
        let sum: f64 = self.at.iter().map(|p| f64::from((p - c).norm())).sum();
        (sum / n) as f32
    }
}

/// The root of robot `i`'s group in a union-find forest of parents,
/// halving the path on the way.
fn root(group: &mut [u32], mut i: u32) -> u32 {
    while group[i as usize] != i {
        let up = group[group[i as usize] as usize];
        group[i as usize] = up;
        i = up;
    }
    i
}

/// A uniform grid over the arena: the robots in each cell, by a counting
/// sort of their centres (the arrays sized once). Each robot's entry also
/// holds its centre now (kept by [`Grid::moved`]), so a search reads one
/// array in order.
#[derive(Clone, Debug)]
struct Grid {
    cell: f32,
    cols: usize,
    rows: usize,
    /// Cell `c`'s robots are `items[start[c]..start[c + 1]]`.
    start: Vec<u32>,
    items: Vec<Entry>,
    /// Each robot's cell while sorting, then its place in `items`.
    cell_of: Vec<u32>,
}

/// A robot in the grid: its index and its centre now.
#[derive(Clone, Copy, Debug)]
struct Entry {
    robot: u32,
    at: Point2<f32>,
}

impl Grid {
    fn new(width: f32, depth: f32, cell: f32, robots: usize) -> Grid {
        let cell = cell.max(1.0);
        // At most 4,096 cells a side: a coarser grid for a huge arena.
        let side = |len: f32| ((len / cell).ceil() as usize).clamp(1, 4096);
        let (cols, rows) = (side(width), side(depth));
        let cell = cell.max(width / cols as f32).max(depth / rows as f32);
        Grid {
            cell,
            cols,
            rows,
            start: vec![0; cols * rows + 1],
            items: vec![Entry { robot: 0, at: Point2::origin() }; robots],
            cell_of: vec![0; robots],
        }
    }

    fn coords(&self, p: Point2<f32>) -> (usize, usize) {
        // The cell's index: the floor of a finite quotient, 0 below the
        // first (a cast truncates, which is the floor for what is positive,
        // and makes anything negative 0).
        let c = |v: f32, n: usize| {
            let k = v / self.cell;
            if k.is_finite() {
                (k as usize).min(n - 1)
            } else {
                0
            }
        };
        (c(p.x, self.cols), c(p.y, self.rows))
    }

    fn build(&mut self, at: &[Point2<f32>]) {
        let cells = self.cols * self.rows;
        self.start.fill(0);
        for (i, p) in at.iter().enumerate() {
            let (x, y) = self.coords(*p);
            let c = y * self.cols + x;
            self.cell_of[i] = c as u32;
            self.start[c + 1] += 1;
        }
        for c in 0..cells {
            self.start[c + 1] += self.start[c];
        }
        // Each robot at its cell's cursor (robots in increasing order within
        // a cell); the cursors end at their cells' ends, one place on.
        for (i, p) in at.iter().enumerate() {
            let c = self.cell_of[i] as usize;
            let k = self.start[c];
            self.items[k as usize] = Entry { robot: i as u32, at: *p };
            self.cell_of[i] = k;
            self.start[c] += 1;
        }
        for c in (0..cells).rev() {
            self.start[c + 1] = self.start[c];
        }
        self.start[0] = 0;
    }

    /// Robot `i` is now at `p` (it stays in the cell it was sorted into).
    #[inline]
    fn moved(&mut self, i: usize, p: Point2<f32>) {
        self.items[self.cell_of[i] as usize].at = p;
    }

    /// Calls `f` with the robots in the 3 x 3 cells around `p`, a row of
    /// cells at a time (a row's three cells are one run of `items`): row by
    /// row, cell by cell, each cell's in increasing order.
    #[inline]
    fn near(&self, p: Point2<f32>, mut f: impl FnMut(&[Entry])) {
        let (x, y) = self.coords(p);
        let (x0, x1) = (x.saturating_sub(1), (x + 1).min(self.cols - 1));
        for cy in y.saturating_sub(1)..=(y + 1).min(self.rows - 1) {
            let row = cy * self.cols;
            let (a, b) = (self.start[row + x0] as usize, self.start[row + x1 + 1] as usize);
            f(&self.items[a..b]);
        }
    }

    /// Calls `f` with the robots in the cells `k` cells away from `p`'s
    /// (the ring of cells around the `2k - 1` cells across; `p`'s own cell
    /// for 0), a run of cells at a time. A robot in a cell `k` away is at
    /// least `(k - 1)` cells' width from `p`, wherever `p` is in its cell.
    fn ring(&self, p: Point2<f32>, k: usize, mut f: impl FnMut(&[Entry])) {
        let (x, y) = self.coords(p);
        let (x, y, k) = (x as isize, y as isize, k as isize);
        let (cols, rows) = (self.cols as isize, self.rows as isize);
        let mut run = |cy: isize, x0: isize, x1: isize| {
            let (x0, x1) = (x0.max(0), x1.min(cols - 1));
            if (0..rows).contains(&cy) && x0 <= x1 {
                let row = (cy * cols) as usize;
                let (a, b) =
                    (self.start[row + x0 as usize] as usize, self.start[row + x1 as usize + 1] as usize);
                f(&self.items[a..b]);
            }
        };
        if k == 0 {
            run(y, x, x);
            return;
        }
        run(y - k, x - k, x + k);
        for cy in (y - k + 1).max(0)..(y + k).min(rows) {
            run(cy, x - k, x - k);
            run(cy, x + k, x + k);
        }
        run(y + k, x - k, x + k);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testkit::arena_world;

    /// The grid finds exactly the robots a search of all of them finds.
    #[test]
    fn the_grid_finds_every_robot_within_reach() {
        let world = World { arena: [3000.0, 2000.0], robots: 300, ..arena_world() };
        let mut team = Team::new(&world, 5);
        assert_eq!(team.len(), 300);
        // Robots check their neighbours after the robots before them moved
        // in the same action: the grid is as old as the action.
        for round in 0..20 {
            team.begin_action();
            for i in 0..team.len() {
                team.prepare(i);
                let p = team.at[i];
                let mut brute: Vec<[u32; 2]> = team
                    .at
                    .iter()
                    .enumerate()
                    .filter(|&(j, q)| j != i && (q - p).norm_squared() <= team.reach * team.reach)
                    .map(|(_, q)| [q.x.to_bits(), q.y.to_bits()])
                    .collect();
                let mut found: Vec<[u32; 2]> =
                    team.sims[i].others.iter().map(|q| [q.x.to_bits(), q.y.to_bits()]).collect();
                brute.sort_unstable();
                found.sort_unstable();
                assert_eq!(found, brute, "robot {i}, round {round}");
                let turn = if (i + round) % 3 == 0 { 0.2 } else { 1.0 };
                team.step(i, &Command { wheels: [1.0, turn], ..Command::default() });
                // The grid's centres are the robots' own.
                assert!(team.grid.items.iter().all(|e| e.at == team.at[e.robot as usize]), "round {round}");
            }
        }
        assert!(team.sims.iter().map(|s| s.others.len()).sum::<usize>() > 0, "some robots are near others");
    }

    /// Two robots' range-and-bearing readings: robot 0 at (300, 500)
    /// facing east, robot 1 at (455, 500) facing north (bodies 100 mm
    /// apart), `wall` an inner wall between them.
    fn pair(wall: bool, seed: u64) -> Team {
        use crate::program::{InnerWall, RangeBearing};
        let mut world = World { arena: [1000.0, 1000.0], robots: 2, ..arena_world() };
        world.body.rab =
            Some(RangeBearing { range_noise: 0.0, bearing_noise: 0.0, signals: 2, ..RangeBearing::DEFAULT });
        world.body.sensor_noise = 0.0;
        if wall {
            world.items.walls.push(InnerWall { name: None, from: [377.0, 450.0], to: [377.0, 550.0] });
        }
        let mut team = Team::new(&world, seed);
        let far = |x| super::super::Pose { x, y: 150.0, theta: 0.0 };
        assert!(team.place(0, far(100.0)) && team.place(1, far(800.0)));
        assert!(team.place(0, super::super::Pose { x: 300.0, y: 500.0, theta: 0.0 }));
        let north = std::f32::consts::FRAC_PI_2;
        assert!(team.place(1, super::super::Pose { x: 455.0, y: 500.0, theta: north }));
        team.end_action();
        team
    }

    fn rab(team: &mut Team, i: usize) -> [f32; RAB_CHANNELS] {
        let mut out = [0.0; CHANNELS];
        team.sense(i, &mut out);
        out[CH_RAB..CH_RAB + RAB_CHANNELS].try_into().unwrap()
    }

    /// Each robot reads the other in the sector it is in, at the proximity
    /// of the gap between the bodies (1 - 100 / 300), and nothing elsewhere.
    #[test]
    fn two_robots_read_each_other_in_the_right_sector() {
        let mut team = pair(false, 3);
        let expect = 1.0 - 100.0 / 300.0;
        let a = rab(&mut team, 0);
        let b = rab(&mut team, 1);
        // Robot 1 is straight ahead of robot 0: sector 0.
        assert!((a[0] - expect).abs() < 1e-4, "{a:?}");
        assert!(a[1..].iter().all(|&v| v == 0.0), "{a:?}");
        // Robot 0 is on robot 1's left (90 degrees): sector 2 of 8.
        assert!((b[2] - expect).abs() < 1e-4, "{b:?}");
        assert!(b.iter().enumerate().all(|(k, &v)| k == 2 || v == 0.0), "{b:?}");
    }

    /// An inner wall between the two robots hides them from each other;
    /// without occlusion it does not.
    #[test]
    fn a_wall_between_two_robots_hides_them() {
        let mut team = pair(true, 3);
        assert_eq!(rab(&mut team, 0), [0.0; RAB_CHANNELS]);
        assert_eq!(rab(&mut team, 1), [0.0; RAB_CHANNELS]);
        team.rab.as_mut().unwrap().spec.occlusion = false;
        team.end_action();
        assert!(rab(&mut team, 0)[0] > 0.6);
    }

    /// A value broadcast during an action is heard once every robot has
    /// acted (the next action's readings), in the sector of the robot
    /// that sent it, whatever the order of the robots; not before.
    #[test]
    fn a_signal_is_heard_at_the_next_action_not_before() {
        let mut team = pair(false, 3);
        team.begin_action();
        // Robot 1 acts after robot 0, but signals before robot 0 senses
        // again: robot 0 still hears nothing in this action.
        team.prepare(1);
        team.step(1, &Command { signal: Some([0.0, 0.75, 0.0, 0.0]), ..Command::default() });
        team.prepare(0);
        assert_eq!(rab(&mut team, 0)[RAB_SECTORS..], [0.0; RAB_CHANNELS - RAB_SECTORS]);
        team.end_action();
        let heard = rab(&mut team, 0);
        // Signal 1 in sector 0 (8 sectors): channel 8 + 1 * 8 + 0 after the sectors.
        assert_eq!(heard[RAB_SECTORS + 8], 0.75, "{heard:?}");
        assert_eq!(heard[RAB_SECTORS..].iter().filter(|&&v| v != 0.0).count(), 1, "{heard:?}");
        // Robot 1 hears nothing: robot 0 sent nothing.
        assert_eq!(rab(&mut team, 1)[RAB_SECTORS..], [0.0; RAB_CHANNELS - RAB_SECTORS]);
    }

    /// With the broadcasts silenced (`rab_signals off`), the talker still
    /// sets its value, but the listener hears 0 in every signal channel,
    /// while it still perceives the talker; heard again once turned on.
    #[test]
    fn a_silenced_board_hears_nothing_but_still_perceives() {
        let mut team = pair(false, 3);
        team.rab.as_mut().unwrap().spec.silenced = true;
        team.begin_action();
        team.prepare(1);
        team.step(1, &Command { signal: Some([0.5, 0.75, 0.0, 0.0]), ..Command::default() });
        team.end_action();
        assert_eq!(team.signal(1)[..2], [0.5, 0.75]);
        let heard = rab(&mut team, 0);
        assert_eq!(heard[RAB_SECTORS..], [0.0; RAB_CHANNELS - RAB_SECTORS], "{heard:?}");
        assert!(heard[0] > 0.6, "{heard:?}");
        team.rab.as_mut().unwrap().spec.silenced = false;
        team.end_action();
        assert_eq!(rab(&mut team, 0)[RAB_SECTORS + 8], 0.75);
    }

    /// A robot alone reads 0 on every channel of the board.
    #[test]
    fn a_robot_alone_reads_nothing() {
        let mut team = pair(false, 3);
        assert!(team.place(1, super::super::Pose { x: 900.0, y: 900.0, theta: 0.0 }));
        team.end_action();
        assert_eq!(rab(&mut team, 0), [0.0; RAB_CHANNELS]);
    }

    /// Puts robot `i` at `(x, y)` heading `theta`, overlapping or not (the
    /// team's measures do not care).
    fn put(team: &mut Team, i: usize, x: f32, y: f32, theta: f32) {
        team.sims[i].set_pose_unchecked(super::super::Pose { x, y, theta });
        team.at[i] = team.sims[i].centre();
    }

    /// `[team.nearest, team.order, team.connected]` by a search over every
    /// pair of robots, in f64.
    fn brute_force(team: &Team) -> [f64; 3] {
        let n = team.at.len();
        let d2 = |i: usize, j: usize| {
            let (p, q) = (team.at[i], team.at[j]);
            (f64::from(p.x) - f64::from(q.x)).powi(2) + (f64::from(p.y) - f64::from(q.y)).powi(2)
        };
        let nearest = if n < 2 {
            0.0
        } else {
            (0..n)
                .map(|i| (0..n).filter(|&j| j != i).map(|j| d2(i, j)).fold(f64::INFINITY, f64::min).sqrt())
                .sum::<f64>()
                / n as f64
        };
        let (sx, sy) = team.sims.iter().fold((0.0, 0.0), |(x, y), s| {
            let t = f64::from(s.pose().theta);
            (x + t.cos(), y + t.sin())
        });
        let order = (sx * sx + sy * sy).sqrt() / n as f64;
        // The largest component by a walk from every robot not seen yet.
        let mut seen = vec![false; n];
        let mut largest = 0;
        for start in 0..n {
            if seen[start] {
                continue;
            }
            seen[start] = true;
            let (mut todo, mut size) = (vec![start], 0);
            while let Some(i) = todo.pop() {
                size += 1;
                for j in 0..n {
                    // The same test as the team's, on the same f32 numbers.
                    let close = (team.at[i] - team.at[j]).norm_squared() <= team.link * team.link;
                    if !seen[j] && close {
                        seen[j] = true;
                        todo.push(j);
                    }
                }
            }
            largest = largest.max(size);
        }
        [nearest, order, largest as f64 / n as f64]
    }

    fn measured(team: &mut Team) -> [f32; 3] {
        let s = team.state(TeamReads::ALL);
        [s[3], s[4], s[5]]
    }

    fn assert_near(team: &mut Team, what: &str) -> [f32; 3] {
        let got = measured(team);
        let want = brute_force(team);
        for (k, name) in ["nearest", "order", "connected"].iter().enumerate() {
            let tol = 1e-4 * want[k].abs().max(1.0);
            assert!(
                (f64::from(got[k]) - want[k]).abs() <= tol,
                "{what}: team.{name} {} != {}",
                got[k],
                want[k]
            );
        }
        got
    }

    /// `team.nearest`, `team.order` and `team.connected` are what a search
    /// over every pair finds, on random configurations of 1 to 300 robots
    /// (uniform, in two far clusters, all on one spot), with a board of a
    /// short range, of the default range, and without a board.
    #[test]
    fn team_measures_match_a_search_over_every_pair() {
        use crate::program::RangeBearing;
        use rand::RngCore;
        use std::f32::consts::PI;
        let mut rng = Xoshiro256pp::seed_from_u64(11);
        for (case, &n) in [1u32, 2, 3, 7, 40, 150, 300].iter().enumerate() {
            for board in [None, Some(60.0), Some(300.0)] {
                let mut world = World { arena: [3000.0, 2000.0], robots: n, ..arena_world() };
                world.body.rab = board.map(|range| RangeBearing { range, ..RangeBearing::DEFAULT });
                let mut team = Team::new(&world, case as u64);
                assert_eq!(team.len(), n as usize);
                let r = team.sims[0].radius;
                assert_eq!(team.link, 2.0 * r + board.unwrap_or(crate::state::LINK_RANGE));
                let mut u = |lo: f32, hi: f32| lo + (hi - lo) * (rng.next_u32() as f32 / u32::MAX as f32);
                let what = |kind: &str| format!("{n} robots, board {board:?}, {kind}");
                // Uniform over the arena, any headings.
                for i in 0..n as usize {
                    let (x, y, t) = (u(30.0, 2970.0), u(30.0, 1970.0), u(-PI, PI));
                    put(&mut team, i, x, y, t);
                }
                assert_near(&mut team, &what("uniform"));
                // Two clusters 150 mm across, far apart (out of each other's
                // reach), headings near east.
                let a = (n as usize).div_ceil(3);
                for i in 0..n as usize {
                    let (cx, cy) = if i < a { (400.0, 400.0) } else { (2500.0, 1500.0) };
                    let (x, y, t) = (cx + u(-75.0, 75.0), cy + u(-75.0, 75.0), u(-0.3, 0.3));
                    put(&mut team, i, x, y, t);
                }
                let got = assert_near(&mut team, &what("two clusters"));
                if team.link > 150.0 * std::f32::consts::SQRT_2 {
                    // Links longer than a cluster's diagonal: each cluster one group.
                    let big = a.max(n as usize - a) as f32 / n as f32;
                    assert!((got[2] - big).abs() < 1e-6, "{}: {got:?}", what("two clusters"));
                }
                assert!(got[1] > 0.9, "{}: {got:?}", what("two clusters"));
                // All on one spot, half heading east and half west.
                for i in 0..n as usize {
                    let t = if i % 2 == 0 { 0.0 } else { PI };
                    put(&mut team, i, 1234.5, 876.5, t);
                }
                let got = assert_near(&mut team, &what("one spot"));
                assert_eq!(got[0], 0.0);
                assert_eq!(got[2], 1.0);
                if n == 1 {
                    // A team of one: its own values.
                    assert_eq!(team.state(TeamReads::ALL), crate::state::TEAM_OF_ONE);
                } else if n % 2 == 0 {
                    assert!(got[1] < 1e-5, "{}: {got:?}", what("one spot"));
                }
            }
        }
    }

    /// The measures nothing reads are not measured: a team of one's values.
    #[test]
    fn team_measures_not_read_are_not_measured() {
        let world = World { arena: [3000.0, 2000.0], robots: 20, ..arena_world() };
        let mut team = Team::new(&world, 2);
        for i in 0..20 {
            put(&mut team, i, 100.0 + 50.0 * i as f32, 500.0, i as f32);
        }
        let none = team.state(TeamReads::default());
        assert_eq!(none[1..], crate::state::TEAM_OF_ONE[1..]);
        let all = team.state(TeamReads::ALL);
        assert_eq!(all[0], none[0], "the spread is always measured");
        assert!(all[3] > 0.0 && all[4] < 1.0, "{all:?}");
    }
}
