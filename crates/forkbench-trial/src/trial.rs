//! One pick trial: estimate the pallet, plan, track with pure pursuit on NAV350 fixes in rapier2d, judge the entry.

use std::time::Instant;

use forkbench_core::units::wrap_angle;
use forkbench_core::{ForkliftSpec, Pose2};
use forkbench_plan::{PlanParams, PlanRequest, PlannerConfig, PlannerKind};
use forkbench_sensors::Nav350;
use forkbench_sim::{PalletSpec, Sim};
use forkbench_track::{PosePredictor, PurePursuit};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

use crate::outcome::{Failure, TrialOutcome};
use crate::recorder::{Level, NoRecorder, Recorder, SceneInfo, StepRecord};
use crate::scenario::{Case, Scenario, truck_footprint};

/// Arc-length spacing of the footprint checks along a plan (its samples are 1 cm apart):
/// between two checks the fork root moves 2 cm and a body corner a few cm more in a turn,
/// far below the racks' and walls' thickness.
const PATH_CHECK_STEP_M: f64 = 0.02;

/// Per-run choices on top of the scenario file.
#[derive(Debug, Clone, Default)]
pub struct TrialOptions {
    pub seed: Option<u64>,
    pub planner: Option<PlannerKind>,
    /// Turn off NAV350 and pallet-estimate noise.
    pub no_noise: bool,
    /// Override of the pallet-estimate σ scale (0 = perfect estimate, NAV350 noise kept).
    pub pallet_noise_scale: Option<f64>,
    /// Force replanning on new pallet estimates on or off.
    pub replan: Option<bool>,
}

/// Independent random streams per sensor, so changing one sensor's settings does not
/// change the other's draws.
fn stream(seed: u64, salt: u64) -> ChaCha8Rng {
    ChaCha8Rng::seed_from_u64(seed ^ salt.wrapping_mul(0x9E37_79B9_7F4A_7C15))
}

/// Gap between the fork tips and the pallet face at the end of the approach curve.
pub const APPROACH_GAP_M: f64 = 0.3;

/// Fork-root pose that puts the fork tips `insertion_m` past the pallet face
/// (negative: before it).
pub fn goal_for(face: &Pose2, truck: &ForkliftSpec, insertion_m: f64) -> Pose2 {
    face.to_world(&Pose2::new(insertion_m - truck.fork_length_m, 0.0, 0.0))
}

/// Depth the fork tips reach aimed at: 5 cm short of the pallet back (or the fork length).
pub fn target_insertion_m(truck: &ForkliftSpec, pallet: &PalletSpec) -> f64 {
    pallet.depth_m.min(truck.fork_length_m) - 0.05
}

/// The pallet pose moved by a draw of N(0, σ) per axis in its own frame, truncated at 3σ.
fn jitter(pallet: &Pose2, sigma: &Pose2, rng: &mut ChaCha8Rng) -> Pose2 {
    if sigma.x_m == 0.0 && sigma.y_m == 0.0 && sigma.heading_rad == 0.0 {
        return *pallet;
    }
    let mut draw = |s: f64| {
        let z: f64 = rand::RngExt::sample(rng, rand_distr::StandardNormal);
        s * z.clamp(-3.0, 3.0)
    };
    let d = Pose2::new(draw(sigma.x_m), draw(sigma.y_m), draw(sigma.heading_rad));
    pallet.to_world(&d)
}

/// Fork-root pose in the pallet frame: x < 0 before the face, y the lateral offset.
fn in_pallet_frame(pallet: &Pose2, root: &Pose2) -> Pose2 {
    pallet.to_local(root)
}

/// Depth of the shallower fork tip past the pallet face, at most the fork length. A fork
/// root that is itself past the face plane (a truck that drove past or away behind the
/// pallet) inserted nothing: 0.
fn insertion_depth(pallet: &Pose2, root: &Pose2, truck: &ForkliftSpec) -> f64 {
    if pallet.to_local(root).x_m > 0.0 {
        return 0.0;
    }
    let depth = [1.0, -1.0]
        .iter()
        .map(|side| {
            let tip = root.to_world(&Pose2::new(
                truck.fork_length_m,
                side * truck.fork_spacing_m / 2.0,
                0.0,
            ));
            pallet.to_local(&tip).x_m
        })
        .fold(f64::INFINITY, f64::min);
    depth.min(truck.fork_length_m)
}

