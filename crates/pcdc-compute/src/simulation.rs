//! The simulation: builder, explicit central-difference stepping, stable time step,
//! divergence watchdog and energies (save/restore: [`crate::snapshot`]).
//!
//! One mechanical step (`docs/design-targets.md` of the workspace): clear slots; every
//! physics computes its forces into its own slots; each node sums its slots in a fixed
//! order; central-difference update with lumped mass and gravity, `v += dt (F/m + g)`
//! (manual 7.1 eq. iv); prescribed kinematics; `u += dt v` (eq. v); watchdog.

use pcdc_mesh::{Dim, Mesh};
use serde::{Deserialize, Serialize};

use crate::energy::EnergyTracker;
use crate::gpu::GpuRun;
use crate::physics::{ForceContext, InitContext, Kinematics};
use crate::{Backend, ComputeError, FieldAccess, FieldStore, Physics, StableStep};

/// Default safety factor applied to the critical time step.
pub const DEFAULT_SAFETY: f64 = 0.5;

/// The evolving state: everything a snapshot must hold to continue a run bit for bit.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct State {
    /// Time (s).
    pub time: f64,
    /// Completed steps.
    pub step: u64,
    /// Node displacement (m), stride D.
    pub u: Vec<f64>,
    /// Node velocity (m/s), stride D, at the half step `t - dt/2`.
    pub v: Vec<f64>,
    /// Fields declared by the composed physics.
    pub fields: FieldStore,
}

/// Builds a [`Simulation`] from a mesh, a backend and the physics a scene composes.
pub struct SimulationBuilder<D: Dim> {
    mesh: Mesh<D>,
    backend: Backend,
    physics: Vec<Box<dyn Physics<D>>>,
    gravity: [f64; 3],
    safety: f64,
    fixed_dt: Option<f64>,
    runaway: Option<f64>,
    local_damping: f64,
    energy: Option<Option<f64>>,
}

impl<D: Dim> SimulationBuilder<D> {
    /// Starts a builder on `mesh` run by `backend`.
    pub fn new(mesh: Mesh<D>, backend: impl Into<Backend>) -> Self {
        SimulationBuilder {
            mesh,
            backend: backend.into(),
            physics: Vec::new(),
            gravity: [0.0; 3],
            safety: DEFAULT_SAFETY,
            fixed_dt: None,
            runaway: None,
            local_damping: 0.0,
            energy: None,
        }
    }

    /// Tracks the energy balance ([`crate::EnergyBalance`], read with
    /// [`Simulation::energy_balance`]): the work of every force source accumulated each
    /// step (one extra pass over the nodes and force slots), stored energies evaluated
    /// every [`crate::ENERGY_CHECK_EVERY`] steps. Off by default.
    pub fn track_energy(mut self) -> Self {
        if self.energy.is_none() {
            self.energy = Some(None);
        }
        self
    }

    /// Tracks the energy balance and stops the run with
    /// [`ComputeError::EnergyGrowth`] (naming the step, the physics and the entity that
    /// injects energy) when the total energy exceeds the initial energy plus the
    /// external work by more than `tolerance` (relative, e.g. 0.01) of the reference
    /// energy max(E_0 + W_ext, largest total so far). Checked every
    /// [`crate::ENERGY_CHECK_EVERY`] steps.
    pub fn energy_watchdog(mut self, tolerance: f64) -> Self {
        self.energy = Some(Some(tolerance));
        self
    }

    /// Adds a physics. Physics run in the order they are added (this fixes the
    /// summation order of forces).
    pub fn physics(mut self, p: impl Physics<D> + 'static) -> Self {
        self.physics.push(Box::new(p));
        self
    }

    /// Adds every physics of a group ([`crate::PhysicsGroup`]), in the group's order.
    pub fn group(mut self, g: impl crate::PhysicsGroup<D>) -> Self {
        self.physics.extend(g.into_physics());
        self
    }

    /// Adds a boxed physics.
    pub fn boxed_physics(mut self, p: Box<dyn Physics<D>>) -> Self {
        self.physics.push(p);
        self
    }

    /// Gravity acceleration (m/s²); only the first `D` components are used.
    pub fn gravity(mut self, g: [f64; 3]) -> Self {
        self.gravity = g;
        self
    }

    /// Safety factor on the critical time step (0 < f <= 1, default 0.5).
    pub fn safety_factor(mut self, f: f64) -> Self {
        self.safety = f;
        self
    }

