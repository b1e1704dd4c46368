//! The stages of a step after the position update: the post-update stage and the
//! sub-cycled field stages (their schedule is fixed when the simulation is built).
//!
//! One step runs: forces ([`crate::Physics::compute_forces`]), gather and velocity
//! update, kinematic conditions ([`crate::Physics::apply_kinematics`]), position update
//! and watchdog, post-update ([`crate::Physics::post_update`]), then each physics'
//! field stage ([`crate::Physics::field_step`]) as its [`SubCycle`] says: `n` field
//! steps of `dt/n`, or one field step of `n dt` after every `n`-th step. The GPU
//! program runs the same stages in the same order.

use pcdc_mesh::Dim;

use crate::physics::{FieldContext, FieldSchedule, SubCycle};
use crate::{ComputeError, Simulation, StableStep};

/// Largest sub-cycling ratio accepted. A fixed schedule beyond it is refused (almost
/// surely mis-scaled); [`FieldSchedule::Auto`] caps a slower field at it (heat is often
/// 1e7 times slower than the mechanics: it then steps at a million mechanical steps,
/// below its own stable step) and refuses a field that would need more sub-steps.
pub const MAX_SUBCYCLE: u32 = 1_000_000;

/// The schedule of one physics' field stage.
#[derive(Clone, Debug, PartialEq)]
pub struct FieldStage {
    /// The physics.
    pub physics: String,
    /// How it runs relative to the mechanical step.
    pub cycle: SubCycle,
    /// Its own stable step (before the safety factor) and limiting entity, when it
    /// reports one.
    pub limit: Option<StableStep>,
    /// The field step (s): the mechanical step times [`SubCycle::scale`].
    pub dt: f64,
}

impl<D: Dim> Simulation<D> {
    /// Fixes the sub-cycling of every field stage from the physics' schedules, their
    /// field stable steps and the mechanical step.
    pub(crate) fn schedule_field_stages(&mut self) -> Result<(), ComputeError> {
        let kin = self.kinematics();
        let mut stages = Vec::with_capacity(self.physics.len());
        for p in &self.physics {
            let Some(schedule) = p.field_schedule() else {
                stages.push(None);
                continue;
            };
            let limit = p.field_stable_step(&kin, &self.state.fields);
            let cycle = match schedule {
                FieldSchedule::Fixed(c) => c,
                FieldSchedule::Auto => {
                    let l = limit.as_ref().ok_or_else(|| {
                        ComputeError::param(
                            format!("field schedule of physics '{}'", p.name()),
                            "Auto",
                            "the physics reports no field stable step: give a fixed SubCycle",
                        )
                    })?;
                    let dt_f = l.dt * self.safety;
                    if !(dt_f > 0.0 && dt_f.is_finite()) {
                        return Err(ComputeError::param(
                            format!("field stable step of physics '{}' ({})", p.name(), l.entity),
                            l.dt,
                            "must be positive and finite",
                        ));
                    }
                    let ratio = if dt_f >= self.dt {
                        (dt_f / self.dt).floor()
                    } else {
                        (self.dt / dt_f).ceil()
                    };
                    let n = ratio.min(MAX_SUBCYCLE as f64 + 1.0) as u32;
                    if dt_f >= self.dt {
                        // A slower field than that (heat against mechanics: 1e7 and
                        // more) steps below its stable step at the cap: safe, and it
                        // keeps the field moving.
                        SubCycle::Every(n.clamp(1, MAX_SUBCYCLE))
                    } else {
                        SubCycle::Substeps(n.max(1))
                    }
                }
            };
            let n = match cycle {
                SubCycle::Substeps(n) | SubCycle::Every(n) => n,
            };
            if n == 0 || n > MAX_SUBCYCLE {
                return Err(ComputeError::param(
                    format!("sub-cycling of physics '{}'", p.name()),
                    format!("{cycle:?}"),
                    format!("the ratio must lie in 1..={MAX_SUBCYCLE}"),
                ));
            }
            stages.push(Some(FieldStage {
                physics: p.name().to_string(),
                cycle,
                limit,
                dt: self.dt * cycle.scale(),
            }));
        }
        self.field_stages = stages;
        Ok(())
    }

    /// The field stages of the composed physics and their schedules (the mechanical
    /// limit is [`Simulation::time_step_limit`]).
    pub fn field_stages(&self) -> Vec<&FieldStage> {
        self.field_stages.iter().flatten().collect()
    }

    /// Post-update and field stages after the position update of step `self.state.step`
    /// (CPU backend).
    pub(crate) fn after_update(&mut self) -> Result<(), ComputeError> {
        let step = self.state.step;
        let t_end = self.state.time;
        let dt = self.dt;
        {
            for p in self.physics.iter_mut() {
                let mut ctx = FieldContext {
                    kin: crate::physics::Kinematics {
                        mesh: &self.mesh,
                        coords: &self.coords,
                        mass: &self.mass_phys,
                        u: &self.state.u,
                        v: &self.state.v,
                        time: t_end,
                        dt,
                        step,
                        damping: self.damping,
                    },
                    fields: &mut self.state.fields,
                    dt,
                    time: t_end,
                    substep: 0,
                    backend: &self.backend,
                };
                p.post_update(&mut ctx)?;
            }
        }
        for (p, stage) in self.physics.iter_mut().zip(&self.field_stages) {
            let Some(stage) = stage else { continue };
            if !stage.cycle.runs_after(step) {
                continue;
            }
            // The same expression as the GPU kernels' p_dt() * FIELD_DT_SCALE.
            let dt_f = dt * stage.cycle.scale();
            let start = match stage.cycle {
                SubCycle::Substeps(_) => t_end - dt,
                SubCycle::Every(_) => t_end - dt_f,
            };
            for k in 0..stage.cycle.substeps() {
                let mut ctx = FieldContext {
                    kin: crate::physics::Kinematics {
                        mesh: &self.mesh,
                        coords: &self.coords,
                        mass: &self.mass_phys,
                        u: &self.state.u,
                        v: &self.state.v,
                        time: t_end,
                        dt,
                        step,
                        damping: self.damping,
                    },
                    fields: &mut self.state.fields,
                    dt: dt_f,
                    time: start + k as f64 * dt_f,
                    substep: k,
                    backend: &self.backend,
                };
                p.field_step(&mut ctx)?;
            }
        }
        Ok(())
    }
}
