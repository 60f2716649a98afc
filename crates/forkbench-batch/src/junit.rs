//! JUnit XML (the schema GitLab, GitHub Actions and Jenkins read): one test case per result row.

use forkbench_trial::text::markup as escape;

use super::{GateReport, Provenance, Summary, Verdict};

/// One test case: a result row, failed with a message or passed.
#[derive(Debug, Clone, PartialEq)]
pub struct Case {
    pub name: String,
    pub classname: String,
    /// (short message, full text) of a failure.
    pub failure: Option<(String, String)>,
    /// The case's numbers, passing or not (its `<system-out>`).
    pub numbers: String,
}

/// A `<testsuites>` document with one suite of `cases`, and provenance as properties.
pub fn junit_xml(suite: &str, cases: &[Case], provenance: Option<&Provenance>) -> String {
    let failures = cases.iter().filter(|c| c.failure.is_some()).count();
    let mut x = String::from("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    x.push_str(&format!(
        "<testsuites name=\"forkbench\" tests=\"{}\" failures=\"{failures}\" errors=\"0\">\n",
        cases.len()
    ));
    let (host, stamp) = provenance.map_or((String::new(), String::new()), |p| {
        (
            format!(" hostname=\"{}\"", escape(&p.host)),
            format!(" timestamp=\"{}\"", escape(&p.finished_at)),
        )
    });
    x.push_str(&format!(
        "  <testsuite name=\"{}\" tests=\"{}\" failures=\"{failures}\" errors=\"0\" skipped=\"0\"{host}{stamp}>\n",
        escape(suite),
        cases.len()
    ));
    if let Some(p) = provenance {
        x.push_str("    <properties>\n");
        let props = [
            ("forkbench_version", p.forkbench_version.clone()),
            ("git_commit", p.git_commit.clone().unwrap_or_default()),
            ("seed", p.manifest.seed.to_string()),
            ("trials", p.manifest.trials.to_string()),
            ("cpu_model", p.cpu_model.clone()),
            ("jobs", p.jobs.to_string()),
        ];
        for (k, v) in props {
            x.push_str(&format!(
                "      <property name=\"{k}\" value=\"{}\"/>\n",
                escape(&v)
            ));
        }
        x.push_str("    </properties>\n");
    }
    for c in cases {
        let head = format!(
            "    <testcase name=\"{}\" classname=\"{}\"",
            escape(&c.name),
            escape(&c.classname)
        );
        let out = format!("      <system-out>{}</system-out>\n", escape(&c.numbers));
        match &c.failure {
            None => x.push_str(&format!("{head}>\n{out}    </testcase>\n")),
            Some((message, text)) => x.push_str(&format!(
                "{head}>\n      <failure type=\"forkbench.regression\" message=\"{}\">{}</failure>\n{out}    </testcase>\n",
                escape(message),
                escape(text)
            )),
        }
    }
    x.push_str("  </testsuite>\n</testsuites>\n");
    x
}

fn case_name(
    scenario: &str,
    planner: &str,
    tracker: &str,
    replan: Option<bool>,
) -> (String, String) {
    let mode = replan.map_or(String::new(), |m| {
        format!(" / {}", super::summary::mode_name(m))
    });
    (
        format!("{scenario} / {planner} / {tracker}{mode}"),
        format!("forkbench.{scenario}"),
    )
}

/// `regress` as JUnit: a case per row (baseline rows, then new ones), failing on a
/// significant drop after the correction, a rate below the floor, a missing row, too few
/// trials, or a new row with `--fail-on-new`; the numbers (adjusted p included) in the
/// message and, on every case, its output. A component gated `--as` a shipped one
/// (`mappings`) names its cases: `mypp (as pure_pursuit)`.
pub fn regress_cases(
    report: &GateReport,
    fail_on_new: bool,
    mappings: &[super::Mapping],
) -> Vec<Case> {
    let shown = |name: &str| {
        mappings
            .iter()
            .find(|m| m.to == name)
            .map_or(name.to_owned(), |m| format!("{} (as {name})", m.from))
    };
    report
        .rows
        .iter()
        .map(|r| {
            let (planner, tracker) = (shown(&r.planner), shown(&r.tracker));
            let (name, classname) = case_name(&r.scenario, &planner, &tracker, r.replan);
            let numbers = r.numbers(report);
            let what = match r.verdict {
                Verdict::Ok => None,
                Verdict::New if !fail_on_new => None,
                Verdict::New => Some("new row, not in the baseline (--fail-on-new)"),
                Verdict::Drop => Some("significant drop in fork-entry success"),
                Verdict::BelowFloor => Some("success rate below the floor"),
                Verdict::Missing => Some("row missing from the results"),
                Verdict::Underpowered => Some("too few trials for --min-detectable-drop"),
                Verdict::Worse => Some("a measure worse than the baseline beyond its margin"),
            };
            Case {
                name,
                classname,
                failure: what.map(|w| (format!("{w}: {numbers}"), numbers.clone())),
                numbers,
            }
        })
        .collect()
}

/// A batch as JUnit: a case per row, and per phase of a row's handling cycle, failing
/// when its success rate is below `floor` (every case passes without a floor, and
/// reports its rate).
pub fn batch_cases(summary: &Summary, floor: Option<f64>) -> Vec<Case> {
    let mut cases = Vec::new();
    for r in &summary.rows {
        let (name, classname) = case_name(&r.scenario, &r.planner, &r.tracker, Some(r.replan));
        let rate = (
            r.success_rate,
            r.successes,
            r.trials,
            r.ci95_low,
            r.ci95_high,
        );
        cases.push(rate_case(name.clone(), classname.clone(), rate, floor));
        for p in &r.phases {
            let rate = (p.success_rate, p.done, p.attempted, p.ci95_low, p.ci95_high);
            let name = format!("{name} / phase {}", p.name);
            cases.push(rate_case(name, classname.clone(), rate, floor));
        }
    }
    cases
}

/// A case reporting a success rate (rate, successes, trials, CI low, CI high), failing
/// below `floor`.
fn rate_case(
    name: String,
    classname: String,
    (rate, k, n, lo, hi): (f64, u64, u64, f64, f64),
    floor: Option<f64>,
) -> Case {
    let numbers = format!(
        "success {:.1} % ({k} of {n}, 95 % CI {:.1}–{:.1} %)",
        100.0 * rate,
        100.0 * lo,
        100.0 * hi
    );
    let failure = floor.filter(|f| rate < *f).map(|f| {
        (
            format!("{numbers} is below the floor {:.1} %", 100.0 * f),
            numbers.clone(),
        )
    });
    Case {
        name,
        classname,
        failure,
        numbers,
    }
}
