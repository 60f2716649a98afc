//! RRT and RRT-Connect on the same grid (the paper's baseline): seeded samples, fixed steps, free segments.

use std::time::Instant;

use kiddo::{KdTree, SquaredEuclidean};
use rand::{RngExt as _, SeedableRng as _};
use rand_chacha::ChaCha8Rng;

use crate::space::FreeSpace;
use crate::{NavError, Route, Timing};

/// RRT settings: step length, iteration limit, goal bias (RRT only) and seed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RrtParams {
    pub step_m: f64,
    pub max_iterations: usize,
    pub goal_bias: f64,
    pub seed: u64,
}

impl Default for RrtParams {
    fn default() -> Self {
        Self {
            step_m: 1.0,
            max_iterations: 20_000,
            goal_bias: 0.05,
            seed: 0,
        }
    }
}

/// A tree of points with parents and a k-d tree for its nearest node.
struct Tree {
    points: Vec<[f64; 2]>,
    parent: Vec<usize>,
    index: KdTree<f64, 2>,
}

impl Tree {
    fn new(root: [f64; 2]) -> Self {
        let mut index = KdTree::new();
        index.add(&root, 0);
        Self {
            points: vec![root],
            parent: vec![usize::MAX],
            index,
        }
    }

    fn nearest(&self, q: [f64; 2]) -> usize {
        self.index.nearest_one::<SquaredEuclidean>(&q).item as usize
    }

    fn add(&mut self, p: [f64; 2], parent: usize) -> usize {
        self.points.push(p);
        self.parent.push(parent);
        let i = self.points.len() - 1;
        self.index.add(&p, i as u64);
        i
    }

    /// Points from the root to node `i`.
    fn branch(&self, mut i: usize) -> Vec<[f64; 2]> {
        let mut out = vec![self.points[i]];
        while self.parent[i] != usize::MAX {
            i = self.parent[i];
            out.push(self.points[i]);
        }
        out.reverse();
        out
    }

    /// Grows one step from the node nearest `q` toward it; the new node, if its segment
    /// is free.
    fn extend<S: FreeSpace + ?Sized>(&mut self, grid: &S, q: [f64; 2], step: f64) -> Option<usize> {
        let near = self.nearest(q);
        let p = self.points[near];
        let d = (q[0] - p[0]).hypot(q[1] - p[1]);
        let new = if d <= step {
            q
        } else {
            [
                p[0] + (q[0] - p[0]) * step / d,
                p[1] + (q[1] - p[1]) * step / d,
            ]
        };
        grid.segment_free(p, new).then(|| self.add(new, near))
    }
}

fn sample<S: FreeSpace + ?Sized>(rng: &mut ChaCha8Rng, grid: &S) -> [f64; 2] {
    let (lo, hi) = grid.extent();
    [
        rng.random_range(lo[0]..hi[0]),
        rng.random_range(lo[1]..hi[1]),
    ]
}

/// Checks the query and settings; the clock and the seeded stream of a plan.
fn begin<S: FreeSpace + ?Sized>(
    grid: &S,
    (start, goal): ([f64; 2], [f64; 2]),
    p: &RrtParams,
) -> Result<(Instant, ChaCha8Rng), NavError> {
    crate::check_endpoints(grid, start, goal)?;
    if !(p.step_m.is_finite() && p.step_m > 0.0 && (0.0..=1.0).contains(&p.goal_bias)) {
        return Err(NavError::Params(
            "step_m must be positive and goal_bias within 0..1".into(),
        ));
    }
    Ok((Instant::now(), ChaCha8Rng::seed_from_u64(p.seed)))
}

/// RRT from `start`, biased toward `goal`; done when a node reaches the goal by a free
/// segment.
pub fn plan_rrt<S: FreeSpace + ?Sized>(
    grid: &S,
    start: [f64; 2],
    goal: [f64; 2],
    p: &RrtParams,
) -> Result<Route, NavError> {
    let (t0, mut rng) = begin(grid, (start, goal), p)?;
    let mut tree = Tree::new(start);
    let mut found = None;
    for _ in 0..p.max_iterations {
        let q = if rng.random_bool(p.goal_bias) {
            goal
        } else {
            sample(&mut rng, grid)
        };
        let Some(new) = tree.extend(grid, q, p.step_m) else {
            continue;
        };
        let at = tree.points[new];
        if (at[0] - goal[0]).hypot(at[1] - goal[1]) <= p.step_m && grid.segment_free(at, goal) {
            found = Some(tree.add(goal, new));
            break;
        }
    }
    let timing = Timing {
        search_s: t0.elapsed().as_secs_f64(),
        ..Timing::default()
    };
    Ok(Route::new(
        found.map(|i| tree.branch(i)),
        timing,
        tree.points.len(),
    ))
}

/// RRT-Connect (Kuffner & LaValle): a tree from each end; one extends toward a sample,
/// the other greedily connects to the new node; the roles swap every iteration.
pub fn plan_rrt_connect<S: FreeSpace + ?Sized>(
    grid: &S,
    start: [f64; 2],
    goal: [f64; 2],
    p: &RrtParams,
) -> Result<Route, NavError> {
    let (t0, mut rng) = begin(grid, (start, goal), p)?;
    let (mut a, mut b) = (Tree::new(start), Tree::new(goal));
    let mut a_is_start = true;
    let mut found = None;
    for _ in 0..p.max_iterations {
        let q = sample(&mut rng, grid);
        if let Some(new) = a.extend(grid, q, p.step_m) {
            let target = a.points[new];
            // Connect: step the other tree toward the new node until blocked or there.
            while let Some(m) = b.extend(grid, target, p.step_m) {
                if b.points[m] == target {
                    found = Some((new, m));
                    break;
                }
            }
        }
        if found.is_some() {
            break;
        }
        std::mem::swap(&mut a, &mut b);
        a_is_start = !a_is_start;
    }
    let nodes = a.points.len() + b.points.len();
    let points = found.map(|(ia, ib)| {
        let (mut from_a, mut from_b) = (a.branch(ia), b.branch(ib));
        from_b.reverse();
        from_a.extend(from_b.into_iter().skip(1));
        if !a_is_start {
            from_a.reverse();
        }
        from_a
    });
    let timing = Timing {
        search_s: t0.elapsed().as_secs_f64(),
        ..Timing::default()
    };
    Ok(Route::new(points, timing, nodes))
}
