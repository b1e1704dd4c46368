//! The `Physics` trait: one implementation per physics crate and backend.
//!
//! A physics declares the fields it needs, registers the node slots it writes forces
//! into, contributes lumped mass and a stable time step, computes its forces each step,
//! and may impose kinematic conditions on the integrated velocities. Everything that
//! evolves in time lives in fields (so save/restore and device residency work); a
//! physics struct holds only parameters and data derived once from the mesh.

use pcdc_mesh::{Dim, Mesh};

use crate::{Backend, ComputeError, FieldStore, FieldUse};

/// Handle to a block of force slots registered by a physics.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SlotBlock {
    /// Index of the first slot in the physics' own slot buffer.
    pub first: usize,
    /// Number of slots.
    pub len: usize,
}

/// Kinds of entities a physics reports (in stable steps and errors).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum EntityKind {
    /// A mesh node.
    Node,
    /// A mesh element.
    Element,
    /// A mesh face.
    Face,
    /// A face-joint (cohesive interface).
    Joint,
    /// An entity of a physics-defined set, named by its kind (e.g. "contact element",
    /// "bolt segment", "flow channel").
    Other(&'static str),
}

/// A typed entity: kind and index, e.g. element 42. Displays as `element 42`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Entity {
    /// What the index counts.
    pub kind: EntityKind,
    /// Index within its kind.
    pub index: usize,
}

impl Entity {
    /// An entity.
    pub fn new(kind: EntityKind, index: usize) -> Self {
        Entity { kind, index }
    }
}

impl std::fmt::Display for Entity {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let kind = match self.kind {
            EntityKind::Node => "node",
            EntityKind::Element => "element",
            EntityKind::Face => "face",
            EntityKind::Joint => "joint",
            EntityKind::Other(k) => k,
        };
        write!(f, "{kind} {}", self.index)
    }
}

/// What limits a stable time step: the mechanical step ([`Physics::stable_step`]) or a
/// physics' own sub-cycled field step ([`Physics::field_stable_step`]).
#[derive(Clone, Debug, PartialEq)]
pub struct StableStep {
    /// Critical time step of the limiting entity (s), before the safety factor.
    pub dt: f64,
    /// The limiting entity.
    pub entity: Entity,
    /// Which physics reported it.
    pub physics: String,
}

/// How a physics' field stage runs relative to the mechanical step.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SubCycle {
    /// `n` field steps of `dt / n` after every mechanical step (a field whose stable
    /// step is smaller than the mechanical one).
    Substeps(u32),
    /// One field step of `n dt` after every `n`-th mechanical step (a field whose stable
    /// step is larger, e.g. slow diffusion).
    Every(u32),
}

impl SubCycle {
    /// Field steps per mechanical step (`Substeps(n)`: n) or 1.
    pub fn substeps(self) -> u32 {
        match self {
            SubCycle::Substeps(n) => n,
            SubCycle::Every(_) => 1,
        }
    }

    /// The field step over the mechanical step: `1/n` or `n`. The field step is
    /// `dt * scale()` on both backends (GPU kernels: `p_dt() * FIELD_DT_SCALE`).
    pub fn scale(self) -> f64 {
        match self {
            SubCycle::Substeps(n) => 1.0 / n as f64,
            SubCycle::Every(n) => n as f64,
        }
    }

    /// Whether the field stage runs after mechanical step number `step` (1-based).
    pub fn runs_after(self, step: u64) -> bool {
        match self {
            SubCycle::Substeps(_) => true,
            SubCycle::Every(n) => step % n.max(1) as u64 == 0,
        }
    }
}

/// How a physics asks its field stage to be scheduled.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FieldSchedule {
    /// From [`Physics::field_stable_step`] (times the safety factor) and the mechanical
    /// step: sub-steps when the field is the faster, one step every n mechanical steps
    /// when it is the slower.
    Auto,
    /// A fixed ratio.
    Fixed(SubCycle),
}

/// Context of the post-update and field stages (after the position update).
pub struct FieldContext<'a, D: Dim> {
    /// Kinematic state at the end of the mechanical step (`u` updated, `v` at the half
    /// step); `kin.dt` is the mechanical step.
    pub kin: Kinematics<'a, D>,
    /// Field storage.
    pub fields: &'a mut FieldStore,
    /// The step of this stage (s): the mechanical step in the post-update stage, the
    /// field step (`dt * SubCycle::scale`) in a field stage.
    pub dt: f64,
    /// Time at the start of this field step (s).
    pub time: f64,
    /// Index of this sub-step within the mechanical step (0 without sub-steps).
    pub substep: u32,
    /// The backend.
    pub backend: &'a Backend,
}

