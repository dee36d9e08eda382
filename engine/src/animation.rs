//! A recorded episode as an animation: `replay --gif` and `--mp4`.
//!
//! Every frame is [`plot::trajectory_rgb`] of the world as the robot left
//! it after an action (the objects where they were, held ones in the
//! gripper, those thrown out gone) and of its path so far, coloured by the
//! module that won each action (a team's other robots: their paths so far
//! and bodies, one colour each, or their role's in a team of roles; `replay
//! --robot N` draws the team as robot N lived it); the strip above the arena shows the
//! battery as a bar and the action's number (drawn with a small built-in
//! digit font, so a frame looks the same whatever fonts the machine has).
//! At most [`MAX_FRAMES`] frames: a longer episode is subsampled evenly,
//! and the last action is always the last frame.
//!
//! The GIF is written by the `gif` crate (the encoder plotters' own GIF
//! backend uses) in memory, in one palette for all frames, each frame only
//! the rectangle that changed since the one before with its unchanged
//! pixels transparent (so a 300-frame episode of one robot takes a few
//! hundred kilobytes, and one of 24 robots over 200 actions under 3 MB),
//! then written whole like every other file; plotters'
//! `BitMapBackend::gif` would write every frame whole, straight into the
//! target file as it draws. The MP4 is the same frames piped to `ffmpeg`, which must be on the
//! `PATH`.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

use shaping_runtime::sim::Scene;

use crate::episode::Episode;
use crate::error::Error;
use crate::files::write_atomic;
use crate::plot::{self, Rgb};
use crate::report;

/// The most frames an animation has.
pub const MAX_FRAMES: usize = 300;
/// Time a frame is shown, hundredths of a second (12.5 frames a second).
pub const FRAME_DELAY_CS: u16 = 8;
const FPS: &str = "12.5";

/// The action indices the frames show: every action of a short episode; of
/// a longer one, `max` evenly spaced, the last action last.
pub fn frame_actions(actions: usize, max: usize) -> Vec<usize> {
    if actions == 0 || max == 0 {
        return Vec::new();
    }
    if actions <= max {
        return (0..actions).collect();
    }
    // Frame k shows action ceil((k + 1) * actions / max) - 1: evenly
    // spaced, strictly increasing, the last one `actions - 1`.
    (0..max).map(|k| ((k + 1) * actions).div_ceil(max) - 1).collect()
}

/// The frames of the episode's first world (a replay has one), drawn from
/// `scene` (the world before the first action: what does not move, and
/// which objects are virtual) and the episode's per-action columns.
pub fn frames(scene: &Scene, episode: &Episode) -> Result<Vec<Rgb>, Error> {
    frames_of_team(scene, episode, &[], 0)
}

/// [`frames`] of a team of `roles` (names and robots, in order; empty
/// without roles), each robot outlined in its role's colour, as lived by
/// robot `robot` (the episode is [`Episode::following`] it; 0 otherwise).
pub fn frames_of_team(
    scene: &Scene,
    episode: &Episode,
    roles: &[(String, u32)],
    robot: usize,
) -> Result<Vec<Rgb>, Error> {
    let c = &episode.actions;
    let end = episode.worlds.get(1).map_or(c.x.len(), |w| w.from as usize).min(c.x.len());
    let base = plot::TrajectoryScene { roles: roles.to_vec(), robot, ..report::picture(scene, Vec::new()) };
    let mut objects = base.objects.clone();
    let mut changes = c.objects.iter().peekable();
    let mut out = Vec::new();
    let to_err = Error::from;
    let mut path = Vec::with_capacity(end);
    // A team's other robots in the first world, their paths so far.
    let mut others = vec![Vec::with_capacity(end); episode.robots_in(0) - 1];
    let mut shown = frame_actions(end, MAX_FRAMES).into_iter().peekable();
    for a in 0..end {
        path.push([c.x[a], c.y[a], c.theta[a]]);
        for (o, p) in c.others.iter().zip(&mut others) {
            if let (Some(&x), Some(&y), Some(&theta)) = (o.x.get(a), o.y.get(a), o.theta.get(a)) {
                p.push([x, y, theta]);
            }
        }
        while let Some(ch) = changes.next_if(|ch| ch[0] as usize <= a) {
            if let Some(o) = objects.get_mut(ch[1] as usize) {
                (o.x, o.y, o.radius) = (ch[2], ch[3], ch[4]);
                // Held objects are drawn in the gripper; those outside
                // are left out of the frame.
                o.collected = ch[5] >= 2.0;
            }
        }
        if shown.next_if_eq(&a).is_none() {
            continue;
        }
        let frame_scene = plot::TrajectoryScene {
            objects: objects.clone(),
            path: path.clone(),
            path_modules: Some(c.winner[..=a].to_vec()),
            module_names: episode.modules.clone(),
            others: others.clone(),
            ..base.clone()
        };
        let mut rgb = plot::trajectory_rgb(&frame_scene).map_err(to_err)?;
        let battery = c.battery.get(a).copied().unwrap_or(0.0);
        overlay(&mut rgb, battery, a + 1, end);
        out.push(rgb);
    }
    // Frames of one size: a path that widened the view is cut, never scaled.
    if let Some(first) = out.first() {
        let (w, h) = (first.width, first.height);
        for f in &mut out {
            *f = fit(f, w, h);
        }
    }
    Ok(out)
}

