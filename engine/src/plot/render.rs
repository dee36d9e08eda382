//! Shared machinery: font registration, writing both files, styles and small
//! geometry helpers used by every picture.

use std::ffi::OsString;
use std::fs;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use plotters::style::{register_font, FontStyle};

use super::PlotError;

/// Font family name every picture uses; registered at first use.
pub(super) const FAMILY: &str = "sans-serif";
/// Height of the strip above a chart that holds the title.
pub(super) const TITLE_H: u32 = 48;

pub(super) type DrawResult<DB> = Result<(), DrawingAreaErrorKind<<DB as DrawingBackend>::ErrorType>>;

/// A picture that can be drawn on any backend.
pub(super) trait Figure {
    /// Canvas size in pixels; `text` says whether text will be drawn.
    fn size(&self, text: bool) -> (u32, u32);
    /// Draws the whole picture; never draws text when `text` is false.
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>, text: bool) -> DrawResult<DB>;
}

/// Environment variable naming a TrueType file to use instead of searching.
const FONT_ENV: &str = "SHAPING_PLOT_FONT";

const FONT_CANDIDATES: &[(&str, Option<&str>)] = &[
    (
        "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf",
        Some("/usr/share/fonts/truetype/dejavu/DejaVuSans-Bold.ttf"),
    ),
    ("/usr/share/fonts/TTF/DejaVuSans.ttf", Some("/usr/share/fonts/TTF/DejaVuSans-Bold.ttf")),
    ("/usr/share/fonts/dejavu/DejaVuSans.ttf", Some("/usr/share/fonts/dejavu/DejaVuSans-Bold.ttf")),
    (
        "/usr/share/fonts/dejavu-sans-fonts/DejaVuSans.ttf",
        Some("/usr/share/fonts/dejavu-sans-fonts/DejaVuSans-Bold.ttf"),
    ),
    ("/usr/local/share/fonts/DejaVuSans.ttf", Some("/usr/local/share/fonts/DejaVuSans-Bold.ttf")),
    (
        "/usr/share/fonts/truetype/liberation/LiberationSans-Regular.ttf",
        Some("/usr/share/fonts/truetype/liberation/LiberationSans-Bold.ttf"),
    ),
    ("/usr/share/fonts/liberation-sans/LiberationSans-Regular.ttf", None),
    (
        "/usr/share/fonts/truetype/freefont/FreeSans.ttf",
        Some("/usr/share/fonts/truetype/freefont/FreeSansBold.ttf"),
    ),
    (
        "/System/Library/Fonts/Supplemental/Arial.ttf",
        Some("/System/Library/Fonts/Supplemental/Arial Bold.ttf"),
    ),
    ("/Library/Fonts/Arial.ttf", None),
    ("C:\\Windows\\Fonts\\arial.ttf", Some("C:\\Windows\\Fonts\\arialbd.ttf")),
];

static FONT: OnceLock<Option<PathBuf>> = OnceLock::new();

/// The TrueType file registered for text, registering one at the first call:
/// the file named by `SHAPING_PLOT_FONT` if set (and only that one), else the
/// first of a list of common system locations (DejaVu Sans first). `None`
/// means pictures are drawn without text.
pub fn font_path() -> Option<&'static Path> {
    FONT.get_or_init(register_system_font).as_deref()
}

fn register_system_font() -> Option<PathBuf> {
    if let Some(p) = std::env::var_os(FONT_ENV) {
        let p = PathBuf::from(p);
        return register_file(&p, FontStyle::Normal).then_some(p);
    }
    for (regular, bold) in FONT_CANDIDATES {
        let path = Path::new(regular);
        if register_file(path, FontStyle::Normal) {
            if let Some(b) = bold {
                register_file(Path::new(b), FontStyle::Bold);
            }
            return Some(path.to_path_buf());
        }
    }
    None
}

fn register_file(path: &Path, style: FontStyle) -> bool {
    let Ok(bytes) = fs::read(path) else { return false };
    // plotters keeps fonts for the life of the program; this runs once per style.
    let bytes: &'static [u8] = Box::leak(bytes.into_boxed_slice());
    register_font(FAMILY, style, bytes).is_ok()
}

/// `<stem>.<ext>`, keeping any dot already in the stem.
pub(super) fn with_ext(stem: &Path, ext: &str) -> PathBuf {
    let mut s = OsString::from(stem.as_os_str());
    s.push(".");
    s.push(ext);
    PathBuf::from(s)
}

/// Writes `<stem>.svg` and `<stem>.png`, with text if a font is available.
pub(super) fn render(stem: &Path, fig: &impl Figure) -> Result<(), PlotError> {
    render_with(stem, fig, font_path().is_some())
}

