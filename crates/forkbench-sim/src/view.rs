//! The simulator as the world sensors see: ray casts through rapier's query pipeline against every collider but the truck's own.

use forkbench_core::Pose2;
use forkbench_sensors::scan::{RayHit, Seen, Surface, WorldView};
use rapier2d::prelude::*;

use crate::{Sim, v2};

impl Sim {
    /// What a collider is to a sensor: a pallet's stringer or a fixed obstacle.
    fn seen(&self, handle: ColliderHandle) -> Seen {
        if self.stringers.contains(&handle) {
            Seen::Pallet(0)
        } else {
            Seen::Fixed
        }
    }
}

impl WorldView for Sim {
    fn cast_ray(&self, origin: [f64; 2], dir: [f64; 2], max_m: f64) -> Option<RayHit> {
        let ray = Ray::new(v2(origin[0], origin[1]), v2(dir[0], dir[1]));
        // The truck's chassis and forks are never seen: its sensors sit between the forks.
        let filter = QueryFilter::default().exclude_rigid_body(self.truck);
        let (handle, hit) =
            self.world
                .cast_ray_and_get_normal(&ray, max_m as Real, true, filter)?;
        Some(RayHit {
            range_m: f64::from(hit.time_of_impact),
            normal: [f64::from(hit.normal.x), f64::from(hit.normal.y)],
            seen: self.seen(handle),
        })
    }

    fn surfaces_near(&self, centre: [f64; 2], radius_m: f64, out: &mut Vec<Surface>) {
        for (handle, c) in self.world.colliders.iter() {
            if c.parent() == Some(self.truck) {
                continue;
            }
            let Some(cuboid) = c.shape().as_cuboid() else {
                continue;
            };
            let pose = c.position();
            let (hx, hy) = (
                f64::from(cuboid.half_extents.x),
                f64::from(cuboid.half_extents.y),
            );
            let t = pose.translation;
            let (tx, ty) = (f64::from(t.x), f64::from(t.y));
            if (tx - centre[0]).hypot(ty - centre[1]) > radius_m + hx.hypot(hy) {
                continue;
            }
            let at = Pose2::new(tx, ty, f64::from(pose.rotation.angle()));
            out.extend(Surface::rect(&at, 2.0 * hx, 2.0 * hy, self.seen(handle)));
        }
    }
}