    /// Uses a fixed time step (s) instead of the automatic stable one. A step above the
    /// stable one is accepted but reported by [`Simulation::time_step_limit`].
    pub fn time_step(mut self, dt: f64) -> Self {
        self.fixed_dt = Some(dt);
        self
    }

    /// Local non-viscous damping coefficient α (0 ≤ α < 1, default 0): each node force
    /// component is reduced by `α |F| sign(v)` (Cundall's damping, as in PFC and
    /// MatDEM), a quick way to reach a quasi-static state in a dynamic run.
    pub fn local_damping(mut self, alpha: f64) -> Self {
        self.local_damping = alpha;
        self
    }

    /// Largest displacement (m) before the watchdog stops the run (default: 100 times
    /// the model's bounding-box diagonal).
    pub fn runaway_displacement(mut self, limit: f64) -> Self {
        self.runaway = Some(limit);
        self
    }

    /// Declares fields, initialises every physics, lumps masses and picks the time step.
    pub fn build(self) -> Result<Simulation<D>, ComputeError> {
        let SimulationBuilder {
            mesh,
            backend,
            mut physics,
            gravity,
            safety,
            fixed_dt,
            runaway,
            local_damping,
            energy,
        } = self;
        if let Some(Some(tol)) = energy {
            if !(tol > 0.0 && tol.is_finite()) {
                return Err(ComputeError::param(
                    "energy_watchdog tolerance",
                    tol,
                    "must be positive and finite (relative, e.g. 0.01)",
                ));
            }
        }
        if !(0.0..1.0).contains(&local_damping) {
            return Err(ComputeError::param(
                "local_damping",
                local_damping,
                "must lie in [0, 1)",
            ));
        }
        if !(safety > 0.0 && safety <= 1.0) {
            return Err(ComputeError::param(
                "safety_factor",
                safety,
                "must lie in (0, 1]",
            ));
        }
        if gravity.iter().any(|g| !g.is_finite()) {
            return Err(ComputeError::param(
                "gravity",
                format!("{gravity:?}"),
                "must be finite",
            ));
        }
        if let Some(dt) = fixed_dt {
            if !(dt > 0.0 && dt.is_finite()) {
                return Err(ComputeError::param(
                    "time_step",
                    dt,
                    "must be positive and finite",
                ));
            }
        }
        let (lo, hi) = mesh.bounding_box();
        let diag = lo
            .iter()
            .zip(&hi)
            .map(|(a, b)| (b - a).powi(2))
            .sum::<f64>()
            .sqrt();
        let runaway = runaway.unwrap_or(100.0 * diag);
        if runaway.is_nan() || runaway <= 0.0 {
            return Err(ComputeError::param(
                "runaway_displacement",
                runaway,
                "must be positive",
            ));
        }
        let layout = prepare_layout(&mesh, &mut physics)?;
        let n_nodes = layout.coords.len() / D::D;
        let fields = layout.fields.clone();
        let mut mass = vec![0.0; n_nodes];
        mass[mesh.n_nodes()..].copy_from_slice(&layout.added_mass);
        for p in &physics {
            p.add_mass(&mesh, &fields, &mut mass, None);
        }
        if let Some(n) = mass.iter().position(|&m| !(m > 0.0 && m.is_finite())) {
            return Err(ComputeError::param(
                format!("mass of node {n}"),
                mass[n],
                "every node needs a positive mass: compose a physics that gives the elements a density",
            ));
        }
        let d = D::D;
        let mut sim = Simulation {
            state: State {
                time: 0.0,
                step: 0,
                u: vec![0.0; n_nodes * d],
                v: vec![0.0; n_nodes * d],
                fields,
            },
            mass_phys: mass.clone(),
            mass,
            force: vec![0.0; n_nodes * d],
            slot_forces: vec![0.0; layout.n_slots * d],
            slot_ranges: layout.slot_ranges.clone(),
            gather_ptr: layout.gather_ptr.clone(),
            gather_idx: layout.gather_idx.clone(),
            gpu: None,
            device_fresh: false,
            coords: layout.coords.clone(),
            sets: layout.sets.clone(),
            mesh,
            backend,
            physics,
            gravity,
            safety,
            fixed_dt,
            runaway,
            dt: 0.0,
            limit: None,
            damping: true,
            local_damping,
            energy: None,
            field_stages: Vec::new(),
            kinematic_nodes: None,
            beside: None,
        };
        sim.beside = Some(Box::new(crate::beside::Beside::plan(
            &sim.mesh,
            &sim.physics,
            &sim.state.fields,
            sim.backend.threads(),
        )?));
        sim.kinematic_nodes = crate::node_pass::kinematic_nodes(&sim.physics, n_nodes)?;
        if let Some(tol) = energy {
            let loads: Vec<bool> = sim.physics.iter().map(|p| p.applies_loads()).collect();
            sim.energy = Some(Box::new(EnergyTracker::new(
                tol,
                &layout.slot_ranges,
                loads,
            )));
        }
        sim.update_time_step()?;
        sim.schedule_field_stages()?;
        #[cfg(feature = "gpu")]
        if let Some(gpu) = sim.backend.as_gpu().cloned() {
            sim.gpu = Some(Box::new(GpuRun::new(&gpu, &mut sim, &layout)?));
        }
        Ok(sim)
    }
}

