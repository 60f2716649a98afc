//! Foxglove and forkbench message types of the MCAP recording, serialised as JSON.

use forkbench_core::Pose2;
use serde::Serialize;

/// Simulated time 0 in every MCAP file: 2000-01-01T00:00:00Z. Fixed, so the same seed
/// writes the same file, and not 1970, which viewers show as a missing clock.
pub const SIM_EPOCH_UNIX_S: u64 = 946_684_800;

/// A simulated time as nanoseconds since the Unix epoch, from [`SIM_EPOCH_UNIX_S`].
pub(super) fn ns(t_s: f64) -> u64 {
    SIM_EPOCH_UNIX_S * 1_000_000_000 + (t_s.max(0.0) * 1e9).round() as u64
}

/// Typed forms of the per-step messages: serialised straight into a reused buffer, no
/// `Value` tree (the trial writes three of these per 100 Hz step).
#[derive(Serialize)]
pub(super) struct Stamp {
    pub(super) sec: u64,
    pub(super) nsec: u64,
}

impl Stamp {
    pub(super) fn at(t_s: f64) -> Self {
        let n = ns(t_s);
        Self {
            sec: n / 1_000_000_000,
            nsec: n % 1_000_000_000,
        }
    }
}

#[derive(Serialize)]
pub(super) struct Vec3 {
    pub(super) x: f32,
    pub(super) y: f32,
    pub(super) z: f32,
}

#[derive(Serialize)]
pub(super) struct Quat {
    pub(super) x: f32,
    pub(super) y: f32,
    pub(super) z: f32,
    pub(super) w: f32,
}

impl Quat {
    pub(super) fn yaw(yaw_rad: f64) -> Self {
        let (s, c) = (yaw_rad / 2.0).sin_cos();
        Self {
            x: 0.0,
            y: 0.0,
            z: s as f32,
            w: c as f32,
        }
    }
}

#[derive(Serialize)]
pub(super) struct FoxPose {
    pub(super) position: Vec3,
    pub(super) orientation: Quat,
}

impl FoxPose {
    pub(super) fn of(p: &Pose2) -> Self {
        Self {
            position: Vec3 {
                x: p.x_m as f32,
                y: p.y_m as f32,
                z: 0.0,
            },
            orientation: Quat::yaw(p.heading_rad),
        }
    }
}

#[derive(Serialize)]
pub(super) struct FrameTransform {
    pub(super) timestamp: Stamp,
    pub(super) parent_frame_id: &'static str,
    pub(super) child_frame_id: &'static str,
    pub(super) translation: Vec3,
    pub(super) rotation: Quat,
}

impl FrameTransform {
    /// `child`'s pose in the world frame.
    pub(super) fn world(t_s: f64, child: &'static str, p: &Pose2) -> Self {
        let FoxPose {
            position,
            orientation,
        } = FoxPose::of(p);
        Self {
            timestamp: Stamp::at(t_s),
            parent_frame_id: "world",
            child_frame_id: child,
            translation: position,
            rotation: orientation,
        }
    }
}

#[derive(Serialize)]
pub(super) struct PoseInFrame {
    pub(super) timestamp: Stamp,
    pub(super) frame_id: &'static str,
    pub(super) pose: FoxPose,
}

impl PoseInFrame {
    pub(super) fn world(t_s: f64, p: &Pose2) -> Self {
        Self {
            timestamp: Stamp::at(t_s),
            frame_id: "world",
            pose: FoxPose::of(p),
        }
    }
}

#[derive(Serialize)]
pub(super) struct Telemetry {
    pub(super) t_s: f64,
    pub(super) truth: [f32; 3],
    pub(super) estimate: [f32; 3],
    pub(super) pallet: [f32; 3],
    pub(super) pallet_estimate: [f32; 3],
    pub(super) steer_cmd_rad: f32,
    pub(super) steer_rad: f32,
    pub(super) speed_cmd_mps: f32,
    pub(super) speed_mps: f32,
    pub(super) lookahead_m: [f32; 2],
    pub(super) cross_track_m: f32,
    pub(super) path_curvature_per_m: f32,
    pub(super) contact_force_n: f32,
}

pub(super) fn xyh(p: &Pose2) -> [f32; 3] {
    [p.x_m as f32, p.y_m as f32, p.heading_rad as f32]
}

/// An empty JSON array, for the SceneEntity primitive lists we do not use.
pub(super) type None0 = [u8; 0];

#[derive(Serialize)]
pub(super) struct Color {
    pub(super) r: f64,
    pub(super) g: f64,
    pub(super) b: f64,
    pub(super) a: f64,
}

#[derive(Serialize)]
pub(super) struct LinePrimitive {
    #[serde(rename = "type")]
    pub(super) kind: u8,
    pub(super) pose: FoxPose,
    pub(super) thickness: f64,
    pub(super) scale_invariant: bool,
    pub(super) points: Vec<Vec3>,
    pub(super) color: Color,
    pub(super) colors: None0,
    pub(super) indices: None0,
}

