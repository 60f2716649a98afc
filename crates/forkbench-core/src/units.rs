//! Angle helpers: SI (radians) inside, degrees only at the user interface.

use std::f64::consts::{PI, TAU};

/// Degrees to radians (for values arriving from a user).
pub fn deg_to_rad(deg: f64) -> f64 {
    deg.to_radians()
}

/// Radians to degrees (for values shown to a user).
pub fn rad_to_deg(rad: f64) -> f64 {
    rad.to_degrees()
}

/// Wraps an angle into (-π, π].
pub fn wrap_angle(a_rad: f64) -> f64 {
    let mut a = a_rad.rem_euclid(TAU);
    if a > PI {
        a -= TAU;
    }
    a
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wrap_keeps_range() {
        for k in -20..=20 {
            let a = k as f64 * 0.7;
            let w = wrap_angle(a);
            assert!(w > -PI - 1e-12 && w <= PI + 1e-12, "{a} -> {w}");
            assert!(((a - w) / TAU - ((a - w) / TAU).round()).abs() < 1e-9);
        }
        assert!((wrap_angle(PI) - PI).abs() < 1e-15);
        assert!((wrap_angle(-PI) - PI).abs() < 1e-15);
    }
}
