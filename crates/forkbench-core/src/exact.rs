//! Fixed-length number arrays read from users' files with their length checked: a point written with a third number is refused, not cut short.

use serde::{Deserialize, Deserializer, de::Error as _};

fn exactly<const N: usize, E: serde::de::Error>(v: &[f64]) -> Result<[f64; N], E> {
    <[f64; N]>::try_from(v).map_err(|_| {
        E::custom(format!(
            "expected {N} numbers in each array, got {} ({v:?})",
            v.len()
        ))
    })
}

/// One `[a, b, …]` of exactly `N` numbers (`#[serde(deserialize_with = "…::array")]`).
pub fn array<'de, D: Deserializer<'de>, const N: usize>(d: D) -> Result<[f64; N], D::Error> {
    exactly(&Vec::<f64>::deserialize(d)?)
}

/// A list of points or corners, each exactly `N` numbers.
pub fn arrays<'de, D: Deserializer<'de>, const N: usize>(d: D) -> Result<Vec<[f64; N]>, D::Error> {
    Vec::<Vec<f64>>::deserialize(d)?
        .iter()
        .enumerate()
        .map(|(i, v)| exactly(v).map_err(|e: D::Error| D::Error::custom(format!("item {i}: {e}"))))
        .collect()
}

#[cfg(test)]
mod tests {
    #[derive(serde::Deserialize, Debug)]
    struct Route {
        #[serde(deserialize_with = "super::arrays")]
        points: Vec<[f64; 2]>,
        #[serde(deserialize_with = "super::array")]
        span: [f64; 2],
    }

    #[test]
    fn a_third_number_is_refused_and_two_are_read() {
        let ok: Route = toml::from_str("points = [[1, 2], [3, 4]]\nspan = [0, 1]").expect("reads");
        assert_eq!(ok.points, vec![[1.0, 2.0], [3.0, 4.0]]);
        assert_eq!(ok.span, [0.0, 1.0]);
        let e = toml::from_str::<Route>("points = [[1, 2, 9], [3, 4]]\nspan = [0, 1]")
            .expect_err("three numbers");
        assert!(e.to_string().contains("item 0: expected 2 numbers"), "{e}");
        let e = toml::from_str::<Route>("points = [[1, 2]]\nspan = [0, 1, 2]").expect_err("span");
        assert!(e.to_string().contains("expected 2 numbers"), "{e}");
    }
}
