//! The laboratory test shared by the UCS ([`crate::scenes::ucs`]) and Brazilian
//! ([`crate::scenes::brazilian`]) scenes: a rock specimen with a cohesive joint on every
//! interior face (manual 7.4), pressed between two elastic steel platens that move
//! towards each other at a prescribed velocity, with potential contact (manual 7.3)
//! between the platens and the specimen and on the faces of broken joints.
//!
//! The parameter groups are `serde` types that read and write TOML (see
//! [`crate::scenes::file`]); every group rejects unknown keys and every value is
//! checked by `validate`, which names the offending key. Units are SI throughout.

use std::path::PathBuf;
use std::time::Instant;

use serde::{Deserialize, Serialize};

use pcdc::fdem::Fdem;
use pcdc_cohesive::{
    czm_state, FailureMode, IntrinsicCzm, IntrinsicCzmParams, JOINT_DAMAGE, JOINT_STATE,
};
use pcdc_compute::{Backend, BackendKind, Simulation, Table, TimeValue};
use pcdc_contact::Contact;
use pcdc_mech::{output, Boundary, LinearElastic, ServoGains, StressServo};
use pcdc_mesh::property::{classes, PropertyField};
use pcdc_mesh::vtu::{DataArray, PvdSeries};
use pcdc_mesh::{builders, split_nodes, Dim2, Mesh, Range};

use crate::report::SceneError;

use super::limits::{
    at_most, MAX_DENSITY, MAX_FRACTURE_ENERGY, MAX_MODULUS, MAX_PENALTY_FACTOR,
    MAX_PLATEN_VELOCITY, MAX_RAMP_TIME, MAX_SAMPLE_SIZE, MAX_STRENGTH,
};

/// Checks Poisson's ratio: −1 < ν < 0.5 (bulk and shear moduli positive; ν < 0 is allowed
/// for auxetic materials).
pub(crate) fn poisson(key: &str, value: f64) -> Result<(), ParamError> {
    if value > -1.0 && value < 0.5 {
        Ok(())
    } else {
        Err(ParamError {
            key: key.into(),
            value,
            reason: "must lie in (-1, 0.5) so that the bulk and shear moduli are positive",
        })
    }
}

/// Checks an elastic modulus: positive, finite and at most [`MAX_MODULUS`].
pub(crate) fn modulus(key: &str, value: f64) -> Result<(), ParamError> {
    positive(key, value)?;
    at_most(
        key,
        value,
        MAX_MODULUS,
        "must be at most 1e13 Pa (10 TPa, ten times diamond)",
    )
}

/// Checks a density: positive, finite and at most [`MAX_DENSITY`].
fn density(key: &str, value: f64) -> Result<(), ParamError> {
    positive(key, value)?;
    at_most(
        key,
        value,
        MAX_DENSITY,
        "must be at most 1e5 kg/m³ (four times osmium)",
    )
}

/// Checks a specimen or platen dimension: positive, finite and at most [`MAX_SAMPLE_SIZE`].
pub(crate) fn dimension(key: &str, value: f64) -> Result<(), ParamError> {
    positive(key, value)?;
    at_most(
        key,
        value,
        MAX_SAMPLE_SIZE,
        "must be at most 10 m (laboratory specimens are 25-150 mm)",
    )
}

/// Checks a penalty factor (multiple of E): positive, finite, at most [`MAX_PENALTY_FACTOR`].
fn penalty(key: &str, value: f64) -> Result<(), ParamError> {
    positive(key, value)?;
    at_most(
        key,
        value,
        MAX_PENALTY_FACTOR,
        "must be at most 1e4 (times E)",
    )
}

/// A parameter value that is out of range: names the key (as written in a scene file,
/// e.g. `rock.poisson`), the value and what is allowed.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{key} = {value}: {reason}")]
pub struct ParamError {
    /// Key path in the scene file, e.g. `sample.height`.
    pub key: String,
    /// The rejected value.
    pub value: f64,
    /// What the key accepts.
    pub reason: &'static str,
}

/// Checks that `value` is positive and finite.
pub(crate) fn positive(key: &str, value: f64) -> Result<(), ParamError> {
    if value > 0.0 && value.is_finite() {
        Ok(())
    } else {
        Err(ParamError {
            key: key.into(),
            value,
            reason: "must be positive and finite",
        })
    }
}

/// Checks that `value` lies in `[lo, hi)`.
pub(crate) fn within(
    key: &str,
    value: f64,
    lo: f64,
    hi: f64,
    reason: &'static str,
) -> Result<(), ParamError> {
    if value >= lo && value < hi {
        Ok(())
    } else {
        Err(ParamError {
            key: key.into(),
            value,
            reason,
        })
    }
}

/// Elastic rock of the specimen (linear elastic, plane strain; manual 7.2.3) with the
/// element viscous damping of eq. 17-19.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Rock {
    /// Young's modulus E (Pa).
    pub young: f64,
    /// Poisson's ratio ν, in (−1, 0.5).
    pub poisson: f64,
    /// Density ρ (kg/m³).
    pub density: f64,
    /// Damping factor D_f of eq. 19 (fraction of the element-scale critical damping).
    pub damping: f64,
}

impl Default for Rock {
    /// E = 30 GPa, ν = 0.25, ρ = 2600 kg/m³ (the manual's quick start does not give them),
    /// D_f = 0.5.
    fn default() -> Self {
        Rock {
            young: 30e9,
            poisson: 0.25,
            density: 2600.0,
            damping: 0.5,
        }
    }
}

impl Rock {
    fn validate(&self, key: &str) -> Result<(), ParamError> {
        modulus(&format!("{key}.young"), self.young)?;
        poisson(&format!("{key}.poisson"), self.poisson)?;
        density(&format!("{key}.density"), self.density)?;
        within(
            &format!("{key}.damping"),
            self.damping,
            0.0,
            f64::INFINITY,
            "must be non-negative and finite",
        )
    }

    fn model(&self) -> Result<LinearElastic, SceneError> {
        Ok(LinearElastic::new(self.young, self.poisson, self.density)?
            .with_damping(self.damping)?)
    }
}

/// The two steel platens: rectangles centred on the specimen's axis, one below and one
/// above it, elastic (pure FEM, shared nodes: they do not crack).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Platens {
    /// Platen height (m).
    pub height: f64,
    /// Platen width (m).
    pub width: f64,
    /// Young's modulus (Pa).
    pub young: f64,
    /// Poisson's ratio.
    pub poisson: f64,
    /// Density (kg/m³).
    pub density: f64,
}

impl Default for Platens {
    /// The manual's quick start: 10 × 56 mm; steel E = 200 GPa, ν = 0.3, ρ = 7800 kg/m³.
    fn default() -> Self {
        Platens {
            height: 0.010,
            width: 0.056,
            young: 200e9,
            poisson: 0.3,
            density: 7800.0,
        }
    }
}

