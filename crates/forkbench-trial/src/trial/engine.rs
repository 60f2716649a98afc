//! The one drive loop every part of a trial runs through (the mission legs, staging, the pick, each phase) and its tick in order: sense, the steering's re-estimate, the caller's turn (the yield point where a session's caller takes the tick), command, safety gate, the physics step with odometry and record, the steering's judgement.

use std::future::Future;
use std::pin::Pin;
use std::task::{Context, Poll};

use forkbench_core::Pose2;
use forkbench_core::profile::{self, Stage};
use forkbench_track::Command;

use super::link::{Control, Link, Observation, Truth};
use super::safety;
use super::state::{Localization, Trial, WorldState};
use super::{SIGNAL_EVERY_STEPS, goal_for};
use crate::outcome::TrialOutcome;
use crate::recorder::{Level, Recorder, StepRecord};
use crate::stage_error::StageError;
use forkbench_core::{Signal, Style};

/// A drive's command source, its stop condition and its per-step criteria.
pub(crate) trait Steering<'a, E> {
    /// After the tick's reading, before the command (a re-estimate, a replan).
    fn sensed<R: Recorder + ?Sized>(
        &mut self,
        _t: &mut Trial<'a>,
        _pose: Pose2,
        _rec: &mut R,
    ) -> Result<(), E> {
        Ok(())
    }
    /// The tick's command from the controller's `pose` (`control` says whether a caller
    /// replaces it); `None` ends the drive.
    fn command(
        &mut self,
        t: &mut Trial<'a>,
        control: Control,
        pose: Pose2,
    ) -> Result<Option<Command>, E>;
    /// After the physics step under `cmd`: the per-step criteria. `Ok(true)` ends the
    /// drive.
    fn stepped<R: Recorder + ?Sized>(
        &mut self,
        _t: &mut Trial<'a>,
        _control: Control,
        _cmd: &Command,
        _rec: &mut R,
    ) -> Result<bool, E> {
        Ok(false)
    }
}

impl<'a> Trial<'a> {
    /// Steps the truck, tick by tick, under `steering` until it ends the drive (`Ok(true)`),
    /// `limit_s` passes (`Ok(false)`), or it fails. Every tick: the reading, the steering's
    /// re-estimate, a caller's turn (in a session that covers the trial's stage), the
    /// command, the physics step, the criteria.
    pub(crate) async fn drive_by<R, E, S>(
        &mut self,
        limit_s: f64,
        steering: &mut S,
        rec: &mut R,
    ) -> Result<bool, E>
    where
        R: Recorder + ?Sized,
        E: From<StageError>,
        S: Steering<'a, E>,
    {
        let deadline_s = self.world.sim.time_s() + limit_s;
        let every = self.control_steps_per_tick();
        let mut last = None;
        // The tick's command (before the safety gate) and control, held until the next
        // tick; the safety function acts on the drive at every step, as a safety
        // controller does beside the truck's computer.
        let mut held: Option<(Command, Control, u32)> = None;
        let ended = loop {
            if self.world.sim.time_s() >= deadline_s {
                break Ok(false);
            }
            if let (Some((cmd, control, since)), Some((_, pose))) = (held.as_mut(), last)
                && *since < every
            {
                *since += 1;
                let (mut cmd, control) = (*cmd, *control);
                cmd.speed_mps = profile::timed(Stage::Safety, || {
                    safety::gate(&mut self.safety, &self.world.sim, cmd.speed_mps, rec)
                });
                self.physics_step(&cmd, None, pose, rec);
                match profile::timed(Stage::Criteria, || {
                    steering.stepped(self, control, &cmd, rec)
                }) {
                    Ok(false) => continue,
                    Ok(true) => break Ok(true),
                    Err(e) => break Err(e),
                }
            }
            let (fix, pose) = match self.sense(rec) {
                Ok(r) => r,
                Err(e) => break Err(E::from(e)),
            };
            if let Err(e) = steering.sensed(self, pose, rec) {
                break Err(e);
            }
            last = Some((fix, pose));
            let control = self.caller_turn(deadline_s, fix, pose).await;
            let asked = match steering.command(self, control, pose) {
                Ok(Some(cmd)) => applied(control, cmd, &self.scn.truck),
                Ok(None) => break Ok(true),
                Err(e) => break Err(e),
            };
            let mut cmd = asked;
            cmd.speed_mps = profile::timed(Stage::Safety, || {
                safety::gate(&mut self.safety, &self.world.sim, asked.speed_mps, rec)
            });
            self.physics_step(&cmd, fix, pose, rec);
            held = Some((asked, control, 1));
            match profile::timed(Stage::Criteria, || {
                steering.stepped(self, control, &cmd, rec)
            }) {
                Ok(false) => {}
                Ok(true) => break Ok(true),
                Err(e) => break Err(e),
            }
        };
        if let Some((fix, pose)) = last {
            self.publish(deadline_s, fix, pose);
        }
        if let Some(link) = self.caller() {
            // Whether the caller's episode, if it ends with this drive, was cut short.
            link.lock().deadline_hit = matches!(ended, Ok(false));
        }
        ended
    }

