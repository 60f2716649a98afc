//! NAV350 positioning from reflectors: which reflectors the scanner sees past racks and walls, their measured range and bearing, association to the map, the weighted least-squares fix, and its predicted accuracy.
//!
//! SICK NAV350 (operating instructions 8013889 and the project's SPEC digest): 360°, 8 Hz,
//! reflectors measured from 0.5 m (the start of the measurement area) to 70 m (the
//! manual's beam-size table ends there), a pose needs at least three reflectors, and the
//! device reports the reflectors used and a mean deviation. The per-reflector range and
//! bearing noise are not published: σ 4 mm in range and 0.4 mrad in bearing are chosen so
//! that a fix from four reflectors around the truck at 10 m has the datasheet's ±4 mm
//! (read as 2σ) per axis. Pallets on the floor lie below the scanner's plane and never
//! block a reflector.

use forkbench_core::units::wrap_angle;
use forkbench_core::{Pose2, SettingsError};
use rand::{Rng, RngExt as _};
use rand_distr::StandardNormal;
use serde::{Deserialize, Serialize};

use crate::sight::Sight;

/// A point reflector in the map.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Reflector {
    pub name: String,
    pub x_m: f64,
    pub y_m: f64,
}

/// The NAV350's reflector measurement (SI).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ReflectorNavConfig {
    pub range_min_m: f64,
    pub range_max_m: f64,
    pub range_sigma_m: f64,
    pub bearing_sigma_rad: f64,
    /// A measured reflector is the map's nearest one within this distance of where the
    /// predicted pose puts it; two within it is ambiguous and neither is used.
    pub association_gate_m: f64,
    /// Fewest associated reflectors for a fix.
    pub min_reflectors: usize,
}

impl Default for ReflectorNavConfig {
    fn default() -> Self {
        Self {
            range_min_m: 0.5,
            range_max_m: 70.0,
            range_sigma_m: 0.004,
            bearing_sigma_rad: 0.0004,
            association_gate_m: 0.5,
            min_reflectors: 3,
        }
    }
}

impl ReflectorNavConfig {
    pub fn validate(&self) -> Result<(), SettingsError> {
        // Ranges a NAV350 can have: σ from a micrometre (the fix's weights are 1/σ², and
        // below that they overflow) to a metre or a radian (beyond that nothing is measured).
        for (f, v, lo, hi) in [
            ("range_sigma_m", self.range_sigma_m, 1e-6, 1.0),
            ("bearing_sigma_rad", self.bearing_sigma_rad, 1e-7, 1.0),
            ("association_gate_m", self.association_gate_m, 1e-3, 10.0),
            ("range_max_m", self.range_max_m, 0.1, 1000.0),
        ] {
            if !(v.is_finite() && (lo..=hi).contains(&v)) {
                return Err(SettingsError::field(
                    f,
                    format!("{v:?}: must lie within {lo:?}..{hi:?}"),
                ));
            }
        }
        if !(self.range_min_m.is_finite() && (0.0..self.range_max_m).contains(&self.range_min_m)) {
            return Err(SettingsError::field(
                "range_min_m",
                "must lie in [0, range_max_m)",
            ));
        }
        if self.min_reflectors < 3 {
            return Err(SettingsError::field(
                "min_reflectors",
                "must be at least 3 (a pose has three unknowns)",
            ));
        }
        if self.min_reflectors > 1000 {
            return Err(SettingsError::field(
                "min_reflectors",
                "must be at most 1000",
            ));
        }
        Ok(())
    }
}

/// A reflector hangs on a face: its sight line ends this short of it, so the face it
/// is on (met exactly where the line ends, or a rounding error beyond) does not hide it.
const ON_FACE_M: f64 = 1e-3;

/// Indices of the reflectors in line of sight from `at` and within range: no fixed
/// surface (rack, wall) between; pallets do not block.
pub fn visible(
    at: [f64; 2],
    reflectors: &[Reflector],
    sight: &Sight,
    cfg: &ReflectorNavConfig,
) -> Vec<usize> {
    reflectors
        .iter()
        .enumerate()
        .filter(|(_, r)| {
            let d = (r.x_m - at[0]).hypot(r.y_m - at[1]);
            let short = 1.0 - ON_FACE_M / d.max(ON_FACE_M);
            let end = [
                at[0] + (r.x_m - at[0]) * short,
                at[1] + (r.y_m - at[1]) * short,
            ];
            (cfg.range_min_m..=cfg.range_max_m).contains(&d) && !sight.blocked(at, end)
        })
        .map(|(i, _)| i)
        .collect()
}

