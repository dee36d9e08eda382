//! The HTML report in a real browser: headless Chromium opens the report of
//! a short run, with no console message; the URL fragment takes it to an
//! action, where the robot's position and the winning module it shows must
//! be those of `trace.csv`; and a screenshot is saved to look at.
//!
//! Without a browser these tests say so and pass, except under CI
//! (`CI=true`), where a missing browser is a failure: `.ci/run` installs
//! the Debian package `chromium`. `SHAPING_CHROMIUM` names another binary.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn shaping() -> Command {
    Command::new(env!("CARGO_BIN_EXE_shaping"))
}

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("shaping-browser-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn on_ci() -> bool {
    std::env::var("CI").is_ok_and(|v| !v.is_empty() && v != "false" && v != "0")
}

/// The Chromium binary, if there is one.
fn chromium() -> Option<PathBuf> {
    if let Some(p) = std::env::var_os("SHAPING_CHROMIUM") {
        return Some(PathBuf::from(p));
    }
    let path = std::env::var_os("PATH")?;
    for dir in std::env::split_paths(&path) {
        for name in ["chromium", "chromium-browser", "google-chrome", "google-chrome-stable"] {
            let p = dir.join(name);
            if p.is_file() {
                return Some(p);
            }
        }
    }
    None
}

/// The browser, or `None` after saying why the test is skipped.
fn browser_or_skip() -> Option<PathBuf> {
    match chromium() {
        Some(p) => Some(p),
        None if on_ci() => panic!(
            "CI is set but no Chromium was found (install the Debian package `chromium`, or set SHAPING_CHROMIUM)"
        ),
        None => {
            eprintln!("skipped: no Chromium found (install `chromium` or set SHAPING_CHROMIUM to run the browser tests)");
            None
        }
    }
}

/// Runs headless Chromium on `url` with its own profile; `what` is
/// `--dump-dom` or `--screenshot=PATH`.
fn headless(browser: &Path, profile: &Path, url: &str, what: &str) -> Output {
    let out = Command::new(browser)
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            // Containers often have a small /dev/shm, where the renderer crashes.
            "--disable-dev-shm-usage",
            "--no-first-run",
            "--disable-extensions",
            "--hide-scrollbars",
            "--enable-logging=stderr",
            "--v=0",
            "--virtual-time-budget=3000",
            "--window-size=1300,1000",
        ])
        .arg(format!("--user-data-dir={}", profile.display()))
        .arg(what)
        .arg(url)
        .output()
        .unwrap_or_else(|e| panic!("cannot start {}: {e}", browser.display()));
    assert!(out.status.success(), "chromium failed: {}", String::from_utf8_lossy(&out.stderr));
    out
}

/// Console messages the page caused (Chromium logs them as `CONSOLE`).
fn console_messages(out: &Output) -> Vec<String> {
    String::from_utf8_lossy(&out.stderr)
        .lines()
        .filter(|l| l.contains(":CONSOLE"))
        .map(str::to_string)
        .collect()
}

/// The text of the element with id `id` in a dumped DOM.
fn text_of<'a>(dom: &'a str, id: &str) -> &'a str {
    let open = format!("id=\"{id}\"");
    let at = dom.find(&open).unwrap_or_else(|| panic!("no element #{id} in the page"));
    let start = at + dom[at..].find('>').unwrap() + 1;
    let end = start + dom[start..].find('<').unwrap();
    &dom[start..end]
}

/// The log a driver script leaves in `data-driven` (a JSON list of
/// strings) after it drove the report `html`, opened at `hash` in a fresh
/// profile `profile`, and the page as the driver left it; the page must
/// log nothing to the console.
fn driven_log(
    browser: &Path,
    dir: &Path,
    html: &str,
    driver: &str,
    hash: &str,
    profile: &str,
) -> (Vec<String>, String) {
    let driven = dir.join("driven.html");
    std::fs::write(&driven, html.replacen("</body>", driver, 1)).unwrap();
    let url = format!("{}{hash}", file_url(&driven));
    let out = headless(browser, &scratch(profile), &url, "--dump-dom");
    let console = console_messages(&out);
    assert!(console.is_empty(), "the page logged to the console:\n{}", console.join("\n"));
    let dom = String::from_utf8_lossy(&out.stdout).into_owned();
    let log = body_attr(&dom, "data-driven").expect("the driver ran");
    let log = serde_json::from_str(&log.replace("&quot;", "\"").replace("&amp;", "&")).unwrap();
    (log, dom)
}

