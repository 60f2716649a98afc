//! Checks of a scenario at load: run settings, value ranges, and the layout of every case (no overlaps at the start).

use forkbench_core::{ForkliftSpec, PalletSpec, Pose2};
use forkbench_geom::Obstacles;

use crate::footprints::{pallet_footprint, shrunk, truck_footprint};

use super::file::{CaseFile, PalletPlacement, ScenarioFile};
use super::{Case, MAX_CASES, MAX_TIMEOUT_S, World, invalid, invalid_setting};
use crate::ScenarioError;

fn check_layout(
    case: &Case,
    truck: &ForkliftSpec,
    pallet: &PalletSpec,
    world: &World,
    file: &str,
    field: &str,
) -> Result<(), ScenarioError> {
    let (obstacles, labels) = world.footprint_obstacles();
    let (pallet_fp, truck_fp) = (
        shrunk(pallet_footprint(pallet)),
        shrunk(truck_footprint(truck)),
    );
    if let Some(i) = obstacles.hit(&pallet_fp, &case.pallet) {
        return Err(invalid(
            file,
            &format!("{field}pallet"),
            &format!("pallet overlaps {}", labels[i]),
        ));
    }
    if let Some(i) = obstacles.hit(&truck_fp, &case.start) {
        return Err(invalid(
            file,
            &format!("{field}start"),
            &format!("truck starts inside {}", labels[i]),
        ));
    }
    let mut pallet_only = Obstacles::new();
    pallet_only.add_rect(
        &pallet_fp.centre(&case.pallet),
        pallet_fp.length_m,
        pallet_fp.width_m,
    );
    if pallet_only.collides(&truck_fp, &case.start) {
        return Err(invalid(
            file,
            &format!("{field}start"),
            "truck starts overlapping the pallet",
        ));
    }
    Ok(())
}

/// Run settings of a scenario file, checked at load: the trial timeout, [sim], [replan]
/// and the tolerances.
fn check_settings(f: &ScenarioFile, file: &str) -> Result<(), ScenarioError> {
    if !(f.timeout_s.is_finite() && f.timeout_s > 0.0 && f.timeout_s <= MAX_TIMEOUT_S) {
        return Err(invalid(
            file,
            "timeout_s",
            "must be a positive time of at most 600 s",
        ));
    }
    if let Err(e) = f.sim.validate() {
        return Err(invalid_setting(file, "sim", &e));
    }
    if let Err(e) = f.pick.check() {
        return Err(invalid_setting(file, "pick", &e));
    }
    for (name, v) in [
        ("position_threshold_m", f.replan.position_threshold_m),
        ("heading_threshold_deg", f.replan.heading_threshold_deg),
    ] {
        if !(v.is_finite() && v > 0.0) {
            return Err(invalid(
                file,
                &format!("replan.{name}"),
                "must be a positive finite number (NaN would disable the trigger)",
            ));
        }
    }
    let ranges = f.replan.reestimate_at_m.as_deref().unwrap_or_default();
    if ranges.len() > 64 || ranges.iter().any(|r| !(r.is_finite() && *r > 0.0)) {
        return Err(invalid(
            file,
            "replan.reestimate_at_m",
            "must list at most 64 positive finite ranges",
        ));
    }
    let t = &f.tolerances;
    for (name, v) in [
        ("lateral_m", t.lateral_m),
        ("heading_deg", t.heading_deg),
        ("insertion_depth_m", t.insertion_depth_m),
        ("contact_force_n", t.contact_force_n),
        ("pallet_displacement_m", t.pallet_displacement_m),
        ("pallet_rotation_deg", t.pallet_rotation_deg),
    ] {
        if !(v.is_finite() && v > 0.0) {
            return Err(invalid(
                file,
                &format!("tolerances.{name}"),
                "must be a positive finite number",
            ));
        }
    }
    check_upper_bounds(f, file)
}