#[derive(Serialize)]
pub(super) struct SceneEntity {
    pub(super) timestamp: Stamp,
    pub(super) frame_id: &'static str,
    pub(super) id: String,
    pub(super) lifetime: Stamp,
    pub(super) frame_locked: bool,
    pub(super) metadata: None0,
    pub(super) arrows: Vec<ArrowPrimitive>,
    pub(super) cubes: None0,
    pub(super) spheres: Vec<SpherePrimitive>,
    pub(super) cylinders: None0,
    pub(super) lines: Vec<LinePrimitive>,
    pub(super) triangles: None0,
    pub(super) texts: None0,
    pub(super) models: None0,
}

#[derive(Serialize)]
pub(super) struct SceneUpdate {
    pub(super) deletions: Vec<Deletion>,
    pub(super) entities: Vec<SceneEntity>,
}

#[derive(Serialize)]
pub(super) struct PlanMsg {
    pub(super) index: u32,
    pub(super) t_s: f64,
    pub(super) length_m: f64,
    /// [s_m, x_m, y_m, heading_rad, curvature_per_m]
    pub(super) samples: Vec<[f64; 5]>,
    pub(super) control_polygon_m: Option<Vec<[f64; 2]>>,
}

/// A line strip (type 0) in world coordinates.
pub(super) fn line(points: &[[f64; 2]], rgba: [f64; 4], thickness: f64) -> LinePrimitive {
    line_at(points, 0.0, rgba, thickness)
}

/// A line strip at height `z_m` (drawn over the ones below in a top-down view).
pub(super) fn line_at(
    points: &[[f64; 2]],
    z_m: f32,
    rgba: [f64; 4],
    thickness: f64,
) -> LinePrimitive {
    LinePrimitive {
        kind: 0,
        pose: FoxPose::of(&Pose2::new(0.0, 0.0, 0.0)),
        thickness,
        scale_invariant: false,
        points: points
            .iter()
            .map(|p| Vec3 {
                x: p[0] as f32,
                y: p[1] as f32,
                z: z_m,
            })
            .collect(),
        color: Color::of(rgba),
        colors: [],
        indices: [],
    }
}

/// Separate segments (type 2, LINE_LIST): points pair up.
pub(super) fn line_list(
    segments: impl IntoIterator<Item = [[f64; 2]; 2]>,
    rgba: [f64; 4],
    thickness: f64,
) -> LinePrimitive {
    let pts: Vec<[f64; 2]> = segments.into_iter().flatten().collect();
    LinePrimitive {
        kind: 2,
        ..line(&pts, rgba, thickness)
    }
}

pub(super) fn entity(t_s: f64, id: &str, lines: Vec<LinePrimitive>) -> SceneEntity {
    entity_in("world", t_s, id, lines)
}

/// An entity drawn in `frame`; frame-locked, so it follows that frame's /tf.
pub(super) fn entity_in(
    frame: &'static str,
    t_s: f64,
    id: &str,
    lines: Vec<LinePrimitive>,
) -> SceneEntity {
    SceneEntity {
        timestamp: Stamp::at(t_s),
        frame_id: frame,
        id: id.to_owned(),
        lifetime: Stamp { sec: 0, nsec: 0 },
        frame_locked: frame != "world",
        metadata: [],
        arrows: Vec::new(),
        cubes: [],
        spheres: Vec::new(),
        cylinders: [],
        lines,
        triangles: [],
        texts: [],
        models: [],
    }
}

/// `foxglove.SceneEntityDeletion` of one entity by id (type 0, MATCHING_ID).
#[derive(Serialize)]
pub(super) struct Deletion {
    pub(super) timestamp: Stamp,
    #[serde(rename = "type")]
    pub(super) kind: u8,
    pub(super) id: String,
}

impl Deletion {
    pub(super) fn of(t_s: f64, id: String) -> Self {
        Self {
            timestamp: Stamp::at(t_s),
            kind: 0,
            id,
        }
    }
}

#[derive(Serialize)]
pub(super) struct SpherePrimitive {
    pub(super) pose: FoxPose,
    pub(super) size: Vec3,
    pub(super) color: Color,
}

/// A sphere of `diameter_m` at `p`.
pub(super) fn sphere(p: [f64; 2], diameter_m: f32, rgba: [f64; 4]) -> SpherePrimitive {
    SpherePrimitive {
        pose: FoxPose::of(&Pose2::new(p[0], p[1], 0.0)),
        size: Vec3 {
            x: diameter_m,
            y: diameter_m,
            z: diameter_m,
        },
        color: Color::of(rgba),
    }
}

#[derive(Serialize)]
pub(super) struct ArrowPrimitive {
    pub(super) pose: FoxPose,
    pub(super) shaft_length: f64,
    pub(super) shaft_diameter: f64,
    pub(super) head_length: f64,
    pub(super) head_diameter: f64,
    pub(super) color: Color,
}

/// A 0.6 m arrow along the pose's heading, for the start and goal markers.
pub(super) fn pose_arrow(p: &Pose2, rgba: [f64; 4]) -> ArrowPrimitive {
    ArrowPrimitive {
        pose: FoxPose::of(p),
        shaft_length: 0.45,
        shaft_diameter: 0.05,
        head_length: 0.15,
        head_diameter: 0.15,
        color: Color::of(rgba),
    }
}

impl Color {
    pub(super) fn of(rgba: [f64; 4]) -> Self {
        Self {
            r: rgba[0],
            g: rgba[1],
            b: rgba[2],
            a: rgba[3],
        }
    }
}
