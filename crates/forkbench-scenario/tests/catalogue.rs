//! The format loads without the engine: a catalogue that only knows names checks a scenario's components and phases, and its refusals reach the user at the file's line.

use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

use forkbench_core::SettingsError;
use forkbench_scenario::{
    Catalogue, ComponentSpec, Context, PhaseSpec, Role, Scenario, ScenarioError, World,
};

/// Knows components by role and name only; remembers what it was asked.
#[derive(Debug, Default)]
struct Names {
    asked: Mutex<Vec<String>>,
}

const KNOWN: &[(Role, &str)] = &[
    (Role::Planner, "bspline"),
    (Role::Tracker, "pure_pursuit"),
    (Role::Detector, "pockets"),
    (Role::Localizer, "gaussian"),
    (Role::Localizer, "nav350"),
];

impl Names {
    fn note(&self, what: String) {
        self.asked.lock().expect("not poisoned").push(what);
    }
}

impl Catalogue for Names {
    /// A phase is its name and the slot or station it was checked against.
    type Phase = String;

    fn builtin() -> Arc<Self> {
        Arc::new(Names::default())
    }

    fn check(&self, spec: &ComponentSpec) -> Result<(), SettingsError> {
        self.note(format!("{} {}", spec.role, spec.kind));
        if !KNOWN.contains(&(spec.role, spec.kind.as_str())) {
            return Err(SettingsError::field(
                "kind",
                format!("no {} {:?}", spec.role, spec.kind),
            ));
        }
        match spec
            .settings
            .get("lookahead_m")
            .and_then(toml::Value::as_float)
        {
            Some(v) if v > 5.0 => Err(SettingsError::field("lookahead_m", "at most 5")),
            _ => Ok(()),
        }
    }

    fn check_localizer(
        &self,
        spec: &ComponentSpec,
        scn: &Scenario<Self>,
    ) -> Result<(), SettingsError> {
        self.note(format!(
            "localizer {} with {} reflectors",
            spec.kind,
            scn.world.reflector.len()
        ));
        self.check(spec)
    }

    fn detector_takes_pocket_settings(&self, kind: &str) -> bool {
        kind == "pockets"
    }

    fn localizer_measures_reflectors(&self, kind: &str) -> bool {
        kind == "nav350"
    }

    fn phases(
        &self,
        names: &[String],
        settings: &toml::Table,
        cx: &dyn Context,
    ) -> Result<Vec<PhaseSpec<String>>, (String, String)> {
        self.note(format!("phases {}", names.join(" ")));
        let mut out = Vec::new();
        for name in &names[1..] {
            let table = settings
                .get(name)
                .and_then(toml::Value::as_table)
                .cloned()
                .unwrap_or_default();
            let place = table
                .get("slot")
                .or_else(|| table.get("to"))
                .and_then(toml::Value::as_str)
                .map(str::to_owned);
            if let Some(p) = place.as_deref()
                && cx.slot_pose(p).is_none()
                && cx.station_pose(p).is_none()
            {
                return Err((format!("phase.{name}"), format!("no slot or station {p:?}")));
            }
            out.push(PhaseSpec {
                name: name.clone(),
                settings: table,
                phase: format!("{name}@{}", place.as_deref().unwrap_or("-")),
            });
        }
        Ok(out)
    }
}

fn repo(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .join(rel)
}

fn cycle_text() -> String {
    std::fs::read_to_string(repo("scenarios/warehouse-cycle.toml")).expect("reads the cycle")
}

fn parse(text: &str, names: Arc<Names>) -> Result<Scenario<Names>, ScenarioError> {
    let dir = repo("scenarios");
    Scenario::parse_with(text, "cycle.toml", |p| World::load(&dir.join(p)), names)
}

#[test]
fn a_shipped_cycle_loads_against_a_catalogue_of_names() {
    let names = Arc::new(Names::default());
    let scn = Scenario::load_with(&repo("scenarios/warehouse-cycle.toml"), Arc::clone(&names))
        .expect("loads");
    let phases: Vec<_> = scn.phases.iter().map(|p| p.phase.as_str()).collect();
    assert_eq!(
        phases,
        [
            "lift@-",
            "reverse_out@-",
            "carry@-",
            "place@sorting-drop",
            "return@charging"
        ]
    );
    assert_eq!(
        (scn.planner.kind.as_str(), scn.tracker.kind.as_str()),
        ("bspline", "pure_pursuit")
    );
    assert_eq!(scn.localizer.kind, "nav350");
    let asked = names.asked.lock().expect("not poisoned").clone();
    assert!(asked.contains(&"planner bspline".to_owned()), "{asked:?}");
    assert!(asked.contains(&"detector pockets".to_owned()), "{asked:?}");
    let reflectors = scn.world.reflector.len();
    assert!(reflectors > 0, "the warehouse has reflectors");
    assert!(
        asked.contains(&format!("localizer nav350 with {reflectors} reflectors")),
        "{asked:?}"
    );
    assert!(asked.contains(&"phases pick lift reverse_out carry place return".to_owned()));
}

/// The cycle's error with `from` written as `to`.
fn refusal(from: &str, to: &str) -> String {
    let text = cycle_text().replace(from, to);
    assert_ne!(text, cycle_text(), "{from} is in the cycle");
    parse(&text, Arc::new(Names::default()))
        .expect_err("refused")
        .to_string()
}

#[test]
fn what_the_catalogue_refuses_is_named_at_its_line() {
    assert_eq!(
        refusal("planner = \"bspline\"", "planner = \"nope\""),
        "cycle.toml:10: field `planner.kind`: no planner \"nope\""
    );
    assert_eq!(
        refusal("lookahead_m = 0.7", "lookahead_m = 7.0"),
        "cycle.toml:36: field `tracker.lookahead_m`: at most 5"
    );
    assert_eq!(
        refusal("slot = \"sorting-drop\"", "slot = \"nowhere\""),
        "cycle.toml:26: field `phase.place`: no slot or station \"nowhere\""
    );
}

#[test]
fn a_run_may_name_only_what_the_catalogue_knows() {
    let scn = parse(&cycle_text(), Arc::new(Names::default())).expect("loads");
    assert_eq!(
        scn.component(Role::Planner, Some("bspline"))
            .expect("own")
            .kind,
        "bspline"
    );
    let e = scn
        .component(Role::Planner, Some("spiral"))
        .expect_err("unknown")
        .to_string();
    assert!(
        e.contains("\"spiral\" is neither this scenario's planner"),
        "{e}"
    );
    // The catalogue says the NAV350 measures reflectors, so a run may take one away.
    let fewer = scn
        .with_missing_reflectors(&["west-3".to_owned()])
        .expect("nav350");
    let missing = fewer.localizer.settings.get("missing_reflectors");
    assert_eq!(
        missing.map(ToString::to_string).as_deref(),
        Some("[\"west-3\"]")
    );
    let gaussian = parse(
        &cycle_text().replace("kind = \"nav350\"", "kind = \"gaussian\""),
        Arc::new(Names::default()),
    )
    .expect("loads");
    let e = gaussian
        .with_missing_reflectors(&["west-3".to_owned()])
        .expect_err("refused")
        .to_string();
    assert!(
        e.contains("only the nav350 localiser measures reflectors"),
        "{e}"
    );
}
