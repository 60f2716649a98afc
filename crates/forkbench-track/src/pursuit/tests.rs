//! Pure pursuit's steering, speed profile and look-ahead, and its skipping searches against full scans.
use super::*;

fn straight(len: f64) -> Path {
    Path::straight(&Pose2::new(0.0, 0.0, 0.0), len, 0.01)
}

#[test]
fn steers_back_toward_the_path() {
    let truck = ForkliftSpec::default();
    let mut pp = PurePursuit::new(straight(5.0), TrackerConfig::default(), 0.0);
    let left = pp.command(&Pose2::new(1.0, 0.2, 0.0), 0.5, &truck);
    assert!(left.steer_rad < 0.0, "left of the path must steer right");
    assert!((left.cross_track_m - 0.2).abs() < 1e-9);
    let mut pp = PurePursuit::new(straight(5.0), TrackerConfig::default(), 0.0);
    let right = pp.command(&Pose2::new(1.0, -0.2, 0.0), 0.5, &truck);
    assert!(right.steer_rad > 0.0);
}

#[test]
fn slows_near_the_goal_and_stops_there() {
    let truck = ForkliftSpec::default();
    let mut pp = PurePursuit::new(straight(5.0), TrackerConfig::default(), 0.0);
    let far = pp.command(&Pose2::new(0.5, 0.0, 0.0), 0.8, &truck);
    assert!((far.speed_mps - 0.8).abs() < 1e-9);
    let near = pp.command(&Pose2::new(4.0, 0.0, 0.0), 0.3, &truck);
    assert!(near.speed_mps <= 0.3 + 1e-9);
    let end = pp.command(&Pose2::new(4.999, 0.0, 0.0), 0.05, &truck);
    assert!(end.done && end.speed_mps == 0.0);
}

#[test]
fn speed_scaled_lookahead_grows_with_speed() {
    let truck = ForkliftSpec::default();
    let cfg = TrackerConfig {
        lookahead_gain_s: Some(1.5),
        ..TrackerConfig::default()
    };
    let mut pp = PurePursuit::new(straight(8.0), cfg.clone(), 0.0);
    let slow = pp.command(&Pose2::new(1.0, 0.0, 0.0), 0.1, &truck);
    let mut pp = PurePursuit::new(straight(8.0), cfg, 0.0);
    let fast = pp.command(&Pose2::new(1.0, 0.0, 0.0), 0.8, &truck);
    assert!((slow.lookahead_point[0] - 1.3).abs() < 0.02);
    assert!((fast.lookahead_point[0] - 2.2).abs() < 0.02);
}

/// A wavy path (curvature changing sign, a tight loop part way) at `spacing_m`.
fn wavy(spacing_m: f64) -> Path {
    let (mut x, mut y, mut h) = (0.0, 0.0, 0.3);
    let n = (12.0 / spacing_m) as usize;
    let samples = (0..n)
        .map(|i| {
            let s_m = i as f64 * spacing_m;
            let sample = forkbench_core::PathSample {
                s_m,
                x_m: x,
                y_m: y,
                heading_rad: h,
                curvature_per_m: 0.0,
            };
            let k = 1.5 * (s_m * 0.9).sin() + if (6.0..7.0).contains(&s_m) { 3.0 } else { 0.0 };
            x += spacing_m * h.cos();
            y += spacing_m * h.sin();
            h += k * spacing_m;
            sample
        })
        .collect();
    Path::new(samples)
}

/// The skipping searches return what scanning every sample returns, from any
/// progress, for poses on, beside and far from the path.
#[test]
fn skipping_searches_find_what_full_scans_find() {
    let mut state = 0x9e37_79b9_7f4a_7c15_u64;
    let mut unit = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    for spacing in [0.001, 0.008, 0.05] {
        let mut pp = PurePursuit::new(wavy(spacing), TrackerConfig::default(), 0.0);
        let n = pp.path.samples.len();
        for _ in 0..3000 {
            pp.idx = (unit() * n as f64) as usize % n;
            let near = pp.path.samples[(pp.idx + (unit() * 300.0) as usize).min(n - 1)];
            let off = [0.002, 0.05, 0.6, 5.0][(unit() * 4.0) as usize % 4];
            let a = unit() * std::f64::consts::TAU;
            let pose = Pose2::new(near.x_m + off * a.cos(), near.y_m + off * a.sin(), a);
            let d2 = |p: &forkbench_core::PathSample| {
                (p.x_m - pose.x_m).powi(2) + (p.y_m - pose.y_m).powi(2)
            };
            let window = (pp.idx + 400).min(n);
            let mut want = pp.idx;
            for i in pp.idx..window {
                if d2(&pp.path.samples[i]) < d2(&pp.path.samples[want]) {
                    want = i;
                }
            }
            assert_eq!(pp.closest(&pose), want, "spacing {spacing}, {pose:?}");
            let ld = 0.05 + 2.0 * unit();
            let scan = pp.path.samples[want..]
                .iter()
                .find(|p| d2(p) >= ld * ld)
                .copied();
            assert_eq!(
                pp.first_at_least(&pose, want, ld),
                scan,
                "spacing {spacing}, ld {ld}"
            );
        }
    }
}
