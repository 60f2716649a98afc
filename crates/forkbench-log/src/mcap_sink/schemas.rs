//! The MCAP recording's channels and their JSON Schemas.

/// Topics, schemas and how often they are written.
pub(super) const CHANNELS: [(&str, &str, &str); 9] = [
    ("/world", "foxglove.SceneUpdate", SCENE_UPDATE_SCHEMA),
    ("/truck/scene", "foxglove.SceneUpdate", SCENE_UPDATE_SCHEMA),
    ("/tf", "foxglove.FrameTransform", FRAME_TRANSFORM_SCHEMA),
    (
        "/truck/pose_true",
        "foxglove.PoseInFrame",
        POSE_IN_FRAME_SCHEMA,
    ),
    (
        "/truck/pose_measured",
        "foxglove.PoseInFrame",
        POSE_IN_FRAME_SCHEMA,
    ),
    ("/log", "foxglove.Log", LOG_SCHEMA),
    (
        "/forkbench/telemetry",
        "forkbench.Telemetry",
        TELEMETRY_SCHEMA,
    ),
    ("/forkbench/plan", "forkbench.Plan", PLAN_SCHEMA),
    ("/forkbench/outcome", "forkbench.Outcome", OUTCOME_SCHEMA),
];

pub(super) const SCENE_UPDATE_SCHEMA: &str = r#"{"title":"foxglove.SceneUpdate","type":"object","properties":{"deletions":{"type":"array","items":{"type":"object"}},"entities":{"type":"array","items":{"type":"object","properties":{"timestamp":{"type":"object"},"frame_id":{"type":"string"},"id":{"type":"string"},"lifetime":{"type":"object"},"frame_locked":{"type":"boolean"},"metadata":{"type":"array"},"arrows":{"type":"array"},"cubes":{"type":"array"},"spheres":{"type":"array"},"cylinders":{"type":"array"},"lines":{"type":"array","items":{"type":"object","properties":{"type":{"type":"integer"},"pose":{"type":"object"},"thickness":{"type":"number"},"scale_invariant":{"type":"boolean"},"points":{"type":"array"},"color":{"type":"object"},"colors":{"type":"array"},"indices":{"type":"array"}}}},"triangles":{"type":"array"},"texts":{"type":"array"},"models":{"type":"array"}}}}}}"#;

pub(super) const FRAME_TRANSFORM_SCHEMA: &str = r#"{"title":"foxglove.FrameTransform","type":"object","properties":{"timestamp":{"type":"object"},"parent_frame_id":{"type":"string"},"child_frame_id":{"type":"string"},"translation":{"type":"object","properties":{"x":{"type":"number"},"y":{"type":"number"},"z":{"type":"number"}}},"rotation":{"type":"object","properties":{"x":{"type":"number"},"y":{"type":"number"},"z":{"type":"number"},"w":{"type":"number"}}}}}"#;

pub(super) const POSE_IN_FRAME_SCHEMA: &str = r#"{"title":"foxglove.PoseInFrame","type":"object","properties":{"timestamp":{"type":"object"},"frame_id":{"type":"string"},"pose":{"type":"object","properties":{"position":{"type":"object"},"orientation":{"type":"object"}}}}}"#;

pub(super) const LOG_SCHEMA: &str = r#"{"title":"foxglove.Log","type":"object","properties":{"timestamp":{"type":"object"},"level":{"type":"integer","minimum":0,"maximum":5},"message":{"type":"string"},"name":{"type":"string"},"file":{"type":"string"},"line":{"type":"integer","minimum":0}}}"#;

pub(super) const TELEMETRY_SCHEMA: &str = r#"{"title":"forkbench.Telemetry","description":"One control step, SI units","type":"object","properties":{"t_s":{"type":"number"},"truth":{"type":"array","items":{"type":"number"},"description":"true fork-root x_m, y_m, heading_rad"},"estimate":{"type":"array","items":{"type":"number"},"description":"x_m, y_m, heading_rad the controller used"},"pallet":{"type":"array","items":{"type":"number"}},"pallet_estimate":{"type":"array","items":{"type":"number"}},"steer_cmd_rad":{"type":"number"},"steer_rad":{"type":"number"},"speed_cmd_mps":{"type":"number"},"speed_mps":{"type":"number"},"lookahead_m":{"type":"array","items":{"type":"number"}},"cross_track_m":{"type":"number"},"path_curvature_per_m":{"type":"number"},"contact_force_n":{"type":"number"}}}"#;

pub(super) const PLAN_SCHEMA: &str = r#"{"title":"forkbench.Plan","type":"object","properties":{"index":{"type":"integer"},"t_s":{"type":"number"},"length_m":{"type":"number"},"samples":{"type":"array","description":"[s_m, x_m, y_m, heading_rad, curvature_per_m]","items":{"type":"array","items":{"type":"number"}}},"control_polygon_m":{"type":["array","null"]}}}"#;

pub(super) const OUTCOME_SCHEMA: &str = r#"{"title":"forkbench.Outcome","description":"The judged trial outcome (forkbench_trial::TrialOutcome), SI units","type":"object","properties":{"scenario":{"type":"string"},"case":{"type":"string"},"planner":{"type":"string"},"seed":{"type":"integer"},"success":{"type":"boolean"},"failure":{"type":["string","null"]},"lateral_error_m":{"type":["number","null"]},"heading_error_rad":{"type":["number","null"]},"insertion_depth_m":{"type":["number","null"]},"sim_time_s":{"type":"number"},"measures":{"type":"object","description":"What the pick's step criteria measured, by name with its unit","additionalProperties":{"type":"number"}}}}"#;

pub(super) const SCALAR_SCHEMA: &str = r#"{"title":"forkbench.Scalar","description":"One value of a recorded signal's series (the topic names the signal)","type":"object","properties":{"t_s":{"type":"number"},"value":{"type":"number"}}}"#;

pub(super) const LASER_SCAN_SCHEMA: &str = r#"{"title":"foxglove.LaserScan","type":"object","properties":{"timestamp":{"type":"object"},"frame_id":{"type":"string"},"pose":{"type":"object"},"start_angle":{"type":"number"},"end_angle":{"type":"number"},"ranges":{"type":"array","items":{"type":["number","null"]},"description":"metres; null: no return"},"intensities":{"type":"array","items":{"type":"number"}}}}"#;

pub(super) const GRID_SCHEMA: &str = r#"{"title":"foxglove.Grid","type":"object","properties":{"timestamp":{"type":"object"},"frame_id":{"type":"string"},"pose":{"type":"object"},"column_count":{"type":"integer"},"cell_size":{"type":"object","properties":{"x":{"type":"number"},"y":{"type":"number"}}},"row_stride":{"type":"integer"},"cell_stride":{"type":"integer"},"fields":{"type":"array"},"data":{"type":"string","contentEncoding":"base64"}}}"#;
