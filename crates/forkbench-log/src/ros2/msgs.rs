//! The ROS 2 messages forkbench records: their `ros2msg` definitions (as rosbag2 stores them, dependencies after `MSG:` separators) and their CDR encoders.

use forkbench_core::Pose2;
use forkbench_core::signal::Scan;

use super::cdr::CdrWriter;
use crate::mcap_sink::SIM_EPOCH_UNIX_S;

const TIME: &str = "int32 sec\nuint32 nanosec\n";
const HEADER: &str = "builtin_interfaces/Time stamp\nstring frame_id\n";
const POINT: &str = "float64 x\nfloat64 y\nfloat64 z\n";
const QUATERNION: &str = "float64 x\nfloat64 y\nfloat64 z\nfloat64 w\n";
const POSE: &str = "Point position\nQuaternion orientation\n";
const POSE_STAMPED: &str = "std_msgs/Header header\nPose pose\n";
const TRANSFORM: &str = "Vector3 translation\nQuaternion rotation\n";
const TRANSFORM_STAMPED: &str =
    "std_msgs/Header header\nstring child_frame_id\nTransform transform\n";
const LASER_SCAN: &str = "std_msgs/Header header\nfloat32 angle_min\nfloat32 angle_max\n\
float32 angle_increment\nfloat32 time_increment\nfloat32 scan_time\nfloat32 range_min\n\
float32 range_max\nfloat32[] ranges\nfloat32[] intensities\n";
const COLOR: &str = "float32 r\nfloat32 g\nfloat32 b\nfloat32 a\n";
const DURATION: &str = "int32 sec\nuint32 nanosec\n";
const COMPRESSED_IMAGE: &str = "std_msgs/Header header\nstring format\nuint8[] data\n";
const UV: &str = "float32 u\nfloat32 v\n";
const MESH_FILE: &str = "string filename\nuint8[] data\n";
const MARKER: &str = "int32 ARROW=0\nint32 CUBE=1\nint32 SPHERE=2\nint32 CYLINDER=3\n\
int32 LINE_STRIP=4\nint32 LINE_LIST=5\nint32 CUBE_LIST=6\nint32 SPHERE_LIST=7\nint32 POINTS=8\n\
int32 TEXT_VIEW_FACING=9\nint32 MESH_RESOURCE=10\nint32 TRIANGLE_LIST=11\nint32 ADD=0\n\
int32 MODIFY=0\nint32 DELETE=2\nint32 DELETEALL=3\nstd_msgs/Header header\nstring ns\nint32 id\n\
int32 type\nint32 action\ngeometry_msgs/Pose pose\ngeometry_msgs/Vector3 scale\n\
std_msgs/ColorRGBA color\nbuiltin_interfaces/Duration lifetime\nbool frame_locked\n\
geometry_msgs/Point[] points\nstd_msgs/ColorRGBA[] colors\nstring texture_resource\n\
sensor_msgs/CompressedImage texture\nvisualization_msgs/UVCoordinate[] uv_coordinates\n\
string text\nstring mesh_resource\nvisualization_msgs/MeshFile mesh_file\n\
bool mesh_use_embedded_materials\n";
const MAP_META: &str = "builtin_interfaces/Time map_load_time\nfloat32 resolution\n\
uint32 width\nuint32 height\ngeometry_msgs/Pose origin\n";
const LOG: &str = "byte DEBUG=10\nbyte INFO=20\nbyte WARN=30\nbyte ERROR=40\nbyte FATAL=50\n\
builtin_interfaces/Time stamp\nuint8 level\nstring name\nstring msg\nstring file\n\
string function\nuint32 line\n";

/// A message type: its name and its full definition with every dependency.
#[derive(Debug)]
pub struct MsgType {
    pub name: &'static str,
    parts: &'static [(&'static str, &'static str)],
}

impl MsgType {
    /// The `ros2msg` schema text: the message's own definition, then each dependency
    /// after a line of 80 `=` and `MSG: package/Type`.
    pub fn definition(&self) -> String {
        let mut s = String::new();
        for (i, (name, text)) in self.parts.iter().enumerate() {
            if i > 0 {
                s.push_str(&"=".repeat(80));
                s.push_str(&format!("\nMSG: {name}\n"));
            }
            s.push_str(text);
        }
        s
    }
}

pub const LASER_SCAN_MSG: MsgType = MsgType {
    name: "sensor_msgs/msg/LaserScan",
    parts: &[
        ("sensor_msgs/LaserScan", LASER_SCAN),
        ("std_msgs/Header", HEADER),
        ("builtin_interfaces/Time", TIME),
    ],
};