impl Platens {
    fn validate(&self) -> Result<(), ParamError> {
        dimension("platens.height", self.height)?;
        dimension("platens.width", self.width)?;
        modulus("platens.young", self.young)?;
        poisson("platens.poisson", self.poisson)?;
        density("platens.density", self.density)
    }
}

/// Intrinsic cohesive joints on every interior face of the specimen (manual 7.4.2,
/// table 9). Penalties are given as multiples of the rock's Young's modulus, as in the
/// manual's quick-start script (`m_s_mod*10`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct JointParams {
    /// Friction angle φ (degrees), in [0, 90).
    pub friction_deg: f64,
    /// Cohesion c (Pa).
    pub cohesion: f64,
    /// Tensile strength T_s (Pa).
    pub tensile_strength: f64,
    /// Mode I fracture energy G_f1 (N/m).
    pub gf1: f64,
    /// Mode II fracture energy G_f2 (N/m).
    pub gf2: f64,
    /// Normal (opening) penalty P_open as a multiple of the rock's E.
    pub penalty_normal: f64,
    /// Shear penalty P_tan as a multiple of the rock's E.
    pub penalty_shear: f64,
    /// Overlap penalty P_overlap as a multiple of the rock's E.
    pub penalty_overlap: f64,
}

impl Default for JointParams {
    /// The manual's quick start (figure 5): φ = 30°, c = 10 MPa, T_s = 2 MPa,
    /// G_f1 = 0.5 N/m (500 µN/mm), G_f2 = 5 N/m, penalties 10 E, 10 E and 100 E.
    fn default() -> Self {
        JointParams {
            friction_deg: 30.0,
            cohesion: 10e6,
            tensile_strength: 2e6,
            gf1: 0.5,
            gf2: 5.0,
            penalty_normal: 10.0,
            penalty_shear: 10.0,
            penalty_overlap: 100.0,
        }
    }
}

impl JointParams {
    fn validate(&self) -> Result<(), ParamError> {
        within(
            "joints.friction_deg",
            self.friction_deg,
            0.0,
            90.0,
            "must lie in [0, 90) degrees",
        )?;
        for (key, v) in [
            ("joints.cohesion", self.cohesion),
            ("joints.tensile_strength", self.tensile_strength),
        ] {
            positive(key, v)?;
            at_most(key, v, MAX_STRENGTH, "must be at most 1e10 Pa (10 GPa)")?;
        }
        for (key, v) in [("joints.gf1", self.gf1), ("joints.gf2", self.gf2)] {
            positive(key, v)?;
            at_most(key, v, MAX_FRACTURE_ENERGY, "must be at most 1e6 N/m")?;
        }
        penalty("joints.penalty_normal", self.penalty_normal)?;
        penalty("joints.penalty_shear", self.penalty_shear)?;
        penalty("joints.penalty_overlap", self.penalty_overlap)
    }

    /// The intrinsic CZM for a rock of Young's modulus `young` (Pa).
    pub fn model(&self, young: f64) -> Result<IntrinsicCzm, SceneError> {
        Ok(IntrinsicCzmParams {
            friction_deg: self.friction_deg,
            cohesion: self.cohesion,
            tensile_strength: self.tensile_strength,
            gf1: self.gf1,
            gf2: self.gf2,
            penalty_open: self.penalty_normal * young,
            penalty_shear: self.penalty_shear * young,
            penalty_overlap: self.penalty_overlap * young,
        }
        .build()?)
    }
}

/// Potential contact (manual 7.3, `contact-m-c`) between the platens and the specimen
/// and between the faces of broken joints.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ContactParams {
    /// Normal and shear penalty as a multiple of the rock's E.
    pub penalty: f64,
    /// Coulomb friction angle (degrees), in [0, 90).
    pub friction_deg: f64,
}

impl Default for ContactParams {
    /// Penalty 10 E (the manual's default), friction 30° (the joints' φ).
    fn default() -> Self {
        ContactParams {
            penalty: 10.0,
            friction_deg: 30.0,
        }
    }
}

impl ContactParams {
    fn validate(&self) -> Result<(), ParamError> {
        penalty("contact.penalty", self.penalty)?;
        within(
            "contact.friction_deg",
            self.friction_deg,
            0.0,
            90.0,
            "must lie in [0, 90) degrees",
        )
    }
}

/// Loading by platen velocity and when to stop. The defaults differ between the scenes,
/// so a `[loading]` table in a scene file gives all its keys.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Loading {
    /// Speed of each platen towards the specimen (m/s, at most
    /// [`MAX_PLATEN_VELOCITY`]); the platens close at twice this.
    pub platen_velocity: f64,
    /// Time over which the platen speed ramps up linearly from zero (s, at most
    /// [`MAX_RAMP_TIME`]): no loading shock.
    pub ramp_time: f64,
    /// After the peak, stop once the load has fallen below this fraction of it and joints
    /// have broken, in (0, 1).
    pub stop_fraction: f64,
    /// Stop anyway once the platens have closed by this fraction of the specimen height.
    pub max_closure: f64,
    /// Steps per recorded sample of the load history (the load is averaged over them:
    /// every step on the CPU, ten reads per sample on the GPU).
    pub record_every: u64,
}

impl Loading {
    fn validate(&self) -> Result<(), ParamError> {
        positive("loading.platen_velocity", self.platen_velocity)?;
        at_most(
            "loading.platen_velocity",
            self.platen_velocity,
            MAX_PLATEN_VELOCITY,
            "must be at most 10 m/s (faster is an impact, not a quasi-static test)",
        )?;
        within(
            "loading.ramp_time",
            self.ramp_time,
            0.0,
            f64::INFINITY,
            "must be non-negative and finite",
        )?;
        at_most(
            "loading.ramp_time",
            self.ramp_time,
            MAX_RAMP_TIME,
            "must be at most 1 s (1e7-1e8 explicit steps)",
        )?;
        within(
            "loading.stop_fraction",
            self.stop_fraction,
            f64::MIN_POSITIVE,
            1.0,
            "must lie in (0, 1)",
        )?;
        within(
            "loading.max_closure",
            self.max_closure,
            f64::MIN_POSITIVE,
            1.0,
            "must lie in (0, 1)",
        )?;
        within(
            "loading.record_every",
            self.record_every as f64,
            1.0,
            1e9,
            "must be at least 1",
        )
    }
}

/// What to write. The defaults differ between the scenes, so an `[output]` table in a
/// scene file gives all its keys.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Output {
    /// Folder of the outputs (CSV, PNG, VTU/PVD); relative to the working directory.
    pub dir: PathBuf,
    /// VTU frames over the longest possible run (up to `loading.max_closure`); a run
    /// that stops at failure writes fewer, and its last state is always written
    /// (0: no VTU series).
    pub frames: u32,
}

impl Output {
    fn validate(&self) -> Result<(), ParamError> {
        within(
            "output.frames",
            self.frames as f64,
            0.0,
            1e5,
            "must be at most 100000",
        )
    }
}

