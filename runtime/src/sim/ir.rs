//! The infrared proximity model: 8 sensors on the body rim, a response for
//! flat walls and one for cylinders, fitted to real Khepera readings.
//!
//! For one sensor and one surface the model computes a log-intensity
//!
//! ```text
//! z = (reach - d) / decay + focus * (cos(alpha) - 1)
//! ```
//!
//! where `d` is the distance in mm from the sensor to the surface (for a wall:
//! perpendicular; for a cylinder: to its nearest point) and `alpha` the angle
//! between the sensor's axis and the direction to the surface (wall normal,
//! or cylinder centre). The von Mises term `focus * (cos - 1)` is the angular
//! lobe (about a Gaussian of width `1/sqrt(focus)` rad). The reading is the
//! soft saturation `v = e^z / (1 + e^(knee z))^(1/knee)`: exponential decay far
//! away, 1 when close. Readings of several surfaces add and clamp at 1.
//!
//! Cylinders of other radii than the measured 12.5 mm: we assume the returned
//! light scales with the fraction `r / (r + r0)` of the beam a cylinder of
//! radius `r` intercepts (a wall is the limit `r -> inf`); relative to the
//! measured cylinder that shifts `reach` by `decay * ln(g(r) / g(12.5))`.
//! With `r0 = 13` mm a 10 mm object reads 0.57 times as much as the 25 mm
//! one at the same distance (about 1.2 mm less reach with the fitted decay of
//! ~2.1 mm), and larger cylinders read more, up to 2 times (the limit of the
//! assumption). Held objects are off the floor and read nothing.

// Loops over the 8 sensors index several parallel arrays.
#![allow(clippy::needless_range_loop)]

use std::sync::OnceLock;

use nalgebra::{Point2, SMatrix, UnitComplex, Vector2};

use crate::program::{IrLayout, SensorSpot};

/// Number of IR sensors.
pub const SENSORS: usize = 8;
/// Radius of the cylinder the cylinder constants were measured with, mm.
pub const REF_CYLINDER_RADIUS: f32 = 12.5;
/// How far beyond the body surface a surface is still considered, mm. The
/// front sensors are at noise level by 41 mm, the most sensitive back ones
/// still read ~0.07 at 43 mm; beyond 60 mm the model gives < 0.002.
pub const RANGE: f32 = 60.0;
/// The nearest measured distance from the body surface, mm; objects closer
/// than this (virtual ones under the body) read as if at this distance.
pub const NEAREST: f32 = 5.0;

/// The response to one kind of surface, per sensor.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Response {
    /// Distance (mm, from the sensor) where `z = 0` head-on (reading ~0.5..0.7).
    pub reach: [f32; SENSORS],
    /// Exponential decay length, mm.
    pub decay: [f32; SENSORS],
    /// Angular concentration of the lobe (von Mises kappa).
    pub focus: [f32; SENSORS],
    /// Sharpness of the saturation (larger = harder knee).
    pub knee: f32,
}

/// The whole IR model: sensor geometry and the two responses.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IrModel {
    /// Where each sensor sits on the body rim, degrees counter-clockwise from
    /// the heading.
    pub position_deg: [f32; SENSORS],
    /// Where each sensor looks, degrees counter-clockwise from the heading.
    pub axis_deg: [f32; SENSORS],
    pub wall: Response,
    pub cylinder: Response,
    /// `r0` of the beam-fraction assumption `g(r) = r / (r + r0)`, mm.
    pub cylinder_r0: f32,
}

/// The fitted Khepera model.
///
/// Fitted by `fit_ir_model` in `runtime/tests/ir_data.rs` (run it with
/// `cargo test -p shaping-runtime --test ir_data -- --ignored --nocapture`):
/// a pattern search minimising the mean absolute error over all 20 distances
/// x 180 bearings of both real tables (wall and 25 mm cylinder), per sensor,
/// sharing the sensor geometry between the two surfaces; it prints this
/// constant. `cylinder_r0` is an assumption, not fitted (one diameter only).
pub const KHEPERA: IrModel = IrModel {
    position_deg: [70.25, 41.81, 11.06, -15.25, -43.00, -69.31, -164.75, 167.44],
    axis_deg: [67.06, 42.62, 2.31, -16.75, -46.62, -84.06, -178.19, 163.44],
    wall: Response {
        reach: [22.03, 21.59, 20.50, 17.94, 23.00, 26.19, 20.66, 25.31],
        decay: [3.50, 3.92, 3.59, 3.28, 3.78, 4.80, 3.64, 5.03],
        focus: [5.28, 5.53, 6.50, 6.94, 6.12, 4.62, 4.53, 3.50],
        knee: 3.0,
    },
    cylinder: Response {
        reach: [18.34, 18.38, 17.00, 15.16, 19.47, 21.53, 17.06, 21.06],
        decay: [2.22, 2.36, 2.09, 1.97, 2.12, 2.80, 2.25, 2.95],
        focus: [4.34, 4.56, 4.03, 3.94, 5.97, 4.41, 3.81, 3.56],
        knee: 2.0,
    },
    cylinder_r0: 13.0,
};