pub const TF_MSG: MsgType = MsgType {
    name: "tf2_msgs/msg/TFMessage",
    parts: &[
        (
            "tf2_msgs/TFMessage",
            "geometry_msgs/TransformStamped[] transforms\n",
        ),
        ("geometry_msgs/TransformStamped", TRANSFORM_STAMPED),
        ("std_msgs/Header", HEADER),
        ("builtin_interfaces/Time", TIME),
        ("geometry_msgs/Transform", TRANSFORM),
        ("geometry_msgs/Vector3", POINT),
        ("geometry_msgs/Quaternion", QUATERNION),
    ],
};

pub const POSE_STAMPED_MSG: MsgType = MsgType {
    name: "geometry_msgs/msg/PoseStamped",
    parts: &[
        ("geometry_msgs/PoseStamped", POSE_STAMPED),
        ("std_msgs/Header", HEADER),
        ("builtin_interfaces/Time", TIME),
        ("geometry_msgs/Pose", POSE),
        ("geometry_msgs/Point", POINT),
        ("geometry_msgs/Quaternion", QUATERNION),
    ],
};

pub const PATH_MSG: MsgType = MsgType {
    name: "nav_msgs/msg/Path",
    parts: &[
        (
            "nav_msgs/Path",
            "std_msgs/Header header\ngeometry_msgs/PoseStamped[] poses\n",
        ),
        ("std_msgs/Header", HEADER),
        ("builtin_interfaces/Time", TIME),
        ("geometry_msgs/PoseStamped", POSE_STAMPED),
        ("geometry_msgs/Pose", POSE),
        ("geometry_msgs/Point", POINT),
        ("geometry_msgs/Quaternion", QUATERNION),
    ],
};

pub const STRING_MSG: MsgType = MsgType {
    name: "std_msgs/msg/String",
    parts: &[("std_msgs/String", "string data\n")],
};

pub const LOG_MSG: MsgType = MsgType {
    name: "rcl_interfaces/msg/Log",
    parts: &[
        ("rcl_interfaces/Log", LOG),
        ("builtin_interfaces/Time", TIME),
    ],
};

pub const MARKER_ARRAY_MSG: MsgType = MsgType {
    name: "visualization_msgs/msg/MarkerArray",
    parts: &[
        (
            "visualization_msgs/MarkerArray",
            "visualization_msgs/Marker[] markers\n",
        ),
        ("visualization_msgs/Marker", MARKER),
        ("std_msgs/Header", HEADER),
        ("builtin_interfaces/Time", TIME),
        ("geometry_msgs/Pose", POSE),
        ("geometry_msgs/Point", POINT),
        ("geometry_msgs/Quaternion", QUATERNION),
        ("geometry_msgs/Vector3", POINT),
        ("std_msgs/ColorRGBA", COLOR),
        ("builtin_interfaces/Duration", DURATION),
        ("sensor_msgs/CompressedImage", COMPRESSED_IMAGE),
        ("visualization_msgs/UVCoordinate", UV),
        ("visualization_msgs/MeshFile", MESH_FILE),
    ],
};

pub const OCCUPANCY_GRID_MSG: MsgType = MsgType {
    name: "nav_msgs/msg/OccupancyGrid",
    parts: &[
        (
            "nav_msgs/OccupancyGrid",
            "std_msgs/Header header\nnav_msgs/MapMetaData info\nint8[] data\n",
        ),
        ("std_msgs/Header", HEADER),
        ("builtin_interfaces/Time", TIME),
        ("nav_msgs/MapMetaData", MAP_META),
        ("geometry_msgs/Pose", POSE),
        ("geometry_msgs/Point", POINT),
        ("geometry_msgs/Quaternion", QUATERNION),
    ],
};

const ACKERMANN_DRIVE: &str = "float32 steering_angle\nfloat32 steering_angle_velocity\n\
float32 speed\nfloat32 acceleration\nfloat32 jerk\n";
const ACKERMANN_DRIVE_STAMPED: &str = "std_msgs/Header header\nAckermannDrive drive\n";

pub const ACKERMANN_MSG: MsgType = MsgType {
    name: "ackermann_msgs/msg/AckermannDriveStamped",
    parts: &[
        (
            "ackermann_msgs/AckermannDriveStamped",
            ACKERMANN_DRIVE_STAMPED,
        ),
        ("std_msgs/Header", HEADER),
        ("builtin_interfaces/Time", TIME),
        ("ackermann_msgs/AckermannDrive", ACKERMANN_DRIVE),
    ],
};

/// A steering angle and speed (commanded or measured) at `t_s`, the rest of the drive
/// message left 0.
pub fn ackermann(t_s: f64, frame: &str, steer_rad: f64, speed_mps: f64) -> Vec<u8> {
    let mut w = CdrWriter::new();
    header(&mut w, t_s, frame);
    for v in [steer_rad, 0.0, speed_mps, 0.0, 0.0] {
        w.f32(v as f32);
    }
    w.into_bytes()
}

