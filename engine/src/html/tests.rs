//! The data a report embeds: the recorded episode, the stage views, the
//! fitness series and the page around them.

use std::path::Path;

use rand::{Rng, SeedableRng};
use shaping_runtime::controller::{run_episode, EpisodeOptions, Trace};
use shaping_runtime::genome::Genome;
use shaping_runtime::program::{Param, Program, StageRun};

use super::data::{self, seed_series, stage_view, ReportData};
use super::{embedded_json, page};
use crate::episode::{run_recorded, Episode};
use crate::run::{before_after, BeforeAfter, Lives};
use crate::rundir::{parse_generations, GenRow};

fn program() -> Program {
    let src = include_str!("../../../tests/cli/report.bat");
    shaping_compiler::compile(src, "report.bat").expect("the report test architecture compiles")
}

fn random_genome(bits: u32, seed: u64) -> Genome {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    Genome { bits: (0..bits).map(|_| rng.random_range(0..2u8)).collect() }
}

/// The objects of every action, rebuilt from the world's start and the
/// changes, as the page does.
fn objects_per_action(ep: &Episode) -> Vec<Vec<[f32; 4]>> {
    let n = ep.actions.x.len();
    let mut out = Vec::with_capacity(n);
    for (wi, w) in ep.worlds.iter().enumerate() {
        let end = ep.worlds.get(wi + 1).map_or(n, |x| x.from as usize);
        let mut cur = w.objects.clone();
        for a in w.from as usize..end {
            for c in ep.actions.objects.iter().filter(|c| c[0] as usize == a) {
                cur[c[1] as usize] = [c[2], c[3], c[4], c[5]];
            }
            out.push(cur.clone());
        }
    }
    out
}

#[test]
fn a_recorded_episode_is_the_same_episode_and_its_columns_are_the_trace() {
    let p = program();
    let (i, stage) = p.stage("collect").unwrap();
    let genome = random_genome(stage.layout.bits, 7);
    let opts = EpisodeOptions { actions: 120, learning: true, seed: 11 };
    let mut plain = Trace::default();
    let expected = run_episode(stage, &genome, &opts, Some(&mut plain));
    let (result, trace, ep) = run_recorded(stage, &genome, &opts).unwrap();
    // Recording draws no random number: the same episode, action for action.
    assert_eq!(result, expected);
    assert_eq!(trace, plain);
    assert!(i == 1 && ep.gripper && ep.worlds.len() == 1);
    let n = trace.rows.len();
    assert!(n > 10, "the episode lasted {n} actions");
    let c = &ep.actions;
    for (k, r) in trace.rows.iter().enumerate() {
        // Rounded to 2 digits: half a unit, plus the f32 error of a value
        // halfway between two.
        let near = |a: f32, b: f32| (a - b).abs() <= 0.005 + 1e-4;
        assert!(
            near(c.x[k], r.pose.x) && near(c.y[k], r.pose.y),
            "action {k}: {:?} {:?}",
            (c.x[k], c.y[k]),
            r.pose
        );
        assert_eq!(c.winner[k], r.winner);
        assert_eq!(c.grips[k], r.grips);
        assert_eq!(c.holding[k], r.holding as u8);
        for m in 0..ep.modules.len() {
            // Rounded to 4 digits: half a unit, plus the f32 error of a
            // value halfway between two (0.99565 recorded as 0.9957).
            let (got, want) = (c.activation[m][k], r.activations[m]);
            assert!((got - want).abs() <= 5e-5 + 1e-6, "module {m} action {k}: {got} {want}");
            assert_eq!(c.reinforcement[m][k], r.reinforcement[m]);
        }
    }
    for v in [c.ir.len(), c.arm_down.len(), c.claw_closed.len(), c.barrier.len(), c.wheels.len()] {
        assert_eq!(v, n);
    }
    assert_eq!(ep.modules, trace.modules);
    // The robot starts in the world's start pose, and the objects are the
    // simulator's, one of 10 mm per declared object.
    let w = &ep.worlds[0];
    assert_eq!(w.objects.len(), 6);
    assert!(w.objects.iter().all(|o| (o[2] - 5.0).abs() < 1e-3 && o[3] == 0.0));
    assert!(w.start[0] > 0.0 && w.start[0] < w.arena[0] && w.start[1] > 0.0 && w.start[1] < w.arena[1]);
}

