//! Feasibility search per turning mode on a grid of body-centre positions × headings; minimum width by bisection; G regions.

use std::collections::VecDeque;

use rayon::prelude::*;

use crate::bend::{Bend, Junction, MARGIN_M, Vehicle};

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

const ROOT: u32 = u32::MAX;

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

    /// Breadth-first search from leg 1 (`forward`) or back from leg 2; stops at the first
    /// goal when `stop_at_goal`.
    pub fn search(&self, forward: bool, stop_at_goal: bool) -> Reached {
        let n = self.cells() * self.layers;
        let mut parent = vec![0u32; n];
        let mut pos = vec![[0.0f64; 2]; n];
        let mut queue = VecDeque::new();
        // A queued state not yet expanded takes a later arrival nearer its cell's centre.
        let mut expanded = vec![false; n];
        let (first, last) = (0, self.layers - 1);
        let start_layer = if forward { first } else { last };
        for cell in 0..self.cells() {
            let p = self.cell_centre(cell);
            let starts = if forward {
                self.is_start(p)
            } else {
                self.is_goal(p)
            };
            if starts
                && self.in_window(p)
                && self.free_to(&self.body(p, start_layer), p, start_layer)
            {
                let s = start_layer * self.cells() + cell;
                parent[s] = ROOT;
                pos[s] = p;
                queue.push_back(s as u32);
            }
        }
        let h = self.res.cell_m;
        let sign = if forward { 1.0 } else { -1.0 };
        let mut goal = None;
        let mut moves: Vec<([f64; 2], usize)> = Vec::with_capacity(10);
        while let Some(s) = queue.pop_front() {
            let s = s as usize;
            expanded[s] = true;
            let (layer, p) = (s / self.cells(), pos[s]);
            let done = if forward {
                layer == last && self.is_goal(p)
            } else {
                layer == first && self.is_start(p)
            };
            if done {
                goal = Some(s as u32);
                if stop_at_goal {
                    break;
                }
            }
            let head = self.heading(layer);
            let here = self.body(p, layer);
            moves.clear();
            if self.translates(layer) {
                for (dx, dy) in [
                    (1, 0),
                    (-1, 0),
                    (0, 1),
                    (0, -1),
                    (1, 1),
                    (1, -1),
                    (-1, 1),
                    (-1, -1),
                ] {
                    moves.push(([p[0] + dx as f64 * h, p[1] + dy as f64 * h], layer));
                }
                // Slides along leg 2 itself: lattice steps alone need a channel about a
                // cell wider than the body to zigzag along an oblique leg.
                let d2 = self.bend.d2;
                for dir in [d2, [-d2[0], -d2[1]]] {
                    moves.push((self.straight_step(p, dir), layer));
                }
            }
            if self.drives_straight(layer) {
                let dir = [sign * head.cos(), sign * head.sin()];
                let q = self.straight_step(p, dir);
                moves.push((q, layer));
                if self.mode == Mode::Truck && !stop_at_goal {
                    // A truck cannot slide back onto a ray whose cells other poses took
                    // over: for the whole reachable set (G regions) it also drives on
                    // through cells already reached to the first one that is not (one
                    // sweep covers the stretch: a translation's hull). Without it the
                    // truck's G missed strips along the walls up to 4 cells wide; a search
                    // for one passage (W_min) skips it, at 2.5× the time it moves W_min by
                    // under a cell.
                    // (Cells outside the corridor are never reached, so the walk stops
                    // at a wall; the move's own checks then drop it.)
                    let mut far = q;
                    let layer_base = layer * self.cells();
                    while self
                        .cell_of(far)
                        .is_some_and(|c| parent[layer_base + c] != 0)
                    {
                        far = self.straight_step(far, dir);
                    }
                    if far != q {
                        moves.push((far, layer));
                    }
                }
            }
            for &r in &self.turn_radii_m {
                if forward && layer < last {
                    let d = self.turn_displacement(layer, r);
                    moves.push(([p[0] + d[0], p[1] + d[1]], layer + 1));
                }
                if !forward && layer > first {
                    let d = self.turn_displacement(layer - 1, r);
                    moves.push(([p[0] - d[0], p[1] - d[1]], layer - 1));
                }
            }
            for &(q, ql) in &moves {
                if !self.in_window(q) {
                    continue;
                }
                let Some(cell) = self.cell_of(q) else {
                    continue;
                };
                let t = ql * self.cells() + cell;
                let seen = parent[t] != 0;
                // The pose a state keeps decides what follows, above all for the truck,
                // which cannot slide: keeping the first arrival made its W_min jump by
                // several cells under 1e-7 m changes. Preferring the arrival nearest the
                // cell centre (until the state is expanded) ties the choice to the grid,
                // not to the order of arrival; each kept move is still checked exactly.
                let better = seen && !expanded[t] && {
                    let c = self.cell_centre(cell);
                    let d = |p: [f64; 2]| (p[0] - c[0]).powi(2) + (p[1] - c[1]).powi(2);
                    d(q) < d(pos[t])
                };
                if (seen && !better) || !self.free_to(&here, q, ql) {
                    continue;
                }
                parent[t] = s as u32 + 1;
                pos[t] = q;
                if !seen {
                    queue.push_back(t as u32);
                }
            }
        }
        Reached { parent, pos, goal }
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

/// The movable range of one mode at one width.
#[derive(Debug)]
pub struct GRegion {
    pub space: Space,
    /// Per cell: one state on a passage through it (forward-reached and backward-reached
    /// in the same heading layer), if any.
    pub through: Vec<Option<usize>>,
    pub forward: Reached,
    pub backward: Reached,
}

impl GRegion {
    pub fn compute(bend: Bend, vehicle: Vehicle, mode: Mode, res: Resolution) -> Self {
        let space = Space::new(bend, vehicle, mode, res);
        let forward = space.search(true, false);
        let backward = space.search(false, false);
        let through = (0..space.cells())
            .map(|c| {
                (0..space.layers).map(|l| l * space.cells() + c).find(|&s| {
                    // Both searches reached the state, each with its own pose in the
                    // cell; the passage joins them by a slide, which must be free too.
                    let layer = s / space.cells();
                    forward.parent[s] != 0
                        && backward.parent[s] != 0
                        && space.free_to(&space.body(forward.pos[s], layer), backward.pos[s], layer)
                })
            })
            .collect();
        Self {
            space,
            through,
            forward,
            backward,
        }
    }

    pub fn cells(&self) -> impl Iterator<Item = usize> + '_ {
        self.through
            .iter()
            .enumerate()
            .filter_map(|(c, s)| s.map(|_| c))
    }

    pub fn area_m2(&self) -> f64 {
        self.cells().count() as f64 * self.space.res.cell_m.powi(2)
    }

    /// A whole passage through `cell`: from leg 1 to the cell, a step of at most one cell
    /// inside it, and on to leg 2.
    pub fn witness(&self, cell: usize) -> Option<Vec<([f64; 2], f64)>> {
        let s = self.through[cell]?;
        let mut path = self.space.chain(&self.forward, s);
        let mut back = self.space.chain(&self.backward, s);
        back.reverse();
        path.extend(back);
        Some(path)
    }
}

