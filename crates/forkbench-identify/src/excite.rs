//! A step test of the simulated truck: seeded steering and speed steps on an open floor, logged as an actuator log (what a team logs on its own truck to identify it).

use forkbench_core::{ForkliftSpec, PalletSpec, Pose2};
use forkbench_sim::{Sim, SimConfig, SimError};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

use crate::log::{ActuatorLog, Channel, Run};

/// How many runs, how long each, and the seed of the steps.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepTest {
    pub runs: usize,
    pub run_s: f64,
    pub seed: u64,
    /// Steer as well as drive (false: straight, the speed steps alone, with no
    /// steering channel in the log).
    pub steering: bool,
}

impl Default for StepTest {
    fn default() -> Self {
        Self {
            runs: 8,
            run_s: 20.0,
            seed: 1,
            steering: true,
        }
    }
}

/// Most runs and longest run a step test takes (a log's size).
pub const MAX_RUNS: usize = 1000;
pub const MAX_RUN_S: f64 = 600.0;

/// The step test excites one actuator at a time, as a commissioning test does: steering
/// steps with the truck standing, then speed steps with the wheel straight (a wheel turned
/// while driving drags the truck through its tyres, which no speed-loop model holds).
const STEER_PHASE_S: f64 = 6.0;
const DRIVE_PHASE_S: f64 = 8.0;
/// How long each phase first lets the other actuator settle: the truck stop, the wheel
/// come straight (a quarter of the steering phase in a run shorter than a cycle).
const SETTLE_S: f64 = 1.5;

/// Drives `truck` through `test` in the physics with `sim`'s settings: each run starts at
/// rest, then alternates a steering phase (the speed commanded to 0; the steering command
/// steps to the other side, up to 0.9 of the limit, every 0.8–2 s) and a drive phase (the
/// wheel commanded straight; the speed command steps to a new speed every 1.5–3 s); logged
/// every physics step. Without steering, the speed steps run throughout.
pub fn step_test(
    truck: &ForkliftSpec,
    sim: &SimConfig,
    test: &StepTest,
) -> Result<ActuatorLog, SimError> {
    let mut log = ActuatorLog::default();
    for r in 0..test.runs.min(MAX_RUNS) {
        let mut rng =
            ChaCha8Rng::seed_from_u64(test.seed ^ (r as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15));
        let mut run = one_run(
            truck,
            sim,
            (test.run_s.min(MAX_RUN_S), test.steering),
            &mut rng,
        )?;
        if !test.steering {
            run.steer = None;
        }
        log.runs.push(run);
    }
    Ok(log)
}

fn one_run(
    truck: &ForkliftSpec,
    cfg: &SimConfig,
    (run_s, steering): (f64, bool),
    rng: &mut ChaCha8Rng,
) -> Result<Run, SimError> {
    // The pallet far off: the floor is open.
    let far = Pose2::new(1.0e3, 1.0e3, 0.0);
    let mut sim = Sim::new(
        truck,
        &Pose2::new(0.0, 0.0, 0.0),
        &PalletSpec::field_1200(),
        &far,
        &[],
        cfg,
    )?;
    let reach = 0.9 * truck.max_steer_rad;
    let (mut steer_cmd, mut speed_cmd) = (0.0, 0.0);
    let (mut next_steer, mut next_speed) = (0.5, 0.5);
    let mut run = Run {
        t_s: vec![0.0],
        steer: Some(Channel {
            cmd: vec![0.0],
            measured: vec![sim.steer_rad()],
        }),
        speed: Some(Channel {
            cmd: vec![0.0],
            measured: vec![sim.speed_mps()],
        }),
    };
    // A run shorter than one cycle holds both phases, in proportion.
    let cycle_s = (STEER_PHASE_S + DRIVE_PHASE_S).min(run_s);
    let steer_s = cycle_s * STEER_PHASE_S / (STEER_PHASE_S + DRIVE_PHASE_S);
    let settle_s = SETTLE_S.min(steer_s / 4.0);
    let steps = (run_s / cfg.dt_s).round() as usize;
    for _ in 0..steps {
        let t = sim.time_s();
        let in_cycle = t % cycle_s;
        let (steer_phase, settled) = match steering {
            false => (false, true),
            true if in_cycle < steer_s => (true, in_cycle >= settle_s),
            true => (false, in_cycle - steer_s >= settle_s),
        };
        if steer_phase {
            speed_cmd = 0.0;
            if settled && t >= next_steer {
                // Alternating sides, so steps run up to twice the reach: the rate limit
                // shows.
                let side = if steer_cmd > 0.0 { -1.0 } else { 1.0 };
                steer_cmd = side * reach * rng.random_range(0.15..=1.0);
                next_steer = t + rng.random_range(0.8..2.0);
            }
        } else {
            steer_cmd = 0.0;
            if settled && t >= next_speed {
                speed_cmd = rng.random_range(-0.5..=truck.max_speed_mps);
                next_speed = t + rng.random_range(1.5..3.0);
            }
        }
        sim.step(speed_cmd, steer_cmd);
        run.t_s.push(sim.time_s());
        for (ch, cmd, got) in [
            (&mut run.steer, steer_cmd, sim.steer_rad()),
            (&mut run.speed, speed_cmd, sim.speed_mps()),
        ] {
            if let Some(ch) = ch.as_mut() {
                ch.cmd.push(cmd);
                ch.measured.push(got);
            }
        }
    }
    Ok(run)
}
