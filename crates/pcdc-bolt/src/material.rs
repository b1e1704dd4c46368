//! Bolt properties (manual table 19) and the two constitutive laws of a bolt: the
//! elastic-plastic axial force of a bolt segment (eq. 138-142, 141 corrected) and the
//! grout's bond-slip shear force at a bolt node (eq. 143-147).

use serde::{Deserialize, Serialize};

use crate::BoltError;

/// The properties of a bolt or cable (manual table 19), as a user writes them. Checked
/// when turned into a [`BoltMaterial`] (so a struct literal or a file cannot smuggle in a
/// bad value). Forces in N, lengths in m, stresses in Pa, angles in degrees.
///
/// In 2D (plane strain) a bolt stands for a row of bolts `spacing` apart out of plane:
/// its stiffnesses, strengths, masses and pretension are divided by the spacing (per
/// unit thickness, as FLAC's cables are smeared) \[NOT IN MANUAL\].
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BoltProperties {
    /// Density ρ_b (kg/m³; the manual's table prints m³/kg).
    pub density: f64,
    /// Young's modulus E_b of the bolt (Pa).
    pub young: f64,
    /// Bolt diameter D_b (m); cross-section A_b = π D_b² / 4.
    pub diameter: f64,
    /// Tensile yield force f_b,t,l (N, > 0).
    pub tensile_yield_force: f64,
    /// Compressive yield force f_b,c,l, as a magnitude (N, > 0; the law uses −f_b,c,l).
    pub compressive_yield_force: f64,
    /// Tension failure strain ε_b,t,l (-, > 0): a segment whose strain reaches it breaks
    /// for good (eq. 142). `f64::INFINITY` for a bolt that never breaks.
    pub tension_failure_strain: f64,
    /// Grout shear stiffness per unit length K_b,r,s (N/m/m, eq. 143).
    pub shear_stiffness: f64,
    /// Grout stiffness perpendicular to the bolt per unit length (N/m/m)
    /// \[NOT IN MANUAL: the manual ignores it, which leaves the bolt nodes free to drift
    /// sideways; FLAC's cable links are rigid across the axis, this is their explicit
    /// penalty form]. `None`: equal to `shear_stiffness`.
    #[serde(default)]
    pub normal_stiffness: Option<f64>,
    /// Grout annulus thickness T_g (m, ≥ 0, eq. 146).
    pub grout_thickness: f64,
    /// Cohesion of the rock-grout interface C_r,g (Pa, ≥ 0, eq. 146).
    pub cohesion_rock_grout: f64,
    /// Cohesion of the grout-bolt interface C_b,g (Pa, ≥ 0, eq. 147).
    pub cohesion_grout_bolt: f64,
    /// Friction angle of the rock-grout interface φ_r,g (degrees, in [0, 90)).
    pub friction_rock_grout: f64,
    /// Friction angle of the grout-bolt interface φ_b,g (degrees, in [0, 90)).
    pub friction_grout_bolt: f64,
    /// Out-of-plane spacing of a bolt row in 2D (m, > 0); `None` in 3D, and in 2D one
    /// bolt per unit of thickness: spacing 1 in the model's length unit (1 m in SI, but
    /// 1 mm in a millimetre model, where a row 1 m apart needs `Some(1000.0)`).
    #[serde(default)]
    pub spacing: Option<f64>,
    /// Pretension f_b,pre (N, ≥ 0), carried by the segments of the bolt's free
    /// (ungrouted) length ([`crate::Bolt::free_length`]).
    #[serde(default)]
    pub pretension: f64,
    /// Damping factor D_b,f (-, ≥ 0, eq. 148): the fraction of the axial damping
    /// coefficient C = 2 A_b √(E_b ρ_b) on each segment's stretching rate, and of the
    /// critical damping 2 √(k_n l m) of each bolt node's lateral grout spring on its
    /// sideways velocity against the rock (\[NOT IN MANUAL\]; it stops the sideways
    /// flutter a bolt sliding at its bond strength can develop, see the crate docs).
    #[serde(default)]
    pub damping_factor: f64,
}