#[test]
fn object_changes_rebuild_the_recorded_objects_at_every_action() {
    let p = program();
    let (_, stage) = p.stage("collect").unwrap();
    // Search a few genomes for an episode where objects are gripped, so
    // that the objects do change.
    let mut tried = 0;
    for seed in 0..40 {
        let genome = random_genome(stage.layout.bits, seed);
        let opts = EpisodeOptions { actions: 200, learning: true, seed };
        let (result, _, ep) = run_recorded(stage, &genome, &opts).unwrap();
        tried += 1;
        if result.grips == 0 {
            continue;
        }
        let rebuilt = objects_per_action(&ep);
        assert_eq!(rebuilt.len(), ep.actions.x.len());
        assert!(!ep.actions.objects.is_empty());
        // An object is held exactly when the trace says the robot holds one.
        for (a, objs) in rebuilt.iter().enumerate() {
            let held = objs.iter().filter(|o| o[3] == 1.0).count();
            assert_eq!(held, ep.actions.holding[a] as usize, "action {a}");
        }
        return;
    }
    panic!("none of {tried} random genomes gripped an object");
}

/// The test stage `bigger` of a random individual with episode seed 5, its
/// index, and its lives `(actions, lives)` as given or else as declared.
fn bigger(lives: Option<(u32, u32)>) -> (usize, BeforeAfter) {
    let p = program();
    let (i, stage) = p.stage("bigger").unwrap();
    let parent = &p.stages[stage.parent.unwrap()];
    let genome = random_genome(stage.layout.bits, 3);
    let StageRun::Test { actions, lives: declared, learning } = stage.run else {
        panic!("bigger is a test stage")
    };
    let (actions, lives) = lives.unwrap_or((actions, declared));
    (i, before_after(parent, stage, &genome, Lives { actions, count: lives, learning }, 5, None).unwrap())
}

#[test]
fn a_test_stage_episode_has_both_worlds_and_the_objects_grow() {
    let (i, ba) = bigger(None);
    let ep = &ba.episode;
    assert_eq!(i, 2);
    assert_eq!(ep.worlds.len(), 2);
    assert_eq!(ep.worlds[0].stage, "collect");
    assert_eq!(ep.worlds[1].stage, "bigger");
    assert_eq!(ep.worlds[1].from, ba.switch);
    assert_eq!(ep.actions.x.len(), ba.trace.rows.len());
    assert!(ep.worlds[0].objects.iter().all(|o| (o[2] - 5.0).abs() < 1e-3));
    assert!(ep.worlds[1].objects.iter().all(|o| (o[2] - 12.5).abs() < 1e-3));
    let rebuilt = objects_per_action(ep);
    let s = ba.switch as usize;
    assert!(rebuilt[..s].iter().flatten().all(|o| o[2] < 6.0));
    assert!(rebuilt[s..].iter().flatten().all(|o| o[2] > 12.0));
}

/// Every life of a test stage is a part of its episode, in its world, and
/// the first life of each world is the one-life test's.
#[test]
fn a_test_stage_with_lives_records_every_life_as_a_part() {
    let (_, ba) = bigger(Some((40, 3)));
    let ep = &ba.episode;
    let names: Vec<&str> = ep.worlds.iter().map(|w| w.stage.as_str()).collect();
    assert_eq!(names, ["collect", "collect", "collect", "bigger", "bigger", "bigger"]);
    let starts: Vec<u32> = ep.worlds.iter().skip(1).map(|w| w.from).collect();
    assert_eq!(starts, ba.life_starts());
    assert_eq!(ep.worlds[3].from, ba.switch);
    assert_eq!((ba.before.len(), ba.after.len()), (3, 3));
    let total: u32 = ba.before.iter().chain(&ba.after).map(|r| r.actions).sum();
    assert_eq!(ba.trace.rows.len(), total as usize);
    assert_eq!(ep.actions.x.len(), total as usize);
    assert!(ba.trace.rows.iter().enumerate().all(|(i, r)| r.action as usize == i));
    // Each life starts in a fresh world: objects placed anew.
    assert_ne!(ep.worlds[0].objects, ep.worlds[1].objects);
    assert!(ep.worlds[4].objects.iter().all(|o| (o[2] - 12.5).abs() < 1e-3));
    let (_, one) = bigger(Some((40, 1)));
    assert_eq!(one.before[0], ba.before[0]);
    assert_eq!(one.episode.worlds[0], ep.worlds[0]);
    assert_eq!(one.episode.worlds[1].objects, ep.worlds[3].objects);
}