/// Writes `<stem>.svg` and `<stem>.png`; `text` false draws no text at all.
pub(super) fn render_with(stem: &Path, fig: &impl Figure, text: bool) -> Result<(), PlotError> {
    let svg_path = with_ext(stem, "svg");
    let png_path = with_ext(stem, "png");
    if let Some(dir) = stem.parent().filter(|d| !d.as_os_str().is_empty()) {
        fs::create_dir_all(dir).map_err(|source| PlotError::Io { path: dir.to_path_buf(), source })?;
    }
    let (w, h) = fig.size(text);

    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (w, h)).into_drawing_area();
        fig.draw(&root, text).map_err(|e| draw_error(&svg_path, e))?;
        root.present().map_err(|e| draw_error(&svg_path, e))?;
    }
    fs::write(&svg_path, svg).map_err(|source| PlotError::Io { path: svg_path.clone(), source })?;

    let drawn = {
        let root = BitMapBackend::new(&png_path, (w, h)).into_drawing_area();
        fig.draw(&root, text).and_then(|()| root.present())
    };
    if let Err(e) = drawn {
        // The backend saves whatever it has when dropped; do not leave half a picture.
        let _ = fs::remove_file(&png_path);
        return Err(draw_error(&png_path, e));
    }
    Ok(())
}

/// Draws `fig` without text into memory.
pub(super) fn to_rgb(stem: &Path, fig: &impl Figure) -> Result<super::Rgb, PlotError> {
    let (w, h) = fig.size(false);
    let mut pixels = vec![0u8; w as usize * h as usize * 3];
    {
        let root = BitMapBackend::with_buffer(&mut pixels, (w, h)).into_drawing_area();
        fig.draw(&root, false).and_then(|()| root.present()).map_err(|e| draw_error(stem, e))?;
    }
    Ok(super::Rgb { width: w, height: h, pixels })
}

fn draw_error<E: std::error::Error + Send + Sync>(path: &Path, e: DrawingAreaErrorKind<E>) -> PlotError {
    PlotError::Draw { path: path.to_path_buf(), message: e.to_string() }
}

/// Splits off the title strip, draws the title in it, returns the rest.
pub(super) fn title_strip<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    title: &str,
    text: bool,
) -> Result<DrawingArea<DB, Shift>, DrawingAreaErrorKind<DB::ErrorType>> {
    root.fill(&WHITE)?;
    let (top, rest) = root.split_vertically(TITLE_H);
    if text && !title.is_empty() {
        let w = top.dim_in_pixel().0 as i32;
        // A title wider than the picture is set smaller (down to half its
        // size) rather than cut at both edges.
        let fits = |size: f64| {
            top.estimate_text_size(title, &title_style(size)).map_or(true, |(tw, _)| tw as i32 <= w - 24)
        };
        let size =
            [22.0, 20.0, 18.0, 16.0, 14.0, 13.0, 12.0, 11.0].into_iter().find(|&s| fits(s)).unwrap_or(11.0);
        let style = title_style(size).pos(Pos::new(HPos::Center, VPos::Center));
        top.draw_text(title, &style, (w / 2, TITLE_H as i32 / 2 + 4))?;
    }
    Ok(rest)
}

/// The title's font at `size` pixels (22 unless the title is too wide).
pub(super) fn title_style(size: f64) -> TextStyle<'static> {
    FontDesc::new(FontFamily::Name(FAMILY), size, FontStyle::Bold).into()
}

pub(super) fn label_style(size: f64) -> TextStyle<'static> {
    FontDesc::new(FontFamily::Name(FAMILY), size, FontStyle::Normal).into()
}

/// Axis tick labels: integers without decimals, others with up to 3 digits.
pub(super) fn tick(v: &f64) -> String {
    if (v - v.round()).abs() < 1e-9 {
        format!("{}", v.round() as i64)
    } else {
        let s = format!("{v:.3}");
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    }
}

pub(super) const GRID_BOLD: RGBColor = RGBColor(215, 215, 215);
pub(super) const GRID_LIGHT: RGBColor = RGBColor(240, 240, 240);
pub(super) const INK: RGBColor = RGBColor(40, 40, 40);
pub(super) const MARK: RGBColor = RGBColor(110, 110, 110);
/// Unlabelled marks (life boundaries), fainter than [`MARK`].
pub(super) const LIGHT_MARK: RGBColor = RGBColor(185, 185, 185);

/// A categorical palette (Tableau 10 order), repeated if needed.
pub(super) fn palette(i: usize) -> RGBColor {
    const P: [RGBColor; 10] = [
        RGBColor(31, 119, 180),
        RGBColor(255, 127, 14),
        RGBColor(44, 160, 44),
        RGBColor(214, 39, 40),
        RGBColor(148, 103, 189),
        RGBColor(140, 86, 75),
        RGBColor(227, 119, 194),
        RGBColor(127, 127, 127),
        RGBColor(188, 189, 34),
        RGBColor(23, 190, 207),
    ];
    P[i % P.len()]
}