/// One measured reflector: range and bearing in the sensor's frame (unlabelled).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Observation {
    pub range_m: f64,
    pub bearing_rad: f64,
}

/// What the scanner measures from `sensor` (its true pose): every visible reflector with
/// range and bearing noise drawn from `rng`.
pub fn measure<R: Rng + ?Sized>(
    sensor: &Pose2,
    reflectors: &[Reflector],
    seen: &[usize],
    cfg: &ReflectorNavConfig,
    rng: &mut R,
) -> Vec<Observation> {
    seen.iter()
        .map(|&i| measure_one(sensor, &reflectors[i], cfg, rng))
        .collect()
}

/// One reflector as [`measure`] measures it (range draw, then bearing draw).
pub fn measure_one<R: Rng + ?Sized>(
    sensor: &Pose2,
    reflector: &Reflector,
    cfg: &ReflectorNavConfig,
    rng: &mut R,
) -> Observation {
    let (dx, dy) = (reflector.x_m - sensor.x_m, reflector.y_m - sensor.y_m);
    let zr: f64 = rng.sample(StandardNormal);
    let zb: f64 = rng.sample(StandardNormal);
    Observation {
        range_m: dx.hypot(dy) + cfg.range_sigma_m * zr,
        bearing_rad: wrap_angle(dy.atan2(dx) - sensor.heading_rad + cfg.bearing_sigma_rad * zb),
    }
}

/// Pairs each observation with the map reflector nearest where `predicted` puts it,
/// within the gate and unambiguous; each reflector at most once.
pub fn associate(
    obs: &[Observation],
    predicted: &Pose2,
    reflectors: &[Reflector],
    cfg: &ReflectorNavConfig,
) -> Vec<(usize, usize)> {
    let mut out: Vec<(usize, usize)> = Vec::new();
    for (k, o) in obs.iter().enumerate() {
        let a = predicted.heading_rad + o.bearing_rad;
        let p = [
            predicted.x_m + o.range_m * a.cos(),
            predicted.y_m + o.range_m * a.sin(),
        ];
        let mut near = reflectors
            .iter()
            .enumerate()
            .filter(|(_, r)| (r.x_m - p[0]).hypot(r.y_m - p[1]) <= cfg.association_gate_m)
            .map(|(i, _)| i);
        if let (Some(i), None) = (near.next(), near.next())
            && !out.iter().any(|(_, j)| *j == i)
        {
            out.push((k, i));
        }
    }
    out
}

/// A pose fix as the device reports it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Fix {
    /// The sensor's pose.
    pub pose: Pose2,
    /// Names of the reflectors used.
    pub used: Vec<String>,
    /// Mean distance between each used reflector's map position and where the fix and
    /// its measurement put it.
    pub mean_deviation_m: f64,
    /// Predicted 1σ position error (radial) from the geometry and the noise model.
    pub sigma_m: f64,
}

/// A reflector at `p` as seen from `pose`: its predicted range and bearing (in the
/// sensor's frame, not wrapped), and their gradients with respect to (x, y, heading).
struct Predicted {
    range_m: f64,
    bearing_rad: f64,
    d_range: [f64; 3],
    d_bearing: [f64; 3],
}

fn predict(pose: &Pose2, p: &[f64; 2]) -> Predicted {
    let (dx, dy) = (p[0] - pose.x_m, p[1] - pose.y_m);
    let r2 = (dx * dx + dy * dy).max(1e-12);
    let r = r2.sqrt();
    Predicted {
        range_m: r,
        bearing_rad: dy.atan2(dx) - pose.heading_rad,
        d_range: [-dx / r, -dy / r, 0.0],
        d_bearing: [dy / r2, -dx / r2, -1.0],
    }
}

/// Information matrix JᵀWJ of range and bearing measurements of `pts` from `pose`.
fn information(pose: &Pose2, pts: &[[f64; 2]], cfg: &ReflectorNavConfig) -> [[f64; 3]; 3] {
    let mut m = [[0.0; 3]; 3];
    let (wr, wb) = (cfg.range_sigma_m.powi(-2), cfg.bearing_sigma_rad.powi(-2));
    for p in pts {
        let q = predict(pose, p);
        for (row, w) in [(q.d_range, wr), (q.d_bearing, wb)] {
            for i in 0..3 {
                for j in 0..3 {
                    m[i][j] += w * row[i] * row[j];
                }
            }
        }
    }
    m
}