/// The soft saturation `e^z / (1 + e^(knee z))^(1/knee)`.
pub fn saturate(z: f32, knee: f32) -> f32 {
    let z = z as f64;
    let k = knee.max(0.1) as f64;
    // Computed in a form that does not overflow for large z.
    let v = if z > 0.0 {
        1.0 / (1.0 + (-k * z).exp()).powf(1.0 / k)
    } else {
        z.exp() / (1.0 + (k * z).exp()).powf(1.0 / k)
    };
    v as f32
}

impl IrModel {
    /// Reach of every sensor for a cylinder of radius `r` (see module doc).
    pub fn cylinder_reach(&self, r: f32) -> [f32; SENSORS] {
        let g = |r: f32| r / (r + self.cylinder_r0);
        let ratio = (g(r.max(0.5)) / g(REF_CYLINDER_RADIUS)).ln();
        let mut reach = self.cylinder.reach;
        for (s, x) in reach.iter_mut().enumerate() {
            *x += self.cylinder.decay[s] * ratio;
        }
        reach
    }

    /// Exact (table-free) reading of sensor `s` for a wall whose outward
    /// normal, in the body frame, is `normal` (unit) and whose distance from
    /// the body centre is `dist`; `body` is the body radius.
    pub fn wall_reading(&self, s: usize, body: f32, dist: f32, normal: Vector2<f32>) -> f32 {
        let g = Geometry::new(self, body);
        let d = dist - g.position(s).coords.dot(&normal);
        let cos_a = g.axis(s).dot(&normal);
        let r = &self.wall;
        saturate((r.reach[s] - d) / r.decay[s] + r.focus[s] * (cos_a - 1.0), r.knee)
    }

    /// Exact reading of sensor `s` for a cylinder of radius `radius` centred
    /// at `centre` (body frame, mm).
    pub fn cylinder_reading(&self, s: usize, body: f32, centre: Point2<f32>, radius: f32) -> f32 {
        let g = Geometry::new(self, body);
        let v = centre - g.position(s);
        let dist = v.norm().max(1e-3);
        let d = dist - radius;
        let cos_a = g.axis(s).dot(&v) / dist;
        let r = &self.cylinder;
        let reach = self.cylinder_reach(radius)[s];
        saturate((reach - d) / r.decay[s] + r.focus[s] * (cos_a - 1.0), r.knee)
    }
}

/// The rotation by `deg` degrees. sin and cos in f64, rounded once: the
/// correctly rounded values, the same whether or not the compiler folds the
/// model's constants (an f32 `sin_cos` at run time can be one unit in the
/// last place off).
fn turn(deg: f32) -> UnitComplex<f32> {
    let (s, c) = f64::from(deg.to_radians()).sin_cos();
    UnitComplex::from_cos_sin_unchecked(c as f32, s as f32)
}

/// The sensors in the body frame (x ahead, y to the left; mm), precomputed
/// for a body radius. One row per sensor, so that a product with a vector
/// projects every sensor on it at once (`pos * n`, `rays * n`).
#[derive(Clone, Copy, Debug)]
pub struct Geometry {
    /// Where each sensor sits, on the body rim: row `s` is sensor `s`'s (x, y).
    pub pos: SMatrix<f32, SENSORS, 2>,
    /// Where each sensor looks: row `s` is the unit vector of its axis.
    pub rays: SMatrix<f32, SENSORS, 2>,
}

impl Geometry {
    pub fn new(model: &IrModel, body: f32) -> Geometry {
        let pos = model.position_deg.map(|deg| (turn(deg) * Point2::new(body, 0.0)).coords.transpose());
        let rays = model.axis_deg.map(|deg| (turn(deg) * Vector2::x()).transpose());
        Geometry { pos: SMatrix::from_rows(&pos), rays: SMatrix::from_rows(&rays) }
    }

