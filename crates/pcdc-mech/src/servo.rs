//! Servo-controlled walls (PFC's servo mechanism): a stress servo drives the velocity of
//! a set of nodes (a platen's loaded edge, a specimen's side) along one axis so that
//! the reaction on them holds a target stress.
//!
//! The nodes get a velocity condition whose value is a [`Control`]
//! ([`StressServo::velocity`], for [`crate::Boundary::velocity`]); between steps the
//! program calls [`StressServo::update`], which reads the reaction (the gathered force
//! on the nodes, [`Simulation::node_force`]), converts it to a stress over the loaded
//! length (2D, per unit thickness) or area (3D) and sets the inward speed by a PI law:
//!
//! v = K_p e + K_i ∫ e dt + v_ff, e = σ_target − σ_measured (compression positive),
//!
//! with an optional feed-forward speed v_ff ([`StressServo::set_feed_forward`]),
//!
//! with K_p = min(span / (M τ), 0.5 / Z) ([`ServoGains::for_specimen`]): a stress
//! error closes in about τ through a specimen of modulus M and span (the distance to the
//! opposite wall), but no faster than the wall's impedance Z = ρ c allows: a velocity
//! step Δv sends a stress ρ c Δv into the body behind the wall at once, so the error
//! after an update is (1 − K_p Z) times the one before: K_p Z ≥ 1 flips the wall's speed
//! every update (measured: a steel platen with K_p Z = 2.4 oscillated at ±1 m/s), and
//! 0.5 halves the error per update without overshoot. K_i = K_p / (2 τ) with the
//! response time τ = span / (M K_p) the gain gives (the wall on its specimen is an
//! integrating plant, σ̇ = (M / span) v, and 2 τ damps the PI loop at ζ = √2 / 2 ≈ 0.7).
//! The integral term supplies the steady speed a wall needs to follow a specimen that
//! keeps expanding (a biaxial test's lateral dilation), which a proportional servo
//! (PFC's) can only follow with a lag error. The speed is capped at `max_speed`, and
//! the integral stops growing while capped (no wind-up). A response time of a few P-wave
//! transits of the span keeps the loop stable against the specimen's own dynamics.

use pcdc_compute::{Control, Simulation, TimeValue};
use pcdc_mesh::Dim;

use crate::MechError;

/// The gains of a [`StressServo`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ServoGains {
    /// Proportional gain K_p (m/s per Pa).
    pub proportional: f64,
    /// Integral time T_i (s): K_i = K_p / T_i.
    pub integral_time: f64,
}

impl ServoGains {
    /// Gains for a wall on a specimen of P-wave modulus `modulus` (Pa) and `span` (m),
    /// aiming at a response time `tau` (s), limited by the impedance `impedance`
    /// (ρ c, Pa·s/m) of the body the wall drives or pushes, whichever is larger (module
    /// docs).
    pub fn for_specimen(modulus: f64, span: f64, tau: f64, impedance: f64) -> Self {
        let kp = (span / (modulus * tau)).min(0.5 / impedance);
        let tau_eff = span / (modulus * kp);
        ServoGains {
            proportional: kp,
            integral_time: 2.0 * tau_eff,
        }
    }

    /// The response time span / (M K_p) these gains give on a specimen (s).
    pub fn response_time(&self, modulus: f64, span: f64) -> f64 {
        span / (modulus * self.proportional)
    }
}

/// A stress servo on one axis of a node set (module docs).
#[derive(Clone, Debug)]
pub struct StressServo {
    nodes: Vec<u32>,
    axis: usize,
    inward: f64,
    area: f64,
    target: f64,
    kp: f64,
    ki: f64,
    max_speed: f64,
    integral: f64,
    feed_forward: f64,
    control: Control,
    last_time: Option<f64>,
}