/// Whether the search finds a passage through a bend of `width_m`. A passage found is
/// real (every step is an exact sweep); a miss may be the grid's. The truck cannot slide
/// sideways, so which pose a cell keeps matters most there: it is also searched on a grid
/// shifted by half a cell diagonally, and passes if either finds a way.
pub fn passes(
    vehicle: &Vehicle,
    mode: Mode,
    junction: Junction,
    angle_rad: f64,
    res: Resolution,
    width_m: f64,
) -> bool {
    let shifts: &[[f64; 2]] = if mode == Mode::Truck {
        &[[0.0, 0.0], [0.5, 0.5]]
    } else {
        &[[0.0, 0.0]]
    };
    // The shifted searches are independent: run them on all cores, stop at the first way.
    shifts.par_iter().any(|s| {
        let mut space = Space::new(junction.bend(width_m, angle_rad), *vehicle, mode, res);
        space.shift_grid(*s);
        space.search(true, true).goal.is_some()
    })
}

/// Smallest width (bisection to a quarter cell; the grid itself limits it to about one
/// cell) at which `mode` passes the bend, or `None`
/// when even `max_width_m` does not.
pub fn min_width_m(
    vehicle: &Vehicle,
    mode: Mode,
    junction: Junction,
    angle_rad: f64,
    res: Resolution,
    max_width_m: f64,
) -> Option<f64> {
    let passes = |w: f64| passes(vehicle, mode, junction, angle_rad, res, w);
    let mut lo = vehicle.width_m;
    let mut hi = vehicle.circumscribed_m() + res.cell_m;
    while !passes(hi) {
        lo = hi;
        hi *= 1.5;
        if hi > max_width_m {
            return if passes(max_width_m) {
                bisect(lo, max_width_m, res.cell_m / 4.0, passes)
            } else {
                None
            };
        }
    }
    bisect(lo, hi, res.cell_m / 4.0, passes)
}

fn bisect(mut lo: f64, mut hi: f64, tol: f64, passes: impl Fn(f64) -> bool) -> Option<f64> {
    while hi - lo > tol {
        let mid = (lo + hi) / 2.0;
        if passes(mid) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    Some(hi)
}