/// The inverse of a 3 × 3 matrix (cofactors), `None` when singular.
fn invert(m: &[[f64; 3]; 3]) -> Option<[[f64; 3]; 3]> {
    let c = |i: usize, j: usize| {
        let (r0, r1) = ((i + 1) % 3, (i + 2) % 3);
        let (c0, c1) = ((j + 1) % 3, (j + 2) % 3);
        m[r0][c0] * m[r1][c1] - m[r0][c1] * m[r1][c0]
    };
    let det = m[0][0] * c(0, 0) + m[0][1] * c(0, 1) + m[0][2] * c(0, 2);
    let scale = m.iter().flatten().fold(0.0f64, |a, v| a.max(v.abs()));
    // NaN (a non-finite input) counts as singular too.
    if det.is_nan() || det.abs() <= 1e-12 * scale.powi(3) {
        return None;
    }
    Some(std::array::from_fn(|i| {
        std::array::from_fn(|j| c(j, i) / det)
    }))
}

/// Predicted 1σ radial position error of a fix from `at` on the reflectors at `pts`
/// (independent of heading for a 360° scanner); `None` with fewer than the minimum or a
/// degenerate geometry.
pub fn predicted_sigma_m(at: [f64; 2], pts: &[[f64; 2]], cfg: &ReflectorNavConfig) -> Option<f64> {
    if pts.len() < cfg.min_reflectors {
        return None;
    }
    let cov = invert(&information(&Pose2::new(at[0], at[1], 0.0), pts, cfg))?;
    Some((cov[0][0] + cov[1][1]).sqrt())
}

/// The weighted least-squares pose from associated observations (Gauss–Newton from
/// `predicted`); `None` with fewer than the minimum or a degenerate geometry.
pub fn solve(
    obs: &[Observation],
    pairs: &[(usize, usize)],
    reflectors: &[Reflector],
    predicted: &Pose2,
    cfg: &ReflectorNavConfig,
) -> Option<Fix> {
    if pairs.len() < cfg.min_reflectors {
        return None;
    }
    let pts: Vec<[f64; 2]> = pairs
        .iter()
        .map(|&(_, i)| [reflectors[i].x_m, reflectors[i].y_m])
        .collect();
    let mut pose = *predicted;
    for _ in 0..8 {
        let info = information(&pose, &pts, cfg);
        let inv = invert(&info)?;
        let mut g = [0.0; 3];
        let (wr, wb) = (cfg.range_sigma_m.powi(-2), cfg.bearing_sigma_rad.powi(-2));
        for (&(k, _), p) in pairs.iter().zip(&pts) {
            let q = predict(&pose, p);
            let er = obs[k].range_m - q.range_m;
            let eb = wrap_angle(obs[k].bearing_rad - q.bearing_rad);
            for (i, gi) in g.iter_mut().enumerate() {
                *gi += wr * q.d_range[i] * er + wb * q.d_bearing[i] * eb;
            }
        }
        let step: [f64; 3] = std::array::from_fn(|i| (0..3).map(|j| inv[i][j] * g[j]).sum());
        pose = Pose2::new(
            pose.x_m + step[0],
            pose.y_m + step[1],
            wrap_angle(pose.heading_rad + step[2]),
        );
        if step[0].hypot(step[1]) < 1e-9 && step[2].abs() < 1e-12 {
            break;
        }
    }
    let mean_deviation_m = pairs
        .iter()
        .zip(&pts)
        .map(|(&(k, _), p)| {
            let a = pose.heading_rad + obs[k].bearing_rad;
            (pose.x_m + obs[k].range_m * a.cos() - p[0])
                .hypot(pose.y_m + obs[k].range_m * a.sin() - p[1])
        })
        .sum::<f64>()
        / pairs.len() as f64;
    let cov = invert(&information(&pose, &pts, cfg))?;
    Some(Fix {
        pose,
        used: pairs
            .iter()
            .map(|&(_, i)| reflectors[i].name.clone())
            .collect(),
        mean_deviation_m,
        sigma_m: (cov[0][0] + cov[1][1]).sqrt(),
    })
}
