//! Draws every picture from small synthetic data.
//!
//! Set `SHAPING_KEEP_PLOTS=1` to keep the files (the path is printed) for a look.

use std::fs;
use std::path::{Path, PathBuf};

use super::render::{dash, render_with, with_ext};
use super::series::median;
use super::*;

/// A fresh folder for one test; removed on drop unless `SHAPING_KEEP_PLOTS` is set.
struct Dir(PathBuf);

impl Dir {
    fn new(name: &str) -> Dir {
        let d = std::env::temp_dir().join(format!("shaping-plot-{}-{name}", std::process::id()));
        let _ = fs::remove_dir_all(&d);
        fs::create_dir_all(&d).expect("temp dir");
        Dir(d)
    }

    fn stem(&self, name: &str) -> PathBuf {
        self.0.join(name)
    }
}

impl Drop for Dir {
    fn drop(&mut self) {
        if std::env::var_os("SHAPING_KEEP_PLOTS").is_some() {
            eprintln!("plots kept in {}", self.0.display());
        } else {
            let _ = fs::remove_dir_all(&self.0);
        }
    }
}

/// A small deterministic generator (xorshift) so the test data need no crate.
struct Noise(u64);

impl Noise {
    fn next(&mut self) -> f32 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 40) as f32 / (1u64 << 24) as f32
    }
}

const PNG_SIGNATURE: [u8; 8] = [0x89, b'P', b'N', b'G', b'\r', b'\n', 0x1a, b'\n'];

fn assert_written(stem: &Path) {
    let svg = fs::read(with_ext(stem, "svg")).expect("svg written");
    let png = fs::read(with_ext(stem, "png")).expect("png written");
    assert!(svg.starts_with(b"<svg"), "{} is not an SVG", stem.display());
    assert!(svg.len() > 500, "{} SVG is nearly empty", stem.display());
    assert!(png.starts_with(&PNG_SIGNATURE), "{} has no PNG signature", stem.display());
    assert!(png.len() > 1000, "{} PNG is nearly empty", stem.display());
}

fn run(seed: u64, gens: std::ops::Range<u32>, scale: f32) -> Vec<GenPoint> {
    let mut n = Noise(seed);
    gens.map(|g| {
        let t = g as f32;
        let best = scale * (0.25 + 0.6 * (1.0 - (-t / 12.0).exp())) + 0.05 * scale * n.next();
        let mean = best * (0.45 + 0.15 * n.next());
        GenPoint { generation: g, best, mean }
    })
    .collect()
}

fn stages() -> Vec<(u32, String)> {
    vec![(0, "stage 1: recharge".into()), (40, "stage 2: gripper".into())]
}

fn staged_run(seed: u64) -> Vec<GenPoint> {
    let mut r = run(seed, 0..40, 1.0);
    r.extend(run(seed + 1, 0..40, 9.0).into_iter().map(|g| GenPoint { generation: g.generation + 40, ..g }));
    r
}

fn reinforcement(seed: u64, n: usize, change: Option<usize>) -> Vec<f32> {
    let mut z = Noise(seed);
    (0..n)
        .map(|i| {
            let since = change.filter(|&c| i >= c).map_or(i, |c| i - c);
            let p = 0.5 + 0.35 * (1.0 - (-(since as f32) / 150.0).exp());
            if z.next() < p {
                1.0
            } else {
                -1.0
            }
        })
        .collect()
}

fn trace() -> ActivationTrace {
    let modules: Vec<String> = ["wander", "avoid", "light_follow", "recharge", "grip", "release"]
        .iter()
        .map(|s| s.to_string())
        .collect();
    let mut z = Noise(7);
    let n = 225;
    let mut t = ActivationTrace { modules, ..ActivationTrace::default() };
    let mut battery = 1.0f32;
    for i in 0..n {
        battery = if (150..165).contains(&i) { (battery + 0.06).min(1.0) } else { battery - 0.0055 };
        let low = battery < 0.35 || (140..165).contains(&i);
        let row = vec![
            0.55 + 0.1 * z.next(),
            if i % 23 < 3 { 0.8 + 0.1 * z.next() } else { 0.2 * z.next() },
            if low { 0.75 + 0.1 * z.next() } else { 0.1 * z.next() },
            if (150..165).contains(&i) { 0.95 } else { 0.05 * z.next() },
            if i % 40 == 10 { 0.9 } else { 0.15 * z.next() },
            if i % 40 == 30 { 0.9 } else { 0.15 * z.next() },
        ];
        let (w, _) =
            row.iter().enumerate().fold((0, f32::MIN), |b, (k, &a)| if a > b.1 { (k, a) } else { b });
        t.winner.push(w as u16);
        t.activations.push(row);
        t.battery.push(battery.max(0.0));
        t.holding.push(i % 40 > 10 && i % 40 < 30);
    }
    t
}