impl StressServo {
    /// A servo on `nodes` moving along `axis` (0 x, 1 y, 2 z); `inward` is +1 when the
    /// wall pushes the specimen towards +axis, −1 towards −axis. `area`: loaded length
    /// (m, 2D per unit thickness) or area (m², 3D); `target`: stress to hold (Pa,
    /// compression positive); `gains` (e.g. [`ServoGains::for_specimen`]);
    /// `max_speed` (m/s) caps the speed.
    pub fn new(
        nodes: Vec<u32>,
        axis: usize,
        inward: f64,
        area: f64,
        target: f64,
        gains: ServoGains,
        max_speed: f64,
    ) -> Result<Self, MechError> {
        if nodes.is_empty() {
            return Err(MechError::param(
                "servo nodes",
                "none",
                "the servo needs at least one node",
            ));
        }
        if axis > 2 {
            return Err(MechError::param("servo axis", axis, "must be 0, 1 or 2"));
        }
        if inward != 1.0 && inward != -1.0 {
            return Err(MechError::param("servo inward", inward, "must be +1 or -1"));
        }
        for (name, v) in [
            ("servo area", area),
            ("servo proportional gain", gains.proportional),
            ("servo integral time", gains.integral_time),
            ("servo max_speed", max_speed),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(MechError::param(name, v, "must be finite and positive"));
            }
        }
        if !target.is_finite() {
            return Err(MechError::param("servo target", target, "must be finite"));
        }
        Ok(StressServo {
            nodes,
            axis,
            inward,
            area,
            target,
            kp: gains.proportional,
            ki: gains.proportional / gains.integral_time,
            max_speed,
            integral: 0.0,
            feed_forward: 0.0,
            control: Control::new(0.0),
            last_time: None,
        })
    }

    /// The velocity value of the nodes' condition along the servo's axis.
    pub fn velocity(&self) -> TimeValue {
        self.control.clone().into()
    }

    /// The response time of the proportional gain on the servo's own terms: the integral
    /// time / 2 (s).
    pub fn response_time(&self) -> f64 {
        self.kp / self.ki / 2.0
    }

    /// The loaded length (m, 2D per unit thickness) or area (m², 3D).
    pub fn area(&self) -> f64 {
        self.area
    }

    /// The nodes.
    pub fn nodes(&self) -> &[u32] {
        &self.nodes
    }

    /// Sets a new target stress (Pa, compression positive).
    pub fn set_target(&mut self, target: f64) {
        if target.is_finite() {
            self.target = target;
        }
    }

    /// The target stress (Pa).
    pub fn target(&self) -> f64 {
        self.target
    }

    /// The stress on the nodes now (Pa, compression positive): the gathered force on
    /// them along the axis, pushing against the inward direction, over the area.
    pub fn stress<D: Dim>(&self, sim: &Simulation<D>) -> f64 {
        let f = sim.node_force();
        let d = D::D;
        let sum: f64 = self
            .nodes
            .iter()
            .map(|&n| f[d * n as usize + self.axis])
            .sum();
        -self.inward * sum / self.area
    }

    /// Reads the stress, updates the wall speed (module docs) and returns the stress
    /// (Pa). Call it between steps; the first call only starts the clock's integral.
    pub fn update<D: Dim>(&mut self, sim: &Simulation<D>) -> f64 {
        let s = self.stress(sim);
        let t = sim.state.time;
        let dt = self.last_time.map_or(0.0, |t0| (t - t0).max(0.0));
        self.last_time = Some(t);
        let e = self.target - s;
        let trial = self.integral + self.ki * e * dt;
        let v = self.kp * e + trial + self.feed_forward;
        let capped = v.clamp(-self.max_speed, self.max_speed);
        if capped == v {
            self.integral = trial;
        }
        self.control.set(self.inward * capped);
        s
    }

    /// A known inward speed (m/s) added to the PI output, e.g. the speed at which a
    /// specimen is expected to push the wall out (negative): the PI then corrects only
    /// the estimate's error, so a sudden start of that motion does not open a lag.
    pub fn set_feed_forward(&mut self, speed: f64) {
        if speed.is_finite() {
            self.feed_forward = speed;
        }
    }

    /// Turns the servo off and drives the wall inward at `speed` (m/s) until the next
    /// [`Self::update`] or `drive`.
    pub fn drive(&mut self, speed: f64) {
        self.integral = 0.0;
        self.control.set(self.inward * speed);
    }

    /// Stops the wall (speed 0) and clears the integral.
    pub fn stop(&mut self) {
        self.integral = 0.0;
        self.control.set(0.0);
    }
}
