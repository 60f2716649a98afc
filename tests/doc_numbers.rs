//! The guide's numbers are tied to their commands: `tools/doc-numbers` passes a document whose marked number matches a fresh run, fails one changed by hand naming file, line, key, old and new value, rewrites it on request, and refuses a marker it cannot check.

use crate::common::{repo_root, s, text, tmp_in};
use std::path::Path;
use std::process::{Command, Output};

/// A numbers file with one cheap source: the field test without noise, its entry error.
const NUMBERS: &str = r#"
[source.field]
command = "{forkbench} trial scenarios/field-test.toml --no-noise --json"
exit = [0, 3]

[number."field.lateral_mm"]
source = "field"
value = "abs(j['lateral_error_m']) * 1000"

[number."field.sim_s"]
source = "field"
value = "j['sim_time_s']"
"#;

fn doc_numbers(numbers: &Path, doc: &Path, extra: &[&str]) -> Output {
    Command::new("python3")
        .arg(repo_root().join("tools/doc-numbers"))
        .args(["--forkbench", env!("CARGO_BIN_EXE_forkbench")])
        .args(["--numbers", s(numbers)])
        .args(extra)
        .arg(doc)
        .output()
        .expect("python3 runs tools/doc-numbers")
}

fn write_doc(doc: &Path, lateral: &str, sim: &str) {
    let body = format!(
        "# A page\n\nThe forks end {lateral}<!-- n:field.lateral_mm --> mm off the centre line,\n\
         after {sim}<!-- n:field.sim_s --> s.\n"
    );
    std::fs::write(doc, body).expect("doc written");
}

#[test]
fn a_number_changed_by_hand_fails_naming_it_and_rewrite_restores_it() {
    let numbers = tmp_in("doc-numbers", "numbers.toml");
    let doc = tmp_in("doc-numbers", "page.md");
    std::fs::write(&numbers, NUMBERS).expect("numbers written");
    // The true values, listed without a document of them being wrong.
    write_doc(&doc, "0.0", "0.00");
    let listed = text(&doc_numbers(&numbers, &doc, &["--list", "--rewrite"]));
    assert!(listed.contains("field.lateral_mm = "), "{listed}");
    let good = std::fs::read_to_string(&doc).expect("doc read");
    let o = doc_numbers(&numbers, &doc, &[]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    // Changed by hand: the check fails and names the file, line, key, old and new value.
    let fresh = good
        .split("end ")
        .nth(1)
        .and_then(|t| t.split('<').next())
        .expect("the rewritten number")
        .to_string();
    std::fs::write(&doc, good.replacen(&fresh, "99.9", 1)).expect("doc edited");
    let o = doc_numbers(&numbers, &doc, &[]);
    let out = text(&o);
    assert_eq!(o.status.code(), Some(1), "{out}");
    let want =
        format!("page.md:3: field.lateral_mm: the document says 99.9, a fresh run gives {fresh}");
    assert!(out.contains(&want), "wanted `{want}` in:\n{out}");
    assert!(!out.contains("field.sim_s: the document says"), "{out}");
    // Rewritten, the document is what it was and passes again.
    let o = doc_numbers(&numbers, &doc, &["--rewrite"]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    assert_eq!(std::fs::read_to_string(&doc).expect("doc read"), good);
    assert_eq!(doc_numbers(&numbers, &doc, &[]).status.code(), Some(0));
}

#[test]
fn a_marker_without_its_key_or_its_number_is_refused() {
    let numbers = tmp_in("doc-numbers-bad", "numbers.toml");
    let doc = tmp_in("doc-numbers-bad", "page.md");
    std::fs::write(&numbers, NUMBERS).expect("numbers written");
    std::fs::write(
        &doc,
        "12<!-- n:field.nowhere --> and a marker alone <!-- n:field.sim_s -->\n",
    )
    .expect("doc written");
    let o = doc_numbers(&numbers, &doc, &[]);
    let out = text(&o);
    assert_eq!(o.status.code(), Some(1), "{out}");
    assert!(
        out.contains("page.md:1: field.nowhere: no such key"),
        "{out}"
    );
    assert!(
        out.contains("page.md:1: field.sim_s: a marker with no number right before it"),
        "{out}"
    );
}

#[test]
fn every_marked_number_of_the_guide_has_its_key() {
    // The whole set is checked against fresh runs in CI (.ci/run); here, that every marker
    // names a key and every key is shown, without running the sources.
    let root = repo_root();
    let toml = std::fs::read_to_string(root.join("docs/numbers.toml")).expect("numbers.toml");
    let mut shown = 0;
    let mut docs = vec![root.join("README.md")];
    for e in std::fs::read_dir(root.join("docs")).expect("docs/") {
        let p = e.expect("entry").path();
        if p.extension().is_some_and(|x| x == "md") {
            docs.push(p);
        }
    }
    for doc in docs {
        let body = std::fs::read_to_string(&doc).expect("doc");
        for part in body.split("<!-- n:").skip(1) {
            let key = part.split(' ').next().expect("key");
            assert!(
                toml.contains(&format!("[number.\"{key}\"]")),
                "{}: {key} is not in docs/numbers.toml",
                doc.display()
            );
            shown += 1;
        }
    }
    assert!(shown >= 20, "only {shown} marked numbers");
}
