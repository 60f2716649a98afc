//! Reeds-Shepp curves: the shortest path of a car that drives forwards and backwards at a bounded curvature (Reeds and Shepp 1990, the 48 words as OMPL enumerates them).

use std::f64::consts::{FRAC_PI_2, PI};

use forkbench_core::Pose2;

/// One piece of a Reeds-Shepp word.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Steer {
    Left,
    Straight,
    Right,
}

/// One segment: how it steers and its signed length (negative: driven backwards), in
/// metres once scaled by the turning radius.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Segment {
    pub steer: Steer,
    pub length_m: f64,
}

/// The shortest Reeds-Shepp path between two poses at turning radius `radius_m`.
#[derive(Debug, Clone, PartialEq)]
pub struct RsPath {
    pub segments: Vec<Segment>,
    pub radius_m: f64,
}

const ZERO: f64 = 1e-9;

use Steer::{Left as L, Right as R, Straight as S};

/// The 18 words (OMPL's `reedsSheppPathType`); unused pieces of shorter words are absent.
const WORDS: [&[Steer]; 18] = [
    &[L, R, L],
    &[R, L, R],
    &[L, R, L, R],
    &[R, L, R, L],
    &[L, R, S, L],
    &[R, L, S, R],
    &[L, S, R, L],
    &[R, S, L, R],
    &[L, R, S, R],
    &[R, L, S, L],
    &[R, S, R, L],
    &[L, S, L, R],
    &[L, S, R],
    &[R, S, L],
    &[L, S, L],
    &[R, S, R],
    &[L, R, S, L, R],
    &[R, L, S, R, L],
];

fn mod2pi(x: f64) -> f64 {
    let v = x % (2.0 * PI);
    if v < -PI {
        v + 2.0 * PI
    } else if v > PI {
        v - 2.0 * PI
    } else {
        v
    }
}

fn polar(x: f64, y: f64) -> (f64, f64) {
    (x.hypot(y), y.atan2(x))
}

fn tau_omega(u: f64, v: f64, xi: f64, eta: f64, phi: f64) -> (f64, f64) {
    let delta = mod2pi(u - v);
    let a = u.sin() - delta.sin();
    let b = u.cos() - delta.cos() - 1.0;
    let t1 = (eta * a - xi * b).atan2(xi * a + eta * b);
    let t2 = 2.0 * (delta.cos() - v.cos() - u.cos()) + 3.0;
    let tau = if t2 < 0.0 {
        mod2pi(t1 + PI)
    } else {
        mod2pi(t1)
    };
    (tau, mod2pi(tau - u + v - phi))
}

type Word = fn(f64, f64, f64) -> Option<[f64; 3]>;

/// Formula 8.1.
fn lp_sp_lp(x: f64, y: f64, phi: f64) -> Option<[f64; 3]> {
    let (u, t) = polar(x - phi.sin(), y - 1.0 + phi.cos());
    let v = mod2pi(phi - t);
    (t >= -ZERO && v >= -ZERO).then_some([t, u, v])
}

/// Formula 8.2.
fn lp_sp_rp(x: f64, y: f64, phi: f64) -> Option<[f64; 3]> {
    let (u1, t1) = polar(x + phi.sin(), y - 1.0 - phi.cos());
    let u1 = u1 * u1;
    if u1 < 4.0 {
        return None;
    }
    let u = (u1 - 4.0).sqrt();
    let t = mod2pi(t1 + 2.0_f64.atan2(u));
    let v = mod2pi(t - phi);
    (t >= -ZERO && v >= -ZERO).then_some([t, u, v])
}

/// Formula 8.3.
fn lp_rm_l(x: f64, y: f64, phi: f64) -> Option<[f64; 3]> {
    let (u1, theta) = polar(x - phi.sin(), y - 1.0 + phi.cos());
    if u1 > 4.0 {
        return None;
    }
    let u = -2.0 * (0.25 * u1).asin();
    let t = mod2pi(theta + 0.5 * u + PI);
    let v = mod2pi(phi - t + u);
    (t >= -ZERO && u <= ZERO).then_some([t, u, v])
}

/// Formula 8.7.
fn lp_rup_lum_rm(x: f64, y: f64, phi: f64) -> Option<[f64; 3]> {
    let (xi, eta) = (x + phi.sin(), y - 1.0 - phi.cos());
    let rho = 0.25 * (2.0 + xi.hypot(eta));
    if rho > 1.0 {
        return None;
    }
    let u = rho.acos();
    let (t, v) = tau_omega(u, -u, xi, eta, phi);
    (t >= -ZERO && v <= ZERO).then_some([t, u, v])
}