/// Upper bounds of `[replan]` and `[tolerances]`: a threshold or a tolerance beyond them
/// judges nothing.
fn check_upper_bounds(f: &ScenarioFile, file: &str) -> Result<(), ScenarioError> {
    let t = &f.tolerances;
    let ranges = f.replan.reestimate_at_m.as_deref().unwrap_or_default();
    let r = &f.replan;
    forkbench_core::settings::in_ranges(&[
        (
            "replan.position_threshold_m",
            r.position_threshold_m,
            0.0,
            100.0,
        ),
        (
            "replan.heading_threshold_deg",
            r.heading_threshold_deg,
            0.0,
            180.0,
        ),
        ("tolerances.lateral_m", t.lateral_m, 0.0, 10.0),
        ("tolerances.heading_deg", t.heading_deg, 0.0, 180.0),
        (
            "tolerances.insertion_depth_m",
            t.insertion_depth_m,
            0.0,
            10.0,
        ),
        ("tolerances.contact_force_n", t.contact_force_n, 0.0, 1e12),
        (
            "tolerances.pallet_displacement_m",
            t.pallet_displacement_m,
            0.0,
            100.0,
        ),
        (
            "tolerances.pallet_rotation_deg",
            t.pallet_rotation_deg,
            0.0,
            180.0,
        ),
    ])
    .map_err(|e| invalid(file, e.field.as_deref().unwrap_or(""), &e.reason))?;
    if ranges.iter().any(|r| *r > 100.0) {
        return Err(invalid(
            file,
            "replan.reestimate_at_m",
            "ranges must be at most 100 m",
        ));
    }
    Ok(())
}

/// `file:line` of the first line that writes `key` (a key before its `=`, or a table
/// header), else `file` alone.
pub(super) fn at_line(file: &str, text: &str, key: &str) -> String {
    text.lines()
        .position(|l| {
            l.trim_start().strip_prefix(key).is_some_and(|rest| {
                let rest = rest.trim_start();
                rest.is_empty() || rest.starts_with(['=', '#'])
            })
        })
        .map_or_else(|| file.to_owned(), |i| format!("{file}:{}", i + 1))
}

/// The pallet's payload: a mass, and with the pallet no more than the truck may lift.
pub(super) fn check_payload(
    truck: &ForkliftSpec,
    pallet: &PalletSpec,
    (file, text): (&str, &str),
) -> Result<(), ScenarioError> {
    let file = &at_line(file, text, "payload_kg");
    // The pallet kinds are fixed and valid: only the payload can fail here.
    if let Err(e) = pallet.validate() {
        return Err(invalid(
            file,
            e.field.as_deref().unwrap_or("payload_kg"),
            &e.reason,
        ));
    }
    if pallet.loaded_mass_kg() > truck.rated_capacity_kg {
        return Err(invalid(
            file,
            "payload_kg",
            &format!(
                "the pallet with its payload weighs {} kg, more than the truck's rated capacity \
                 (truck.rated_capacity_kg = {} kg)",
                pallet.loaded_mass_kg(),
                truck.rated_capacity_kg
            ),
        ));
    }
    Ok(())
}

/// Value ranges of the truck, sensors, run settings, estimate bias and pallet jitter.
pub(super) fn check_values(f: &ScenarioFile, file: &str) -> Result<(), ScenarioError> {
    f.truck
        .validate()
        .map_err(|e| invalid_setting(file, "truck", &e))?;
    if let Err(e) = f.noise.nav350.validate() {
        return Err(invalid_setting(file, "noise.nav350", &e));
    }
    if let Err(e) = f.noise.pallet_estimate.validate() {
        return Err(invalid_setting(file, "noise.pallet_estimate", &e));
    }
    if let Err(e) = f.noise.odometry.validate() {
        return Err(invalid_setting(file, "noise.odometry", &e));
    }
    check_settings(f, file)?;
    f.truck
        .control
        .steps_per_tick(f.sim.dt_s)
        .map_err(|e| invalid_setting(file, "truck", &e))?;
    if let Some(b) = &f.estimate_bias {
        b.check(file, "estimate_bias")?;
    }
    if let Some(j) = &f.pallet_jitter {
        j.check(file, "pallet_jitter")?;
        for (name, v) in [
            ("x_m", j.x_m),
            ("y_m", j.y_m),
            ("heading_deg", j.heading_deg),
        ] {
            if v < 0.0 {
                return Err(invalid(
                    file,
                    &format!("pallet_jitter.{name}"),
                    "a standard deviation must be ≥ 0",
                ));
            }
        }
    }
    Ok(())
}

