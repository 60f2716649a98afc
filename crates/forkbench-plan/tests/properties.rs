//! Property tests: random feasible and infeasible goals never panic or yield NaN; Ok plans end exactly at the goal.

use forkbench_core::{ForkliftSpec, Pose2};
use forkbench_plan::{BsplinePlanner, Plan, PlanError, PlanRequest, Planner, SpiralPlanner};

/// The two published planners, through the `Planner` trait with the papers' settings.
#[derive(Debug, Clone, Copy)]
enum PlannerKind {
    Bspline,
    Spiral,
}

impl PlannerKind {
    const ALL: [PlannerKind; 2] = [PlannerKind::Bspline, PlannerKind::Spiral];
}

/// Plans with the papers' default settings.
fn plan(kind: PlannerKind, req: &PlanRequest) -> Result<Plan, PlanError> {
    match kind {
        PlannerKind::Bspline => BsplinePlanner::default().plan(req),
        PlannerKind::Spiral => SpiralPlanner::default().plan(req),
    }
}
use proptest::prelude::*;

fn check(kind: PlannerKind, req: &PlanRequest, endpoint_tol_m: f64) -> Result<(), TestCaseError> {
    match plan(kind, req) {
        Ok(p) => {
            prop_assert!(p.path.is_finite(), "NaN in path");
            prop_assert!(p.path.samples.len() >= 2);
            let m = p.path.metrics(&req.start, &req.goal, &req.truck);
            prop_assert!(
                m.endpoint_position_error_m <= endpoint_tol_m,
                "endpoint {} m",
                m.endpoint_position_error_m
            );
            prop_assert!(
                m.endpoint_heading_error_rad <= 1e-6,
                "heading {}",
                m.endpoint_heading_error_rad
            );
            prop_assert!(m.start_position_error_m <= 1e-9);
            prop_assert!(
                m.max_abs_curvature_per_m <= req.truck.max_curvature_per_m() * (1.0 + 1e-9)
            );
            prop_assert!(m.max_sample_spacing_m <= 0.01 + 1e-12);
            prop_assert!(p.cost.is_finite());
        }
        Err(e) => {
            // A typed refusal must say which limit failed, with finite numbers.
            match &e {
                PlanError::CurvatureLimit {
                    needed_per_m,
                    limit_per_m,
                    ..
                } => {
                    prop_assert!(
                        needed_per_m.is_finite() && needed_per_m > limit_per_m,
                        "{e}"
                    );
                }
                PlanError::Unreachable { .. } | PlanError::GoalTooClose { .. } => {}
                other => prop_assert!(false, "unexpected error for valid input: {other}"),
            }
            prop_assert!(!e.to_string().is_empty());
        }
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 160, rng_seed: proptest::test_runner::RngSeed::Fixed(21), ..ProptestConfig::default() })]

    /// Goals anywhere around the truck, including behind it and far too close.
    #[test]
    fn any_goal_plans_or_refuses_cleanly(
        x in -8.0..12.0f64, y in -8.0..8.0f64, h in -180.0..180.0f64,
        sx in -5.0..5.0f64, sy in -5.0..5.0f64, sh in -180.0..180.0f64,
        k0 in -1.0..1.0f64,
    ) {
        let start = Pose2::new(sx, sy, sh.to_radians());
        let goal = Pose2::new(sx + x, sy + y, h.to_radians());
        let mut req = PlanRequest::new(start, goal);
        req.start_curvature_per_m = k0;
        prop_assume!(start.distance_to(&goal) > 0.06);
        check(PlannerKind::Bspline, &req, 1e-9)?;
        check(PlannerKind::Spiral, &req, 1e-3)?;
    }

    /// Typical pick geometry (ahead, modest offset and angle): both planners succeed.
    #[test]
    fn typical_picks_succeed(
        ahead in 5.0..9.0f64, lateral in -1.5..1.5f64, angle in -15.0..15.0f64, k0 in -0.2..0.2f64,
    ) {
        let start = Pose2::new(0.0, 0.0, 0.0);
        let goal = Pose2::new(ahead, lateral, angle.to_radians());
        let mut req = PlanRequest::new(start, goal);
        req.start_curvature_per_m = k0;
        for kind in PlannerKind::ALL {
            let p = plan(kind, &req);
            prop_assert!(p.is_ok(), "{kind:?} failed on a typical pick: {:?}", p.err());
        }
        check(PlannerKind::Bspline, &req, 1e-9)?;
        check(PlannerKind::Spiral, &req, 1e-3)?;
    }
}

