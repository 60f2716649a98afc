//! Feasibility search per turning mode on a grid of body-centre positions × headings; minimum width by bisection; G regions.

use crate::bend::{Bend, MARGIN_M, Vehicle};

mod bfs;
mod region;

pub use region::{GRegion, min_width_m, passes};

/// How the vehicle changes direction at the bend.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Mode {
    /// Omnidirectional base: slides through with leg 1's heading, never turning.
    Oblique,
    /// Turns on the spot at one point (between straight slides in each leg).
    Spin,
    /// Drives forward while turning with any curvature, including on the spot.
    Curve,
    /// Turns along one arc of fixed radius (the paper's R = Wc/2) about the body centre.
    CurveFixedRadius,
    /// Forward driving about the kinematic point (front axle) with radius ≥ the vehicle's
    /// minimum; no sideways motion at all.
    Truck,
}

impl Mode {
    pub const ALL: [Mode; 5] = [
        Mode::Oblique,
        Mode::Spin,
        Mode::Curve,
        Mode::CurveFixedRadius,
        Mode::Truck,
    ];

    pub fn name(&self) -> &'static str {
        match self {
            Mode::Oblique => "oblique",
            Mode::Spin => "spin",
            Mode::Curve => "curve",
            Mode::CurveFixedRadius => "curve_fixed_radius",
            Mode::Truck => "truck",
        }
    }
}

/// Grid and heading resolution of the search.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Resolution {
    pub cell_m: f64,
    pub heading_rad: f64,
}

/// The search space around one bend.
#[derive(Debug)]
pub struct Space {
    pub bend: Bend,
    pub vehicle: Vehicle,
    pub mode: Mode,
    pub res: Resolution,
    /// Legs are searched this far from the corner (centre lines' crossing).
    pub reach_m: f64,
    pub x0: f64,
    pub y0: f64,
    pub nx: usize,
    pub ny: usize,
    /// Heading layers: 0 = leg 1's heading … `layers - 1` = leg 2's.
    pub layers: usize,
    pub dphi: f64,
    /// Radii one heading step may turn on. Free curvature is any sequence of on-the-spot
    /// steps, arcs of Wc/2 (the fixed-radius mode's), L0/2, L0 and 2·L0, and straight
    /// steps; the fixed-radius mode and the truck have one radius each.
    pub turn_radii_m: Vec<f64>,
    /// Clearance every step keeps: the sagitta of the widest arc a body point follows in
    /// one heading step (0.26 mm for the A30 body on a 2·L0 arc), at least `MARGIN_M`.
    pub margin_m: f64,
    /// (sin, cos) of each layer's heading: corners and edge normals without trigonometry
    /// in the search's inner loop.
    trig: Vec<[f64; 2]>,
}

/// One search's visited states: parent (state index + 1; 0 = unvisited) and the exact
/// pose each state keeps (of the arrivals before it was expanded, the one nearest its
/// cell's centre).
#[derive(Debug)]
pub struct Reached {
    pub parent: Vec<u32>,
    pub pos: Vec<[f64; 2]>,
    pub goal: Option<u32>,
}

pub(crate) const ROOT: u32 = u32::MAX;

/// The search window's corners: both legs out to `reach_m` (and a T's left arm).
fn window(bend: &Bend, reach_m: f64) -> ([f64; 2], [f64; 2]) {
    let hw = bend.width_m / 2.0;
    let corners = [
        [-hw, -reach_m],
        [hw, -reach_m],
        bend.j,
        bend.i,
        [
            bend.d2[0] * reach_m + bend.l2[0] * hw,
            bend.d2[1] * reach_m + bend.l2[1] * hw,
        ],
        [
            bend.d2[0] * reach_m - bend.l2[0] * hw,
            bend.d2[1] * reach_m - bend.l2[1] * hw,
        ],
    ];
    // A T's left arm, searched as far as leg 2.
    let left_arm = [
        [
            -bend.d2[0] * reach_m + bend.l2[0] * hw,
            -bend.d2[1] * reach_m + bend.l2[1] * hw,
        ],
        [
            -bend.d2[0] * reach_m - bend.l2[0] * hw,
            -bend.d2[1] * reach_m - bend.l2[1] * hw,
        ],
    ];
    let corners = corners
        .into_iter()
        .chain(left_arm.into_iter().filter(|_| bend.tee));
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for c in corners {
        for k in 0..2 {
            lo[k] = lo[k].min(c[k]);
            hi[k] = hi[k].max(c[k]);
        }
    }
    (lo, hi)
}