impl BoltProperties {
    /// A fully grouted steel rebar of diameter `diameter` (m) in a cement grout, with
    /// the usual design values: E_b 200 GPa, ρ_b 7850 kg/m³, yield 500 MPa × A_b in
    /// tension and compression, failure strain 10 %, grout annulus 10 mm, grout shear
    /// stiffness 1 GN/m/m, bond cohesions 1 MPa (rock-grout) and 5 MPa (grout-bolt),
    /// friction 30°, no pretension, damping factor 0.
    pub fn steel_rebar(diameter: f64) -> Self {
        let area = std::f64::consts::PI * diameter * diameter / 4.0;
        BoltProperties {
            density: 7850.0,
            young: 200e9,
            diameter,
            tensile_yield_force: 500e6 * area,
            compressive_yield_force: 500e6 * area,
            tension_failure_strain: 0.1,
            shear_stiffness: 1e9,
            normal_stiffness: None,
            grout_thickness: 0.01,
            cohesion_rock_grout: 1e6,
            cohesion_grout_bolt: 5e6,
            friction_rock_grout: 30.0,
            friction_grout_bolt: 30.0,
            spacing: None,
            pretension: 0.0,
            damping_factor: 0.0,
        }
    }
}

/// Checked bolt properties (see [`BoltProperties`] for each value and unit).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "BoltProperties", into = "BoltProperties")]
pub struct BoltMaterial {
    p: BoltProperties,
}

impl From<BoltMaterial> for BoltProperties {
    fn from(m: BoltMaterial) -> Self {
        m.p
    }
}

impl TryFrom<BoltProperties> for BoltMaterial {
    type Error = BoltError;
    fn try_from(p: BoltProperties) -> Result<Self, BoltError> {
        BoltMaterial::new(p)
    }
}

fn check(name: &str, v: f64, ok: bool, reason: &str) -> Result<(), BoltError> {
    if ok && !v.is_nan() {
        Ok(())
    } else {
        Err(BoltError::param(name, v, reason))
    }
}

impl BoltMaterial {
    /// Checks `p`: density, modulus, diameter, yield forces, shear stiffness positive and
    /// finite; failure strain positive (infinite allowed); normal stiffness and spacing
    /// positive if given; thickness, cohesions, pretension, damping non-negative; friction
    /// angles in [0°, 90°). Errors name the parameter.
    pub fn new(p: BoltProperties) -> Result<Self, BoltError> {
        let pos = |v: f64| v > 0.0 && v.is_finite();
        let nonneg = |v: f64| v >= 0.0 && v.is_finite();
        check(
            "density",
            p.density,
            pos(p.density),
            "must be positive (kg/m³)",
        )?;
        check("young", p.young, pos(p.young), "must be positive (Pa)")?;
        check(
            "diameter",
            p.diameter,
            pos(p.diameter),
            "must be positive (m)",
        )?;
        check(
            "tensile_yield_force",
            p.tensile_yield_force,
            pos(p.tensile_yield_force),
            "must be positive (N)",
        )?;
        check(
            "compressive_yield_force",
            p.compressive_yield_force,
            pos(p.compressive_yield_force),
            "must be positive: give the magnitude (N), the law uses its negative",
        )?;
        check(
            "tension_failure_strain",
            p.tension_failure_strain,
            p.tension_failure_strain > 0.0,
            "must be positive (f64::INFINITY for a bolt that never breaks)",
        )?;
        check(
            "shear_stiffness",
            p.shear_stiffness,
            pos(p.shear_stiffness),
            "must be positive (N/m/m)",
        )?;
        if let Some(k) = p.normal_stiffness {
            check("normal_stiffness", k, pos(k), "must be positive (N/m/m)")?;
        }
        if let Some(s) = p.spacing {
            check("spacing", s, pos(s), "must be positive (m)")?;
        }
        for (name, v, unit) in [
            ("grout_thickness", p.grout_thickness, "m"),
            ("cohesion_rock_grout", p.cohesion_rock_grout, "Pa"),
            ("cohesion_grout_bolt", p.cohesion_grout_bolt, "Pa"),
            ("pretension", p.pretension, "N"),
            ("damping_factor", p.damping_factor, "-"),
        ] {
            check(
                name,
                v,
                nonneg(v),
                &format!("must be non-negative ({unit})"),
            )?;
        }
        for (name, v) in [
            ("friction_rock_grout", p.friction_rock_grout),
            ("friction_grout_bolt", p.friction_grout_bolt),
        ] {
            check(
                name,
                v,
                (0.0..90.0).contains(&v),
                "must lie in [0, 90) degrees",
            )?;
        }
        if p.pretension >= p.tensile_yield_force {
            return Err(BoltError::param(
                "pretension",
                p.pretension,
                format!(
                    "must be below the tensile yield force {} N",
                    p.tensile_yield_force
                ),
            ));
        }
        Ok(BoltMaterial { p })
    }