/// Fields, slots and the node -> slot gather lists of a composition.
pub(crate) struct Layout {
    /// The entity sets: the mesh's interfaces, then the physics' own.
    pub sets: Vec<crate::EntitySet>,
    /// Reference coordinates of every node: the mesh's, then the added ones.
    pub coords: Vec<f64>,
    /// Masses of the nodes physics added (kg).
    pub added_mass: Vec<f64>,
    pub fields: FieldStore,
    pub slot_ranges: Vec<std::ops::Range<usize>>,
    pub n_slots: usize,
    pub gather_ptr: Vec<u32>,
    pub gather_idx: Vec<u32>,
}

/// The mesh's interfaces as the set [`crate::names::JOINTS`], then every physics' own
/// sets (names unique; node indices within the mesh, or from `mesh.n_nodes()` on for the
/// nodes the physics itself adds), with the index of the physics that declared each set
/// (`None` for the joints).
fn entity_sets<D: Dim>(
    mesh: &Mesh<D>,
    physics: &[Box<dyn Physics<D>>],
) -> Result<(Vec<crate::EntitySet>, Vec<Option<usize>>), ComputeError> {
    let joints = mesh.interfaces();
    let mut sets = vec![crate::EntitySet::new(
        crate::names::JOINTS,
        joints.nodes_per_joint().max(1),
        joints.nodes().to_vec(),
    )?];
    let mut owners = vec![None];
    for (i, p) in physics.iter().enumerate() {
        for s in p.entity_sets(mesh) {
            if sets.iter().any(|t| t.name() == s.name()) {
                return Err(ComputeError::param(
                    format!("entity set of physics '{}'", p.name()),
                    s.name(),
                    "another set has that name",
                ));
            }
            sets.push(s);
            owners.push(Some(i));
        }
    }
    Ok((sets, owners))
}

/// Shifts the nodes physics `p` adds in its sets (numbered from the mesh's node count)
/// to their simulation indices, `first_added` on.
fn shift_added_nodes(
    sets: &mut [crate::EntitySet],
    owners: &[Option<usize>],
    p: usize,
    n_mesh: usize,
    first_added: usize,
) {
    for (s, o) in sets.iter_mut().zip(owners) {
        if *o == Some(p) && first_added > n_mesh {
            s.shift_nodes_from(n_mesh as u32, (first_added - n_mesh) as u32);
        }
    }
}

/// Checks that every node of physics `p`'s sets exists once it has added its nodes.
fn check_set_nodes(
    sets: &[crate::EntitySet],
    owners: &[Option<usize>],
    p: usize,
    name: &str,
    n_nodes: usize,
) -> Result<(), ComputeError> {
    for (s, o) in sets.iter().zip(owners) {
        if *o != Some(p) {
            continue;
        }
        if let Some(&n) = s.nodes().iter().find(|&&n| n as usize >= n_nodes) {
            return Err(ComputeError::param(
                format!("entity set '{}' of physics '{name}'", s.name()),
                n,
                format!("the simulation has {n_nodes} nodes (mesh nodes and those physics added)"),
            ));
        }
    }
    Ok(())
}