fn body_attr<'a>(dom: &'a str, name: &str) -> Option<&'a str> {
    let body = &dom[dom.find("<body")?..];
    let tag = &body[..body.find('>')?];
    let key = format!("{name}=\"");
    let start = tag.find(&key)? + key.len();
    Some(&tag[start..start + tag[start..].find('"')?])
}

fn file_url(path: &Path) -> String {
    let abs = std::fs::canonicalize(path).unwrap();
    format!("file://{}", abs.display())
}

/// Runs `tests/cli/report.bat` into `dir` (with `extra` arguments) and
/// returns its report and the rows of the test stage's `trace.csv`, with
/// its header.
fn report_run(dir: &Path, extra: &[&str]) -> (PathBuf, Vec<String>, Vec<Vec<String>>) {
    let out = shaping()
        .arg("run")
        .arg(root().join("tests/cli/report.bat"))
        .arg("--out")
        .arg(dir)
        .arg("--quiet")
        .args(extra)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let trace = std::fs::read_to_string(dir.join("bigger/trace.csv")).unwrap();
    let header = trace.lines().next().unwrap().split(',').map(str::to_string).collect();
    let rows = trace.lines().skip(1).map(|l| l.split(',').map(str::to_string).collect()).collect();
    (dir.join("report.html"), header, rows)
}

/// Opens the report at `action` of the test stage: no console message, no
/// error, and the action, winner and position of `trace.csv`'s row.
fn shows_the_trace_at(
    browser: &Path,
    page: &Path,
    header: &[String],
    row: &[String],
    action: usize,
    profile: &str,
) {
    let col = |name: &str| header.iter().position(|h| h == name).unwrap();
    let url = format!("{}#stage=bigger&action={action}", file_url(page));
    let out = headless(browser, &scratch(profile), &url, "--dump-dom");
    let console = console_messages(&out);
    assert!(console.is_empty(), "the page logged to the console:\n{}", console.join("\n"));
    let dom = String::from_utf8_lossy(&out.stdout);
    assert_eq!(body_attr(&dom, "data-ready"), Some("1"), "the page's script did not finish");
    assert_eq!(body_attr(&dom, "data-errors"), None, "the page reported errors: {}", text_of(&dom, "errors"));
    assert_eq!(text_of(&dom, "r-action"), action.to_string());
    assert_eq!(body_attr(&dom, "data-stage"), Some("bigger"));
    assert_eq!(text_of(&dom, "r-winner"), row[col("winner")], "winner at action {action}");
    for (id, c) in [("r-x", "x"), ("r-y", "y")] {
        let shown: f64 = text_of(&dom, id).parse().unwrap();
        let csv: f64 = row[col(c)].parse().unwrap();
        assert!((shown - csv).abs() <= 0.011, "{c} at action {action}: page {shown}, trace.csv {csv}");
    }
}

#[test]
fn report_opens_without_console_messages_and_shows_the_trace_at_an_action() {
    let Some(browser) = browser_or_skip() else { return };
    let dir = scratch("run");
    let (page, header, rows) = report_run(&dir, &[]);
    assert!(rows.len() > 20, "the test stage lasted {} actions", rows.len());

    // Actions in both worlds of the test stage: before and after the change.
    let actions = [rows.len() / 4, rows.len() * 3 / 4, rows.len() - 1];
    for (k, &action) in actions.iter().enumerate() {
        shows_the_trace_at(&browser, &page, &header, &rows[action], action, &format!("profile-{k}"));
    }

    // A screenshot of the last of them, to look at.
    let shot = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("report.png");
    let _ = std::fs::remove_file(&shot);
    let url = format!("{}#stage=bigger&action={}", file_url(&page), actions[1]);
    let out = headless(&browser, &scratch("profile-shot"), &url, &format!("--screenshot={}", shot.display()));
    let console = console_messages(&out);
    assert!(console.is_empty(), "the page logged to the console:\n{}", console.join("\n"));
    let png = std::fs::read(&shot).unwrap();
    assert!(png.starts_with(b"\x89PNG") && png.len() > 20_000, "screenshot of {} bytes", png.len());
    eprintln!("screenshot: {}", shot.display());
}

