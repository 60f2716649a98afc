//! Small numerical kernels the planners share: Gauss–Legendre rules, Brent minimiser, peak search.

use std::sync::OnceLock;

/// Gauss–Legendre nodes and weights on [-1, 1].
#[derive(Debug, Clone)]
pub struct GaussLegendre {
    pub nodes: Vec<f64>,
    pub weights: Vec<f64>,
}

impl GaussLegendre {
    /// Builds an n-point rule by Newton iteration on the Legendre polynomial.
    pub fn new(n: usize) -> Self {
        let mut nodes = vec![0.0; n];
        let mut weights = vec![0.0; n];
        let nf = n as f64;
        for i in 0..n.div_ceil(2) {
            let mut x = (std::f64::consts::PI * (i as f64 + 0.75) / (nf + 0.5)).cos();
            let mut dp = 1.0;
            for _ in 0..100 {
                let (mut p0, mut p1) = (1.0, x);
                for k in 2..=n {
                    let kf = k as f64;
                    let p2 = ((2.0 * kf - 1.0) * x * p1 - (kf - 1.0) * p0) / kf;
                    p0 = p1;
                    p1 = p2;
                }
                // p1 = P_n(x), p0 = P_{n-1}(x)
                dp = nf * (x * p1 - p0) / (x * x - 1.0);
                let dx = p1 / dp;
                x -= dx;
                if dx.abs() < 1e-16 {
                    break;
                }
            }
            let w = 2.0 / ((1.0 - x * x) * dp * dp);
            nodes[i] = -x;
            nodes[n - 1 - i] = x;
            weights[i] = w;
            weights[n - 1 - i] = w;
        }
        Self { nodes, weights }
    }

    /// Shared 12-point rule: error ~ (T/24)^24 for a turning T per panel, so ≤ 1e-14
    /// for panels of up to 6 rad.
    pub fn rule12() -> &'static GaussLegendre {
        static RULE: OnceLock<GaussLegendre> = OnceLock::new();
        RULE.get_or_init(|| GaussLegendre::new(12))
    }

    /// Shared 16-point rule: exact for polynomials to degree 31 (the spiral's cost
    /// ∫½κ² has degree 8).
    pub fn rule16() -> &'static GaussLegendre {
        static RULE: OnceLock<GaussLegendre> = OnceLock::new();
        RULE.get_or_init(|| GaussLegendre::new(16))
    }
}

/// Largest |f(u)| over [lo, hi]: dense sampling, then parabolic refinement of the peak.
///
/// Returns (u at the peak, |f| there). Used for curvature peaks, which are smooth.
pub fn max_abs_on_interval(
    f: impl Fn(f64) -> f64,
    lo: f64,
    hi: f64,
    samples: usize,
    refine_iters: usize,
) -> (f64, f64) {
    // A stack buffer: this runs in the optimisers' innermost loop.
    const MAX_SAMPLES: usize = 128;
    let n = samples.clamp(2, MAX_SAMPLES);
    let h = (hi - lo) / n as f64;
    let (mut best_i, mut best) = (0, f64::NEG_INFINITY);
    let mut vals = [0.0; MAX_SAMPLES + 1];
    for (i, slot) in vals.iter_mut().enumerate().take(n + 1) {
        let v = f(lo + h * i as f64).abs();
        let v = if v.is_nan() { f64::INFINITY } else { v };
        *slot = v;
        if v > best {
            best = v;
            best_i = i;
        }
    }
    if best_i == 0 || best_i == n || !best.is_finite() {
        return (lo + h * best_i as f64, best);
    }
    // Successive parabolic interpolation on the bracketing triple: |κ| is smooth near
    // its peaks, so a few steps reach ~1e-9 relative; a bad parabola ends the loop.
    let (mut xs, mut fs) = (
        [
            lo + h * (best_i - 1) as f64,
            lo + h * best_i as f64,
            lo + h * (best_i + 1) as f64,
        ],
        [vals[best_i - 1], vals[best_i], vals[best_i + 1]],
    );
    let (mut bu, mut bv) = (xs[1], fs[1]);
    for _ in 0..refine_iters {
        let (d1, d2) = (xs[1] - xs[0], xs[1] - xs[2]);
        let (g1, g2) = (fs[1] - fs[0], fs[1] - fs[2]);
        let den = d1 * g2 - d2 * g1;
        if den.abs() < 1e-300 {
            break;
        }
        let u = xs[1] - 0.5 * (d1 * d1 * g2 - d2 * d2 * g1) / den;
        if !(u > xs[0] && u < xs[2]) || (u - xs[1]).abs() < 1e-12 * (hi - lo) {
            break;
        }
        let v = f(u).abs();
        if v > bv {
            (bu, bv) = (u, v);
        }
        // Keep the best point in the middle of the new bracket.
        if v >= fs[1] {
            if u < xs[1] {
                xs = [xs[0], u, xs[1]];
                fs = [fs[0], v, fs[1]];
            } else {
                xs = [xs[1], u, xs[2]];
                fs = [fs[1], v, fs[2]];
            }
        } else if u < xs[1] {
            xs[0] = u;
            fs[0] = v;
        } else {
            xs[2] = u;
            fs[2] = v;
        }
    }
    (bu, bv)
}

