//! What the end-to-end test modules share: the binary run with arguments, a temporary path of a test's own, a path as an argument, the repository's root.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The `forkbench` binary run with `args` to completion.
pub fn forkbench(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_forkbench"))
        .args(args)
        .output()
        .expect("binary runs")
}

/// `name` in the folder `<temp>/<folder>-<pid>`, made if absent.
pub fn tmp_in(folder: &str, name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("{folder}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    dir.join(name)
}

/// A path as a command-line argument.
pub fn s(p: &Path) -> &str {
    p.to_str().expect("utf-8")
}

/// The repository's root (scenarios/, worlds/).
pub fn repo_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// What a run printed, stdout then stderr.
pub fn text(o: &Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

/// The field test without noise recorded as a forkbench MCAP at `mcap` (replacing one
/// there): scans for `detect` to read.
pub fn record_field_mcap(mcap: &Path) {
    let field = repo_root().join("scenarios/field-test.toml");
    let o = forkbench(&[
        "trial",
        s(&field),
        "--no-noise",
        "--mcap",
        s(mcap),
        "--force",
    ]);
    assert!(matches!(o.status.code(), Some(0 | 3)), "{}", text(&o));
}

/// The names in folder `dir`, sorted.
pub fn names_in(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

/// What a run that asks for an .rrd says: `with` in a build with rerun (`--features
/// rerun`), and the refusal naming the feature in the default build, which leaves rerun out.
pub fn rrd_says(with: &str) -> &str {
    if cfg!(feature = "rerun") {
        with
    } else {
        "needs rerun, which this build of forkbench leaves out"
    }
}
