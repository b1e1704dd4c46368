//! Heterogeneous properties (PFC's property ranges and gradients, MatDEM's random
//! fields): a material parameter's value per element or joint, as a mean with an
//! optional linear gradient along an axis and an optional seeded random factor.
//!
//! The value at a point x (an element's centroid, a joint's midpoint) is
//!
//! v(x) = mean · (1 + slope · (x − origin) · d̂) · ξ,
//!
//! with d̂ the unit direction of the [`Gradient`] (PFC's `grad`: a relative change per
//! metre) and ξ a random factor of mean 1 drawn independently per point
//! ([`Randomness`]): normal with a coefficient of variation (ξ = 1 + cov · N(0, 1),
//! redrawn while ξ ≤ 0.01 so no value loses its sign), or Weibull with modulus m (the
//! classic strength distribution of rock grains: ξ = λ W, W Weibull of shape m and
//! scale 1, λ = 1 / Γ(1 + 1/m) so that E\[ξ\] = 1; coefficient of variation about
//! 1.2 / m). A gradient that would make a value non-positive inside the points is an
//! error naming the point.
//!
//! The physics crates assign models by range or by entity list; [`classes`] bins the
//! values into a number of classes of equal count (quantiles), each with its mean value
//! and its members, so that a scene gives each class its own model (16-32 classes
//! resolve a Weibull distribution of m ≥ 3 to within a few per cent of its spread). The
//! draws use the portable PCG generator (`rand_pcg`) and `rand_distr`: the same seed
//! gives the same values on every platform.

use rand::SeedableRng;
use rand_distr::{Distribution, StandardNormal, Weibull};
use rand_pcg::Pcg64Mcg;
use serde::{Deserialize, Serialize};

use crate::MeshError;

/// A linear gradient: a relative change `slope` per metre along `direction` from
/// `origin`, where the factor is 1.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Gradient {
    /// Direction (any non-zero length; only the first D components count).
    pub direction: [f64; 3],
    /// Point where the gradient's factor is 1 (m).
    pub origin: [f64; 3],
    /// Relative change per metre (1/m).
    pub slope: f64,
}

/// A random factor of mean 1.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum Randomness {
    /// Normal with coefficient of variation `cov` (≥ 0, < 1).
    Normal {
        /// Standard deviation over the mean.
        cov: f64,
    },
    /// Weibull with modulus (shape) `modulus` (≥ 1).
    Weibull {
        /// Weibull modulus m: the larger, the narrower.
        modulus: f64,
    },
}

/// A parameter's spatial field (module docs).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PropertyField {
    /// Mean value (any unit; the parameter's).
    pub mean: f64,
    /// Linear gradient, if any.
    #[serde(default)]
    pub gradient: Option<Gradient>,
    /// Random factor, if any.
    #[serde(default)]
    pub random: Option<Randomness>,
    /// Seed of the random factor.
    #[serde(default)]
    pub seed: u64,
}

fn bad(name: &'static str, value: f64, reason: &'static str) -> MeshError {
    MeshError::InvalidParameter {
        name,
        value,
        reason,
    }
}

impl PropertyField {
    /// A uniform field.
    pub fn uniform(mean: f64) -> Self {
        PropertyField {
            mean,
            gradient: None,
            random: None,
            seed: 0,
        }
    }

    /// Checks the parameters.
    pub fn validate(&self) -> Result<(), MeshError> {
        if !self.mean.is_finite() {
            return Err(bad("property mean", self.mean, "must be finite"));
        }
        if let Some(g) = &self.gradient {
            if !(g.direction.iter().chain(&g.origin).all(|v| v.is_finite())
                && g.direction.iter().any(|v| *v != 0.0))
            {
                return Err(bad(
                    "gradient direction",
                    f64::NAN,
                    "needs a finite, non-zero direction and a finite origin",
                ));
            }
            if !g.slope.is_finite() {
                return Err(bad("gradient slope", g.slope, "must be finite"));
            }
        }
        match self.random {
            Some(Randomness::Normal { cov }) if !(0.0..1.0).contains(&cov) => Err(bad(
                "normal cov",
                cov,
                "must lie in [0, 1): wider would draw non-positive values",
            )),
            Some(Randomness::Weibull { modulus }) if !(modulus >= 1.0 && modulus.is_finite()) => {
                Err(bad(
                    "weibull modulus",
                    modulus,
                    "must be finite and at least 1",
                ))
            }
            _ => Ok(()),
        }
    }

