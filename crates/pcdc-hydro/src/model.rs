//! The parameters of fracture flow (manual 7.5.3, table 10, `hydr-p-m`): the fluid, the
//! hydraulic aperture and Carter leak-off, each checked before a run starts.

use pcdc_compute::ComputeError;
use serde::{Deserialize, Serialize};

/// The fluid (table 10: `f-den`, `f-b`, `vis`).
///
/// The manual's viscosity input is kinematic (m²/s); the cubic law uses the dynamic
/// viscosity μ_d = μ_k ρ_f (eq. 76 as printed, `μ_k = μ_d ρ_f`, is garbled: corrected).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Fluid {
    /// Density ρ_f (kg/m³).
    pub density: f64,
    /// Bulk modulus K_f (Pa): the stiffness of the stored fluid, dp = K_f dV/V.
    pub bulk_modulus: f64,
    /// Kinematic viscosity μ_k (m²/s).
    pub kinematic_viscosity: f64,
}

impl Fluid {
    /// Water at 20 °C: 1000 kg/m³, 2.2 GPa, 1.0e-6 m²/s.
    pub fn water() -> Self {
        Fluid {
            density: 1000.0,
            bulk_modulus: 2.2e9,
            kinematic_viscosity: 1.0e-6,
        }
    }

    /// A fluid, checked ([`Fluid::check`]).
    pub fn new(
        density: f64,
        bulk_modulus: f64,
        kinematic_viscosity: f64,
    ) -> Result<Self, ComputeError> {
        let f = Fluid {
            density,
            bulk_modulus,
            kinematic_viscosity,
        };
        f.check()?;
        Ok(f)
    }

    /// Dynamic viscosity μ_d = μ_k ρ_f (Pa·s), eq. 76 corrected.
    pub fn dynamic_viscosity(&self) -> f64 {
        self.kinematic_viscosity * self.density
    }

    /// Errors naming the first parameter that is not positive and finite.
    pub fn check(&self) -> Result<(), ComputeError> {
        positive("fluid density (kg/m³)", self.density)?;
        positive("fluid bulk modulus (Pa)", self.bulk_modulus)?;
        positive("fluid kinematic viscosity (m²/s)", self.kinematic_viscosity)
    }
}

/// The hydraulic aperture of the channels (table 10: `a-i`, `a-min`, `a-max`; eq. 79).
///
/// δ_ap = δ⁰ + ō (ō the joint's mean normal opening), clamped to [δ_min, δ_max]. For
/// intact joints δ⁰ is a virtual aperture calibrated to the rock mass permeability (a
/// set of parallel channels of aperture δ⁰ at spacing s has the permeability
/// δ⁰³/(12 s)); pre-existing fractures carry their own ([`crate::Hydro::fracture`]).
/// δ_min > 0 keeps a closed channel's volume positive (penalty joints overlap slightly in
/// compression); δ_max bounds the fluid's stable step, which scales as 1/δ_max².
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Aperture {
    /// Initial (virtual) aperture δ⁰ of intact joints (m).
    pub initial: f64,
    /// Minimum hydraulic aperture δ_min (m), > 0.
    pub min: f64,
    /// Maximum hydraulic aperture δ_max (m), ≥ δ_min.
    pub max: f64,
}

impl Aperture {
    /// An aperture range, checked ([`Aperture::check`]).
    pub fn new(initial: f64, min: f64, max: f64) -> Result<Self, ComputeError> {
        let a = Aperture { initial, min, max };
        a.check()?;
        Ok(a)
    }

    /// A fixed aperture δ (m): δ⁰ = δ_min = δ_max = δ (a rigid channel).
    pub fn fixed(delta: f64) -> Result<Self, ComputeError> {
        Aperture::new(delta, delta, delta)
    }

    /// δ⁰ + opening clamped to [δ_min, δ_max] (eq. 79).
    #[inline]
    pub fn hydraulic(&self, initial: f64, opening: f64) -> f64 {
        (initial + opening).clamp(self.min, self.max)
    }

    /// Errors on δ_min ≤ 0, δ_max < δ_min, a negative initial aperture or a non-finite
    /// value, naming the parameter.
    pub fn check(&self) -> Result<(), ComputeError> {
        positive("minimum aperture a-min (m)", self.min)?;
        positive("maximum aperture a-max (m)", self.max)?;
        if self.max < self.min {
            return Err(ComputeError::param(
                "maximum aperture a-max (m)",
                self.max,
                format!("must be at least the minimum aperture {}", self.min),
            ));
        }
        non_negative("initial aperture a-i (m)", self.initial)
    }
}

/// Carter leak-off into the rock matrix (table 10: `m-p-p`, `m-p`, `m-p-c`, `m-p`;
/// eq. 86–88), from the time a joint breaks (pre-existing fractures: from the start).
///
/// C_leak = (p_f − p_s) sqrt(k_s n_s (C_f + C_s) / (π μ_d)) when p_f > p_s, else 0
/// (eq. 87, C_f = 1/K_f); a channel of length (2D, per unit thickness) or area (3D) A
/// loses 2 A C_leak / sqrt(t − t_i) m³/s (eq. 86 on both walls of the fracture [NOT IN
/// MANUAL: the manual's L_f counts one wall; Carter's coefficient is per wall, as in
/// GEOS and the KGD/PKN theory]), weighted by f(s̄) (eq. 88), integrated exactly over a
/// step: 4 A C_leak (sqrt(t + Δt − t_i) − sqrt(t − t_i)) (eq. 88 corrected: the printed
/// form adds a volume to a rate), shared equally by the channel's nodes.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct LeakOff {
    /// Matrix pore pressure p_s (Pa).
    pub pore_pressure: f64,
    /// Matrix permeability k_s (m²).
    pub permeability: f64,
    /// Matrix pore compressibility C_s (1/Pa).
    pub pore_compressibility: f64,
    /// Matrix porosity n_s (-), in (0, 1].
    pub porosity: f64,
}

