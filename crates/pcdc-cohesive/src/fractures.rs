//! Pre-existing fractures: straight fractures (segments in 2D, discs in 3D) and
//! statistical fracture networks, mapped onto the face-joints of a split mesh so that a
//! joint model (typically [`crate::MohrCoulombJoint`]) can be assigned to them with
//! [`crate::CohesiveJoints::model_for`].
//!
//! Mapping rule: a joint belongs to a fracture when the centroid of its face lies within
//! 0.3 face sizes of the fracture (and inside its extent), and the face normal makes an
//! angle below 40° with the fracture normal; on a mesh whose faces do not follow the
//! fracture this picks the staircase of faces closest to it.

use pcdc_mesh::{Dim, Mesh};
use serde::{Deserialize, Serialize};

use crate::CohesiveError;

/// A planar fracture.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum Fracture {
    /// A straight segment in 2D between two points (m).
    Segment {
        /// First end (m).
        a: [f64; 2],
        /// Second end (m).
        b: [f64; 2],
    },
    /// A circular disc in 3D.
    Disc {
        /// Centre (m).
        center: [f64; 3],
        /// Normal (any length, non-zero).
        normal: [f64; 3],
        /// Radius (m).
        radius: f64,
    },
}

/// A scalar distribution for fracture statistics.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum Distribution {
    /// Always the same value.
    Fixed(f64),
    /// Uniform between `min` and `max`.
    Uniform {
        /// Lower bound.
        min: f64,
        /// Upper bound.
        max: f64,
    },
    /// Normal with mean and standard deviation (lengths are clipped at zero).
    Normal {
        /// Mean.
        mean: f64,
        /// Standard deviation.
        std: f64,
    },
    /// Log-normal: exp of a normal with parameters `mu`, `sigma`.
    LogNormal {
        /// Mean of the logarithm.
        mu: f64,
        /// Standard deviation of the logarithm.
        sigma: f64,
    },
}

/// A small deterministic generator (SplitMix64), so that a seed gives the same network
/// on every platform.
#[derive(Clone, Debug)]
pub struct Rng(u64);

impl Rng {
    /// A generator from a seed.
    pub fn new(seed: u64) -> Self {
        Rng(seed)
    }

