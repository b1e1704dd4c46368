//! Energy balance and the energy watchdog.
//!
//! With tracking on ([`crate::SimulationBuilder::track_energy`] or
//! [`crate::SimulationBuilder::energy_watchdog`]) the simulation accumulates, every
//! step, the work that each force source does on the nodes, with the step's mean
//! velocity v̄ = (v⁻ + v⁺)/2 (v⁻ before the velocity update, v⁺ the velocity the node
//! then moves with, after the kinematic conditions):
//!
//! W = Σ_steps Σ_nodes Δt f · v̄.
//!
//! For the central-difference update v⁺ = v⁻ + Δt (F + R)/m (R the reaction of the
//! kinematic conditions) this is exact: ½ m (v⁺² − v⁻²) = Δt (F + R) · v̄, so the sum
//! of all works equals the change of kinetic energy to rounding. The sources are
//!
//! - each internal physics p (elements, joints, contact): its forces do the work −A_p,
//!   A_p the energy it *absorbed*;
//! - applied loads ([`crate::Physics::applies_loads`], e.g. face tractions) and
//!   gravity: external work;
//! - kinematic conditions (prescribed velocities, supports): Δt R · v̄, the rest of each
//!   node's kinetic-energy change (zero at a fixed node, the platen's work at a moved
//!   one), counted as external work;
//! - local non-viscous damping: dissipated.
//!
//! A physics stores S_p ([`crate::Physics::stored_energy`]) and dissipates the rest of
//! what it absorbed: D_p = A_p − (S_p − S_p(0)). A passive physics (elastic storage,
//! fracture, friction, viscous damping) has D_p ≥ 0 at all times; D_p < 0 means the
//! physics gave back more energy than it took and holds: it *injects* energy. The
//! balance
//!
//! total = K + Σ S_p + Σ max(D_p, 0) + D_local,  excess = total − (E_0 + W_ext)
//!
//! is therefore the energy created by physics that are not passive (to rounding: the
//! stored energies describe u_N, so the last step's forward half ½ Δt f · v⁺ is taken off
//! every work and the kinetic energy is that of time N, ½ m v⁻ · v⁺; a linear elastic
//! body then balances exactly, as the leapfrog invariant says). The watchdog stops the run when the excess exceeds a tolerance
//! times the reference energy max(E_0 + W_ext, largest total so far), naming the step,
//! the physics whose D_p fell the most since the previous evaluation (a physics
//! that dissipated much earlier, e.g. fracture energy, cannot hide a recent injection
//! behind it) and the entity whose forces did the most work
//! on the nodes in that step. Stored energies are evaluated every
//! [`ENERGY_CHECK_EVERY`] steps (they cost a pass over the physics' entities); the works
//! are accumulated every step.
//!
//! A physics that does not report its stored energy (default 0) is still checked: its
//! D_p is then A_p − 0, the energy it holds plus what it dissipated, which must not go
//! negative either when it starts unloaded.

use pcdc_mesh::Dim;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::{ComputeError, Simulation};

/// Steps between two evaluations of the stored energies (and of the watchdog).
pub const ENERGY_CHECK_EVERY: u64 = 100;

/// Nodes per chunk of the work pass: the partial sums are added in chunk order, so the
/// balance does not depend on the thread count.
const CHUNK: usize = 4096;