/// Servo-controlled confinement of a rectangular specimen's sides (biaxial test, PFC's
/// servo walls): a smooth rigid wall on each side (x velocity from a [`StressServo`], y
/// free) holds the confining stress σ3, by default through a soft [`Membrane`] (the
/// rubber sleeve of a laboratory cell) and optionally split into `segments` along the
/// height, each with its own servo. The test first consolidates: the walls and the
/// platens are servo-controlled to σ3 until all hold it within `tolerance` over a record
/// window; then the platens load at `loading.platen_velocity` (ramped) while the walls
/// keep σ3, with a feed-forward of the sample's elastic lateral expansion. The
/// confining stress reported is the walls' total force over their length.
///
/// Measured at σ3 = 5 MPa (largest pre-peak deviation of the record-window means, 5 /
/// 2 mm meshes): walls on the rock 12.9 % / 4.6 % (bursts of cracking push the rock
/// out faster than a wall can retreat: a wall moving at Δv sends Z Δv into the rock at
/// once), 4 wall segments 0.98 % / 6.9 %, walls behind the default membrane 0.71 % /
/// 0.81 %.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Confinement {
    /// Confining stress σ3 (Pa, compression positive, > 0).
    pub stress: f64,
    /// Servo response time τ (s): a few P-wave transits of the specimen's width.
    pub response_time: f64,
    /// Largest wall speed (m/s).
    pub max_speed: f64,
    /// Relative tolerance on σ3 that ends the consolidation.
    pub tolerance: f64,
    /// Servo wall segments per side (≥ 1; 1 is one rigid wall per side), each with at
    /// least [`MIN_SEGMENT_NODES`] nodes. A local burst of cracking pushes out one
    /// segment, whose servo retreats on the local stress error; a rigid wall answers
    /// only the side's mean error (type docs: it helps walls on the rock at 5 mm, not
    /// at 2 mm; behind a membrane one wall per side does as well).
    #[serde(default = "default_segments")]
    pub segments: u32,
    /// A soft membrane between each servo wall and the specimen's side (the rubber
    /// sleeve of a laboratory cell), `None` for walls on the specimen's own nodes. In
    /// a scene file: a `[confinement.membrane]` table (the default when absent), or
    /// `membrane = "none"` (TOML has no null, and an absent key means the default).
    #[serde(default = "default_membrane", with = "membrane_or_none")]
    pub membrane: Option<Membrane>,
}

fn default_membrane() -> Option<Membrane> {
    Some(Membrane::default())
}

/// [`Confinement::membrane`] in scene files: a table, or the string `"none"`.
mod membrane_or_none {
    use super::Membrane;
    use serde::de::{self, MapAccess, Visitor};
    use serde::{Deserialize, Deserializer, Serialize, Serializer};

    pub fn serialize<S: Serializer>(m: &Option<Membrane>, s: S) -> Result<S::Ok, S::Error> {
        match m {
            Some(m) => m.serialize(s),
            None => s.serialize_str("none"),
        }
    }

    /// A visitor rather than an untagged enum, so that a bad key inside the table is
    /// named by the membrane's own error.
    struct Form;

    impl<'de> Visitor<'de> for Form {
        type Value = Option<Membrane>;

        fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
            f.write_str("a membrane table or \"none\"")
        }

        fn visit_str<E: de::Error>(self, w: &str) -> Result<Self::Value, E> {
            if w == "none" {
                Ok(None)
            } else {
                Err(E::custom(format!(
                    "confinement.membrane: \"{w}\" is neither a membrane table nor \"none\""
                )))
            }
        }

        fn visit_map<A: MapAccess<'de>>(self, map: A) -> Result<Self::Value, A::Error> {
            Membrane::deserialize(de::value::MapAccessDeserializer::new(map)).map(Some)
        }
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Option<Membrane>, D::Error> {
        d.deserialize_any(Form)
    }
}

/// The membrane of a servo-confined test: an elastic strip of `thickness` along each
/// side, in contact with the specimen, whose outer edge the servo wall drives. A burst
/// of cracking pushes the specimen's side out faster than any wall can retreat (a wall
/// moving at Δv sends Z Δv into the rock at once, Z = ρ c): on the rock itself the
/// burst is a stress spike of the rock's impedance; through a soft membrane it reaches
/// the wall as the membrane's much smaller stress change (E_m δ / t for a bulge δ, or
/// Z_m v when faster), which the servo then removes. The membrane's axial stiffness
/// is a negligible part of the platens' load (E_m ≪ E).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Membrane {
    /// Thickness (m).
    pub thickness: f64,
    /// Young's modulus (Pa).
    pub young: f64,
    /// Poisson's ratio.
    pub poisson: f64,
    /// Density (kg/m³).
    pub density: f64,
}

impl Default for Membrane {
    /// 6 mm thick, E = 0.3 GPa, ν = 0.3 (a stiff rubber: 20 MPa of confinement strain
    /// it by 7 %), ρ = 2600 kg/m³: the rock's density rather than rubber's 1100, so
    /// that the contact on its nodes does not shorten the time step (its inertia plays
    /// no part in a quasi-static test; measured: 1100 cut the step by 47 % at 5 mm).
    fn default() -> Self {
        Membrane {
            thickness: 0.006,
            young: 0.3e9,
            poisson: 0.3,
            density: 2600.0,
        }
    }
}

impl Membrane {
    /// Checks every value.
    pub fn validate(&self) -> Result<(), ParamError> {
        dimension("confinement.membrane.thickness", self.thickness)?;
        positive("confinement.membrane.young", self.young)?;
        positive("confinement.membrane.density", self.density)?;
        within(
            "confinement.membrane.poisson",
            self.poisson,
            -0.99,
            0.5,
            "must lie in (-1, 0.5)",
        )
    }
}

/// Default [`Confinement::segments`].
pub const CONFINEMENT_SEGMENTS: u32 = 1;

/// Fewest nodes a servo wall segment may hold: a segment only a few elements long is
/// stiffer than a wall (its ends shear the rock beside it), so the impedance bound of
/// its gain no longer holds (measured: 8 segments of 2-3 nodes on the 5 mm sample
/// oscillated and never consolidated; 4 of 5-6 nodes held σ3).
pub const MIN_SEGMENT_NODES: usize = 5;

fn default_segments() -> u32 {
    CONFINEMENT_SEGMENTS
}

impl Confinement {
    /// Checks every value.
    pub fn validate(&self) -> Result<(), ParamError> {
        positive("confinement.stress", self.stress)?;
        positive("confinement.response_time", self.response_time)?;
        positive("confinement.max_speed", self.max_speed)?;
        within(
            "confinement.segments",
            f64::from(self.segments),
            1.0,
            1025.0,
            "must lie in 1 to 1024",
        )?;
        if let Some(m) = &self.membrane {
            m.validate()?;
        }
        within(
            "confinement.tolerance",
            self.tolerance,
            1e-6,
            0.5,
            "must lie in 1e-6 to 0.5",
        )
    }
}