/// Checks the composition's field uses (one owner per field, no use without an owner,
/// readers after writers, unique physics once) and declares the owned fields in the
/// order of their owners.
fn declare_fields<D: Dim>(
    mesh: &Mesh<D>,
    physics: &[Box<dyn Physics<D>>],
    sets: &[crate::EntitySet],
) -> Result<FieldStore, ComputeError> {
    for (i, p) in physics.iter().enumerate() {
        if p.unique() && physics[..i].iter().any(|q| q.name() == p.name()) {
            return Err(ComputeError::DuplicatePhysics(p.name().to_string()));
        }
    }
    let uses: Vec<Vec<crate::FieldUse>> = physics.iter().map(|p| p.fields(mesh)).collect();
    let mut fields = FieldStore::default();
    let mut owner: std::collections::HashMap<&str, usize> = std::collections::HashMap::new();
    for (i, list) in uses.iter().enumerate() {
        for u in list.iter().filter(|u| u.access == FieldAccess::Own) {
            if let Some(&j) = owner.get(u.name.as_str()) {
                return Err(ComputeError::FieldOwnedTwice {
                    field: u.name.clone(),
                    first: physics[j].name().to_string(),
                    second: physics[i].name().to_string(),
                });
            }
            owner.insert(&u.name, i);
            let (spec, count) = u.spec(mesh, sets)?;
            fields.declare(spec, count)?;
        }
    }
    for (i, list) in uses.iter().enumerate() {
        for u in list.iter().filter(|u| u.access != FieldAccess::Own) {
            let Some(&o) = owner.get(u.name.as_str()) else {
                return Err(ComputeError::FieldWithoutOwner {
                    field: u.name.clone(),
                    physics: physics[i].name().to_string(),
                    verb: u.access.verb(),
                });
            };
            let spec = fields.spec(fields.id(&u.name)?);
            let place_ok = u.place.is_none_or(|p| {
                matches!(
                    (p, spec.location),
                    (crate::Place::Node, crate::Location::Node)
                        | (crate::Place::Element, crate::Location::Element)
                        | (crate::Place::Face, crate::Location::Face)
                        | (crate::Place::Set(_), crate::Location::Entities(_))
                )
            });
            if !place_ok || u.components.is_some_and(|c| c != spec.components) {
                return Err(ComputeError::FieldConflict {
                    name: u.name.clone(),
                    a: format!(
                        "{:?}x{} (owned by '{}')",
                        spec.location,
                        spec.components,
                        physics[o].name()
                    ),
                    b: format!(
                        "{:?}x{:?} ({} by '{}')",
                        u.place,
                        u.components,
                        u.access.verb(),
                        physics[i].name()
                    ),
                });
            }
            if u.access == FieldAccess::Read {
                // Every writer (the owner included) must come before the reader.
                let writers = uses.iter().enumerate().filter(|(j, l)| {
                    l.iter().any(|w| {
                        w.name == u.name
                            && matches!(w.access, FieldAccess::Own | FieldAccess::Write)
                    }) && *j > i
                });
                if let Some((j, _)) = writers.into_iter().next() {
                    return Err(ComputeError::FieldReadBeforeWrite {
                        field: u.name.clone(),
                        reader: physics[i].name().to_string(),
                        writer: physics[j].name().to_string(),
                    });
                }
            }
        }
    }
    Ok(fields)
}

/// Declares the fields of every physics, initialises them in order (registering their
/// slots) and builds the CSR node -> slots lists (slots in registration order).
pub(crate) fn prepare_layout<D: Dim>(
    mesh: &Mesh<D>,
    physics: &mut [Box<dyn Physics<D>>],
) -> Result<Layout, ComputeError> {
    let (mut sets, owners) = entity_sets(mesh, physics)?;
    let mut fields = declare_fields(mesh, physics, &sets)?;
    let mut slot_ranges = Vec::with_capacity(physics.len());
    let mut slot_nodes = Vec::new();
    let mut coords = mesh.coords().to_vec();
    let mut added_mass = Vec::new();
    for (i, p) in physics.iter_mut().enumerate() {
        shift_added_nodes(&mut sets, &owners, i, mesh.n_nodes(), coords.len() / D::D);
        let mut ctx = InitContext {
            mesh,
            fields: &mut fields,
            slot_nodes: Vec::new(),
            sets: &sets,
            n_nodes: coords.len() / D::D,
            added_coords: Vec::new(),
            added_mass: Vec::new(),
        };
        p.init(&mut ctx)?;
        let first = slot_nodes.len();
        slot_nodes.extend_from_slice(&ctx.slot_nodes);
        slot_ranges.push(first..slot_nodes.len());
        coords.extend_from_slice(&ctx.added_coords);
        added_mass.extend_from_slice(&ctx.added_mass);
        check_set_nodes(&sets, &owners, i, p.name(), coords.len() / D::D)?;
    }
    let n_nodes = coords.len() / D::D;
    let mut gather_ptr = vec![0u32; n_nodes + 1];
    for &n in &slot_nodes {
        gather_ptr[n as usize + 1] += 1;
    }
    for i in 0..n_nodes {
        gather_ptr[i + 1] += gather_ptr[i];
    }
    let mut fill = gather_ptr.clone();
    let mut gather_idx = vec![0u32; slot_nodes.len()];
    for (s, &n) in slot_nodes.iter().enumerate() {
        gather_idx[fill[n as usize] as usize] = s as u32;
        fill[n as usize] += 1;
    }
    Ok(Layout {
        sets,
        coords,
        added_mass,
        fields,
        slot_ranges,
        n_slots: slot_nodes.len(),
        gather_ptr,
        gather_idx,
    })
}