/// The turning radii a mode searches, and the sweep margin that covers the sagitta of a
/// step's arc at the widest of them.
fn turn_radii(mode: Mode, vehicle: &Vehicle, l0: f64, dphi: f64) -> (Vec<f64>, f64) {
    let turn_radii_m = match mode {
        Mode::Oblique | Mode::Spin => vec![0.0],
        Mode::Curve => vec![0.0, vehicle.width_m / 2.0, l0 / 2.0, l0, 2.0 * l0],
        Mode::CurveFixedRadius => vec![vehicle.width_m / 2.0],
        Mode::Truck => vec![vehicle.min_radius_m],
    };
    // Body points turn about the arc centre at up to radius + |offset of the turning
    // point| + half the diagonal; between two states they bulge past the chord by the
    // sagitta r·(1 − cos(Δφ/2)).
    let widest = turn_radii_m.iter().copied().fold(0.0, f64::max)
        + vehicle.kinematic_ahead_m.abs()
        + l0 / 2.0;
    let margin_m = MARGIN_M.max(1.25 * widest * (1.0 - (dphi / 2.0).cos()));
    (turn_radii_m, margin_m)
}

impl Space {
    pub fn new(bend: Bend, vehicle: Vehicle, mode: Mode, res: Resolution) -> Self {
        let l0 = vehicle.circumscribed_m();
        // Room for the forklift's turning circle; every mode of one vehicle gets the same
        // legs, so their G areas compare.
        let turn_room = if vehicle.min_radius_m > 0.0 {
            2.0 * (vehicle.min_radius_m + vehicle.kinematic_ahead_m.abs())
        } else {
            0.0
        };
        let reach_m = bend.width_m / 2.0 + l0 + turn_room + 2.0 * res.cell_m;
        let (lo, hi) = window(&bend, reach_m);
        let h = res.cell_m;
        let layers = if mode == Mode::Oblique || bend.angle_rad == 0.0 {
            1
        } else {
            (bend.angle_rad / res.heading_rad).ceil() as usize + 1
        };
        let dphi = if layers > 1 {
            bend.angle_rad / (layers - 1) as f64
        } else {
            0.0
        };
        let (turn_radii_m, margin_m) = turn_radii(mode, &vehicle, l0, dphi);
        let mut space = Self {
            turn_radii_m,
            margin_m,
            trig: Vec::new(),
            bend,
            vehicle,
            mode,
            res,
            reach_m,
            x0: lo[0],
            y0: lo[1],
            nx: ((hi[0] - lo[0]) / h).ceil() as usize + 1,
            ny: ((hi[1] - lo[1]) / h).ceil() as usize + 1,
            layers,
            dphi,
        };
        space.trig = (0..layers)
            .map(|l| {
                let (s, c) = space.heading(l).sin_cos();
                [s, c]
            })
            .collect();
        space
    }

    /// Moves the grid origin back by a fraction of a cell (the window keeps covering the
    /// legs: one more cell in each direction).
    pub fn shift_grid(&mut self, fraction: [f64; 2]) {
        if fraction != [0.0, 0.0] {
            self.x0 -= fraction[0] * self.res.cell_m;
            self.y0 -= fraction[1] * self.res.cell_m;
            self.nx += 1;
            self.ny += 1;
        }
    }

    pub fn cells(&self) -> usize {
        self.nx * self.ny
    }

    pub fn cell_of(&self, p: [f64; 2]) -> Option<usize> {
        let ix = ((p[0] - self.x0) / self.res.cell_m).floor();
        let iy = ((p[1] - self.y0) / self.res.cell_m).floor();
        if ix < 0.0 || iy < 0.0 || ix >= self.nx as f64 || iy >= self.ny as f64 {
            return None;
        }
        Some(iy as usize * self.nx + ix as usize)
    }

    pub fn cell_centre(&self, cell: usize) -> [f64; 2] {
        let h = self.res.cell_m;
        [
            self.x0 + ((cell % self.nx) as f64 + 0.5) * h,
            self.y0 + ((cell / self.nx) as f64 + 0.5) * h,
        ]
    }

    pub fn heading(&self, layer: usize) -> f64 {
        self.bend.headings().0 - layer as f64 * self.dphi
    }

    /// Inside the searched part of the corridor (legs cut at `reach_m`).
    pub fn in_window(&self, p: [f64; 2]) -> bool {
        let along = self.bend.d2[0] * p[0] + self.bend.d2[1] * p[1];
        p[1] >= -self.reach_m
            && along <= self.reach_m
            && (!self.bend.tee || along >= -self.reach_m)
            && self.bend.clearance(p) > 0.0
    }