fn scene(by_module: bool) -> TrajectoryScene {
    let mut z = Noise(11);
    let (mut x, mut y, mut th) = (200.0f32, 300.0f32, 0.3f32);
    let mut path = Vec::new();
    let mut modules = Vec::new();
    for i in 0..300 {
        th += 0.35 * (z.next() - 0.5);
        let (nx, ny) = (x + 12.0 * th.cos(), y + 12.0 * th.sin());
        let near_wall = !(35.0..365.0).contains(&nx) || !(35.0..565.0).contains(&ny);
        if near_wall {
            th += 1.9;
        } else {
            (x, y) = (nx, ny);
        }
        path.push([x, y, th]);
        modules.push(if near_wall {
            1
        } else if i > 200 {
            2
        } else {
            0
        });
    }
    let objects = (0..8)
        .map(|k| SceneObject {
            x: 40.0 + 320.0 * z.next(),
            y: 40.0 + 520.0 * z.next(),
            radius: 5.0,
            virtual_: k >= 6,
            collected: k % 3 == 0,
        })
        .chain(std::iter::once(SceneObject {
            x: -20.0,
            y: 200.0,
            radius: 5.0,
            virtual_: false,
            collected: true,
        }))
        .collect();
    TrajectoryScene {
        arena: [400.0, 600.0],
        bar: Some(([100.0, 600.0], [300.0, 600.0])),
        lamp: Some([200.0, 600.0]),
        objects,
        path,
        body_radius: 27.5,
        marks: vec![(40, "grip 1".into()), (120, "release 1".into()), (260, "grip 2".into())],
        path_modules: by_module.then_some(modules),
        module_names: vec!["wander".into(), "avoid".into(), "light_follow".into()],
        ..TrajectoryScene::default()
    }
}

#[test]
fn every_picture_is_written_as_svg_and_png() {
    let d = Dir::new("all");
    let s = d.stem("fig4_9");
    fitness_curves(&s, "Fitness during incremental evolution", &staged_run(1), &stages(), true).unwrap();
    assert_written(&s);

    let s = d.stem("fig4_raw");
    fitness_curves(&s, "Stage 1 fitness (raw)", &run(3, 0..40, 1.0), &[], false).unwrap();
    assert_written(&s);

    let runs: Vec<Vec<GenPoint>> = (0..5).map(|k| staged_run(10 + 7 * k)).collect();
    let s = d.stem("fitness_seeds");
    multi_seed_fitness(&s, "Fitness over 5 seeds", &runs, &stages()).unwrap();
    assert_written(&s);

    let s = d.stem("fig5");
    let series = vec![("avoid".to_string(), reinforcement(5, 800, None))];
    rolling_reinforcement(&s, "Obstacle-avoidance module learning", &series, 30, &[]).unwrap();
    assert_written(&s);

    let s = d.stem("fig13");
    let series = vec![
        ("grip".to_string(), reinforcement(8, 900, Some(450))),
        ("release".to_string(), reinforcement(9, 900, Some(500))),
    ];
    rolling_reinforcement(
        &s,
        "Object-gripping module re-adapting",
        &series,
        30,
        &[(450, "objects 10→25 mm".into())],
    )
    .unwrap();
    assert_written(&s);

    let s = d.stem("fig11");
    activation_trace(&s, "Module activations of the best individual", &trace()).unwrap();
    assert_written(&s);

    let s = d.stem("path_time");
    trajectory(&s, "Path of the best individual", &scene(false)).unwrap();
    assert_written(&s);

    let s = d.stem("path_modules");
    trajectory(&s, "Path coloured by winning module", &scene(true)).unwrap();
    assert_written(&s);
}

