//! Trucks of any geometry: the library's trucks pick noise-free, a truck file gives the outcome of the same `[truck]` table, and over drawn trucks and every pallet kind a straight-in pick reaches its insertion target, a mirrored pick mirrors, and no verdict contradicts its own measures.

use std::path::{Path, PathBuf};

use forkbench_core::pallet::{PALLET_KINDS, PalletBuild, PalletFace};
use forkbench_core::{ForkliftSpec, PalletSpec, TruckLayout};
use forkbench_trial::trial::{Overrides, read_truck_text};
use forkbench_trial::{Scenario, TrialOptions, TrialOutcome, World, run_trial};
use proptest::prelude::*;

fn repo(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .join(rel)
}

fn library() -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(repo("trucks"))
        .expect("trucks/")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    v.sort();
    assert!(v.len() >= 4, "{v:?}");
    v
}

/// A run's options carrying a truck file, as `--truck FILE` gives them.
fn with_truck_file(path: &Path, mut opts: TrialOptions) -> TrialOptions {
    let text = std::fs::read_to_string(path).expect("reads");
    let f = read_truck_text(&text, &path.display().to_string()).expect("a valid truck file");
    opts.overrides = Overrides {
        truck_preset: f.preset,
        truck: f.settings,
        ..opts.overrides
    };
    opts
}

fn without_clock(o: &TrialOutcome) -> serde_json::Value {
    let mut v = serde_json::to_value(o.without_wall_times()).expect("serialises");
    v.as_object_mut().expect("object").remove("wall_time_ms");
    v
}

#[test]
fn every_library_truck_picks_the_field_test_and_the_rack_noise_free() {
    let no_noise = TrialOptions {
        no_noise: true,
        ..TrialOptions::default()
    };
    for scenario in ["scenarios/field-test.toml", "scenarios/rack-pick.toml"] {
        let scn = Scenario::load(&repo(scenario)).expect("loads");
        for truck in library() {
            let out = run_trial(
                &scn,
                &scn.cases[0],
                &with_truck_file(&truck, no_noise.clone()),
            );
            assert!(
                out.success,
                "{scenario} with {}: {:?} {:?}",
                truck.display(),
                out.failure,
                out.failure_detail
            );
            assert!(out.insertion_depth_m >= scn.tolerances.insertion_depth_m);
        }
    }
}

/// `--truck FILE` and the same truck named by the scenario (`truck = "FILE"`) give the
/// same outcome to the bit, noisy seeds included.
#[test]
fn a_truck_file_gives_the_outcome_of_the_scenario_naming_it() {
    let path = repo("scenarios/field-test.toml");
    let text = std::fs::read_to_string(&path).expect("reads");
    for truck in library() {
        let named = format!("truck = {:?}\n{text}", truck.display().to_string());
        let inline = Scenario::parse(&named, "named.toml", |p| {
            World::load(&repo("scenarios").join(p))
        })
        .expect("loads with its truck file");
        let plain = Scenario::load(&path).expect("loads");
        for seed in [1, 7, 6300000017380417641] {
            let opts = TrialOptions {
                seed: Some(seed),
                ..TrialOptions::default()
            };
            let a = run_trial(&inline, &inline.cases[0], &opts);
            let b = run_trial(&plain, &plain.cases[0], &with_truck_file(&truck, opts));
            assert_eq!(without_clock(&a), without_clock(&b), "{}", truck.display());
        }
    }
}