    /// In the first cell of the entry leg's cut end, where passages start.
    pub fn is_start(&self, p: [f64; 2]) -> bool {
        p[1] < -self.reach_m + self.res.cell_m
    }

    /// In the last cell of the exit leg's cut end, where passages end.
    pub fn is_goal(&self, p: [f64; 2]) -> bool {
        self.bend.d2[0] * p[0] + self.bend.d2[1] * p[1] > self.reach_m - self.res.cell_m
    }

    fn translates(&self, layer: usize) -> bool {
        self.mode != Mode::Truck && (layer == 0 || layer + 1 == self.layers)
    }

    fn drives_straight(&self, layer: usize) -> bool {
        matches!(self.mode, Mode::Curve | Mode::Truck)
            && (self.mode == Mode::Truck || (layer > 0 && layer + 1 < self.layers))
    }

    /// Body-centre displacement of one heading step from `layer` to `layer + 1` on an
    /// arc of `radius_m` (0: on the spot) about the turning point: the body centre for the
    /// AMV modes, the kinematic point for the truck.
    fn turn_displacement(&self, layer: usize, radius_m: f64) -> [f64; 2] {
        let (a, b) = (self.heading(layer), self.heading(layer + 1));
        let mid = (a + b) / 2.0;
        let chord = 2.0 * radius_m * (self.dphi / 2.0).sin();
        let k = if self.mode == Mode::Truck {
            self.vehicle.kinematic_ahead_m
        } else {
            0.0
        };
        [
            k * (a.cos() - b.cos()) + chord * mid.cos(),
            k * (a.sin() - b.sin()) + chord * mid.sin(),
        ]
    }

    /// Where a straight step from `p` along the unit vector `dir` ends: one cell on, or
    /// just out of p's cell if that is farther. A fixed one-cell step can end in the same
    /// cell on oblique headings (the diagonal is longer than a side), where pruning dropped
    /// it, and a vehicle that cannot slide sideways was then stuck in legs that are not
    /// axis-aligned.
    fn straight_step(&self, p: [f64; 2], dir: [f64; 2]) -> [f64; 2] {
        let t = self.exit_distance(p, dir).max(self.res.cell_m);
        [p[0] + t * dir[0], p[1] + t * dir[1]]
    }

    /// How far a straight drive from `p` along the unit vector `dir` goes to just leave
    /// p's cell.
    fn exit_distance(&self, p: [f64; 2], dir: [f64; 2]) -> f64 {
        let h = self.res.cell_m;
        let origin = [self.x0, self.y0];
        let mut t = f64::INFINITY;
        for k in 0..2 {
            let i = ((p[k] - origin[k]) / h).floor();
            if dir[k] > 1e-12 {
                t = t.min((origin[k] + (i + 1.0) * h - p[k]) / dir[k]);
            } else if dir[k] < -1e-12 {
                t = t.min((p[k] - (origin[k] + i * h)) / -dir[k]);
            }
        }
        // Just past the boundary, so the end lies in the neighbouring cell.
        t + 1e-6 * h
    }

    /// The body's corners at `p` in heading layer `layer`, and its two edge normals.
    fn body(&self, p: [f64; 2], layer: usize) -> ([[f64; 2]; 4], [[f64; 2]; 2]) {
        let [s, c] = self.trig[layer];
        let (hl, hw) = (self.vehicle.length_m / 2.0, self.vehicle.width_m / 2.0);
        let corners = [[hl, hw], [-hl, hw], [-hl, -hw], [hl, -hw]]
            .map(|[x, y]| [p[0] + c * x - s * y, p[1] + s * x + c * y]);
        (corners, [[c, s], [-s, c]])
    }

    /// Whether the body moves freely from `a` (see [`Space::body`]) to `q` in layer `ql`.
    fn free_to(&self, a: &([[f64; 2]; 4], [[f64; 2]; 2]), q: [f64; 2], ql: usize) -> bool {
        let b = self.body(q, ql);
        self.bend
            .sweep_free_axes(&a.0, &b.0, [a.1[0], a.1[1], b.1[0], b.1[1]], self.margin_m)
    }

    /// The chain of (position, heading) from a search root to state `s`.
    pub fn chain(&self, r: &Reached, mut s: usize) -> Vec<([f64; 2], f64)> {
        let mut out = Vec::new();
        loop {
            out.push((r.pos[s], self.heading(s / self.cells())));
            match r.parent[s] {
                ROOT => break,
                0 => break,
                p => s = p as usize - 1,
            }
        }
        out.reverse();
        out
    }
}