/// Formula 8.8.
fn lp_rum_lum_rp(x: f64, y: f64, phi: f64) -> Option<[f64; 3]> {
    let (xi, eta) = (x + phi.sin(), y - 1.0 - phi.cos());
    let rho = (20.0 - xi * xi - eta * eta) / 16.0;
    if !(0.0..=1.0).contains(&rho) {
        return None;
    }
    let u = -rho.acos();
    if u < -0.5 * PI {
        return None;
    }
    let (t, v) = tau_omega(u, u, xi, eta, phi);
    (t >= -ZERO && v >= -ZERO).then_some([t, u, v])
}

/// Formula 8.9.
fn lp_rm_sm_lm(x: f64, y: f64, phi: f64) -> Option<[f64; 3]> {
    let (rho, theta) = polar(x - phi.sin(), y - 1.0 + phi.cos());
    if rho < 2.0 {
        return None;
    }
    let r = (rho * rho - 4.0).sqrt();
    let u = 2.0 - r;
    let t = mod2pi(theta + r.atan2(-2.0));
    let v = mod2pi(phi - 0.5 * PI - t);
    (t >= -ZERO && u <= ZERO && v <= ZERO).then_some([t, u, v])
}

/// Formula 8.10.
fn lp_rm_sm_rm(x: f64, y: f64, phi: f64) -> Option<[f64; 3]> {
    let (xi, eta) = (x + phi.sin(), y - 1.0 - phi.cos());
    let (rho, theta) = polar(-eta, xi);
    if rho < 2.0 {
        return None;
    }
    let t = theta;
    let u = 2.0 - rho;
    let v = mod2pi(t + 0.5 * PI - phi);
    (t >= -ZERO && u <= ZERO && v <= ZERO).then_some([t, u, v])
}

/// Formula 8.11.
fn lp_rm_s_lm_rp(x: f64, y: f64, phi: f64) -> Option<[f64; 3]> {
    let (xi, eta) = (x + phi.sin(), y - 1.0 - phi.cos());
    let (rho, _) = polar(xi, eta);
    if rho < 2.0 {
        return None;
    }
    let u = 4.0 - (rho * rho - 4.0).sqrt();
    if u > ZERO {
        return None;
    }
    let t = mod2pi(((4.0 - u) * xi - 2.0 * eta).atan2(-2.0 * xi + (u - 4.0) * eta));
    let v = mod2pi(t - phi);
    (t >= -ZERO && v >= -ZERO).then_some([t, u, v])
}

/// How a formula's (t, u, v) become a word's segment lengths.
type Lengths = fn([f64; 3]) -> Vec<f64>;

/// One family: a formula, solved in the four symmetric frames (plain, time-flipped,
/// reflected, both), and optionally also backwards (the goal seen from the start).
struct Family {
    formula: Word,
    /// Word index for the plain and time-flipped frames; the reflected frames use the next.
    word: usize,
    lengths: Lengths,
    backwards: bool,
}

const FAMILIES: [Family; 11] = [
    Family {
        formula: lp_sp_lp,
        word: 14,
        lengths: |[t, u, v]| vec![t, u, v],
        backwards: false,
    },
    Family {
        formula: lp_sp_rp,
        word: 12,
        lengths: |[t, u, v]| vec![t, u, v],
        backwards: false,
    },
    Family {
        formula: lp_rm_l,
        word: 0,
        lengths: |[t, u, v]| vec![t, u, v],
        backwards: false,
    },
    Family {
        formula: lp_rm_l,
        word: 0,
        lengths: |[t, u, v]| vec![v, u, t],
        backwards: true,
    },
    Family {
        formula: lp_rup_lum_rm,
        word: 2,
        lengths: |[t, u, v]| vec![t, u, -u, v],
        backwards: false,
    },
    Family {
        formula: lp_rum_lum_rp,
        word: 2,
        lengths: |[t, u, v]| vec![t, u, u, v],
        backwards: false,
    },
    Family {
        formula: lp_rm_sm_lm,
        word: 4,
        lengths: |[t, u, v]| vec![t, -FRAC_PI_2, u, v],
        backwards: false,
    },
    Family {
        formula: lp_rm_sm_rm,
        word: 8,
        lengths: |[t, u, v]| vec![t, -FRAC_PI_2, u, v],
        backwards: false,
    },
    Family {
        formula: lp_rm_sm_lm,
        word: 6,
        lengths: |[t, u, v]| vec![v, u, -FRAC_PI_2, t],
        backwards: true,
    },
    Family {
        formula: lp_rm_sm_rm,
        word: 10,
        lengths: |[t, u, v]| vec![v, u, -FRAC_PI_2, t],
        backwards: true,
    },
    // Formula 8.11: two quarter turns around the straight.
    Family {
        formula: lp_rm_s_lm_rp,
        word: 16,
        lengths: |[t, u, v]| vec![t, -FRAC_PI_2, u, -FRAC_PI_2, v],
        backwards: false,
    },
];