#[test]
fn stage_views_decode_link_weights_and_mark_what_a_stage_adds() {
    let p = program();
    let (i, stage) = p.stage("collect").unwrap();
    let genome = random_genome(stage.layout.bits, 9);
    let v = stage_view(&p, i, Some((&genome, "collect/best.genome".into())));
    assert_eq!(v.genes.len(), stage.layout.genes.len());
    for (l, lv) in stage.links.iter().zip(&v.links) {
        let Param::Gene(g) = l.weight else { panic!("links are evolvable") };
        let gene = &stage.layout.genes[g as usize];
        assert_eq!(lv.weight, Some(genome.decode(gene)));
        assert_eq!(lv.frozen, gene.frozen);
        // A link is new in `collect` exactly when one of its ends is.
        let new_end = [l.from, l.to].iter().any(|&m| stage.modules[m as usize].stage == 1);
        assert_eq!(lv.new, new_end, "link {} -> {}", l.from, l.to);
    }
    let names: Vec<(&str, bool)> = v.modules.iter().map(|m| (m.name.as_str(), m.new)).collect();
    assert_eq!(
        names,
        [("wander", false), ("avoid", false), ("follow", false), ("grip", true), ("release", true)]
    );
    let follow = &v.modules[2];
    assert_eq!(follow.sensors, ["light", "battery"]);
    assert!(
        v.modules[3].behavior.starts_with("script commit { toward(ir, 0.5) until"),
        "{}",
        v.modules[3].behavior
    );
    assert!(v.added.contains(&"sensors barrier".to_string()), "{:?}", v.added);
    assert!(v.added.iter().any(|a| a == "world: 6 objects of 10 mm, virtual"), "{:?}", v.added);
    // Frozen genes are the navigation stage's, with their decoded value and bits.
    let frozen = v.genes.iter().filter(|g| g.frozen).count();
    assert_eq!(frozen, p.stages[0].layout.genes.len());
    let g0 = &v.genes[0];
    assert_eq!((g0.stage.as_str(), g0.module.as_str(), g0.role.as_str()), ("navigation", "wander", "bias"));
    assert_eq!(g0.code.as_deref().map(str::len), Some(4));
    let bigger = stage_view(&p, 2, None);
    assert!(bigger.added.iter().any(|a| a == "world: 6 objects of 25 mm, virtual"), "{:?}", bigger.added);
    assert!(bigger.genes.iter().all(|g| g.value.is_none()));
}

#[test]
fn generations_csv_is_parsed_by_column_name_and_bad_lines_are_named() {
    let text = "stage,generation,stage_generation,best,mean,worst,best_index\n\
                a,0,0,0.5,0.25,0.1,3\n\
                b,1,0,0.75,0.5,0.2,1\n";
    let rows = parse_generations(text, Path::new("g.csv")).unwrap().rows;
    let row = |stage: &str, generation, best, mean, worst, index| GenRow {
        stage: stage.into(),
        generation,
        best,
        mean,
        worst: Some(worst),
        best_index: Some(index),
        ..GenRow::default()
    };
    assert_eq!(rows, [row("a", 0, 0.5, 0.25, 0.1, 3), row("b", 1, 0.75, 0.5, 0.2, 1)]);
    let bad =
        parse_generations("stage,generation,stage_generation,best,mean\na,0,0,x,1\n", Path::new("g.csv"));
    let msg = bad.unwrap_err().to_string();
    assert!(msg.contains("g.csv") && msg.contains("line 2") && msg.contains("`x`"), "{msg}");
    let missing = parse_generations("stage,best\n", Path::new("g.csv")).unwrap_err().to_string();
    assert!(missing.contains("no column `generation`"), "{missing}");
}

#[test]
fn seed_series_are_medians_with_the_range_of_the_best() {
    let row = |g: u32, best: f32, mean: f32| GenRow {
        stage: "s".into(),
        generation: g,
        stage_generation: g,
        best,
        mean,
        ..GenRow::default()
    };
    let seeds = vec![
        vec![row(0, 0.1, 0.0), row(1, 0.4, 0.2)],
        vec![row(0, 0.3, 0.1), row(1, 0.2, 0.1)],
        vec![row(0, 0.2, 0.3)],
    ];
    let s = seed_series("s", &seeds);
    assert_eq!(s.generation, [0, 1]);
    assert_eq!(s.best, [0.2, (0.4 + 0.2) / 2.0]);
    assert_eq!(s.mean, [0.1, (0.2 + 0.1) / 2.0]);
    assert_eq!(s.best_min, [0.1, 0.2]);
    assert_eq!(s.best_max, [0.3, 0.4]);
    assert_eq!(s.seeds, [3, 2]);
}