/// Handle to a block of nodes a physics added ([`InitContext::add_nodes`]): nodes
/// `first..first + len` of the simulation, after the mesh nodes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct NodeBlock {
    /// Index of the first added node in the simulation's node arrays.
    pub first: usize,
    /// Number of nodes.
    pub len: usize,
}

/// Read-only view of the kinematic state during a step.
pub struct Kinematics<'a, D: Dim> {
    /// The mesh (reference configuration).
    pub mesh: &'a Mesh<D>,
    /// Reference coordinates of every node (m), stride D: the mesh nodes, then the nodes
    /// physics added ([`InitContext::add_nodes`]).
    pub coords: &'a [f64],
    /// Physical lumped node mass (kg).
    pub mass: &'a [f64],
    /// Node displacement (m), stride D.
    pub u: &'a [f64],
    /// Node velocity (m/s), stride D (at the half step before the update in progress).
    pub v: &'a [f64],
    /// Current time (s).
    pub time: f64,
    /// Time step (s).
    pub dt: f64,
    /// Step counter.
    pub step: u64,
    /// Whether element viscous damping (manual eq. 17-19) is active (off during static
    /// relaxation, which damps kinetically).
    pub damping: bool,
}

impl<D: Dim> Kinematics<'_, D> {
    /// Current position of node `n` component `k` (m).
    #[inline]
    pub fn x(&self, n: usize, k: usize) -> f64 {
        self.coords[n * D::D + k] + self.u[n * D::D + k]
    }

    /// Current position of node `n` (m): the first `D` components (the rest zero), with
    /// one bounds check per array instead of one per component.
    #[inline(always)]
    pub fn position(&self, n: usize) -> [f64; 3] {
        let d = D::D;
        let (x, u) = (&self.coords[n * d..n * d + d], &self.u[n * d..n * d + d]);
        let mut p = [0.0; 3];
        for k in 0..d {
            p[k] = x[k] + u[k];
        }
        p
    }
}

/// Context given to [`Physics::init`].
pub struct InitContext<'a, D: Dim> {
    /// The mesh.
    pub mesh: &'a Mesh<D>,
    /// Field storage (already holding every declared field).
    pub fields: &'a mut FieldStore,
    pub(crate) slot_nodes: Vec<u32>,
    /// The simulation's entity sets.
    pub(crate) sets: &'a [crate::EntitySet],
    /// Nodes in the simulation before this physics' `add_nodes` calls.
    pub(crate) n_nodes: usize,
    /// Reference coordinates and masses of the nodes this physics adds.
    pub(crate) added_coords: Vec<f64>,
    pub(crate) added_mass: Vec<f64>,
}

impl<D: Dim> InitContext<'_, D> {
    /// Registers force slots: slot `i` of the block adds its `D` components to node
    /// `nodes[i]`. Nodes sum their slots in registration order (deterministic gather).
    /// Slots may also act on nodes added with [`InitContext::add_nodes`] by this or an
    /// earlier physics.
    pub fn register_slots(&mut self, nodes: &[u32]) -> Result<SlotBlock, ComputeError> {
        let n = self.n_nodes() as u32;
        if let Some(&bad) = nodes.iter().find(|&&x| x >= n) {
            return Err(ComputeError::param(
                "slot node",
                bad,
                format!("the simulation has {n} nodes"),
            ));
        }
        let first = self.slot_nodes.len();
        self.slot_nodes.extend_from_slice(nodes);
        Ok(SlotBlock {
            first,
            len: nodes.len(),
        })
    }

    /// The entity set named `name` (e.g. [`crate::names::JOINTS`]).
    pub fn entity_set(&self, name: &str) -> Option<&crate::EntitySet> {
        self.sets.iter().find(|s| s.name() == name)
    }

    /// Nodes in the simulation so far: the mesh nodes and every node added up to now.
    pub fn n_nodes(&self) -> usize {
        self.n_nodes + self.added_mass.len()
    }

    /// Adds degrees of freedom this physics owns (e.g. bolt nodes, particles): nodes at
    /// reference positions `coords` (m, stride D) with lumped masses `mass` (kg). They
    /// are integrated by the same step as the mesh nodes (gravity, local damping,
    /// watchdog, snapshots, both backends); the physics gives them forces through its
    /// slots ([`InitContext::register_slots`]). Node fields (`Place::Node`) cover the
    /// mesh nodes only.
    pub fn add_nodes(&mut self, coords: &[f64], mass: &[f64]) -> Result<NodeBlock, ComputeError> {
        if coords.len() != mass.len() * D::D {
            return Err(ComputeError::param(
                "added node coordinates",
                coords.len(),
                format!(
                    "need {} values ({} nodes x {})",
                    mass.len() * D::D,
                    mass.len(),
                    D::D
                ),
            ));
        }
        if let Some(i) = coords.iter().position(|x| !x.is_finite()) {
            return Err(ComputeError::param(
                format!("added node {} coordinate", i / D::D),
                coords[i],
                "must be finite",
            ));
        }
        if let Some(i) = mass.iter().position(|m| !(*m > 0.0 && m.is_finite())) {
            return Err(ComputeError::param(
                format!("added node {i} mass"),
                mass[i],
                "must be positive and finite",
            ));
        }
        let first = self.n_nodes();
        self.added_coords.extend_from_slice(coords);
        self.added_mass.extend_from_slice(mass);
        Ok(NodeBlock {
            first,
            len: mass.len(),
        })
    }
}