pub const FLOAT64_MSG: MsgType = MsgType {
    name: "std_msgs/msg/Float64",
    parts: &[("std_msgs/Float64", "float64 data\n")],
};

/// Nanoseconds since the Unix epoch of simulated time `t_s`: from the same fixed epoch as
/// the Foxglove MCAP ([`SIM_EPOCH_UNIX_S`]), so the two files of a trial line up.
pub fn unix_ns(t_s: f64) -> u64 {
    SIM_EPOCH_UNIX_S * 1_000_000_000 + (t_s.max(0.0) * 1e9).round() as u64
}

/// Simulation time as `builtin_interfaces/Time`.
fn time(w: &mut CdrWriter, t_s: f64) {
    let ns = unix_ns(t_s);
    w.i32(i32::try_from(ns / 1_000_000_000).unwrap_or(i32::MAX));
    w.u32((ns % 1_000_000_000) as u32);
}

fn header(w: &mut CdrWriter, t_s: f64, frame: &str) {
    time(w, t_s);
    w.string(frame);
}

/// A planar pose as position and a yaw quaternion.
fn pose(w: &mut CdrWriter, p: &Pose2) {
    let (s, c) = (p.heading_rad / 2.0).sin_cos();
    for v in [p.x_m, p.y_m, 0.0, 0.0, 0.0, s, c] {
        w.f64(v);
    }
}

/// A scan in its sensor's frame (`frame`): beams without a return are +∞ (REP 117).
pub fn laser_scan(t_s: f64, frame: &str, scan: &Scan) -> Vec<u8> {
    let mut w = CdrWriter::new();
    header(&mut w, t_s, frame);
    let n = scan.ranges_m.len();
    let last = scan.angle_min_rad + scan.angle_step_rad * n.saturating_sub(1) as f64;
    for v in [
        scan.angle_min_rad,
        last,
        scan.angle_step_rad,
        // A simulated scan is taken at one instant.
        0.0,
        0.0,
        scan.range_min_m,
        scan.range_max_m,
    ] {
        w.f32(v as f32);
    }
    let ranges: Vec<f32> = scan
        .ranges_m
        .iter()
        .map(|r| {
            if r.is_finite() {
                *r as f32
            } else {
                f32::INFINITY
            }
        })
        .collect();
    w.f32_seq(&ranges);
    w.f32_seq(&[]);
    w.into_bytes()
}

/// Transforms from `parent` to each `(child, pose)`.
pub fn tf(t_s: f64, parent: &str, children: &[(&str, Pose2)]) -> Vec<u8> {
    let mut w = CdrWriter::new();
    w.len(children.len());
    for (child, p) in children {
        header(&mut w, t_s, parent);
        w.string(child);
        pose(&mut w, p);
    }
    w.into_bytes()
}

pub fn pose_stamped(t_s: f64, frame: &str, p: &Pose2) -> Vec<u8> {
    let mut w = CdrWriter::new();
    header(&mut w, t_s, frame);
    pose(&mut w, p);
    w.into_bytes()
}

pub fn path(t_s: f64, frame: &str, poses: &[Pose2]) -> Vec<u8> {
    let mut w = CdrWriter::new();
    header(&mut w, t_s, frame);
    w.len(poses.len());
    for p in poses {
        header(&mut w, t_s, frame);
        pose(&mut w, p);
    }
    w.into_bytes()
}

pub fn string(text: &str) -> Vec<u8> {
    let mut w = CdrWriter::new();
    w.string(text);
    w.into_bytes()
}

/// An `rcl_interfaces/msg/Log` (what `/rosout` carries) from logger `name` at `level`
/// (20 info, 30 warn, 40 error).
pub fn log(t_s: f64, level: u8, name: &str, text: &str) -> Vec<u8> {
    let mut w = CdrWriter::new();
    time(&mut w, t_s);
    w.u8(level);
    w.string(name);
    w.string(text);
    w.string("");
    w.string("");
    w.u32(0);
    w.into_bytes()
}

/// `visualization_msgs/Marker` types forkbench draws with.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Shape {
    Arrow = 0,
    Cube = 1,
    LineStrip = 4,
    LineList = 5,
    Points = 8,
}

/// One marker: a shape at `pose` in `frame` (points in that frame too), named `ns`/`id`
/// so a later marker of the same name replaces it.
#[derive(Debug, Clone)]
pub struct Marker<'a> {
    pub frame: &'a str,
    pub ns: &'a str,
    pub id: i32,
    pub shape: Shape,
    pub pose: Pose2,
    /// Size (cube, arrow) or line width and point size (x, y) in metres.
    pub scale: [f64; 3],
    pub rgba: [u8; 4],
    /// Moves with its frame's later transforms (the truck's and the pallet's outlines).
    pub frame_locked: bool,
    pub points: Vec<[f64; 2]>,
}