    /// The properties as given.
    pub fn properties(&self) -> &BoltProperties {
        &self.p
    }

    /// Cross-section A_b = π D_b² / 4 (m²).
    pub fn area(&self) -> f64 {
        std::f64::consts::PI * self.p.diameter * self.p.diameter / 4.0
    }

    /// Bond strength per unit length S_b = min(S_r,g, S_b,g) (N/m, eq. 144-147) under a
    /// confining (compressive) stress `sigma_n` ≥ 0 (Pa) normal to the bolt:
    /// S_r,g = π (D_b + 2 T_g)(C_r,g + σ_n tan φ_r,g), S_b,g = π D_b (C_b,g + σ_n tan φ_b,g).
    pub fn bond_strength(&self, sigma_n: f64) -> f64 {
        bond_strength(&self.bond_constants(), sigma_n)
    }

    /// The constants of eq. 146-147: π (D_b + 2 T_g), C_r,g, tan φ_r,g, π D_b, C_b,g,
    /// tan φ_b,g.
    pub(crate) fn bond_constants(&self) -> [f64; 6] {
        let p = &self.p;
        let pi = std::f64::consts::PI;
        [
            pi * (p.diameter + 2.0 * p.grout_thickness),
            p.cohesion_rock_grout,
            p.friction_rock_grout.to_radians().tan(),
            pi * p.diameter,
            p.cohesion_grout_bolt,
            p.friction_grout_bolt.to_radians().tan(),
        ]
    }

    /// The values a segment or node uses, per unit thickness in 2D (divided by the
    /// spacing) and as given in 3D.
    pub(crate) fn effective(&self, two_d: bool) -> Effective {
        let p = &self.p;
        let s = if two_d { p.spacing.unwrap_or(1.0) } else { 1.0 };
        let a = self.area();
        Effective {
            axial: AxialLaw {
                ea: p.young * a / s,
                tensile: p.tensile_yield_force / s,
                compressive: p.compressive_yield_force / s,
                failure_strain: p.tension_failure_strain,
            },
            shear: p.shear_stiffness / s,
            normal: p.normal_stiffness.unwrap_or(p.shear_stiffness) / s,
            mass_per_length: p.density * a / s,
            pretension: p.pretension / s,
            damping: p.damping_factor * 2.0 * a * (p.young * p.density).sqrt() / s,
            damping_factor: p.damping_factor,
            bond_per_spacing: 1.0 / s,
        }
    }
}

/// A bolt's values per unit thickness (2D) or as given (3D).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Effective {
    /// The axial law.
    pub axial: AxialLaw,
    /// Grout stiffness per unit length along and across the axis (N/m/m).
    pub shear: f64,
    pub normal: f64,
    /// ρ_b A_b (kg/m).
    pub mass_per_length: f64,
    /// Pretension (N).
    pub pretension: f64,
    /// Axial damping coefficient D_b,f · 2 A_b √(E_b ρ_b) (N·s/m).
    pub damping: f64,
    /// D_b,f (-), for the lateral grout damping.
    pub damping_factor: f64,
    /// The factor the bond strength per length is multiplied by (1 / spacing).
    pub bond_per_spacing: f64,
}

/// State of a bolt segment (the `bolt_state` field's values).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SegmentState {
    /// Elastic.
    Elastic = 0,
    /// At the tensile yield force.
    YieldTension = 1,
    /// At the compressive yield force.
    YieldCompression = 2,
    /// Broken in tension (permanent: carries no force).
    Broken = 3,
}

impl SegmentState {
    /// The state a field value stands for (anything else is broken).
    pub fn from_value(v: f64) -> Self {
        match v as i64 {
            0 => SegmentState::Elastic,
            1 => SegmentState::YieldTension,
            2 => SegmentState::YieldCompression,
            _ => SegmentState::Broken,
        }
    }
}