/// Context given to [`Physics::compute_forces`].
pub struct ForceContext<'a, D: Dim> {
    /// Kinematic state.
    pub kin: Kinematics<'a, D>,
    /// Field storage.
    pub fields: &'a mut FieldStore,
    /// This physics' force slots (stride D), to be overwritten (they start zeroed).
    pub slots: &'a mut [f64],
    /// The backend.
    pub backend: &'a Backend,
}

/// Which node velocities a physics' [`Physics::apply_kinematics`] writes
/// ([`Physics::kinematic_nodes`]).
#[derive(Clone, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum KinematicNodes {
    /// None: the physics imposes no kinematic condition.
    None,
    /// Only these nodes' velocities (indices into all nodes, mesh nodes first; any
    /// order, repeats allowed).
    Nodes(Vec<u32>),
    /// Any node's velocity (the default).
    Any,
}

/// Context given to [`Physics::apply_kinematics`] after the velocity update.
pub struct VelocityContext<'a, D: Dim> {
    /// The mesh.
    pub mesh: &'a Mesh<D>,
    /// Node displacement at the start of the step (m) at the nodes this physics names
    /// in [`Physics::kinematic_nodes`] (all nodes with [`KinematicNodes::Any`]); at the
    /// other nodes it may already hold the end of the step's value.
    pub u: &'a [f64],
    /// Node velocity just integrated (m/s): overwrite prescribed components here.
    pub v: &'a mut [f64],
    /// Time at the end of the step (s).
    pub time: f64,
    /// Time step (s).
    pub dt: f64,
    /// Field storage (e.g. for velocities integrated from prescribed accelerations).
    pub fields: &'a mut FieldStore,
}

/// Several physics composed by one call ([`crate::SimulationBuilder::group`]), e.g. the
/// canonical FDEM composition (elements, cohesive joints on every interior face, contact
/// with bonded neighbours excluded) of the `pcdc` facade.
pub trait PhysicsGroup<D: Dim> {
    /// The physics of the group, in the order they run.
    fn into_physics(self) -> Vec<Box<dyn Physics<D>>>;
}

/// A linear constraint on one node's displacement used by the direct static solve.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum DofConstraint {
    /// Component `comp` of node `node` is held fixed.
    Fixed {
        /// Node index.
        node: u32,
        /// Component (0 = x, 1 = y, 2 = z).
        comp: usize,
    },
    /// The node moves only along a direction or in a plane that is not axis-aligned.
    Oblique {
        /// Node index.
        node: u32,
    },
}

/// A physics on backend `B` in dimension `D`.
pub trait Physics<D: Dim>: Send + Sync {
    /// Name used in reports and errors.
    fn name(&self) -> &str;

    /// The fields this physics owns, writes and reads ([`crate::FieldKey::own`],
    /// [`crate::FieldKey::read`], ...). Owned fields are allocated before
    /// [`Physics::init`]; the builder checks that every field has exactly one owner and
    /// that a reader of the current step's value runs after the field's writers.
    fn fields(&self, _mesh: &Mesh<D>) -> Vec<FieldUse> {
        Vec::new()
    }

