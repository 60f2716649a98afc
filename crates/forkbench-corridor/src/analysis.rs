//! G regions against circle inflation, and their validation with parry2d at finer resolution than the search.

use forkbench_core::Pose2;

use crate::bend::{Junction, Vehicle};
use crate::search::{GRegion, Mode, Resolution, Space};

/// Bad corridor-analysis input.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CorridorError {
    #[error("{field} = {value}: {reason}")]
    Invalid {
        field: &'static str,
        value: f64,
        reason: &'static str,
    },
}

/// Checks the inputs of an analysis; every field is named in the error.
pub fn check_inputs(
    v: &Vehicle,
    junction: Junction,
    width_m: Option<f64>,
    angles_deg: &[f64],
    cell_m: f64,
) -> Result<(), CorridorError> {
    let bad = |field, value, reason| {
        Err(CorridorError::Invalid {
            field,
            value,
            reason,
        })
    };
    for (field, value) in [
        ("vehicle length_m", v.length_m),
        ("vehicle width_m", v.width_m),
    ] {
        if !(value.is_finite() && value > 0.0) {
            return bad(field, value, "must be a positive size");
        }
    }
    if v.width_m > v.length_m {
        return bad(
            "vehicle width_m",
            v.width_m,
            "must not exceed the length (give LcxWc)",
        );
    }
    if !(cell_m.is_finite() && cell_m > 0.0 && cell_m <= v.width_m / 4.0) {
        return bad(
            "resolution_m",
            cell_m,
            "must be positive and at most a quarter of the vehicle width",
        );
    }
    if let Some(w) = width_m {
        if !(w.is_finite() && w > 0.0) {
            return bad("width_m", w, "must be a positive corridor width");
        }
        if w <= v.width_m {
            return bad(
                "width_m",
                w,
                "is not wider than the vehicle (Li = Wc): no pose passes",
            );
        }
    }
    for &a in angles_deg {
        if !(a.is_finite() && (0.0..=135.0).contains(&a)) {
            return bad("angle_deg", a, "must lie in 0…135°");
        }
        if junction == Junction::T && a != 90.0 {
            return bad("angle_deg", a, "a T junction turns by 90°");
        }
        // The minimum-width search starts just wider than the vehicle's circumscribed
        // circle: a resolution too fine for even that is refused here, not by the allocator.
        let first = v.circumscribed_m() + cell_m;
        if search_states(v, junction, first, a, cell_m) > MAX_SEARCH_STATES {
            return bad(
                "resolution_m",
                cell_m,
                "needs more than 1e7 search states (cells × 1° heading layers) even for the \
                 narrowest corridor the search tries: use a coarser --resolution",
            );
        }
        if let Some(w) = width_m
            && search_states(v, junction, w, a, cell_m) > MAX_SEARCH_STATES
        {
            return bad(
                "width_m",
                w,
                "needs more than 1e7 search states (cells × 1° heading layers) at this \
                 resolution: use a coarser --resolution or a narrower corridor",
            );
        }
    }
    Ok(())
}

/// Most search states (grid cells × heading layers) one analysis may allocate: bounds
/// its memory (about 20 bytes each) and time.
pub const MAX_SEARCH_STATES: f64 = 1e7;

/// The widest corridor, up to `upto_m`, whose search stays within
/// [`MAX_SEARCH_STATES`]: where the minimum-width search stops widening.
pub fn widest_searchable_m(
    v: &Vehicle,
    junction: Junction,
    angle_deg: f64,
    cell_m: f64,
    upto_m: f64,
) -> f64 {
    let fits = |w: f64| search_states(v, junction, w, angle_deg, cell_m) <= MAX_SEARCH_STATES;
    if fits(upto_m) {
        return upto_m;
    }
    let (mut lo, mut hi) = (v.width_m, upto_m);
    while hi - lo > cell_m {
        let mid = (lo + hi) / 2.0;
        if fits(mid) { lo = mid } else { hi = mid }
    }
    lo
}