/// Brent's minimiser (golden section with parabolic steps) on [lo, hi] to tolerance `tol`.
pub fn brent_min(mut f: impl FnMut(f64) -> f64, lo: f64, hi: f64, tol: f64) -> (f64, f64) {
    const CGOLD: f64 = 0.381_966_011_250_105_1;
    let (mut a, mut b) = (lo, hi);
    let mut x = a + CGOLD * (b - a);
    let (mut w, mut v) = (x, x);
    let mut fx = f(x);
    let (mut fw, mut fv) = (fx, fx);
    let (mut d, mut e) = (0.0_f64, 0.0_f64);
    for _ in 0..100 {
        let xm = 0.5 * (a + b);
        let tol1 = tol / 2.0 + 1e-12 * x.abs();
        let tol2 = 2.0 * tol1;
        if (x - xm).abs() <= tol2 - 0.5 * (b - a) {
            break;
        }
        let mut golden = true;
        if e.abs() > tol1 && fx.is_finite() && fw.is_finite() && fv.is_finite() {
            let r = (x - w) * (fx - fv);
            let mut q = (x - v) * (fx - fw);
            let mut p = (x - v) * q - (x - w) * r;
            q = 2.0 * (q - r);
            if q > 0.0 {
                p = -p;
            }
            q = q.abs();
            if p.abs() < (0.5 * q * e).abs() && p > q * (a - x) && p < q * (b - x) {
                e = d;
                d = p / q;
                let u = x + d;
                if u - a < tol2 || b - u < tol2 {
                    d = if xm >= x { tol1 } else { -tol1 };
                }
                golden = false;
            }
        }
        if golden {
            e = if x >= xm { a - x } else { b - x };
            d = CGOLD * e;
        }
        let u = if d.abs() >= tol1 {
            x + d
        } else {
            x + tol1.copysign(d)
        };
        let fu = f(u);
        if fu <= fx {
            if u >= x {
                a = x;
            } else {
                b = x;
            }
            (v, fv, w, fw, x, fx) = (w, fw, x, fx, u, fu);
        } else {
            if u < x {
                a = u;
            } else {
                b = u;
            }
            if fu <= fw || w == x {
                (v, fv, w, fw) = (w, fw, u, fu);
            } else if fu <= fv || v == x || v == w {
                (v, fv) = (u, fu);
            }
        }
    }
    (x, fx)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gauss_legendre_integrates_polynomials_and_cosine() {
        let gl = GaussLegendre::new(24);
        let wsum: f64 = gl.weights.iter().sum();
        assert!((wsum - 2.0).abs() < 1e-13);
        let x10: f64 = gl
            .nodes
            .iter()
            .zip(&gl.weights)
            .map(|(x, w)| w * x.powi(10))
            .sum();
        assert!((x10 - 2.0 / 11.0).abs() < 1e-14);
        let c: f64 = gl
            .nodes
            .iter()
            .zip(&gl.weights)
            .map(|(x, w)| w * (3.0 * x).cos())
            .sum();
        assert!((c - 2.0 * 3.0_f64.sin() / 3.0).abs() < 1e-14);
    }

    #[test]
    fn peak_search_finds_interior_maximum() {
        let (u, v) = max_abs_on_interval(|u| -(u - 0.3137).powi(2) + 2.0, 0.0, 1.0, 8, 30);
        assert!((u - 0.3137).abs() < 1e-5, "{u}");
        assert!((v - 2.0).abs() < 1e-9);
    }

    #[test]
    fn brent_minimum() {
        let (x, _) = brent_min(
            |x| (x - 1.234).powi(2) + 0.1 * (x - 1.234).powi(4),
            0.0,
            3.0,
            1e-9,
        );
        assert!((x - 1.234).abs() < 1e-7, "{x}");
        // A wall of infinities on one side (infeasible region) still converges to the edge.
        let (x, _) = brent_min(|x| if x < 0.7 { f64::INFINITY } else { x }, 0.0, 3.0, 1e-9);
        assert!((x - 0.7).abs() < 1e-6, "{x}");
    }
}

