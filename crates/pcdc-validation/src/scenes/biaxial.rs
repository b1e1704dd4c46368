//! Biaxial compression series with servo-controlled confinement (issue 19; PFC's
//! biaxial test with servo walls): the UCS sample of [`crate::scenes::ucs`] (its mesh,
//! rock, joints, platens and loading) with its sides held at a confining stress σ3 by
//! servo walls ([`pcdc_mech::StressServo`], [`Confinement`]), loaded axially to failure
//! at several σ3; the peaks σ1(σ3) give the Mohr-Coulomb envelope of the jointed rock.
//!
//! Envelope: the least-squares line σ1 = N σ3 + σ_c through the peaks gives
//! φ = asin((N − 1)/(N + 1)) and c = σ_c / (2 √N) (Mohr-Coulomb in principal stresses,
//! N = (1 + sin φ)/(1 − sin φ)). It is compared with the joints' c and φ: the rock is
//! stronger than one joint plane (failure must cross joints at every orientation, and
//! the joints' tensile cut-off and softening act too), so the fit reports, not assumes,
//! how the two relate.
//!
//! The walls push the sides through soft membranes ([`Membrane`], the rubber sleeve of
//! a laboratory cell): a burst of cracking that pushes the rock out reaches the wall as
//! the membrane's small stress change, not as a spike of the rock's impedance.
//!
//! Servo check: the sides' confining stress (window means of the two walls) must stay
//! within 1 % of σ3 from the start of the axial loading to the peak
//! ([`CONFINEMENT_TOL`]). σ3 = 0 is the unconfined test (no servo, no membrane).

use pcdc_compute::Backend;

use super::platen_test::{Confinement, Membrane, CONFINEMENT_SEGMENTS};
use super::ucs;
use crate::report::SceneError;

/// Largest deviation of the confining stress from σ3 before the peak.
pub const CONFINEMENT_TOL: f64 = 0.01;

/// The platens' ramp to full speed in servo response times ([`Params::full`]).
pub const RAMP_RESPONSES: f64 = 8.0;

/// Confining stresses of the series (Pa): 0, 5, 10 and 20 MPa.
pub const PRESSURES: [f64; 4] = [0.0, 5e6, 10e6, 20e6];

/// Parameters of the series.
#[derive(Clone, Debug)]
pub struct Params {
    /// The sample, rock, joints, platens and loading (a UCS scene).
    pub sample: ucs::Params,
    /// Confining stresses (Pa, ≥ 0).
    pub pressures: Vec<f64>,
    /// Servo response time (s).
    pub response_time: f64,
    /// Largest servo wall speed (m/s).
    pub max_speed: f64,
    /// Servo wall segments per side ([`Confinement::segments`]).
    pub segments: u32,
    /// The membrane between the walls and the sides ([`Confinement::membrane`]).
    pub membrane: Option<Membrane>,
}

impl Params {
    /// The series on the UCS quick start's sample (calibrated rock, 2 mm mesh) at
    /// [`PRESSURES`]; servo response 25 µs (about 1.5 P-wave transits of the 52 mm
    /// width), walls at most 1 m/s, [`CONFINEMENT_SEGMENTS`] wall per side behind the
    /// default [`Membrane`]. The platens' speed ramps up
    /// over [`RAMP_RESPONSES`] servo response times, so that the sides' servos follow
    /// the start of the lateral expansion (over the UCS test's 50 µs ramp they fell
    /// 1-2 % behind, measured). Each test stops once the stress has fallen to 90 % of
    /// its peak (a confined sample keeps most of its strength after the peak; run on,
    /// it compacts and hardens).
    pub fn full() -> Self {
        let mut sample = ucs::Params::full();
        sample.output.frames = 0;
        // Confined rock keeps most of its strength after the peak: stop at 90 %.
        sample.loading.stop_fraction = 0.9;
        let response_time = 2.5e-5;
        sample.loading.ramp_time = sample.loading.ramp_time.max(RAMP_RESPONSES * response_time);
        Params {
            sample,
            pressures: PRESSURES.to_vec(),
            response_time,
            max_speed: 1.0,
            segments: CONFINEMENT_SEGMENTS,
            membrane: Some(Membrane::default()),
        }
    }

    /// The same at the reduced size of the UCS tests (5 mm mesh).
    pub fn reduced() -> Self {
        let mut p = Self::full();
        let r = ucs::Params::reduced();
        p.sample.sample = r.sample;
        p.sample.loading = r.loading;
        p.sample.loading.stop_fraction = 0.9;
        p.sample.loading.ramp_time = p
            .sample
            .loading
            .ramp_time
            .max(RAMP_RESPONSES * p.response_time);
        p
    }
}

