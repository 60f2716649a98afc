//! Property tests: input checking never panics and names the field; the oblique search
//! stays within the grid (a cell plus the bisection's quarter cell) of its closed form
//! for any vehicle and angle.

use forkbench_corridor::{
    Junction, MARGIN_M, Mode, Resolution, Vehicle, check_inputs, min_width_m, oblique_min_width_m,
};
use proptest::prelude::*;

fn any_number() -> impl Strategy<Value = f64> {
    prop_oneof![
        Just(f64::NAN),
        Just(f64::INFINITY),
        Just(-1.0),
        Just(0.0),
        -10.0..10.0f64,
        0.0..200.0f64,
    ]
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, rng_seed: proptest::test_runner::RngSeed::Fixed(11), ..ProptestConfig::default() })]

    #[test]
    fn inputs_are_accepted_exactly_when_valid(
        length in any_number(),
        width in any_number(),
        corridor in proptest::option::of(any_number()),
        angle in any_number(),
        cell in any_number(),
        tee in any::<bool>(),
    ) {
        let v = Vehicle { length_m: length, width_m: width, kinematic_ahead_m: 0.0, min_radius_m: 0.0 };
        let junction = if tee { Junction::T } else { Junction::L };
        let valid = length.is_finite() && length > 0.0
            && width.is_finite() && width > 0.0 && width <= length
            && cell.is_finite() && cell > 0.0 && cell <= width / 4.0
            && corridor.is_none_or(|w| w.is_finite() && w > width)
            && angle.is_finite() && (0.0..=135.0).contains(&angle)
            && (!tee || angle == 90.0);
        match check_inputs(&v, junction, corridor, &[angle], cell) {
            Ok(()) => prop_assert!(valid),
            Err(e) => {
                prop_assert!(!valid, "{e}");
                let text = e.to_string();
                prop_assert!(
                    ["length_m", "width_m", "resolution_m", "angle_deg"].iter().any(|f| text.contains(f)),
                    "{text}"
                );
            }
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, rng_seed: proptest::test_runner::RngSeed::Fixed(12), ..ProptestConfig::default() })]

    #[test]
    fn oblique_search_is_within_the_grid_of_the_closed_form(
        length in 0.3..1.2f64,
        aspect in 0.3..1.0f64,
        angle_deg in 0.0..=135.0f64,
    ) {
        let v = Vehicle { length_m: length, width_m: length * aspect, kinematic_ahead_m: 0.0, min_radius_m: 0.0 };
        let cell = v.width_m / 10.0;
        let res = Resolution { cell_m: cell, heading_rad: 1f64.to_radians() };
        let th = angle_deg.to_radians();
        let w = min_width_m(&v, Mode::Oblique, Junction::L, th, res, 20.0).expect("passes");
        let exact = oblique_min_width_m(&v, th);
        // One cell for the lattice of the centre's offset across leg 2, a quarter cell for
        // the bisection's tolerance, and the clearance kept on both sides.
        let bound = 1.25 * cell + 2.0 * MARGIN_M;
        prop_assert!(w >= exact - 1e-9 && w - exact <= bound, "{angle_deg}°: {w} vs {exact}");
    }
}