/// `frame` cut or padded (white) to `w` x `h`, from its top left corner.
fn fit(frame: &Rgb, w: u32, h: u32) -> Rgb {
    if frame.width == w && frame.height == h {
        return frame.clone();
    }
    let mut pixels = vec![255u8; w as usize * h as usize * 3];
    for y in 0..h.min(frame.height) as usize {
        let n = w.min(frame.width) as usize * 3;
        let from = y * frame.width as usize * 3;
        pixels[y * w as usize * 3..][..n].copy_from_slice(&frame.pixels[from..from + n]);
    }
    Rgb { width: w, height: h, pixels }
}

const INK: [u8; 3] = [40, 40, 40];
/// Digits 0-9 and `/`, 3 pixels wide and 5 high, rows from the top.
const GLYPHS: [[u8; 5]; 11] = [
    [0b111, 0b101, 0b101, 0b101, 0b111],
    [0b010, 0b110, 0b010, 0b010, 0b111],
    [0b111, 0b001, 0b111, 0b100, 0b111],
    [0b111, 0b001, 0b111, 0b001, 0b111],
    [0b101, 0b101, 0b111, 0b001, 0b001],
    [0b111, 0b100, 0b111, 0b001, 0b111],
    [0b111, 0b100, 0b111, 0b101, 0b111],
    [0b111, 0b001, 0b001, 0b001, 0b001],
    [0b111, 0b101, 0b111, 0b101, 0b111],
    [0b111, 0b101, 0b111, 0b001, 0b111],
    [0b001, 0b001, 0b010, 0b100, 0b100],
];

fn rect(f: &mut Rgb, (x0, y0): (u32, u32), (x1, y1): (u32, u32), c: [u8; 3]) {
    for y in y0..y1.min(f.height) {
        for x in x0..x1.min(f.width) {
            let i = (y as usize * f.width as usize + x as usize) * 3;
            f.pixels[i..i + 3].copy_from_slice(&c);
        }
    }
}