/// The axial law of a bolt segment (eq. 138-142): stiffness and limits, per unit
/// thickness in 2D.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AxialLaw {
    /// E_b A_b (N).
    pub ea: f64,
    /// Tensile yield force f_b,t,l (N, > 0).
    pub tensile: f64,
    /// Compressive yield force f_b,c,l as a magnitude (N, > 0).
    pub compressive: f64,
    /// Tension failure strain ε_b,t,l (-).
    pub failure_strain: f64,
}

impl AxialLaw {
    /// Axial force of a segment (eq. 138-142, tension positive), in total form: with
    /// the segment's elongation `elongation` = L − L₀ (m), reference length `l0` (m) and
    /// the plastic elongation `plastic` accumulated so far (m; negative for a
    /// pretensioned segment, whose natural length is shorter), the trial force
    /// f* = (E_b A_b / L₀)(L − L₀ − u_p) is clamped to [−f_c, f_t] (eq. 140-141,
    /// \[CORRECTED\] 141 uses the compressive yield force f_b,c,l, printed f_b,t,l) and
    /// the plastic elongation moved so that the force stays on the limit. This is eq.
    /// 138-139's increment f + (E_b A_b / L₀) Δu_a summed exactly, so it does not drift
    /// under rotation. A segment whose strain (L − L₀)/L₀ reaches the failure strain
    /// breaks (eq. 142) and carries nothing from then on \[NOT IN MANUAL: permanently\].
    ///
    /// Returns (force N, new plastic elongation m, state).
    pub fn update(
        &self,
        elongation: f64,
        l0: f64,
        plastic: f64,
        broken: bool,
    ) -> (f64, f64, SegmentState) {
        let fails = broken || elongation / l0 >= self.failure_strain;
        self.settle(fails, elongation, self.ea / l0, plastic)
    }

    /// [`AxialLaw::update`] once the failure test is done (`fails`), with the stiffness
    /// `k` = E_b A_b / L₀ (N/m) known: the walk keeps `k` per segment and skips the
    /// failure test's division where the strain is clearly below the failure strain.
    #[inline(always)]
    pub(crate) fn settle(
        &self,
        fails: bool,
        elongation: f64,
        k: f64,
        plastic: f64,
    ) -> (f64, f64, SegmentState) {
        if fails {
            return (0.0, plastic, SegmentState::Broken);
        }
        let trial = k * (elongation - plastic);
        if trial > self.tensile {
            (
                self.tensile,
                elongation - self.tensile / k,
                SegmentState::YieldTension,
            )
        } else if trial < -self.compressive {
            (
                -self.compressive,
                elongation + self.compressive / k,
                SegmentState::YieldCompression,
            )
        } else {
            (trial, plastic, SegmentState::Elastic)
        }
    }
}

/// Bond strength per unit length (N/m, eq. 144-147) from the constants `b` of
/// [`BoltMaterial::bond_constants`] under a confining stress `sigma_n` (Pa; negative
/// values count as 0).
pub(crate) fn bond_strength(b: &[f64; 6], sigma_n: f64) -> f64 {
    let s = sigma_n.max(0.0);
    (b[0] * (b[1] + s * b[2])).min(b[3] * (b[4] + s * b[5]))
}

/// Grout shear force at a bolt node along the bolt (eq. 143-145), in total form: with
/// the relative axial displacement `delta` of the bolt node against the host material
/// point it is grouted to (m), the slip `slip` so far (m), the grout stiffness over
/// the tributary length `k_l` = K_b,r,s (L_b0 + L_b1)/2 (N/m) and the bond capacity
/// `cap` = S_b (L_b0 + L_b1)/2 (N), the trial force k_l (δ − s) is clamped to
/// [−cap, cap] and the slip moved so that the force stays on the bond limit.
///
/// Returns (force N, acting on the host along the axis; new slip m).
pub fn grout_force(delta: f64, slip: f64, k_l: f64, cap: f64) -> (f64, f64) {
    let trial = k_l * (delta - slip);
    if trial > cap {
        (cap, delta - cap / k_l)
    } else if trial < -cap {
        (-cap, delta + cap / k_l)
    } else {
        (trial, slip)
    }
}