/// A test stage of several lives: the page shows every life of both worlds.
#[test]
fn report_of_a_test_stage_with_lives_shows_every_life() {
    let Some(browser) = browser_or_skip() else { return };
    let dir = scratch("lives");
    let (page, header, rows) = report_run(&dir, &["--set", "bigger.test.lives=3"]);
    let summary: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("bigger/summary.json")).unwrap()).unwrap();
    let lives = |key: &str| -> Vec<usize> {
        summary[key].as_array().unwrap().iter().map(|v| v.as_u64().unwrap() as usize).collect()
    };
    let (before, after) = (lives("before_lives"), lives("after_lives"));
    assert_eq!((before.len(), after.len()), (3, 3));
    let (b, a): (usize, usize) = (before.iter().sum(), after.iter().sum());
    assert_eq!(rows.len(), b + a);
    // In the third life before the change, and in the second after it.
    for (k, action) in [before[0] + before[1] + 1, b + after[0] + 1].into_iter().enumerate() {
        shows_the_trace_at(&browser, &page, &header, &rows[action], action, &format!("profile-lives-{k}"));
    }
}

/// Drives the page's controls in the browser: keys, the scrub bar, a click
/// on the timeline, play and pause, and a changed fragment. A script added
/// to a copy of the report does it once the page has loaded, and leaves
/// what the page showed after each step in an attribute of the body.
#[test]
fn keyboard_mouse_and_fragment_move_the_replay() {
    let Some(browser) = browser_or_skip() else { return };
    let dir = scratch("controls");
    let out = shaping()
        .arg("run")
        .arg(root().join("tests/cli/report.bat"))
        .arg("--out")
        .arg(&dir)
        .arg("--quiet")
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let html = std::fs::read_to_string(dir.join("report.html")).unwrap();
    let driver = r#"<script>
window.addEventListener('load', () => {
  const log = [];
  const key = (k, shift) => document.dispatchEvent(new KeyboardEvent('keydown', { key: k, shiftKey: !!shift, bubbles: true }));
  const shown = () => document.getElementById('r-action').textContent + ' ' + document.body.dataset.stage + ' ' + location.hash;
  key('Home'); log.push(shown());
  key('ArrowRight'); log.push(shown());
  key('ArrowRight', true); log.push(shown());
  key('ArrowLeft'); log.push(shown());
  key('End'); log.push(shown());
  const s = document.getElementById('scrub'); s.value = '5'; s.dispatchEvent(new Event('input')); log.push(shown());
  const tl = document.getElementById('timeline'); const r = tl.getBoundingClientRect();
  tl.dispatchEvent(new MouseEvent('mousedown', { clientX: r.left + r.width * 0.5, clientY: r.top + 10, bubbles: true }));
  window.dispatchEvent(new MouseEvent('mouseup', {}));
  log.push(shown());
  key(' ');
  setTimeout(() => {
    key(' '); log.push(shown());
    location.hash = '#stage=navigation&action=7';
    setTimeout(() => { log.push(shown()); document.body.dataset.driven = JSON.stringify(log); }, 100);
  }, 1000);
});
</script>
</body>"#;
    let (log, _) = driven_log(&browser, &dir, &html, driver, "#stage=bigger&action=3", "profile-controls");
    let trace = std::fs::read_to_string(dir.join("bigger/trace.csv")).unwrap();
    let last = trace.lines().count() - 2;
    let at = |a: usize| format!("{a} bigger #stage=bigger&action={a}");
    assert_eq!(log[0], at(0), "Home");
    assert_eq!(log[1], at(1), "Right");
    assert_eq!(log[2], at(11), "Shift+Right");
    assert_eq!(log[3], at(10), "Left");
    assert_eq!(log[4], at(last), "End");
    assert_eq!(log[5], at(5), "the scrub bar");
    let clicked: usize = log[6].split(' ').next().unwrap().parse().unwrap();
    assert!(
        last / 4 < clicked && clicked < last * 3 / 4,
        "a click in the middle of the timeline went to {clicked} of {last}"
    );
    assert_eq!(log[6], at(clicked));
    let played: usize = log[7].split(' ').next().unwrap().parse().unwrap();
    assert!(played > clicked, "a second of play moved from {clicked} to {played}");
    assert_eq!(log[7], at(played), "the fragment follows the replay");
    assert_eq!(log[8], "7 navigation #stage=navigation&action=7", "a changed fragment moves the replay");
}