#[test]
fn non_finite_and_degenerate_inputs_are_refused() {
    let ok = Pose2::new(0.0, 0.0, 0.0);
    for kind in PlannerKind::ALL {
        let req = PlanRequest::new(ok, Pose2::new(f64::NAN, 1.0, 0.0));
        assert!(matches!(
            plan(kind, &req),
            Err(PlanError::InvalidInput { what: "goal", .. })
        ));
        let req = PlanRequest::new(ok, Pose2::new(0.01, 0.0, 0.0));
        assert!(matches!(
            plan(kind, &req),
            Err(PlanError::GoalTooClose { .. })
        ));
        let mut req = PlanRequest::new(ok, Pose2::new(6.0, 0.0, 0.0));
        req.start_curvature_per_m = 2.0;
        assert!(matches!(
            plan(kind, &req),
            Err(PlanError::StartCurvature { .. })
        ));
        let mut req = PlanRequest::new(ok, Pose2::new(6.0, 0.0, 0.0));
        req.truck = ForkliftSpec {
            wheelbase_m: 0.0,
            ..ForkliftSpec::default()
        };
        assert!(matches!(
            plan(kind, &req),
            Err(PlanError::InvalidInput { what: "truck", .. })
        ));
    }
}

#[test]
fn sharp_goal_names_the_curvature_limit() {
    // 1 m ahead and 1.5 m to the side, turned 90°: needs far more than κ_max.
    let req = PlanRequest::new(Pose2::new(0.0, 0.0, 0.0), Pose2::new(1.0, 1.5, -1.5));
    for kind in PlannerKind::ALL {
        let e = plan(kind, &req).expect_err("infeasible");
        let text = e.to_string();
        assert!(
            matches!(
                e,
                PlanError::CurvatureLimit { .. } | PlanError::Unreachable { .. }
            ),
            "{kind:?}: {text}"
        );
        if let PlanError::CurvatureLimit { .. } = e {
            assert!(text.contains("κ_max 1.0630 m⁻¹"), "{text}");
        }
    }
}

#[test]
fn mirrored_goals_give_mirrored_spirals() {
    let start = Pose2::new(0.0, 0.0, 0.0);
    let mut left = PlanRequest::new(start, Pose2::new(6.0, 1.0, 0.3));
    left.start_curvature_per_m = 0.1;
    let mut right = PlanRequest::new(start, Pose2::new(6.0, -1.0, -0.3));
    right.start_curvature_per_m = -0.1;
    let l = plan(PlannerKind::Spiral, &left).expect("feasible");
    let r = plan(PlannerKind::Spiral, &right).expect("feasible");
    assert!((l.cost - r.cost).abs() < 1e-9);
    for (a, b) in l.path.samples.iter().zip(&r.path.samples) {
        assert!(
            (a.y_m + b.y_m).abs() < 1e-9 && (a.curvature_per_m + b.curvature_per_m).abs() < 1e-9
        );
    }
}

/// Regression: a 159° turn with κ0 = −0.65 m⁻¹ over R = 11.8 m ended 1.9 mm off the goal
/// while the spiral's endpoint was integrated with a single 16-point rule.
#[test]
fn large_turn_spiral_endpoint_is_exact() {
    let start = Pose2::new(0.0, 0.0, (-65.439_440_600_119_23_f64).to_radians());
    let goal = Pose2::new(
        11.763_295_236_047_32,
        0.696_950_159_807_437_1,
        135.919_938_135_708_52_f64.to_radians(),
    );
    let mut req = PlanRequest::new(start, goal);
    req.start_curvature_per_m = -0.654_394_592_948_561_6;
    let p = plan(PlannerKind::Spiral, &req).expect("feasible");
    let m = p.path.metrics(&start, &goal, &req.truck);
    assert!(
        m.endpoint_position_error_m < 1e-6,
        "{}",
        m.endpoint_position_error_m
    );
}

/// Regression: a symmetric lane change (θ_f = 0, κ0 = 0, 1.25 m lateral over 5 m) was
/// "unreachable": its solutions sit at a fold in s_f where the fixed-length Jacobian is
/// singular. Nearly symmetric variants failed the same way.
#[test]
fn symmetric_lane_change_spiral_is_found() {
    for k0 in [0.0, -0.004_616_645_353_913_662, 0.003] {
        let mut req = PlanRequest::new(
            Pose2::new(0.0, 0.0, 0.0),
            Pose2::new(5.0, 1.254_866_699_262_767_5, 0.0),
        );
        req.start_curvature_per_m = k0;
        let p = plan(PlannerKind::Spiral, &req).unwrap_or_else(|e| panic!("k0 = {k0}: {e}"));
        let m = p.path.metrics(&req.start, &req.goal, &req.truck);
        assert!(
            m.endpoint_position_error_m < 1e-6,
            "k0 = {k0}: {}",
            m.endpoint_position_error_m
        );
    }
}