/// A running simulation.
pub struct Simulation<D: Dim> {
    /// The evolving state.
    pub state: State,
    pub(crate) mesh: Mesh<D>,
    /// Reference coordinates of every node (mesh nodes, then added ones), stride D.
    pub(crate) coords: Vec<f64>,
    /// Entity sets (the mesh's interfaces first).
    pub(crate) sets: Vec<crate::EntitySet>,
    pub(crate) backend: Backend,
    pub(crate) physics: Vec<Box<dyn Physics<D>>>,
    pub(crate) mass: Vec<f64>,
    pub(crate) mass_phys: Vec<f64>,
    pub(crate) force: Vec<f64>,
    pub(crate) slot_forces: Vec<f64>,
    pub(crate) slot_ranges: Vec<std::ops::Range<usize>>,
    pub(crate) gather_ptr: Vec<u32>,
    pub(crate) gather_idx: Vec<u32>,
    pub(crate) gravity: [f64; 3],
    pub(crate) safety: f64,
    pub(crate) fixed_dt: Option<f64>,
    pub(crate) runaway: f64,
    pub(crate) dt: f64,
    pub(crate) limit: Option<StableStep>,
    pub(crate) damping: bool,
    pub(crate) local_damping: f64,
    /// Device state on the GPU backend.
    pub(crate) gpu: Option<Box<GpuRun>>,
    /// True only between an internal read-back and the next internal device call that
    /// may skip its upload (relaxation loop); public entry points always upload.
    pub(crate) device_fresh: bool,
    /// Energy balance accumulators, when tracking is on.
    pub(crate) energy: Option<Box<EnergyTracker>>,
    /// Schedule of each physics' field stage (`None`: it has none), fixed at build.
    pub(crate) field_stages: Vec<Option<crate::FieldStage>>,
    /// The nodes whose velocity a kinematic condition writes (sorted, unique) when every
    /// physics names them: then the CPU step fuses the node passes (`node_pass.rs`).
    pub(crate) kinematic_nodes: Option<Vec<u32>>,
    /// Which physics run beside which in the CPU forces stage (`beside.rs`).
    pub(crate) beside: Option<Box<crate::beside::Beside>>,
}

impl<D: Dim> Simulation<D> {
    /// Starts a builder on `backend` (a [`Backend`], or a [`crate::CpuBackend`] or GPU backend).
    pub fn builder(mesh: Mesh<D>, backend: impl Into<Backend>) -> SimulationBuilder<D> {
        SimulationBuilder::new(mesh, backend)
    }

    /// Advances one explicit step. On the GPU backend this is `run(1)` (one read-back);
    /// prefer [`Simulation::run`] with many steps there. On the CPU each call hands the
    /// step to the backend's thread pool and back; in a loop that needs no per-step
    /// access, [`Simulation::run`] is faster (one hand-over, and the pool's threads stay
    /// on their cores: 10–15 % on an unpinned 2-core machine, docs/performance.md).
    pub fn step(&mut self) -> Result<(), ComputeError> {
        if self.gpu.is_some() {
            return self.run(1);
        }
        // The whole step on the pool: every pass's `install` then runs in place instead
        // of handing over to the pool and back (about 20 µs each, a sixth of a 10k step).
        let backend = self.backend.clone();
        backend.install(|| self.cpu_step())
    }

    /// One CPU step (called on the backend's pool).
    fn cpu_step(&mut self) -> Result<(), ComputeError> {
        self.physics_forces()?;
        self.energy_before_update();
        if self.kinematic_nodes.is_some() {
            self.fused_node_pass()?;
        } else {
            self.gather(true);
            self.finish_step()?;
        }
        self.after_update()?;
        self.energy_after_step()
    }

    /// Advances `n` steps. On the GPU backend the host state (`state`, masses) is
    /// uploaded at the start, the `n` steps run on the device without any read, and the
    /// state is read back once at the end; the watchdog's verdict arrives then, naming the
    /// first bad step and node.
    pub fn run(&mut self, n: u64) -> Result<(), ComputeError> {
        if let Some(mut gpu) = self.gpu.take() {
            let r = gpu.run(self, n);
            self.gpu = Some(gpu);
            return r;
        }
        let backend = self.backend.clone();
        backend.install(|| {
            for _ in 0..n {
                self.cpu_step()?;
            }
            Ok(())
        })
    }