/// Adds node `n`'s works over the step into `acc[..NACC]` (per physics, then gravity,
/// local damping, kinematic conditions) and their forward halves ½ Δt f · v⁺ into
/// `acc[NACC..]`: the same arithmetic as the `energy_work` kernel.
#[allow(clippy::too_many_arguments)]
#[inline]
fn node_works(
    n: usize,
    d: usize,
    dt: f64,
    g: [f64; 3],
    alpha: f64,
    m: f64,
    ptr: &[u32],
    idx: &[u32],
    slots: &[f64],
    slot_phys: &[u32],
    v_prev: &[f64],
    v: &[f64],
    acc: &mut [f64],
) {
    let nacc = acc.len() / 2;
    let np = nacc - 3;
    let mut vbar = [0.0; 3];
    for k in 0..d {
        vbar[k] = 0.5 * (v_prev[n * d + k] + v[n * d + k]);
    }
    let mut fsum = [0.0; 3];
    let (mut total, mut total_fwd) = (0.0, 0.0);
    for &s in &idx[ptr[n] as usize..ptr[n + 1] as usize] {
        let s = s as usize;
        let (mut w, mut wf) = (0.0, 0.0);
        for k in 0..d {
            let f = slots[s * d + k];
            w += f * vbar[k];
            wf += f * v[n * d + k];
            fsum[k] += f;
        }
        let p = slot_phys[s] as usize;
        acc[p] += dt * w;
        acc[nacc + p] += 0.5 * dt * wf;
        total += dt * w;
        total_fwd += 0.5 * dt * wf;
    }
    let (mut dke, mut dke_fwd) = (0.0, 0.0);
    for k in 0..d {
        let i = n * d + k;
        let fg = m * g[k];
        acc[np] += dt * fg * vbar[k];
        acc[nacc + np] += 0.5 * dt * fg * v[i];
        total += dt * fg * vbar[k];
        total_fwd += 0.5 * dt * fg * v[i];
        if alpha > 0.0 && v_prev[i] != 0.0 {
            let fl = -alpha * (fsum[k] + fg).abs() * v_prev[i].signum();
            acc[np + 1] += dt * fl * vbar[k];
            acc[nacc + np + 1] += 0.5 * dt * fl * v[i];
            total += dt * fl * vbar[k];
            total_fwd += 0.5 * dt * fl * v[i];
        }
        dke += v[i] * v[i] - v_prev[i] * v_prev[i];
        dke_fwd += (v[i] - v_prev[i]) * v[i];
    }
    // ½ m (v⁺² − v⁻²) = Δt (F + R) · v̄ and ½ m (v⁺ − v⁻) · v⁺ = ½ Δt (F + R) · v⁺.
    acc[np + 2] += 0.5 * m * dke - total;
    acc[nacc + np + 2] += 0.5 * m * dke_fwd - total_fwd;
}

/// The energy of one physics in an [`EnergyBalance`] (J; per unit thickness in 2D).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PhysicsEnergy {
    /// The physics' name.
    pub name: String,
    /// Whether its forces are applied loads (its work is external work).
    pub applies_loads: bool,
    /// Stored energy now, S_p (J).
    pub stored: f64,
    /// Stored energy at the start of tracking, S_p(0) (J).
    pub stored_initial: f64,
    /// Energy absorbed from the nodes, A_p = −(work of its forces) (J).
    pub absorbed: f64,
}

impl PhysicsEnergy {
    /// Energy dissipated, inferred: D_p = A_p − (S_p − S_p(0)) (J); negative means the
    /// physics injected energy. Zero for applied loads.
    pub fn dissipated(&self) -> f64 {
        if self.applies_loads {
            0.0
        } else {
            self.absorbed - (self.stored - self.stored_initial)
        }
    }
}

/// The energy balance of a run since tracking started (J; per unit thickness in 2D).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct EnergyBalance {
    /// Step of the evaluation.
    pub step: u64,
    /// Kinetic energy now, ½ Σ m v² with the half-step velocities (J).
    pub kinetic: f64,
    /// Initial total energy E_0 = K(0) + Σ S_p(0) (J).
    pub initial: f64,
    /// Work of gravity, applied loads and kinematic conditions, W_ext (J).
    pub external_work: f64,
    /// The part of `external_work` done by the kinematic conditions (J): zero for fixed
    /// supports, the work of a prescribed motion.
    pub kinematic_work: f64,
    /// Energy removed by local non-viscous damping, D_local ≥ 0 (J).
    pub local_damping: f64,
    /// Per physics, in composition order.
    pub physics: Vec<PhysicsEnergy>,
}

impl EnergyBalance {
    /// Total energy K + Σ S_p + Σ max(D_p, 0) + D_local (J).
    pub fn total(&self) -> f64 {
        self.kinetic
            + self
                .physics
                .iter()
                .filter(|p| !p.applies_loads)
                .map(|p| p.stored + p.dissipated().max(0.0))
                .sum::<f64>()
            + self.local_damping
    }

