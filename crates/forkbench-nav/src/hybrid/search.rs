//! The Hybrid-A* search: expand arcs at κ_max and straights forwards and backwards from the best node, try a Reeds-Shepp shot to the goal on the way, stop at the budget.

use std::cmp::Reverse;
use std::collections::{BinaryHeap, HashMap};
use std::time::Instant;

use forkbench_core::Pose2;
use forkbench_core::units::wrap_angle;

use super::heuristic::Distances;
use super::refine::{Move, Run, move_cost, refine, sample};
use super::{Body, HybridQuery, Manoeuvre, relaxed_grid, segments_of};
use crate::reeds_shepp::{Costs, RsPath, Steer, advance};
use crate::{NavError, NavMap};

/// Spacing of the footprint checks along a straight move.
pub(super) const CHECK_STEP_M: f64 = 0.1;
/// Most distance any corner of the truck moves between two footprint checks (within the
/// margin the footprint is grown by).
pub const CORNER_STEP_M: f64 = 0.05;
/// Nodes between two Reeds-Shepp shots, per coarse cell of heuristic distance (Smac's
/// analytic expansion ratio).
const SHOT_RATIO: f64 = 3.5;

#[derive(Debug, Clone, Copy)]
struct Node {
    pose: Pose2,
    g: f64,
    parent: u32,
    /// The move that reached it: signed length and curvature.
    ds: f64,
    kappa: f64,
    /// Distance driven in this direction since the last cusp (or the start).
    run_m: f64,
}

/// One search's fixed inputs.
pub(super) struct Ctx<'a> {
    map: &'a NavMap,
    pub(super) q: &'a HybridQuery,
    body: Body,
    extent: ([f64; 2], [f64; 2]),
    dist: Distances,
    /// The relaxed grid grown by `proximity_m`: a centreline point outside it is far
    /// enough from everything.
    near: std::sync::Arc<crate::OccupancyGrid>,
    kappa_max: f64,
    step_m: f64,
    /// Farthest corner of the body from the fork root.
    reach_m: f64,
}

impl Ctx<'_> {
    /// Check spacing on a move at `kappa`: turning, the far corners sweep faster than the
    /// fork root.
    fn check_step_m(&self, kappa: f64) -> f64 {
        CHECK_STEP_M.min(CORNER_STEP_M / (kappa.abs() * self.reach_m).max(1e-9))
    }

    pub(super) fn free(&self, pose: &Pose2) -> bool {
        self.body.on_map(pose, self.extent) && self.body.free(&self.map.obstacles, pose)
    }

    fn key(&self, p: &Pose2) -> u64 {
        let c = self.q.params.cell_m;
        let ix = ((p.x_m - self.extent.0[0]) / c).floor().max(0.0) as u64;
        let iy = ((p.y_m - self.extent.0[1]) / c).floor().max(0.0) as u64;
        let h = self.q.params.headings as f64;
        let ih = ((wrap_angle(p.heading_rad) / std::f64::consts::TAU * h).round() as i64)
            .rem_euclid(h as i64) as u64;
        (ix << 40) | (iy << 20) | ih
    }

    fn heuristic(&self, p: &Pose2) -> f64 {
        let rs =
            RsPath::between(p, &self.q.goal, 1.0 / self.kappa_max).map_or(0.0, |r| r.length_m());
        rs.max(self.dist.at([p.x_m, p.y_m]))
    }

    /// The cost of a move from `from` (reached by `prev_ds`) of signed length `ds` at
    /// `kappa`, or `None` when the footprint strikes something on the way.
    fn step(&self, from: &Pose2, prev_ds: f64, ds: f64, kappa: f64) -> Option<(Pose2, f64)> {
        let n = (ds.abs() / self.check_step_m(kappa)).ceil().max(1.0) as usize;
        // Coarse to fine: the end, then every fourth pose, then the rest, so a blocked
        // move is usually refused after a check or two.
        let at_k = |k: usize| advance(from, ds * k as f64 / n as f64, kappa);
        let at = at_k(n);
        let order = (1..n)
            .filter(|k| k % 4 == 0)
            .chain((1..n).filter(|k| k % 4 != 0));
        if !self.free(&at) || order.into_iter().any(|k| !self.free(&at_k(k))) {
            return None;
        }
        let cost = move_cost(self, &[Move { ds, kappa }], prev_ds);
        Some((at, cost + self.proximity(&at) * ds.abs()))
    }

    /// Extra cost per metre near obstacles: `proximity_penalty` × how far inside
    /// `proximity_m` the chassis is (from the relaxed grid's view of the centreline).
    fn proximity(&self, pose: &Pose2) -> f64 {
        let p = &self.q.params;
        if p.proximity_penalty == 0.0 || p.proximity_m == 0.0 {
            return 0.0;
        }
        let behind = pose.to_world(&Pose2::new(-self.q.truck.body_length_m / 2.0, 0.0, 0.0));
        let near = [[pose.x_m, pose.y_m], [behind.x_m, behind.y_m]]
            .iter()
            .filter(|c| !self.near.is_free(**c))
            .count();
        p.proximity_penalty * near as f64 / 2.0
    }

    /// A Reeds-Shepp path from `from` to `to` whose footprint is clear (forwards only
    /// when so set) and whose runs between cusps are not too short, as moves. `prev`: the
    /// run the truck is on when it reaches `from`.
    pub(super) fn shot(&self, from: &Pose2, to: &Pose2, prev: Run) -> Option<Vec<Move>> {
        let p = &self.q.params;
        let costs = Costs {
            reverse: p.reverse_penalty,
            turn: p.turn_penalty,
            cusp_m: p.cusp_penalty_m,
        };
        let rs = RsPath::cheapest(from, to, 1.0 / self.kappa_max, costs)?;
        if self.q.params.forward_only && rs.segments.iter().any(|s| s.length_m < 0.0) {
            return None;
        }
        let moves: Vec<Move> = rs
            .segments
            .iter()
            .map(|s| Move {
                ds: s.length_m,
                kappa: match s.steer {
                    Steer::Left => self.kappa_max,
                    Steer::Right => -self.kappa_max,
                    Steer::Straight => 0.0,
                },
            })
            .collect();
        if !prev.runs_long_enough(&moves, self.q.params.min_segment_m) {
            return None;
        }
        let samples = rs.sample(from, self.check_step_m(self.kappa_max));
        samples
            .iter()
            .all(|(p, _, _)| self.free(p))
            .then_some(moves)
    }
}