/// The strip above the arena (blank in [`plot::trajectory_rgb`]): a
/// battery at the left, filled to its level, and `action/actions` at the
/// right.
fn overlay(f: &mut Rgb, battery: f32, action: usize, actions: usize) {
    let (x, y, w, h) = (16, 14, 160, 20);
    rect(f, (x, y), (x + w + 4, y + h + 4), INK);
    rect(f, (x + w + 4, y + 6), (x + w + 9, y + h - 2), INK);
    rect(f, (x + 2, y + 2), (x + w + 2, y + h + 2), [255, 255, 255]);
    let level = battery.clamp(0.0, 1.0);
    let colour = if level > 0.3 { [80, 170, 80] } else { [220, 80, 40] };
    rect(f, (x + 2, y + 2), (x + 2 + (level * w as f32).round() as u32, y + h + 2), colour);
    let text: Vec<usize> =
        format!("{action}/{actions}").chars().map(|ch| ch.to_digit(10).map_or(10, |d| d as usize)).collect();
    let scale = 4;
    let advance = 4 * scale;
    let width = text.len() as u32 * advance;
    let x0 = f.width.saturating_sub(16 + width);
    for (k, &g) in text.iter().enumerate() {
        for (row, bits) in GLYPHS[g].iter().enumerate() {
            for col in 0..3 {
                if bits & (0b100 >> col) != 0 {
                    let px = x0 + k as u32 * advance + col * scale;
                    let py = 14 + row as u32 * scale;
                    rect(f, (px, py), (px + scale, py + scale), INK);
                }
            }
        }
    }
}

/// The index of the transparent colour in a GIF's palette: a pixel the
/// frame before showed already.
const CLEAR: u8 = 255;

/// One palette of at most 255 colours for every frame (index [`CLEAR`] is
/// transparent): the colours of the first and last frames when they are
/// that few (a picture of flat colours: exact), else NeuQuant's 255 for
/// them; every pixel is then its nearest palette colour.
struct Palette {
    rgb: Vec<[u8; 3]>,
    known: std::collections::HashMap<[u8; 3], u8>,
}

impl Palette {
    fn of(frames: &[Rgb]) -> Palette {
        let sample: Vec<&Rgb> = match (frames.first(), frames.last()) {
            (Some(a), Some(b)) => vec![a, b],
            _ => Vec::new(),
        };
        let mut seen = std::collections::HashMap::new();
        let mut rgb: Vec<[u8; 3]> = Vec::new();
        'count: for f in &sample {
            for p in f.pixels.chunks_exact(3) {
                let c = [p[0], p[1], p[2]];
                if seen.contains_key(&c) {
                    continue;
                }
                if rgb.len() == usize::from(CLEAR) {
                    rgb.clear();
                    break 'count;
                }
                seen.insert(c, rgb.len() as u8);
                rgb.push(c);
            }
        }
        if rgb.is_empty() && !sample.is_empty() {
            seen.clear();
            let rgba: Vec<u8> = sample
                .iter()
                .flat_map(|f| f.pixels.chunks_exact(3))
                .flat_map(|p| [p[0], p[1], p[2], 255])
                .collect();
            let nq = color_quant::NeuQuant::new(10, usize::from(CLEAR), &rgba);
            rgb = nq.color_map_rgb().chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
        }
        Palette { rgb, known: seen }
    }

    /// The index of the palette colour nearest `c`.
    fn index(&mut self, c: [u8; 3]) -> u8 {
        if let Some(&i) = self.known.get(&c) {
            return i;
        }
        let d = |p: &[u8; 3]| (0..3).map(|k| (i32::from(p[k]) - i32::from(c[k])).pow(2)).sum::<i32>();
        let i = (0..self.rgb.len()).min_by_key(|&i| d(&self.rgb[i])).unwrap_or(0) as u8;
        self.known.insert(c, i);
        i
    }

    /// The table the GIF holds: 256 colours, the transparent one last.
    fn table(&self) -> Vec<u8> {
        let mut t: Vec<u8> = self.rgb.iter().flatten().copied().collect();
        t.resize(256 * 3, 255);
        t
    }
}

/// The bounding box `(x, y, w, h)` of the pixels that differ between two
/// frames of palette indices of width `w`; `None` when none does.
fn changed_indices(a: &[u8], b: &[u8], w: usize) -> Option<(u32, u32, u32, u32)> {
    let h = a.len() / w.max(1);
    let (mut x0, mut y0, mut x1, mut y1) = (w, h, 0, 0);
    for y in 0..h {
        let (ra, rb) = (&a[y * w..(y + 1) * w], &b[y * w..(y + 1) * w]);
        if ra == rb {
            continue;
        }
        let first = (0..w).find(|&x| ra[x] != rb[x]).unwrap_or(0);
        let last = (0..w).rev().find(|&x| ra[x] != rb[x]).unwrap_or(0);
        (x0, x1, y0, y1) = (x0.min(first), x1.max(last + 1), y0.min(y), y + 1);
    }
    (x1 > x0).then(|| (x0 as u32, y0 as u32, (x1 - x0) as u32, (y1 - y0) as u32))
}

