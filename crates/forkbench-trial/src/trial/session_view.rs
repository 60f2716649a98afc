//! What a session shows of its world when asked (the truth, the estimate, the plan, the last scans), for drawing an episode.

use forkbench_core::{Pose2, Signal, Style};

use crate::recorder::Recorder;

/// A snapshot of the world a session's trial stands in, in map coordinates.
#[derive(Debug, Clone, PartialEq)]
pub struct SceneView {
    /// The true fork-root pose.
    pub fork_root: Pose2,
    /// The true pallet face pose.
    pub pallet: Pose2,
    /// The pallet face pose the plan aims at.
    pub pallet_estimate: Pose2,
    /// The path the truck follows (fork root).
    pub path: Vec<[f64; 2]>,
    /// Racks and walls as closed outlines.
    pub obstacles: Vec<[[f64; 2]; 5]>,
    /// The returns of the last scans of each scanner, as map points.
    pub scan: Vec<[f64; 2]>,
}

/// Keeps the returns of the latest scan of each scanner, for [`SceneView::scan`].
#[derive(Debug, Default)]
pub(crate) struct ScanKeeper {
    /// Per scanner path: its last returns.
    last: Vec<(String, Vec<[f64; 2]>)>,
}

impl Recorder for ScanKeeper {
    fn signal(&mut self, _t_s: f64, path: &str, signal: &Signal<'_>, _style: Style) {
        let Signal::Scan(scan) = signal else {
            return;
        };
        let points = scan.points();
        match self.last.iter_mut().find(|(p, _)| p == path) {
            Some((_, v)) => *v = points,
            None => self.last.push((path.to_owned(), points)),
        }
    }
}

impl ScanKeeper {
    /// The returns of every scanner's last scan, as map points.
    pub(crate) fn points(&self) -> Vec<[f64; 2]> {
        self.last
            .iter()
            .flat_map(|(_, v)| v.iter().copied())
            .collect()
    }
}
