//! The search over lengths: fresh starts, continuation sweeps that follow branches across the window, and Brent refinement of the best brackets.

use super::SpiralProblem;
use super::newton::Trace;
use super::problem::Rule;
use crate::numeric::brent_min;

/// One solved length: (s_f, [b, c], cost, max normalised |κ|).
pub(super) type Candidate = (f64, [f64; 2], f64, f64);

/// The candidate of a solution (b, c) at length `sf`: its cost and largest |κ|.
fn candidate(p: &SpiralProblem, sf: f64, bc: [f64; 2]) -> Candidate {
    (
        sf,
        bc,
        p.cost(bc[0], bc[1], sf),
        p.max_abs_curvature(bc[0], bc[1], sf),
    )
}

/// The search over lengths: each grid length keeps the least-cost solution any start or
/// any neighbour's solution reached, then the best bracket is refined.
pub(super) struct LengthSearch<'a> {
    prob: &'a SpiralProblem,
    lo: f64,
    hi: f64,
    sfs: Vec<f64>,
    /// Per gap between grid lengths and direction, whether the curve was already
    /// followed across it.
    folds_tried: Vec<[bool; 2]>,
    /// Solutions found at folds (s_f free).
    folds: Vec<Candidate>,
    /// How often each grid length's solution changed.
    versions: Vec<u32>,
    /// Per grid length, the version of its lower and upper neighbour it was last
    /// continued from (`u32::MAX`: never), so unchanged neighbours are not solved again.
    continued: Vec<[u32; 2]>,
    pub(super) newton_solves: usize,
}

impl<'a> LengthSearch<'a> {
    /// A search over `m` evenly spaced lengths of the window `(lo, hi)`.
    pub(super) fn new(prob: &'a SpiralProblem, (lo, hi): (f64, f64), m: usize) -> Self {
        LengthSearch {
            prob,
            lo,
            hi,
            sfs: (0..m)
                .map(|i| lo + (hi - lo) * i as f64 / (m - 1) as f64)
                .collect(),
            folds_tried: vec![[false; 2]; m],
            folds: Vec::new(),
            versions: vec![0; m],
            continued: vec![[u32::MAX; 2]; m],
            newton_solves: 0,
        }
    }

    /// The least-cost feasible spiral found, solved to the final accuracy; or, when none
    /// is feasible, the least max |κ| of any spiral that reached the goal (∞ for none).
    pub(super) fn run(&mut self) -> Result<Candidate, f64> {
        let profiles = [
            self.prob.bezier_heading_profile(0.4),
            self.prob.bezier_heading_profile(0.8),
            self.prob.swing_heading_profile(),
        ];
        let grid = self.grid(&profiles);
        let mut refined: Vec<Candidate> = Vec::new();
        for i in self.local_minima(&grid).into_iter().take(REFINED_MINIMA) {
            // A bracket whose own cost is well above the best refined so far cannot hold
            // the optimum (costs vary smoothly along a branch between grid lengths).
            let least = refined.iter().map(|c| c.2).fold(f64::INFINITY, f64::min);
            if grid[i].is_some_and(|c| c.2 > PROMISING * least) {
                continue;
            }
            refined.extend(self.refine(&grid, i));
        }
        let limit = self.prob.kappa_limit;
        let best = refined
            .into_iter()
            .chain(self.folds.iter().copied().filter(|c| c.3 <= limit))
            .min_by(|a, b| a.2.total_cmp(&b.2));
        match best {
            Some(c) => Ok(self.polish(c)),
            None => Err(grid
                .iter()
                .flatten()
                .chain(&self.folds)
                .map(|c| c.3)
                .fold(f64::INFINITY, f64::min)),
        }
    }

    /// Puts `c` at grid length `k` when that is empty or `c` is cheaper; returns whether it did.
    fn keep(&mut self, grid: &mut [Option<Candidate>], k: usize, c: Candidate) -> bool {
        let better = grid[k].is_none_or(|g| c.2 < g.2 * (1.0 - 1e-9) - 1e-12);
        if better {
            grid[k] = Some(c);
            self.versions[k] += 1;
        }
        better
    }

    /// Least-cost solution at `sf` from several starts (they can land on different branches).
    fn solve(&mut self, sf: f64, guesses: &[[f64; 2]]) -> Option<Candidate> {
        let mut best: Option<Candidate> = None;
        for g in guesses {
            self.newton_solves += 1;
            if let Some(bc) = self.prob.solve_bc(sf, *g, Rule::Search) {
                let cost = self.prob.cost(bc[0], bc[1], sf);
                if best.is_none_or(|b| cost < b.2 - 1e-12) {
                    best = Some((sf, bc, cost, self.prob.max_abs_curvature(bc[0], bc[1], sf)));
                }
            }
        }
        best
    }

