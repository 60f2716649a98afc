//! The importance-sampling proposal: diagonal Gaussian components beside a defensive share of the nominal density, and its fit to weighted elite points.

use rand::RngExt as _;
use rand_distr::StandardNormal;
use serde::Serialize;

use crate::normal::ln_pdf;
use crate::stream;

/// One Gaussian of the mixture.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Component {
    pub weight: f64,
    pub mean: Vec<f64>,
    pub sigma: Vec<f64>,
}

/// With probability `defensive` the nominal N(0, I), else one of `components` by weight.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Proposal {
    pub components: Vec<Component>,
    pub defensive: f64,
}

impl Proposal {
    /// The nominal density itself.
    pub fn nominal(dims: usize) -> Self {
        Proposal {
            components: vec![Component {
                weight: 1.0,
                mean: vec![0.0; dims],
                sigma: vec![1.0; dims],
            }],
            defensive: 0.0,
        }
    }

    /// `n` points drawn from the stream for `purpose`.
    pub fn draw(&self, n: usize, seed: u64, purpose: u64) -> Vec<Vec<f64>> {
        let mut rng = stream(seed, purpose);
        let dims = self.components[0].mean.len();
        (0..n)
            .map(|_| {
                let nominal = self.defensive > 0.0 && rng.random::<f64>() < self.defensive;
                let c = self.pick(rng.random::<f64>());
                (0..dims)
                    .map(|i| {
                        let u: f64 = rng.sample(StandardNormal);
                        if nominal {
                            u
                        } else {
                            c.mean[i] + c.sigma[i] * u
                        }
                    })
                    .collect()
            })
            .collect()
    }

    /// The component a uniform draw `u` selects by weight.
    fn pick(&self, u: f64) -> &Component {
        let mut acc = 0.0;
        for c in &self.components {
            acc += c.weight;
            if u < acc {
                return c;
            }
        }
        self.components.last().unwrap_or(&self.components[0])
    }

    /// ln of the likelihood ratio nominal / proposal at `z`.
    pub fn ln_weight(&self, z: &[f64]) -> f64 {
        let nominal: f64 = z.iter().map(|&x| ln_pdf(x)).sum();
        let d = self.defensive;
        let mut terms: Vec<f64> = self
            .components
            .iter()
            .filter(|c| c.weight > 0.0)
            .map(|c| {
                let own: f64 = z
                    .iter()
                    .zip(c.mean.iter().zip(&c.sigma))
                    .map(|(&x, (&m, &s))| ln_pdf((x - m) / s) - s.ln())
                    .sum();
                (1.0 - d).ln() + c.weight.ln() + own
            })
            .collect();
        if d > 0.0 {
            terms.push(d.ln() + nominal);
        }
        nominal - log_sum_exp(&terms)
    }
}

fn log_sum_exp(v: &[f64]) -> f64 {
    let top = v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    if !top.is_finite() {
        return top;
    }
    top + v.iter().map(|x| (x - top).exp()).sum::<f64>().ln()
}

/// The Gaussian of `elite` points (each with its log weight), σ widened by `inflation`
/// and at least `min_sigma`; `defensive` kept beside it. One component: a mixture fitted
/// by clustering the elite was tried and lost coverage on single tails.
pub(crate) fn fit(
    elite: &[(&Vec<f64>, f64)],
    dims: usize,
    (min_sigma, inflation, defensive): (f64, f64, f64),
) -> Proposal {
    let top = elite.iter().map(|e| e.1).fold(f64::NEG_INFINITY, f64::max);
    let w: Vec<f64> = elite.iter().map(|e| (e.1 - top).exp()).collect();
    let mass: f64 = w.iter().sum();
    let mean: Vec<f64> = (0..dims)
        .map(|d| elite.iter().zip(&w).map(|(e, w)| w * e.0[d]).sum::<f64>() / mass)
        .collect();
    let sigma = (0..dims)
        .map(|d| {
            let var = elite
                .iter()
                .zip(&w)
                .map(|(e, w)| w * (e.0[d] - mean[d]).powi(2))
                .sum::<f64>()
                / mass;
            (inflation * var.sqrt()).max(min_sigma)
        })
        .collect();
    Proposal {
        components: vec![Component {
            weight: 1.0,
            mean,
            sigma,
        }],
        defensive,
    }
}