/// Heterogeneous rock (PFC's property ranges and gradients): factor fields (mean 1
/// keeps the rock's values on average) on the elements' Young's modulus and on the
/// joints' strengths, evaluated at element centroids and joint midpoints and binned
/// into `classes` quantile classes, each with its own model
/// ([`pcdc_mesh::property::classes`]). A strength factor f scales the cohesion and the
/// tensile strength by f and the fracture energies by f² (the cohesive-zone length
/// stays the rock's). The joints' penalties stay multiples of the mean E.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Heterogeneity {
    /// Factor on the elements' E, if any.
    #[serde(default)]
    pub modulus: Option<PropertyField>,
    /// Factor on the joints' strengths, if any.
    #[serde(default)]
    pub strength: Option<PropertyField>,
    /// Quantile classes per field (1-1000; 16 resolves a Weibull m ≥ 3 to a few per
    /// cent of its spread).
    #[serde(default = "default_classes")]
    pub classes: usize,
}

fn default_classes() -> usize {
    16
}

impl Heterogeneity {
    /// Checks every value.
    pub fn validate(&self) -> Result<(), ParamError> {
        within(
            "heterogeneity.classes",
            self.classes as f64,
            1.0,
            1000.0,
            "must lie in 1-1000",
        )?;
        for (key, f) in [
            ("heterogeneity.modulus", &self.modulus),
            ("heterogeneity.strength", &self.strength),
        ] {
            if let Some(f) = f {
                f.validate().map_err(|_| ParamError {
                    key: key.into(),
                    value: f.mean,
                    reason: "needs a positive finite mean, a finite non-zero gradient direction, a normal cov in [0, 1) or a Weibull modulus >= 1",
                })?;
                positive(&format!("{key}.mean"), f.mean)?;
            }
        }
        Ok(())
    }
}

/// Validates the groups shared by both scenes.
pub(crate) fn validate_common(
    rock: &Rock,
    platens: &Platens,
    joints: &JointParams,
    contact: &ContactParams,
    loading: &Loading,
    output: &Output,
) -> Result<(), ParamError> {
    rock.validate("rock")?;
    platens.validate()?;
    joints.validate()?;
    contact.validate()?;
    loading.validate()?;
    output.validate()
}

/// Progress of a running test, reported every recorded sample.
#[derive(Clone, Copy, Debug)]
pub struct Progress {
    /// Steps done.
    pub step: u64,
    /// Upper bound on the steps (reached if the specimen never fails).
    pub max_steps: u64,
    /// Platen closure so far (m).
    pub closure: f64,
    /// Current load per unit thickness (N/m), compression positive.
    pub load: f64,
    /// Largest load so far (N/m).
    pub peak: f64,
}

/// One recorded sample of the load history (the load averaged over `record_every`
/// steps: every step on the CPU, ten evenly spaced reads on the GPU).
#[derive(Clone, Copy, Debug, Default)]
pub struct Sample {
    /// Time (s).
    pub time: f64,
    /// Closure of the platens' loaded edges (m).
    pub closure: f64,
    /// Shortening of the specimen between its top and bottom nodes (m).
    pub shortening: f64,
    /// Confining stress on the sides (Pa, compression positive): the mean of both
    /// servo walls over the record window; 0 without confinement.
    pub confinement: f64,
    /// Widening of the specimen: mean x displacement of its rightmost nodes minus that
    /// of its leftmost ones, both over the middle half of its height, away from the
    /// platens' end restraint (m; the lateral strain of a rectangular sample times its
    /// width).
    pub widening: f64,
    /// Load per unit thickness (N/m): mean of the top and bottom platen reactions,
    /// compression positive.
    pub load: f64,
    /// Kinetic energy of the specimen's nodes relative to uniform compression between the
    /// platens' current velocities, i.e. of the motion a quasi-static test would not
    /// have (J/m).
    pub kinetic: f64,
    /// Elastic strain energy of all elements (J/m).
    pub strain_energy: f64,
}

/// Broken joints by failure mode (the mode the cohesive model records when D reaches 1).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct BrokenCount {
    /// Opening (mode I).
    pub tensile: usize,
    /// Sliding (mode II).
    pub shear: usize,
    /// Mixed I-II.
    pub mixed: usize,
}

impl BrokenCount {
    /// All broken joints.
    pub fn total(&self) -> usize {
        self.tensile + self.shear + self.mixed
    }
}

/// A broken joint: midpoint (m) and failure mode.
#[derive(Clone, Copy, Debug)]
pub struct Crack {
    /// Midpoint of the joint in the undeformed mesh (m).
    pub at: [f64; 2],
    /// Direction of the joint's trace from the x axis (degrees, 0-180): 90 is a vertical
    /// crack (parallel to the UCS load).
    pub angle_deg: f64,
    /// Length of the joint (m).
    pub length: f64,
    /// Failure mode.
    pub mode: FailureMode,
}

/// What a platen test measured.
#[derive(Clone, Debug)]
pub struct Raw {
    /// The load history.
    pub samples: Vec<Sample>,
    /// Index of the peak sample.
    pub peak_index: usize,
    /// Broken joints by mode at the end.
    pub broken: BrokenCount,
    /// Broken joints at the end.
    pub cracks: Vec<Crack>,
    /// Elements (specimen and platens).
    pub elements: usize,
    /// Elements of the specimen.
    pub specimen_elements: usize,
    /// Joints.
    pub joints: usize,
    /// Steps.
    pub steps: u64,
    /// Time step (s).
    pub dt: f64,
    /// What limits the time step, e.g. `cohesive joints: joint 12`.
    pub dt_limit: String,
    /// Wall time (s).
    pub wall_s: f64,
    /// The `.pvd` file of the VTU series, if written.
    pub pvd: Option<PathBuf>,
}

/// The specimen and the test set-up.
pub(crate) struct Setup<'a> {
    /// Specimen mesh (one body, shared nodes); it is split into FDEM elements here.
    pub specimen: Mesh<Dim2>,
    /// Element size (m), also used for the platens.
    pub size: f64,
    pub rock: &'a Rock,
    pub platens: &'a Platens,
    pub joints: &'a JointParams,
    pub contact: &'a ContactParams,
    pub loading: &'a Loading,
    pub output: &'a Output,
    /// Base name of the VTU series.
    pub name: &'a str,
    /// Servo-controlled side confinement (biaxial test), if any.
    pub confinement: Option<&'a Confinement>,
    /// Heterogeneous rock, if any.
    pub heterogeneity: Option<&'a Heterogeneity>,
}