/// What a path costs beyond its length: multipliers on distance driven backwards and
/// turning, and a price per change of direction (in metres).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Costs {
    pub reverse: f64,
    pub turn: f64,
    pub cusp_m: f64,
}

impl Costs {
    /// Length alone: the classic shortest path.
    pub const LENGTH: Self = Self {
        reverse: 1.0,
        turn: 1.0,
        cusp_m: 0.0,
    };

    /// The cost of a word's lengths (turning radius 1), the cusp price scaled to it.
    fn of(&self, word: usize, lengths: &[f64], radius_m: f64) -> f64 {
        let mut total = 0.0;
        let mut last = 0.0;
        for (steer, &l) in WORDS[word].iter().zip(lengths) {
            if l.abs() <= ZERO {
                continue;
            }
            let mut c = l.abs();
            if l < 0.0 {
                c *= self.reverse;
            }
            if *steer != Steer::Straight {
                c *= self.turn;
            }
            if last != 0.0 && f64::signum(last) != l.signum() {
                c += self.cusp_m / radius_m;
            }
            total += c;
            last = l;
        }
        total
    }
}

/// The costs and the turning radius a word is priced at.
type Pricing = (Costs, f64);

fn consider(
    best: &mut Option<(f64, usize, Vec<f64>)>,
    (c, radius_m): &Pricing,
    word: usize,
    lengths: Vec<f64>,
) {
    let total = c.of(word, &lengths, *radius_m);
    if best.as_ref().is_none_or(|(b, _, _)| total < *b) {
        *best = Some((total, word, lengths));
    }
}

/// The cheapest word from the origin (heading 0) to (x, y, phi), turning radius 1: its
/// index into [`WORDS`] and signed lengths (radians for turns, metres for straights).
fn shortest(x: f64, y: f64, phi: f64, c: &Pricing) -> Option<(usize, Vec<f64>)> {
    let mut best = None;
    let (xb, yb) = (x * phi.cos() + y * phi.sin(), x * phi.sin() - y * phi.cos());
    for f in &FAMILIES {
        let (px, py) = if f.backwards { (xb, yb) } else { (x, y) };
        for (sx, sy, flip) in [
            (1.0, 1.0, false),
            (-1.0, 1.0, true),
            (1.0, -1.0, false),
            (-1.0, -1.0, true),
        ] {
            let Some(tuv) = (f.formula)(sx * px, sy * py, sx * sy * phi) else {
                continue;
            };
            let word = if sy > 0.0 { f.word } else { f.word + 1 };
            let mut lengths = (f.lengths)(tuv);
            if flip {
                lengths.iter_mut().for_each(|l| *l = -*l);
            }
            consider(&mut best, c, word, lengths);
        }
    }
    best.map(|(_, w, l)| (w, l))
}

impl RsPath {
    /// The shortest path from `from` to `to` at turning radius `radius_m` (> 0).
    pub fn between(from: &Pose2, to: &Pose2, radius_m: f64) -> Option<Self> {
        Self::cheapest(from, to, radius_m, Costs::LENGTH)
    }

    /// Of the 48 candidate paths, the one of least `costs`.
    pub fn cheapest(from: &Pose2, to: &Pose2, radius_m: f64, costs: Costs) -> Option<Self> {
        let (dx, dy) = (to.x_m - from.x_m, to.y_m - from.y_m);
        let (s, c) = from.heading_rad.sin_cos();
        let x = (c * dx + s * dy) / radius_m;
        let y = (-s * dx + c * dy) / radius_m;
        let phi = to.heading_rad - from.heading_rad;
        let (word, lengths) = shortest(x, y, phi, &(costs, radius_m))?;
        let segments = WORDS[word]
            .iter()
            .zip(lengths)
            .filter(|(_, l)| l.abs() > ZERO)
            .map(|(&steer, l)| Segment {
                steer,
                length_m: l * radius_m,
            })
            .collect();
        Some(Self { segments, radius_m })
    }

