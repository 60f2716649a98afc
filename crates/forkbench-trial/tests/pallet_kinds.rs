//! Pallet kinds in scenarios: each of `scenarios/pallets/` is picked without noise by its scanners, the truck's forks entering the pockets the kind's parts leave (the colliders are those parts: a fork off its pocket strikes a block); bad pallets are refused at load with file, line and field.

use std::path::{Path, PathBuf};

use forkbench_trial::{Scenario, TrialOptions, World, run_trial};

fn repo(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .join(rel)
}

#[test]
fn every_pallet_scenario_is_picked_without_noise_after_replanning() {
    let opts = TrialOptions {
        no_noise: true,
        replan: Some(true),
        ..TrialOptions::default()
    };
    for name in [
        "epal-1",
        "iso-1200x1000-side",
        "gma-48x40",
        "dusseldorf-custom",
    ] {
        let scn = Scenario::load(&repo(&format!("scenarios/pallets/{name}.toml")))
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        let out = run_trial(&scn, &scn.cases[0], &opts);
        assert!(
            out.success,
            "{name}: {:?} {:?}",
            out.failure, out.failure_detail
        );
        assert!(out.insertion_depth_m >= scn.tolerances.insertion_depth_m);
    }
}

/// The same pick with the forks set 5 cm off the EPAL's pocket centres still fits the
/// check at load but strikes the blocks in the physics.
#[test]
fn forks_set_off_the_pockets_strike_the_blocks() {
    let path = repo("scenarios/pallets/epal-1.toml");
    let text = std::fs::read_to_string(&path)
        .expect("reads")
        .replace("fork_spacing_m = 0.3725", "fork_spacing_m = 0.4725");
    let scn = Scenario::parse(&text, "off.toml", |_| Ok(World::default())).expect("loads");
    let opts = TrialOptions {
        no_noise: true,
        replan: Some(true),
        ..TrialOptions::default()
    };
    let out = run_trial(&scn, &scn.cases[0], &opts);
    assert!(!out.success, "{out:?}");
    assert!(
        out.max_contact_force_n > scn.tolerances.contact_force_n,
        "{out:?}"
    );
}

fn refused(extra: &str) -> String {
    let text = format!(
        "name = \"x\"\nplanner = \"bspline\"\nstart = {{ x_m = 0, y_m = 0, heading_deg = 0 }}\n\
         pallet = {{ x_m = 6, y_m = 0, heading_deg = 0 }}\n{extra}"
    );
    Scenario::parse(&text, "x.toml", |_| Ok(World::default()))
        .expect_err(extra)
        .to_string()
}

const MODEL: &str = "[pallet_model]\nname = \"m\"\ndepth_m = 1.0\nwidth_m = 1.0\nmass_kg = 20\n\
    pocket_height_m = 0.1\nentry = [\"front\"]\nblock = [\n\
    { x_m = 0.5, y_m = -0.45, length_m = 1.0, width_m = 0.1 },\n\
    { x_m = 0.5, y_m = 0.0, length_m = 1.0, width_m = 0.1 },\n\
    { x_m = 0.5, y_m = 0.45, length_m = 1.0, width_m = 0.1 },\n]\n";

#[test]
fn bad_pallets_are_refused_naming_file_line_and_field() {
    // A custom model loads.
    let text = format!(
        "name = \"x\"\nplanner = \"bspline\"\nstart = {{ x_m = 0, y_m = 0, heading_deg = 0 }}\n\
         pallet = {{ x_m = 6, y_m = 0, heading_deg = 0 }}\n{MODEL}"
    );
    let scn = Scenario::parse(&text, "x.toml", |_| Ok(World::default())).expect("loads");
    assert_eq!(scn.pallet.parts().len(), 3);
    assert!((scn.pallet.pocket_width_m - 0.35).abs() < 1e-9);
    for (extra, want) in [
        (
            format!("pallet_kind = \"epal-1\"\n{MODEL}"),
            "x.toml:5: field `pallet_kind`",
        ),
        (
            "pallet_kind = \"field-1200\"\npallet_entry = \"left\"\n".to_owned(),
            "x.toml:6: field `pallet_entry`: pallet_kind field-1200 is a two-way stringer pallet",
        ),
        (
            format!("pallet_entry = \"left\"\n{MODEL}"),
            "field `pallet_entry`: m does not allow entry from its left face",
        ),
        (
            MODEL.replace("y_m = 0.0,", "y_m = 0.3,"),
            "field `pallet_model.block`: m entered from its front face: the pockets",
        ),
        (
            MODEL.replace("y_m = 0.0, length_m = 1.0", "y_m = -0.4, length_m = 1.0"),
            "field `pallet_model.block[1]`: overlaps block[0]",
        ),
        (
            "pallet_kind = \"gma-48x40\"\npallet_entry = \"right\"\n[truck]\nfork_thickness_m = 0.045\n"
                .to_owned(),
            "field `truck.fork_thickness_m`: 0.045 m forks do not fit the 0.0381 m high pockets",
        ),
        (
            "pallet_kind = \"pallet-9000\"\n".to_owned(),
            "\"pallet-9000\": no such pallet kind (known: field-1200, sim-1000, epal-1, \
             iso-1200x1000, gma-48x40)",
        ),
    ] {
        let e = refused(&extra);
        assert!(e.contains(want), "{extra}\n→ {e}");
    }
}