    /// Fresh starts at every sixth grid length and the longest (at all of them if none
    /// solves), then continuation sweeps down and up until no length improves: a branch found at one length is followed across the whole
    /// window (through folds), so the cheapest branch wins wherever it was first reached
    /// (e.g. only near the fold at the short end, while its cost keeps falling toward
    /// the long end).
    fn grid(&mut self, profiles: &[Vec<(f64, f64)>]) -> Vec<Option<Candidate>> {
        let m = self.sfs.len();
        let mut grid: Vec<Option<Candidate>> = vec![None; m];
        let seeds = |i: &usize| i.is_multiple_of(FRESH_START_EVERY) || i + 1 == m;
        self.fresh_starts(&mut grid, (0..m).filter(seeds), profiles);
        if grid.iter().all(Option::is_none) {
            // Hard goals (large turns) may solve only at some lengths: try them all.
            self.fresh_starts(&mut grid, (0..m).filter(|i| !seeds(i)), profiles);
        }
        if grid.iter().all(Option::is_none)
            && let Some(f) = self.fold(&profiles[0])
        {
            self.folds.push(f);
            self.seed_from(&mut grid, f);
        }
        let up: Vec<usize> = (1..m).collect();
        let down: Vec<usize> = (0..m - 1).rev().collect();
        for sweep in 0..8 {
            let (order, from): (&[usize], isize) = if sweep % 2 == 0 {
                (&down, 1)
            } else {
                (&up, -1)
            };
            if !self.sweep(&mut grid, order, from) && sweep > 0 {
                break;
            }
        }
        grid
    }

    /// Solves the grid lengths `idx` from the heading-profile fits and from zero.
    fn fresh_starts(
        &mut self,
        grid: &mut [Option<Candidate>],
        idx: impl Iterator<Item = usize>,
        profiles: &[Vec<(f64, f64)>],
    ) {
        for i in idx {
            let sf = self.sfs[i];
            let mut guesses: Vec<[f64; 2]> =
                profiles.iter().map(|p| self.prob.fit_bc(sf, p)).collect();
            guesses.push([0.0, 0.0]);
            if let Some(c) = self.solve(sf, &guesses) {
                self.keep(grid, i, c);
            }
        }
    }

    /// One continuation sweep: each length is solved from its neighbour's solution and
    /// keeps it when cheaper; where Newton fails, the neighbour's branch is followed along
    /// the solution curve. Returns whether any length improved.
    fn sweep(&mut self, grid: &mut [Option<Candidate>], order: &[usize], from: isize) -> bool {
        let mut improved = false;
        let side = usize::from(from > 0);
        for &i in order {
            let j = i.wrapping_add_signed(from);
            let Some(prev) = grid[j] else {
                continue;
            };
            if std::mem::replace(&mut self.continued[i][side], self.versions[j]) == self.versions[j]
            {
                continue;
            }
            let guess = self.prob.predict(prev, self.sfs[i]);
            let found = match self.solve(self.sfs[i], &[guess]) {
                Some(c) => Some((i, c)),
                None => self.follow(prev, i, j),
            };
            if let Some((k, c)) = found
                && self.keep(grid, k, c)
            {
                improved = true;
                if k == i {
                    // Length i now continues j's branch: continuing j back from it would
                    // walk the same branch again.
                    self.continued[j][1 - side] = self.versions[i];
                }
            }
        }
        improved
    }

    /// Where `prev`'s branch did not reach grid length `i` by Newton, follows it there
    /// along the solution curve (looked for once per gap). Returns the grid index and
    /// the solution put there: at `i` when the curve reaches it, otherwise at `prev`'s
    /// length on the branch beyond the fold the curve turned at (the fold point itself
    /// becomes a candidate).
    fn follow(&mut self, prev: Candidate, i: usize, j: usize) -> Option<(usize, Candidate)> {
        if std::mem::replace(&mut self.folds_tried[i.min(j)][usize::from(j > i)], true) {
            return None;
        }
        let p = self.prob;
        match p.trace([prev.1[0], prev.1[1], prev.0], self.sfs[i])? {
            Trace::Reached(q) => Some((i, self.solve(self.sfs[i], &[[q[0], q[1]]])?)),
            Trace::Turned { fold, back } => {
                let [b, c, sf] = fold;
                self.folds.push(candidate(p, sf, [b, c]));
                Some((j, self.solve(prev.0, &[[back[0], back[1]]])?))
            }
        }
    }