/// sin and cos together: Cody–Waite reduction by π/2, then fdlibm's minimax kernels on
/// [−π/4, π/4] (both within about an ulp of the exact values there).
///
/// Branch-free and call-free for |x| < 1e5 rad, so a loop over many angles vectorises;
/// the spiral's endpoint integral spends most of its time here. Larger (or non-finite)
/// arguments take the library path, where the three-part reduction would lose digits.
#[inline]
pub fn sin_cos(x: f64) -> (f64, f64) {
    if x.abs() < 1e5 {
        sin_cos_reduced(x)
    } else {
        x.sin_cos()
    }
}

/// [`sin_cos`] for |x| < 1e5 rad, with no branch.
#[inline]
pub fn sin_cos_reduced(x: f64) -> (f64, f64) {
    const PIO2_1: f64 = 1.570_796_326_734_125_6; // first 33 bits of π/2
    const PIO2_2: f64 = 6.077_100_506_506_192e-11; // next 33 bits
    const PIO2_3: f64 = 2.022_266_248_795_950_7e-21; // the rest
    // Adding and subtracting 1.5·2⁵² rounds to the nearest integer without a call
    // (`f64::round` is a library call on baseline x86-64).
    const ROUNDER: f64 = 6_755_399_441_055_744.0;
    const S: [f64; 6] = [
        -1.666_666_666_666_663_2e-1,
        8.333_333_333_322_49e-3,
        -1.984_126_982_985_795e-4,
        2.755_731_370_707_007e-6,
        -2.505_076_025_340_686_3e-8,
        1.589_690_995_211_55e-10,
    ];
    const C: [f64; 6] = [
        4.166_666_666_666_66e-2,
        -1.388_888_888_887_411e-3,
        2.480_158_728_947_673e-5,
        -2.755_731_435_139_066_3e-7,
        2.087_572_321_298_175e-9,
        -1.135_964_755_778_819_5e-11,
    ];
    let shifted = x * std::f64::consts::FRAC_2_PI + ROUNDER;
    let k = shifted - ROUNDER;
    // k's low bits sit in the mantissa's low bits of `shifted` (two's complement).
    let q = shifted.to_bits() & 3;
    let r = ((x - k * PIO2_1) - k * PIO2_2) - k * PIO2_3;
    let z = r * r;
    let sin_r = r + r * z * (S[0] + z * (S[1] + z * (S[2] + z * (S[3] + z * (S[4] + z * S[5])))));
    let cos_r = 1.0 - 0.5 * z
        + z * z * (C[0] + z * (C[1] + z * (C[2] + z * (C[3] + z * (C[4] + z * C[5])))));
    // Quadrant q = k mod 4: (sin, cos) = (s, c), (c, −s), (−s, −c), (−c, s).
    let swap = (q & 1) as f64;
    let s = swap * cos_r + (1.0 - swap) * sin_r;
    let c = swap * sin_r + (1.0 - swap) * cos_r;
    let s_sign = 1.0 - 2.0 * ((q >> 1) & 1) as f64;
    let c_sign = 1.0 - 2.0 * (((q + 1) >> 1) & 1) as f64;
    (s_sign * s, c_sign * c)
}

#[cfg(test)]
mod sin_cos_tests {
    use super::sin_cos;

    #[test]
    fn sin_cos_matches_the_library_to_a_few_ulps() {
        let mut worst: f64 = 0.0;
        let mut x = -60.0;
        while x < 60.0 {
            let ((s, c), (es, ec)) = (sin_cos(x), x.sin_cos());
            worst = worst.max((s - es).abs()).max((c - ec).abs());
            x += 0.000_731;
        }
        for x in [
            0.0,
            -0.0,
            1e-300,
            std::f64::consts::FRAC_PI_2,
            std::f64::consts::PI,
            99_999.9,
        ] {
            let ((s, c), (es, ec)) = (sin_cos(x), x.sin_cos());
            worst = worst.max((s - es).abs()).max((c - ec).abs());
        }
        assert!(worst < 4e-16, "{worst:e}");
        assert_eq!(sin_cos(2e5), 2e5_f64.sin_cos());
        assert!(sin_cos(f64::NAN).0.is_nan());
    }
}
