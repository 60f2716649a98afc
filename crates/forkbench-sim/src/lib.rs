//! The rapier2d world of a pick trial: one rigid-body forklift with tyre impulses, pallets with stringers it can lift and carry, fixed racks.

mod actuator;
mod bodies;
mod load;
mod tyres;
mod view;
use bodies::{insert_obstacles, insert_pallet, insert_truck};

use forkbench_core::{ForkliftSpec, Pose2};
use rapier2d::prelude::*;
use serde::{Deserialize, Serialize};

pub use forkbench_core::PalletSpec;
pub use forkbench_core::geometry::Obstacle;
pub use load::LiftError;

/// Standard gravity, for tyre and floor normal loads (the plane itself has no gravity).
const G_MPS2: f64 = 9.81;

/// Settings of the physics model.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SimConfig {
    /// Fixed physics step (100 Hz by default).
    pub dt_s: f64,
    /// Tyre–floor friction coefficient: caps each axle's lateral tyre impulse, and the
    /// drive axle's traction and braking, at μ N dt.
    pub tyre_friction: f64,
    /// Pallet–floor friction coefficient.
    pub pallet_floor_friction: f64,
    /// Largest drive/brake acceleration.
    pub max_accel_mps2: f64,
    /// Proportional gain of the speed controller (1/s).
    pub speed_gain_per_s: f64,
    /// Friction between forks and pallet wood.
    pub fork_friction: f64,
}

impl Default for SimConfig {
    fn default() -> Self {
        Self {
            dt_s: 0.01,
            tyre_friction: 0.8,
            pallet_floor_friction: 0.4,
            max_accel_mps2: 1.0,
            speed_gain_per_s: 4.0,
            fork_friction: 0.3,
        }
    }
}

/// Why a world could not be built.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SimError {
    #[error("sim setting {0}")]
    Config(forkbench_core::SettingsError),
    #[error("pallet spec: {0}")]
    Pallet(forkbench_core::SettingsError),
    #[error("truck spec: {0}")]
    Truck(forkbench_core::SettingsError),
}

/// The simulated truck, pallet and obstacles.
pub struct Sim {
    world: PhysicsWorld,
    truck: RigidBodyHandle,
    forks: [ColliderHandle; 2],
    chassis: ColliderHandle,
    pallet: RigidBodyHandle,
    stringers: Vec<ColliderHandle>,
    obstacles: Vec<ColliderHandle>,
    spec: ForkliftSpec,
    pallet_spec: PalletSpec,
    cfg: SimConfig,
    steer_rad: f64,
    steering: actuator::Steering,
    drive: actuator::Drive,
    /// Steps taken; time is steps × dt, so it never drifts from float accumulation.
    steps: u64,
    truck_mass_kg: f64,
    truck_inertia: f64,
    /// Chassis centre (the centre of mass) ahead of the front axle, in the body frame.
    com_ahead_m: f64,
    pallet_inertia: f64,
    last_pallet_force_n: f64,
    last_mast_force_n: f64,
    last_obstacle_contact: bool,
    /// The pallet on the forks, once lifted.
    carried: Option<load::Carried>,
    load_shifted: bool,
    peak_load_accel_mps2: f64,
    /// The bodies' state as of the last step: read many times per control tick, and
    /// each read would otherwise redo the same trigonometry on unchanged bodies.
    now: Kinematics,
}

/// What the accessors report, computed once per step from the bodies.
#[derive(Debug, Clone, Copy)]
struct Kinematics {
    axle: Pose2,
    fork_root: Pose2,
    pallet: Pose2,
    speed_mps: f64,
    lateral_speed_mps: f64,
}

impl std::fmt::Debug for Sim {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Sim")
            .field("time_s", &self.time_s())
            .field("fork_root", &self.fork_root_pose())
            .field("pallet", &self.pallet_pose())
            .field("steer_rad", &self.steer_rad)
            .finish_non_exhaustive()
    }
}

pub(crate) fn v2(x: f64, y: f64) -> Vector {
    Vector::new(x as Real, y as Real)
}

fn cross(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[1] - a[1] * b[0]
}

/// `field` refused: `reason`, with the value given.
fn setting(field: &str, value: f64, reason: &str) -> forkbench_core::SettingsError {
    forkbench_core::SettingsError::field(field, format!("{reason} (got {value})"))
}