    /// Puts the branch through a solution off the grid (a fold) at the grid lengths
    /// either side of it, following the solution curve there.
    fn seed_from(&mut self, grid: &mut [Option<Candidate>], f: Candidate) {
        let above = self.sfs.iter().position(|&s| s >= f.0);
        let below = above.map_or(Some(self.sfs.len() - 1), |k| k.checked_sub(1));
        for k in [above, below].into_iter().flatten() {
            if let Some(Trace::Reached(q)) = self.prob.trace([f.1[0], f.1[1], f.0], self.sfs[k])
                && let Some(c) = self.solve(self.sfs[k], &[[q[0], q[1]]])
            {
                self.keep(grid, k, c);
            }
        }
    }

    /// Where nothing solved at any grid length, the only solutions may sit at a fold in
    /// s_f (the shortest length that reaches; e.g. a symmetric lane change), where the
    /// fixed-length solve is singular: solve with s_f free from each grid length in turn.
    fn fold(&self, profile: &[(f64, f64)]) -> Option<Candidate> {
        self.sfs.iter().find_map(|&sf| {
            let (bc, s) =
                self.prob
                    .solve_free(self.prob.fit_bc(sf, profile), sf, self.lo, self.hi)?;
            Some(candidate(self.prob, s, bc))
        })
    }

    /// The chosen candidate solved to the final accuracy at its length (the search
    /// solved to ~1e-9); fold points, found at final accuracy already, are kept.
    fn polish(&mut self, c: Candidate) -> Candidate {
        self.newton_solves += 1;
        match self.prob.solve_bc(c.0, c.1, Rule::Final) {
            Some(bc) => {
                let polished = candidate(self.prob, c.0, bc);
                // Polishing moves (b, c) by ~1e-9: the same spiral, unless Newton fell
                // onto another branch, which must not replace the chosen one.
                if (polished.2 - c.2).abs() <= 1e-6 * (1.0 + c.2)
                    && polished.3 <= self.prob.kappa_limit
                {
                    polished
                } else {
                    c
                }
            }
            None => c,
        }
    }

    /// The cost with an exact penalty on curvature beyond the limit: equal to the cost
    /// where feasible, and its minima over a branch sit at the constrained optima.
    fn penalised(&self, c: &Candidate) -> f64 {
        c.2 + CURVATURE_PENALTY * (c.3 - self.prob.kappa_limit).max(0.0)
    }

    /// Grid lengths where the penalised cost is a local minimum over the grid, most
    /// promising first: each brackets an optimum of its branch (or a stretch of lengths
    /// where the branch becomes feasible).
    fn local_minima(&self, grid: &[Option<Candidate>]) -> Vec<usize> {
        let phi: Vec<f64> = grid
            .iter()
            .map(|c| c.map_or(f64::INFINITY, |c| self.penalised(&c)))
            .collect();
        let m = phi.len();
        let mut idx: Vec<usize> = (0..m)
            .filter(|&i| {
                phi[i].is_finite()
                    && (i == 0 || phi[i] <= phi[i - 1])
                    && (i + 1 == m || phi[i] <= phi[i + 1])
            })
            .collect();
        idx.sort_by(|&a, &b| phi[a].total_cmp(&phi[b]));
        idx
    }

    /// Brent's method on the penalised cost over the lengths either side of grid length
    /// `idx`, continuing from its solution; returns the least-cost feasible candidate
    /// seen (the grid's own, at a window bound, when the cost falls toward that bound).
    fn refine(&mut self, grid: &[Option<Candidate>], idx: usize) -> Option<Candidate> {
        let limit = self.prob.kappa_limit;
        let mut best = grid[idx].filter(|c| c.3 <= limit);
        let mut warm = grid[idx]?;
        let m = self.sfs.len();
        let (a, b) = (
            self.sfs[idx.saturating_sub(1)],
            self.sfs[(idx + 1).min(m - 1)],
        );
        let tol = 1e-6 * (self.hi - self.lo);
        brent_min(
            |sf| match self.solve(sf, &[self.prob.predict(warm, sf)]) {
                Some(c) => {
                    warm = c;
                    if c.3 <= limit && best.is_none_or(|b| c.2 < b.2) {
                        best = Some(c);
                    }
                    self.penalised(&c)
                }
                None => f64::INFINITY,
            },
            a,
            b,
            tol,
        );
        best
    }
}

/// Weight of curvature beyond the limit (normalised) in the penalised cost: far above
/// any cost's sensitivity to curvature, so penalised minima are feasible where a branch
/// can be.
const CURVATURE_PENALTY: f64 = 1e4;

/// Local minima of the penalised cost refined per plan: the best few brackets.
const REFINED_MINIMA: usize = 3;

/// A further bracket is refined only while its grid cost is below this multiple of the
/// best refined cost.
const PROMISING: f64 = 1.2;

/// Fresh starts are tried at every this many grid lengths (and the longest); the
/// continuation sweeps carry their branches to the lengths between.
const FRESH_START_EVERY: usize = 6;