    /// The part of the cycle the trial drives from now on, as a session's caller sees it.
    pub(super) fn enter(&mut self, stage: super::link::Stage) {
        self.stage = stage;
    }

    /// Physics steps per control tick (`[truck.control] period_s`, checked at load).
    fn control_steps_per_tick(&self) -> u32 {
        self.run
            .truck
            .control
            .steps_per_tick(self.world.sim.dt_s())
            .unwrap_or(1)
    }

    /// The session whose caller takes this stage's ticks, if one does.
    fn caller(&self) -> Option<&Link> {
        self.link.as_ref().filter(|l| l.covers(self.stage))
    }

    /// In a session covering the stage: the controller's view goes to the caller, and the
    /// trial waits for its control. Elsewhere the scenario's own controller steers.
    async fn caller_turn(&mut self, deadline_s: f64, fix: Option<Pose2>, pose: Pose2) -> Control {
        if self.caller().is_none() {
            return Control::Tracker;
        }
        self.publish(deadline_s, fix, pose);
        let waited = std::time::Instant::now();
        Yield(false).await;
        // A caller's thinking time is not the trial's: the wall budget is for components.
        self.wall_start += waited.elapsed();
        self.link.as_ref().map_or(Control::Tracker, Link::control)
    }

    /// The controller's view and the truth now, to the session's caller.
    fn publish(&self, deadline_s: f64, fix: Option<Pose2>, pose: Pose2) {
        let Some(link) = self.caller() else {
            return;
        };
        let truck = &self.scn.truck;
        let (root, pallet) = (
            self.world.sim.fork_root_pose(),
            self.world.sim.pallet_pose(),
        );
        let t_s = self.world.sim.time_s();
        let mut slot = link.lock();
        slot.obs = Some(Observation {
            t_s,
            time_left_s: (deadline_s - t_s).max(0.0),
            pose,
            fix: fix.is_some(),
            pallet_estimate: self.sense.pallet_est,
            goal: goal_for(&self.sense.pallet_est, truck, self.insertion_m),
            speed_mps: self.world.sim.speed_mps(),
            steer_rad: self.world.sim.steer_rad(),
            stage: self.stage,
        });
        slot.truth = Some(Truth {
            fork_root: root,
            goal: goal_for(&pallet, truck, self.insertion_m),
            insertion_depth_m: truck.insertion_depth_m(&pallet, self.scn.pallet.depth_m, &root),
            pallet,
        });
        if slot.path_version != Some(self.path_version) {
            slot.path_version = Some(self.path_version);
            slot.path = Some(self.path.clone());
        }
        if slot.viewed && !slot.obstacles_sent {
            slot.obstacles_sent = true;
            slot.obstacles = Some(
                self.world
                    .obstacles
                    .iter()
                    .map(|o| {
                        forkbench_core::geometry::rect_outline(&o.centre, o.length_m, o.width_m)
                    })
                    .collect(),
            );
        }
    }
}

impl Trial<'_> {
    /// One physics step under `cmd`: the world and the odometry move, the people and
    /// the safety fields follow, the step is recorded.
    pub(super) fn physics_step<R: Recorder + ?Sized>(
        &mut self,
        cmd: &Command,
        fix: Option<Pose2>,
        pose: Pose2,
        rec: &mut R,
    ) {
        let truck = &self.scn.truck;
        step_world(
            &mut self.world,
            &mut self.loc,
            &mut self.verdict.out,
            truck,
            cmd,
            rec,
        );
        profile::timed(Stage::Safety, || self.safety_step(rec));
        let pallet_est = self.sense.pallet_est;
        profile::timed(Stage::Record, || {
            record_step(&self.world, pallet_est, cmd, (fix, pose), rec);
        });
    }
}

