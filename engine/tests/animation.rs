//! The GIF of a large team: `replay --gif` of 24 robots over 200 actions
//! stays under 3 MB (one palette for all frames, and in each frame only
//! the pixels that changed).

mod common;

use common::{load, root};
use shaping_engine::{animation, episode};
use shaping_runtime::controller::EpisodeOptions;
use shaping_runtime::genome::Genome;

/// The best individual of `examples/aggregation.bat` with 24 robots in a
/// 930 x 930 mm arena (the example's density) after 6 generations of 20
/// (`--set aggregate.evolve.actions=200`): robots that go about the arena.
const EVOLVED: &str = "11110110111101110100000000101110001100010001001110010110001101000010110100100111010000100110011000101011011011111111011111001100001000101101110001011101001010110010000110110100";

/// The measured episode: that individual's 200 actions (seed 1), whose GIF
/// took 4,730,506 bytes when each frame was the whole rectangle that
/// changed in a palette of its own, and takes 1,505,647 now.
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
    let moved = rec.others.iter().filter(|o| {
        let (a, b) = (&o.trace.rows[0].pose, &o.trace.rows[199].pose);
        (a.x - b.x).hypot(a.y - b.y) > 50.0
    });
    assert!(moved.count() >= 8, "robots go about the arena");
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