/// Runs `examples/aggregation-roles.bat` briefly into `dir` (a team of 10
/// robots in two roles) and replays its best with `--report` into
/// `dir/replay` (and `extra` arguments). Returns the replay's report and
/// its `trace.csv`'s header and rows (every robot's, a `robot` column
/// first).
fn team_run(dir: &Path, extra: &[&str]) -> (PathBuf, Vec<String>, Vec<Vec<String>>) {
    let sets =
        ["aggregate.evolve.generations=1", "aggregate.evolve.population=4", "aggregate.evolve.actions=60"];
    team_replay(&root().join("examples/aggregation-roles.bat"), &sets, dir, extra)
}

/// [`team_run`] of `file`, a team's stage `aggregate`, with settings `sets`.
fn team_replay(
    file: &Path,
    sets: &[&str],
    dir: &Path,
    extra: &[&str],
) -> (PathBuf, Vec<String>, Vec<Vec<String>>) {
    let sets: Vec<String> = sets.iter().flat_map(|s| ["--set".to_string(), s.to_string()]).collect();
    if !dir.join("aggregate/best.genome").exists() {
        let out =
            shaping().arg("run").arg(file).arg("--out").arg(dir).arg("--quiet").args(&sets).output().unwrap();
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    }
    let replay = dir.join("replay");
    let out = shaping()
        .arg("replay")
        .arg(file)
        .arg("--run")
        .arg(dir)
        .arg("--out")
        .arg(&replay)
        .arg("--report")
        .args(&sets)
        .args(extra)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let trace = std::fs::read_to_string(replay.join("trace.csv")).unwrap();
    let header = trace.lines().next().unwrap().split(',').map(str::to_string).collect();
    let rows = trace.lines().skip(1).map(|l| l.split(',').map(str::to_string).collect()).collect();
    (replay.join("report.html"), header, rows)
}

/// Checks that the page shows robot `robot` at `action`: its number, role
/// and position as `trace.csv` has them.
fn follows(dom: &str, header: &[String], rows: &[Vec<String>], robot: usize, action: usize, role: &str) {
    let col = |name: &str| header.iter().position(|h| h == name).unwrap();
    let row = rows
        .iter()
        .find(|r| r[col("robot")] == robot.to_string() && r[col("action")] == action.to_string())
        .unwrap_or_else(|| panic!("no row of robot {robot} at action {action}"));
    assert_eq!(body_attr(dom, "data-robot"), Some(robot.to_string().as_str()), "the robot followed");
    assert_eq!(text_of(dom, "r-action"), action.to_string());
    assert_eq!(text_of(dom, "r-robot"), format!("{robot} of 10, role {role}"));
    for (id, c) in [("r-x", "x"), ("r-y", "y")] {
        let shown: f64 = text_of(dom, id).parse().unwrap();
        let csv: f64 = row[col(c)].parse().unwrap();
        assert!(
            (shown - csv).abs() <= 0.011,
            "robot {robot}'s {c} at action {action}: page {shown}, trace.csv {csv}"
        );
    }
}