/// One test of the series.
#[derive(Clone, Debug)]
pub struct Test {
    /// Confining stress σ3 (Pa).
    pub sigma3: f64,
    /// Peak axial stress σ1 (Pa).
    pub sigma1: f64,
    /// Largest relative deviation of the confining stress in the pre-peak (up to 95 %
    /// of the peak).
    pub deviation: f64,
    /// Largest relative deviation from 95 % of the peak to the peak.
    pub deviation_at_failure: f64,
    /// Share of the pre-peak record windows within 1 % of σ3.
    pub held: f64,
    /// Axial strain at the peak.
    pub strain_at_peak: f64,
    /// Broken joints at the end.
    pub broken: usize,
    /// The whole UCS-scene outcome.
    pub outcome: ucs::Outcome,
}

/// The series and its envelope.
#[derive(Clone, Debug)]
pub struct Outcome {
    /// The tests, in the order of the pressures.
    pub tests: Vec<Test>,
    /// Fitted friction angle (degrees).
    pub friction_deg: f64,
    /// Fitted cohesion (Pa).
    pub cohesion: f64,
    /// Fitted unconfined strength σ_c (Pa) and slope N.
    pub sigma_c: f64,
    /// See [`Outcome::sigma_c`].
    pub slope: f64,
    /// Coefficient of determination of the fit.
    pub r2: f64,
    /// Wall time of the series (s).
    pub wall_s: f64,
}

impl Outcome {
    /// Largest confinement deviation over the tests.
    pub fn max_deviation(&self) -> f64 {
        self.tests.iter().map(|t| t.deviation).fold(0.0, f64::max)
    }
}

/// Runs the series; `progress` sees each finished test.
pub fn run(
    backend: &Backend,
    p: &Params,
    progress: &mut dyn FnMut(&Test),
) -> Result<Outcome, SceneError> {
    if p.pressures.len() < 2 {
        return Err(SceneError::Measurement(
            "biaxial series: give at least two confining stresses to fit an envelope".into(),
        ));
    }
    if let Some(&bad) = p.pressures.iter().find(|s| !(s.is_finite() && **s >= 0.0)) {
        return Err(SceneError::Measurement(format!(
            "biaxial series: confining stress {bad} Pa must be finite and non-negative"
        )));
    }
    let start = std::time::Instant::now();
    let mut tests = Vec::new();
    for &sigma3 in &p.pressures {
        let mut q = p.sample.clone();
        q.confinement = (sigma3 > 0.0).then_some(Confinement {
            stress: sigma3,
            response_time: p.response_time,
            max_speed: p.max_speed,
            tolerance: 0.5 * CONFINEMENT_TOL,
            segments: p.segments,
            membrane: p.membrane,
        });
        let out = ucs::run(backend, &q, &mut |_| {})?;
        let t = Test {
            sigma3,
            sigma1: out.ucs,
            deviation: out.confinement_deviation,
            deviation_at_failure: out.confinement_deviation_at_failure,
            held: out.confinement_held,
            strain_at_peak: out.strain_at_peak,
            broken: out.broken.total(),
            outcome: out,
        };
        progress(&t);
        tests.push(t);
    }
    // Least squares σ1 = N σ3 + σ_c.
    let n = tests.len() as f64;
    let (mx, my) = (
        tests.iter().map(|t| t.sigma3).sum::<f64>() / n,
        tests.iter().map(|t| t.sigma1).sum::<f64>() / n,
    );
    let sxx: f64 = tests.iter().map(|t| (t.sigma3 - mx).powi(2)).sum();
    let sxy: f64 = tests
        .iter()
        .map(|t| (t.sigma3 - mx) * (t.sigma1 - my))
        .sum();
    let syy: f64 = tests.iter().map(|t| (t.sigma1 - my).powi(2)).sum();
    if sxx <= 0.0 {
        return Err(SceneError::Measurement(
            "biaxial series: the confining stresses must differ".into(),
        ));
    }
    let slope = sxy / sxx;
    let sigma_c = my - slope * mx;
    let r2 = if syy > 0.0 {
        sxy * sxy / (sxx * syy)
    } else {
        1.0
    };
    let sin_phi = ((slope - 1.0) / (slope + 1.0)).clamp(-1.0, 1.0);
    Ok(Outcome {
        tests,
        friction_deg: sin_phi.asin().to_degrees(),
        cohesion: sigma_c / (2.0 * slope.max(0.0).sqrt()),
        sigma_c,
        slope,
        r2,
        wall_s: start.elapsed().as_secs_f64(),
    })
}