/// Runs the platen test: builds specimen + platens, splits the specimen into FDEM
/// elements with joints, loads by platen velocity until the load has dropped to
/// `stop_fraction` of its peak (or the closure limit) and reports the history.
pub(crate) fn run(
    backend: &Backend,
    s: &Setup<'_>,
    progress: &mut dyn FnMut(&Progress),
) -> Result<Raw, SceneError> {
    let start = Instant::now();
    let (lo, hi) = s.specimen.bounding_box();
    let (y0, y1) = (lo[1], hi[1]);
    let height = y1 - y0;
    let xc = 0.5 * (lo[0] + hi[0]);
    let (pw, ph) = (s.platens.width, s.platens.height);
    // The platens touch the specimen's lowest and highest points; their elements are of
    // the specimen's size (at most the platen height).
    let size = s.size.min(ph);
    let bottom = builders::rectangle(xc - 0.5 * pw, y0 - ph, pw, ph, size)?;
    let top = builders::rectangle(xc - 0.5 * pw, y1, pw, ph, size)?;
    let n_spec = s.specimen.n_elements();
    // The membranes of a servo-confined test: strips along the sides, in contact.
    let membrane = s.confinement.and_then(|c| c.membrane);
    let strips = match membrane {
        Some(m) => {
            m.validate()?;
            let t = m.thickness;
            let sz = size.min(t / 2.0);
            Some([
                builders::rectangle(lo[0] - t, y0, t, height, sz)?,
                builders::rectangle(hi[0], y0, t, height, sz)?,
            ])
        }
        None => None,
    };
    let mut bodies = vec![&s.specimen, &bottom, &top];
    if let Some([l, r]) = &strips {
        bodies.extend([l, r]);
    }
    let (joined, _) = builders::union(&bodies)?;
    // FDEM region: the specimen's elements (centroids strictly between the platens and
    // the sides).
    let eps = 1e-9 * height;
    let in_specimen = Range::rect(lo[0], y0 + eps, hi[0], y1 - eps);
    let mesh = split_nodes(&joined, &in_specimen)?;
    let joints = mesh.interfaces().clone();
    let ne = mesh.n_elements();
    // Nodes by body (element order is kept by the union and the split).
    let nodes_of = |r: std::ops::Range<usize>| {
        let mut v: Vec<u32> = r.flat_map(|e| mesh.element(e).to_vec()).collect();
        v.sort_unstable();
        v.dedup();
        v
    };
    let spec_nodes = nodes_of(0..n_spec);
    let n_bottom = bottom.n_elements();
    let bottom_nodes = nodes_of(n_spec..n_spec + n_bottom);
    let n_platens = n_bottom + top.n_elements();
    let top_nodes = nodes_of(n_spec + n_bottom..n_spec + n_platens);
    // The membranes' outer edges: the servo walls.
    let outer = strips.as_ref().map(|[l, _]| {
        let n_strip = l.n_elements();
        let first = n_spec + n_platens;
        let t = membrane.map_or(0.0, |m| m.thickness);
        let edge = |r: std::ops::Range<usize>, x: f64| -> Vec<u32> {
            nodes_of(r)
                .into_iter()
                .filter(|&n| (mesh.node(n as usize)[0] - x).abs() <= eps)
                .collect()
        };
        (
            edge(first..first + n_strip, lo[0] - t),
            edge(first + n_strip..ne, hi[0] + t),
        )
    });
    let at_y = |list: &[u32], y: f64| -> Vec<u32> {
        list.iter()
            .copied()
            .filter(|&n| (mesh.node(n as usize)[1] - y).abs() <= eps)
            .collect()
    };
    let loaded_bottom = at_y(&bottom_nodes, y0 - ph);
    let loaded_top = at_y(&top_nodes, y1 + ph);
    let spec_top = at_y(&spec_nodes, y1);
    let spec_bottom = at_y(&spec_nodes, y0);
    let at_x = |x: f64| -> Vec<u32> {
        (spec_nodes.iter().copied())
            .filter(|&n| {
                let q = mesh.node(n as usize);
                (q[0] - x).abs() <= eps && (q[1] - 0.5 * (y0 + y1)).abs() <= 0.25 * height
            })
            .collect()
    };
    let (spec_left, spec_right) = (at_x(lo[0]), at_x(hi[0]));
    let width = hi[0] - lo[0];
    let side = |x: f64| -> Vec<u32> {
        (spec_nodes.iter().copied())
            .filter(|&n| (mesh.node(n as usize)[0] - x).abs() <= eps)
            .collect()
    };
    let (side_left, side_right) = (side(lo[0]), side(hi[0]));
    if loaded_bottom.is_empty() || loaded_top.is_empty() || spec_top.is_empty() {
        return Err(SceneError::Measurement(
            "platen test: no loaded or measured nodes found".into(),
        ));
    }
    let mut mesh = mesh;
    mesh.add_node_group("platen_bottom_edge", loaded_bottom.clone())?;
    mesh.add_node_group("platen_top_edge", loaded_top.clone())?;
    // Servos of the biaxial test: the sides (whole height) and, while consolidating,
    // the platens; gains from the rock's P-wave modulus over the span.
    let mut servos = match s.confinement {
        Some(c) => {
            c.validate()?;
            // P-wave moduli and impedances of rock and steel: the sides drive the rock,
            // the platens the steel (the stiffer, heavier body limits their gain).
            let wave = |e: f64, nu: f64| e * (1.0 - nu) / ((1.0 + nu) * (1.0 - 2.0 * nu));
            let m_rock = wave(s.rock.young, s.rock.poisson);
            let m_steel = wave(s.platens.young, s.platens.poisson);
            let z_rock = (m_rock * s.rock.density).sqrt();
            let z_steel = (m_steel * s.platens.density).sqrt();
            let platen_gains =
                ServoGains::for_specimen(m_rock, height, c.response_time, z_steel.max(z_rock));
            let servo = |nodes: Vec<u32>, axis, inward, area, gains| {
                StressServo::new(nodes, axis, inward, area, c.stress, gains, c.max_speed)
            };
            // Each segment keeps the whole wall's gains: it pushes the same specimen
            // across the same width, and a lower gain lets the wall lag the lateral
            // expansion (measured: 8 segments at gains from their own length held
            // σ3 only within ±1.5 % at 2 mm).
            // With a membrane, the wall drives the membrane and the rock in series: the
            // span in rock-equivalent length is W + t M_rock / M_membrane, and the
            // membrane's impedance bounds the gain.
            let (walls, span, z_wall) = match (&outer, c.membrane) {
                (Some((l, r)), Some(m)) => {
                    let m_mem = wave(m.young, m.poisson);
                    (
                        (l.clone(), r.clone()),
                        width + m.thickness * m_rock / m_mem,
                        (m_mem * m.density).sqrt(),
                    )
                }
                _ => ((side_left.clone(), side_right.clone()), width, z_rock),
            };
            let side_gains = ServoGains::for_specimen(m_rock, span, c.response_time, z_wall);
            let fewest = walls.0.len().min(walls.1.len());
            if (c.segments as usize) * MIN_SEGMENT_NODES > fewest {
                return Err(SceneError::Measurement(format!(
                    "confinement.segments = {}: a side has {fewest} nodes, and a wall segment needs at least {MIN_SEGMENT_NODES} (a shorter one is stiffer than the impedance bound of its gain assumes and oscillates); use at most {}",
                    c.segments,
                    (fewest / MIN_SEGMENT_NODES).max(1)
                )));
            }
            let mut sides = Vec::new();
            for (side, name, inward) in [(&walls.0, "left", 1.0), (&walls.1, "right", -1.0)] {
                for (k, (nodes, length)) in wall_segments(&mesh, side, c.segments)
                    .into_iter()
                    .enumerate()
                {
                    let group = format!("servo_{name}_{k}");
                    mesh.add_node_group(&group, nodes.clone())?;
                    sides.push((group, servo(nodes, 0, inward, length, side_gains)?));
                }
            }
            Some(Servos {
                sides,
                platens: [
                    servo(loaded_bottom.clone(), 1, 1.0, width, platen_gains)?,
                    servo(loaded_top.clone(), 1, -1.0, width, platen_gains)?,
                ],
            })
        }
        None => None,
    };

    let e = s.rock.young;
    let rock = s.rock.model()?;
    let steel = Rock {
        young: s.platens.young,
        poisson: s.platens.poisson,
        density: s.platens.density,
        damping: s.rock.damping,
    }
    .model()?;
    let czm = s.joints.model(e)?;
    let contact =
        Contact::new(s.contact.penalty * e).friction(s.contact.friction_deg, s.contact.penalty * e);
    let v = s.loading.platen_velocity;
    let ramp = s.loading.ramp_time.max(0.0);
    let table = |sign: f64| -> Result<TimeValue, pcdc_compute::ComputeError> {
        if ramp > 0.0 {
            Table::new("platen velocity", &[(0.0, 0.0), (ramp, sign * v)]).map(Into::into)
        } else {
            Ok((sign * v).into())
        }
    };
    let boundary = match &servos {
        None => Boundary::new()
            .velocity(
                Range::group("platen_bottom_edge"),
                [Some(0.0.into()), Some(table(1.0)?), None],
            )
            .velocity(
                Range::group("platen_top_edge"),
                [Some(0.0.into()), Some(table(-1.0)?), None],
            ),
        Some(sv) => {
            let mut b = Boundary::new()
                .velocity(
                    Range::group("platen_bottom_edge"),
                    [Some(0.0.into()), Some(sv.platens[0].velocity()), None],
                )
                .velocity(
                    Range::group("platen_top_edge"),
                    [Some(0.0.into()), Some(sv.platens[1].velocity()), None],
                );
            for (group, servo) in &sv.sides {
                b = b.velocity(Range::group(group), [Some(servo.velocity()), None, None]);
            }
            b
        }
    };
    let mut fdem = Fdem::new(rock, czm, contact).material(in_specimen.clone().complement(), steel);
    if let Some(m) = membrane {
        let sleeve = Rock {
            young: m.young,
            poisson: m.poisson,
            density: m.density,
            damping: s.rock.damping,
        }
        .model()?;
        fdem = fdem
            .material(
                Range::rect(f64::NEG_INFINITY, y0, lo[0], y1),
                sleeve.clone(),
            )
            .material(Range::rect(hi[0], y0, f64::INFINITY, y1), sleeve);
    }
    if let Some(h) = s.heterogeneity {
        fdem = heterogeneous(fdem, h, &mesh, n_spec, s)?;
    }
    let mut sim = Simulation::builder(mesh, backend.clone())
        .group(fdem)
        .physics(boundary)
        .build()?;
    let dt = sim.dt();
    let dt_limit = sim
        .time_step_limit()
        .map(|l| format!("{}: {}", l.physics, l.entity))
        .unwrap_or_default();
    // Time to close by max_closure · height, plus the ramp's lost travel.
    let t_max = s.loading.max_closure * height / (2.0 * v) + 0.5 * ramp;
    // Consolidation may take up to 40 response times of the slowest servo.
    let t_consolidate = match (&servos, s.confinement) {
        (Some(sv), Some(c)) => 40.0 * c.response_time.max(sv.platens[0].response_time()),
        _ => 0.0,
    };
    let max_steps = ((t_max + t_consolidate) / dt).ceil() as u64;
    let every = s.loading.record_every.max(1);
    let mut series = if s.output.frames > 0 {
        Some(PvdSeries::new(&s.output.dir, s.name)?)
    } else {
        None
    };
    // Frames: evenly over the longest possible run; a run that stops at failure writes
    // fewer, and the last state is always written.
    let frame_every = (max_steps / u64::from(s.output.frames.max(1))).max(every);
    let mut next_frame = frame_every;
    let chunk = reaction_chunk(backend.kind(), every);
    let mean_y = |sim: &Simulation<Dim2>, list: &[u32]| mean_of(&sim.state.u, list, 1);
    // Weight of one reaction read in the feed-forward's running mean of the strain rate
    // (time constant a fifth of the servo's response time).
    let rate_weight = s.confinement.map_or(1.0, |c| {
        (chunk as f64 * dt / (0.2 * c.response_time)).min(1.0)
    });
    let mut samples = Vec::new();
    let (mut acc, mut count) = (0.0, 0u64);
    let (mut peak, mut peak_index) = (0.0f64, 0usize);
    // Consolidation (with servos): window means of the four walls' stresses; the
    // loading starts at `load_start` (s), measured from the values there.
    let mut loading = servos.is_none();
    let n_sides = servos.as_ref().map_or(0, |sv| sv.sides.len());
    // Per side segment, then the two platens.
    let mut wall_acc = vec![0.0f64; n_sides + 2];
    let mut load_start = 0.0;
    let mut base = [0.0f64; 3];
    // The sample's smoothed axial strain rate (1/s) for the sides' feed-forward.
    let mut strain_rate = 0.0f64;
    loop {
        sim.run(chunk)?;
        if let Some(servos) = servos.as_mut() {
            for (k, (_, servo)) in servos.sides.iter_mut().enumerate() {
                wall_acc[k] += servo.update(&sim);
            }
            if !loading {
                for (k, servo) in servos.platens.iter_mut().enumerate() {
                    wall_acc[n_sides + k] += servo.update(&sim);
                }
            } else {
                let ramped = if ramp > 0.0 {
                    ((sim.state.time - load_start) / ramp).clamp(0.0, 1.0)
                } else {
                    1.0
                };
                servos.platens[0].drive(v * ramped);
                servos.platens[1].drive(v * ramped);
                // Feed-forward of the sides: the elastic lateral expansion of the
                // sample's own axial strain rate, ν' ε̇ W / 2 outward per side with the
                // elements' plane-strain ν' = ν/(1 − ν) (the PI corrects the
                // estimate). ε̇ from the sample's end nodes, not the platens' speed:
                // the sample starts to shorten a wave transit after the platens
                // start, and walls fed from the platens' speed retreat too early
                // (measured: −1.8 % of σ3 at the start of the loading). Smoothed over
                // the servo's response time against the end nodes' vibration.
                let v = &sim.state.v;
                let rate = (mean_of(v, &spec_bottom, 1) - mean_of(v, &spec_top, 1)) / height;
                strain_rate += rate_weight * (rate - strain_rate);
                let nu = s.rock.poisson;
                let expansion = nu / (1.0 - nu) * strain_rate.max(0.0) * 0.5 * width;
                for (_, servo) in &mut servos.sides {
                    servo.set_feed_forward(-expansion);
                }
            }
        }
        let f = sim.node_force();
        // Reactions: the gathered force on the held edge nodes is what the specimen and
        // platen push back with; compression pushes the bottom edge down (−y) and the top
        // edge up (+y).
        let rb: f64 = loaded_bottom.iter().map(|&n| -f[2 * n as usize + 1]).sum();
        let rt: f64 = loaded_top.iter().map(|&n| f[2 * n as usize + 1]).sum();
        // The load of a record window is the mean of its reaction reads.
        acc += 0.5 * (rb + rt);
        count += 1;
        let step = sim.state.step;
        if step % every == 0 && !loading {
            // Consolidating: start the loading once every wall holds σ3.
            let c = s.confinement.expect("servos come with a confinement");
            let means: Vec<f64> = wall_acc.iter().map(|a| a / count as f64).collect();
            (acc, count) = (0.0, 0);
            wall_acc.fill(0.0);
            if means
                .iter()
                .all(|m| (m - c.stress).abs() <= c.tolerance * c.stress)
            {
                loading = true;
                load_start = sim.state.time;
                base = [
                    mean_y(&sim, &loaded_bottom) - mean_y(&sim, &loaded_top),
                    mean_y(&sim, &spec_bottom) - mean_y(&sim, &spec_top),
                    0.0,
                ];
                let u = &sim.state.u;
                base[2] = mean_of(u, &spec_right, 0) - mean_of(u, &spec_left, 0);
            } else if sim.state.time > t_consolidate {
                return Err(SceneError::Measurement(format!(
                    "biaxial consolidation: the servo walls did not hold {:.3e} Pa within {:.1} % after {:.3e} s (stresses {means:?} Pa); raise confinement.response_time",
                    c.stress,
                    100.0 * c.tolerance,
                    t_consolidate
                )));
            }
            continue;
        }
        if step % every == 0 {
            let load = acc / count as f64;
            // The sides' total force over their length.
            let confinement = servos.as_ref().map_or(0.0, |sv| {
                let (force, length) = sv
                    .sides
                    .iter()
                    .zip(&wall_acc)
                    .fold((0.0, 0.0), |(f, l), ((_, servo), acc)| {
                        (f + acc * servo.area(), l + servo.area())
                    });
                force / length / count as f64
            });
            (acc, count) = (0.0, 0);
            wall_acc.fill(0.0);
            let closure = mean_y(&sim, &loaded_bottom) - mean_y(&sim, &loaded_top) - base[0];
            let shortening = mean_y(&sim, &spec_bottom) - mean_y(&sim, &spec_top) - base[1];
            let u = &sim.state.u;
            let widening = mean_of(u, &spec_right, 0) - mean_of(u, &spec_left, 0) - base[2];
            // Kinetic energy of the specimen relative to the uniform compression between
            // the platens' current velocities (the motion a quasi-static test has).
            let v = &sim.state.v;
            let (vb, vt) = (mean_of(v, &loaded_bottom, 1), mean_of(v, &loaded_top, 1));
            let mass = sim.mass();
            let kinetic = 0.5
                * spec_nodes
                    .iter()
                    .map(|&n| {
                        let n = n as usize;
                        let y = sim.mesh().node(n)[1];
                        let vq = vb + (vt - vb) * (y - y0) / height;
                        mass[n]
                            * (sim.state.v[2 * n].powi(2) + (sim.state.v[2 * n + 1] - vq).powi(2))
                    })
                    .sum::<f64>();
            samples.push(Sample {
                time: sim.state.time,
                closure,
                shortening,
                widening,
                confinement,
                load,
                kinetic,
                strain_energy: sim.stored_energy(),
            });
            if load > peak {
                peak = load;
                peak_index = samples.len() - 1;
            }
            progress(&Progress {
                step,
                max_steps,
                closure,
                load,
                peak,
            });
            // Failure: the load has fallen well below its peak and joints have broken
            // (a dip of the load during the first contact transient is no failure).
            let failed = peak > 0.0
                && load < s.loading.stop_fraction * peak
                && samples.len() > peak_index + 1
                && sim.field(JOINT_DAMAGE)?.iter().any(|&d| d >= 1.0);
            if failed || step >= max_steps {
                break;
            }
        }
        if let Some(series) = series.as_mut() {
            if step >= next_frame {
                write_frame(series, &sim, &joints)?;
                next_frame += frame_every;
            }
        }
    }
    let pvd = match series.as_mut() {
        Some(series) => {
            write_frame(series, &sim, &joints)?;
            Some(series.pvd_path())
        }
        None => None,
    };
    let (broken, cracks) = broken_joints(&sim, &joints)?;
    Ok(Raw {
        samples,
        peak_index,
        broken,
        cracks,
        elements: ne,
        specimen_elements: n_spec,
        joints: joints.len(),
        steps: sim.state.step,
        dt,
        dt_limit,
        wall_s: start.elapsed().as_secs_f64(),
        pvd,
    })
}