impl SimConfig {
    /// Checks every setting; scenario loading calls it so bad values fail at load.
    pub fn validate(&self) -> Result<(), forkbench_core::SettingsError> {
        let fields = [
            ("dt_s", self.dt_s),
            ("tyre_friction", self.tyre_friction),
            ("pallet_floor_friction", self.pallet_floor_friction),
            ("max_accel_mps2", self.max_accel_mps2),
            ("speed_gain_per_s", self.speed_gain_per_s),
        ];
        for (field, value) in fields {
            if !(value.is_finite() && value > 0.0) {
                return Err(setting(field, value, "must be a positive finite number"));
            }
        }
        if self.dt_s > 0.02 {
            return Err(setting(
                "dt_s",
                self.dt_s,
                "must be ≤ 0.02 s (50 Hz) for stable tyre impulses",
            ));
        }
        if self.dt_s < 1e-3 {
            return Err(setting(
                "dt_s",
                self.dt_s,
                "must be ≥ 0.001 s: a finer step only multiplies the work",
            ));
        }
        if !(self.fork_friction.is_finite() && self.fork_friction >= 0.0) {
            return Err(setting(
                "fork_friction",
                self.fork_friction,
                "must be a finite number ≥ 0",
            ));
        }
        forkbench_core::settings::in_ranges(&[
            ("tyre_friction", self.tyre_friction, 0.0, 5.0),
            (
                "pallet_floor_friction",
                self.pallet_floor_friction,
                0.0,
                5.0,
            ),
            ("fork_friction", self.fork_friction, 0.0, 5.0),
            ("max_accel_mps2", self.max_accel_mps2, 0.0, 50.0),
            ("speed_gain_per_s", self.speed_gain_per_s, 0.0, 1000.0),
        ])
    }
}

impl Sim {
    /// Builds the world. `start` is the fork-root pose; `pallet_pose` the pallet's front-face
    /// centre with heading pointing into the pallet (the direction the forks travel).
    pub fn new(
        spec: &ForkliftSpec,
        start: &Pose2,
        pallet_spec: &PalletSpec,
        pallet_pose: &Pose2,
        obstacles: &[Obstacle],
        cfg: &SimConfig,
    ) -> Result<Self, SimError> {
        spec.validate().map_err(SimError::Truck)?;
        pallet_spec.validate().map_err(SimError::Pallet)?;
        cfg.validate().map_err(SimError::Config)?;
        let mut world = PhysicsWorld::new();
        world.gravity = Vector::ZERO;
        world.integration_parameters.dt = cfg.dt_s as Real;

        let (truck, chassis, forks, com_ahead_m) = insert_truck(&mut world, spec, start, cfg);
        let truck_mass_kg = spec.mass_kg;
        let truck_inertia = bodies::truck_inertia(spec);
        let (pallet, stringers) = insert_pallet(&mut world, pallet_spec, pallet_pose, cfg);
        // The pallet stands on the floor with its payload.
        let pallet_inertia = pallet_spec.loaded_mass_kg()
            * (pallet_spec.depth_m.powi(2) + pallet_spec.width_m.powi(2))
            / 12.0;
        let obstacles = insert_obstacles(&mut world, obstacles);
        // Scene queries (the sensors' ray casts) read the broad phase, which a step fills:
        // fill it now, so the world can be seen before the first step.
        world.detect_collisions(&(), &());

        let mut sim = Self {
            world,
            truck,
            forks,
            chassis,
            pallet,
            stringers,
            obstacles,
            spec: spec.clone(),
            pallet_spec: pallet_spec.clone(),
            cfg: cfg.clone(),
            steer_rad: 0.0,
            steering: actuator::Steering::new(spec, cfg.dt_s),
            drive: actuator::Drive::new(spec, cfg.dt_s),
            steps: 0,
            truck_mass_kg,
            truck_inertia,
            com_ahead_m,
            pallet_inertia,
            last_pallet_force_n: 0.0,
            last_mast_force_n: 0.0,
            last_obstacle_contact: false,
            carried: None,
            load_shifted: false,
            peak_load_accel_mps2: 0.0,
            // Filled from the bodies just below.
            now: Kinematics {
                axle: *start,
                fork_root: *start,
                pallet: *pallet_pose,
                speed_mps: 0.0,
                lateral_speed_mps: 0.0,
            },
        };
        sim.now = sim.kinematics();
        Ok(sim)
    }

    /// The accessors' values, read from the bodies.
    fn kinematics(&self) -> Kinematics {
        let axle = self.body_pose(self.truck);
        let fork_root = axle.to_world(&Pose2::new(
            self.spec.fork_root_ahead_of_front_axle_m,
            0.0,
            0.0,
        ));
        let b = &self.world.bodies[self.truck];
        let v = b.velocity_at_point(b.translation());
        let (vx, vy) = (v.x as f64, v.y as f64);
        let pallet = match &self.carried {
            Some(c) => c.pallet_pose(&axle),
            None => self.body_pose(self.pallet),
        };
        Kinematics {
            axle,
            fork_root,
            pallet,
            speed_mps: vx * axle.heading_rad.cos() + vy * axle.heading_rad.sin(),
            lateral_speed_mps: -vx * axle.heading_rad.sin() + vy * axle.heading_rad.cos(),
        }
    }

    pub fn time_s(&self) -> f64 {
        self.steps as f64 * self.cfg.dt_s
    }

    pub fn dt_s(&self) -> f64 {
        self.cfg.dt_s
    }

    /// Actual (rate-limited) equivalent steering angle.
    pub fn steer_rad(&self) -> f64 {
        self.steer_rad
    }

    fn body_pose(&self, h: RigidBodyHandle) -> Pose2 {
        let b = &self.world.bodies[h];
        let t = b.translation();
        Pose2::new(t.x as f64, t.y as f64, b.rotation().angle() as f64)
    }

