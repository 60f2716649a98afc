//! The simulator as the world sensors see: ray casts through rapier's query pipeline against every collider but the truck's own.

use forkbench_sensors::scan::{RayHit, Seen, Surface, WorldView};
use rapier2d::prelude::*;

use crate::{Sim, v2};

impl WorldView for Sim {
    fn cast_ray(&self, origin: [f64; 2], dir: [f64; 2], max_m: f64) -> Option<RayHit> {
        let ray = Ray::new(v2(origin[0], origin[1]), v2(dir[0], dir[1]));
        // The truck's chassis and forks are never seen: its sensors sit between the forks.
        let filter = QueryFilter::default().exclude_rigid_body(self.truck);
        let (handle, hit) =
            self.world
                .cast_ray_and_get_normal(&ray, max_m as Real, true, filter)?;
        let seen = match self.stringers.contains(&handle) {
            true => Seen::Pallet(0),
            false => Seen::Fixed,
        };
        Some(RayHit {
            range_m: f64::from(hit.time_of_impact),
            normal: [f64::from(hit.normal.x), f64::from(hit.normal.y)],
            seen,
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
            let (s, co) = f64::from(pose.rotation.angle()).sin_cos();
            let world = |x: f64, y: f64| [tx + co * x - s * y, ty + s * x + co * y];
            let corners = [
                world(hx, hy),
                world(-hx, hy),
                world(-hx, -hy),
                world(hx, -hy),
            ];
            let normals = [[-s, co], [-co, -s], [s, -co], [co, s]];
            let seen = match self.stringers.contains(&handle) {
                true => Seen::Pallet(0),
                false => Seen::Fixed,
            };
            for k in 0..4 {
                out.push(Surface {
                    a: corners[k],
                    b: corners[(k + 1) % 4],
                    normal: normals[k],
                    seen,
                });
            }
        }
    }
}