/// The frames as an animated GIF that loops, in one palette for all
/// ([`Palette`]): the first whole, each later one as the rectangle that
/// changed (drawn over the frame before), in which the pixels that did not
/// change are transparent (long runs of one index, which LZW packs small).
pub fn gif(frames: &[Rgb]) -> Result<Vec<u8>, String> {
    let first = frames.first().ok_or("no frames to animate")?;
    let (w, h) = (first.width, first.height);
    if frames.iter().any(|f| f.width != w || f.height != h) {
        return Err("the frames differ in size".into());
    }
    let side =
        |v: u32| u16::try_from(v).map_err(|_| format!("a frame of {w} x {h} pixels is too large for a GIF"));
    let mut palette = Palette::of(frames);
    let mut bytes = Vec::new();
    {
        let mut enc =
            gif::Encoder::new(&mut bytes, side(w)?, side(h)?, &palette.table()).map_err(|e| e.to_string())?;
        enc.set_repeat(gif::Repeat::Infinite).map_err(|e| e.to_string())?;
        let mut prev: Option<Vec<u8>> = None;
        for f in frames {
            let now: Vec<u8> = f.pixels.chunks_exact(3).map(|p| palette.index([p[0], p[1], p[2]])).collect();
            let (x, y, fw, fh) = match &prev {
                None => (0, 0, w, h),
                // An unchanged frame still takes its time: one pixel.
                Some(p) => changed_indices(p, &now, w as usize).unwrap_or((0, 0, 1, 1)),
            };
            let mut part = Vec::with_capacity(fw as usize * fh as usize);
            for row in y..y + fh {
                let from = row as usize * w as usize + x as usize;
                let cells = from..from + fw as usize;
                match &prev {
                    None => part.extend_from_slice(&now[cells]),
                    Some(p) => part.extend(cells.map(|i| if p[i] == now[i] { CLEAR } else { now[i] })),
                }
            }
            let mut frame = gif::Frame::from_indexed_pixels(side(fw)?, side(fh)?, part, Some(CLEAR));
            frame.left = side(x)?;
            frame.top = side(y)?;
            frame.delay = FRAME_DELAY_CS;
            frame.dispose = gif::DisposalMethod::Keep;
            enc.write_frame(&frame).map_err(|e| e.to_string())?;
            prev = Some(now);
        }
    }
    Ok(bytes)
}

/// Writes the frames to `path` as an animated GIF.
pub fn write_gif(path: &Path, frames: &[Rgb]) -> Result<(), Error> {
    let bytes = gif(frames).map_err(|e| Error::file(crate::ErrorKind::Internal, "write", path, e))?;
    write_atomic(path, &bytes)
}

/// Where `program` is on the `PATH`, if anywhere.
pub fn find_program(program: &str) -> Option<PathBuf> {
    let path = std::env::var_os("PATH")?;
    std::env::split_paths(&path).map(|d| d.join(program)).find(|p| p.is_file())
}

/// `ffmpeg` on the `PATH`, or the error `--mp4` gives without it.
pub fn ffmpeg() -> Result<PathBuf, Error> {
    find_program("ffmpeg").ok_or_else(|| {
        let subject = crate::Subject::File { path: "ffmpeg".into(), operation: "run".into() };
        Error::new(
            crate::ErrorKind::NotFound,
            "error: `--mp4` needs the program `ffmpeg`, which is not on the PATH; install it, or write a GIF with `--gif`",
        )
        .about(subject)
    })
}

