//! A child's whole process tree, found through `/proc` by parent links: a descendant that left its process group (`setsid`) or was orphaned to forkbench is still found and killed.

use std::collections::BTreeMap;
use std::sync::atomic::{AtomicBool, Ordering};

use nix::sys::signal::{Signal, kill};
use nix::sys::wait::{WaitPidFlag, waitpid};
use nix::unistd::Pid;

/// Whether this process adopts its children's orphans (set by [`adopt_orphans`]).
static ADOPTING: AtomicBool = AtomicBool::new(false);

/// Makes this process the reaper of its descendants' orphans (Linux's child subreaper), so
/// a child's daemonised grandchild is reparented here, not to init, and `kill_orphans`
/// can find it. For a program whose every child is an external component (the CLI), not
/// for a host process (Python) that has children of its own.
pub fn adopt_orphans() {
    if nix::sys::prctl::set_child_subreaper(true).is_ok() {
        ADOPTING.store(true, Ordering::SeqCst);
    }
}

/// Every process whose chain of parents leads to `root` (not `root` itself).
pub(crate) fn descendants(root: i32) -> Vec<i32> {
    let children = children_by_parent();
    let mut out = Vec::new();
    let mut todo = vec![root];
    while let Some(p) = todo.pop() {
        if let Some(kids) = children.get(&p) {
            for &k in kids {
                // A pid cannot be its own ancestor; the guard only bounds a racing table.
                if !out.contains(&k) && k != root {
                    out.push(k);
                    todo.push(k);
                }
            }
        }
    }
    out
}

/// SIGKILLs every descendant of `root`.
pub(crate) fn kill_descendants(root: i32) {
    for p in descendants(root) {
        let _ = kill(Pid::from_raw(p), Signal::SIGKILL);
    }
}

/// When this process adopts orphans: kills every descendant it still has and reaps them.
/// Call only when exiting, after the tracked children are gone.
pub(crate) fn kill_orphans() {
    if !ADOPTING.load(Ordering::SeqCst) {
        return;
    }
    let me = i32::try_from(std::process::id()).unwrap_or(i32::MAX);
    let all = descendants(me);
    for &p in &all {
        let _ = kill(Pid::from_raw(p), Signal::SIGKILL);
    }
    let direct: Vec<i32> = children_by_parent().remove(&me).unwrap_or_default();
    for p in direct {
        // Killed above; a short bounded wait reaps it so it does not stay a zombie.
        for _ in 0..50 {
            match waitpid(Pid::from_raw(p), Some(WaitPidFlag::WNOHANG)) {
                Ok(nix::sys::wait::WaitStatus::StillAlive) => {
                    std::thread::sleep(std::time::Duration::from_millis(2));
                }
                _ => break,
            }
        }
    }
}

/// Parent pid → child pids, from `/proc/<pid>/stat` (empty where `/proc` is absent).
fn children_by_parent() -> BTreeMap<i32, Vec<i32>> {
    let mut map: BTreeMap<i32, Vec<i32>> = BTreeMap::new();
    let Ok(dir) = std::fs::read_dir("/proc") else {
        return map;
    };
    for entry in dir.flatten() {
        let Some(pid) = entry
            .file_name()
            .to_str()
            .and_then(|s| s.parse::<i32>().ok())
        else {
            continue;
        };
        if let Some(ppid) = parent_of(pid) {
            map.entry(ppid).or_default().push(pid);
        }
    }
    map
}

/// A process's parent pid: the second field after the command name, which is in
/// parentheses and may itself hold spaces and parentheses.
fn parent_of(pid: i32) -> Option<i32> {
    let stat = std::fs::read_to_string(format!("/proc/{pid}/stat")).ok()?;
    let rest = &stat[stat.rfind(')')? + 1..];
    rest.split_whitespace().nth(1)?.parse().ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_a_grandchild_that_left_the_group() {
        let mut sh = std::process::Command::new("sh")
            .args(["-c", "setsid sleep 30 & wait"])
            .spawn()
            .expect("sh");
        let root = i32::try_from(sh.id()).expect("pid");
        let t0 = std::time::Instant::now();
        let mut found = Vec::new();
        while t0.elapsed() < std::time::Duration::from_secs(5) {
            found = descendants(root);
            if !found.is_empty() {
                break;
            }
            std::thread::sleep(std::time::Duration::from_millis(20));
        }
        assert!(!found.is_empty(), "the setsid child was not found");
        kill_descendants(root);
        let _ = sh.wait();
        assert!(descendants(root).is_empty());
    }
}