    /// The geometry of a declared layout (`body { proximity at [...] facing
    /// [...] }`) for a body radius: a sensor on the rim sits at `body` mm
    /// from the centre at its angle, a sensor at a point sits there.
    pub fn from_layout(layout: &IrLayout, body: f32) -> Geometry {
        let pos = layout.at.map(|spot| match spot {
            SensorSpot::Rim(deg) => (turn(deg) * Point2::new(body, 0.0)).coords.transpose(),
            SensorSpot::Point([x, y]) => Vector2::new(x, y).transpose(),
        });
        let rays = layout.facing.map(|deg| (turn(deg) * Vector2::x()).transpose());
        Geometry { pos: SMatrix::from_rows(&pos), rays: SMatrix::from_rows(&rays) }
    }

    /// Where sensor `s` sits.
    pub fn position(&self, s: usize) -> Point2<f32> {
        Point2::new(self.pos[(s, 0)], self.pos[(s, 1)])
    }

    /// The unit vector of sensor `s`'s axis.
    pub fn axis(&self, s: usize) -> Vector2<f32> {
        Vector2::new(self.rays[(s, 0)], self.rays[(s, 1)])
    }
}

/// Per-sensor constants in the form the inner loop uses.
#[derive(Clone, Copy, Debug)]
pub struct Coeffs {
    /// `reach / decay`.
    pub offset: [f32; SENSORS],
    /// `1 / decay`.
    pub inv_decay: [f32; SENSORS],
    pub focus: [f32; SENSORS],
}

impl Coeffs {
    pub fn new(reach: &[f32; SENSORS], r: &Response) -> Coeffs {
        let mut c = Coeffs { offset: [0.0; 8], inv_decay: [0.0; 8], focus: r.focus };
        for s in 0..SENSORS {
            let decay = r.decay[s].max(0.1);
            c.offset[s] = reach[s] / decay;
            c.inv_decay[s] = 1.0 / decay;
        }
        c
    }

    /// Log-intensity of sensor `s` at sensor distance `d` and lobe cosine `cos_a`.
    #[inline]
    pub fn z(&self, s: usize, d: f32, cos_a: f32) -> f32 {
        self.offset[s] - d * self.inv_decay[s] + self.focus[s] * (cos_a - 1.0)
    }
}

const Z_MIN: f32 = -9.0;
const Z_MAX: f32 = 8.0;
pub(crate) const TABLE_LEN: usize = 1024;
const Z_SCALE: f32 = (TABLE_LEN - 1) as f32 / (Z_MAX - Z_MIN);

/// A lookup table of [`saturate`] over `Z_MIN..Z_MAX` (linear interpolation).
#[derive(Debug)]
pub struct SatTable {
    v: [f32; TABLE_LEN + 1],
}

impl SatTable {
    fn new(knee: f32) -> SatTable {
        let mut v = [0.0; TABLE_LEN + 1];
        for (i, x) in v.iter_mut().enumerate().take(TABLE_LEN) {
            *x = saturate(Z_MIN + i as f32 / Z_SCALE, knee);
        }
        // Exactly 0 below the table and 1 above it.
        v[0] = 0.0;
        v[TABLE_LEN - 1] = 1.0;
        v[TABLE_LEN] = 1.0;
        SatTable { v }
    }

    /// `Z_MIN` and the scale that maps `Z_MIN..Z_MAX` to the table's
    /// indices (`t = (z - Z_MIN) * scale`).
    pub(crate) const SCALE: (f32, f32) = (Z_MIN, Z_SCALE);

    /// The table's values (the last two are 1).
    pub(crate) fn values(&self) -> &[f32; TABLE_LEN + 1] {
        &self.v
    }

    /// [`saturate`] at `z`, interpolated (no branches on the value).
    #[inline]
    pub fn get(&self, z: f32) -> f32 {
        let t = ((z - Z_MIN) * Z_SCALE).clamp(0.0, (TABLE_LEN - 1) as f32);
        let i = (t as usize).min(TABLE_LEN - 1);
        let f = t - i as f32;
        self.v[i] + (self.v[i + 1] - self.v[i]) * f
    }
}

/// The saturation tables of [`KHEPERA`] (wall, cylinder), built once.
pub fn tables() -> &'static (SatTable, SatTable) {
    static T: OnceLock<(SatTable, SatTable)> = OnceLock::new();
    T.get_or_init(|| (SatTable::new(KHEPERA.wall.knee), SatTable::new(KHEPERA.cylinder.knee)))
}