    /// Energy created: total − (E_0 + W_ext) (J); about zero in a sound run.
    pub fn excess(&self) -> f64 {
        self.total() - (self.initial + self.external_work)
    }

    /// The physics that injects the most energy (most negative D_p), if any does.
    pub fn worst(&self) -> Option<&PhysicsEnergy> {
        self.physics
            .iter()
            .filter(|p| p.dissipated() < 0.0)
            .min_by(|a, b| a.dissipated().total_cmp(&b.dissipated()))
    }
}

/// Accumulated works (J): what each internal physics absorbed, the external work (of
/// which the kinematic conditions' part) and the local damping.
#[derive(Clone, Debug, Default)]
struct Sums {
    absorbed: Vec<f64>,
    external: f64,
    kinematic: f64,
    local_damping: f64,
}

impl Sums {
    /// Adds `sign` × one batch of works (per physics, then gravity, local damping and
    /// kinematic conditions).
    fn add(&mut self, works: &[f64], loads: &[bool], sign: f64) {
        let n = loads.len();
        for (p, (&w, &load)) in works[..n].iter().zip(loads).enumerate() {
            if load {
                self.external += sign * w;
            } else {
                self.absorbed[p] -= sign * w;
            }
        }
        self.external += sign * (works[n] + works[n + 2]);
        self.kinematic += sign * works[n + 2];
        self.local_damping -= sign * works[n + 1];
    }
}

/// The running accumulators (J).
#[derive(Clone, Debug)]
pub(crate) struct EnergyTracker {
    /// Relative tolerance of the watchdog; `None` tracks without stopping.
    pub tolerance: Option<f64>,
    /// Physics of each force slot.
    slot_phys: Vec<u32>,
    /// Per physics: whether its forces are applied loads (external work).
    loads: Vec<bool>,
    /// Velocity before this step's update.
    v_prev: Vec<f64>,
    /// Works accumulated over all steps.
    sums: Sums,
    /// Per physics: stored energy at the start (None until the first evaluation).
    stored_initial: Option<Vec<f64>>,
    initial: f64,
    /// Largest total energy seen at an evaluation.
    peak: f64,
    /// Inferred dissipation per physics at the previous evaluation.
    dissipated_before: Vec<f64>,
    /// Forward halves ½ Δt f · v⁺ of the last step's works (same layout as a batch of
    /// works): the part of the last step that lies beyond the state the stored energies
    /// describe.
    forward: Vec<f64>,
    /// Last evaluated balance.
    pub last: Option<EnergyBalance>,
}

impl EnergyTracker {
    pub fn new(
        tolerance: Option<f64>,
        slot_ranges: &[std::ops::Range<usize>],
        loads: Vec<bool>,
    ) -> Self {
        let n_slots = slot_ranges.last().map_or(0, |r| r.end);
        let mut slot_phys = vec![0u32; n_slots];
        for (p, r) in slot_ranges.iter().enumerate() {
            slot_phys[r.clone()].fill(p as u32);
        }
        EnergyTracker {
            tolerance,
            slot_phys,
            v_prev: Vec::new(),
            sums: Sums {
                absorbed: vec![0.0; loads.len()],
                ..Sums::default()
            },
            forward: vec![0.0; loads.len() + 3],
            loads,
            stored_initial: None,
            initial: 0.0,
            peak: 0.0,
            dissipated_before: Vec::new(),
            last: None,
        }
    }

    /// Adds one step's (CPU) or one run's (GPU) batch: the works (per physics, then
    /// gravity, local damping and kinematic conditions), followed by the last step's
    /// forward halves in the same layout; the same bookkeeping on both backends.
    pub fn add_batch(&mut self, batch: &[f64]) {
        let n = self.loads.len() + 3;
        self.sums.add(&batch[..n], &self.loads, 1.0);
        self.forward.copy_from_slice(&batch[n..2 * n]);
    }

    /// The sums at the state the stored energies describe: the last step's forward
    /// halves taken off.
    fn sums_at_state(&self) -> Sums {
        let mut s = self.sums.clone();
        s.add(&self.forward, &self.loads, -1.0);
        s
    }

