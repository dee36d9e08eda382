//! The GIF of a large team: `replay --gif` of 24 robots over 200 actions
//! stays under 3 MB (one palette for all frames, and in each frame only
//! the pixels that changed).

mod common;

use common::{load, root};
use shaping_engine::{animation, episode};
use shaping_runtime::controller::EpisodeOptions;
use shaping_runtime::genome::Genome;

/// The best individual of `examples/aggregation.bat` with 24 robots in a
/// 930 x 930 mm arena (the example's density) after 25 generations of 30
/// (`--set aggregate.evolve.actions=200 --set aggregate.evolve.evaluations=1`):
/// robots that go about the arena all the time (every robot's pixels
/// change in every frame, which is what the GIF holds).
const EVOLVED: &str = "10001110011100100001000010011000000011010100000110000011011000101001010001001110011000000010111000111100010001111101111110100110010110101101110111010100001010010010010010100100";

/// The measured episode: that individual's 200 actions (seed 1), whose GIF
/// took 3,222,945 bytes when each frame was the whole rectangle that
/// changed in a palette of its own, and takes 2,065,831 now (an individual
/// of 6 generations: 4,730,506 then, 1,505,647 now).
#[test]
fn the_gif_of_24_robots_over_200_actions_is_at_most_3_mb() {
    let mut program = load(&root().join("examples/aggregation.bat"));
    let sets = [("aggregate.world.robots", "24"), ("aggregate.world.arena", "930x930")];
    let sets: Vec<(String, String)> = sets.iter().map(|(t, v)| (t.to_string(), v.to_string())).collect();
    shaping_engine::sweep::apply(&mut program, &sets).unwrap();
    let stage = &program.stages[0];
    assert_eq!(stage.world.robots, 24);
    let genome = Genome::parse_bitstring(EVOLVED).unwrap();
    let rec =
        episode::record(stage, &genome, &EpisodeOptions { actions: 200, learning: true, seed: 1 }).unwrap();
    assert_eq!(rec.episode.actions.x.len(), 200);
    let travelled = |o: &episode::OtherRobot| -> f32 {
        o.trace.rows.windows(2).map(|w| (w[1].pose.x - w[0].pose.x).hypot(w[1].pose.y - w[0].pose.y)).sum()
    };
    let moved = rec.others.iter().filter(|o| travelled(o) > 200.0).count();
    assert!(moved >= 16, "robots go about the arena: {moved} of 23 went 200 mm");
    let frames = animation::frames(&rec.scene, &rec.episode).unwrap();
    assert_eq!(frames.len(), 200, "a frame per action: none dropped");
    let bytes = animation::gif(&frames).unwrap();
    eprintln!(
        "the GIF of 24 robots x 200 actions ({} x {} px): {} bytes",
        frames[0].width,
        frames[0].height,
        bytes.len()
    );
    assert!(bytes.len() <= 3_000_000, "{} bytes", bytes.len());
    // Every robot is in it: the last frame decodes to the last frame drawn.
    let mut opts = gif::DecodeOptions::new();
    opts.set_color_output(gif::ColorOutput::RGBA);
    let mut dec = opts.read_info(bytes.as_slice()).unwrap();
    let (w, h) = (dec.width() as usize, dec.height() as usize);
    let mut screen = vec![0u8; w * h * 4];
    let mut n = 0;
    while let Some(f) = dec.read_next_frame().unwrap() {
        for y in 0..f.height as usize {
            for x in 0..f.width as usize {
                let src = &f.buffer[(y * f.width as usize + x) * 4..][..4];
                if src[3] != 0 {
                    let at = ((y + f.top as usize) * w + x + f.left as usize) * 4;
                    screen[at..at + 4].copy_from_slice(src);
                }
            }
        }
        n += 1;
    }
    assert_eq!(n, 200);
    let last = &frames[199];
    let off = (0..w * h)
        .filter(|&i| {
            let (a, b) = (&screen[i * 4..i * 4 + 3], &last.pixels[i * 3..i * 3 + 3]);
            a.iter().zip(b).map(|(p, q)| (i32::from(*p) - i32::from(*q)).abs()).max().unwrap_or(0) > 40
        })
        .count();
    assert!(off * 100 < w * h, "{off} of {} pixels far from the frame drawn", w * h);
}