/// The heterogeneity's classes as models on the specimen's elements (`0..n_spec`) and
/// on the joints.
fn heterogeneous(
    mut fdem: Fdem,
    h: &Heterogeneity,
    mesh: &Mesh<Dim2>,
    n_spec: usize,
    s: &Setup<'_>,
) -> Result<Fdem, SceneError> {
    h.validate()?;
    if let Some(field) = &h.modulus {
        let mut c = [0.0; 2];
        let pts: Vec<f64> = (0..n_spec)
            .flat_map(|e| {
                mesh.element_centroid(e, &mut c);
                c
            })
            .collect();
        for class in classes(&field.values(&pts, 2)?, h.classes)? {
            let rock = Rock {
                young: s.rock.young * class.value,
                ..s.rock.clone()
            };
            fdem = fdem.material_for(class.members, rock.model()?);
        }
    }
    if let Some(field) = &h.strength {
        let joints = mesh.interfaces();
        let pts: Vec<f64> = (0..joints.len())
            .flat_map(|j| {
                let n = &joints.nodes()[4 * j..4 * j + 2];
                let (a, b) = (mesh.node(n[0] as usize), mesh.node(n[1] as usize));
                [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])]
            })
            .collect();
        for class in classes(&field.values(&pts, 2)?, h.classes)? {
            let f = class.value;
            let j = JointParams {
                cohesion: s.joints.cohesion * f,
                tensile_strength: s.joints.tensile_strength * f,
                gf1: s.joints.gf1 * f * f,
                gf2: s.joints.gf2 * f * f,
                ..s.joints.clone()
            };
            fdem = fdem.joint_model_for(class.members, j.model(s.rock.young)?);
        }
    }
    Ok(fdem)
}

