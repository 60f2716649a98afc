//! Records the git commit forkbench is built from (when built from a checkout), and whether the sources differ from it, for batch provenance.

use std::fs::File;
use std::io::Read;
use std::path::Path;
use std::process::Command;

/// What the trials' outcomes are built from, relative to the checkout's top.
const SOURCES: &[&str] = &["crates", "scenarios", "Cargo.toml", "Cargo.lock"];

fn git_bytes(dir: Option<&str>, args: &[&str]) -> Option<Vec<u8>> {
    let mut cmd = Command::new("git");
    if let Some(d) = dir {
        cmd.current_dir(d);
    }
    let out = cmd.args(args).output().ok()?;
    out.status.success().then_some(out.stdout)
}

fn git(args: &[&str]) -> Option<String> {
    let out = git_bytes(None, args)?;
    Some(String::from_utf8_lossy(&out).trim().to_owned()).filter(|s| !s.is_empty())
}

/// Cargo treats a watched path that does not exist as changed on every build, so only
/// existing paths are watched (a clone without `packed-refs` is common).
fn watch(path: &str) {
    if Path::new(path).exists() {
        println!("cargo:rerun-if-changed={path}");
    }
}

/// FNV-1a, 64-bit: a stable fingerprint without a dependency.
struct Fnv(u64);

impl Fnv {
    fn feed(&mut self, bytes: &[u8]) {
        for b in bytes {
            self.0 ^= u64::from(*b);
            self.0 = self.0.wrapping_mul(0x0100_0000_01b3);
        }
    }
}

/// A fingerprint of how the checkout's sources at `top` differ from its commit (the diff
/// of tracked files, and each untracked file's path and content), or `None` when they
/// do not.
fn changes(top: &str) -> Option<String> {
    let mut status_args = vec![
        "status",
        "--porcelain=v1",
        "-z",
        "--untracked-files=all",
        "--",
    ];
    status_args.extend(SOURCES);
    let status = git_bytes(Some(top), &status_args)?;
    if status.is_empty() {
        return None;
    }
    let mut h = Fnv(0xcbf2_9ce4_8422_2325);
    let mut diff_args = vec!["diff", "HEAD", "--binary", "--"];
    diff_args.extend(SOURCES);
    h.feed(&git_bytes(Some(top), &diff_args).unwrap_or_default());
    for entry in status.split(|b| *b == 0) {
        let Some(path) = entry.strip_prefix(b"?? ") else {
            continue;
        };
        h.feed(path);
        let path = String::from_utf8_lossy(path);
        if let Ok(mut f) = File::open(Path::new(top).join(path.as_ref())) {
            let mut buf = [0u8; 64 * 1024];
            while let Ok(n @ 1..) = f.read(&mut buf) {
                h.feed(&buf[..n]);
            }
        }
    }
    Some(format!("{:016x}", h.0))
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
    // And when a source changes, so a build from edited sources is told apart from the
    // commit's own.
    let dirty = match git(&["rev-parse", "--show-toplevel"]) {
        Some(top) if !commit.is_empty() => {
            for s in SOURCES {
                watch(&format!("{top}/{s}"));
            }
            changes(&top)
        }
        _ => None,
    };
    println!("cargo:rustc-env=FORKBENCH_GIT_COMMIT={commit}");
    println!(
        "cargo:rustc-env=FORKBENCH_GIT_CHANGES={}",
        dirty.unwrap_or_default()
    );
}
