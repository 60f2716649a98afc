//! The criteria of the phases after the pick, under the pick's one trait: no rack or wall touched and the load held, observed at every step of every phase (`PHASE_CRITERIA`), and a pallet left standing that stayed where it stood, judged when a phase's move ends.

use forkbench_core::Pose2;
use forkbench_core::units::wrap_angle;

use super::{StepCriterion, StepCtor, StepView};
use crate::tolerances::Limits;

/// What every phase holds at every step, in the order of blame.
pub const PHASE_CRITERIA: &[StepCtor] = &[no_collision, load_held];

fn no_collision() -> Box<dyn StepCriterion> {
    Box::<NoCollision>::default()
}

fn load_held() -> Box<dyn StepCriterion> {
    Box::<LoadHeld>::default()
}

/// The truck touched no rack or wall.
#[derive(Debug, Default)]
pub struct NoCollision {
    touched: bool,
}

impl StepCriterion for NoCollision {
    fn name(&self) -> &'static str {
        "collision"
    }
    fn measure(&self) -> Option<&'static str> {
        None
    }
    fn describe(&self) -> &'static str {
        "the truck touched a rack or wall"
    }
    fn observe(&mut self, view: &StepView<'_>) {
        self.touched |= view.collision;
    }
    fn value(&self) -> Option<f64> {
        Some(f64::from(u8::from(self.touched)))
    }
    fn broken(&self) -> Option<String> {
        self.touched
            .then(|| "truck touched a rack or wall".to_owned())
    }
}

/// The carried load stayed on the forks: the truck never accelerated it harder than its
/// friction on them holds (μ g).
#[derive(Debug, Default)]
pub struct LoadHeld {
    seen: Option<super::LoadView>,
}

impl StepCriterion for LoadHeld {
    fn name(&self) -> &'static str {
        "load_shifted"
    }
    fn measure(&self) -> Option<&'static str> {
        None
    }
    fn describe(&self) -> &'static str {
        "the carried load's peak acceleration against what its friction on the forks holds"
    }
    fn observe(&mut self, view: &StepView<'_>) {
        self.seen = Some(view.load);
    }
    fn value(&self) -> Option<f64> {
        self.seen.map(|l| l.peak_accel_mps2)
    }
    fn broken(&self) -> Option<String> {
        let load = self.seen.filter(|l| l.shifted)?;
        Some(format!(
            "the load was accelerated at {:.2} m/s² (its friction on the forks holds {:.2} m/s²)",
            load.peak_accel_mps2, load.grip_mps2
        ))
    }
}

/// A pallet left standing stayed where it stood (the forks did not drag it) within the
/// pick's displacement and rotation limits.
#[derive(Debug)]
pub struct PalletStayed {
    from: Pose2,
    limits: Limits,
    now: Option<Pose2>,
}

impl PalletStayed {
    /// Judged against where the pallet stood, `from`, with the scenario's limits.
    pub fn new(from: Pose2, limits: &Limits) -> Self {
        Self {
            from,
            limits: limits.clone(),
            now: None,
        }
    }

    fn moved(&self) -> Option<(f64, f64)> {
        let now = self.now?;
        Some((
            now.distance_to(&self.from),
            wrap_angle(now.heading_rad - self.from.heading_rad),
        ))
    }
}

impl StepCriterion for PalletStayed {
    fn name(&self) -> &'static str {
        "pallet_displaced"
    }
    fn measure(&self) -> Option<&'static str> {
        None
    }
    fn describe(&self) -> &'static str {
        "how far the forks dragged and turned a pallet left standing"
    }
    fn observe(&mut self, view: &StepView<'_>) {
        self.now = Some(view.pallet_pose);
    }
    fn value(&self) -> Option<f64> {
        self.moved().map(|(m, _)| m)
    }
    fn broken(&self) -> Option<String> {
        let (moved, turned) = self.moved()?;
        let tol = &self.limits;
        (moved > tol.pallet_displacement_m || turned.abs() > tol.pallet_rotation_rad).then(|| {
            format!(
                "the forks dragged the pallet {moved:.3} m and turned it {:.2}° (limits {} m, {}°)",
                turned.to_degrees(),
                tol.pallet_displacement_m,
                tol.pallet_rotation_deg()
            )
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::step_criteria::LoadView;
    use forkbench_core::{ForkliftSpec, PalletSpec};

    fn judged(c: &mut dyn StepCriterion, pallet_pose: Pose2, collision: bool, load: LoadView) {
        let (truck, pallet) = (ForkliftSpec::default(), PalletSpec::field_1200());
        c.observe(&StepView {
            t_s: 1.0,
            truck: &truck,
            pallet: &pallet,
            fork_root: Pose2::new(-2.0, 0.0, 0.0),
            pallet_pose,
            collision,
            load,
        });
    }

    #[test]
    fn a_touch_and_a_shifted_load_break_theirs_with_the_measured_figures() {
        let still = Pose2::new(0.0, 0.0, 0.0);
        let mut c = NoCollision::default();
        judged(&mut c, still, false, LoadView::default());
        assert!(c.broken().is_none());
        judged(&mut c, still, true, LoadView::default());
        judged(&mut c, still, false, LoadView::default());
        assert_eq!(c.broken().as_deref(), Some("truck touched a rack or wall"));
        let mut l = LoadHeld::default();
        let shifted = LoadView {
            shifted: true,
            peak_accel_mps2: 1.0,
            grip_mps2: 0.49,
        };
        judged(&mut l, still, false, shifted);
        let why = l.broken().expect("shifted");
        assert!(
            why.contains("1.00 m/s²") && why.contains("0.49 m/s²"),
            "{why}"
        );
    }

    #[test]
    fn a_dragged_pallet_breaks_its_limits_and_one_left_alone_does_not() {
        let limits = Limits::default();
        let from = Pose2::new(1.0, 2.0, 0.3);
        let mut c = PalletStayed::new(from, &limits);
        judged(&mut c, from, false, LoadView::default());
        assert!(c.broken().is_none());
        let dragged = Pose2::new(1.0 + 2.0 * limits.pallet_displacement_m, 2.0, 0.3);
        judged(&mut c, dragged, false, LoadView::default());
        assert!(c.broken().expect("dragged").contains("dragged the pallet"));
    }
}