    /// Advances until `time` (s) is reached (the last step may overshoot by < dt).
    pub fn run_until(&mut self, time: f64) -> Result<(), ComputeError> {
        if self.gpu.is_some() {
            let (mut t, mut n) = (self.state.time, 0u64);
            while t < time {
                t += self.dt;
                n += 1;
            }
            return self.run(n);
        }
        let backend = self.backend.clone();
        backend.install(|| {
            while self.state.time < time {
                self.cpu_step()?;
            }
            Ok(())
        })
    }

    /// Device-memory bytes one step streams on the GPU backend (every bound buffer read
    /// once, read-write ones written once more; `None` on the CPU backend). Divide by the
    /// element count and multiply by the achieved element-steps/s to compare with the
    /// device's memory bandwidth.
    pub fn gpu_bytes_per_step(&self) -> Option<u64> {
        self.gpu.as_ref().map(|g| g.bytes_per_step())
    }

    /// The pairs of physics whose forces the CPU step computes side by side (the second
    /// [`Physics::runs_beside`] the first), by name; empty on one thread.
    pub fn physics_beside(&self) -> Vec<(&str, &str)> {
        let Some(b) = self.beside.as_deref() else {
            return Vec::new();
        };
        b.partner
            .iter()
            .enumerate()
            .filter_map(|(h, l)| l.map(|l| (self.physics[h].name(), self.physics[l].name())))
            .collect()
    }

    /// Whether the CPU step runs its node work in one fused pass: every composed physics
    /// names the nodes its kinematic conditions write ([`Physics::kinematic_nodes`]).
    pub fn fuses_node_passes(&self) -> bool {
        self.kinematic_nodes.is_some()
    }

    /// Labels of the GPU kernels in dispatch order (empty on the CPU backend).
    pub fn gpu_kernels(&self) -> Vec<String> {
        self.gpu
            .as_ref()
            .map(|g| g.kernel_labels())
            .unwrap_or_default()
    }

    /// Evaluates every physics' forces at the current state without advancing, and
    /// returns the net node force (N, stride D): applied loads minus internal forces.
    /// At constrained nodes this includes the reaction.
    pub fn evaluate_forces(&mut self) -> Result<&[f64], ComputeError> {
        self.compute_forces(false)?;
        Ok(&self.force)
    }

    /// Evaluates all forces at the current state and gathers them into the node force
    /// (`gross = true` also returns the sum of absolute slot contributions per dof).
    pub(crate) fn compute_forces(&mut self, gross: bool) -> Result<Option<Vec<f64>>, ComputeError> {
        if let Some(mut gpu) = self.gpu.take() {
            let r = gpu.evaluate(self, gross);
            self.gpu = Some(gpu);
            return r;
        }
        let d = D::D;
        self.physics_forces()?;
        self.gather(false);
        let (ptr, idx, slots) = (&self.gather_ptr, &self.gather_idx, &self.slot_forces);
        let force = &self.force;
        if !gross {
            return Ok(None);
        }
        let mut g = vec![0.0; force.len()];
        for n in 0..self.n_nodes() {
            for &s in &idx[ptr[n] as usize..ptr[n + 1] as usize] {
                for k in 0..d {
                    g[n * d + k] += slots[s as usize * d + k].abs();
                }
            }
        }
        Ok(Some(g))
    }