/// States a search of this bend at this resolution allocates, in f64 (no overflow for
/// absurd widths), with 1° heading layers.
fn search_states(
    v: &Vehicle,
    junction: Junction,
    width_m: f64,
    angle_deg: f64,
    cell_m: f64,
) -> f64 {
    if width_m.is_nan() || width_m >= 1e4 {
        return f64::INFINITY;
    }
    let res = Resolution {
        cell_m,
        heading_rad: 1f64.to_radians(),
    };
    let space = Space::new(
        junction.bend(width_m, angle_deg.to_radians()),
        *v,
        Mode::Oblique,
        res,
    );
    space.nx as f64 * space.ny as f64 * (angle_deg + 1.0)
}

/// Areas claimed passable by circle inflation, and where each is wrong, for one mode.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Comparison {
    pub mode: Mode,
    pub g_area_m2: f64,
    /// Inflation by the inscribed circle (radius Wc/2): centres it calls free.
    pub inscribed_area_m2: f64,
    /// …of which outside G: the body collides or cannot pass there in this mode.
    pub inscribed_wrong_m2: f64,
    /// Inflation by the circumscribed circle (radius L0/2).
    pub circumscribed_area_m2: f64,
    /// G positions it wrongly blocks.
    pub circumscribed_wrong_m2: f64,
}

pub fn compare(g: &GRegion) -> Comparison {
    let s = &g.space;
    let a = s.res.cell_m.powi(2);
    let (mut ins, mut ins_wrong, mut circ, mut circ_wrong, mut area) = (0, 0, 0, 0, 0);
    for (cell, through) in g.through.iter().enumerate() {
        let p = s.cell_centre(cell);
        if !s.in_window(p) {
            continue;
        }
        let c = s.bend.clearance(p);
        let in_g = through.is_some();
        area += usize::from(in_g);
        if c >= s.vehicle.inscribed_m() / 2.0 {
            ins += 1;
            ins_wrong += usize::from(!in_g);
        }
        if c >= s.vehicle.circumscribed_m() / 2.0 {
            circ += 1;
        } else if in_g {
            circ_wrong += 1;
        }
    }
    let m2 = |n: usize| n as f64 * a;
    Comparison {
        mode: s.mode,
        g_area_m2: m2(area),
        inscribed_area_m2: m2(ins),
        inscribed_wrong_m2: m2(ins_wrong),
        circumscribed_area_m2: m2(circ),
        circumscribed_wrong_m2: m2(circ_wrong),
    }
}

/// Outcome of checking sampled positions with parry2d.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub struct Validation {
    /// G positions whose whole passage was swept at 1 mm / 0.1° without contact.
    pub g_sampled: usize,
    pub g_passed: usize,
    /// Positions inscribed inflation calls free but outside G…
    pub inscribed_wrong_sampled: usize,
    /// …where the body touches a wall at every heading the mode can have there.
    pub inscribed_wrong_colliding: usize,
    /// …confirmed wrong: colliding at every heading, or outside G again when the search
    /// is repeated with half the cell (all four half-cells around the position).
    pub inscribed_wrong_confirmed: usize,
    /// …beyond G's edge, where the grid cannot explain a miss (more than one cell from any
    /// G cell, two for the truck): each of these must be confirmed.
    pub inscribed_wrong_beyond_edge: usize,
    pub inscribed_wrong_beyond_edge_confirmed: usize,
}

const FINE_STEP_M: f64 = 1e-3;
const FINE_STEP_RAD: f64 = 0.1 * std::f64::consts::PI / 180.0;