    /// Total length driven, forwards and backwards.
    pub fn length_m(&self) -> f64 {
        self.segments.iter().map(|s| s.length_m.abs()).sum()
    }

    /// Poses every `step_m` or less along the path from `from`, each with its signed
    /// curvature and whether it is driven backwards; the first is `from`, the last the end.
    pub fn sample(&self, from: &Pose2, step_m: f64) -> Vec<(Pose2, f64, bool)> {
        let mut out = vec![(*from, 0.0, false)];
        let mut at = *from;
        for seg in &self.segments {
            let n = (seg.length_m.abs() / step_m).ceil().max(1.0) as usize;
            let ds = seg.length_m / n as f64;
            let kappa = match seg.steer {
                Steer::Left => 1.0 / self.radius_m,
                Steer::Right => -1.0 / self.radius_m,
                Steer::Straight => 0.0,
            };
            for _ in 0..n {
                at = advance(&at, ds, kappa);
                out.push((at, kappa, seg.length_m < 0.0));
            }
        }
        if let (Some(first), Some(second)) = (out.first().cloned(), out.get(1)) {
            out[0] = (first.0, second.1, second.2);
        }
        out
    }
}

/// The pose after driving signed distance `ds` at curvature `kappa` (exact arc).
pub fn advance(p: &Pose2, ds: f64, kappa: f64) -> Pose2 {
    let th = p.heading_rad;
    if kappa.abs() < 1e-12 {
        return Pose2::new(p.x_m + ds * th.cos(), p.y_m + ds * th.sin(), th);
    }
    let th2 = th + kappa * ds;
    Pose2::new(
        p.x_m + (th2.sin() - th.sin()) / kappa,
        p.y_m - (th2.cos() - th.cos()) / kappa,
        th2,
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use forkbench_core::units::wrap_angle;

    fn end(p: &RsPath, from: &Pose2) -> Pose2 {
        p.sample(from, 0.05).last().expect("samples").0
    }

    #[test]
    fn every_path_ends_at_its_goal() {
        let mut seed = 12345u64;
        let mut next = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut words = std::collections::BTreeSet::new();
        for _ in 0..5000 {
            let from = Pose2::new(next() * 10.0 - 5.0, next() * 10.0 - 5.0, next() * 6.0 - 3.0);
            let scale = if next() < 0.5 { 1.0 } else { 8.0 };
            let to = Pose2::new(
                from.x_m + (next() - 0.5) * scale,
                from.y_m + (next() - 0.5) * scale,
                next() * 6.0 - 3.0,
            );
            let p = RsPath::between(&from, &to, 0.94).expect("a Reeds-Shepp path always exists");
            let e = end(&p, &from);
            assert!((e.x_m - to.x_m).hypot(e.y_m - to.y_m) < 1e-6, "{p:?}");
            assert!(wrap_angle(e.heading_rad - to.heading_rad).abs() < 1e-6);
            words.insert(
                p.segments
                    .iter()
                    .map(|s| format!("{:?}{}", s.steer, if s.length_m < 0.0 { '-' } else { '+' }))
                    .collect::<String>(),
            );
        }
        assert!(words.len() > 20, "only {} distinct words", words.len());
    }

    #[test]
    fn straight_ahead_and_behind_are_straights() {
        let o = Pose2::new(0.0, 0.0, 0.0);
        let ahead = RsPath::between(&o, &Pose2::new(3.0, 0.0, 0.0), 1.0).expect("a path");
        assert_eq!(ahead.segments.len(), 1);
        assert!((ahead.segments[0].length_m - 3.0).abs() < 1e-9);
        let behind = RsPath::between(&o, &Pose2::new(-2.0, 0.0, 0.0), 1.0).expect("a path");
        assert!((behind.segments[0].length_m + 2.0).abs() < 1e-9);
    }

    #[test]
    fn a_quarter_turn_is_a_quarter_circle() {
        let p = RsPath::between(
            &Pose2::new(0.0, 0.0, 0.0),
            &Pose2::new(2.0, 2.0, FRAC_PI_2),
            2.0,
        )
        .expect("a path");
        assert!((p.length_m() - PI).abs() < 1e-9, "{p:?}");
    }
}
