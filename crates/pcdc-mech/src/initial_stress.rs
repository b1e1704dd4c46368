//! Initial (in-situ) stress of the elements (manual chapter 4 item 8 and 7.2.8): uniform,
//! geostatic under gravity with a lateral coefficient K0, a linear gradient with depth,
//! or principal values at an angle. Evaluated at each element's centroid; in plane
//! strain σzz is part of the state.
//!
//! Sign convention: tension positive, so the weight of the overburden is compressive:
//! at depth d below the surface σv = −ρ g d. The vertical axis is y in 2D and z in 3D
//! (the direction gravity acts against).

use serde::{Deserialize, Serialize};

use crate::model::Sym6;
use crate::MechError;

/// An initial stress field (Pa, tension positive; xx, yy, zz, xy, yz, xz).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum InitialStress {
    /// The same tensor everywhere.
    Uniform(Sym6),
    /// Geostatic stress under gravity: σv = −ρ g (surface − elevation) on the vertical
    /// axis, σh = K0 σv on both horizontal axes (in 2D xx and zz), no shear; zero above
    /// the surface.
    Geostatic {
        /// Elevation of the free surface along the vertical axis (m).
        surface: f64,
        /// Mean density of the overburden ρ (kg/m³), > 0.
        density: f64,
        /// Gravitational acceleration g (m/s², its magnitude), > 0.
        gravity: f64,
        /// Lateral earth pressure coefficient K0 = σh/σv (-), ≥ 0 (for example
        /// ν/(1 − ν) for a laterally confined elastic layer, 1 − sin φ for a normally
        /// consolidated soil).
        k0: f64,
    },
    /// σ = `at_surface` + depth × `per_metre`, depth = max(surface − elevation, 0) (m).
    Gradient {
        /// Elevation of the reference surface along the vertical axis (m).
        surface: f64,
        /// The stress at the surface (Pa).
        at_surface: Sym6,
        /// Its change per metre of depth (Pa/m).
        per_metre: Sym6,
    },
    /// Principal values in the x–y plane, the first at `angle_deg` from the x axis
    /// (counter-clockwise), and the out-of-plane value along z (σzz in plane strain).
    Principal {
        /// The principal stress along the direction at `angle_deg` (Pa).
        first: f64,
        /// The in-plane principal stress normal to it (Pa).
        second: f64,
        /// The principal stress along z (Pa).
        out_of_plane: f64,
        /// Angle of `first` from the x axis (degrees).
        angle_deg: f64,
    },
}

impl From<Sym6> for InitialStress {
    fn from(s: Sym6) -> Self {
        InitialStress::Uniform(s)
    }
}

impl InitialStress {
    /// Checks the parameters; errors name them.
    pub fn check(&self) -> Result<(), MechError> {
        let finite = |name: &str, v: &[f64]| {
            if v.iter().all(|x| x.is_finite()) {
                Ok(())
            } else {
                Err(MechError::param(
                    format!("initial stress: {name}"),
                    format!("{v:?}"),
                    "must be finite",
                ))
            }
        };
        match self {
            InitialStress::Uniform(s) => finite("tensor", s),
            InitialStress::Geostatic {
                surface,
                density,
                gravity,
                k0,
            } => {
                finite("surface elevation", &[*surface])?;
                for (name, v) in [("density ρ", *density), ("gravity g", *gravity)] {
                    if !(v > 0.0 && v.is_finite()) {
                        return Err(MechError::param(
                            format!("geostatic initial stress: {name}"),
                            v,
                            "must be positive and finite",
                        ));
                    }
                }
                if !(*k0 >= 0.0 && k0.is_finite()) {
                    return Err(MechError::param(
                        "geostatic initial stress: K0",
                        k0,
                        "must be non-negative and finite",
                    ));
                }
                Ok(())
            }
            InitialStress::Gradient {
                surface,
                at_surface,
                per_metre,
            } => {
                finite("surface elevation", &[*surface])?;
                finite("stress at the surface", at_surface)?;
                finite("gradient", per_metre)
            }
            InitialStress::Principal {
                first,
                second,
                out_of_plane,
                angle_deg,
            } => finite(
                "principal values and angle",
                &[*first, *second, *out_of_plane, *angle_deg],
            ),
        }
    }

    /// The stress at a point `x` (m; x, y[, z]) of a `dim`-dimensional mesh.
    pub fn at(&self, x: &[f64], dim: usize) -> Sym6 {
        let elevation = x[dim - 1];
        match *self {
            InitialStress::Uniform(s) => s,
            InitialStress::Geostatic {
                surface,
                density,
                gravity,
                k0,
            } => {
                let sv = -density * gravity * (surface - elevation).max(0.0);
                let sh = k0 * sv;
                let mut s = [sh, sh, sh, 0.0, 0.0, 0.0];
                s[dim - 1] = sv;
                s
            }
            InitialStress::Gradient {
                surface,
                at_surface,
                per_metre,
            } => {
                let d = (surface - elevation).max(0.0);
                std::array::from_fn(|k| at_surface[k] + d * per_metre[k])
            }
            InitialStress::Principal {
                first,
                second,
                out_of_plane,
                angle_deg,
            } => {
                let (s, c) = angle_deg.to_radians().sin_cos();
                [
                    first * c * c + second * s * s,
                    first * s * s + second * c * c,
                    out_of_plane,
                    (first - second) * s * c,
                    0.0,
                    0.0,
                ]
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn geostatic_weight_and_k0() {
        let g = InitialStress::Geostatic {
            surface: 10.0,
            density: 2000.0,
            gravity: 9.81,
            k0: 0.5,
        };
        let s = g.at(&[3.0, 4.0], 2);
        let sv = -2000.0 * 9.81 * 6.0;
        assert_eq!(s, [0.5 * sv, sv, 0.5 * sv, 0.0, 0.0, 0.0]);
        let s = g.at(&[0.0, 1.0, 4.0], 3);
        assert_eq!(s, [0.5 * sv, 0.5 * sv, sv, 0.0, 0.0, 0.0]);
        assert_eq!(g.at(&[0.0, 12.0], 2), [0.0; 6]);
    }

    #[test]
    fn principal_values_rotate_into_the_plane() {
        let p = InitialStress::Principal {
            first: -10.0,
            second: -4.0,
            out_of_plane: -6.0,
            angle_deg: 30.0,
        };
        let s = p.at(&[0.0, 0.0], 2);
        // Invariants: trace and determinant of the in-plane part.
        assert!((s[0] + s[1] + 14.0).abs() < 1e-12);
        assert!((s[0] * s[1] - s[3] * s[3] - 40.0).abs() < 1e-12);
        // The first principal direction (cos 30°, sin 30°) is an eigenvector.
        let (c, sn) = (30f64.to_radians().cos(), 30f64.to_radians().sin());
        assert!((s[0] * c + s[3] * sn + 10.0 * c).abs() < 1e-12);
        assert_eq!(s[2], -6.0);
    }

    #[test]
    fn bad_parameters_are_named() {
        let e = InitialStress::Geostatic {
            surface: 0.0,
            density: -1.0,
            gravity: 9.81,
            k0: 0.5,
        }
        .check()
        .unwrap_err()
        .to_string();
        assert!(e.contains("density"), "{e}");
        let e = InitialStress::Geostatic {
            surface: 0.0,
            density: 2000.0,
            gravity: 9.81,
            k0: -0.1,
        }
        .check()
        .unwrap_err()
        .to_string();
        assert!(e.contains("K0"), "{e}");
        assert!(InitialStress::Uniform([f64::NAN; 6]).check().is_err());
    }
}
