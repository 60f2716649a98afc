//! Records the git commit forkbench is built from (when built from a checkout) for batch provenance.

use std::path::Path;
use std::process::Command;

fn git(args: &[&str]) -> Option<String> {
    let out = Command::new("git").args(args).output().ok()?;
    out.status
        .success()
        .then(|| String::from_utf8_lossy(&out.stdout).trim().to_owned())
        .filter(|s| !s.is_empty())
}

/// Cargo treats a watched path that does not exist as changed on every build, so only
/// existing paths are watched (a clone without `packed-refs` is common).
fn watch(path: &str) {
    if Path::new(path).exists() {
        println!("cargo:rerun-if-changed={path}");
    }
}

fn main() {
    // Without any rerun-if-changed line cargo would re-run this on every source change.
    println!("cargo:rerun-if-changed=build.rs");
    // Re-run when HEAD moves: HEAD itself, packed refs, and the folder that holds the
    // branch's loose ref (a directory is scanned, so a ref written there later counts).
    for what in ["HEAD", "packed-refs"] {
        if let Some(p) = git(&["rev-parse", "--git-path", what]) {
            watch(&p);
        }
    }
    if let Some(r) = git(&["symbolic-ref", "-q", "HEAD"])
        && let Some(p) = git(&["rev-parse", "--git-path", &r])
    {
        watch(&p);
        if let Some(dir) = Path::new(&p).parent().and_then(Path::to_str) {
            watch(dir);
        }
    }
    let commit = git(&["rev-parse", "HEAD"]).unwrap_or_default();
    println!("cargo:rustc-env=FORKBENCH_GIT_COMMIT={commit}");
}