    /// Lets every physics write its forces, clearing its slots first unless it writes
    /// every one of them ([`Physics::writes_all_slots`]); a physics that runs beside an
    /// earlier one ([`Physics::runs_beside`]) runs with it in a `rayon::join`.
    fn physics_forces(&mut self) -> Result<(), ComputeError> {
        let d = D::D;
        let (u, v) = (&self.state.u, &self.state.v);
        let (time, step) = (self.state.time, self.state.step);
        let kin = || Kinematics {
            mesh: &self.mesh,
            coords: &self.coords,
            mass: &self.mass_phys,
            u,
            v,
            time,
            dt: self.dt,
            step,
            damping: self.damping,
        };
        let fields = &mut self.state.fields;
        let backend = &self.backend;
        let mut beside = self.beside.as_deref_mut();
        for i in 0..self.physics.len() {
            if beside.as_ref().is_some_and(|b| b.skip[i]) {
                continue;
            }
            let r = self.slot_ranges[i].clone();
            let Some(l) = beside.as_ref().and_then(|b| b.partner[i]) else {
                let p = &mut self.physics[i];
                let slots = &mut self.slot_forces[r.start * d..r.end * d];
                if !p.writes_all_slots() {
                    slots.fill(0.0);
                }
                p.compute_forces(&mut ForceContext {
                    kin: kin(),
                    fields,
                    slots,
                    backend,
                })?;
                continue;
            };
            // The partner comes later (l > i): its physics and slots lie past the split.
            let rl = self.slot_ranges[l].clone();
            let (before, after) = self.physics.split_at_mut(l);
            let (p, q) = (&mut before[i], &mut after[0]);
            let (lo, hi) = self.slot_forces.split_at_mut(rl.start * d);
            let slots = &mut lo[r.start * d..r.end * d];
            let q_slots = &mut hi[..(rl.end - rl.start) * d];
            for (x, s) in [(&*p, &mut *slots), (&*q, &mut *q_slots)] {
                if !x.writes_all_slots() {
                    s.fill(0.0);
                }
            }
            let side = beside.as_deref_mut().expect("a partner comes from a plan");
            side.swap(fields, l);
            let side_fields = &mut side.side;
            let (a, b) = backend.install(|| {
                rayon::join(
                    || {
                        p.compute_forces(&mut ForceContext {
                            kin: kin(),
                            fields,
                            slots,
                            backend,
                        })
                    },
                    || {
                        q.compute_forces(&mut ForceContext {
                            kin: kin(),
                            fields: side_fields,
                            slots: q_slots,
                            backend,
                        })
                    },
                )
            });
            side.swap(fields, l);
            a?;
            b?;
        }
        Ok(())
    }

    /// The divergence error for node `n` at `step` (time `time`).
    pub(crate) fn divergence(
        &self,
        step: u64,
        time: f64,
        n: usize,
        nonfinite: bool,
    ) -> ComputeError {
        let hint = match &self.limit {
            Some(l) => format!(
                "time step {:e} s (limit set by {} of {}); check that the time step is not above the stable one, that penalties are not extreme, and that loads and boundary conditions are sensible",
                self.dt, l.entity, l.physics
            ),
            None => "check the time step and the boundary conditions".to_string(),
        };
        let what = if nonfinite {
            "non-finite (NaN or infinite) velocity or displacement".to_string()
        } else {
            format!("runaway displacement above {:e} m", self.runaway)
        };
        ComputeError::Diverged {
            step,
            time,
            what,
            entity: format!("node {n}"),
            hint,
        }
    }
}