/// Plans `q` on `map`: a manoeuvre from the start pose to the goal pose whose footprint
/// clears every obstacle, or an error naming why there is none.
pub fn plan_hybrid(map: &NavMap, q: &HybridQuery) -> Result<Manoeuvre, NavError> {
    if q.approach_m != 0.0 {
        return super::approach::plan_with_approach(map, q);
    }
    q.params.check()?;
    let t0 = Instant::now();
    let kappa_max = super::root_max_curvature_per_m(&q.truck) * q.params.curvature_fraction;
    let relaxed = relaxed_grid(map, q);
    let ends = ([q.start.x_m, q.start.y_m], [q.goal.x_m, q.goal.y_m]);
    let body = Body::of(&q.truck, q.margin_m, q.load);
    let deadline = t0 + std::time::Duration::from_secs_f64(q.params.max_time_s);
    let over_budget = || NavError::Budget {
        expansions: 0,
        time_s: t0.elapsed().as_secs_f64(),
    };
    let dist =
        Distances::to_goal(&relaxed, q.params.cell_m, ends, deadline).ok_or_else(over_budget)?;
    let cx = Ctx {
        map,
        q,
        body: body.clone(),
        extent: map.grid.extent(),
        dist,
        near: map.inflated(super::covered_radius_m(&q.truck, q.margin_m) + q.params.proximity_m),
        kappa_max,
        step_m: primitive_length_m(q.params.cell_m, kappa_max, q.params.headings),
        reach_m: body.reach_m(),
    };
    if Instant::now() > deadline {
        return Err(over_budget());
    }
    check_ends(&cx)?;
    if !cx.dist.at(ends.0).is_finite() {
        return Err(NavError::Unreachable(
            "no corridor wide enough for the truck joins the start to the goal".into(),
        ));
    }
    let (moves, expansions) = search(&cx, t0)?;
    let moves = refine(&cx, moves);
    let segments = segments_of(&sample(&q.start, &moves));
    let length_m = segments.iter().map(|p| p.length_m()).sum();
    Ok(Manoeuvre {
        segments,
        length_m,
        expansions,
        time_s: t0.elapsed().as_secs_f64(),
    })
}

/// [`plan_hybrid`] from where a truck stands after driving: when its footprint grown by
/// the full margin touches something (tracking left it nearer than planned), the margin
/// is halved, then dropped, so the truck can still leave; the margin used comes back.
pub fn plan_hybrid_from_here(map: &NavMap, q: &HybridQuery) -> Result<(Manoeuvre, f64), NavError> {
    let mut last = None;
    for margin_m in [q.margin_m, q.margin_m / 2.0, 0.0] {
        let try_q = HybridQuery {
            margin_m,
            ..q.clone()
        };
        match plan_hybrid(map, &try_q) {
            Err(e @ NavError::Blocked { which: "start", .. }) => last = Some(e),
            other => return other.map(|m| (m, margin_m)),
        }
    }
    Err(last.unwrap_or(NavError::Blocked {
        which: "start",
        x: q.start.x_m,
        y: q.start.y_m,
    }))
}

