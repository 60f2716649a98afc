//! Simplifying a route's polyline: greedy vertex shortcuts, then seeded shortcuts between random points along the path (as OMPL's `PathSimplifier::shortcutPath`).

use rand::{RngExt as _, SeedableRng as _};
use rand_chacha::ChaCha8Rng;

use crate::smooth::shortcut;
use crate::space::FreeSpace;

/// Most random shortcuts tried in a row without a gain before stopping.
const MAX_FAILS_IN_A_ROW: usize = 100;
/// Most random shortcuts tried in all.
const MAX_TRIES: usize = 2000;

/// A plan's route after simplification, its length, and the time simplifying took.
#[derive(Debug, Clone)]
pub struct Simplified {
    pub points: Vec<[f64; 2]>,
    pub length_m: f64,
    pub time_s: f64,
}

/// A plan's route simplified ([`simplify`], seeded with `seed`) in the space it was
/// planned in (inflated grid or footprint); `None` without a route.
pub fn simplify_plan(
    map: &crate::NavMap,
    q: &crate::GlobalQuery,
    plan: &crate::GlobalPlan,
    seed: u64,
) -> Option<Simplified> {
    let points = plan.route.points.as_ref()?;
    let t0 = std::time::Instant::now();
    let short = match q.collision {
        crate::CollisionModel::Inflate => simplify(&*map.inflated(q.inflate_m), points, seed),
        crate::CollisionModel::Footprint => simplify(
            &crate::FootprintSpace::on(map, &q.truck, q.margin_m),
            points,
            seed,
        ),
    };
    let time_s = t0.elapsed().as_secs_f64();
    Some(Simplified {
        length_m: crate::polyline_length_m(&short),
        points: short,
        time_s,
    })
}

/// `points` shortened by shortcuts that stay in free space; the ends are kept.
pub fn simplify<S: FreeSpace + ?Sized>(space: &S, points: &[[f64; 2]], seed: u64) -> Vec<[f64; 2]> {
    let mut path = shortcut(space, points, &[]);
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut fails = 0;
    let mut cum = cumulative(&path);
    for _ in 0..MAX_TRIES {
        // A path of one repeated point (or non-finite points) has no length to draw from.
        let total = cum.last().copied().unwrap_or(0.0);
        if fails >= MAX_FAILS_IN_A_ROW || path.len() < 3 || !total.is_finite() || total <= 0.0 {
            break;
        }
        let (s, t) = (rng.random_range(0.0..total), rng.random_range(0.0..total));
        let (a, b) = (s.min(t), s.max(t));
        let ((ia, pa), (ib, pb)) = (point_at(&path, &cum, a), point_at(&path, &cum, b));
        let gain = (b - a) - dist(pa, pb);
        if ib <= ia || gain <= 1e-9 || !space.segment_free(pa, pb) {
            fails += 1;
            continue;
        }
        let mut next = path[..=ia].to_vec();
        next.extend([pa, pb]);
        next.extend_from_slice(&path[ib + 1..]);
        next.dedup_by(|p, q| dist(*p, *q) < 1e-9);
        path = next;
        cum = cumulative(&path);
        fails = 0;
    }
    shortcut(space, &path, &[])
}

fn dist(a: [f64; 2], b: [f64; 2]) -> f64 {
    (b[0] - a[0]).hypot(b[1] - a[1])
}

/// Arc length at each vertex.
fn cumulative(path: &[[f64; 2]]) -> Vec<f64> {
    let mut out = Vec::with_capacity(path.len());
    let mut s = 0.0;
    for (i, p) in path.iter().enumerate() {
        if i > 0 {
            s += dist(path[i - 1], *p);
        }
        out.push(s);
    }
    out
}

/// The point at arc length `s`, with the index of the segment's first vertex.
fn point_at(path: &[[f64; 2]], cum: &[f64], s: f64) -> (usize, [f64; 2]) {
    let i = cum.partition_point(|&c| c <= s).clamp(1, path.len() - 1) - 1;
    let len = cum[i + 1] - cum[i];
    let u = if len > 0.0 {
        ((s - cum[i]) / len).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let (p, q) = (path[i], path[i + 1]);
    (i, [p[0] + u * (q[0] - p[0]), p[1] + u * (q[1] - p[1])])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::OccupancyGrid;
    use forkbench_core::Pose2;
    use forkbench_core::geometry::Obstacle;

    /// A zig-zag around one block comes out shorter, still free, with its ends kept.
    #[test]
    fn shortcuts_shorten_a_detour_and_stay_free() {
        let block = Obstacle {
            centre: Pose2::new(5.0, 5.0, 0.0),
            length_m: 2.0,
            width_m: 2.0,
        };
        let wall = |x, y, l, w| Obstacle {
            centre: Pose2::new(x, y, 0.0),
            length_m: l,
            width_m: w,
        };
        let obstacles = [
            block,
            wall(5.0, -0.5, 11.0, 1.0),
            wall(5.0, 10.5, 11.0, 1.0),
        ];
        let grid = OccupancyGrid::from_obstacles(&obstacles, &[], 0.05, 0.0).expect("grid");
        let route = [
            [1.0, 1.0],
            [1.0, 9.0],
            [3.0, 9.0],
            [3.0, 8.0],
            [9.0, 8.0],
            [9.0, 1.0],
        ];
        let before = crate::polyline_length_m(&route);
        let after_path = simplify(&grid, &route, 3);
        let after = crate::polyline_length_m(&after_path);
        assert_eq!(after_path.first(), route.first());
        assert_eq!(after_path.last(), route.last());
        assert!(after < before - 3.0, "{before} → {after}");
        assert!(after_path.windows(2).all(|w| grid.segment_free(w[0], w[1])));
        assert!(after >= dist(route[0], route[5]) - 1e-9);
        assert_eq!(simplify(&grid, &route, 3), after_path, "seeded");
    }
}