    /// Restarts the balance from the current state (e.g. after static relaxation).
    pub fn rebase(&mut self) {
        self.sums = Sums {
            absorbed: vec![0.0; self.loads.len()],
            ..Sums::default()
        };
        self.stored_initial = None;
        self.initial = 0.0;
        self.peak = 0.0;
        self.dissipated_before.clear();
        self.forward.fill(0.0);
        self.last = None;
    }
}

impl<D: Dim> Simulation<D> {
    /// Before the velocity update: keeps v⁻ and, on the first tracked step, the initial
    /// energies.
    pub(crate) fn energy_before_update(&mut self) {
        let Some(mut t) = self.energy.take() else {
            return;
        };
        self.energy_baseline(&mut t);
        t.v_prev.clear();
        t.v_prev.extend_from_slice(&self.state.v);
        self.energy = Some(t);
    }

    /// After the step (velocity update, kinematic conditions, position update): the
    /// work of every source over the step with v̄ = (v⁻ + v⁺)/2, v⁺ the velocity the
    /// nodes actually moved with; the kinematic conditions get the rest of each node's
    /// kinetic-energy change. Every [`ENERGY_CHECK_EVERY`] steps: the balance and the
    /// watchdog.
    pub(crate) fn energy_after_step(&mut self) -> Result<(), ComputeError> {
        let Some(mut t) = self.energy.take() else {
            return Ok(());
        };
        let d = D::D;
        let n_phys = self.physics.len();
        let (dt, g, alpha) = (self.dt, self.gravity, self.local_damping);
        let (ptr, idx, slots) = (&self.gather_ptr, &self.gather_idx, &self.slot_forces);
        let (mass, v, vp) = (&self.mass, &self.state.v, &t.v_prev);
        let sp = &t.slot_phys;
        // Per chunk: work per physics, gravity, local damping, kinematic conditions.
        let parts: Vec<Vec<f64>> = self.backend.install(|| {
            (0..self.n_nodes())
                .into_par_iter()
                .step_by(CHUNK)
                .map(|start| {
                    let mut acc = vec![0.0; 2 * (n_phys + 3)];
                    for n in start..(start + CHUNK).min(mass.len()) {
                        node_works(
                            n, d, dt, g, alpha, mass[n], ptr, idx, slots, sp, vp, v, &mut acc,
                        );
                    }
                    acc
                })
                .collect()
        });
        let mut sum = vec![0.0; 2 * (n_phys + 3)];
        for part in &parts {
            for (a, b) in sum.iter_mut().zip(part) {
                *a += b;
            }
        }
        t.add_batch(&sum);
        let verdict = if self.state.step % ENERGY_CHECK_EVERY == 0 {
            self.energy_check(&mut t)
        } else {
            Ok(())
        };
        self.energy = Some(t);
        verdict
    }

    /// Takes the initial energies on the first tracked step.
    pub(crate) fn energy_baseline(&self, t: &mut EnergyTracker) {
        if t.stored_initial.is_none() {
            let stored = self.stored_by_physics();
            t.initial = self.kinetic_energy() + stored.iter().sum::<f64>();
            t.peak = t.initial;
            t.stored_initial = Some(stored);
        }
    }

