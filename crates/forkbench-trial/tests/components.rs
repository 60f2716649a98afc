//! Scenario files choose components by name with their settings; old files keep working;
//! unknown kinds and settings are refused with the file, line and field.

use std::path::Path;

use forkbench_trial::{Scenario, ScenarioError, World};

const LAYOUT: &str = "name = \"c\"\nstart = { x_m = 0.0, y_m = 0.0, heading_deg = 0.0 }\n\
                      pallet = { x_m = 8.0, y_m = 0.0, heading_deg = 0.0 }\n";

fn parse(body: &str) -> Result<Scenario, ScenarioError> {
    let text = format!("{LAYOUT}{body}");
    Scenario::parse(&text, "c.toml", |_: &Path| Ok(World::default()))
}

fn error(body: &str) -> String {
    parse(body).expect_err("refused").to_string()
}

#[test]
fn old_scenario_files_keep_working() {
    let s = parse("planner = \"spiral\"\n[tracker]\nlookahead_m = 0.9\n").expect("old form");
    assert_eq!(
        (s.planner.kind.as_str(), s.planner.name.as_str()),
        ("spiral", "spiral")
    );
    assert_eq!(s.tracker.kind, "pure_pursuit");
    assert_eq!(s.tracker.settings.get("lookahead_m"), Some(&0.9.into()));
}

#[test]
fn tables_name_the_kind_a_name_and_settings() {
    let s = parse(
        "[planner]\nkind = \"bspline\"\nname = \"bs-fine\"\ngrid_points = 12\n\
         [tracker]\nkind = \"regulated_pure_pursuit\"\nmax_lookahead_m = 1.5\n",
    )
    .expect("new form");
    assert_eq!(s.planner.name, "bs-fine");
    assert_eq!(s.planner.settings.get("grid_points"), Some(&12.into()));
    assert_eq!(s.tracker.kind, "regulated_pure_pursuit");
}

#[test]
fn unknown_kinds_and_settings_name_file_line_and_field() {
    let e = error("[planner]\nkind = \"bspline\"\ngrid_points = 8\nmin_handel_m = 1.0\n");
    assert!(
        e.starts_with("c.toml:7: field `planner.min_handel_m`"),
        "{e}"
    );
    let e = error("planner = \"bspline\"\n[tracker]\nkind = \"stanley\"\n");
    assert!(e.starts_with("c.toml:6: field `tracker.kind`"), "{e}");
    assert!(e.contains("pure_pursuit, regulated_pure_pursuit"), "{e}");
    let e = error("planner = \"bspline\"\n[tracker]\ncruise_speed_mps = -1\n");
    assert!(
        e.starts_with("c.toml:6: field `tracker.cruise_speed_mps`"),
        "{e}"
    );
    let e = error("[planner]\nkind = \"external\"\n");
    assert!(e.contains("field `planner.command`"), "{e}");
    let e = error("[planner]\ngrid_points = 8\n");
    assert!(
        e.contains("field `planner.kind`") && e.contains("missing"),
        "{e}"
    );
}

#[test]
fn a_run_names_the_scenarios_own_component_or_a_registered_kind() {
    let s = parse("[planner]\nkind = \"bspline\"\nname = \"mine\"\n").expect("loads");
    use forkbench_trial::Role;
    assert_eq!(
        s.component(Role::Planner, Some("mine")).expect("own").kind,
        "bspline"
    );
    assert_eq!(
        s.component(Role::Planner, Some("spiral"))
            .expect("kind")
            .kind,
        "spiral"
    );
    let e = s
        .component(Role::Planner, Some("nope"))
        .expect_err("unknown")
        .to_string();
    assert!(e.contains("unknown planner \"nope\""), "{e}");
}

/// Issue 78: a components file adds names and never redefines a built-in one; the refusal
/// names the built-in and what the file made of it.
#[test]
fn a_components_file_cannot_redefine_a_built_in_name() {
    let dir = std::env::temp_dir().join(format!("fb-redefine-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let registry = forkbench_trial::Registry::builtin();
    for (text, name) in [
        (
            "[[tracker]]\nname = \"regulated_pure_pursuit\"\nkind = \"external\"\ncommand = [\"sh\", \"-c\", \"true\"]\n",
            "regulated_pure_pursuit",
        ),
        (
            "[[planner]]\nname = \"bspline\"\nkind = \"spiral\"\n",
            "bspline",
        ),
    ] {
        let path = dir.join("components.toml");
        std::fs::write(&path, text).expect("written");
        let e = forkbench_trial::scenario::load_components(&path, &registry)
            .expect_err(name)
            .to_string();
        assert!(
            e.contains(name) && e.contains("built-in") && e.contains("components.toml:"),
            "{e}"
        );
    }
    // A new name still loads.
    let path = dir.join("components.toml");
    std::fs::write(
        &path,
        "[[planner]]\nname = \"my_spiral\"\nkind = \"spiral\"\n",
    )
    .expect("written");
    let named = forkbench_trial::scenario::load_components(&path, &registry).expect("a new name");
    assert_eq!(named[0].name, "my_spiral");
    std::fs::remove_dir_all(&dir).ok();
}