    /// The values at `points` (stride `dim`, 2 or 3).
    pub fn values(&self, points: &[f64], dim: usize) -> Result<Vec<f64>, MeshError> {
        self.validate()?;
        if !(dim == 2 || dim == 3) || points.len() % dim != 0 {
            return Err(bad("points", dim as f64, "need stride 2 or 3"));
        }
        let n = points.len() / dim;
        let mut out = vec![self.mean; n];
        if let Some(g) = &self.gradient {
            let norm = g.direction[..dim].iter().map(|v| v * v).sum::<f64>().sqrt();
            if norm == 0.0 {
                return Err(bad(
                    "gradient direction",
                    0.0,
                    "has no component in the mesh's dimensions",
                ));
            }
            for (i, v) in out.iter_mut().enumerate() {
                let x = &points[i * dim..(i + 1) * dim];
                let s: f64 = (0..dim)
                    .map(|k| (x[k] - g.origin[k]) * g.direction[k])
                    .sum::<f64>()
                    / norm;
                let f = 1.0 + g.slope * s;
                if f <= 0.0 {
                    return Err(MeshError::InvalidParameter {
                        name: "gradient slope",
                        value: g.slope,
                        reason: "makes the factor 1 + slope (x - origin).d non-positive at some point; lower the slope",
                    });
                }
                *v *= f;
            }
        }
        if let Some(r) = self.random {
            let mut rng = Pcg64Mcg::seed_from_u64(self.seed);
            match r {
                Randomness::Normal { cov } => {
                    for v in out.iter_mut() {
                        let xi = loop {
                            let z: f64 = StandardNormal.sample(&mut rng);
                            let xi = 1.0 + cov * z;
                            if xi > 0.01 {
                                break xi;
                            }
                        };
                        *v *= xi;
                    }
                }
                Randomness::Weibull { modulus } => {
                    let w = Weibull::new(1.0, modulus)
                        .map_err(|_| bad("weibull modulus", modulus, "is not a valid shape"))?;
                    let lambda = 1.0 / libm::tgamma(1.0 + 1.0 / modulus);
                    for v in out.iter_mut() {
                        *v *= lambda * w.sample(&mut rng);
                    }
                }
            }
        }
        Ok(out)
    }
}

/// One class of [`classes`]: the members' mean value and their indices (ascending).
#[derive(Clone, Debug, PartialEq)]
pub struct Class {
    /// Mean of the members' values.
    pub value: f64,
    /// Indices into the values.
    pub members: Vec<u32>,
}