/// The report of a team follows any robot: `#robot=N` selects robot N on
/// load; the selector changes the robot followed and the address with it;
/// a robot the team does not have is said, not followed.
#[test]
fn the_report_of_a_team_follows_any_robot() {
    let Some(browser) = browser_or_skip() else { return };
    let dir = scratch("team");
    let (page, header, rows) = team_run(&dir, &[]);

    // A deep link to robot 7 (of the second role) at action 30.
    let url = format!("{}#stage=aggregate&action=30&robot=7", file_url(&page));
    let out = headless(&browser, &scratch("profile-team"), &url, "--dump-dom");
    let console = console_messages(&out);
    assert!(console.is_empty(), "the page logged to the console:\n{}", console.join("\n"));
    let dom = String::from_utf8_lossy(&out.stdout);
    assert_eq!(body_attr(&dom, "data-ready"), Some("1"), "the page's script did not finish");
    assert_eq!(body_attr(&dom, "data-errors"), None, "the page reported errors: {}", text_of(&dom, "errors"));
    follows(&dom, &header, &rows, 7, 30, "second");

    // The selector: robot 2, then the address and the readout follow it.
    let html = std::fs::read_to_string(&page).unwrap();
    let driver = r#"<script>
window.addEventListener('load', () => {
  const log = [];
  const sel = document.getElementById('robot');
  log.push(sel.options.length + ' ' + sel.options[7].textContent);
  sel.value = '2'; sel.dispatchEvent(new Event('change'));
  log.push(location.hash);
  document.body.dataset.driven = JSON.stringify(log);
});
</script>
</body>"#;
    let (log, dom) = driven_log(
        &browser,
        &dir,
        &html,
        driver,
        "#stage=aggregate&action=12&robot=7",
        "profile-team-select",
    );
    assert_eq!(log[0], "10 robot 7 (second)", "one entry per robot, with its role");
    assert_eq!(log[1], "#stage=aggregate&action=12&robot=2", "the address follows the selector");
    follows(&dom, &header, &rows, 2, 12, "first");

    // A robot the team does not have: said, and robot 0 followed.
    let url = format!("{}#stage=aggregate&action=5&robot=12", file_url(&page));
    let out = headless(&browser, &scratch("profile-team-bad"), &url, "--dump-dom");
    let dom = String::from_utf8_lossy(&out.stdout);
    assert_eq!(body_attr(&dom, "data-errors"), None);
    assert!(text_of(&dom, "robot-note").contains("no robot 12 in this episode (robots 0 to 9)"));
    follows(&dom, &header, &rows, 0, 5, "first");

    // `replay --robot 4`: its report follows robot 4 when it opens.
    let (page, header, rows) = team_run(&dir, &["--robot", "4"]);
    let url = format!("{}#stage=aggregate&action=9", file_url(&page));
    let out = headless(&browser, &scratch("profile-team-replay"), &url, "--dump-dom");
    let dom = String::from_utf8_lossy(&out.stdout);
    assert_eq!(body_attr(&dom, "data-errors"), None);
    follows(&dom, &header, &rows, 4, 9, "first");
}

/// The readout's board and the drawing of who hears whom, as the page
/// left them after `driver`'s steps: per step, the board table's rows
/// (`name: values`), then `data-hears` and `data-heard` of the body
/// (`-` when absent), then whether the table is hidden.
const BOARD_DRIVER: &str = r#"<script>
window.addEventListener('load', () => {
  const log = [];
  const look = () => {
    const t = document.getElementById('r-board');
    const rows = [...t.tBodies[0].rows].map((r) => r.cells[0].textContent + ': ' + r.cells[1].textContent);
    const d = document.body.dataset;
    log.push(JSON.stringify([rows, d.hears === undefined ? '-' : d.hears, d.heard === undefined ? '-' : d.heard, t.hidden]));
  };
  look();
  const sel = document.getElementById('robot');
  sel.value = '3'; sel.dispatchEvent(new Event('change'));
  look();
  document.body.dataset.driven = JSON.stringify(log);
});
</script>
</body>"#;

/// One step of [`BOARD_DRIVER`]'s log: the board's rows, `data-hears`,
/// `data-heard` and whether the table is hidden.
fn board_step(entry: &str) -> (Vec<String>, String, String, bool) {
    serde_json::from_str(entry).unwrap()
}