#[test]
fn same_data_give_the_same_bytes() {
    let d = Dir::new("determinism");
    let (a, b) = (d.stem("a"), d.stem("b"));
    for stem in [&a, &b] {
        activation_trace(stem, "trace", &trace()).unwrap();
    }
    assert_eq!(fs::read(with_ext(&a, "svg")).unwrap(), fs::read(with_ext(&b, "svg")).unwrap());
    assert_eq!(fs::read(with_ext(&a, "png")).unwrap(), fs::read(with_ext(&b, "png")).unwrap());
    for stem in [&a, &b] {
        trajectory(stem, "path", &scene(false)).unwrap();
    }
    assert_eq!(fs::read(with_ext(&a, "svg")).unwrap(), fs::read(with_ext(&b, "svg")).unwrap());
}

#[test]
fn without_a_font_everything_but_text_is_drawn() {
    let d = Dir::new("notext");
    let s = d.stem("fig4");
    let gens = run(3, 0..40, 1.0);
    let stages = stages();
    let fig = fitness::Single { title: "no text", gens: &gens, stages: &stages, smooth: false };
    render_with(&s, &fig, false).unwrap();
    assert_written(&s);
    let svg = fs::read_to_string(with_ext(&s, "svg")).unwrap();
    assert!(!svg.contains("<text"), "text drawn without a font");
    assert!(svg.contains("<polyline"), "no lines drawn");

    let t = trace();
    render_with(&s, &trace::Trace { title: "no text", t: &t }, false).unwrap();
    assert!(!fs::read_to_string(with_ext(&s, "svg")).unwrap().contains("<text"));
    let sc = scene(true);
    render_with(&s, &arena::Arena::new("no text", &sc), false).unwrap();
    assert!(!fs::read_to_string(with_ext(&s, "svg")).unwrap().contains("<text"));
    let series = vec![("grip".to_string(), reinforcement(8, 300, None))];
    let marks = vec![(100, "change".to_string())];
    let fig = series::Reinforcement { title: "", series: &series, window: 30, marks: &marks };
    render_with(&s, &fig, false).unwrap();
    assert!(!fs::read_to_string(with_ext(&s, "svg")).unwrap().contains("<text"));
}

#[test]
fn text_is_drawn_when_a_font_is_found() {
    let d = Dir::new("text");
    let s = d.stem("fig4");
    fitness_curves(&s, "Stage 1", &run(3, 0..40, 1.0), &stages(), false).unwrap();
    let svg = fs::read_to_string(with_ext(&s, "svg")).unwrap();
    if font_path().is_some() {
        assert!(svg.contains("Stage 1") && svg.contains("generation") && svg.contains("best individual"));
    } else {
        assert!(!svg.contains("<text"));
    }
}

#[test]
fn bad_input_is_an_error_naming_the_file() {
    let d = Dir::new("errors");
    let s = d.stem("bad");
    let e = fitness_curves(&s, "t", &[], &[], false).unwrap_err();
    assert!(e.to_string().contains("bad") && e.to_string().contains("no generations"), "{e}");
    assert!(multi_seed_fitness(&s, "t", &[vec![], vec![]], &[]).is_err());
    assert!(rolling_reinforcement(&s, "t", &[("a".into(), vec![1.0])], 0, &[]).is_err());
    assert!(rolling_reinforcement(&s, "t", &[], 30, &[]).is_err());

    let mut t = trace();
    t.battery.pop();
    let e = activation_trace(&s, "t", &t).unwrap_err();
    assert!(e.to_string().contains("`battery` has 224 actions but `activations` has 225"), "{e}");
    let mut t = trace();
    t.activations[3].pop();
    assert!(activation_trace(&s, "t", &t).unwrap_err().to_string().contains("action 3 has 5 activations"));

    let mut sc = scene(false);
    sc.marks.push((999, "late".into()));
    let e = trajectory(&s, "t", &sc).unwrap_err();
    assert!(e.to_string().contains("mark `late` is at path index 999"), "{e}");
    let mut sc = scene(true);
    sc.path_modules.as_mut().unwrap().pop();
    assert!(trajectory(&s, "t", &sc).is_err());
    let mut sc = scene(false);
    sc.arena = [0.0, 600.0];
    assert!(trajectory(&s, "t", &sc).is_err());
    sc.arena = [400.0, 600.0];
    sc.path[5][0] = f32::NAN;
    assert!(trajectory(&s, "t", &sc).unwrap_err().to_string().contains("path point 5"));
    assert!(!with_ext(&s, "svg").exists(), "an error must not leave a picture");
}