    /// Evaluates the balance into `t.last` and applies the watchdog.
    pub(crate) fn energy_check(&self, t: &mut EnergyTracker) -> Result<(), ComputeError> {
        let stored = self.stored_by_physics();
        let initial = t.stored_initial.clone().unwrap_or_else(|| stored.clone());
        // The stored energies describe u_N (the fields of the last force evaluation),
        // while the works run to u_{N+1}: take the forward halves of the last step off
        // every work and use the kinetic energy of time N, ½ m v⁻ · v⁺ = K(v⁺) − Σ of
        // the forward halves. With these, the balance of a linear elastic body is exact
        // (the leapfrog invariant), not only to O(ω Δt).
        let check = t.sums_at_state();
        let kinetic = self.kinetic_energy() - t.forward.iter().sum::<f64>();
        let balance = EnergyBalance {
            step: self.state.step,
            kinetic,
            initial: t.initial,
            external_work: check.external,
            kinematic_work: check.kinematic,
            local_damping: check.local_damping,
            physics: self
                .physics
                .iter()
                .enumerate()
                .map(|(p, ph)| PhysicsEnergy {
                    name: ph.name().to_string(),
                    applies_loads: ph.applies_loads(),
                    stored: stored[p],
                    stored_initial: initial[p],
                    absorbed: check.absorbed[p],
                })
                .collect(),
        };
        let total = balance.total();
        t.peak = t.peak.max(total);
        let reference = (t.initial + check.external).max(t.peak);
        let excess = balance.excess();
        // Dissipation gained since the previous evaluation, per physics: the injector is
        // the physics whose dissipation fell the most over the window in which the
        // excess appeared (its cumulative dissipation, e.g. fracture energy, could hide
        // a recent injection).
        let dissipated: Vec<f64> = balance.physics.iter().map(|q| q.dissipated()).collect();
        let previous = std::mem::replace(&mut t.dissipated_before, dissipated.clone());
        t.last = Some(balance);
        let Some(tol) = t.tolerance else {
            return Ok(());
        };
        if reference > 0.0 && excess > tol * reference {
            let worst = (0..dissipated.len())
                .filter(|&p| !t.loads[p])
                .map(|p| (p, dissipated[p] - previous.get(p).copied().unwrap_or(0.0)))
                .filter(|&(_, gain)| gain < 0.0)
                .min_by(|a, b| a.1.total_cmp(&b.1));
            let (physics, entity) = match worst {
                Some((p, _)) => (
                    self.physics[p].name().to_string(),
                    self.most_active_entity(p, t),
                ),
                None => (
                    "(no physics whose dissipation fell)".to_string(),
                    String::new(),
                ),
            };
            return Err(ComputeError::EnergyGrowth {
                step: self.state.step,
                time: self.state.time,
                excess,
                reference,
                tolerance: tol,
                physics,
                entity,
            });
        }
        Ok(())
    }

    /// The entity of physics `p` whose forces did the most work on the nodes over the
    /// last step (the likeliest injector), named by the physics.
    fn most_active_entity(&self, p: usize, t: &EnergyTracker) -> String {
        let d = D::D;
        let r = &self.slot_ranges[p];
        let mut best = (f64::NEG_INFINITY, None);
        for n in 0..self.n_nodes() {
            for &s in &self.gather_idx[self.gather_ptr[n] as usize..self.gather_ptr[n + 1] as usize]
            {
                let s = s as usize;
                if !r.contains(&s) {
                    continue;
                }
                let mut w = 0.0;
                for k in 0..d {
                    let vp = t.v_prev.get(n * d + k).copied().unwrap_or(0.0);
                    w += self.slot_forces[s * d + k] * 0.5 * (vp + self.state.v[n * d + k]);
                }
                if w > best.0 {
                    best = (w, Some((s - r.start, n)));
                }
            }
        }
        match best.1 {
            Some((slot, node)) => {
                let what = self.physics[p]
                    .slot_entity(slot)
                    .unwrap_or_else(|| format!("force slot {slot}"));
                format!("{what} (node {node})")
            }
            None => String::new(),
        }
    }

    /// Stored energy of each physics (J).
    fn stored_by_physics(&self) -> Vec<f64> {
        let kin = self.kinematics();
        self.physics
            .iter()
            .map(|p| p.stored_energy(&kin, &self.state.fields))
            .collect()
    }

    /// The energy balance at the last evaluation (every [`ENERGY_CHECK_EVERY`] steps and
    /// at [`Simulation::evaluate_energy`]); `None` when tracking is off.
    pub fn energy_balance(&self) -> Option<&EnergyBalance> {
        self.energy.as_ref().and_then(|t| t.last.as_ref())
    }

    /// Evaluates the energy balance now (stored energies included) and applies the
    /// watchdog; `Ok(None)` when tracking is off.
    pub fn evaluate_energy(&mut self) -> Result<Option<&EnergyBalance>, ComputeError> {
        let Some(mut t) = self.energy.take() else {
            return Ok(None);
        };
        let r = self.energy_check(&mut t);
        self.energy = Some(t);
        r?;
        Ok(self.energy_balance())
    }
}