    /// Entity sets this physics defines (e.g. flow channels, bolt segments), available to
    /// every physics' fields ([`crate::Place::Set`]) and at init
    /// ([`InitContext::entity_set`]). The mesh's interfaces are always the set
    /// [`crate::names::JOINTS`]. A set may join nodes this physics adds in `init`
    /// ([`InitContext::add_nodes`], e.g. bolt nodes): number them from
    /// `mesh.n_nodes()` in the order they will be added; the engine shifts them to their
    /// simulation indices before this physics' `init` and checks after it that they
    /// were added. Default: none.
    fn entity_sets(&self, _mesh: &Mesh<D>) -> Vec<crate::EntitySet> {
        Vec::new()
    }

    /// Whether this physics may be composed only once in a simulation (e.g. element
    /// mechanics: a second instance would add the element forces twice). Default: no.
    fn unique(&self) -> bool {
        false
    }

    /// Validates the physics against the mesh, derives constant data, registers force
    /// slots and sets initial field values.
    fn init(&mut self, ctx: &mut InitContext<'_, D>) -> Result<(), ComputeError>;

    /// Adds this physics' lumped nodal mass (kg) into `mass` (one value per node, the
    /// added nodes included; their own masses are already in).
    /// With `scale_to_dt = Some(dt)` the mass of each contributing entity is scaled up
    /// where needed so that the entity is stable at `dt` (mass scaling for static
    /// relaxation).
    fn add_mass(
        &self,
        _mesh: &Mesh<D>,
        _fields: &FieldStore,
        _mass: &mut [f64],
        _scale_to_dt: Option<f64>,
    ) {
    }

    /// The smallest critical time step of this physics' entities, with the entity.
    fn stable_step(&self, _kin: &Kinematics<'_, D>, _fields: &FieldStore) -> Option<StableStep> {
        None
    }

    /// Forces stage: computes this physics' forces into its slots (and updates its
    /// fields).
    fn compute_forces(&mut self, ctx: &mut ForceContext<'_, D>) -> Result<(), ComputeError>;

    /// Post-update stage: runs once after every mechanical step's position update, in
    /// composition order (e.g. fields derived from the new positions). Default: nothing.
    /// GPU kernels of this stage use [`crate::gpu::Phase::PostUpdate`].
    fn post_update(&mut self, _ctx: &mut FieldContext<'_, D>) -> Result<(), ComputeError> {
        Ok(())
    }

    /// Whether this physics has a sub-cycled field stage, and how it is scheduled
    /// (fixed when the simulation is built). Default: none.
    fn field_schedule(&self) -> Option<FieldSchedule> {
        None
    }

    /// The critical step of this physics' own field stage (s), before the safety factor,
    /// with its limiting entity; used by [`FieldSchedule::Auto`]. It does not limit the
    /// mechanical step.
    fn field_stable_step(
        &self,
        _kin: &Kinematics<'_, D>,
        _fields: &FieldStore,
    ) -> Option<StableStep> {
        None
    }

    /// One field step of the sub-cycled field stage (after the post-update stage; as
    /// often as [`SubCycle`] says). GPU kernels of this stage use
    /// [`crate::gpu::Phase::Field`] and are repeated the same number of times.
    fn field_step(&mut self, _ctx: &mut FieldContext<'_, D>) -> Result<(), ComputeError> {
        Ok(())
    }

    /// Imposes prescribed velocities, accelerations and constraints on the freshly
    /// integrated velocities.
    fn apply_kinematics(&mut self, _ctx: &mut VelocityContext<'_, D>) {}

    /// The nodes whose velocity [`Physics::apply_kinematics`] writes, asked once after
    /// [`Physics::init`]. When every physics of a composition names its nodes (or
    /// [`KinematicNodes::None`]), the CPU step moves every other node in the pass that
    /// gathers its forces and integrates its velocity (the node arrays are read once per
    /// step, not twice) and moves the named ones after the kinematic conditions; the
    /// result is the same. The default, [`KinematicNodes::Any`], keeps the two passes:
    /// right for any physics, and what a physics that writes velocities without saying
    /// where must return.
    fn kinematic_nodes(&self) -> KinematicNodes {
        KinematicNodes::Any
    }

    /// Adds the linear (small-displacement) stiffness of this physics as triplets
    /// `(row dof, col dof, value)`, dof = node * D + component, for the direct static
    /// solve. `Ok(false)` means the physics has no stiffness; the default refuses.
    fn linear_stiffness(
        &self,
        _mesh: &Mesh<D>,
        _fields: &FieldStore,
        _triplets: &mut Vec<(usize, usize, f64)>,
    ) -> Result<bool, ComputeError> {
        Err(ComputeError::NotLinear(format!(
            "physics '{}' has no linear stiffness",
            self.name()
        )))
    }

    /// Kinematic constraints for the direct static solve.
    fn dof_constraints(&self, _mesh: &Mesh<D>, _out: &mut Vec<DofConstraint>) {}

    /// State this physics keeps outside the fields, encoded for a snapshot; the default
    /// has none. Prefer fields for evolving state (they reach the GPU, and a snapshot
    /// holds them on both backends; check their values in [`Physics::check_fields`]):
    /// this hook remains for user physics that keep host-only state.
    fn save_state(&self) -> Result<Vec<u8>, ComputeError> {
        Ok(Vec::new())
    }

    /// Restores what [`Physics::save_state`] wrote. The bytes come from a file: check
    /// every length and index against the mesh and return an error (never panic) when
    /// they do not fit; on error, keep the state held before the call. The default
    /// (no state) accepts only an empty state.
    fn restore_state(&mut self, bytes: &[u8]) -> Result<(), ComputeError> {
        if bytes.is_empty() {
            return Ok(());
        }
        Err(ComputeError::SnapshotCorrupt(format!(
            "physics '{}' keeps no state outside its fields, but the snapshot holds {} bytes for it",
            self.name(),
            bytes.len()
        )))
    }

    /// Checks the values of this physics' fields in a state that a restore is about to
    /// accept (they come from a file, with a valid checksum but possibly forged): values
    /// the physics uses as indices, counts or flags must be checked here and refused with
    /// [`ComputeError::SnapshotCorrupt`], never trusted (a later step must not panic).
    /// Called after [`Physics::init`], before anything changes; the default accepts any
    /// values.
    fn check_fields(&self, _fields: &FieldStore) -> Result<(), ComputeError> {
        Ok(())
    }

    /// A fingerprint of this physics' parameters (materials, laws, ranges; not its
    /// evolving state), e.g. built with [`crate::Fingerprint`], called after
    /// [`Physics::init`]. Snapshots store it and a restore into a physics whose
    /// fingerprint differs is refused, naming the physics. The default, 0, leaves the
    /// physics identified by its name, its declared fields, the nodes of its force slots
    /// and the mass it lumps (which the snapshot fingerprints for every physics).
    fn fingerprint(&self) -> u64 {
        0
    }

    /// Declares this physics' GPU kernels, data and signals (GPU backend only); the
    /// kernels must compute exactly what [`Physics::compute_forces`] and
    /// [`Physics::apply_kinematics`] compute on the host. The default refuses, so that a
    /// physics without kernels is an error when the simulation is built, never a silent
    /// fallback.
    fn gpu_setup(&mut self, _setup: &mut crate::gpu::GpuSetup<'_, D>) -> Result<(), ComputeError> {
        Err(ComputeError::NoGpuKernel {
            physics: self.name().to_string(),
            reason: "it has no GPU kernels yet".to_string(),
        })
    }

    /// Energy stored by this physics (J), e.g. elastic strain energy; used by energy checks.
    fn stored_energy(&self, _kin: &Kinematics<'_, D>, _fields: &FieldStore) -> f64 {
        0.0
    }

    /// Whether this physics' forces are applied loads (face tractions, point loads):
    /// the energy balance counts their work as external work instead of energy the
    /// physics absorbs (default: internal forces of a body).
    fn applies_loads(&self) -> bool {
        false
    }

    /// Whether this physics' forces stage is short and serial (e.g. a few hundred rock
    /// bolts walked on one thread) and uses only the fields it declares in
    /// [`Physics::fields`]: the CPU step may then run it beside an earlier physics with
    /// which, and with every physics between them, it shares no field (`rayon::join`;
    /// its fields are moved to a store of its own for the time), so that the pool's
    /// other threads work on that physics instead of idling through this one. The result
    /// is the same: the two write disjoint slots and fields and read the same kinematics.
    /// Default: no.
    fn runs_beside(&self) -> bool {
        false
    }

    /// Whether [`Physics::compute_forces`] writes every value of its slot block every
    /// step (zeros included), so the engine need not clear the block before it; the
    /// default `false` has the block cleared, and a physics may then add into it.
    fn writes_all_slots(&self) -> bool {
        false
    }

    /// Names the entity that owns slot `slot` of this physics' slot block (e.g.
    /// "joint 12", "element 7"), for the energy watchdog's message; `None`: the slot.
    fn slot_entity(&self, _slot: usize) -> Option<String> {
        None
    }
}