impl<D: Dim> Simulation<D> {
    /// Read-only view of the current kinematic state (on the GPU backend: as read back at
    /// the end of the last run).
    pub fn kinematics(&self) -> Kinematics<'_, D> {
        Kinematics {
            mesh: &self.mesh,
            coords: &self.coords,
            mass: &self.mass_phys,
            u: &self.state.u,
            v: &self.state.v,
            time: self.state.time,
            dt: self.dt,
            step: self.state.step,
            damping: self.damping,
        }
    }

    /// The mesh.
    pub fn mesh(&self) -> &Mesh<D> {
        &self.mesh
    }

    /// The backend.
    pub fn backend(&self) -> &Backend {
        &self.backend
    }

    /// Current time step (s).
    pub fn dt(&self) -> f64 {
        self.dt
    }

    /// The entity that limits the stable time step, if any physics reported one.
    pub fn time_step_limit(&self) -> Option<&StableStep> {
        self.limit.as_ref()
    }

    /// Sets the local non-viscous damping coefficient α (see
    /// [`SimulationBuilder::local_damping`]).
    pub fn set_local_damping(&mut self, alpha: f64) -> Result<(), ComputeError> {
        if !(0.0..1.0).contains(&alpha) {
            return Err(ComputeError::param(
                "local_damping",
                alpha,
                "must lie in [0, 1)",
            ));
        }
        self.local_damping = alpha;
        Ok(())
    }

    /// Turns element viscous damping (manual eq. 17-19) on or off for subsequent steps.
    pub fn set_damping(&mut self, on: bool) {
        self.damping = on;
    }

    /// Recomputes the stable time step from the current state (e.g. after large
    /// deformation) unless a fixed step was set.
    pub fn update_time_step(&mut self) -> Result<(), ComputeError> {
        let kin = self.kinematics();
        let mut best: Option<StableStep> = None;
        for p in &self.physics {
            if let Some(s) = p.stable_step(&kin, &self.state.fields) {
                if best.as_ref().is_none_or(|b| s.dt < b.dt) {
                    best = Some(s);
                }
            }
        }
        self.limit = best;
        self.dt = match (self.fixed_dt, &self.limit) {
            (Some(dt), _) => dt,
            (None, Some(l)) => l.dt * self.safety,
            (None, None) => return Err(ComputeError::NoTimeStep),
        };
        Ok(())
    }

    /// Recomputes the lumped node masses from the physics, after a stage that changed
    /// them (elements switched to the null model, manual 7.2.8), and the stable step.
    /// A mesh node left without mass (every element around it null) drops out: its
    /// physical mass and velocity become zero, so that neither gravity nor motion acts
    /// on it, and it integrates with a unit mass, which only a force could move (no
    /// element gives it one). Nodes that physics added (bolt nodes) keep their masses.
    /// Returns the number of mesh nodes that dropped out.
    pub fn refresh_mass(&mut self) -> Result<usize, ComputeError> {
        let nm = self.mesh.n_nodes();
        let mut mass = vec![0.0; self.mass_phys.len()];
        mass[nm..].copy_from_slice(&self.mass_phys[nm..]);
        for p in &self.physics {
            p.add_mass(&self.mesh, &self.state.fields, &mut mass, None);
        }
        let d = D::D;
        let mut out = 0;
        for (n, m) in mass.iter().enumerate().take(nm) {
            if *m == 0.0 {
                out += 1;
                self.state.v[n * d..(n + 1) * d].fill(0.0);
            }
        }
        self.mass_phys = mass;
        self.mass = self.integration_mass(&self.mass_phys);
        self.device_fresh = false;
        self.update_time_step()?;
        Ok(out)
    }

    /// The masses the integration divides by: `m`, with a unit mass where it is zero
    /// (nodes that dropped out, [`Self::refresh_mass`]).
    pub(crate) fn integration_mass(&self, m: &[f64]) -> Vec<f64> {
        m.iter().map(|&x| if x == 0.0 { 1.0 } else { x }).collect()
    }

    /// Lumped nodal mass (kg), one value per node.
    pub fn mass(&self) -> &[f64] {
        &self.mass
    }

    /// Node force gathered at the last step (N), stride D.
    pub fn node_force(&self) -> &[f64] {
        &self.force
    }

    /// Kinetic energy ½ Σ m v² (J) with the half-step velocities.
    pub fn kinetic_energy(&self) -> f64 {
        let d = D::D;
        0.5 * self
            .state
            .v
            .chunks_exact(d)
            .zip(&self.mass_phys)
            .map(|(v, m)| m * v.iter().map(|x| x * x).sum::<f64>())
            .sum::<f64>()
    }

    /// Energy stored by all physics (J), e.g. elastic strain energy.
    pub fn stored_energy(&self) -> f64 {
        let kin = self.kinematics();
        self.physics
            .iter()
            .map(|p| p.stored_energy(&kin, &self.state.fields))
            .sum()
    }

    /// The entity set named `name` (e.g. [`crate::names::JOINTS`]: the mesh's
    /// interfaces), with its node connectivity.
    pub fn entity_set(&self, name: &str) -> Option<&crate::EntitySet> {
        self.sets.iter().find(|s| s.name() == name)
    }

    /// Number of nodes integrated: the mesh nodes, then the nodes physics added
    /// ([`crate::InitContext::add_nodes`]).
    pub fn n_nodes(&self) -> usize {
        self.coords.len() / D::D
    }

    /// Reference coordinates of every node (m), stride D (mesh nodes, then added ones).
    pub fn reference_coords(&self) -> &[f64] {
        &self.coords
    }

    /// Current position of every node (m), stride D.
    pub fn positions(&self) -> Vec<f64> {
        self.coords
            .iter()
            .zip(&self.state.u)
            .map(|(x, u)| x + u)
            .collect()
    }

    /// Values of a field by name.
    pub fn field(&self, name: impl AsRef<str>) -> Result<&[f64], ComputeError> {
        let id = self.state.fields.id(name)?;
        Ok(self.state.fields.get(id))
    }

    /// Names of the composed physics, in order.
    pub fn physics_names(&self) -> Vec<String> {
        self.physics.iter().map(|p| p.name().to_string()).collect()
    }

    /// Bytes held by the state, masses and force slots (memory footprint of the run).
    pub fn state_bytes(&self) -> usize {
        8 * (self.state.u.len()
            + self.state.v.len()
            + self.mass.len() * 2
            + self.force.len()
            + self.slot_forces.len())
            + 4 * (self.gather_idx.len() + self.gather_ptr.len())
            + self.state.fields.bytes()
    }
}