/// A truck file's sensor mounts reach its scanners and its NAV350, by `--truck` and by
/// the scenario naming the file alike, and move the outcome.
#[test]
fn a_truck_files_mounts_place_its_sensors() {
    let dir = std::env::temp_dir().join(format!("fb-mounts-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let file = dir.join("mounted.toml");
    let base = std::fs::read_to_string(repo("trucks/jungheinrich-efg-316k.toml")).expect("reads");
    std::fs::write(
        &file,
        format!("{base}\n[mount.tim561]\nx_m = 0.05\ny_m = 0.12\n[mount.nav350]\nx_m = -0.6\n"),
    )
    .expect("written");
    let plain_truck = repo("trucks/jungheinrich-efg-316k.toml");
    for scenario in ["scenarios/field-test.toml", "scenarios/rack-pick.toml"] {
        let path = repo(scenario);
        let text = std::fs::read_to_string(&path).expect("reads");
        let named = format!("truck = {:?}\n{text}", file.display().to_string());
        let inline = Scenario::parse(&named, "named.toml", |p| {
            World::load(&repo("scenarios").join(p))
        })
        .expect("loads with its truck file");
        let plain = Scenario::load(&path).expect("loads");
        let opts = TrialOptions {
            seed: Some(7),
            ..TrialOptions::default()
        };
        let run = with_truck_file(&file, opts.clone())
            .resolve(&plain)
            .expect("resolves");
        if let Some(tim) = run.pallet_sensing.scanner("tim561") {
            assert_eq!((tim.mount.x_m, tim.mount.y_m), (0.05, 0.12), "{scenario}");
        }
        let a = run_trial(&inline, &inline.cases[0], &opts);
        let b = run_trial(
            &plain,
            &plain.cases[0],
            &with_truck_file(&file, opts.clone()),
        );
        let c = run_trial(
            &plain,
            &plain.cases[0],
            &with_truck_file(&plain_truck, opts),
        );
        assert!(
            a.failure != Some(forkbench_trial::Failure::Error),
            "{scenario}: {:?}",
            a.failure_detail
        );
        assert_eq!(without_clock(&a), without_clock(&b), "{scenario}");
        assert_ne!(
            without_clock(&a),
            without_clock(&c),
            "{scenario}: the mounts moved nothing"
        );
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// A sensor mounted twice (by the truck and by the scenario's `[sensors]`) is refused at
/// load, and so is a NAV350 the run's truck mounts outside its body, before any trial.
#[test]
fn a_mount_given_twice_or_off_the_truck_is_refused_at_load() {
    let load =
        |text: &str| Scenario::parse(text, "t.toml", |p| World::load(&repo("scenarios").join(p)));
    let field = std::fs::read_to_string(repo("scenarios/field-test.toml")).expect("reads");
    let twice = field.replace(
        "kind = \"tim561+kinect2\"",
        "kind = \"tim561+kinect2\"\n[sensors.pallet.scanners.tim561]\nmount = { x_m = 0.1, y_m = 0.0, heading_rad = 0.0 }",
    ) + "\n[truck.mount.tim561]\nx_m = 0.05\n";
    let e = load(&twice).expect_err("mounted twice").to_string();
    assert!(
        e.contains("sensors.pallet.scanners.tim561.mount") && e.contains("mounts tim561 already"),
        "{e}"
    );
    let rack = std::fs::read_to_string(repo("scenarios/rack-pick.toml")).expect("reads");
    // Refused as the scenario loads (its components are built once there).
    let e = load(&format!("{rack}\n[truck.mount.nav350]\nx_m = 1.0\n"))
        .expect_err("a NAV350 ahead of the forks")
        .to_string();
    assert!(
        e.contains("mount.nav350") && e.contains("outside the truck"),
        "{e}"
    );
    // The same truck given by the run, as `--truck` does.
    let dir = std::env::temp_dir().join(format!("fb-mount-off-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let file = dir.join("off.toml");
    std::fs::write(&file, "[mount.nav350]\nx_m = 1.0\n").expect("written");
    let plain = Scenario::load(&repo("scenarios/rack-pick.toml")).expect("loads");
    let e = with_truck_file(&file, TrialOptions::default())
        .check_against(&plain)
        .expect_err("refused before the first trial")
        .to_string();
    assert!(e.contains("mount.nav350"), "{e}");
    std::fs::remove_dir_all(&dir).ok();
}

/// The A30's file is the bench's default truck: every field written out.
#[test]
fn the_a30_file_is_the_default_truck() {
    let scn = Scenario::load(&repo("scenarios/field-test.toml")).expect("loads");
    let text = format!(
        "truck = {:?}\n{}",
        repo("trucks/hangcha-a30.toml").display().to_string(),
        std::fs::read_to_string(repo("scenarios/field-test.toml")).expect("reads")
    );
    let named = Scenario::parse(&text, "a30.toml", |p| {
        World::load(&repo("scenarios").join(p))
    })
    .expect("loads");
    assert_eq!(named.truck, scn.truck);
    assert_eq!(scn.truck, ForkliftSpec::default());
}

/// A pallet kind as the forks meet it.
fn pallet_of(kind: &str) -> PalletSpec {
    let k = PALLET_KINDS.iter().find(|k| k.name == kind).expect("kind");
    match k.build {
        PalletBuild::Stringers(f) => f(),
        PalletBuild::Parts(m) => m().entered_from(PalletFace::Front).expect("front entry"),
    }
}

/// A drawn truck: a geometry within the library's envelope, its forks set to the pallet's
/// pocket centres and no wider than its pockets leave room for.
#[derive(Debug, Clone)]
struct Drawn {
    kind: &'static str,
    layout: TruckLayout,
    wheelbase_m: f64,
    lock_rad: f64,
    body_length_m: f64,
    body_width_m: f64,
    mass_kg: f64,
    fork_length_m: f64,
    fork_width_share: f64,
    root_ahead_m: f64,
    /// The steered wheel's share of the weight, when axle loads place the mass.
    steered_share: Option<f64>,
}

fn drawn() -> impl Strategy<Value = Drawn> {
    let kinds: Vec<&'static str> = PALLET_KINDS.iter().map(|k| k.name).collect();
    (
        proptest::sample::select(kinds),
        proptest::sample::select(TruckLayout::ALL.to_vec()),
        1.2..2.0f64,
        0.0..1.0f64,
        1.6..3.0f64,
        0.9..1.3f64,
        1500.0..6000.0f64,
        1.0..1.8f64,
        0.3..0.8f64,
        0.0..1.0f64,
        0.3..0.85f64,
    )
        .prop_map(|(kind, layout, y, lock, l, b, m, fl, fw, x, share)| {
            // A counterbalance truck: lock 46–69°, the root 0.25–0.6 m ahead of its drive
            // axle. A steered drive wheel: lock up to 90°, the load wheels up to 0.8 m
            // under the forks (a stacker's) or the mast reached 0.5 m past them.
            let (lock_rad, root_ahead_m) = match layout.steered_drive_wheel() {
                false => (0.8 + 0.4 * lock, 0.25 + 0.35 * x),
                true => (
                    0.8 + (std::f64::consts::FRAC_PI_2 - 0.8) * lock,
                    -0.8 + 1.3 * x,
                ),
            };
            // A chassis whose centre leaves an axle less than a tenth of the weight has
            // its mass placed by drawn axle loads instead (VDI 2198 line 2.3), as its
            // type sheet would.
            let centre_share = -(root_ahead_m - l / 2.0) / y;
            let steered_share = (!(0.1..=0.9).contains(&centre_share)).then_some(share);
            Drawn {
                kind,
                layout,
                wheelbase_m: y,
                lock_rad,
                body_length_m: l,
                body_width_m: b,
                mass_kg: m,
                fork_length_m: fl,
                fork_width_share: fw,
                root_ahead_m,
                steered_share,
            }
        })
}

/// A straight-in pick of `d` from `y_m` to the side at `heading_deg`, its required depth
/// 0.8 of the default target so every drawn truck can meet it.
fn straight_in(d: &Drawn, y_m: f64, heading_deg: f64) -> Scenario {
    let pallet = pallet_of(d.kind);
    let fork_width = (0.06 + d.fork_width_share * 0.1).min(pallet.pocket_width_m - 0.04);
    let spacing = 2.0 * pallet.pocket_offsets_m()[0].abs();
    let truck = ForkliftSpec {
        layout: d.layout,
        wheelbase_m: d.wheelbase_m,
        max_steer_rad: d.lock_rad,
        body_length_m: d.body_length_m,
        body_width_m: d.body_width_m,
        mass_kg: d.mass_kg,
        fork_length_m: d.fork_length_m,
        fork_width_m: fork_width,
        fork_spacing_m: spacing,
        fork_root_ahead_of_front_axle_m: d.root_ahead_m,
        axle_load_fixed_kg: d.steered_share.map(|s| d.mass_kg * (1.0 - s)),
        axle_load_steered_kg: d.steered_share.map(|s| d.mass_kg * s),
        ..ForkliftSpec::default()
    };
    let target = forkbench_trial::scenario::default_insertion_m(&truck, &pallet);
    let table = toml::to_string(&truck).expect("serialises");
    let text = format!(
        "name = \"straight-in\"\nplanner = \"bspline\"\npallet_kind = \"{}\"\n\
         start = {{ x_m = 0.0, y_m = {y_m}, heading_deg = {heading_deg} }}\n\
         pallet = {{ x_m = 5.0, y_m = 0.0, heading_deg = 0.0 }}\n\
         [tolerances]\ninsertion_depth_m = {}\n[truck]\n{table}",
        d.kind,
        0.8 * target
    );
    Scenario::parse(&text, "straight-in.toml", |_| Ok(World::default()))
        .unwrap_or_else(|e| panic!("{d:?}: {e}\n{text}"))
}

/// What a record names as having stopped the forks short.
fn something_stopped(o: &TrialOutcome) -> bool {
    o.max_contact_force_n > 0.0
        || o.mast_contact_force_n > 0.0
        || o.pallet_displacement_m > 0.0
        || matches!(
            o.failure.as_ref().map(|f| f.name()),
            Some("timeout" | "collision" | "plan_failed" | "pallet_not_found" | "error")
        )
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, failure_persistence: None, ..ProptestConfig::default() })]

    /// Noise-free and straight in, every drawn truck succeeds at every pallet kind with
    /// its forks at the target depth; and its verdict agrees with its measures.
    #[test]
    fn a_straight_in_pick_reaches_its_target(d in drawn()) {
        let scn = straight_in(&d, 0.0, 0.0);
        let opts = TrialOptions { no_noise: true, ..TrialOptions::default() };
        let out = run_trial(&scn, &scn.cases[0], &opts);
        let target = scn.insertion_m();
        prop_assert!(out.success, "{d:?}: {:?} {:?}", out.failure, out.failure_detail);
        prop_assert!((out.insertion_depth_m - target).abs() < 0.03,
            "{d:?}: depth {} against target {target}", out.insertion_depth_m);
        prop_assert!(out.insertion_depth_m >= scn.tolerances.insertion_depth_m
            || something_stopped(&out), "{d:?}: {out:?}");
    }

    /// The same pick mirrored about the pallet's axis gives the mirrored outcome.
    #[test]
    fn a_mirrored_pick_mirrors(d in drawn(), y in 0.05..0.3f64, h in 1.0..6.0f64) {
        let opts = TrialOptions { no_noise: true, ..TrialOptions::default() };
        let left = straight_in(&d, y, -h);
        let right = straight_in(&d, -y, h);
        let a = run_trial(&left, &left.cases[0], &opts);
        let b = run_trial(&right, &right.cases[0], &opts);
        prop_assert_eq!(a.success, b.success, "{:?}: {:?} / {:?}", d, a.failure_detail, b.failure_detail);
        prop_assert!((a.insertion_depth_m - b.insertion_depth_m).abs() < 0.005, "{d:?}");
        if let (Some(la), Some(lb)) = (a.lateral_error_m, b.lateral_error_m) {
            prop_assert!((la + lb).abs() < 0.005, "{d:?}: {la} against {lb}");
        }
    }

    /// With noise, a depth short of the requirement is never a bare number: a contact, a
    /// push, a collision or a time-out is in the record with it (the "0.000 m deep with
    /// the forks in the pockets" of a short-forked truck).
    #[test]
    fn a_short_depth_names_what_stopped_the_forks(d in drawn(), seed in 0u64..1_000_000) {
        let scn = straight_in(&d, 0.1, 2.0);
        let opts = TrialOptions { seed: Some(seed), ..TrialOptions::default() };
        let out = run_trial(&scn, &scn.cases[0], &opts);
        if out.insertion_depth_m < 0.01 {
            prop_assert!(something_stopped(&out), "{d:?} seed {seed}: {out:?}");
        }
    }
}

/// Whether a fork `fork_width_m` wide centred `y_m` across the pallet overlaps a solid
/// part of its face.
fn fork_meets_a_part(pallet: &PalletSpec, y_m: f64, fork_width_m: f64) -> bool {
    pallet
        .parts()
        .iter()
        .any(|p| (p.y_m - y_m).abs() < (p.width_m + fork_width_m) / 2.0)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]
    /// The forks' lateral play is where a fork first meets a block or stringer, for every
    /// pallet kind and drawn forks; a lateral tolerance wider than it is warned of at
    /// load, one within it is not.
    #[test]
    fn the_forks_play_is_where_a_fork_meets_a_part_and_a_wider_tolerance_warns(
        k in 0..PALLET_KINDS.len(), share in 0.0..1.0f64, off in -0.02..0.02f64
    ) {
        let kind = PALLET_KINDS[k].name;
        let pallet = pallet_of(kind);
        let fork_width = 0.05 + share * (pallet.pocket_width_m - 0.1);
        let spacing = 2.0 * pallet.pocket_offsets_m()[0].abs() + off;
        let truck = ForkliftSpec { fork_width_m: fork_width, fork_spacing_m: spacing, ..ForkliftSpec::default() };
        let play = forkbench_trial::scenario::fork_play::lateral_play_m(&truck, &pallet);
        prop_assume!(play > 0.004);
        for side in [-1.0, 1.0] {
            let at = |y: f64| [spacing / 2.0 + y, -spacing / 2.0 + y]
                .iter()
                .any(|&c| fork_meets_a_part(&pallet, c, fork_width));
            prop_assert!(!at(side * (play - 0.002)), "{kind}: a fork meets a part within the play {play}");
            prop_assert!(at(side * (play + 0.002)), "{kind}: no part beyond the play {play}");
        }
        let table = toml::to_string(&truck).expect("serialises");
        let scn = |lateral: f64| {
            let text = format!(
                "name = \"play\"\nplanner = \"bspline\"\npallet_kind = \"{kind}\"\n\
                 start = {{ x_m = 0.0, y_m = 0.0, heading_deg = 0.0 }}\n\
                 pallet = {{ x_m = 5.0, y_m = 0.0, heading_deg = 0.0 }}\n\
                 [tolerances]\nlateral_m = {lateral}\ninsertion_depth_m = 0.3\n[truck]\n{table}"
            );
            Scenario::parse(&text, "play.toml", |_| Ok(World::default())).expect("parses")
        };
        let warns = |s: &Scenario| s.warnings.iter().any(|w| w.contains("wider than the forks' play"));
        prop_assert!(warns(&scn(play + 0.003)), "{kind}: no warning above the play {play}");
        prop_assert!(!warns(&scn(play - 0.003)), "{kind}: a warning within the play {play}");
    }
}