fn sample_data(title: &str) -> ReportData {
    let p = program();
    let (_, stage) = p.stage("collect").unwrap();
    let genome = random_genome(stage.layout.bits, 1);
    let (_, _, ep) =
        run_recorded(stage, &genome, &EpisodeOptions { actions: 50, learning: true, seed: 1 }).unwrap();
    ReportData {
        format: data::REPORT_FORMAT,
        title: title.into(),
        kind: "run",
        source: "runs/x".into(),
        generator: "shaping test".into(),
        seeds: Vec::new(),
        episodes_note: "a test".into(),
        shown_seed: None,
        stages: (0..p.stages.len()).map(|i| stage_view(&p, i, None)).collect(),
        fitness: Vec::new(),
        episodes: vec![ep],
        robots: vec![None],
        boards: vec![None],
        sweep: None,
        sweep_point: None,
        tests: None,
    }
}

/// The text of the page's one JSON data element.
fn embedded(html: &str) -> &str {
    let open = "<script type=\"application/json\" id=\"data\">";
    assert_eq!(html.matches(open).count(), 1);
    let start = html.find(open).unwrap() + open.len();
    let len = html[start..].find("</script>").unwrap();
    &html[start..start + len]
}

#[test]
fn the_page_embeds_the_data_intact_even_when_it_holds_markup() {
    let data = sample_data("evil</script><script>alert(1)</script><!--");
    let html = page(&data).unwrap();
    let json = embedded(&html);
    assert!(!json.contains('<'), "every `<` is escaped in the embedded data");
    let back: serde_json::Value = serde_json::from_str(json).unwrap();
    let expected: serde_json::Value = serde_json::from_str(&embedded_json(&data).unwrap()).unwrap();
    assert_eq!(back, expected);
    assert_eq!(back["title"], "evil</script><script>alert(1)</script><!--");
    assert_eq!(back["episodes"][0]["actions"]["x"].as_array().unwrap().len(), 50);
    // The title element is escaped too, and every placeholder is filled.
    assert!(html.contains("<title>evil&lt;/script&gt;"));
    for mark in ["{{title}}", "{{style}}", "{{stats}}", "{{data}}", "{{script}}"] {
        assert!(!html.contains(mark), "{mark} left in the page");
    }
    // Exactly the page's own two scripts: the data and the code.
    assert_eq!(html.matches("<script").count(), 2);
}

#[test]
fn the_page_fetches_nothing() {
    let html = page(&sample_data("x")).unwrap();
    let lower = html.to_lowercase();
    for bad in [
        "src=\"http",
        "href=\"http",
        "src='http",
        "href='http",
        "url(http",
        "url(//",
        "@import",
        "fetch(",
        "xmlhttprequest",
        "<link rel=\"stylesheet\"",
        "<script src",
        "<img",
    ] {
        assert!(!lower.contains(bad), "the page refers to the network or a file: `{bad}`");
    }
    // The only `<link>` is the empty icon, there so the browser asks for no favicon.
    assert_eq!(lower.matches("<link").count(), 1);
    assert!(lower.contains("<link rel=\"icon\" href=\"data:,\">"));
}

#[test]
fn episode_json_round_trips() {
    let data = sample_data("x");
    let mut ep = data.episodes[0].clone();
    // Episode seeds use all 64 bits: written as a string, which a
    // JavaScript number could not hold exactly.
    ep.seed = 8_684_134_590_060_804_097;
    let text = serde_json::to_string(&ep).unwrap();
    assert!(text.contains("\"seed\":\"8684134590060804097\""), "{}", &text[..200]);
    let back: Episode = serde_json::from_str(&text).unwrap();
    assert_eq!(back, ep);
}

#[test]
fn a_training_stage_episode_is_the_training_life() {
    let src = include_str!("../../../examples/khepera.bat");
    let p = shaping_compiler::compile(src, "khepera.bat").expect("the example compiles");
    let (i, stage) = p
        .stages
        .iter()
        .enumerate()
        .find(|(_, s)| matches!(s.run, StageRun::Train { .. }))
        .expect("khepera.bat has a training stage");
    let StageRun::Train { actions } = stage.run else { unreachable!() };
    let mut trace = Trace::default();
    let trained = shaping_runtime::evolve::train_stage(&p, i, 5, Some(&mut trace)).unwrap();
    let opts =
        EpisodeOptions { actions, learning: true, seed: shaping_runtime::evolve::train::training_seed(5, i) };
    let (result, recorded, ep) =
        run_recorded(stage, &Genome::zeros(stage.layout.bits as usize), &opts).unwrap();
    assert_eq!(result, trained.result);
    assert_eq!(recorded, trace);
    assert_eq!(ep.actions.x.len(), trace.rows.len());
    assert!(trace.rows.len() > 100);
}