/// Steps between two reads of the platen reaction: every step on the CPU, where reading
/// costs nothing; on the GPU ten reads per record window of `every` steps (the largest
/// divisor of `every` up to `every / 10`), so that the steps in between run on the
/// device without a read-back.
fn reaction_chunk(kind: BackendKind, every: u64) -> u64 {
    match kind {
        BackendKind::Cpu => 1,
        BackendKind::Gpu => (1..=(every / 10).max(1))
            .rev()
            .find(|c| every % c == 0)
            .unwrap_or(1),
    }
}

/// Broken joints (D = 1) by failure mode and where they are. A joint's mode is that of
/// the first of its Gauss points that broke with a recorded mode.
fn broken_joints(
    sim: &Simulation<Dim2>,
    joints: &pcdc_mesh::Interfaces,
) -> Result<(BrokenCount, Vec<Crack>), SceneError> {
    let damage = sim.field(JOINT_DAMAGE)?;
    let state = sim.field(JOINT_STATE)?;
    let nj = joints.len();
    let stride = state.len().checked_div(nj).unwrap_or(0);
    let mut count = BrokenCount::default();
    let mut cracks = Vec::new();
    for (j, &d) in damage.iter().enumerate() {
        if d < 1.0 {
            continue;
        }
        let st = &state[j * stride..(j + 1) * stride];
        let mode = st
            .chunks_exact(czm_state::LEN)
            .map(|g| FailureMode::from_code(g[czm_state::MODE]))
            .find(|m| *m != FailureMode::Intact)
            .unwrap_or(FailureMode::Mixed);
        match mode {
            FailureMode::Tensile => count.tensile += 1,
            FailureMode::Shear => count.shear += 1,
            _ => count.mixed += 1,
        }
        let n = &joints.nodes()[4 * j..4 * j + 2];
        let (a, b) = (
            sim.mesh().node(n[0] as usize),
            sim.mesh().node(n[1] as usize),
        );
        cracks.push(Crack {
            at: [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])],
            angle_deg: (b[1] - a[1])
                .atan2(b[0] - a[0])
                .to_degrees()
                .rem_euclid(180.0),
            length: (b[0] - a[0]).hypot(b[1] - a[1]),
            mode,
        });
    }
    Ok((count, cracks))
}