/// Sweeps up to `samples` G passages and inscribed-but-outside-G positions with parry2d.
pub fn validate(g: &GRegion, samples: usize) -> Validation {
    let s = &g.space;
    let obs = s.bend.obstacles(s.reach_m);
    let fp = s.vehicle.footprint();
    let hits = |p: [f64; 2], h: f64| obs.collides(&fp, &Pose2::new(p[0], p[1], h));
    let (g_sampled, g_passed) = sweep_g_passages(g, samples, &hits);
    let (h1, h2) = s.bend.headings();
    let headings: Vec<f64> = if s.mode == Mode::Oblique {
        vec![h1]
    } else {
        let n = ((h1 - h2) / FINE_STEP_RAD).ceil().max(1.0) as usize;
        (0..=n)
            .map(|i| h1 - (h1 - h2) * i as f64 / n as f64)
            .collect()
    };
    let wrong = inscribed_outside_g(g);
    // G's edge, as far as the grid blurs it: one cell of rasterisation, and for the truck
    // one more for the single pose a search state keeps (a vehicle that slides can move
    // onto any pose in a cell; the truck, driving forward only, cannot).
    let edge = if s.mode == Mode::Truck { 2 } else { 1 };
    let on_edge = |p: [f64; 2]| {
        let h = s.res.cell_m;
        (-edge..=edge).any(|dy| {
            (-edge..=edge).any(|dx| {
                s.cell_of([p[0] + f64::from(dx) * h, p[1] + f64::from(dy) * h])
                    .is_some_and(|c| g.through[c].is_some())
            })
        })
    };
    let stride = (wrong.len() / samples.max(1)).max(1);
    let fine = (!wrong.is_empty()).then(|| {
        let res = Resolution {
            cell_m: s.res.cell_m / 2.0,
            ..s.res
        };
        GRegion::compute(s.bend, s.vehicle, s.mode, res)
    });
    let outside_fine_g = |p: [f64; 2]| {
        let Some(f) = &fine else { return false };
        let q = s.res.cell_m / 4.0;
        [[-q, -q], [-q, q], [q, -q], [q, q]].iter().all(|d| {
            let c = [p[0] + d[0], p[1] + d[1]];
            f.space.in_window(c) && f.space.cell_of(c).is_some_and(|i| f.through[i].is_none())
        })
    };
    let (mut w_sampled, mut w_colliding, mut w_confirmed) = (0, 0, 0);
    let (mut beyond, mut beyond_confirmed) = (0, 0);
    for &cell in wrong.iter().step_by(stride) {
        let p = s.cell_centre(cell);
        w_sampled += 1;
        let collides = headings.iter().all(|&h| hits(p, h));
        w_colliding += usize::from(collides);
        let confirmed = collides || outside_fine_g(p);
        w_confirmed += usize::from(confirmed);
        if !on_edge(p) {
            beyond += 1;
            beyond_confirmed += usize::from(confirmed);
        }
    }
    Validation {
        g_sampled,
        g_passed,
        inscribed_wrong_sampled: w_sampled,
        inscribed_wrong_colliding: w_colliding,
        inscribed_wrong_confirmed: w_confirmed,
        inscribed_wrong_beyond_edge: beyond,
        inscribed_wrong_beyond_edge_confirmed: beyond_confirmed,
    }
}

/// Sweeps up to `samples` G passages at 1 mm / 0.1° steps: (sampled, collision-free).
fn sweep_g_passages(
    g: &GRegion,
    samples: usize,
    hits: &dyn Fn([f64; 2], f64) -> bool,
) -> (usize, usize) {
    let cells: Vec<usize> = g.cells().collect();
    let stride = (cells.len() / samples.max(1)).max(1);
    let (mut g_sampled, mut g_passed) = (0, 0);
    for &cell in cells.iter().step_by(stride) {
        let Some(path) = g.witness(cell) else {
            continue;
        };
        g_sampled += 1;
        let clean = path.windows(2).all(|w| {
            let ((a, ha), (b, hb)) = (w[0], w[1]);
            let d = (b[0] - a[0]).hypot(b[1] - a[1]);
            let n = ((d / FINE_STEP_M)
                .max((hb - ha).abs() / FINE_STEP_RAD)
                .ceil() as usize)
                .max(1);
            (0..=n).all(|i| {
                let t = i as f64 / n as f64;
                !hits(
                    [a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])],
                    ha + t * (hb - ha),
                )
            })
        });
        g_passed += usize::from(clean);
    }
    (g_sampled, g_passed)
}

/// Cells outside G that inscribed-circle inflation calls free.
fn inscribed_outside_g(g: &GRegion) -> Vec<usize> {
    let s = &g.space;
    // The legs' cut ends are left out: passages start and end there, in a band one cell
    // deep, so G there depends on where each grid cuts the window rather than on the bend.
    g.through
        .iter()
        .enumerate()
        .filter(|(c, t)| {
            let p = s.cell_centre(*c);
            t.is_none()
                && s.in_window(p)
                && !s.is_start(p)
                && !s.is_goal(p)
                && s.bend.clearance(p) >= s.vehicle.inscribed_m() / 2.0
        })
        .map(|(c, _)| c)
        .collect()
}