/// The world's physics step under `cmd`, the truck's odometry (`loc`) propagated on its
/// own errors, and what the outcome keeps of the step (the largest steering, a rack or
/// wall touched).
fn step_world<R: Recorder + ?Sized>(
    world: &mut WorldState,
    loc: &mut Localization,
    out: &mut TrialOutcome,
    truck: &forkbench_core::ForkliftSpec,
    cmd: &Command,
    rec: &mut R,
) {
    let before = world.sim.fork_root_pose();
    profile::timed(Stage::Physics, || {
        world.sim.step(cmd.speed_mps, cmd.steer_rad)
    });
    let moved_m = before.distance_to(&world.sim.fork_root_pose());
    world.mark();
    world.travelled_m += moved_m;
    if world.sim.carrying() {
        world.travelled_loaded_m += moved_m;
    }
    let (scale, offset) = loc.odometry_error;
    let (v, steer) = (
        world.sim.speed_mps() * (1.0 + scale),
        world.sim.steer_rad() + offset,
    );
    for p in [&mut loc.predictor, &mut loc.odometry] {
        p.propagate(
            v,
            steer,
            truck.wheelbase_m,
            truck.fork_root_ahead_of_front_axle_m,
            world.sim.dt_s(),
        );
    }
    out.max_steer_rad = out.max_steer_rad.max(world.sim.steer_rad().abs());
    if world.sim.obstacle_contact() && !world.collision {
        rec.event(
            world.sim.time_s(),
            Level::Error,
            "truck touched a rack or wall",
        );
    }
    world.collision |= world.sim.obstacle_contact();
}

/// The step as recorded: the truth, the fix and the controller's `pose`, the pallet and
/// its estimate, the command and the response; at 10 Hz also the localisation and
/// cross-track errors (what a failed entry is most often traced to, at a tenth of the
/// control rate).
fn record_step<R: Recorder + ?Sized>(
    world: &WorldState,
    pallet_est: Pose2,
    cmd: &Command,
    (fix, pose): (Option<Pose2>, Pose2),
    rec: &mut R,
) {
    let sim = &world.sim;
    let t = sim.time_s();
    let truth = sim.fork_root_pose();
    if ((t / sim.dt_s()).round() as u64).is_multiple_of(SIGNAL_EVERY_STEPS) {
        let loc_error = (pose.x_m - truth.x_m).hypot(pose.y_m - truth.y_m);
        let none = Style::default();
        let error = Signal::Scalar(loc_error);
        rec.signal(t, "localisation/position_error_m", &error, none);
        let cross = Signal::Scalar(cmd.cross_track_m);
        rec.signal(t, "track/cross_track_m", &cross, none);
    }
    rec.step(&StepRecord {
        t_s: t,
        truth,
        fix,
        estimate: pose,
        pallet: sim.pallet_pose(),
        pallet_estimate: pallet_est,
        steer_cmd_rad: cmd.steer_rad,
        steer_rad: sim.steer_rad(),
        speed_cmd_mps: cmd.speed_mps,
        speed_mps: sim.speed_mps(),
        lookahead: cmd.lookahead_point,
        cross_track_m: cmd.cross_track_m,
        path_curvature_per_m: cmd.path_curvature_per_m,
        contact_force_n: sim.pallet_contact_force_n(),
    });
}

/// The tick's command under the caller's `control`.
fn applied(control: Control, cmd: Command, truck: &forkbench_core::ForkliftSpec) -> Command {
    let clamp = |speed_mps: f64, steer_rad: f64| {
        let finite = |v: f64| if v.is_finite() { v } else { 0.0 };
        (
            finite(speed_mps).clamp(-truck.max_speed_mps, truck.max_speed_mps),
            finite(steer_rad).clamp(-truck.max_steer_rad, truck.max_steer_rad),
        )
    };
    match control {
        Control::Tracker => cmd,
        Control::Residual {
            speed_mps,
            steer_rad,
        } => {
            let (speed_mps, steer_rad) =
                clamp(cmd.speed_mps + speed_mps, cmd.steer_rad + steer_rad);
            Command {
                speed_mps,
                steer_rad,
                ..cmd
            }
        }
        Control::Command {
            speed_mps,
            steer_rad,
        } => {
            let (speed_mps, steer_rad) = clamp(speed_mps, steer_rad);
            Command {
                speed_mps,
                steer_rad,
                lookahead_point: [f64::NAN; 2],
                cross_track_m: f64::NAN,
                remaining_m: f64::NAN,
                path_curvature_per_m: f64::NAN,
                done: false,
            }
        }
    }
}

/// Pending once, then ready: hands the tick back to whoever polls the trial.
struct Yield(bool);

impl Future for Yield {
    type Output = ();
    fn poll(mut self: Pin<&mut Self>, _cx: &mut Context<'_>) -> Poll<()> {
        if self.0 {
            Poll::Ready(())
        } else {
            self.0 = true;
            Poll::Pending
        }
    }
}