/// A perceptually ordered colour for `t` in 0..1 (viridis-like, dark to yellow).
pub(super) fn ramp(t: f64) -> RGBColor {
    const STOPS: [(f64, f64, f64); 5] = [
        (68.0, 1.0, 84.0),
        (59.0, 82.0, 139.0),
        (33.0, 145.0, 140.0),
        (94.0, 201.0, 98.0),
        (253.0, 231.0, 37.0),
    ];
    let t = if t.is_finite() { t.clamp(0.0, 1.0) } else { 0.0 } * (STOPS.len() - 1) as f64;
    let i = (t.floor() as usize).min(STOPS.len() - 2);
    let f = t - i as f64;
    let (a, b) = (STOPS[i], STOPS[i + 1]);
    let mix = |x: f64, y: f64| (x + (y - x) * f).round().clamp(0.0, 255.0) as u8;
    RGBColor(mix(a.0, b.0), mix(a.1, b.1), mix(a.2, b.2))
}

/// Splits a polyline (pixels) into the drawn pieces of a dash pattern
/// (on, off, on, off, … lengths in pixels). A pattern that is empty or has a
/// non-positive length gives the whole line.
pub(super) fn dash(points: &[(i32, i32)], pattern: &[f64]) -> Vec<Vec<(i32, i32)>> {
    if pattern.is_empty() || pattern.iter().any(|&l| !(l > 0.0 && l.is_finite())) {
        return vec![points.to_vec()];
    }
    let px = |p: (f64, f64)| (p.0.round() as i32, p.1.round() as i32);
    let mut out = Vec::new();
    let mut cur: Vec<(i32, i32)> = Vec::new();
    let mut idx = 0;
    let mut left = pattern[0];
    if let Some(&first) = points.first() {
        cur.push(first);
    }
    for w in points.windows(2) {
        let a = (f64::from(w[0].0), f64::from(w[0].1));
        let b = (f64::from(w[1].0), f64::from(w[1].1));
        let len = ((b.0 - a.0).powi(2) + (b.1 - a.1).powi(2)).sqrt();
        let mut t = 0.0;
        while len - t > left {
            t += left;
            let p = px((a.0 + (b.0 - a.0) * t / len, a.1 + (b.1 - a.1) * t / len));
            if idx % 2 == 0 {
                cur.push(p);
                out.push(std::mem::take(&mut cur));
            }
            idx = (idx + 1) % pattern.len();
            left = pattern[idx];
            if idx % 2 == 0 {
                cur = vec![p];
            }
        }
        left -= len - t;
        if idx % 2 == 0 {
            cur.push(w[1]);
        }
    }
    if cur.len() >= 2 {
        out.push(cur);
    }
    out.retain(|s| s.len() >= 2);
    out
}

/// The dash-dot pattern of the paper's mean-fitness lines.
pub(super) const DASH_DOT: [f64; 4] = [10.0, 4.0, 2.5, 4.0];
/// A plain dashed pattern for markers.
pub(super) const DASHED: [f64; 2] = [6.0, 4.0];
/// A dotted pattern for light markers.
pub(super) const DOTTED: [f64; 2] = [2.0, 4.0];

/// Draws a polyline in backend pixels with a dash pattern on `root` (which
/// must be the unsplit root area, whose pixels are the backend's).
pub(super) fn draw_dashed<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    points: &[(i32, i32)],
    pattern: &[f64],
    style: ShapeStyle,
) -> DrawResult<DB> {
    for piece in dash(points, pattern) {
        root.draw(&PathElement::new(piece, style))?;
    }
    Ok(())
}

/// Consecutive runs of defined points; `None` breaks the line.
pub(super) fn runs(points: impl IntoIterator<Item = Option<(f64, f64)>>) -> Vec<Vec<(f64, f64)>> {
    let mut out = Vec::new();
    let mut cur = Vec::new();
    for p in points {
        match p {
            Some(p) => cur.push(p),
            None if !cur.is_empty() => out.push(std::mem::take(&mut cur)),
            None => {}
        }
    }
    if !cur.is_empty() {
        out.push(cur);
    }
    out
}

/// A finite f32 as f64.
pub(super) fn fin(v: f32) -> Option<f64> {
    v.is_finite().then_some(f64::from(v))
}

/// An axis range covering `values` (and `always`), padded by `pad` of its span,
/// never empty; `fallback` when nothing is finite.
pub(super) fn span(values: impl IntoIterator<Item = f64>, pad: f64, fallback: (f64, f64)) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values.into_iter().filter(|v| v.is_finite()) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if lo > hi {
        return fallback;
    }
    let d = hi - lo;
    if d < 1e-9 {
        let w = if lo.abs() > 1e-9 { lo.abs() * 0.1 } else { 1.0 };
        return (lo - w, hi + w);
    }
    (lo - d * pad, hi + d * pad)
}

/// The legend of a line chart, in its lower right corner.
pub fn series_legend<'a, DB: DrawingBackend + 'a>(
    chart: &mut ChartContext<'a, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>,
) -> DrawResult<DB> {
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::LowerRight)
        .margin(12)
        .label_font(label_style(15.0))
        .background_style(WHITE.mix(0.9))
        .border_style(GRID_BOLD)
        .draw()
}