    /// Front-axle (kinematic origin) pose.
    pub fn front_axle_pose(&self) -> Pose2 {
        self.now.axle
    }

    /// Fork-root (path reference point) pose.
    pub fn fork_root_pose(&self) -> Pose2 {
        self.now.fork_root
    }

    /// Pallet front-face centre pose (moves if the pallet is pushed).
    pub fn pallet_pose(&self) -> Pose2 {
        self.now.pallet
    }

    pub fn pallet_spec(&self) -> &PalletSpec {
        &self.pallet_spec
    }

    /// Longitudinal speed of the front axle (what the drive encoder reads).
    pub fn speed_mps(&self) -> f64 {
        self.now.speed_mps
    }

    /// Lateral (side-slip) speed of the front axle.
    pub fn lateral_speed_mps(&self) -> f64 {
        self.now.lateral_speed_mps
    }

    pub fn yaw_rate_radps(&self) -> f64 {
        self.world.bodies[self.truck].angvel() as f64
    }

    /// Largest contact force between the truck (forks, chassis and mast) and the pallet
    /// in the last step.
    pub fn pallet_contact_force_n(&self) -> f64 {
        self.last_pallet_force_n
    }

    /// Largest contact force between the chassis (with the mast, whose face is the fork
    /// root) and the pallet in the last step: the truck pressing the pallet's face.
    pub fn mast_contact_force_n(&self) -> f64 {
        self.last_mast_force_n
    }

    /// Whether the truck touched a rack or wall in the last step.
    pub fn obstacle_contact(&self) -> bool {
        self.last_obstacle_contact
    }

    /// One fixed step with the commanded speed and steering angle, as the truck's
    /// actuators (`ForkliftSpec::steering`, `drive`, `control`) pass them on.
    pub fn step(&mut self, speed_cmd_mps: f64, steer_cmd_rad: f64) {
        let dt = self.cfg.dt_s;
        self.steer_rad = self.steering.step(steer_cmd_rad);
        self.apply_drive(speed_cmd_mps, dt);
        self.apply_tyres(dt);
        self.apply_pallet_floor_friction(dt);
        self.world.step();
        self.steps += 1;
        self.read_contacts(dt);
        self.now = self.kinematics();
        self.check_load(dt);
    }

    /// Coulomb floor friction on the pallet, as impulses that never reverse its motion.
    fn apply_pallet_floor_friction(&mut self, dt: f64) {
        if self.carried.is_some() {
            return;
        }
        let mu_g_dt = self.cfg.pallet_floor_friction * G_MPS2 * dt;
        let m = self.pallet_spec.loaded_mass_kg();
        let i = self.pallet_inertia;
        let b = &mut self.world.bodies[self.pallet];
        let v = b.linvel();
        let speed = (v.x as f64).hypot(v.y as f64);
        if speed > 0.0 {
            let dv = speed.min(mu_g_dt);
            let j = -m * dv / speed;
            b.apply_impulse(v2(j * v.x as f64, j * v.y as f64), true);
        }
        let w = b.angvel() as f64;
        // Friction torque of a uniformly loaded rectangle ≈ μ m g r̄, r̄ ≈ a third of its size.
        let r_mean = (self.pallet_spec.depth_m + self.pallet_spec.width_m) / 6.0;
        let dw = w.abs().min(mu_g_dt * m * r_mean / i);
        if w != 0.0 {
            b.apply_torque_impulse((-dw.copysign(w) * i) as Real, true);
        }
    }

    fn read_contacts(&mut self, dt: f64) {
        let np = &self.world.narrow_phase;
        let mut pallet_force = 0.0_f64;
        let mut mast_force = 0.0_f64;
        // Every body of the truck that can push the pallet: the forks, and the chassis with
        // its mast (whose face is the fork root), which a short-forked truck presses against
        // the pallet's face.
        for f in [self.forks[0], self.forks[1], self.chassis] {
            for &s in &self.stringers {
                if let Some(pair) = np.contact_pair(f, s)
                    && pair.has_any_active_contact()
                {
                    let n = pair.total_impulse_magnitude() as f64 / dt;
                    pallet_force = pallet_force.max(n);
                    if f == self.chassis {
                        mast_force = mast_force.max(n);
                    }
                }
            }
        }
        self.last_pallet_force_n = pallet_force;
        self.last_mast_force_n = mast_force;
        // A carried pallet is part of the truck: its stringers can hit a rack too.
        let load: &[ColliderHandle] = match self.carried {
            Some(_) => &self.stringers,
            None => &[],
        };
        let truck_colliders = [self.chassis, self.forks[0], self.forks[1]];
        // The truck's own pairs, not every (truck, obstacle) pair: a warehouse has many racks.
        self.last_obstacle_contact = truck_colliders.iter().chain(load).any(|&t| {
            np.contact_pairs_with(t).any(|p| {
                let other = if p.collider1 == t {
                    p.collider2
                } else {
                    p.collider1
                };
                p.has_any_active_contact() && self.obstacles.contains(&other)
            })
        });
    }
}