/// Bins `values` into `n` classes of (nearly) equal count by rank (quantiles); each
/// class carries its members' mean. Every index is in exactly one class; fewer values
/// than classes give one class per value. Errors on `n = 0` or a non-finite value.
pub fn classes(values: &[f64], n: usize) -> Result<Vec<Class>, MeshError> {
    if n == 0 {
        return Err(bad("classes", 0.0, "must be at least 1"));
    }
    if let Some(v) = values.iter().find(|v| !v.is_finite()) {
        return Err(bad("property value", *v, "must be finite"));
    }
    let mut order: Vec<u32> = (0..values.len() as u32).collect();
    order.sort_by(|&a, &b| {
        values[a as usize]
            .total_cmp(&values[b as usize])
            .then(a.cmp(&b))
    });
    let n = n.min(values.len().max(1));
    let mut out = Vec::with_capacity(n);
    for c in 0..n {
        let (lo, hi) = (c * values.len() / n, (c + 1) * values.len() / n);
        if lo == hi {
            continue;
        }
        let mut members = order[lo..hi].to_vec();
        let value = members.iter().map(|&i| values[i as usize]).sum::<f64>() / members.len() as f64;
        members.sort_unstable();
        out.push(Class { value, members });
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn grid(n: usize) -> Vec<f64> {
        (0..n).flat_map(|i| [i as f64 * 0.01, 0.5]).collect()
    }

    #[test]
    fn weibull_and_normal_have_mean_one_and_their_spread() {
        let pts = grid(20_000);
        for (r, cov) in [
            (Randomness::Weibull { modulus: 5.0 }, 0.229),
            (Randomness::Normal { cov: 0.2 }, 0.2),
        ] {
            let f = PropertyField {
                mean: 2.0,
                gradient: None,
                random: Some(r),
                seed: 3,
            };
            let v = f.values(&pts, 2).unwrap();
            let m = v.iter().sum::<f64>() / v.len() as f64;
            let sd = (v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / v.len() as f64).sqrt();
            assert!((m / 2.0 - 1.0).abs() < 0.01, "{r:?}: mean {m}");
            assert!((sd / m - cov).abs() < 0.01, "{r:?}: cov {}", sd / m);
            assert!(v.iter().all(|x| *x > 0.0));
            // The same seed, the same values; another seed, others.
            assert_eq!(v, f.values(&pts, 2).unwrap());
            let g = PropertyField {
                seed: 4,
                ..f.clone()
            };
            assert_ne!(v, g.values(&pts, 2).unwrap());
        }
    }

    #[test]
    fn bad_parameters_are_named() {
        let f = |random| PropertyField {
            mean: 1.0,
            gradient: None,
            random: Some(random),
            seed: 0,
        };
        assert!(f(Randomness::Weibull { modulus: 0.5 })
            .validate()
            .unwrap_err()
            .to_string()
            .contains("weibull"));
        assert!(f(Randomness::Normal { cov: 1.5 })
            .validate()
            .unwrap_err()
            .to_string()
            .contains("cov"));
        let steep = PropertyField {
            mean: 1.0,
            gradient: Some(Gradient {
                direction: [0.0, 1.0, 0.0],
                origin: [0.0; 3],
                slope: -10.0,
            }),
            random: None,
            seed: 0,
        };
        assert!(steep
            .values(&[0.0, 1.0], 2)
            .unwrap_err()
            .to_string()
            .contains("slope"));
        assert!(classes(&[1.0], 0).is_err());
        assert!(classes(&[f64::NAN], 2).is_err());
    }

    proptest! {
        /// A gradient is linear along its direction and constant across it.
        #[test]
        fn gradient_is_linear(slope in -0.5f64..0.5, x in -1.0f64..1.0, y in -1.0f64..1.0) {
            let f = PropertyField {
                mean: 3.0,
                gradient: Some(Gradient { direction: [0.0, 2.0, 0.0], origin: [0.0, 0.0, 0.0], slope }),
                random: None,
                seed: 0,
            };
            let v = f.values(&[x, y, x + 0.3, y], 2).unwrap();
            prop_assert!((v[0] - 3.0 * (1.0 + slope * y)).abs() < 1e-12);
            prop_assert!((v[0] - v[1]).abs() < 1e-12);
        }

        /// Classes partition the indices, hold equal counts to one, and their values
        /// are ordered and within the members' range.
        #[test]
        fn classes_partition(values in proptest::collection::vec(-1e3f64..1e3, 1..300), n in 1usize..40) {
            let c = classes(&values, n).unwrap();
            let mut all: Vec<u32> = c.iter().flat_map(|k| k.members.clone()).collect();
            all.sort_unstable();
            prop_assert_eq!(all, (0..values.len() as u32).collect::<Vec<_>>());
            let sizes: Vec<usize> = c.iter().map(|k| k.members.len()).collect();
            prop_assert!(sizes.iter().max().unwrap() - sizes.iter().min().unwrap() <= 1);
            for w in c.windows(2) {
                prop_assert!(w[0].value <= w[1].value);
            }
            for k in &c {
                let lo = k.members.iter().map(|&i| values[i as usize]).fold(f64::INFINITY, f64::min);
                let hi = k.members.iter().map(|&i| values[i as usize]).fold(f64::NEG_INFINITY, f64::max);
                prop_assert!(k.value >= lo - 1e-9 && k.value <= hi + 1e-9);
            }
        }
    }
}
