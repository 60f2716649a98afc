//! How a safety scan is recorded: the fields in force, drawn in the map and coloured by the function's state.

use forkbench_core::{Pose2, Signal, Style};
use forkbench_safety::{Fields, Reading};

use crate::recorder::Recorder;

pub(super) const CLEAR: Style = Style::rgba([60, 200, 90, 255]).width(0.03);
pub(super) const WARNED: Style = Style::rgba([250, 200, 40, 255]).width(0.03);
pub(super) const STOPPED: Style = Style::rgba([240, 50, 50, 255]).width(0.05);

/// A map point in the fork-root frame.
pub(super) fn local(root: &Pose2, p: [f64; 2]) -> [f64; 2] {
    let q = root.to_local(&Pose2::new(p[0], p[1], 0.0));
    [q.x_m, q.y_m]
}

pub(super) fn record_reading<R: Recorder + ?Sized>(
    rec: &mut R,
    t: f64,
    root: &Pose2,
    set: &Fields,
    r: &Reading,
    stopped: bool,
) {
    let world = |poly: &[[f64; 2]]| -> Vec<[f64; 2]> {
        poly.iter()
            .chain(poly.first())
            .map(|p| {
                let q = root.to_world(&Pose2::new(p[0], p[1], 0.0));
                [q.x_m, q.y_m]
            })
            .collect()
    };
    let style = if r.protective || stopped {
        STOPPED
    } else if r.warning {
        WARNED
    } else {
        CLEAR
    };
    for (name, polys, style) in [
        ("protective", &set.protective, style),
        ("warning", &set.warning, WARNED),
    ] {
        for (i, poly) in polys.iter().enumerate() {
            let path = format!("safety/{name}_field/{i}");
            rec.signal(t, &path, &Signal::Path(&world(poly)), style);
        }
    }
}
