//! The IR model against real Khepera readings (`shared/data/khepera-ir/`).
//!
//! The tables are reference data outside this repository: they are read from
//! the `shared/` directory next to the repository (found by walking up from
//! the crate). Without them the tests fail when `CI=true` and are skipped
//! (with a message) otherwise.

use std::path::{Path, PathBuf};

use shaping_runtime::catalog::{CHANNELS, CH_IR};
use shaping_runtime::program::{Body, Objects, World};
use shaping_runtime::sim::ir::{self, IrModel, Response, KHEPERA, SENSORS};
use shaping_runtime::sim::{Pose, Sim};

const BEARINGS: usize = 180;
const DISTANCES: usize = 20;
const FIRST_MM: f32 = 5.0;
const STEP_MM: f32 = 2.0;
const BODY: f32 = 27.5;
const CYL_RADIUS: f32 = 12.5;

/// `table[t][b][s]`: distance index, bearing index, sensor.
type Table = Vec<Vec<[f32; SENSORS]>>;

fn data_dir() -> Option<PathBuf> {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .ancestors()
        .map(|a| a.join("shared/data/khepera-ir"))
        .find(|p| p.join("khepera-wall.sample").is_file())
}

/// Loads both tables, or explains why not.
fn tables() -> Option<(Table, Table)> {
    let Some(dir) = data_dir() else {
        let msg = "khepera-ir data not found (expected a `shared/data/khepera-ir/` next to the repository)";
        assert!(std::env::var("CI").as_deref() != Ok("true"), "{msg}");
        eprintln!("skipping: {msg}");
        return None;
    };
    let load = |name: &str| {
        let text = std::fs::read_to_string(dir.join(name)).unwrap_or_else(|e| panic!("reading {name}: {e}"));
        parse(&text).unwrap_or_else(|e| panic!("{name}: {e}"))
    };
    Some((load("khepera-wall.sample"), load("khepera-cylinder.sample")))
}

fn parse(text: &str) -> Result<Table, String> {
    let mut lines = text.lines().map(str::trim).filter(|l| !l.is_empty());
    let header: Vec<&str> = lines.next().ok_or("empty file")?.split_whitespace().collect();
    if header != ["8", "180", "20", "5", "2"] {
        return Err(format!("unexpected header {header:?}"));
    }
    let mut table = Vec::new();
    for t in 0..DISTANCES {
        let turn = lines.next().ok_or("truncated")?;
        if turn != format!("TURN {t}") {
            return Err(format!("expected `TURN {t}`, found `{turn}`"));
        }
        let mut rows = Vec::with_capacity(BEARINGS);
        for _ in 0..BEARINGS {
            let line = lines.next().ok_or("truncated")?;
            let mut row = [0.0; SENSORS];
            let mut n = 0;
            for (i, v) in line.split_whitespace().enumerate() {
                *row.get_mut(i).ok_or_else(|| format!("too many values: `{line}`"))? =
                    v.parse().map_err(|e| format!("`{v}`: {e}"))?;
                n += 1;
            }
            if n != SENSORS {
                return Err(format!("expected 8 values: `{line}`"));
            }
            rows.push(row);
        }
        table.push(rows);
    }
    if lines.next() != Some("END") {
        return Err("missing END".into());
    }
    Ok(table)
}

fn distance(t: usize) -> f32 {
    FIRST_MM + STEP_MM * t as f32
}

/// Bearing index `b` is `2 b` degrees clockwise from the heading; returns the
/// direction in radians counter-clockwise.
fn direction(b: usize) -> f32 {
    -(2.0 * b as f32).to_radians()
}

fn test_world(objects: Option<Objects>) -> World {
    World {
        arena: [400.0, 600.0],
        body: Body { radius: BODY, wheel_noise: 0.0, sensor_noise: 0.0, ..Body::default() },
        charger: None,
        battery: None,
        objects,
        items: Default::default(),
        robots: 1,
    }
}

/// Simulated readings in front of a wall at every distance and bearing.
fn simulate_wall() -> Table {
    let mut sim = Sim::new(&test_world(None), 0);
    let mut out = Vec::new();
    for t in 0..DISTANCES {
        let mut rows = Vec::new();
        for b in 0..BEARINGS {
            // The west wall's outward normal points to -x (pi); the robot faces
            // so that the wall lies at the table's bearing.
            let pose = Pose { x: BODY + distance(t), y: 300.0, theta: std::f32::consts::PI - direction(b) };
            assert!(sim.set_pose(pose));
            let mut p = [0.0; CHANNELS];
            sim.sense(&mut p);
            rows.push(std::array::from_fn(|s| p[CH_IR + s]));
        }
        out.push(rows);
    }
    out
}