/// One VTU frame: the standard arrays of [`output::write_step`] (displacement, velocity;
/// stress, strain, σ1, σ_min) and, per element, the largest joint damage and the number
/// of broken joints.
fn write_frame(
    series: &mut PvdSeries,
    sim: &Simulation<Dim2>,
    joints: &pcdc_mesh::Interfaces,
) -> Result<(), SceneError> {
    let damage = sim.field(JOINT_DAMAGE)?;
    let ne = sim.mesh().n_elements();
    let mut elem_damage = vec![0.0; ne];
    let mut elem_broken = vec![0i32; ne];
    for (j, &d) in damage.iter().enumerate() {
        for &e in &joints.elements()[2 * j..2 * j + 2] {
            let e = e as usize;
            elem_damage[e] = f64::max(elem_damage[e], d);
            if d >= 1.0 {
                elem_broken[e] += 1;
            }
        }
    }
    output::write_step_with(
        series,
        sim,
        &[],
        &[
            DataArray::Scalar {
                name: "joint_damage_max",
                values: &elem_damage,
            },
            DataArray::Int {
                name: "broken_joints",
                values: &elem_broken,
            },
        ],
    )?;
    Ok(())
}

/// Writes the load history as CSV: one row per sample.
pub(crate) fn write_csv(
    path: &std::path::Path,
    header: &str,
    rows: impl Iterator<Item = Vec<f64>>,
) -> std::io::Result<()> {
    use std::io::Write;
    let mut w = std::io::BufWriter::new(std::fs::File::create(path)?);
    writeln!(w, "{header}")?;
    for r in rows {
        let line: Vec<String> = r.iter().map(|v| format!("{v:.9e}")).collect();
        writeln!(w, "{}", line.join(","))?;
    }
    w.flush()
}

impl From<ParamError> for SceneError {
    /// A bad scene parameter is reported as an invalid parameter that names its key.
    fn from(e: ParamError) -> Self {
        SceneError::Compute(pcdc_compute::ComputeError::param(e.key, e.value, e.reason))
    }
}

/// Mean of component `k` of the 2D vectors `values` (u or v) over the nodes `list`.
fn mean_of(values: &[f64], list: &[u32], k: usize) -> f64 {
    list.iter()
        .map(|&n| values[2 * n as usize + k])
        .sum::<f64>()
        / list.len().max(1) as f64
}

/// The servo walls of a biaxial test: the side segments (group name, servo) and the two
/// platens (consolidation only; they are driven while loading).
struct Servos {
    sides: Vec<(String, StressServo)>,
    platens: [StressServo; 2],
}

/// Splits a side's nodes into `segments` runs of neighbours along y (as equal in count
/// as the nodes allow) with their tributary lengths: each node carries half of the
/// gaps to its neighbours, so the lengths add up to the side's height.
fn wall_segments(mesh: &Mesh<Dim2>, side: &[u32], segments: u32) -> Vec<(Vec<u32>, f64)> {
    let mut nodes = side.to_vec();
    nodes.sort_by(|&a, &b| mesh.node(a as usize)[1].total_cmp(&mesh.node(b as usize)[1]));
    let y: Vec<f64> = nodes.iter().map(|&n| mesh.node(n as usize)[1]).collect();
    let n = nodes.len();
    let tributary = |i: usize| {
        let below = if i > 0 { y[i] - y[i - 1] } else { 0.0 };
        let above = if i + 1 < n { y[i + 1] - y[i] } else { 0.0 };
        0.5 * (below + above)
    };
    let k = (segments as usize).clamp(1, n.max(1));
    (0..k)
        .map(|s| {
            let (a, b) = (s * n / k, (s + 1) * n / k);
            (nodes[a..b].to_vec(), (a..b).map(tributary).sum())
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The segments partition the side's nodes into runs along y whose tributary
    /// lengths add up to the side's height; more segments than nodes gives one node
    /// per segment.
    #[test]
    fn wall_segments_partition_a_side_and_its_height() {
        let mesh = builders::rectangle(0.0, 0.0, 0.05, 0.1, 0.01).unwrap();
        let side: Vec<u32> = (0..mesh.n_nodes() as u32)
            .filter(|&n| mesh.node(n as usize)[0] == 0.0)
            .collect();
        for k in [1, 3, 4, 100] {
            let segs = wall_segments(&mesh, &side, k);
            assert_eq!(segs.len(), (k as usize).min(side.len()));
            let mut all: Vec<u32> = segs.iter().flat_map(|s| s.0.clone()).collect();
            all.sort_unstable();
            let mut expect = side.clone();
            expect.sort_unstable();
            assert_eq!(all, expect);
            let total: f64 = segs.iter().map(|s| s.1).sum();
            assert!((total - 0.1).abs() < 1e-12, "{total}");
            // Runs of neighbours: each segment lies above the previous one.
            for w in segs.windows(2) {
                let top = w[0]
                    .0
                    .iter()
                    .map(|&n| mesh.node(n as usize)[1])
                    .fold(f64::MIN, f64::max);
                let bottom = w[1]
                    .0
                    .iter()
                    .map(|&n| mesh.node(n as usize)[1])
                    .fold(f64::MAX, f64::min);
                assert!(top < bottom);
            }
        }
    }
}