/// A `visualization_msgs/MarkerArray` of `markers`, each added for good (lifetime 0).
pub fn marker_array(t_s: f64, markers: &[Marker<'_>]) -> Vec<u8> {
    let mut w = CdrWriter::new();
    w.len(markers.len());
    for m in markers {
        header(&mut w, t_s, m.frame);
        w.string(m.ns);
        w.i32(m.id);
        w.i32(m.shape as i32);
        w.i32(0);
        pose(&mut w, &m.pose);
        for v in m.scale {
            w.f64(v);
        }
        for c in m.rgba {
            w.f32(f32::from(c) / 255.0);
        }
        w.i32(0);
        w.u32(0);
        w.u8(u8::from(m.frame_locked));
        w.len(m.points.len());
        for [x, y] in &m.points {
            for v in [*x, *y, 0.0] {
                w.f64(v);
            }
        }
        w.len(0);
        w.string("");
        header(&mut w, t_s, m.frame);
        w.string("");
        w.len(0);
        w.len(0);
        w.string("");
        w.string("");
        w.string("");
        w.len(0);
        w.u8(0);
    }
    w.into_bytes()
}

/// A `nav_msgs/OccupancyGrid`: the same row-major layout from the lower-left corner,
/// each cell 0–100 (ROS's −1, unknown, is never written).
pub fn occupancy_grid(t_s: f64, frame: &str, g: &forkbench_core::signal::Grid) -> Vec<u8> {
    let mut w = CdrWriter::new();
    header(&mut w, t_s, frame);
    time(&mut w, t_s);
    w.f32(g.cell_m as f32);
    w.u32(u32::try_from(g.cols).unwrap_or(u32::MAX));
    w.u32(u32::try_from(g.rows).unwrap_or(u32::MAX));
    pose(&mut w, &Pose2::new(g.origin_m[0], g.origin_m[1], 0.0));
    w.bytes_seq(&g.cells.iter().map(|c| (*c).min(100)).collect::<Vec<u8>>());
    w.into_bytes()
}

pub fn float64(v: f64) -> Vec<u8> {
    let mut w = CdrWriter::new();
    w.f64(v);
    w.into_bytes()
}

/// A `sensor_msgs/msg/LaserScan` as read from a bag (intensities are skipped).
#[derive(Debug, Clone, PartialEq)]
pub struct LaserScanMsg {
    pub stamp_s: f64,
    pub frame_id: String,
    pub angle_min_rad: f32,
    pub angle_max_rad: f32,
    pub angle_increment_rad: f32,
    pub range_min_m: f32,
    pub range_max_m: f32,
    pub ranges_m: Vec<f32>,
}

/// Reads a CDR `sensor_msgs/msg/LaserScan`; every length is checked against the message.
pub fn decode_laser_scan(data: &[u8]) -> Result<LaserScanMsg, super::cdr::CdrError> {
    let mut r = super::cdr::CdrReader::new(data)?;
    let sec = r.i32()?;
    let nanosec = r.u32()?;
    let frame_id = r.string()?;
    let mut f = [0f32; 7];
    for v in &mut f {
        *v = r.f32()?;
    }
    let ranges_m = r.f32_seq()?;
    Ok(LaserScanMsg {
        stamp_s: f64::from(sec) + f64::from(nanosec) * 1e-9,
        frame_id,
        angle_min_rad: f[0],
        angle_max_rad: f[1],
        angle_increment_rad: f[2],
        range_min_m: f[5],
        range_max_m: f[6],
        ranges_m,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_laser_scan_reads_back_as_written() {
        let scan = Scan {
            sensor: Pose2::new(1.0, 2.0, 0.5),
            angle_min_rad: -1.0,
            angle_step_rad: 0.01,
            range_min_m: 0.05,
            range_max_m: 10.0,
            ranges_m: vec![1.5, f64::NAN, 2.25],
        };
        let msg = decode_laser_scan(&laser_scan(12.5, "scanner_x", &scan)).expect("decodes");
        assert_eq!(msg.frame_id, "scanner_x");
        assert!((msg.stamp_s - SIM_EPOCH_UNIX_S as f64 - 12.5).abs() < 1e-6);
        assert_eq!((msg.angle_min_rad, msg.angle_max_rad), (-1.0, -0.98));
        assert_eq!(msg.ranges_m[0], 1.5);
        assert!(msg.ranges_m[1].is_infinite() && msg.ranges_m[2] == 2.25);
        let bytes = laser_scan(0.0, "s", &scan);
        assert!(
            decode_laser_scan(&bytes[..bytes.len() - 5]).is_err(),
            "truncated"
        );
    }
}
