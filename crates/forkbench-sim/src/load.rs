//! Carrying a pallet: lifting it onto the forks, the loaded truck's mass distribution, and the load sliding off.

use super::*;

/// Why a pallet could not be lifted.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum LiftError {
    #[error("the truck already carries the pallet")]
    AlreadyCarrying,
    #[error(
        "the forks are {depth_m:.3} m under the pallet (at least {required_m:.3} m, half the pallet, needed to lift it)"
    )]
    NotUnder { depth_m: f64, required_m: f64 },
    #[error(
        "the pallet weighs {load_kg:.0} kg with its payload, more than the truck's rated {rated_kg:.0} kg"
    )]
    OverCapacity { load_kg: f64, rated_kg: f64 },
    #[error(
        "the loaded truck's centre of mass would lie {ahead_m:.3} m ahead of its front axle: it would tip"
    )]
    WouldTip { ahead_m: f64 },
}

/// The truck's own mass properties, which lowering the load restores.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Unloaded {
    mass_kg: f64,
    inertia: f64,
    com_ahead_m: f64,
}

/// A pallet on the forks.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Carried {
    /// The pallet's face pose in the truck's body frame (origin at the front axle).
    on_forks: Pose2,
    unloaded: Unloaded,
    /// Velocity of the load's centre after the last step, for its acceleration.
    last_velocity_mps: [f64; 2],
}

impl Carried {
    /// The pallet's face pose in the world, given the truck's front-axle pose.
    pub(crate) fn pallet_pose(&self, axle: &Pose2) -> Pose2 {
        axle.to_world(&self.on_forks)
    }
}

/// A rapier pose from a bench pose.
fn rapier_pose(p: &Pose2) -> Pose {
    Pose::new(v2(p.x_m, p.y_m), p.heading_rad as Real)
}

impl Sim {
    /// Whether the pallet rides on the forks.
    pub fn carrying(&self) -> bool {
        self.carried.is_some()
    }

    /// Whether a carried load slid on the forks (the truck's acceleration at the load
    /// exceeded its friction on them); the load then came off the forks.
    pub fn load_shifted(&self) -> bool {
        self.load_shifted
    }

    /// Largest acceleration of the carried load's centre since it was lifted.
    pub fn peak_load_accel_mps2(&self) -> f64 {
        self.peak_load_accel_mps2
    }

    /// The largest acceleration a carried load's friction on the forks holds (μ g).
    pub fn load_grip_mps2(&self) -> f64 {
        self.cfg.fork_friction * G_MPS2
    }

    /// Static normal loads on the front (drive) and rear (steer) axles, from where the
    /// centre of mass of the truck and whatever it carries sits between them.
    pub fn axle_loads_n(&self) -> [f64; 2] {
        let rear_share = (-self.com_ahead_m / self.spec.wheelbase_m).clamp(0.0, 1.0);
        let w = self.truck_mass_kg * G_MPS2;
        [w * (1.0 - rear_share), w * rear_share]
    }

    /// Lifts the pallet onto the forks: from now on it rides with the truck as one rigid
    /// body, its mass (with the payload) moving the centre of mass toward the forks.
    pub fn lift(&mut self) -> Result<(), LiftError> {
        if self.carried.is_some() {
            return Err(LiftError::AlreadyCarrying);
        }
        let load_kg = self.pallet_spec.loaded_mass_kg();
        if load_kg > self.spec.rated_capacity_kg {
            return Err(LiftError::OverCapacity {
                load_kg,
                rated_kg: self.spec.rated_capacity_kg,
            });
        }
        let (axle, pallet) = (self.front_axle_pose(), self.pallet_pose());
        let depth_m =
            self.spec
                .insertion_depth_m(&pallet, self.pallet_spec.depth_m, &self.fork_root_pose());
        let required_m = self.pallet_spec.depth_m / 2.0;
        if depth_m < required_m {
            return Err(LiftError::NotUnder {
                depth_m,
                required_m,
            });
        }
        let on_forks = axle.to_local(&pallet);
        let load_centre_ahead_m = self.load_centre(&on_forks).x_m;
        let m = self.truck_mass_kg;
        let ahead_m = (m * self.com_ahead_m + load_kg * load_centre_ahead_m) / (m + load_kg);
        if ahead_m >= 0.0 {
            return Err(LiftError::WouldTip { ahead_m });
        }
        let unloaded = Unloaded {
            mass_kg: m,
            inertia: self.truck_inertia,
            com_ahead_m: self.com_ahead_m,
        };
        self.move_stringers(self.truck, &on_forks);
        self.world.bodies[self.pallet].set_enabled(false);
        self.refresh_truck_mass();
        let mut carried = Carried {
            on_forks,
            unloaded,
            last_velocity_mps: [0.0; 2],
        };
        carried.last_velocity_mps = self.load_velocity(&carried);
        self.carried = Some(carried);
        self.now = self.kinematics();
        Ok(())
    }

