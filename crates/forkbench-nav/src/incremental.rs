//! PRM to the first solution: samples added one at a time, each joined to its nearest neighbours within the connection distance (OMPL's PRM strategy), until start and goal share a component; then A*.

use std::num::NonZero;
use std::time::Instant;

use kiddo::{KdTree, SquaredEuclidean};
use rand::{RngExt as _, SeedableRng as _};
use rand_chacha::ChaCha8Rng;

use crate::roadmap::{MAX_NODES, astar, check_connect_m};
use crate::space::FreeSpace;
use crate::{NavError, PrmParams, Roadmap, Route, Timing};

/// Neighbours each new node tries to join (OMPL's PRM default).
pub const NEIGHBOURS: usize = 10;
const K: NonZero<usize> = NonZero::new(NEIGHBOURS).expect("NEIGHBOURS is positive");

/// Plans from `start` to `goal`, drawing at most `p.nodes` samples: the first route the
/// growing roadmap holds, with the roadmap as it stood then.
pub fn plan_prm_first<S: FreeSpace + ?Sized>(
    space: &S,
    start: [f64; 2],
    goal: [f64; 2],
    p: &PrmParams,
) -> Result<(Route, Roadmap), NavError> {
    crate::check_endpoints(space, start, goal)?;
    if p.nodes > MAX_NODES {
        return Err(NavError::Params(format!(
            "{} samples: at most {MAX_NODES}",
            p.nodes
        )));
    }
    check_connect_m(p.connect_m)?;
    let t0 = Instant::now();
    let mut g = Growing::new(space, p.connect_m);
    g.add(start);
    g.add(goal);
    let (lo, hi) = space.extent();
    let mut rng = ChaCha8Rng::seed_from_u64(p.seed);
    let mut drawn = 0;
    while !g.connected() && drawn < p.nodes {
        drawn += 1;
        let q = [
            rng.random_range(lo[0]..hi[0]),
            rng.random_range(lo[1]..hi[1]),
        ];
        if space.point_free(q) {
            g.add(q);
        }
    }
    let grown = Instant::now();
    let found = g.connected().then(|| astar(&g.map, 0, 1)).flatten();
    let timing = Timing {
        sampling_s: 0.0,
        connection_s: (grown - t0).as_secs_f64(),
        search_s: grown.elapsed().as_secs_f64(),
    };
    let points = found.map(|ids| ids.iter().map(|&i| g.map.nodes[i]).collect());
    Ok((Route::new(points, timing, g.map.nodes.len()), g.map))
}

/// A roadmap being grown, its nodes in a k-d tree and its components in a union-find.
struct Growing<'a, S: ?Sized> {
    space: &'a S,
    map: Roadmap,
    tree: KdTree<f64, 2>,
    parent: Vec<usize>,
    reach2: f64,
}

impl<'a, S: FreeSpace + ?Sized> Growing<'a, S> {
    fn new(space: &'a S, connect_m: Option<f64>) -> Self {
        Self {
            space,
            map: Roadmap::default(),
            tree: KdTree::new(),
            parent: Vec::new(),
            reach2: connect_m.map_or(f64::INFINITY, |r| r * r),
        }
    }

    /// Adds `q` and joins it to its nearest neighbours in view.
    fn add(&mut self, q: [f64; 2]) {
        let i = self.map.nodes.len();
        self.map.nodes.push(q);
        self.map.edges.push(Vec::new());
        self.parent.push(i);
        for nb in self
            .tree
            .nearest_n_within::<SquaredEuclidean>(&q, self.reach2, K, true)
        {
            let j = nb.item as usize;
            if self.space.segment_free(q, self.map.nodes[j]) {
                let d = nb.distance.sqrt();
                self.map.edges[i].push((j, d));
                self.map.edges[j].push((i, d));
                let (a, b) = (self.root(i), self.root(j));
                self.parent[a] = b;
            }
        }
        self.tree.add(&q, i as u64);
    }

    fn root(&mut self, mut i: usize) -> usize {
        while self.parent[i] != i {
            self.parent[i] = self.parent[self.parent[i]];
            i = self.parent[i];
        }
        i
    }

    /// Whether the start (node 0) and the goal (node 1) share a component.
    fn connected(&mut self) -> bool {
        self.parent.len() > 1 && self.root(0) == self.root(1)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::OccupancyGrid;
    use forkbench_core::Pose2;
    use forkbench_core::geometry::Obstacle;

    /// A room split by a wall with a gap at the top.
    fn room() -> OccupancyGrid {
        let rect = |x: f64, y: f64, l: f64, w: f64| Obstacle {
            centre: Pose2::new(x, y, 0.0),
            length_m: l,
            width_m: w,
        };
        let walls = [
            rect(10.0, -0.5, 21.0, 1.0),
            rect(10.0, 10.5, 21.0, 1.0),
            rect(10.0, 4.0, 1.0, 8.0),
        ];
        OccupancyGrid::from_obstacles(&walls, &[], 0.1, 0.0).expect("grid")
    }

    fn params(nodes: usize, seed: u64) -> PrmParams {
        PrmParams {
            nodes,
            connect_m: Some(5.0),
            seed,
        }
    }

    /// It stops at the first connection, through the gap, every edge free, the same
    /// route for the same seed.
    #[test]
    fn the_first_route_goes_through_the_gap() {
        let g = room();
        let (start, goal) = ([2.0, 2.0], [18.0, 2.0]);
        let mut nodes = Vec::new();
        for seed in 0..20 {
            let (route, map) = plan_prm_first(&g, start, goal, &params(5000, seed)).expect("plans");
            let pts = route.points.expect("a route");
            assert_eq!((pts[0], *pts.last().expect("end")), (start, goal));
            assert!(pts.windows(2).all(|w| g.segment_free(w[0], w[1])));
            assert!(pts.iter().any(|p| p[1] > 8.0), "through the gap: {pts:?}");
            // Each node joined at most its nearest NEIGHBOURS among those before it.
            assert!(
                map.edges
                    .iter()
                    .enumerate()
                    .all(|(i, e)| e.iter().filter(|(j, _)| *j < i).count() <= NEIGHBOURS)
            );
            let again = plan_prm_first(&g, start, goal, &params(5000, seed)).expect("plans");
            assert_eq!(again.0.points.as_deref(), Some(&pts[..]), "seeded");
            nodes.push(map.nodes.len());
        }
        // Far fewer samples than the cap: it stopped when connected.
        assert!(nodes.iter().all(|&n| n < 1000), "{nodes:?}");
    }

    /// No route when the samples run out, or when a wall closes the gap.
    #[test]
    fn no_route_when_the_cap_is_reached_or_the_way_is_shut() {
        let g = room();
        let (route, map) =
            plan_prm_first(&g, [2.0, 2.0], [18.0, 2.0], &params(3, 1)).expect("plans");
        assert!(route.points.is_none() && map.nodes.len() <= 5);
        let mut shut = g.clone();
        for ix in 0..shut.width {
            let x = shut.origin_m[0] + (ix as f64 + 0.5) * shut.resolution_m;
            if (9.5..10.5).contains(&x) {
                for iy in 0..shut.height {
                    shut.set(ix, iy, crate::Cell::Occupied);
                }
            }
        }
        let (route, _) =
            plan_prm_first(&shut, [2.0, 2.0], [18.0, 2.0], &params(2000, 1)).expect("plans");
        assert!(route.points.is_none());
        let err = plan_prm_first(&g, [2.0, 2.0], [18.0, 2.0], &params(MAX_NODES + 1, 1));
        assert!(matches!(err, Err(NavError::Params(_))));
    }
}
