//! Judge stage: final errors, pallet displacement, and the first failed criterion in check order.

use forkbench_core::Pose2;
use forkbench_core::units::wrap_angle;

use super::state::Trial;
use crate::outcome::Failure;
use crate::step_criteria::{Judged, PickMeasures};
use crate::text::compact_numbers;

/// Fork-root pose in the pallet frame: x < 0 before the face, y the lateral offset.
pub(super) fn in_pallet_frame(pallet: &Pose2, root: &Pose2) -> Pose2 {
    pallet.to_local(root)
}

/// Where the forks stand against the pallet now: the fork root in the pallet frame, the
/// insertion depth, how far the pallet moved and turned, the worst fork's lateral miss of
/// its pocket.
pub(crate) struct Standing {
    pub local: Pose2,
    pub insertion_depth_m: f64,
    pub pallet_displacement_m: f64,
    pub pallet_rotation_rad: f64,
    pub worst_pocket_miss_m: f64,
}

impl<'a> Trial<'a> {
    /// Writes the final measurements and the verdict into the outcome.
    pub(super) fn conclude(&mut self) {
        let now = self.measure();
        let m = self.pick_measures(&now, self.verdict.timed_out);
        let judged = self.judged(m);
        let (mut broken, mut robustness) = (Vec::new(), None::<f64>);
        for c in &self.verdict.criteria {
            if let (Some(key), Some(v)) = (c.measure(), c.value()) {
                self.verdict.out.measures.insert(key.to_owned(), v);
            }
            if let Some(why) = c.judge(&judged) {
                broken.push((Failure::of_criterion(c.name()), why));
            }
            if let Some(margin) = c.margin(&judged) {
                robustness = Some(robustness.map_or(margin, |r| r.min(margin)));
            }
        }
        // The least margin over the criteria that keep one; negative when one is broken.
        self.verdict.out.robustness = robustness;
        let mut broken = broken.into_iter();
        match broken.next() {
            Some((f, why)) => {
                self.verdict.out.also_failed = broken
                    .map(|(f, why)| format!("{}: {}", f.name(), compact_numbers(&why)))
                    .collect();
                self.verdict.out.likely_cause = likely_cause(self);
                self.verdict.out.fail(f, why);
            }
            None => self.verdict.out.success = true,
        }
    }

    /// The pick's measurements with the scenario's limits, truck and pallet.
    pub(super) fn judged(&self, m: PickMeasures) -> Judged<'a> {
        let scn = self.scn;
        Judged {
            m,
            tol: &scn.tolerances,
            truck: &scn.truck,
            pallet: &scn.pallet,
            timeout_s: scn.timeout_s,
        }
    }

    /// The pick's measurements: where the forks stand `now`, what the drive recorded
    /// (contact force, the entry errors), whether it ran out of time. Before the pick
    /// ends, `now` is this step's standing (nothing written to the outcome): what a
    /// caller-driven pick is judged on.
    pub(super) fn pick_measures(&self, now: &Standing, timed_out: bool) -> PickMeasures {
        let out = &self.verdict.out;
        PickMeasures {
            collision: self.world.collision,
            timed_out,
            max_contact_force_n: out.max_contact_force_n,
            mast_contact_force_n: out.mast_contact_force_n,
            pallet_displacement_m: now.pallet_displacement_m,
            pallet_rotation_rad: now.pallet_rotation_rad,
            lateral_error_m: out.lateral_error_m,
            heading_error_rad: out.heading_error_rad,
            insertion_depth_m: now.insertion_depth_m,
            worst_pocket_miss_m: now.worst_pocket_miss_m,
        }
    }

    /// The outcome's simulated time: now.
    pub(super) fn stamp_time(&mut self) {
        self.verdict.out.sim_time_s = self.world.sim.time_s();
    }

    /// The simulated time and the localisation so far: all a trial that ended before its
    /// drive to the pallet measured (the forks were never brought to it).
    pub(crate) fn measure_time(&mut self) {
        self.stamp_time();
        let period_s = self.loc.localizer.period_s();
        self.loc
            .stats
            .finish_trial(self.verdict.out.sim_time_s, period_s, &mut self.verdict.out);
    }

    /// The trial's measurements as it stands now (time, localisation, where the forks are
    /// against the pallet, how far the pallet moved), kept also when it ends in an error;
    /// returns where the forks stand.
    pub(crate) fn measure(&mut self) -> Standing {
        self.measure_time();
        let now = self.standing();
        let out = &mut self.verdict.out;
        out.final_lateral_error_m = now.local.y_m;
        out.final_heading_error_rad = now.local.heading_rad;
        out.insertion_depth_m = now.insertion_depth_m;
        out.pallet_displacement_m = now.pallet_displacement_m;
        out.pallet_rotation_rad = now.pallet_rotation_rad;
        now
    }

    /// Where the forks stand against the pallet now, and how far it moved.
    pub(super) fn standing(&self) -> Standing {
        let truck = &self.scn.truck;
        let root = self.world.sim.fork_root_pose();
        let pallet_now = self.world.sim.pallet_pose();
        let pockets = self.scn.pallet.pocket_offsets_m();
        let worst_pocket_miss_m = truck
            .fork_points(&root, truck.fork_length_m / 2.0)
            .iter()
            .zip(pockets)
            // Lateral position of the fork's middle in the pallet frame, against its pocket.
            .map(|(mid, py)| (pallet_now.to_local(mid).y_m - py).abs())
            .fold(0.0, f64::max);
        Standing {
            local: in_pallet_frame(&pallet_now, &root),
            insertion_depth_m: truck.insertion_depth_m(&pallet_now, self.scn.pallet.depth_m, &root),
            pallet_displacement_m: pallet_now.distance_to(&self.world.pallet0),
            pallet_rotation_rad: wrap_angle(
                pallet_now.heading_rad - self.world.pallet0.heading_rad,
            ),
            worst_pocket_miss_m,
        }
    }
}

/// What most likely made a trial fail, in the order a reviewer would look: the pallet
/// estimate the truck last aimed at (off by more than half the entry limits), then the
/// steering held at its limit. `None` when neither stands out.
fn likely_cause(t: &Trial<'_>) -> Option<String> {
    let (out, tol, truck) = (&t.verdict.out, &t.scn.tolerances, &t.scn.truck);
    let lateral = out.estimate_lateral_error_m.unwrap_or(0.0);
    let heading = out.estimate_heading_error_rad.unwrap_or(0.0);
    if lateral.abs() > tol.lateral_m / 2.0 || heading.abs() > tol.heading_rad / 2.0 {
        return Some(format!(
            "the pallet estimate the truck last aimed at was {lateral:.3} m and {:.2}° off the \
             true pallet",
            heading.to_degrees()
        ));
    }
    (out.max_steer_rad >= 0.98 * truck.max_steer_rad).then(|| {
        format!(
            "the steering reached its limit ({:.1}°): the path asked for more curvature than \
             the truck has",
            truck.max_steer_rad.to_degrees()
        )
    })
}