/// Simulated readings in front of a 25 mm cylinder at every distance and bearing.
fn simulate_cylinder() -> Table {
    let objects = Objects { count: 1, diameter: 2.0 * CYL_RADIUS, virtual_: true };
    let mut sim = Sim::new(&test_world(Some(objects)), 0);
    assert!(sim.set_pose(Pose { x: 200.0, y: 300.0, theta: 0.0 }));
    let mut out = Vec::new();
    for t in 0..DISTANCES {
        let mut rows = Vec::new();
        for b in 0..BEARINGS {
            let r = BODY + distance(t) + CYL_RADIUS;
            let a = direction(b);
            assert!(sim.set_object(0, 200.0 + r * a.cos(), 300.0 + r * a.sin()));
            let mut p = [0.0; CHANNELS];
            sim.sense(&mut p);
            rows.push(std::array::from_fn(|s| p[CH_IR + s]));
        }
        out.push(rows);
    }
    out
}

/// Mean and worst absolute error per sensor.
fn errors(model: &Table, real: &Table) -> [(f32, f32); SENSORS] {
    let mut e = [(0.0, 0.0); SENSORS];
    for (mt, rt) in model.iter().zip(real) {
        for (m, r) in mt.iter().zip(rt) {
            for s in 0..SENSORS {
                let d = (m[s] - r[s]).abs();
                e[s].0 += d;
                e[s].1 = f32::max(e[s].1, d);
            }
        }
    }
    for x in &mut e {
        x.0 /= (DISTANCES * BEARINGS) as f32;
    }
    e
}

fn report(name: &str, e: &[(f32, f32); SENSORS]) {
    println!("{name}: sensor  mean |err|  worst |err|");
    for (s, (mean, worst)) in e.iter().enumerate() {
        println!("{name}:   {s}      {mean:.4}      {worst:.4}");
    }
}

#[test]
fn the_data_files_parse() {
    let Some((wall, cyl)) = tables() else { return };
    assert_eq!(wall.len(), DISTANCES);
    assert_eq!(cyl[19].len(), BEARINGS);
    assert!(wall.iter().flatten().flatten().all(|v| (0.0..=1.0).contains(v)));
    assert!(parse("8 180 20 5 2\nTURN 1\n").is_err());
}

#[test]
fn the_model_matches_the_real_wall_and_cylinder_readings() {
    let Some((wall, cyl)) = tables() else { return };
    let ew = errors(&simulate_wall(), &wall);
    let ec = errors(&simulate_cylinder(), &cyl);
    report("wall", &ew);
    report("cylinder", &ec);
    for s in 1..=4 {
        assert!(ew[s].0 <= 0.05, "wall, sensor {s}: mean error {}", ew[s].0);
        assert!(ec[s].0 <= 0.05, "cylinder, sensor {s}: mean error {}", ec[s].0);
    }
    for s in [0, 5, 6, 7] {
        assert!(ew[s].0 <= 0.08 && ec[s].0 <= 0.08, "sensor {s}: {:?} {:?}", ew[s], ec[s]);
    }
}

// ---------------------------------------------------------------- fitting

/// One data point of one sensor: the geometry and the real reading.
struct Point {
    wall: bool,
    /// Direction to the surface (wall normal or cylinder centre), robot frame.
    dir: [f32; 2],
    /// Distance from the robot centre to the wall, or to the cylinder centre.
    dist: f32,
    value: f32,
}

/// Parameters of one sensor: position, axis (degrees), wall reach, decay,
/// focus, cylinder reach, decay, focus.
type Params = [f32; 8];

fn reading(p: &Params, pt: &Point, knees: (f32, f32)) -> f32 {
    let (sp, cp) = p[0].to_radians().sin_cos();
    let (sa, ca) = p[1].to_radians().sin_cos();
    let (px, py) = (BODY * cp, BODY * sp);
    if pt.wall {
        let d = pt.dist - (px * pt.dir[0] + py * pt.dir[1]);
        let cos_a = ca * pt.dir[0] + sa * pt.dir[1];
        ir::saturate((p[2] - d) / p[3] + p[4] * (cos_a - 1.0), knees.0)
    } else {
        let vx = pt.dist * pt.dir[0] - px;
        let vy = pt.dist * pt.dir[1] - py;
        let dist = (vx * vx + vy * vy).sqrt();
        let cos_a = (ca * vx + sa * vy) / dist;
        ir::saturate((p[5] - (dist - CYL_RADIUS)) / p[6] + p[7] * (cos_a - 1.0), knees.1)
    }
}

fn mae(p: &Params, pts: &[Point], knees: (f32, f32)) -> f32 {
    pts.iter().map(|pt| (reading(p, pt, knees) - pt.value).abs()).sum::<f32>() / pts.len() as f32
}

