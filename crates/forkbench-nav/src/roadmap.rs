//! PRM (Luo's method): seeded uniform samples in free space, edges between nodes closer than the connection distance whose segment is free, A* with the Euclidean heuristic.

use std::cmp::Ordering;
use std::collections::BinaryHeap;
use std::time::Instant;

use kiddo::{KdTree, SquaredEuclidean};
use rand::{RngExt as _, SeedableRng as _};
use rand_chacha::ChaCha8Rng;

use crate::space::FreeSpace;
use crate::{NavError, Route, Timing};

/// Most samples a roadmap may draw.
pub const MAX_NODES: usize = 100_000;
/// Most samples with unlimited connection distance.
pub const MAX_NODES_UNLIMITED: usize = 5_000;
/// Most candidate edges (node pairs within the connection distance) one roadmap may
/// check: what 5,000 nodes with unlimited connections check. Bounds time and memory.
pub const MAX_CANDIDATE_EDGES: f64 = 12_500_000.0;

/// Expected candidate edges of a roadmap of `nodes` samples over `area_m2`: pairs whose
/// distance is within `connect_m` (every pair when unlimited).
pub fn candidate_edges(nodes: usize, connect_m: Option<f64>, area_m2: f64) -> f64 {
    let n = nodes as f64;
    let share = connect_m.map_or(1.0, |r| {
        (std::f64::consts::PI * r * r / area_m2.max(1e-9)).min(1.0)
    });
    n * n / 2.0 * share
}

/// PRM settings: sample count, connection distance (`None`: unlimited) and seed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PrmParams {
    pub nodes: usize,
    pub connect_m: Option<f64>,
    pub seed: u64,
}

/// A roadmap: nodes (start and goal first) and, per node, its neighbours with the
/// edge length.
#[derive(Debug, Clone, Default)]
pub struct Roadmap {
    pub nodes: Vec<[f64; 2]>,
    pub edges: Vec<Vec<(usize, f64)>>,
}

impl Roadmap {
    pub fn edge_count(&self) -> usize {
        self.edges.iter().map(Vec::len).sum::<usize>() / 2
    }
}

/// Plans from `start` to `goal` on `grid` (already inflated): a route, or why none.
pub fn plan_prm<S: FreeSpace + ?Sized>(
    grid: &S,
    start: [f64; 2],
    goal: [f64; 2],
    p: &PrmParams,
) -> Result<(Route, Roadmap), NavError> {
    crate::check_endpoints(grid, start, goal)?;
    if p.nodes > MAX_NODES {
        return Err(NavError::Params(format!(
            "{} nodes: at most {MAX_NODES} (the roadmap's edges grow with their square)",
            p.nodes
        )));
    }
    if p.connect_m.is_none() && p.nodes > MAX_NODES_UNLIMITED {
        return Err(NavError::Params(format!(
            "{} nodes with unlimited connections: at most {MAX_NODES_UNLIMITED} (every pair is checked)",
            p.nodes
        )));
    }
    check_connect_m(p.connect_m)?;
    let (lo, hi) = grid.extent();
    let edges = candidate_edges(p.nodes, p.connect_m, (hi[0] - lo[0]) * (hi[1] - lo[1]));
    if edges > MAX_CANDIDATE_EDGES {
        return Err(NavError::Params(format!(
            "{} nodes within {} of each other on this map: about {edges:.3e} candidate edges, \
             at most {MAX_CANDIDATE_EDGES:.3e} (fewer nodes or a shorter connection distance)",
            p.nodes,
            p.connect_m
                .map_or("any distance".to_owned(), |c| format!("{c} m"))
        )));
    }
    let t0 = Instant::now();
    let mut rng = ChaCha8Rng::seed_from_u64(p.seed);
    let mut nodes = vec![start, goal];
    // n uniform samples over the map; those in obstacles are dropped, as in the paper.
    for _ in 0..p.nodes {
        let q = [
            rng.random_range(lo[0]..hi[0]),
            rng.random_range(lo[1]..hi[1]),
        ];
        if grid.point_free(q) {
            nodes.push(q);
        }
    }
    let sampled = Instant::now();
    let mut tree: KdTree<f64, 2> = KdTree::new();
    for (i, n) in nodes.iter().enumerate() {
        tree.add(n, i as u64);
    }
    let mut edges = vec![Vec::new(); nodes.len()];
    let r2 = p.connect_m.map_or(f64::INFINITY, |r| r * r);
    for i in 0..nodes.len() {
        for nb in tree.within_unsorted::<SquaredEuclidean>(&nodes[i], r2) {
            let j = nb.item as usize;
            if j > i && grid.segment_free(nodes[i], nodes[j]) {
                let d = nb.distance.sqrt();
                edges[i].push((j, d));
                edges[j].push((i, d));
            }
        }
    }
    let connected = Instant::now();
    let roadmap = Roadmap { nodes, edges };
    let found = astar(&roadmap, 0, 1);
    let searched = Instant::now();
    let timing = Timing {
        sampling_s: (sampled - t0).as_secs_f64(),
        connection_s: (connected - sampled).as_secs_f64(),
        search_s: (searched - connected).as_secs_f64(),
    };
    let points = found.map(|ids| ids.iter().map(|&i| roadmap.nodes[i]).collect());
    Ok((Route::new(points, timing, roadmap.nodes.len()), roadmap))
}

/// A connection distance must be a positive number of metres (`None`: unlimited).
pub(crate) fn check_connect_m(connect_m: Option<f64>) -> Result<(), NavError> {
    if connect_m.is_some_and(|c| !(c.is_finite() && c > 0.0)) {
        return Err(NavError::Params(
            "the connection distance must be a positive number of metres".into(),
        ));
    }
    Ok(())
}

/// A* over the roadmap from node `from` to node `to` (Euclidean heuristic, admissible
/// since edges are straight): the node sequence, or `None` when they are not connected.
pub fn astar(map: &Roadmap, from: usize, to: usize) -> Option<Vec<usize>> {
    let h = |i: usize| {
        let (a, b) = (map.nodes[i], map.nodes[to]);
        (a[0] - b[0]).hypot(a[1] - b[1])
    };
    let mut g = vec![f64::INFINITY; map.nodes.len()];
    let mut came = vec![usize::MAX; map.nodes.len()];
    let mut open = BinaryHeap::new();
    g[from] = 0.0;
    open.push(Open(h(from), from));
    while let Some(Open(_, i)) = open.pop() {
        if i == to {
            let mut path = vec![to];
            while *path.last()? != from {
                path.push(came[*path.last()?]);
            }
            path.reverse();
            return Some(path);
        }
        for &(j, d) in &map.edges[i] {
            let cand = g[i] + d;
            if cand < g[j] {
                g[j] = cand;
                came[j] = i;
                open.push(Open(cand + h(j), j));
            }
        }
    }
    None
}

/// An open-list entry ordered by lowest f first.
struct Open(f64, usize);

impl PartialEq for Open {
    fn eq(&self, o: &Self) -> bool {
        self.cmp(o) == Ordering::Equal
    }
}
impl Eq for Open {}
impl PartialOrd for Open {
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}
impl Ord for Open {
    fn cmp(&self, o: &Self) -> Ordering {
        o.0.total_cmp(&self.0).then(o.1.cmp(&self.1))
    }
}
