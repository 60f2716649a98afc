//! Hybrid-A*'s result made drivable and short: runs of lattice moves replaced by clear Reeds-Shepp paths that cost no more, then sampled densely.

use forkbench_core::Pose2;

use super::search::Ctx;
use crate::reeds_shepp::advance;

/// One move: signed length (negative: backwards) at a constant curvature.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Move {
    pub ds: f64,
    pub kappa: f64,
}

/// The run a truck is on: its last move's signed length (0 at the start) and the
/// distance driven in that direction since the last cusp.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Run {
    pub ds: f64,
    pub run_m: f64,
}

impl Run {
    /// Whether `moves`, driven on from this run, change direction only after at least
    /// `min_m` in each direction (the last run, which ends at the goal or continues into
    /// more moves, excepted).
    pub fn runs_long_enough(&self, moves: &[Move], min_m: f64) -> bool {
        let (mut ds, mut run) = (self.ds, self.run_m);
        for m in moves {
            if ds != 0.0 && m.ds.signum() != ds.signum() {
                if run < min_m - 1e-9 {
                    return false;
                }
                run = 0.0;
            }
            run += m.ds.abs();
            ds = m.ds;
        }
        true
    }

    /// The run after driving `m`.
    pub fn after(self, m: &Move) -> Self {
        let same = self.ds == 0.0 || self.ds.signum() == m.ds.signum();
        Self {
            ds: m.ds,
            run_m: if same { self.run_m } else { 0.0 } + m.ds.abs(),
        }
    }
}

/// Spacing of the result's samples.
const SAMPLE_STEP_M: f64 = 0.05;
/// Most moves one shortcut may replace (bounds the work to moves × this).
const WINDOW: usize = 48;

/// The cost of `moves` as the search counts it (without proximity).
pub(crate) fn move_cost(cx: &Ctx, moves: &[Move], mut prev_ds: f64) -> f64 {
    let p = &cx.q.params;
    let mut total = 0.0;
    for m in moves {
        let mut c = m.ds.abs();
        if m.ds < 0.0 {
            c *= p.reverse_penalty;
        }
        if m.kappa != 0.0 {
            c *= p.turn_penalty;
        }
        if prev_ds != 0.0 && prev_ds.signum() != m.ds.signum() {
            c += p.cusp_penalty_m;
        }
        total += c;
        prev_ds = m.ds;
    }
    total
}

/// Greedy shortcuts: from each kept pose, the farthest later pose (within [`WINDOW`]
/// moves) that a clear Reeds-Shepp path reaches at no more cost replaces the moves between.
pub(crate) fn refine(cx: &Ctx, moves: Vec<Move>) -> Vec<Move> {
    let mut poses = vec![cx.q.start];
    for m in &moves {
        let last = poses[poses.len() - 1];
        poses.push(advance(&last, m.ds, m.kappa));
    }
    let mut out: Vec<Move> = Vec::new();
    let mut run = Run {
        ds: 0.0,
        run_m: 0.0,
    };
    let mut i = 0;
    while i < moves.len() {
        let prev = run.ds;
        let far = (i + WINDOW).min(moves.len());
        let found = (i + 2..=far).rev().find_map(|j| {
            let shot = cx.shot(&poses[i], &poses[j], run)?;
            (move_cost(cx, &shot, prev) < move_cost(cx, &moves[i..j], prev) - 1e-9)
                .then_some((j, shot))
        });
        let (taken, next) = match found {
            Some((j, shot)) => (shot, j),
            None => (vec![moves[i]], i + 1),
        };
        for m in &taken {
            run = run.after(m);
        }
        out.extend(taken);
        i = next;
    }
    out
}

/// Poses every [`SAMPLE_STEP_M`] or less along `moves` from `start`, each with its
/// curvature and whether it is driven backwards.
pub(crate) fn sample(start: &Pose2, moves: &[Move]) -> Vec<(Pose2, f64, bool)> {
    let first = moves
        .first()
        .map_or((0.0, false), |m| (m.kappa, m.ds < 0.0));
    let mut out = vec![(*start, first.0, first.1)];
    let mut at = *start;
    for m in moves {
        let n = (m.ds.abs() / SAMPLE_STEP_M).ceil().max(1.0) as usize;
        for _ in 0..n {
            at = advance(&at, m.ds / n as f64, m.kappa);
            out.push((at, m.kappa, m.ds < 0.0));
        }
    }
    out
}
