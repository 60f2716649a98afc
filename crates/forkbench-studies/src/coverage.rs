//! Reflector coverage of a world: at every free cell centre, how many reflectors a NAV350 there sees past racks and walls, and the predicted 1σ position error of a fix (none below the minimum).

use forkbench_sensors::reflectors::{ReflectorNavConfig, predicted_sigma_m, visible};
use forkbench_sensors::sight::Sight;
use rayon::prelude::*;
use serde::Serialize;

use forkbench_trial::ScenarioError;
use forkbench_trial::World;

/// Most cells a coverage map may have (bounded work and memory on any world file).
pub const MAX_CELLS: usize = 4_000_000;
/// Most cell × (obstacle + reflector) tests a coverage map may take.
pub const MAX_WORK: f64 = 5e8;

/// One cell centre.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct CoverageCell {
    pub x_m: f64,
    pub y_m: f64,
    /// Reflectors in line of sight and range.
    pub visible: usize,
    /// Predicted 1σ radial position error of a fix; `None` below the minimum reflectors.
    pub sigma_m: Option<f64>,
}

/// A world's coverage map.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Coverage {
    pub resolution_m: f64,
    /// Lower-left and upper-right corners of the evaluated area.
    pub bounds: [[f64; 2]; 2],
    /// Free cells only (centres inside a rack or wall are left out).
    pub cells: Vec<CoverageCell>,
}

/// The area the world's racks, walls and reflectors span.
fn bounds(world: &World) -> Option<[[f64; 2]; 2]> {
    let mut pts: Vec<[f64; 2]> = world
        .obstacles()
        .iter()
        .flat_map(forkbench_sim::Obstacle::corners)
        .collect();
    pts.extend(world.reflector.iter().map(|r| [r.x_m, r.y_m]));
    let first = *pts.first()?;
    Some(pts.iter().fold([first, first], |[lo, hi], p| {
        [
            [lo[0].min(p[0]), lo[1].min(p[1])],
            [hi[0].max(p[0]), hi[1].max(p[1])],
        ]
    }))
}

/// Evaluates `world` on a grid of `resolution_m` cells.
pub fn coverage(
    world: &World,
    resolution_m: f64,
    cfg: &ReflectorNavConfig,
) -> Result<Coverage, ScenarioError> {
    let bad = |reason: &str| ScenarioError::Invalid {
        file: world.name.clone(),
        field: "resolution_m".into(),
        reason: reason.into(),
    };
    if !(resolution_m.is_finite() && resolution_m > 0.0) {
        return Err(bad("must be a positive finite length"));
    }
    let Some([lo, hi]) = bounds(world) else {
        return Err(ScenarioError::Invalid {
            file: world.name.clone(),
            field: "rack".into(),
            reason: "the world has no racks, walls or reflectors to span an area".into(),
        });
    };
    // Counted in floating point first: a tiny resolution must not wrap or saturate.
    let (fx, fy) = (
        ((hi[0] - lo[0]) / resolution_m).ceil(),
        ((hi[1] - lo[1]) / resolution_m).ceil(),
    );
    if fx * fy > MAX_CELLS as f64 {
        return Err(bad(&format!(
            "gives {fx:.3e} × {fy:.3e} cells, more than {MAX_CELLS}; choose a coarser resolution"
        )));
    }
    let (nx, ny) = (fx as usize, fy as usize);
    let obstacles = world.obstacles();
    // Each cell is tested against every rack, wall and reflector: bound that work.
    let per_cell = obstacles.len() + world.reflector.len() + 1;
    let work = (nx * ny) as f64 * per_cell as f64;
    if work > MAX_WORK {
        return Err(bad(&format!(
            "{} cells × {per_cell} racks, walls and reflectors = {work:.3e} tests, more than \
             {MAX_WORK:.0e}; choose a coarser resolution",
            nx * ny
        )));
    }
    let fixed = Sight::new(&world.fixed_surfaces());
    // A cell centre on a side counts as inside.
    let free = |p: [f64; 2]| !obstacles.iter().any(|o| o.depth_inside(p) >= 0.0);
    let cells = (0..ny)
        .into_par_iter()
        .flat_map_iter(|j| {
            let (fixed, free) = (&fixed, &free);
            (0..nx).filter_map(move |i| {
                let at = [
                    lo[0] + (i as f64 + 0.5) * resolution_m,
                    lo[1] + (j as f64 + 0.5) * resolution_m,
                ];
                free(at).then(|| {
                    let seen = visible(at, &world.reflector, fixed, cfg);
                    let pts: Vec<[f64; 2]> = seen
                        .iter()
                        .map(|&k| [world.reflector[k].x_m, world.reflector[k].y_m])
                        .collect();
                    CoverageCell {
                        x_m: at[0],
                        y_m: at[1],
                        visible: seen.len(),
                        sigma_m: predicted_sigma_m(at, &pts, cfg),
                    }
                })
            })
        })
        .collect();
    Ok(Coverage {
        resolution_m,
        bounds: [lo, hi],
        cells,
    })
}