/// Where a placement puts the pallet: its pose, or the world's slot of that name.
fn place(
    p: &PalletPlacement,
    world: &World,
    file: &str,
    field: &str,
) -> Result<Pose2, ScenarioError> {
    match p {
        PalletPlacement::Pose(pd) => {
            pd.check(file, field)?;
            Ok(pd.to_pose())
        }
        PalletPlacement::Slot { slot } => world.slot_pose(slot).ok_or_else(|| {
            invalid(
                file,
                &format!("{field}.slot"),
                &format!("world has no pallet slot {slot:?}"),
            )
        }),
    }
}

/// The cases (or the one `default` case), each with its start and pallet resolved and
/// its layout checked; names unique.
pub(super) fn resolve_cases(
    f: &ScenarioFile,
    world: &World,
    pallet: &PalletSpec,
    file: &str,
) -> Result<Vec<Case>, ScenarioError> {
    if f.case.len() > MAX_CASES {
        return Err(invalid(
            file,
            "case",
            &format!("{} cases; at most {MAX_CASES} per file", f.case.len()),
        ));
    }
    let default = [CaseFile {
        name: "default".into(),
        start: None,
        pallet: None,
    }];
    let listed: &[CaseFile] = if f.case.is_empty() { &default } else { &f.case };
    let mut cases: Vec<Case> = Vec::new();
    for (i, c) in listed.iter().enumerate() {
        let field = if f.case.is_empty() {
            String::new()
        } else {
            format!("case[{i}].")
        };
        let start = c
            .start
            .or(f.start)
            .ok_or_else(|| invalid(file, &format!("{field}start"), "missing"))?;
        start.check(file, &format!("{field}start"))?;
        let placement = c
            .pallet
            .as_ref()
            .or(f.pallet.as_ref())
            .ok_or_else(|| invalid(file, &format!("{field}pallet"), "missing"))?;
        let case = Case {
            name: c.name.clone(),
            start: start.to_pose(),
            pallet: place(placement, world, file, &format!("{field}pallet"))?,
        };
        check_layout(&case, &f.truck, pallet, world, file, &field)?;
        if cases.iter().any(|k| k.name == case.name) {
            return Err(invalid(
                file,
                &format!("{field}name"),
                "duplicate case name",
            ));
        }
        cases.push(case);
    }
    Ok(cases)
}

/// How the truck's forks fit the pallet: what `forkbench check` prints and the loader
/// refuses when it does not hold.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ForkFit {
    pub fork_spacing_m: f64,
    /// Spacings that keep each fork inside its pocket.
    pub spacing_range_m: [f64; 2],
    pub fork_length_m: f64,
    /// The insertion the judge requires (`tolerances.insertion_depth_m`).
    pub insertion_depth_m: f64,
    /// The insertion the pick aims for (`[pick] insertion_m`, or its default).
    pub insertion_target_m: f64,
    pub pallet_depth_m: f64,
}

impl ForkFit {
    pub fn spacing_ok(&self) -> bool {
        (self.spacing_range_m[0]..=self.spacing_range_m[1]).contains(&self.fork_spacing_m)
    }

    pub fn depth_ok(&self) -> bool {
        self.insertion_depth_m <= self.fork_length_m.min(self.pallet_depth_m)
    }

    /// The target reaches the required depth and stays within the forks and the pallet.
    pub fn target_ok(&self) -> bool {
        const EPS_M: f64 = 1e-9;
        self.insertion_target_m + EPS_M >= self.insertion_depth_m
            && self.insertion_target_m <= self.fork_length_m.min(self.pallet_depth_m) + EPS_M
    }
}

