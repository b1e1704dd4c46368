//! Thermal properties of the solid (manual table 12, `therm-iso-h`).

use pcdc_compute::ComputeError;
use serde::{Deserialize, Serialize};

/// Thermal conductivity of a solid (W/(m·K)).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Conductivity {
    /// Isotropic k (> 0).
    Isotropic(f64),
    /// A symmetric tensor k_ij in the global axes, components xx, yy, zz, xy, yz, xz
    /// (the zz, yz, xz entries are ignored in 2D); positive definite.
    Anisotropic([f64; 6]),
}

impl Conductivity {
    /// The tensor k_ij of a `d`-dimensional problem, row-major `d × d` in a 3 × 3 array.
    pub fn tensor(&self, d: usize) -> [[f64; 3]; 3] {
        match *self {
            Conductivity::Isotropic(k) => {
                let mut t = [[0.0; 3]; 3];
                for (i, row) in t.iter_mut().enumerate().take(d) {
                    row[i] = k;
                }
                t
            }
            Conductivity::Anisotropic(k) => {
                let t = [[k[0], k[3], k[5]], [k[3], k[1], k[4]], [k[5], k[4], k[2]]];
                let mut out = [[0.0; 3]; 3];
                for i in 0..d {
                    for j in 0..d {
                        out[i][j] = t[i][j];
                    }
                }
                out
            }
        }
    }

    /// Errors unless the `d`-dimensional tensor is finite and positive definite.
    fn check(&self, d: usize) -> Result<(), ComputeError> {
        let t = self.tensor(d);
        let finite = t.iter().flatten().all(|v| v.is_finite());
        // Sylvester: leading principal minors positive.
        let m1 = t[0][0];
        let m2 = t[0][0] * t[1][1] - t[0][1] * t[1][0];
        let m3 = t[0][0] * (t[1][1] * t[2][2] - t[1][2] * t[2][1])
            - t[0][1] * (t[1][0] * t[2][2] - t[1][2] * t[2][0])
            + t[0][2] * (t[1][0] * t[2][1] - t[1][1] * t[2][0]);
        let pd = m1 > 0.0 && m2 > 0.0 && (d == 2 || m3 > 0.0);
        if finite && pd {
            return Ok(());
        }
        Err(ComputeError::param(
            "thermal conductivity k (conductivity)",
            format!("{self:?}"),
            "must be positive (isotropic) or a finite positive definite tensor (W/(m·K))",
        ))
    }

    /// The largest diagonal entry (W/(m·K)), for reports.
    pub fn max_diagonal(&self) -> f64 {
        match *self {
            Conductivity::Isotropic(k) => k,
            Conductivity::Anisotropic(k) => k[0].max(k[1]).max(k[2]),
        }
    }
}

/// Thermal properties of a solid material (manual table 12): conductivity k
/// (W/(m·K), `conductivity`), specific heat capacity C_s (J/(kg·K), `capacity`) and
/// density ρ (kg/m³, `density`; the lumped heat capacity of node l is
/// C_s m_l = Σ_e ρ C_s Ω_e / N_e, eq. 94). The expansion coefficient of table 12 belongs
/// to the mechanics (`pcdc_mech::ThermalStrain`), the boundary transfer coefficient to
/// the convection condition ([`crate::Thermal::convection`]).
///
/// Checked by [`HeatMaterial::new`] and on deserialisation: k positive (definite), C_s
/// and ρ positive and finite. Errors name the parameter.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "RawHeatMaterial")]
pub struct HeatMaterial {
    conductivity: Conductivity,
    capacity: f64,
    density: f64,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawHeatMaterial {
    conductivity: Conductivity,
    capacity: f64,
    density: f64,
}

impl TryFrom<RawHeatMaterial> for HeatMaterial {
    type Error = ComputeError;
    fn try_from(r: RawHeatMaterial) -> Result<Self, ComputeError> {
        HeatMaterial::with_conductivity(r.conductivity, r.capacity, r.density)
    }
}

impl HeatMaterial {
    /// Isotropic conductivity k (W/(m·K)), specific heat C_s (J/(kg·K)), density ρ
    /// (kg/m³).
    pub fn new(conductivity: f64, capacity: f64, density: f64) -> Result<Self, ComputeError> {
        Self::with_conductivity(Conductivity::Isotropic(conductivity), capacity, density)
    }

    /// Any [`Conductivity`] (anisotropic allowed), C_s (J/(kg·K)), ρ (kg/m³).
    pub fn with_conductivity(
        conductivity: Conductivity,
        capacity: f64,
        density: f64,
    ) -> Result<Self, ComputeError> {
        // Checked as a 3D tensor: a 2D problem uses its xy block, positive definite too.
        conductivity.check(match conductivity {
            Conductivity::Isotropic(_) => 2,
            Conductivity::Anisotropic(k) if k[2] == 0.0 && k[4] == 0.0 && k[5] == 0.0 => 2,
            Conductivity::Anisotropic(_) => 3,
        })?;
        if !(capacity > 0.0 && capacity.is_finite()) {
            return Err(ComputeError::param(
                "specific heat capacity C_s (capacity)",
                capacity,
                "must be positive and finite (J/(kg·K))",
            ));
        }
        if !(density > 0.0 && density.is_finite()) {
            return Err(ComputeError::param(
                "density ρ (density)",
                density,
                "must be positive and finite (kg/m³)",
            ));
        }
        Ok(HeatMaterial {
            conductivity,
            capacity,
            density,
        })
    }

    /// Conductivity.
    pub fn conductivity(&self) -> Conductivity {
        self.conductivity
    }
    /// Specific heat capacity C_s (J/(kg·K)).
    pub fn capacity(&self) -> f64 {
        self.capacity
    }
    /// Density ρ (kg/m³).
    pub fn density(&self) -> f64 {
        self.density
    }
    /// Thermal diffusivity κ = k / (ρ C_s) (m²/s) of the largest diagonal conductivity.
    pub fn diffusivity(&self) -> f64 {
        self.conductivity.max_diagonal() / (self.density * self.capacity)
    }

    /// Errors if this material's conductivity is not positive definite in `d`
    /// dimensions (a 3D tensor whose zz block was left zero, used in 3D).
    pub(crate) fn check_dim(&self, d: usize) -> Result<(), ComputeError> {
        self.conductivity.check(d)
    }
}