#[test]
fn odd_values_are_drawn_not_refused() {
    let d = Dir::new("odd");
    // One generation, non-finite values, a constant series, an empty path.
    let gens = [
        GenPoint { generation: 5, best: 0.5, mean: f32::NAN },
        GenPoint { generation: 6, best: f32::INFINITY, mean: 0.2 },
    ];
    fitness_curves(&d.stem("a"), "", &gens, &[(5, "s".into())], true).unwrap();
    assert_written(&d.stem("a"));
    let runs = vec![vec![GenPoint { generation: 0, best: 1.0, mean: 1.0 }]];
    multi_seed_fitness(&d.stem("b"), "", &runs, &[]).unwrap();
    let nan = vec![vec![GenPoint { generation: 0, best: f32::NAN, mean: f32::NAN }]];
    multi_seed_fitness(&d.stem("b"), "", &nan, &[]).unwrap();
    assert_written(&d.stem("b"));
    rolling_reinforcement(&d.stem("c"), "", &[("x".into(), vec![0.0; 5])], 30, &[(900, "far".into())])
        .unwrap();
    let sc = TrajectoryScene { arena: [400.0, 600.0], body_radius: 27.5, ..TrajectoryScene::default() };
    trajectory(&d.stem("d"), "", &sc).unwrap();
    let t = ActivationTrace {
        modules: vec!["only".into()],
        activations: vec![vec![2.0]],
        winner: vec![u16::MAX],
        ..ActivationTrace::default()
    };
    activation_trace(&d.stem("e"), "", &t).unwrap();
    assert_written(&d.stem("e"));
}

#[test]
fn a_dot_in_the_stem_is_kept() {
    let d = Dir::new("stem");
    let s = d.stem("fig4.seed.3");
    fitness_curves(&s, "t", &run(1, 0..10, 1.0), &[], false).unwrap();
    assert!(d.0.join("fig4.seed.3.svg").exists() && d.0.join("fig4.seed.3.png").exists());
    let nested = d.0.join("new").join("dir").join("f");
    fitness_curves(&nested, "t", &run(1, 0..10, 1.0), &[], false).unwrap();
    assert_written(&nested);
}

#[test]
fn rolling_mean_is_trailing_and_skips_missing_values() {
    let v = [1.0, -1.0, 1.0, 1.0, f32::NAN, -1.0];
    let r = rolling_mean(&v, 3);
    let want = [1.0, 0.0, 1.0 / 3.0, 1.0 / 3.0, 1.0, 0.0];
    for (a, b) in r.iter().zip(want) {
        assert!((a - b).abs() < 1e-6, "{r:?}");
    }
    assert_eq!(rolling_mean(&v, 1)[..4], v[..4]);
    assert!(rolling_mean(&[f32::NAN], 3)[0].is_nan());
}

#[test]
fn median_of_odd_and_even_counts() {
    assert_eq!(median(&[3.0, 1.0, 2.0]), 2.0);
    assert_eq!(median(&[4.0, 1.0, 3.0, 2.0]), 2.5);
    assert!(median(&[]).is_nan());
}

#[test]
fn dashes_cover_the_on_part_of_the_pattern() {
    let line = [(0, 0), (50, 0), (100, 0)];
    let pieces = dash(&line, &[10.0, 5.0]);
    // 100 px of a 15 px period: on at 0-10, 15-25, ..., 90-100 → 7 pieces.
    assert_eq!(pieces.len(), 7, "{pieces:?}");
    let on: i32 = pieces.iter().map(|p| p.last().unwrap().0 - p[0].0).sum();
    assert_eq!(on, 70);
    assert_eq!(dash(&line, &[]), vec![line.to_vec()]);
    assert_eq!(dash(&line, &[0.0, 1.0]), vec![line.to_vec()]);
}