/// Start and goal on the map with the truck's footprint clear.
fn check_ends(cx: &Ctx) -> Result<(), NavError> {
    for (which, p) in [("start", cx.q.start), ("goal", cx.q.goal)] {
        if !cx.body.on_map(&p, cx.extent) {
            return Err(NavError::OffMap {
                which,
                x: p.x_m,
                y: p.y_m,
            });
        }
        if !cx.body.free(&cx.map.obstacles, &p) {
            return Err(NavError::Blocked {
                which,
                x: p.x_m,
                y: p.y_m,
            });
        }
    }
    Ok(())
}

/// A move long enough to leave its position bin: the arc at κ_max turning a whole number
/// of heading bins whose length is at least a bin's diagonal.
fn primitive_length_m(cell_m: f64, kappa_max: f64, headings: usize) -> f64 {
    let bin_rad = std::f64::consts::TAU / headings as f64;
    let bins = (cell_m * std::f64::consts::SQRT_2 * kappa_max / bin_rad)
        .ceil()
        .max(1.0);
    bins * bin_rad / kappa_max
}

/// The A* loop; the samples from start to goal and the nodes expanded.
fn search(cx: &Ctx, t0: Instant) -> Result<(Vec<Move>, usize), NavError> {
    let p = &cx.q.params;
    let mut nodes = vec![Node {
        pose: cx.q.start,
        g: 0.0,
        parent: u32::MAX,
        ds: 0.0,
        kappa: 0.0,
        run_m: 0.0,
    }];
    let mut best: HashMap<u64, u32> = HashMap::from([(cx.key(&cx.q.start), 0)]);
    let mut closed = std::collections::HashSet::new();
    let mut open = BinaryHeap::from([Reverse((cx.heuristic(&cx.q.start).to_bits(), 0u32))]);
    let (mut expansions, mut next_shot) = (0usize, 0usize);
    let dirs: &[f64] = if p.forward_only { &[1.0] } else { &[1.0, -1.0] };
    while let Some(Reverse((_, i))) = open.pop() {
        let node = nodes[i as usize];
        if !closed.insert(cx.key(&node.pose)) {
            continue;
        }
        expansions += 1;
        if expansions > p.max_expansions || t0.elapsed().as_secs_f64() > p.max_time_s {
            return Err(NavError::Budget {
                expansions: expansions - 1,
                time_s: t0.elapsed().as_secs_f64(),
            });
        }
        if expansions >= next_shot {
            let run = Run {
                ds: node.ds,
                run_m: node.run_m,
            };
            if let Some(tail) = cx.shot(&node.pose, &cx.q.goal, run) {
                return Ok((assemble(&nodes, i, tail), expansions));
            }
            let cells = cx.dist.at([node.pose.x_m, node.pose.y_m]) / p.cell_m;
            next_shot = expansions + (cells / SHOT_RATIO).clamp(1.0, 50.0) as usize;
        }
        for &dir in dirs {
            let turning_back = node.ds != 0.0 && node.ds.signum() != dir;
            // No shuffles: a direction is kept for a least distance before a cusp.
            if turning_back && node.run_m < p.min_segment_m {
                continue;
            }
            let run_m = if turning_back { 0.0 } else { node.run_m } + cx.step_m;
            for kappa in [cx.kappa_max, 0.0, -cx.kappa_max] {
                let ds = dir * cx.step_m;
                let Some((pose, cost)) = cx.step(&node.pose, node.ds, ds, kappa) else {
                    continue;
                };
                let key = cx.key(&pose);
                if closed.contains(&key) {
                    continue;
                }
                let g = node.g + cost;
                if best.get(&key).is_some_and(|&b| nodes[b as usize].g <= g) {
                    continue;
                }
                let j = nodes.len() as u32;
                nodes.push(Node {
                    pose,
                    g,
                    parent: i,
                    ds,
                    kappa,
                    run_m,
                });
                best.insert(key, j);
                open.push(Reverse(((g + cx.heuristic(&pose)).to_bits(), j)));
            }
        }
    }
    Err(NavError::Unreachable(format!(
        "every pose the truck can reach was searched ({expansions} nodes) without reaching the goal"
    )))
}

/// The moves from the start to node `last`, then the shot's.
fn assemble(nodes: &[Node], last: u32, tail: Vec<Move>) -> Vec<Move> {
    let mut moves = Vec::new();
    let mut i = last;
    while i != 0 && i != u32::MAX {
        let n = nodes[i as usize];
        moves.push(Move {
            ds: n.ds,
            kappa: n.kappa,
        });
        i = n.parent;
    }
    moves.reverse();
    moves.extend(tail);
    moves
}