    /// Sets the carried pallet down where it is, moving as the forks move; it stands on
    /// the floor again. Nothing happens when nothing is carried.
    pub fn lower(&mut self) {
        let Some(c) = self.carried.take() else {
            return;
        };
        let face = c.pallet_pose(&self.front_axle_pose());
        let [vx, vy] = self.load_velocity(&c);
        let w = self.world.bodies[self.truck].angvel();
        self.move_stringers(self.pallet, &Pose2::new(0.0, 0.0, 0.0));
        let p = &mut self.world.bodies[self.pallet];
        p.set_enabled(true);
        p.set_position(rapier_pose(&face), true);
        p.set_linvel(v2(vx, vy), true);
        p.set_angvel(w, true);
        p.recompute_mass_properties_from_colliders(&self.world.colliders);
        self.truck_mass_kg = c.unloaded.mass_kg;
        self.truck_inertia = c.unloaded.inertia;
        self.com_ahead_m = c.unloaded.com_ahead_m;
        self.world.bodies[self.truck]
            .recompute_mass_properties_from_colliders(&self.world.colliders);
        self.now = self.kinematics();
    }

    /// Re-parents the stringers to `body`, placing the pallet face at `face` in its frame.
    fn move_stringers(&mut self, body: RigidBodyHandle, face: &Pose2) {
        let boxes = self.pallet_spec.part_boxes(face);
        for (&s, (centre, _, _)) in self.stringers.iter().zip(boxes) {
            let colliders = &mut self.world.colliders;
            colliders.set_parent(s, Some(body), &mut self.world.bodies);
            colliders[s].set_position_wrt_parent(rapier_pose(&centre));
        }
    }

    /// The truck body's mass, inertia and centre of mass from its colliders (chassis and,
    /// when carrying, the stringers), for the tyre and drive models.
    fn refresh_truck_mass(&mut self) {
        let b = &mut self.world.bodies[self.truck];
        b.recompute_mass_properties_from_colliders(&self.world.colliders);
        let props = &b.mass_properties().local_mprops;
        self.truck_mass_kg = f64::from(props.mass());
        self.truck_inertia = f64::from(props.principal_inertia());
        self.com_ahead_m = f64::from(props.local_com.x);
    }

    /// The centre of a pallet (where its load sits) whose face is at `face`.
    fn load_centre(&self, face: &Pose2) -> Pose2 {
        face.to_world(&Pose2::new(self.pallet_spec.depth_m / 2.0, 0.0, 0.0))
    }

    /// World velocity of the carried load's centre.
    fn load_velocity(&self, c: &Carried) -> [f64; 2] {
        let centre = self.load_centre(&c.pallet_pose(&self.front_axle_pose()));
        let v = self.world.bodies[self.truck].velocity_at_point(v2(centre.x_m, centre.y_m));
        [f64::from(v.x), f64::from(v.y)]
    }

    /// After a step: the load's acceleration against its friction on the forks. A load
    /// pushed harder than friction can hold slides off and stands free on the floor.
    pub(crate) fn check_load(&mut self, dt: f64) {
        let Some(mut c) = self.carried else {
            return;
        };
        let v = self.load_velocity(&c);
        let accel = (v[0] - c.last_velocity_mps[0]).hypot(v[1] - c.last_velocity_mps[1]) / dt;
        self.peak_load_accel_mps2 = self.peak_load_accel_mps2.max(accel);
        c.last_velocity_mps = v;
        self.carried = Some(c);
        if accel > self.load_grip_mps2() {
            self.load_shifted = true;
            self.lower();
        }
    }
}