/// A path that runs into the east wall and bounces off it, repeating points
/// as a blocked robot does, never draws beyond the wall (repeated points once
/// drew long spikes in the PNG).
#[test]
fn a_bouncing_path_with_repeated_points_stays_inside_the_arena() {
    use super::arena::Arena;
    use super::render::Figure;
    use plotters::prelude::*;
    // A robot pushed into the east wall, backing off and pushing again:
    // near-reversals at many angles.
    let mut path = vec![[300.0f32, 300.0, 0.0]];
    for k in 0..40 {
        let a = 0.05 * k as f32;
        let y = 300.0 + 0.3 * k as f32;
        path.push([372.0, y, 0.0]);
        path.push([372.0 - 18.0 * a.cos().abs(), y + 18.0 * a.sin(), 0.0]);
    }
    let n = path.len();
    let sc = TrajectoryScene {
        arena: [400.0, 600.0],
        bar: None,
        lamp: None,
        objects: vec![],
        path,
        body_radius: 27.5,
        marks: vec![],
        path_modules: Some(vec![0; n]),
        module_names: vec!["a".into()],
        ..TrajectoryScene::default()
    };
    let fig = Arena::new("", &sc);
    let (w, h) = fig.size(false);
    let mut buf = vec![0u8; (w * h * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
        fig.draw(&root, false).unwrap();
        root.present().unwrap();
    }
    let px = |x: u32, y: u32| {
        let i = ((y * w + x) * 3) as usize;
        [buf[i], buf[i + 1], buf[i + 2]]
    };
    // The east wall: the right-most column with the wall's ink in the row of the path.
    let row = (0..h).find(|&r| (0..w).any(|c| px(c, r) != [255, 255, 255])).unwrap() + h / 2;
    let wall = (0..w).rev().find(|&c| px(c, row) == [0x28, 0x28, 0x28]).expect("the east wall is drawn");
    for r in 0..h {
        for c in wall + 1..w {
            assert_eq!(
                px(c, r),
                [255, 255, 255],
                "pixel ({c}, {r}) east of the wall (column {wall}) is drawn"
            );
        }
    }
}

#[test]
fn polylines_are_cut_at_reversals_and_repeated_points_dropped() {
    use super::arena::unmitered;
    let l = [(0.0, 0.0), (1.0, 0.0), (1.0, 0.0), (2.0, 0.0), (1.5, 0.5), (1.0, 1.0), (1.5, 1.0)];
    assert_eq!(
        unmitered(&l),
        vec![
            vec![(0.0, 0.0), (1.0, 0.0), (2.0, 0.0)],
            vec![(2.0, 0.0), (1.5, 0.5), (1.0, 1.0)],
            vec![(1.0, 1.0), (1.5, 1.0)]
        ]
    );
    assert_eq!(unmitered(&[(3.0, 4.0)]), vec![vec![(3.0, 4.0), (3.0, 4.0)]]);
    assert_eq!(unmitered(&[(3.0, 4.0), (3.0, 4.0)]), vec![vec![(3.0, 4.0), (3.0, 4.0)]]);
}

#[test]
fn declared_world_items_are_drawn() {
    let d = Dir::new("items");
    let plain = scene(false);
    let items = TrajectoryScene {
        walls: vec![([100.0, 100.0], [300.0, 100.0])],
        cylinders: vec![[200.0, 400.0, 25.0]],
        lamps: vec![[350.0, 550.0]],
        zones: vec![([0.0, 500.0], [100.0, 600.0], 0.0, true)],
        ..scene(false)
    };
    trajectory(&d.stem("plain"), "", &plain).unwrap();
    trajectory(&d.stem("items"), "", &items).unwrap();
    let svg = |name: &str| fs::read_to_string(d.0.join(format!("{name}.svg"))).unwrap();
    let (a, b) = (svg("plain"), svg("items"));
    // The cylinder's grey and the black (grey 0) zone appear only with the items.
    for colour in ["#5A5A5A", "#9B9B9B"] {
        assert!(!a.contains(colour) && b.contains(colour), "{colour}");
    }
    let bad = TrajectoryScene { zones: vec![([0.0, 0.0], [1.0, 1.0], 2.0, false)], ..scene(false) };
    assert!(trajectory(&d.stem("bad"), "", &bad).is_err());
}

/// A team's other robots are drawn: their paths and bodies, each in its
/// own colour.
#[test]
fn a_teams_other_robots_are_drawn_each_in_its_colour() {
    let one = TrajectoryScene {
        path: vec![[60.0, 60.0, 0.0], [70.0, 60.0, 0.0]],
        marks: Vec::new(),
        path_modules: None,
        ..scene(true)
    };
    let others =
        vec![vec![[300.0, 100.0, 1.0], [300.0, 200.0, 1.5]], vec![[100.0, 450.0, 0.0], [200.0, 450.0, 0.0]]];
    let team = TrajectoryScene { others: others.clone(), ..one.clone() };
    let (a, b) = (trajectory_rgb(&one).unwrap(), trajectory_rgb(&team).unwrap());
    assert_eq!((a.width, a.height), (b.width, b.height), "the view holds both");
    let changed: Vec<usize> = (0..a.pixels.len() / 3)
        .filter(|&i| a.pixels[3 * i..3 * i + 3] != b.pixels[3 * i..3 * i + 3])
        .collect();
    assert!(changed.len() > 500, "{} pixels changed", changed.len());
    // In each robot's own colour, which the one robot's picture has nowhere.
    for k in 0..2 {
        let c = super::arena::team_colour(k);
        let rgb = [c.0, c.1, c.2];
        let has = |f: &Rgb| f.pixels.chunks(3).filter(|p| *p == rgb).count();
        assert_eq!(has(&a), 0, "robot {}'s colour", k + 1);
        assert!(has(&b) > 50, "robot {}'s colour: {} pixels", k + 1, has(&b));
    }
    // A bad pose of another robot is refused, naming it.
    let bad = TrajectoryScene { others: vec![vec![[f32::NAN, 0.0, 0.0]]], ..one };
    let err = trajectory_rgb(&bad).unwrap_err().to_string();
    assert!(err.contains("robot 1's path"), "{err}");
}

/// A heterogeneous team's robots are drawn in their role's colour, and the
/// legend names each role beside its colour.
#[test]
fn a_teams_roles_each_have_a_colour_named_in_the_legend() {
    let one = TrajectoryScene {
        path: vec![[60.0, 60.0, 0.0], [70.0, 60.0, 0.0]],
        marks: Vec::new(),
        path_modules: None,
        ..scene(true)
    };
    let others = vec![
        vec![[300.0, 100.0, 1.0], [300.0, 200.0, 1.5]],
        vec![[100.0, 450.0, 0.0], [200.0, 450.0, 0.0]],
        vec![[400.0, 400.0, 0.0], [420.0, 300.0, 0.0]],
    ];
    let roles = vec![("scout".to_string(), 2), ("seed".to_string(), 2)];
    let team = TrajectoryScene { others, roles, ..one };
    let f = trajectory_rgb(&team).unwrap();
    let has = |c: plotters::style::RGBColor| f.pixels.chunks(3).filter(|p| *p == [c.0, c.1, c.2]).count();
    for r in 0..2 {
        assert!(has(super::arena::role_colour(r)) > 50, "role {r}'s colour");
    }
    // The clones' colours are not used.
    assert_eq!(has(super::arena::team_colour(0)), 0);
    let d = Dir::new("roles");
    trajectory(&d.stem("roles"), "team", &team).unwrap();
    let svg = fs::read_to_string(with_ext(&d.stem("roles"), "svg")).unwrap();
    if font_path().is_some() {
        assert!(
            svg.contains("role scout: robots 0 to 1") && svg.contains("role seed: robots 2 to 3"),
            "legend"
        );
    }
    let c = super::arena::role_colour(1);
    assert!(
        svg.contains(&format!("#{:02X}{:02X}{:02X}", c.0, c.1, c.2)),
        "the seed role's colour in the SVG"
    );
}