/// Runs one case of a scenario to its judged outcome.
pub fn run_trial(scn: &Scenario, case: &Case, opts: &TrialOptions) -> TrialOutcome {
    run_trial_recorded(scn, case, opts, &mut NoRecorder)
}

/// Runs one case and reports every step to `rec`.
pub fn run_trial_recorded<R: Recorder + ?Sized>(
    scn: &Scenario,
    case: &Case,
    opts: &TrialOptions,
    rec: &mut R,
) -> TrialOutcome {
    let out = run_inner(scn, case, opts, rec);
    rec.outcome(out.sim_time_s, &out);
    out
}

fn run_inner<R: Recorder + ?Sized>(
    scn: &Scenario,
    case: &Case,
    opts: &TrialOptions,
    rec: &mut R,
) -> TrialOutcome {
    let wall = Instant::now();
    let seed = opts.seed.unwrap_or(scn.seed);
    let planner = opts.planner.unwrap_or(scn.planner);
    let noise = scn.noise.enabled && !opts.no_noise;
    let truck = &scn.truck;
    let mut out = TrialOutcome::blank(&scn.name, &case.name, planner.name(), seed, noise);
    let finish = |mut out: TrialOutcome, failure: Option<(Failure, String)>| {
        if let Some((f, d)) = failure {
            out.failure = Some(f);
            out.failure_detail = Some(d);
            out.success = false;
        } else {
            out.success = true;
        }
        out.wall_time_ms = wall.elapsed().as_secs_f64() * 1e3;
        out
    };

    // Per-trial jitter of where the pallet really stands (its own random stream).
    let true_pallet = jitter(&case.pallet, &scn.pallet_jitter, &mut stream(seed, 3));
    let obstacles = scn.world.obstacles();
    let mut sim = match Sim::new(
        truck,
        &case.start,
        &scn.pallet,
        &true_pallet,
        &obstacles,
        &scn.sim,
    ) {
        Ok(s) => s,
        Err(e) => {
            rec.event(0.0, Level::Error, &e.to_string());
            return finish(out, Some((Failure::Error, e.to_string())));
        }
    };
    rec.scene(&SceneInfo {
        scenario: &scn.name,
        case: &case.name,
        planner: planner.name(),
        seed,
        truck,
        pallet: &scn.pallet,
        pallet_pose: true_pallet,
        obstacles: &obstacles,
        start: case.start,
    });
    let mut nav_rng = stream(seed, 1);
    let mut est_rng = stream(seed, 2);
    let mut nav = Nav350::new(scn.noise.nav350.clone(), noise);
    let mut est_cfg = scn.noise.pallet_estimate.clone();
    if let Some(s) = opts.pallet_noise_scale {
        est_cfg.scale = s;
    }
    let est_cfg = &est_cfg;
    let replan_enabled = opts.replan.unwrap_or(scn.replan.enabled);
    let insertion = target_insertion_m(truck, &scn.pallet);
    let dt = sim.dt_s();

    let mut predictor = PosePredictor::new();
    let first_fix = nav
        .update(0.0, &sim.fork_root_pose(), &mut nav_rng)
        .unwrap_or(case.start);
    predictor.fix(first_fix);
    let estimate = |truth: &Pose2, range: f64, rng: &mut ChaCha8Rng| {
        let biased = truth.to_world(&scn.estimate_bias);
        if noise {
            est_cfg.estimate(&biased, range, rng)
        } else {
            biased
        }
    };
    let mut pallet_est = estimate(
        &true_pallet,
        first_fix.distance_to(&true_pallet),
        &mut est_rng,
    );
    let plan_cfg = PlannerConfig::default();
    // The planner's curve ends aligned with the pockets, tips just short of the face (the
    // papers' P_dest); the forks then go in straight to the target depth.
    let plan_from = |pose: Pose2, curvature: f64, est: &Pose2| {
        let mut req = PlanRequest::new(pose, goal_for(est, truck, -APPROACH_GAP_M));
        req.truck = truck.clone();
        req.start_curvature_per_m = curvature;
        // Replans start close to the pallet, where the paper's 1.5 m handle bound cannot
        // fit the chord: relax it to a third of the distance there.
        let mut cfg = plan_cfg.clone();
        let chord = pose.distance_to(&req.goal);
        cfg.bspline.min_handle_m = cfg.bspline.min_handle_m.min(chord / 3.0).max(0.05);
        forkbench_plan::plan(planner, &req, &cfg).map(|mut p| {
            p.path.extend_straight(APPROACH_GAP_M + insertion, 0.01);
            p
        })
    };
    let polygon = |p: &forkbench_plan::Plan| match &p.params {
        PlanParams::Bspline {
            control_points_m, ..
        } => Some(control_points_m.to_vec()),
        PlanParams::Spiral(_) => None,
    };
    // Path validation: the truck body swept along a plan must clear every rack and wall,
    // with the same footprint checker the corridor analysis uses.
    let (footprint_obstacles, obstacle_labels) = scn.world.footprint_obstacles();
    let body = truck_footprint(truck);
    let clash = |path: &forkbench_core::Path| {
        if !scn.validate_paths {
            return None;
        }
        footprint_obstacles
            .first_hit_along(&body, path, PATH_CHECK_STEP_M)
            .map(|h| {
                format!(
                    "the planned path runs the truck body into {} at s = {:.2} m",
                    obstacle_labels[h.obstacle], h.s_m
                )
            })
    };
    let plan = match plan_from(first_fix, 0.0, &pallet_est) {
        Ok(p) => p,
        Err(e) => {
            rec.event(0.0, Level::Error, &format!("planning failed: {e}"));
            return finish(out, Some((Failure::PlanFailed, e.to_string())));
        }
    };
    rec.plan(0.0, 0, &plan.path, polygon(&plan).as_deref());
    if let Some(why) = clash(&plan.path) {
        rec.event(0.0, Level::Error, &why);
        out.path_length_m = plan.path.length_m();
        return finish(out, Some((Failure::PlanFailed, why)));
    }
    rec.event(
        0.0,
        Level::Info,
        &format!(
            "{planner} plan: {:.3} m to the pre-entry pose",
            plan.path.length_m()
        ),
    );
    out.path_length_m = plan.path.length_m();
    let mut tracker = PurePursuit::new(
        plan.path,
        scn.tracker.clone(),
        truck.fork_root_ahead_of_front_axle_m,
    );
    // Re-estimate ranges still ahead of the truck, nearest last.
    let mut reestimates: Vec<f64> = est_cfg
        .reestimate_at_m
        .iter()
        .copied()
        .filter(|r| *r < first_fix.distance_to(&pallet_est))
        .collect();
    reestimates.sort_by(|a, b| b.total_cmp(a));

    let pallet0 = sim.pallet_pose();
    let mut collision = false;
    let mut timed_out = true;
    let deadline = scn.timeout_s;
    while sim.time_s() < deadline {
        let truth = sim.fork_root_pose();
        let fix = nav.update(sim.time_s(), &truth, &mut nav_rng);
        if let Some(fix) = fix {
            predictor.fix(fix);
        }
        let pose = predictor.pose().unwrap_or(first_fix);
        if !(pose.is_finite() && truth.is_finite()) {
            return finish(
                out,
                Some((
                    Failure::Error,
                    format!("non-finite state at t = {:.3} s", sim.time_s()),
                )),
            );
        }
        // New pallet estimate at each configured range; replan if it moved enough.
        if replan_enabled
            && reestimates
                .first()
                .is_some_and(|r| pose.distance_to(&pallet_est) <= *r)
        {
            let range = pose.distance_to(&pallet_est);
            reestimates.remove(0);
            let new_est = estimate(&sim.pallet_pose(), range, &mut est_rng);
            let moved = new_est.distance_to(&pallet_est);
            let turned = wrap_angle(new_est.heading_rad - pallet_est.heading_rad).abs();
            if moved > scn.replan.position_threshold_m
                || turned > scn.replan.heading_threshold_deg.to_radians()
            {
                let k0 = sim.steer_rad().tan() / truck.wheelbase_m;
                let replan = plan_from(pose, k0, &new_est).map_err(|e| e.to_string());
                let replan = replan.and_then(|p| match clash(&p.path) {
                    Some(why) => Err(why),
                    None => Ok(p),
                });
                match replan {
                    Ok(p) => {
                        rec.plan(
                            sim.time_s(),
                            out.replans + 1,
                            &p.path,
                            polygon(&p).as_deref(),
                        );
                        rec.event(
                            sim.time_s(),
                            Level::Info,
                            &format!(
                                "replan at {range:.2} m: estimate moved {moved:.3} m, {:.2}°",
                                turned.to_degrees()
                            ),
                        );
                        tracker = PurePursuit::new(
                            p.path,
                            scn.tracker.clone(),
                            truck.fork_root_ahead_of_front_axle_m,
                        );
                        pallet_est = new_est;
                        out.replans += 1;
                    }
                    // Keep tracking the old plan: the truck cannot turn onto the new goal.
                    Err(e) => {
                        rec.event(
                            sim.time_s(),
                            Level::Warn,
                            &format!("replan refused, keeping the old plan: {e}"),
                        );
                        out.replans_failed += 1;
                    }
                }
            }
        }
        let cmd = tracker.command(&pose, sim.speed_mps(), truck);
        if cmd.done && sim.speed_mps().abs() < 0.01 {
            timed_out = false;
            break;
        }
        sim.step(cmd.speed_mps, cmd.steer_rad);
        predictor.propagate(
            sim.speed_mps(),
            sim.steer_rad(),
            truck.wheelbase_m,
            truck.fork_root_ahead_of_front_axle_m,
            dt,
        );
        out.max_steer_rad = out.max_steer_rad.max(sim.steer_rad().abs());
        if sim.obstacle_contact() && !collision {
            rec.event(sim.time_s(), Level::Error, "truck touched a rack or wall");
        }
        collision |= sim.obstacle_contact();
        rec.step(&StepRecord {
            t_s: sim.time_s(),
            truth: sim.fork_root_pose(),
            fix,
            estimate: pose,
            pallet: sim.pallet_pose(),
            pallet_estimate: pallet_est,
            steer_cmd_rad: cmd.steer_rad,
            steer_rad: sim.steer_rad(),
            speed_cmd_mps: cmd.speed_mps,
            speed_mps: sim.speed_mps(),
            lookahead: cmd.lookahead_point,
            cross_track_m: cmd.cross_track_m,
            path_curvature_per_m: cmd.path_curvature_per_m,
            contact_force_n: sim.fork_contact_force_n(),
        });

        let root = sim.fork_root_pose();
        let pallet_now = sim.pallet_pose();
        let depth = insertion_depth(&pallet_now, &root, truck);
        if depth < insertion - 0.01 {
            out.max_contact_force_n = out.max_contact_force_n.max(sim.fork_contact_force_n());
        }
        // Entry: the tips cross the face plane within the face (not beside the pallet).
        let local = in_pallet_frame(&pallet_now, &root);
        if out.lateral_error_m.is_none()
            && depth >= 0.0
            && local.y_m.abs() < scn.pallet.width_m / 2.0
        {
            out.lateral_error_m = Some(local.y_m);
            out.heading_error_rad = Some(local.heading_rad);
            rec.event(
                sim.time_s(),
                Level::Info,
                &format!(
                    "fork entry: {:.4} m lateral, {:.4} rad heading",
                    local.y_m, local.heading_rad
                ),
            );
        }
    }
    out.sim_time_s = sim.time_s();
    let root = sim.fork_root_pose();
    let pallet_now = sim.pallet_pose();
    let local = in_pallet_frame(&pallet_now, &root);
    out.final_lateral_error_m = local.y_m;
    out.final_heading_error_rad = local.heading_rad;
    out.insertion_depth_m = insertion_depth(&pallet_now, &root, truck);
    out.pallet_displacement_m = pallet_now.distance_to(&pallet0);
    out.pallet_rotation_rad = wrap_angle(pallet_now.heading_rad - pallet0.heading_rad);

    let tol = &scn.tolerances;
    let pockets = scn.pallet.pocket_offsets_m();
    let clearance = (scn.pallet.pocket_width_m - truck.fork_width_m) / 2.0;
    let fork_offsets = [truck.fork_spacing_m / 2.0, -truck.fork_spacing_m / 2.0];
    let worst_pocket_miss = fork_offsets
        .iter()
        .zip(pockets)
        .map(|(fy, py)| {
            // Lateral position of the fork's middle in the pallet frame, against its pocket.
            let mid = root.to_world(&Pose2::new(truck.fork_length_m / 2.0, *fy, 0.0));
            (pallet_now.to_local(&mid).y_m - py).abs()
        })
        .fold(0.0, f64::max);
    let failure = if collision {
        Some((
            Failure::Collision,
            "truck touched a rack or wall".to_owned(),
        ))
    } else if out.max_contact_force_n > tol.contact_force_n {
        Some((
            Failure::ContactForce,
            format!(
                "fork–pallet contact {:.0} N > {:.0} N before full depth",
                out.max_contact_force_n, tol.contact_force_n
            ),
        ))
    } else if out.pallet_displacement_m > tol.pallet_displacement_m
        || out.pallet_rotation_rad.abs() > tol.pallet_rotation_deg.to_radians()
    {
        Some((
            Failure::PalletDisplaced,
            format!(
                "pallet moved {:.3} m and turned {:.2}° (limits {} m, {}°)",
                out.pallet_displacement_m,
                out.pallet_rotation_rad.to_degrees(),
                tol.pallet_displacement_m,
                tol.pallet_rotation_deg
            ),
        ))
    } else if out.lateral_error_m.is_some_and(|e| e.abs() > tol.lateral_m) {
        Some((
            Failure::LateralError,
            format!(
                "{:.3} m off the pocket centre line at entry (limit {} m)",
                out.lateral_error_m.unwrap_or(0.0),
                tol.lateral_m
            ),
        ))
    } else if out
        .heading_error_rad
        .is_some_and(|e| e.abs() > tol.heading_deg.to_radians())
    {
        Some((
            Failure::HeadingError,
            format!(
                "{:.2}° off the pallet axis at entry (limit {}°)",
                out.heading_error_rad.unwrap_or(0.0).to_degrees(),
                tol.heading_deg
            ),
        ))
    } else if timed_out {
        Some((
            Failure::Timeout,
            format!("not stopped at the goal after {deadline} s"),
        ))
    } else if out.insertion_depth_m < tol.insertion_depth_m {
        Some((
            Failure::InsertionDepth,
            format!(
                "forks {:.3} m deep (required {} m)",
                out.insertion_depth_m, tol.insertion_depth_m
            ),
        ))
    } else if worst_pocket_miss > clearance {
        Some((
            Failure::ForkOutsidePocket,
            format!(
                "a fork is {worst_pocket_miss:.3} m from its pocket centre (clearance {clearance:.4} m)"
            ),
        ))
    } else {
        None
    };
    finish(out, failure)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Issue 21, defect 10: a truck that drove away behind the pallet reported an
    /// insertion depth of 106 m; depth counts only from the front and is at most the forks.
    #[test]
    fn insertion_depth_is_bounded_by_the_forks_and_counted_from_the_front() {
        let truck = ForkliftSpec::default();
        let pallet = Pose2::new(0.0, 0.0, 0.0);
        let at = |x: f64| insertion_depth(&pallet, &Pose2::new(x, 0.0, 0.0), &truck);
        assert!(
            (at(-truck.fork_length_m - 0.5) + 0.5).abs() < 1e-12,
            "short of the face"
        );
        assert!(
            (at(-truck.fork_length_m + 0.8) - 0.8).abs() < 1e-12,
            "0.8 m in"
        );
        assert!(at(-0.01) <= truck.fork_length_m);
        assert_eq!(at(0.5), 0.0, "root past the face");
        assert_eq!(at(105.0), 0.0, "drove away behind the pallet");
    }
}