/// The report names the individual of the parent's final population that
/// the best's frozen genes came from, and shows the parent's best values of
/// the frozen genes that differ from them.
#[test]
fn frozen_genes_are_traced_to_the_parents_final_population() {
    let p = program();
    let (nav, parent) = p.stage("navigation").unwrap();
    let (col, stage) = p.stage("collect").unwrap();
    let kept = parent.layout.bits as usize;
    // The parent's final population: random, with fitness 0, 1, 2, ...
    let mut cp = shaping_runtime::evolve::start_stage(&p, nav, 5, None).unwrap();
    let n = cp.population.len();
    cp.fitness = (0..n).map(|i| i as f32).collect();
    // The best of `collect` descends from individual 7 (rank n - 7).
    let mut best = random_genome(stage.layout.bits, 1);
    best.bits[..kept].copy_from_slice(&cp.population[7].bits[..kept]);
    // The parent's best.genome is individual 3, which differs in some frozen genes.
    let parent_best = cp.population[3].clone();
    let frozen: Vec<usize> =
        (0..stage.layout.genes.len()).filter(|&i| stage.layout.genes[i].frozen).collect();
    let differ = frozen
        .iter()
        .filter(|&&i| {
            let g = &stage.layout.genes[i];
            let r = g.offset as usize..(g.offset + g.bits as u32) as usize;
            best.bits[r.clone()] != parent_best.bits[r]
        })
        .count();
    assert!(differ > 0 && differ < frozen.len(), "{differ} of {}", frozen.len());
    let mut v = stage_view(&p, col, Some((&best, "collect/best.genome".into())));
    data::provenance(&p, col, nav, &best, &cp, Some(&parent_best), &mut v);
    let text = v.frozen_from.clone().unwrap();
    assert!(
        text.contains(&format!("The {} frozen genes", frozen.len()))
            && text.contains(&format!("individual #7 (rank {} of {n}, fitness 7)", n - 7))
            && text.contains("stage `navigation`'s final population")
            && text.contains(&format!("{differ} of them differ from `navigation/best.genome`")),
        "{text}"
    );
    assert_eq!(v.genes.iter().filter(|g| g.parent_value.is_some()).count(), differ);
    for &i in &frozen {
        if let Some(pv) = v.genes[i].parent_value {
            assert_eq!(pv, parent_best.decode(&stage.layout.genes[i]));
            assert_ne!(Some(pv), v.genes[i].value);
        }
    }
    assert!(v.genes.iter().filter(|g| !g.frozen).all(|g| g.parent_value.is_none()));
    // Descending from the parent's best itself: equal.
    best.bits[..kept].copy_from_slice(&parent_best.bits[..kept]);
    let mut v = stage_view(&p, col, Some((&best, "collect/best.genome".into())));
    data::provenance(&p, col, nav, &best, &cp, Some(&parent_best), &mut v);
    let text = v.frozen_from.unwrap();
    assert!(text.contains("individual #3") && text.contains("they equal `navigation/best.genome`"), "{text}");
    // Genes from no individual of the checkpoint: said so.
    let mut stranger = best.clone();
    for b in &mut stranger.bits[..kept] {
        *b ^= 1;
    }
    let mut v = stage_view(&p, col, Some((&stranger, "collect/best.genome".into())));
    data::provenance(&p, col, nav, &stranger, &cp, None, &mut v);
    assert!(v.frozen_from.unwrap().contains("match no individual"));
}

/// The statistics section is the summary's tests, escaped; a page without
/// tests has none.
#[test]
fn the_statistics_section_escapes_names_and_is_absent_without_tests() {
    let measures = |v: &[f64]| {
        vec![crate::compare::StageMeasures {
            stage: "s".into(),
            kind: "test",
            measures: vec![("after_fitness", v.to_vec())],
        }]
    };
    let t = crate::compare::tests(&[
        ("<b>a</b>".into(), measures(&[0.1, 0.2, 0.3])),
        ("b".into(), measures(&[0.5, 0.6, 0.7])),
    ]);
    let pair = &t.measures[0].pairs[0];
    let (p, a12) = (pair.p_value.unwrap(), pair.a12.unwrap());
    let mut data = sample_data("x");
    assert!(!page(&data).unwrap().contains("<section id=\"sec-stats\""));
    data.tests = Some(t);
    let html = page(&data).unwrap();
    assert!(html.contains("<code>&lt;b&gt;a&lt;/b&gt;</code>") && !html.contains("<b>a</b>"));
    assert!(html.contains("Groups (numbered in the pairs): 1 <code>"));
    assert!(
        html.contains(&format!("<td class=\"num\">{p:.4}</td><td class=\"num\">{a12:.3}</td>")),
        "{p} {a12}"
    );
    assert!(!html.contains("Holm"));
}