/// The report of a team with a range-and-bearing board
/// (`examples/aggregation-rab.bat`, briefly evolved): at an action, the
/// readout shows the followed robot's board as `trace.csv` has it (its
/// `rab`, `heard` and `signal` values), and the arena draws a line
/// between every two robots within the board's range on where they were
/// after the previous action (as the board read then; no walls there to
/// hide them), which the test counts from `trace.csv` itself; both follow
/// the robot selected. A team without a board (`aggregation-roles.bat`)
/// has neither.
#[test]
fn the_report_shows_the_board_and_draws_who_hears_whom() {
    let Some(browser) = browser_or_skip() else { return };
    let dir = scratch("board");
    let file = root().join("examples/aggregation-rab.bat");
    let sets = [
        "aggregate.evolve.generations=1",
        "aggregate.evolve.population=4",
        "aggregate.evolve.actions=60",
        "aggregate.evolve.evaluations=1",
    ];
    let (page, _, _) = team_replay(&file, &sets, &dir, &[]);
    let program =
        shaping_compiler::compile(&std::fs::read_to_string(&file).unwrap(), "aggregation-rab.bat").unwrap();
    let body = &program.stages[0].world.body;
    let reach = 2.0 * f64::from(body.radius) + f64::from(body.rab.as_ref().unwrap().range);
    let trace = std::fs::read_to_string(dir.join("replay/trace.csv")).unwrap();
    let header: Vec<&str> = trace.lines().next().unwrap().split(',').collect();
    let rows: Vec<Vec<&str>> = trace.lines().skip(1).map(|l| l.split(',').collect()).collect();
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let row = |robot: usize, action: usize| {
        rows.iter()
            .find(|r| r[col("robot")] == robot.to_string() && r[col("action")] == action.to_string())
            .unwrap_or_else(|| panic!("no row of robot {robot} at action {action}"))
    };
    let at = |robot: usize, action: usize| {
        let r = row(robot, action);
        (r[col("x")].parse::<f64>().unwrap(), r[col("y")].parse::<f64>().unwrap())
    };
    // What the readout must show of robot `robot` at `action`: per row,
    // its name and values (the page shows them to 2 decimals).
    let board = |robot: usize, action: usize| -> Vec<(String, Vec<f64>)> {
        let r = row(robot, action);
        let values = |n: usize, name: &str| {
            (0..n).map(|i| r[col(&format!("{name}[{i}]"))].parse::<f64>().unwrap()).collect::<Vec<_>>()
        };
        [("rab", 8), ("heard", 8), ("signal", 1)]
            .iter()
            .map(|&(name, n)| (name.to_string(), values(n, name)))
            .collect()
    };
    // The pairs within reach after action `action - 1`, and those of `robot`.
    let action = 30;
    let near = |i: usize, j: usize| {
        let ((xi, yi), (xj, yj)) = (at(i, action - 1), at(j, action - 1));
        (xi - xj).hypot(yi - yj) <= reach
    };
    let pairs = (0..10).flat_map(|i| (i + 1..10).map(move |j| (i, j))).filter(|&(i, j)| near(i, j)).count();
    let heard = |robot: usize| {
        (0..10).filter(|&j| j != robot && near(robot, j)).map(|j| j.to_string()).collect::<Vec<_>>()
    };
    assert!(pairs > 0 && pairs < 45, "some pairs in range, not all: {pairs}");

    let html = std::fs::read_to_string(page).unwrap();
    let hash = format!("#stage=aggregate&action={action}&robot=0");
    let (log, _) = driven_log(&browser, &dir, &html, BOARD_DRIVER, &hash, "profile-board");
    for (step, robot) in [(0, 0usize), (1, 3)] {
        let (shown, hears, list, hidden) = board_step(&log[step]);
        let want = board(robot, action);
        assert_eq!(shown.len(), want.len() + 1, "{shown:?}");
        for (line, (name, values)) in shown.iter().zip(&want) {
            let (n, v) = line.split_once(": ").unwrap();
            let v: Vec<f64> = v.split(' ').map(|x| x.parse().unwrap()).collect();
            assert_eq!(n, name, "{shown:?}");
            assert_eq!(v.len(), values.len(), "{line}");
            for (got, csv) in v.iter().zip(values) {
                assert!(
                    (got - csv).abs() <= 0.005 + 1e-9,
                    "robot {robot}'s {name} at action {action}: page {line}, trace.csv {values:?}"
                );
            }
        }
        let h = heard(robot);
        let range = if h.is_empty() { "none".to_string() } else { format!("robots {}", h.join(", ")) };
        assert_eq!(shown[want.len()], format!("in range: {range}"));
        assert!(!hidden, "the board's table is shown");
        assert_eq!(hears, pairs.to_string(), "a line per pair in range (robot {robot} followed)");
        assert_eq!(list, h.join(" "), "the robots robot {robot} hears");
    }

    // A team without a board: no table, no lines.
    let plain = scratch("board-none");
    let (page, _, _) = team_run(&plain, &[]);
    let html = std::fs::read_to_string(page).unwrap();
    let (log, _) =
        driven_log(&browser, &plain, &html, BOARD_DRIVER, "#stage=aggregate&action=30", "profile-board-none");
    for entry in &log {
        let (shown, hears, list, hidden) = board_step(entry);
        assert!(shown.is_empty() && hidden, "no board: {shown:?}");
        assert_eq!((hears.as_str(), list.as_str()), ("-", "-"), "no line drawn without a board");
    }
}