/// The fit of `truck`'s forks in `pallet` for a required insertion depth and the
/// insertion the pick aims for.
pub fn fork_fit(
    truck: &forkbench_core::ForkliftSpec,
    pallet: &forkbench_core::PalletSpec,
    insertion_depth_m: f64,
    insertion_target_m: f64,
) -> ForkFit {
    let (half_fork, half_pocket) = (truck.fork_width_m / 2.0, pallet.pocket_width_m / 2.0);
    let o = pallet.pocket_offsets_m()[0].abs();
    // Each fork's centre at ±spacing/2 must keep the fork inside [o − w/2, o + w/2].
    ForkFit {
        fork_spacing_m: truck.fork_spacing_m,
        spacing_range_m: [
            2.0 * (o - half_pocket + half_fork),
            2.0 * (o + half_pocket - half_fork),
        ],
        fork_length_m: truck.fork_length_m,
        insertion_depth_m,
        insertion_target_m,
        pallet_depth_m: pallet.depth_m,
    }
}

/// The truck's forks against the pallet: each fork inside its pocket, and the required
/// insertion depth within both the forks and the pallet. Contradictions are refused at
/// load, naming the field and saying when the other value is a default.
pub(super) fn check_geometry(
    f: &ScenarioFile,
    (pallet, kind): (&forkbench_core::PalletSpec, &str),
    file: &str,
) -> Result<Option<String>, ScenarioError> {
    let t = &f.truck;
    let target = f.pick.insertion_for(t, pallet);
    let fit = fork_fit(t, pallet, f.tolerances.insertion_depth_m, target);
    let o = pallet.pocket_offsets_m()[0].abs();
    let [lo, hi] = fit.spacing_range_m;
    if !fit.spacing_ok() {
        return Err(invalid(
            file,
            "truck.fork_spacing_m",
            &format!(
                "{} m puts the {} m wide forks outside the pallet's pockets ({kind}: pocket centres ±{o:.4} m, {:.4} m wide): the spacing must lie within {lo:.3}..{hi:.3} m",
                t.fork_spacing_m, t.fork_width_m, pallet.pocket_width_m
            ),
        ));
    }
    let depth = f.tolerances.insertion_depth_m;
    let default_depth = crate::tolerances::Tolerances::default().insertion_depth_m;
    let note = if depth == default_depth {
        " (the default)"
    } else {
        ""
    };
    if t.fork_length_m < depth {
        return Err(invalid(
            file,
            "truck.fork_length_m",
            &format!(
                "{} m forks cannot reach the required insertion depth tolerances.insertion_depth_m = {depth} m{note}; lower that or lengthen the forks",
                t.fork_length_m
            ),
        ));
    }
    if pallet.depth_m < depth {
        return Err(invalid(
            file,
            "tolerances.insertion_depth_m",
            &format!(
                "{depth} m is deeper than the pallet ({kind}: {} m)",
                pallet.depth_m
            ),
        ));
    }
    check_target(&fit, f.pick.insertion_m.is_some(), kind, file)
}

/// The pick's insertion target within the forks and the pallet (refused when set deeper),
/// and a warning when it is short of the depth the judge requires: such a pick succeeds
/// only when it overshoots its own goal.
fn check_target(
    fit: &ForkFit,
    set: bool,
    kind: &str,
    file: &str,
) -> Result<Option<String>, ScenarioError> {
    // A target that equals a bound up to rounding (0.6 m − 0.05 m against 0.55 m) meets it.
    const EPS_M: f64 = 1e-9;
    let target = fit.insertion_target_m;
    let whose = if set {
        "[pick] insertion_m".to_owned()
    } else {
        format!(
            "the default insertion ({} m forks less {} m, or {kind} {} m deep less {} m)",
            fit.fork_length_m,
            crate::file::MAST_MARGIN_M,
            fit.pallet_depth_m,
            crate::file::INSERTION_MARGIN_M
        )
    };
    if set && target > fit.fork_length_m.min(fit.pallet_depth_m) + EPS_M {
        return Err(invalid(
            file,
            "pick.insertion_m",
            &format!(
                "{target} m is deeper than the forks ({} m) or the pallet ({} m) allow",
                fit.fork_length_m, fit.pallet_depth_m
            ),
        ));
    }
    Ok((target + EPS_M < fit.insertion_depth_m).then(|| {
        format!(
            "{file}: {whose} = {target:.3} m is short of the required tolerances.insertion_depth_m = {} m: a pick succeeds only by overshooting its goal; lower that, or set [pick] insertion_m to reach it",
            fit.insertion_depth_m
        )
    }))
}