/// Hooke-Jeeves pattern search on the mean absolute error.
fn fit(start: Params, pts: &[Point], knees: (f32, f32)) -> (Params, f32) {
    let mut p = start;
    let mut best = mae(&p, pts, knees);
    let mut step: Params = [4.0, 4.0, 2.0, 1.0, 2.0, 2.0, 1.0, 2.0];
    let lower: Params = [-360.0, -360.0, 0.0, 0.5, 0.0, 0.0, 0.5, 0.0];
    for _ in 0..200 {
        let mut improved = false;
        for i in 0..8 {
            for sign in [1.0, -1.0] {
                let mut q = p;
                q[i] = (q[i] + sign * step[i]).max(lower[i]);
                let e = mae(&q, pts, knees);
                if e < best {
                    best = e;
                    p = q;
                    improved = true;
                    break;
                }
            }
        }
        if !improved {
            step.iter_mut().for_each(|s| *s *= 0.5);
            if step[3] < 0.01 {
                break;
            }
        }
    }
    (p, best)
}

fn points(wall: &Table, cyl: &Table, s: usize) -> Vec<Point> {
    let mut pts = Vec::new();
    for (table, is_wall) in [(wall, true), (cyl, false)] {
        for (t, rows) in table.iter().enumerate() {
            for (b, row) in rows.iter().enumerate() {
                let a = direction(b);
                let dist = BODY + distance(t) + if is_wall { 0.0 } else { CYL_RADIUS };
                pts.push(Point { wall: is_wall, dir: [a.cos(), a.sin()], dist, value: row[s] });
            }
        }
    }
    pts
}

/// Fits [`KHEPERA`] to the data and prints it (slow; run on demand with
/// `cargo test -p shaping-runtime --test ir_data -- --ignored --nocapture`).
#[test]
#[ignore]
fn fit_ir_model() {
    let Some((wall, cyl)) = tables() else { return };
    let pts: Vec<Vec<Point>> = (0..SENSORS).map(|s| points(&wall, &cyl, s)).collect();
    let start = |s: usize| -> Params {
        let m = &KHEPERA;
        [
            m.position_deg[s],
            m.axis_deg[s],
            m.wall.reach[s],
            m.wall.decay[s],
            m.wall.focus[s],
            m.cylinder.reach[s],
            m.cylinder.decay[s],
            m.cylinder.focus[s],
        ]
    };
    let mut best: Option<(f32, (f32, f32), Vec<Params>)> = None;
    // `IR_FIT_KNEES=a,b` fits with these knees only.
    let grid: Vec<(f32, f32)> = match std::env::var("IR_FIT_KNEES") {
        Ok(v) => {
            let k: Vec<f32> = v.split(',').filter_map(|x| x.trim().parse().ok()).collect();
            vec![(k.first().copied().unwrap_or(2.0), k.get(1).copied().unwrap_or(2.0))]
        }
        Err(_) => [1.0, 1.5, 2.0, 3.0, 4.0]
            .iter()
            .flat_map(|&a| [1.0, 1.5, 2.0, 3.0, 4.0].map(|b| (a, b)))
            .collect(),
    };
    for &(kw, kc) in &grid {
        {
            let fits: Vec<(Params, f32)> = (0..SENSORS).map(|s| fit(start(s), &pts[s], (kw, kc))).collect();
            let total = fits.iter().map(|f| f.1).sum::<f32>() / SENSORS as f32;
            println!("knees {kw} {kc}: mean abs error {total:.4}");
            if best.as_ref().is_none_or(|b| total < b.0) {
                best = Some((total, (kw, kc), fits.into_iter().map(|f| f.0).collect()));
            }
        }
    }
    let Some((total, (kw, kc), ps)) = best else { return };
    let col = |i: usize| ps.iter().map(|p| format!("{:.2}", p[i])).collect::<Vec<_>>().join(", ");
    println!("best mean abs error {total:.4}");
    println!("pub const KHEPERA: IrModel = IrModel {{");
    println!("    position_deg: [{}],", col(0));
    println!("    axis_deg: [{}],", col(1));
    println!("    wall: Response {{");
    println!("        reach: [{}],\n        decay: [{}],\n        focus: [{}],", col(2), col(3), col(4));
    println!("        knee: {kw:.1},\n    }},");
    println!("    cylinder: Response {{");
    println!("        reach: [{}],\n        decay: [{}],\n        focus: [{}],", col(5), col(6), col(7));
    println!("        knee: {kc:.1},\n    }},");
    println!("    cylinder_r0: {:.1},\n}};", KHEPERA.cylinder_r0);
    // Keep the printed types in use.
    let _: Option<(IrModel, Response)> = None;
}