impl LeakOff {
    /// Errors naming the first parameter out of range.
    pub fn check(&self) -> Result<(), ComputeError> {
        if !self.pore_pressure.is_finite() {
            return Err(ComputeError::param(
                "leak-off matrix pore pressure m-p-p (Pa)",
                self.pore_pressure,
                "must be finite",
            ));
        }
        positive("leak-off matrix permeability m-p (m²)", self.permeability)?;
        non_negative(
            "leak-off matrix pore compressibility m-p-c (1/Pa)",
            self.pore_compressibility,
        )?;
        if !(self.porosity > 0.0 && self.porosity <= 1.0) {
            return Err(ComputeError::param(
                "leak-off matrix porosity (-)",
                self.porosity,
                "must lie in (0, 1]",
            ));
        }
        Ok(())
    }

    /// Carter's coefficient C_leak (m/s^½) at fracture pressure `p_f` (eq. 87).
    #[inline]
    pub fn coefficient(&self, p_f: f64, fluid_bulk: f64, mu_d: f64) -> f64 {
        let dp = p_f - self.pore_pressure;
        if dp <= 0.0 {
            return 0.0;
        }
        dp * (self.permeability * self.porosity * (1.0 / fluid_bulk + self.pore_compressibility)
            / (std::f64::consts::PI * mu_d))
            .sqrt()
    }
}

/// The flow model of the channels: fluid, aperture and optional leak-off (table 10).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct FlowModel {
    /// The fluid.
    pub fluid: Fluid,
    /// The hydraulic aperture.
    pub aperture: Aperture,
    /// Carter leak-off (table 10 `leak-off`, default off).
    #[serde(default)]
    pub leak_off: Option<LeakOff>,
}

impl FlowModel {
    /// A model without leak-off.
    pub fn new(fluid: Fluid, aperture: Aperture) -> Self {
        FlowModel {
            fluid,
            aperture,
            leak_off: None,
        }
    }

    /// With Carter leak-off.
    pub fn with_leak_off(mut self, leak_off: LeakOff) -> Self {
        self.leak_off = Some(leak_off);
        self
    }

    /// Checks every parameter.
    pub fn check(&self) -> Result<(), ComputeError> {
        self.fluid.check()?;
        self.aperture.check()?;
        if let Some(l) = &self.leak_off {
            l.check()?;
        }
        Ok(())
    }
}

/// Saturation weighting f(s) = s² (3 − 2 s) of the cubic law (eq. 81), s clamped to
/// [0, 1].
#[inline]
pub fn saturation_weight(s: f64) -> f64 {
    let s = s.clamp(0.0, 1.0);
    s * s * (3.0 - 2.0 * s)
}

fn positive(name: &str, v: f64) -> Result<(), ComputeError> {
    if v > 0.0 && v.is_finite() {
        Ok(())
    } else {
        Err(ComputeError::param(name, v, "must be positive and finite"))
    }
}

fn non_negative(name: &str, v: f64) -> Result<(), ComputeError> {
    if v >= 0.0 && v.is_finite() {
        Ok(())
    } else {
        Err(ComputeError::param(
            name,
            v,
            "must be non-negative and finite",
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bad_parameters_are_named() {
        let e = Fluid::new(1000.0, -1.0, 1e-6).unwrap_err().to_string();
        assert!(e.contains("bulk modulus"), "{e}");
        let e = Fluid::new(0.0, 1e9, 1e-6).unwrap_err().to_string();
        assert!(e.contains("density"), "{e}");
        let e = Fluid::new(1000.0, 1e9, 0.0).unwrap_err().to_string();
        assert!(e.contains("viscosity"), "{e}");
        let e = Aperture::new(1e-5, 0.0, 1e-3).unwrap_err().to_string();
        assert!(e.contains("a-min"), "{e}");
        let e = Aperture::new(1e-5, 1e-4, 1e-5).unwrap_err().to_string();
        assert!(e.contains("a-max"), "{e}");
        let e = LeakOff {
            pore_pressure: 0.0,
            permeability: 1e-18,
            pore_compressibility: 1e-9,
            porosity: 1.5,
        }
        .check()
        .unwrap_err()
        .to_string();
        assert!(e.contains("porosity"), "{e}");
    }

    #[test]
    fn a_model_from_a_file_is_checked_too() {
        let m: FlowModel = serde_json::from_str(
            r#"{"fluid":{"density":1000,"bulk_modulus":2e9,"kinematic_viscosity":-1},
                "aperture":{"initial":1e-5,"min":1e-6,"max":1e-3}}"#,
        )
        .unwrap();
        assert!(m.check().unwrap_err().to_string().contains("viscosity"));
    }

    #[test]
    fn weight_and_clamp() {
        assert_eq!(saturation_weight(0.0), 0.0);
        assert_eq!(saturation_weight(1.0), 1.0);
        assert_eq!(saturation_weight(0.5), 0.5);
        assert_eq!(saturation_weight(2.0), 1.0);
        let a = Aperture::new(1e-5, 1e-6, 1e-4).unwrap();
        assert_eq!(a.hydraulic(1e-5, -1.0), 1e-6);
        assert_eq!(a.hydraulic(1e-5, 1.0), 1e-4);
        assert_eq!(a.hydraulic(1e-5, 1e-5), 2e-5);
    }
}
