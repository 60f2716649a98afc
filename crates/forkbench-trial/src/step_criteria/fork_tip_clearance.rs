//! Fork-tip clearance: the least lateral gap between a fork and the pallet's solid parts beside it while the tips are inside the pallet, in millimetres.

use forkbench_core::pallet::PalletBlock;
use forkbench_core::units::wrap_angle;

use super::{StepCriterion, StepView};

/// A fork pressed into a part by more than this has pushed it: the physics lets bodies
/// in contact overlap by about a millimetre.
const LIMIT_MM: f64 = -2.0;

/// The largest turn of the forks against the pallet axis at which they count as entering.
const MAX_TURN_RAD: f64 = 0.35;

#[derive(Debug, Default)]
struct ForkTipClearance {
    least_mm: Option<f64>,
    /// The pallet's parts, taken at the first step (a trial's pallet keeps its parts), so
    /// each step does not build them again.
    parts: Vec<PalletBlock>,
}

pub(super) fn build() -> Box<dyn StepCriterion> {
    Box::new(ForkTipClearance::default())
}

impl StepCriterion for ForkTipClearance {
    fn name(&self) -> &'static str {
        "fork_tip_clearance"
    }

    fn measure(&self) -> Option<&'static str> {
        Some("fork_tip_clearance_mm")
    }

    fn describe(&self) -> &'static str {
        "the least lateral gap between a fork and the solid parts beside it with the tips inside the pallet"
    }

    fn observe(&mut self, v: &StepView<'_>) {
        if self.parts.is_empty() {
            self.parts = v.pallet.parts();
        }
        if let Some(gap_m) = clearance_m(v, &self.parts) {
            let mm = gap_m * 1e3;
            self.least_mm = Some(self.least_mm.map_or(mm, |l| l.min(mm)));
        }
    }

    fn value(&self) -> Option<f64> {
        self.least_mm
    }

    fn broken(&self) -> Option<String> {
        self.least_mm.filter(|mm| *mm < LIMIT_MM).map(|mm| {
            format!(
                "a fork pressed {:.1} mm into a solid part (limit {:.0} mm)",
                -mm, -LIMIT_MM
            )
        })
    }
}

/// The least gap now between each fork's sides and the parts beside it whose depth span
/// the fork reaches, at the ends of that span (negative: how far the fork is into the
/// part, the lesser of across and along). A
/// part the fork's centre line runs into is not beside it: that fork is not in a pocket,
/// which the contact and entry criteria judge. `None` while the tips are outside the
/// pallet.
fn clearance_m(v: &StepView<'_>, parts: &[PalletBlock]) -> Option<f64> {
    let (truck, pallet) = (v.truck, v.pallet);
    let rel = v.pallet_pose.to_local(&v.fork_root);
    let (s, c) = wrap_angle(rel.heading_rad).sin_cos();
    // Turned further than this against the pallet, the forks are not entering pockets
    // (a pushed pallet has spun): nothing to measure.
    if c < MAX_TURN_RAD.cos() {
        return None;
    }
    let half_w = truck.fork_width_m / 2.0 / c;
    let mut least: Option<f64> = None;
    for offset in truck.fork_offsets_m() {
        // The fork's centre line in the pallet frame: from its root to its tip.
        let root = [rel.x_m - offset * s, rel.y_m + offset * c];
        let tip_x = root[0] + truck.fork_length_m * c;
        if tip_x <= 0.0 {
            continue;
        }
        let y_at = |x: f64| root[1] + (x - root[0]) * s / c;
        let inside = [root[0].max(0.0), tip_x.min(pallet.depth_m)];
        for part in parts {
            let ([x0, x1], [y0, y1]) = (part.x_range(), part.y_range());
            let (a, b) = (inside[0].max(x0), inside[1].min(x1));
            if a > b {
                continue;
            }
            for x in [a, b] {
                let y = y_at(x);
                if (y0..=y1).contains(&y) {
                    continue;
                }
                let across = (y0 - (y + half_w)).max((y - half_w) - y1);
                // Overlapping: in by the lesser of across and along (a tip just past the
                // front of a part it presses on is in by that much, not by its width).
                let gap = if across >= 0.0 {
                    across
                } else {
                    -(b - a).min(-across)
                };
                least = Some(least.map_or(gap, |l: f64| l.min(gap)));
            }
        }
    }
    least
}

#[cfg(test)]
mod tests {
    use forkbench_core::{ForkliftSpec, PalletSpec, Pose2};

    use super::*;

    /// The forks 0.5 m into the field pallet, `offset_m` off its axis.
    fn at(offset_m: f64, heading_rad: f64) -> ForkTipClearance {
        let (truck, pallet) = (ForkliftSpec::default(), PalletSpec::field_1200());
        let tips_in = 0.5;
        let mut c = ForkTipClearance::default();
        c.observe(&StepView {
            t_s: 0.0,
            truck: &truck,
            pallet: &pallet,
            fork_root: Pose2::new(tips_in - truck.fork_length_m, offset_m, heading_rad),
            pallet_pose: Pose2::new(0.0, 0.0, 0.0),
            collision: false,
            load: crate::step_criteria::LoadView::default(),
        });
        c
    }

    #[test]
    fn centred_forks_clear_the_stringers_by_half_the_pockets_play() {
        // (0.405 − 0.15) / 2 = 127.5 mm a side.
        let v = at(0.0, 0.0).value().expect("measured");
        assert!((v - 127.5).abs() < 1e-6, "{v}");
        let v = at(0.1, 0.0).value().expect("measured");
        assert!((v - 27.5).abs() < 1e-6, "{v}");
        assert!(at(0.1, 0.0).broken().is_none());
    }

    #[test]
    fn a_fork_into_a_stringer_breaks_it_and_turned_forks_are_not_measured() {
        let c = at(0.14, 0.0);
        let v = c.value().expect("measured");
        assert!((v + 12.5).abs() < 1e-6, "{v}");
        assert!(c.broken().expect("broken").contains("12.5 mm"));
        assert_eq!(at(0.0, 0.6).value(), None);
        // Outside the pallet: nothing yet.
        let (truck, pallet) = (ForkliftSpec::default(), PalletSpec::field_1200());
        let mut c = ForkTipClearance::default();
        c.observe(&StepView {
            t_s: 0.0,
            truck: &truck,
            pallet: &pallet,
            fork_root: Pose2::new(-2.0, 0.0, 0.0),
            pallet_pose: Pose2::new(0.0, 0.0, 0.0),
            collision: false,
            load: crate::step_criteria::LoadView::default(),
        });
        assert_eq!(c.value(), None);
    }
}
