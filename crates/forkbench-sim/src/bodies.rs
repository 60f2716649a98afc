//! The rigid bodies and colliders of a trial's world: truck, pallet, racks and walls.

use super::*;

/// The truck's body (origin at the front axle centre, +x toward the forks), its chassis
/// (carrying the mass, unless axle loads place it) and its two massless forks; also the
/// centre of mass's offset ahead of the fixed axle.
pub(crate) fn insert_truck(
    world: &mut PhysicsWorld,
    spec: &ForkliftSpec,
    start: &Pose2,
    cfg: &SimConfig,
) -> (RigidBodyHandle, ColliderHandle, [ColliderHandle; 2], f64) {
    // Truck: body origin at the front (drive) axle centre, +x forward (fork side).
    let d = spec.fork_root_ahead_of_front_axle_m;
    let (s, c) = start.heading_rad.sin_cos();
    let axle = [start.x_m - c * d, start.y_m - s * d];
    let mut body = RigidBodyBuilder::dynamic()
        .translation(v2(axle[0], axle[1]))
        .rotation(start.heading_rad as Real)
        .can_sleep(false);
    // Chassis (with the mast) ends at the fork root. Without declared axle loads it
    // carries all the mass, so the inertia is that of a solid body of its outline; with
    // them the mass sits where they put it, with the same inertia about that point.
    let chassis_front = d;
    let chassis_centre = chassis_front - spec.body_length_m / 2.0;
    let declared = spec.axle_load_fixed_kg.is_some();
    if declared {
        let com = spec.mass_centre_ahead_of_front_axle_m();
        body = body.additional_mass_properties(MassProperties::new(
            v2(com, 0.0),
            spec.mass_kg as Real,
            truck_inertia(spec) as Real,
        ));
    }
    let truck = world.insert_body(body);
    let chassis = ColliderBuilder::cuboid(
        (spec.body_length_m / 2.0) as Real,
        (spec.body_width_m / 2.0) as Real,
    )
    .translation(v2(chassis_centre, 0.0))
    .friction(0.5);
    let chassis = match declared {
        true => chassis.density(0.0),
        false => chassis.mass(spec.mass_kg as Real),
    };
    let chassis = world.insert_collider(chassis, Some(truck));
    let fork = |side: f64| {
        ColliderBuilder::cuboid(
            (spec.fork_length_m / 2.0) as Real,
            (spec.fork_width_m / 2.0) as Real,
        )
        .translation(v2(
            d + spec.fork_length_m / 2.0,
            side * spec.fork_spacing_m / 2.0,
        ))
        .density(0.0)
        .friction(cfg.fork_friction as Real)
    };
    let forks = [
        world.insert_collider(fork(1.0), Some(truck)),
        world.insert_collider(fork(-1.0), Some(truck)),
    ];
    (
        truck,
        chassis,
        forks,
        spec.mass_centre_ahead_of_front_axle_m(),
    )
}

/// The unladen truck's moment of inertia about its centre of mass: a solid body of the
/// chassis outline's.
pub(crate) fn truck_inertia(spec: &ForkliftSpec) -> f64 {
    spec.mass_kg * (spec.body_length_m.powi(2) + spec.body_width_m.powi(2)) / 12.0
}

/// The pallet's body and its solid parts (stringers or blocks), in its face frame.
pub(crate) fn insert_pallet(
    world: &mut PhysicsWorld,
    pallet_spec: &PalletSpec,
    pallet_pose: &Pose2,
    cfg: &SimConfig,
) -> (RigidBodyHandle, Vec<ColliderHandle>) {
    // Pallet: stringers run along its heading from the face to the back. It may sleep
    // while it stands untouched (a contact wakes it), which spares the solver its body.
    let pallet = world.insert_body(
        RigidBodyBuilder::dynamic()
            .translation(v2(pallet_pose.x_m, pallet_pose.y_m))
            .rotation(pallet_pose.heading_rad as Real)
            .can_sleep(true),
    );
    let parts = pallet_spec.parts();
    let area = |b: &forkbench_core::pallet::PalletBlock| b.length_m * b.width_m;
    let total: f64 = parts.iter().map(area).sum();
    let equal = parts.iter().all(|b| area(b) == area(&parts[0]));
    let mut colliders = Vec::new();
    for b in &parts {
        // The load spread over the parts by their footprint.
        let mass = if equal {
            pallet_spec.loaded_mass_kg() / parts.len() as f64
        } else {
            pallet_spec.loaded_mass_kg() * area(b) / total
        };
        colliders.push(
            world.insert_collider(
                ColliderBuilder::cuboid((b.length_m / 2.0) as Real, (b.width_m / 2.0) as Real)
                    .translation(v2(b.x_m, b.y_m))
                    .mass(mass as Real)
                    .friction(cfg.fork_friction as Real),
                Some(pallet),
            ),
        );
    }
    (pallet, colliders)
}

/// Racks and walls: fixed colliders.
pub(crate) fn insert_obstacles(
    world: &mut PhysicsWorld,
    obstacles: &[Obstacle],
) -> Vec<ColliderHandle> {
    obstacles
        .iter()
        .map(|o| {
            world.insert_collider(
                ColliderBuilder::cuboid((o.length_m / 2.0) as Real, (o.width_m / 2.0) as Real)
                    .translation(v2(o.centre.x_m, o.centre.y_m))
                    .rotation(o.centre.heading_rad as Real),
                None,
            )
        })
        .collect()
}