    /// Uniform in [0, 1).
    pub fn uniform(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        (z >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Standard normal (Box-Muller).
    pub fn normal(&mut self) -> f64 {
        let u1 = self.uniform().max(f64::MIN_POSITIVE);
        let u2 = self.uniform();
        (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
    }
}

impl Distribution {
    /// Draws one value.
    pub fn sample(&self, rng: &mut Rng) -> f64 {
        match *self {
            Distribution::Fixed(v) => v,
            Distribution::Uniform { min, max } => min + (max - min) * rng.uniform(),
            Distribution::Normal { mean, std } => mean + std * rng.normal(),
            Distribution::LogNormal { mu, sigma } => (mu + sigma * rng.normal()).exp(),
        }
    }

    fn check(&self, name: &'static str) -> Result<(), CohesiveError> {
        let bad = |value: f64, reason| {
            Err(CohesiveError::InvalidParameter {
                name,
                value,
                reason,
            })
        };
        match *self {
            Distribution::Fixed(v) if !v.is_finite() => bad(v, "must be finite"),
            Distribution::Uniform { min, max }
                if !(min.is_finite() && max.is_finite() && min <= max) =>
            {
                bad(min, "needs finite min <= max")
            }
            Distribution::Normal { mean, std }
                if !(mean.is_finite() && std >= 0.0 && std.is_finite()) =>
            {
                bad(std, "needs a finite mean and std >= 0")
            }
            Distribution::LogNormal { mu, sigma }
                if !(mu.is_finite() && sigma >= 0.0 && sigma.is_finite()) =>
            {
                bad(sigma, "needs a finite mu and sigma >= 0")
            }
            _ => Ok(()),
        }
    }
}

/// Statistics of a fracture network.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FractureNetwork {
    /// Orientation: in 2D the angle of the trace from the x axis (degrees); in 3D the
    /// dip angle of the normal from the z axis (degrees).
    pub orientation: Distribution,
    /// In 3D the dip direction (azimuth of the normal from the x axis, degrees); unused in
    /// 2D.
    pub azimuth: Distribution,
    /// Trace length (2D) or disc diameter (3D), m.
    pub length: Distribution,
    /// Fracture centres per unit area (2D, 1/m²) or volume (3D, 1/m³).
    pub density: f64,
    /// Seed of the generator: the same seed gives the same network.
    pub seed: u64,
}

impl FractureNetwork {
    /// Generates fractures with centres uniformly in the box `[min, max]` (first `D`
    /// components); the count is `round(density × box measure)`.
    pub fn generate<D: Dim>(
        &self,
        min: &[f64],
        max: &[f64],
    ) -> Result<Vec<Fracture>, CohesiveError> {
        let d = D::D;
        if min.len() < d
            || max.len() < d
            || (0..d).any(|k| !(min[k].is_finite() && max[k].is_finite() && min[k] <= max[k]))
        {
            return Err(CohesiveError::InvalidParameter {
                name: "fracture network box",
                value: f64::NAN,
                reason: "needs D finite components in min and max with min <= max",
            });
        }
        self.orientation.check("fracture orientation")?;
        self.azimuth.check("fracture azimuth")?;
        self.length.check("fracture length")?;
        if !(self.density >= 0.0 && self.density.is_finite()) {
            return Err(CohesiveError::InvalidParameter {
                name: "fracture density",
                value: self.density,
                reason: "must be non-negative and finite",
            });
        }
        let measure: f64 = (0..d).map(|k| (max[k] - min[k]).max(0.0)).product();
        let count = (self.density * measure).round() as usize;
        if count > 10_000_000 {
            return Err(CohesiveError::InvalidParameter {
                name: "fracture density",
                value: self.density,
                reason: "would generate more than 1e7 fractures",
            });
        }
        let mut rng = Rng::new(self.seed);
        let mut out = Vec::with_capacity(count);
        for _ in 0..count {
            let mut c = [0.0; 3];
            for k in 0..d {
                c[k] = min[k] + (max[k] - min[k]) * rng.uniform();
            }
            let len = self.length.sample(&mut rng).max(0.0);
            let angle = self.orientation.sample(&mut rng).to_radians();
            if d == 2 {
                let (dx, dy) = (0.5 * len * angle.cos(), 0.5 * len * angle.sin());
                out.push(Fracture::Segment {
                    a: [c[0] - dx, c[1] - dy],
                    b: [c[0] + dx, c[1] + dy],
                });
            } else {
                let az = self.azimuth.sample(&mut rng).to_radians();
                let normal = [angle.sin() * az.cos(), angle.sin() * az.sin(), angle.cos()];
                out.push(Fracture::Disc {
                    center: c,
                    normal,
                    radius: 0.5 * len,
                });
            }
        }
        Ok(out)
    }
}

/// Indices of the joints (the mesh's [`pcdc_mesh::Interfaces`]) lying on any of the
/// fractures (ascending, unique).
pub fn joints_on_fractures<D: Dim>(
    mesh: &Mesh<D>,
    fractures: &[Fracture],
) -> Result<Vec<u32>, CohesiveError> {
    let d = D::D;
    for f in fractures {
        let ok = match f {
            Fracture::Segment { a, b } => {
                d == 2 && a.iter().chain(b).all(|v| v.is_finite()) && a != b
            }
            Fracture::Disc {
                center,
                normal,
                radius,
            } => {
                d == 3
                    && center.iter().all(|v| v.is_finite())
                    && normal.iter().any(|v| *v != 0.0)
                    && normal.iter().all(|v| v.is_finite())
                    && *radius > 0.0
            }
        };
        if !ok {
            return Err(CohesiveError::InvalidParameter { name: "fracture geometry", value: f64::NAN, reason: "segments need two distinct finite ends (2D), discs a finite centre, non-zero normal and positive radius (3D)" });
        }
    }
    let cos_tol = 40f64.to_radians().cos();
    let mut out = Vec::new();
    let mut c = [0.0; 3];
    let mut n = [0.0; 3];
    let joints = mesh.interfaces();
    for j in 0..joints.len() {
        let fa = joints.faces()[2 * j] as usize;
        mesh.face_centroid(fa, &mut c[..d]);
        let size = mesh.face_measure_normal(fa, &mut n[..d]);
        let half = 0.3 * if d == 2 { size } else { (2.0 * size).sqrt() };
        let hit = fractures.iter().any(|f| match f {
            Fracture::Segment { a, b } => {
                let (tx, ty) = (b[0] - a[0], b[1] - a[1]);
                let len = (tx * tx + ty * ty).sqrt();
                let (ux, uy) = (tx / len, ty / len);
                let along = (c[0] - a[0]) * ux + (c[1] - a[1]) * uy;
                let off = (-(c[0] - a[0]) * uy + (c[1] - a[1]) * ux).abs();
                let aligned = (n[0] * -uy + n[1] * ux).abs() >= cos_tol;
                aligned && off <= half && along >= -half && along <= len + half
            }
            Fracture::Disc {
                center,
                normal,
                radius,
            } => {
                let nn =
                    (normal[0] * normal[0] + normal[1] * normal[1] + normal[2] * normal[2]).sqrt();
                let un = [normal[0] / nn, normal[1] / nn, normal[2] / nn];
                let rel = [c[0] - center[0], c[1] - center[1], c[2] - center[2]];
                let off = rel[0] * un[0] + rel[1] * un[1] + rel[2] * un[2];
                let r2 = rel.iter().map(|v| v * v).sum::<f64>() - off * off;
                let aligned = (n[0] * un[0] + n[1] * un[1] + n[2] * un[2]).abs() >= cos_tol;
                aligned && off.abs() <= half && r2.max(0.0).sqrt() <= radius + half
            }
        });
        if hit {
            out.push(j as u32);
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use pcdc_mesh::{builders, split_nodes, Dim2, Dim3, Range};

    #[test]
    fn horizontal_fracture_maps_to_one_row_of_faces() {
        let m = builders::rectangle(0.0, 0.0, 1.0, 1.0, 0.1).unwrap();
        let s = split_nodes(&m, &Range::All).unwrap();
        let sel = joints_on_fractures(
            &s,
            &[Fracture::Segment {
                a: [0.0, 0.5],
                b: [1.0, 0.5],
            }],
        )
        .unwrap();
        assert_eq!(sel.len(), 10);
        let mut c = [0.0; 2];
        for &j in &sel {
            s.face_centroid(s.interfaces().faces()[2 * j as usize] as usize, &mut c);
            assert!((c[1] - 0.5).abs() < 1e-12);
        }
        // A short fracture maps to fewer faces.
        let short = joints_on_fractures(
            &s,
            &[Fracture::Segment {
                a: [0.2, 0.5],
                b: [0.5, 0.5],
            }],
        )
        .unwrap();
        assert!(short.len() >= 3 && short.len() <= 4, "{}", short.len());
    }

    #[test]
    fn inclined_fracture_maps_to_a_connected_staircase() {
        let m = builders::rectangle(0.0, 0.0, 1.0, 1.0, 0.05).unwrap();
        let s = split_nodes(&m, &Range::All).unwrap();
        let sel = joints_on_fractures(
            &s,
            &[Fracture::Segment {
                a: [0.1, 0.2],
                b: [0.9, 0.6],
            }],
        )
        .unwrap();
        // Every selected face lies close to the line and their total projected length
        // covers the fracture.
        let mut covered = 0.0;
        let mut n = [0.0; 2];
        let (ux, uy) = (0.8 / 0.8f64.hypot(0.4), 0.4 / 0.8f64.hypot(0.4));
        for &j in &sel {
            let f = s.interfaces().faces()[2 * j as usize] as usize;
            let len = s.face_measure_normal(f, &mut n);
            covered += len * (n[0] * uy - n[1] * ux).abs();
        }
        assert!(covered >= 0.8 * 0.8f64.hypot(0.4), "covered {covered}");
    }

    #[test]
    fn disc_fracture_in_3d() {
        let m = builders::cuboid([0.0; 3], [1.0, 1.0, 1.0], 0.25).unwrap();
        let s = split_nodes(&m, &Range::All).unwrap();
        let sel = joints_on_fractures(
            &s,
            &[Fracture::Disc {
                center: [0.5, 0.5, 0.5],
                normal: [0.0, 0.0, 1.0],
                radius: 10.0,
            }],
        )
        .unwrap();
        // The z = 0.5 plane: 4 x 4 cells, 2 triangles each.
        assert_eq!(sel.len(), 32);
        assert!(joints_on_fractures(
            &s,
            &[Fracture::Segment {
                a: [0.0; 2],
                b: [1.0, 0.0]
            }]
        )
        .is_err());
    }

    #[test]
    fn networks_are_reproducible_and_follow_the_statistics() {
        let net = FractureNetwork {
            orientation: Distribution::Normal {
                mean: 30.0,
                std: 5.0,
            },
            azimuth: Distribution::Fixed(0.0),
            length: Distribution::Uniform { min: 0.1, max: 0.3 },
            density: 200.0,
            seed: 7,
        };
        let a = net.generate::<Dim2>(&[0.0, 0.0], &[1.0, 0.5]).unwrap();
        let b = net.generate::<Dim2>(&[0.0, 0.0], &[1.0, 0.5]).unwrap();
        assert_eq!(a, b);
        assert_eq!(a.len(), 100);
        let other = FractureNetwork {
            seed: 8,
            ..net.clone()
        }
        .generate::<Dim2>(&[0.0, 0.0], &[1.0, 0.5])
        .unwrap();
        assert_ne!(a, other);
        let (mut mean_angle, mut lmin, mut lmax) = (0.0, f64::INFINITY, 0.0f64);
        for f in &a {
            if let Fracture::Segment { a, b } = f {
                let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
                mean_angle += dy.atan2(dx).to_degrees() / 100.0;
                let l = dx.hypot(dy);
                lmin = lmin.min(l);
                lmax = lmax.max(l);
            }
        }
        assert!((mean_angle - 30.0).abs() < 2.0, "{mean_angle}");
        assert!(lmin >= 0.1 - 1e-12 && lmax <= 0.3 + 1e-12);
        let d3 = net.generate::<Dim3>(&[0.0; 3], &[1.0, 1.0, 0.5]).unwrap();
        assert_eq!(d3.len(), 100);
        let bad = FractureNetwork {
            density: -1.0,
            ..net
        };
        assert!(bad.generate::<Dim2>(&[0.0, 0.0], &[1.0, 1.0]).is_err());
    }
}