/// Writes the frames to `path` as an H.264 MP4 through `ffmpeg` (into a
/// temporary file beside it, renamed when `ffmpeg` succeeded).
pub fn write_mp4(path: &Path, frames: &[Rgb]) -> Result<(), Error> {
    let ffmpeg = ffmpeg()?;
    let first =
        frames.first().ok_or_else(|| Error::new(crate::ErrorKind::Invalid, "error: no frames to animate"))?;
    // H.264 in yuv420p needs even sides.
    let (w, h) = (first.width + first.width % 2, first.height + first.height % 2);
    let mut tmp = path.as_os_str().to_owned();
    tmp.push(format!(".{}.partial", std::process::id()));
    let tmp = PathBuf::from(tmp);
    let fail = |m: String| Error::file(crate::ErrorKind::Io, "write", path, m);
    let mut child = Command::new(&ffmpeg)
        .args(["-y", "-loglevel", "error", "-f", "rawvideo", "-pixel_format", "rgb24"])
        .args(["-video_size", &format!("{w}x{h}"), "-framerate", FPS, "-i", "-"])
        .args(["-c:v", "libx264", "-pix_fmt", "yuv420p", "-f", "mp4"])
        .arg(&tmp)
        .stdin(Stdio::piped())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .map_err(|e| fail(format!("cannot start `{}`: {e}", ffmpeg.display())))?;
    let written = {
        let mut stdin = child.stdin.take().expect("stdin is piped");
        frames.iter().try_for_each(|f| stdin.write_all(&fit(f, w, h).pixels))
    };
    let output = child.wait_with_output().map_err(|e| fail(e.to_string()))?;
    if !output.status.success() || written.is_err() {
        let _ = std::fs::remove_file(&tmp);
        let said = String::from_utf8_lossy(&output.stderr);
        let said = said.lines().last().unwrap_or("no message").trim();
        return Err(fail(format!("`ffmpeg` failed ({}): {said}", output.status)));
    }
    std::fs::rename(&tmp, path).map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        fail(e.to_string())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frames_are_at_most_the_limit_evenly_spaced_ending_at_the_last_action() {
        assert_eq!(frame_actions(5, 300), vec![0, 1, 2, 3, 4]);
        assert!(frame_actions(0, 300).is_empty());
        let f = frame_actions(1000, 300);
        assert_eq!(f.len(), 300);
        assert_eq!(*f.last().unwrap(), 999);
        assert!(f.windows(2).all(|w| w[0] < w[1] && w[1] - w[0] <= 4));
        let f = frame_actions(301, 300);
        assert_eq!((f.len(), f[0], f[299]), (300, 1, 300));
    }

    #[test]
    fn a_gif_of_changed_rectangles_decodes_to_the_frames() {
        let blank = Rgb { width: 40, height: 30, pixels: vec![255; 40 * 30 * 3] };
        let mut frames = vec![blank.clone()];
        for k in 0..12u32 {
            let mut f = frames.last().unwrap().clone();
            rect(&mut f, (k * 3, 10), (k * 3 + 3, 14), [200, 0, 0]);
            frames.push(f);
        }
        frames.push(frames.last().unwrap().clone());
        overlay(&mut frames[0], 0.5, 7, 10);
        let bytes = gif(&frames).unwrap();
        assert_eq!(&bytes[..6], b"GIF89a");
        let mut opts = gif::DecodeOptions::new();
        opts.set_color_output(gif::ColorOutput::RGBA);
        let mut dec = opts.read_info(bytes.as_slice()).unwrap();
        let mut n = 0;
        let mut first_whole = false;
        while let Some(f) = dec.read_next_frame().unwrap() {
            if n == 0 {
                first_whole = (f.width, f.height) == (40, 30);
            } else if n < 13 {
                // Only the block drawn (and the overlay's corner is not redrawn).
                assert!(f.width <= 40 && f.height <= 30);
            }
            n += 1;
        }
        assert!(first_whole);
        assert_eq!(n, frames.len());
    }

    #[test]
    fn mp4_without_ffmpeg_names_the_program() {
        if find_program("ffmpeg").is_some() {
            return;
        }
        let e = ffmpeg().unwrap_err().to_string();
        assert!(e.contains("`ffmpeg`") && e.contains("PATH"), "{e}");
    }
}
