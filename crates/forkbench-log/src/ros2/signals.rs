//! The open signal vocabulary as ROS 2 messages: poses, grids, scalars and scans on topics of their own, shapes as markers, text on `/rosout`.

use forkbench_core::{Pose2, Signal, Style};

use super::msgs::{self, Marker, Shape};
use super::{MAP, Ros2Recorder};

/// A ROS 2 topic name for a signal's path under `prefix`: each token of letters, digits
/// and `_` only, none starting with a digit (`nav/route/0` → `/nav/route/_0`), no empty
/// token.
pub fn topic(prefix: &str, path: &str) -> String {
    let mut t = prefix.to_owned();
    for token in path.split('/').filter(|s| !s.is_empty()) {
        t.push('/');
        if token.starts_with(|c: char| c.is_ascii_digit()) {
            t.push('_');
        }
        t.extend(token.chars().map(|c| {
            if c.is_ascii_alphanumeric() || c == '_' {
                c
            } else {
                '_'
            }
        }));
    }
    if t.is_empty() { "/_".into() } else { t }
}

/// The outline's four edges of each box, as pairs of points.
fn box_edges(boxes: &[[[f64; 2]; 2]]) -> Vec<[f64; 2]> {
    let mut v = Vec::with_capacity(boxes.len() * 8);
    for [[x0, y0], [x1, y1]] in boxes {
        let c = [[*x0, *y0], [*x1, *y0], [*x1, *y1], [*x0, *y1]];
        for i in 0..4 {
            v.push(c[i]);
            v.push(c[(i + 1) % 4]);
        }
    }
    v
}

/// A marker of a shape signal in the map, named by its path.
fn shape_marker<'a>(path: &'a str, signal: &Signal<'_>, style: Style) -> Option<Marker<'a>> {
    let width = style.width_m.unwrap_or(0.03);
    let (shape, points, scale) = match signal {
        Signal::Path(p) => (Shape::LineStrip, p.to_vec(), [width, 0.0, 0.0]),
        Signal::Segments(s) => (
            Shape::LineList,
            s.iter().flat_map(|[a, b]| [*a, *b]).collect(),
            [width, 0.0, 0.0],
        ),
        Signal::Points(p) => {
            let size = style.width_m.unwrap_or(0.06);
            (Shape::Points, p.to_vec(), [size, size, 0.0])
        }
        Signal::Boxes(b) => (Shape::LineList, box_edges(b), [width, 0.0, 0.0]),
        _ => return None,
    };
    Some(Marker {
        frame: MAP,
        ns: path,
        id: 0,
        shape,
        pose: Pose2::new(0.0, 0.0, 0.0),
        scale,
        rgba: style.rgba.unwrap_or([40, 120, 220, 255]),
        frame_locked: false,
        points,
    })
}

impl Ros2Recorder {
    /// Writes one signal as its kind's message.
    pub(super) fn write_signal(&mut self, t_s: f64, path: &str, signal: &Signal<'_>, style: Style) {
        match signal {
            Signal::Scan(scan) => {
                let name = path.rsplit('/').next().unwrap_or(path);
                let frame = topic("scanner", name).replace('/', "_");
                let tf = msgs::tf(t_s, MAP, &[(&frame, scan.sensor)]);
                self.write("/tf", &msgs::TF_MSG, t_s, &tf);
                let msg = msgs::laser_scan(t_s, &frame, scan);
                self.write(&topic("/scan", path), &msgs::LASER_SCAN_MSG, t_s, &msg);
            }
            Signal::Pose(p) => {
                let msg = msgs::pose_stamped(t_s, MAP, p);
                self.write(&topic("/pose", path), &msgs::POSE_STAMPED_MSG, t_s, &msg);
            }
            Signal::Grid(g) => {
                let msg = msgs::occupancy_grid(t_s, MAP, g);
                self.write(&topic("/grid", path), &msgs::OCCUPANCY_GRID_MSG, t_s, &msg);
            }
            Signal::Scalar(v) => {
                let msg = msgs::float64(*v);
                self.write(&topic("/signals", path), &msgs::FLOAT64_MSG, t_s, &msg);
            }
            Signal::Text(text) => {
                let msg = msgs::log(t_s, 20, path, text);
                self.write("/rosout", &msgs::LOG_MSG, t_s, &msg);
            }
            shape => {
                if let Some(m) = shape_marker(path, shape, style) {
                    let msg = msgs::marker_array(t_s, &[m]);
                    self.write("/markers", &msgs::MARKER_ARRAY_MSG, t_s, &msg);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::topic;

    #[test]
    fn topics_are_valid_ros2_names() {
        assert_eq!(topic("/grid", "nav/route/0"), "/grid/nav/route/_0");
        assert_eq!(topic("/signals", "a b//c-d"), "/signals/a_b/c_d");
        assert_eq!(topic("/scan", "sensors/tim561"), "/scan/sensors/tim561");
        assert_eq!(topic("", ""), "/_");
    }
}
