//! Mechanical boundary conditions (manual 7.2.6, tables 4-7) as one physics:
//! node velocity and acceleration (constants or tables, per component), node forces,
//! face stresses (a stress tensor, xx, yy, zz, xy, yz, xz, and a normal stress that
//! follows the face), and move constraints (fixed, along a line, in a plane).
//!
//! Sign convention: tension positive. A face stress applies the traction `t = σ n` on
//! the face's current outward normal `n`, with σ the symmetric tensor of components
//! s_xx, s_yy, s_zz, s_xy, s_yz, s_xz plus s_n I; a compressive far-field stress or a
//! pressure is therefore negative.
//!
//! On the GPU backend every item is one kernel (`src/shaders/boundary_*.wgsl`): forces
//! (node force, face stress) in the force phase, kinematic items (velocity,
//! acceleration, constraint) after the velocity update, in the order the items were
//! added. Time tables are evaluated on the host once per step as signals, at exactly the
//! times the CPU path uses, so f64 results match the CPU to rounding.

use pcdc_compute::gpu::{Access, GpuData, GpuSetup, Kernel, Phase, WGSL_GEOMETRY};
use pcdc_compute::{
    ComputeError, DofConstraint, FieldId, FieldStore, Fingerprint, ForceContext, InitContext,
    Physics, SlotBlock, TimeValue, VelocityContext,
};
use pcdc_compute::{FieldKey, FieldUse, KinematicNodes, Place};
use pcdc_mesh::{Dim, Mesh, Range};

use crate::MechError;

/// Name of the node field holding velocities integrated from prescribed accelerations.
pub const ACCEL_VELOCITY: FieldKey = FieldKey::new(
    "bc_accel_velocity",
    Place::Node,
    pcdc_compute::Components::Vector,
);

/// The physics name of [`Boundary`], which also prefixes its errors.
const NAME: &str = "mechanical boundary";

/// A boundary error as the simulation reports it: named after the boundary physics
/// (not "mechanics", the element physics of this crate).
fn boundary_error(e: MechError) -> ComputeError {
    e.in_physics(NAME)
}

/// Checks a prescribed value with [`TimeValue::check`]; its invalid-parameter error
/// becomes the boundary's own, so that it is named after the boundary physics.
fn check_value(v: &TimeValue, name: &str) -> Result<(), MechError> {
    v.check(name).map_err(|e| match e {
        ComputeError::InvalidParameter {
            name,
            value,
            reason,
        } => MechError::InvalidParameter {
            name,
            value,
            reason,
        },
        other => MechError::Compute(other),
    })
}

/// A move constraint (manual table 7).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Constraint {
    /// Type 1: the node does not move.
    Fixed,
    /// Type 2: the node moves only along `direction`.
    Line([f64; 3]),
    /// Type 3 (3D): the node moves only in the plane with normal `normal`
    /// (in 2D this is a line constraint perpendicular to `normal`).
    Plane([f64; 3]),
}

/// Per-component prescribed values; `None` leaves a component free.
pub type Components = [Option<TimeValue>; 3];

#[derive(Clone, Debug)]
enum Item {
    Velocity {
        range: Range,
        values: Components,
    },
    Acceleration {
        range: Range,
        values: Components,
    },
    NodeForce {
        range: Range,
        values: Components,
    },
    FaceStress {
        range: Range,
        stress: FaceStress,
    },
    Constraint {
        range: Range,
        constraint: Constraint,
    },
}

/// A stress applied on boundary faces (manual table 6), Pa, tension positive: the
/// traction `t = σ n` on each face's current outward unit normal `n`, σ the symmetric
/// tensor of the components given (`None` is zero) plus `normal` times the identity.
///
/// In 2D, `zz`, `yz` and `xz` must be `None` (or the constant 0): building the simulation
/// rejects them otherwise, since the plane-strain traction has no z component.
#[derive(Clone, Debug, Default)]
pub struct FaceStress {
    /// σ_xx (Pa).
    pub xx: Option<TimeValue>,
    /// σ_yy (Pa).
    pub yy: Option<TimeValue>,
    /// σ_zz (Pa, 3D only).
    pub zz: Option<TimeValue>,
    /// Shear σ_xy = σ_yx (Pa): traction σ_xy n_y along x and σ_xy n_x along y.
    pub xy: Option<TimeValue>,
    /// Shear σ_yz = σ_zy (Pa, 3D only).
    pub yz: Option<TimeValue>,
    /// Shear σ_xz = σ_zx (Pa, 3D only).
    pub xz: Option<TimeValue>,
    /// Normal stress following the face (tension positive; a pressure p is `-p`).
    pub normal: Option<TimeValue>,
}

impl FaceStress {
    /// A uniform stress state `diag(xx, yy, zz)` (constants).
    pub fn diagonal(xx: f64, yy: f64, zz: f64) -> Self {
        FaceStress {
            xx: Some(xx.into()),
            yy: Some(yy.into()),
            zz: Some(zz.into()),
            ..Default::default()
        }
    }

    /// A uniform stress state (constants, Pa) given as `[xx, yy, zz, xy, yz, xz]` (the
    /// order of [`crate::Sym6`]); in 2D, zz, yz and xz must be 0.
    pub fn tensor(s: crate::Sym6) -> Self {
        FaceStress {
            xx: Some(s[0].into()),
            yy: Some(s[1].into()),
            zz: Some(s[2].into()),
            xy: Some(s[3].into()),
            yz: Some(s[4].into()),
            xz: Some(s[5].into()),
            normal: None,
        }
    }

    /// A normal stress that follows the face (tension positive).
    pub fn normal(s: impl Into<TimeValue>) -> Self {
        FaceStress {
            normal: Some(s.into()),
            ..Default::default()
        }
    }

    /// A pure in-plane shear σ_xy = `tau` (Pa), every other component zero.
    pub fn shear_xy(tau: impl Into<TimeValue>) -> Self {
        FaceStress {
            xy: Some(tau.into()),
            ..Default::default()
        }
    }

    /// The off-diagonal components in the order of the shear signals and of
    /// [`shear_pair`]: xy, xz, yz.
    fn shear_components(&self) -> [&Option<TimeValue>; 3] {
        [&self.xy, &self.xz, &self.yz]
    }

    /// Whether any shear component is prescribed.
    fn has_shear(&self) -> bool {
        self.shear_components().iter().any(|v| v.is_some())
    }
}

/// Index in [`FaceStress::shear_components`] of the off-diagonal component σ_cj, c ≠ j:
/// (0, 1) xy → 0, (0, 2) xz → 1, (1, 2) yz → 2. The WGSL kernel uses the same formula.
fn shear_pair(c: usize, j: usize) -> usize {
    c + j - 1
}

#[derive(Clone, Debug)]
struct Resolved {
    nodes: Vec<u32>,
    faces: Vec<u32>,
    slots: Option<SlotBlock>,
}

/// Mechanical boundary conditions, applied in the order they are added (a later
/// kinematic condition on the same node component wins).
#[derive(Clone, Debug, Default)]
pub struct Boundary {
    items: Vec<Item>,
    resolved: Vec<Resolved>,
    accel_field: Option<FieldId>,
}

/// Whether a z value prescribed on a 2D mesh would be ignored silently (anything but the
/// constant 0, which ignoring does not change).
fn ignored_in_2d(v: &TimeValue) -> bool {
    !matches!(v, TimeValue::Const(c) if *c == 0.0)
}

/// Checks prescribed components: constants finite, and no z component (index 2) other
/// than the constant 0 in 2D, where it would be silently ignored.
fn check(values: &Components, what: &str, dim: usize) -> Result<(), MechError> {
    for (k, v) in values.iter().enumerate() {
        if let Some(v) = v {
            if k >= dim && ignored_in_2d(v) {
                return Err(MechError::param(
                    format!("{what} component {k} (z)"),
                    format!("{v:?}"),
                    format!("is prescribed, but the mesh is {dim}D: leave it None"),
                ));
            }
            check_value(v, &format!("{what} component {k}"))?;
        }
    }
    Ok(())
}

impl Boundary {
    /// No conditions.
    pub fn new() -> Self {
        Self::default()
    }

    /// Prescribed node velocity (m/s) per component (table 4).
    pub fn velocity(mut self, range: Range, values: Components) -> Self {
        self.items.push(Item::Velocity { range, values });
        self
    }

    /// Prescribed node acceleration (m/s²) per component (table 4).
    pub fn acceleration(mut self, range: Range, values: Components) -> Self {
        self.items.push(Item::Acceleration { range, values });
        self
    }

    /// A force (N) on every node of the range, per component (table 5).
    pub fn node_force(mut self, range: Range, values: Components) -> Self {
        self.items.push(Item::NodeForce { range, values });
        self
    }

    /// A stress on the boundary faces in the range (table 6).
    pub fn face_stress(mut self, range: Range, stress: FaceStress) -> Self {
        self.items.push(Item::FaceStress { range, stress });
        self
    }

    /// A move constraint on the nodes in the range (table 7).
    pub fn constraint(mut self, range: Range, constraint: Constraint) -> Self {
        self.items.push(Item::Constraint { range, constraint });
        self
    }

    /// Shorthand: fix the nodes in the range.
    pub fn fix(self, range: Range) -> Self {
        self.constraint(range, Constraint::Fixed)
    }

    /// Checks every item for a mesh of dimension `dim` (called when the simulation is
    /// built): constants finite (tables check themselves), no z component or σ_zz in 2D
    /// (other than the constant 0, which changes nothing), constraint directions finite
    /// and non-zero in the mesh's dimension (a z-only direction is an error in 2D).
    fn validate(&self, dim: usize) -> Result<(), MechError> {
        for it in &self.items {
            match it {
                Item::Velocity { values, .. } => check(values, "velocity", dim)?,
                Item::Acceleration { values, .. } => check(values, "acceleration", dim)?,
                Item::NodeForce { values, .. } => check(values, "node force", dim)?,
                Item::FaceStress { stress, .. } => {
                    if dim == 2 {
                        for (n, v) in [("zz", &stress.zz), ("yz", &stress.yz), ("xz", &stress.xz)] {
                            if let Some(v) = v.as_ref().filter(|v| ignored_in_2d(v)) {
                                return Err(MechError::param(
                                    format!("face stress {n}"),
                                    format!("{v:?}"),
                                    "is prescribed, but the mesh is 2D: leave it None",
                                ));
                            }
                        }
                    }
                    for (n, v) in [
                        ("xx", &stress.xx),
                        ("yy", &stress.yy),
                        ("zz", &stress.zz),
                        ("xy", &stress.xy),
                        ("yz", &stress.yz),
                        ("xz", &stress.xz),
                        ("normal", &stress.normal),
                    ] {
                        if let Some(v) = v {
                            check_value(v, &format!("face stress {n}"))?;
                        }
                    }
                }
                Item::Constraint { constraint, .. } => match constraint {
                    Constraint::Fixed => {}
                    Constraint::Line(d) | Constraint::Plane(d) => {
                        if d.iter().any(|x| !x.is_finite()) || d[..dim].iter().all(|x| *x == 0.0) {
                            return Err(MechError::param(
                                "constraint direction",
                                format!("{d:?}"),
                                format!(
                                    "must be finite and non-zero in its first {dim} components"
                                ),
                            ));
                        }
                    }
                },
            }
        }
        Ok(())
    }
}

const NODE_FORCE_WGSL: &str = include_str!("shaders/boundary_node_force.wgsl");
const FACE_STRESS_WGSL: &str = include_str!("shaders/boundary_face_stress.wgsl");
const VELOCITY_WGSL: &str = include_str!("shaders/boundary_velocity.wgsl");
const ACCELERATION_WGSL: &str = include_str!("shaders/boundary_acceleration.wgsl");
const CONSTRAINT_WGSL: &str = include_str!("shaders/boundary_constraint.wgsl");

/// Registers one signal per component `k < D` (consecutive indices) and returns the
/// first; `value(k)` gives component k's closure of `(t, dt)`, t the time at the start of
/// the step.
fn component_signals<D: Dim, F>(
    setup: &mut GpuSetup<'_, D>,
    mut value: impl FnMut(usize) -> F,
) -> u32
where
    F: Fn(f64, f64) -> f64 + Send + Sync + 'static,
{
    let first = setup.signal(value(0));
    for k in 1..D::D {
        let s = setup.signal(value(k));
        debug_assert_eq!(s, first + k as u32);
    }
    first
}

/// Bit k set when component k is prescribed.
fn mask<D: Dim>(values: &Components) -> u32 {
    (0..D::D)
        .filter(|&k| values[k].is_some())
        .fold(0, |m, k| m | (1 << k))
}

fn unit<D: Dim>(d: &[f64; 3]) -> [f64; 3] {
    let n = (0..D::D).map(|k| d[k] * d[k]).sum::<f64>().sqrt();
    let mut out = [0.0; 3];
    for k in 0..D::D {
        out[k] = d[k] / n;
    }
    out
}

impl<D: Dim> Physics<D> for Boundary {
    fn name(&self) -> &str {
        NAME
    }

    fn kinematic_nodes(&self) -> KinematicNodes {
        // The nodes of the velocity, acceleration and constraint items (resolved at init).
        let mut nodes = Vec::new();
        for (it, r) in self.items.iter().zip(&self.resolved) {
            if matches!(
                it,
                Item::Velocity { .. } | Item::Acceleration { .. } | Item::Constraint { .. }
            ) {
                nodes.extend_from_slice(&r.nodes);
            }
        }
        KinematicNodes::Nodes(nodes)
    }

    /// Face tractions and node forces are applied loads: external work.
    fn applies_loads(&self) -> bool {
        true
    }

    fn fingerprint(&self) -> u64 {
        // The conditions (ranges, values, tables) and the nodes and faces they resolved to.
        Fingerprint::new()
            .debug(&self.items)
            .debug(&self.resolved)
            .finish()
    }

    fn fields(&self, _mesh: &Mesh<D>) -> Vec<FieldUse> {
        if self
            .items
            .iter()
            .any(|i| matches!(i, Item::Acceleration { .. }))
        {
            vec![ACCEL_VELOCITY.own::<D>()]
        } else {
            Vec::new()
        }
    }

    fn init(&mut self, ctx: &mut InitContext<'_, D>) -> Result<(), ComputeError> {
        self.validate(D::D).map_err(boundary_error)?;
        let mesh = ctx.mesh;
        self.resolved.clear();
        self.accel_field = ctx.fields.id(ACCEL_VELOCITY).ok();
        for (i, it) in self.items.iter().enumerate() {
            let (range, what) = match it {
                Item::Velocity { range, .. } => (range, "velocity"),
                Item::Acceleration { range, .. } => (range, "acceleration"),
                Item::NodeForce { range, .. } => (range, "node force"),
                Item::FaceStress { range, .. } => (range, "face stress"),
                Item::Constraint { range, .. } => (range, "constraint"),
            };
            let mut r = Resolved {
                nodes: Vec::new(),
                faces: Vec::new(),
                slots: None,
            };
            if let Item::FaceStress { .. } = it {
                r.faces = mesh.select_boundary_faces(range).map_err(MechError::from)?;
                if r.faces.is_empty() {
                    return Err(boundary_error(MechError::EmptyRange {
                        what: format!("boundary condition {i} ({what})"),
                        range: format!("{range:?}"),
                        entity: "boundary face",
                    }));
                }
                let nodes: Vec<u32> = r
                    .faces
                    .iter()
                    .flat_map(|&f| mesh.face(f as usize).iter().copied())
                    .collect();
                r.slots = Some(ctx.register_slots(&nodes)?);
            } else {
                r.nodes = mesh.select_nodes(range).map_err(MechError::from)?;
                if r.nodes.is_empty() {
                    return Err(boundary_error(MechError::EmptyRange {
                        what: format!("boundary condition {i} ({what})"),
                        range: format!("{range:?}"),
                        entity: "node",
                    }));
                }
                if let Item::NodeForce { .. } = it {
                    r.slots = Some(ctx.register_slots(&r.nodes)?);
                }
            }
            self.resolved.push(r);
        }
        Ok(())
    }

    fn compute_forces(&mut self, ctx: &mut ForceContext<'_, D>) -> Result<(), ComputeError> {
        let d = D::D;
        let t = ctx.kin.time;
        for (it, r) in self.items.iter().zip(&self.resolved) {
            match it {
                Item::NodeForce { values, .. } => {
                    let block = r.slots.expect("slots registered");
                    let f: Vec<f64> = (0..d)
                        .map(|k| values[k].as_ref().map_or(0.0, |v| v.at(t)))
                        .collect();
                    for s in 0..block.len {
                        ctx.slots[(block.first + s) * d..(block.first + s + 1) * d]
                            .copy_from_slice(&f);
                    }
                }
                Item::FaceStress { stress, .. } => {
                    let block = r.slots.expect("slots registered");
                    let diag = [
                        stress.xx.as_ref().map_or(0.0, |v| v.at(t)),
                        stress.yy.as_ref().map_or(0.0, |v| v.at(t)),
                        stress.zz.as_ref().map_or(0.0, |v| v.at(t)),
                    ];
                    let sn = stress.normal.as_ref().map_or(0.0, |v| v.at(t));
                    let has_shear = stress.has_shear();
                    let shear = stress
                        .shear_components()
                        .map(|v| v.as_ref().map_or(0.0, |v| v.at(t)));
                    let npf = D::NODES_PER_FACE;
                    let mut x = [0.0; 9];
                    let mut n = [0.0; 3];
                    for (fi, &f) in r.faces.iter().enumerate() {
                        for (k, &node) in ctx.kin.mesh.face(f as usize).iter().enumerate() {
                            for c in 0..d {
                                x[k * d + c] = ctx.kin.x(node as usize, c);
                            }
                        }
                        let area = D::face_measure_normal(&x[..npf * d], &mut n[..d]);
                        // t = σ n: the diagonal term first, then the off-diagonal ones in
                        // increasing j (the order of the WGSL kernel); without shear the
                        // traction is exactly (σ_cc + σ_n) n_c.
                        let mut traction = [0.0; 3];
                        for c in 0..d {
                            let mut tc = (diag[c] + sn) * n[c];
                            if has_shear {
                                for j in (0..d).filter(|&j| j != c) {
                                    tc += shear[shear_pair(c, j)] * n[j];
                                }
                            }
                            traction[c] = tc;
                        }
                        for s in 0..npf {
                            let slot = (block.first + fi * npf + s) * d;
                            for c in 0..d {
                                ctx.slots[slot + c] = traction[c] * area / npf as f64;
                            }
                        }
                    }
                }
                _ => {}
            }
        }
        Ok(())
    }

    fn apply_kinematics(&mut self, ctx: &mut VelocityContext<'_, D>) {
        let d = D::D;
        // Velocities are at the half step t - dt/2.
        let th = ctx.time - 0.5 * ctx.dt;
        for (it, r) in self.items.iter().zip(&self.resolved) {
            match it {
                Item::Velocity { values, .. } => {
                    for k in 0..d {
                        if let Some(v) = &values[k] {
                            let val = v.at(th);
                            for &n in &r.nodes {
                                ctx.v[n as usize * d + k] = val;
                            }
                        }
                    }
                }
                Item::Acceleration { values, .. } => {
                    let id = self.accel_field.expect("field declared");
                    let acc = ctx.fields.get_mut(id);
                    for k in 0..d {
                        if let Some(a) = &values[k] {
                            let inc = a.at(ctx.time - ctx.dt) * ctx.dt;
                            for &n in &r.nodes {
                                let i = n as usize * d + k;
                                acc[i] += inc;
                                ctx.v[i] = acc[i];
                            }
                        }
                    }
                }
                Item::Constraint { constraint, .. } => {
                    for &n in &r.nodes {
                        let v = &mut ctx.v[n as usize * d..(n as usize + 1) * d];
                        match constraint {
                            Constraint::Fixed => v.fill(0.0),
                            Constraint::Line(dir) => {
                                let u = unit::<D>(dir);
                                let dot: f64 = (0..d).map(|k| v[k] * u[k]).sum();
                                for k in 0..d {
                                    v[k] = dot * u[k];
                                }
                            }
                            Constraint::Plane(nrm) => {
                                let u = unit::<D>(nrm);
                                let dot: f64 = (0..d).map(|k| v[k] * u[k]).sum();
                                for k in 0..d {
                                    v[k] -= dot * u[k];
                                }
                            }
                        }
                    }
                }
                _ => {}
            }
        }
    }

    fn gpu_setup(&mut self, setup: &mut GpuSetup<'_, D>) -> Result<(), ComputeError> {
        if self.resolved.len() != self.items.len() {
            return Err(ComputeError::Gpu(format!("{NAME}: GPU setup before init")));
        }
        let d = D::D as u32;
        let slot0 = setup.slot_first();
        for (i, (it, r)) in self.items.iter().zip(&self.resolved).enumerate() {
            let label = |what: &str| format!("boundary {i}: {what}");
            match it {
                Item::NodeForce { values, .. } => {
                    let block = r.slots.expect("slots registered");
                    // Forces at the start of the step, as `compute_forces` (kin.time).
                    let sig = component_signals(setup, |k| {
                        let v = values[k].clone();
                        move |t: f64, _dt: f64| v.as_ref().map_or(0.0, |v| v.at(t))
                    });
                    let k = Kernel::new(label("node force"), NODE_FORCE_WGSL, block.len)
                        .const_u32("D", d)
                        .const_u32("SLOT0", slot0 + block.first as u32)
                        .const_u32("SIG", sig)
                        .bind("slots", setup.slots(), Access::ReadWrite);
                    setup.kernel(Phase::Forces, k)?;
                }
                Item::FaceStress { stress, .. } => {
                    let block = r.slots.expect("slots registered");
                    let npf = D::NODES_PER_FACE;
                    // Component c carries σ_cc + σ_n at the start of the step, summed in
                    // f64 exactly as `compute_forces` does.
                    let sig = component_signals(setup, |c| {
                        let diag = [&stress.xx, &stress.yy, &stress.zz][c].clone();
                        let normal = stress.normal.clone();
                        move |t: f64, _dt: f64| {
                            diag.as_ref().map_or(0.0, |v| v.at(t))
                                + normal.as_ref().map_or(0.0, |v| v.at(t))
                        }
                    });
                    // Off-diagonal σ_cj (c ≠ j), D (D − 1) / 2 signals after the diagonal
                    // ones, in the order of `shear_pair`; none without shear (SHEAR = 0
                    // leaves the kernel's arithmetic that of a diagonal stress).
                    let has_shear = stress.has_shear();
                    let mut shear_sig = 0;
                    if has_shear {
                        for (p, v) in stress.shear_components()[..D::D * (D::D - 1) / 2]
                            .iter()
                            .enumerate()
                        {
                            let v = (*v).clone();
                            let i = setup.signal(move |t: f64, _dt: f64| {
                                v.as_ref().map_or(0.0, |v| v.at(t))
                            });
                            if p == 0 {
                                shear_sig = i;
                            }
                            debug_assert_eq!(i, shear_sig + p as u32);
                        }
                    }
                    let face_nodes: Vec<u32> = r
                        .faces
                        .iter()
                        .flat_map(|&f| setup.mesh.face(f as usize).iter().copied())
                        .collect();
                    let faces = setup.upload(&label("face nodes"), GpuData::U32(face_nodes));
                    let src = format!("{WGSL_GEOMETRY}{FACE_STRESS_WGSL}");
                    let k = Kernel::new(label("face stress"), src, r.faces.len())
                        .const_u32("D", d)
                        .const_u32("NPF", npf as u32)
                        .const_real("NPF_REAL", npf as f64)
                        .const_u32("SLOT0", slot0 + block.first as u32)
                        .const_u32("SIG", sig)
                        .const_u32("SHEAR", u32::from(has_shear))
                        .const_u32("SHEAR_SIG", shear_sig)
                        .bind("coords", setup.coords(), Access::Read)
                        .bind("disp", setup.displacement(), Access::Read)
                        .bind("faces", faces, Access::Read)
                        .bind("slots", setup.slots(), Access::ReadWrite);
                    setup.kernel(Phase::Forces, k)?;
                }
                Item::Velocity { values, .. } => {
                    // `apply_kinematics` evaluates at (t_end) - dt/2, t_end = t + dt.
                    let sig = component_signals(setup, |k| {
                        let v = values[k].clone();
                        move |t: f64, dt: f64| v.as_ref().map_or(0.0, |v| v.at((t + dt) - 0.5 * dt))
                    });
                    let nodes = setup.upload(&label("nodes"), GpuData::U32(r.nodes.clone()));
                    let k = Kernel::new(label("velocity"), VELOCITY_WGSL, r.nodes.len())
                        .const_u32("D", d)
                        .const_u32("MASK", mask::<D>(values))
                        .const_u32("SIG", sig)
                        .bind("nodes", nodes, Access::Read)
                        .bind("vel", setup.velocity(), Access::ReadWrite);
                    setup.kernel(Phase::Kinematics, k)?;
                }
                Item::Acceleration { values, .. } => {
                    // Increment a(t_end - dt) dt, t_end = t + dt, as `apply_kinematics`.
                    let sig = component_signals(setup, |k| {
                        let a = values[k].clone();
                        move |t: f64, dt: f64| a.as_ref().map_or(0.0, |a| a.at((t + dt) - dt) * dt)
                    });
                    let acc = setup.field(ACCEL_VELOCITY)?;
                    let nodes = setup.upload(&label("nodes"), GpuData::U32(r.nodes.clone()));
                    let k = Kernel::new(label("acceleration"), ACCELERATION_WGSL, r.nodes.len())
                        .const_u32("D", d)
                        .const_u32("MASK", mask::<D>(values))
                        .const_u32("SIG", sig)
                        .bind("nodes", nodes, Access::Read)
                        .bind("vel", setup.velocity(), Access::ReadWrite)
                        .bind("acc", acc, Access::ReadWrite);
                    setup.kernel(Phase::Kinematics, k)?;
                }
                Item::Constraint { constraint, .. } => {
                    let (kind, u) = match constraint {
                        Constraint::Fixed => (0, [0.0; 3]),
                        Constraint::Line(dir) => (1, unit::<D>(dir)),
                        Constraint::Plane(nrm) => (2, unit::<D>(nrm)),
                    };
                    let nodes = setup.upload(&label("nodes"), GpuData::U32(r.nodes.clone()));
                    let k = Kernel::new(label("constraint"), CONSTRAINT_WGSL, r.nodes.len())
                        .const_u32("D", d)
                        .const_u32("KIND", kind)
                        .const_real("U0", u[0])
                        .const_real("U1", u[1])
                        .const_real("U2", u[2])
                        .bind("nodes", nodes, Access::Read)
                        .bind("vel", setup.velocity(), Access::ReadWrite);
                    setup.kernel(Phase::Kinematics, k)?;
                }
            }
        }
        Ok(())
    }

    fn linear_stiffness(
        &self,
        _mesh: &Mesh<D>,
        _fields: &FieldStore,
        _t: &mut Vec<(usize, usize, f64)>,
    ) -> Result<bool, ComputeError> {
        Ok(false)
    }

    fn dof_constraints(&self, _mesh: &Mesh<D>, out: &mut Vec<DofConstraint>) {
        let d = D::D;
        for (it, r) in self.items.iter().zip(&self.resolved) {
            let comps: Vec<usize> = match it {
                Item::Velocity { values, .. } | Item::Acceleration { values, .. } => {
                    (0..d).filter(|&k| values[k].is_some()).collect()
                }
                Item::Constraint { constraint, .. } => match constraint {
                    Constraint::Fixed => (0..d).collect(),
                    Constraint::Line(dir) | Constraint::Plane(dir) => {
                        let u = unit::<D>(dir);
                        let axis = (0..d).find(|&k| (u[k].abs() - 1.0).abs() < 1e-12);
                        match (axis, constraint) {
                            (Some(a), Constraint::Line(_)) => (0..d).filter(|&k| k != a).collect(),
                            (Some(a), Constraint::Plane(_)) => vec![a],
                            _ => {
                                out.extend(
                                    r.nodes.iter().map(|&node| DofConstraint::Oblique { node }),
                                );
                                continue;
                            }
                        }
                    }
                },
                _ => continue,
            };
            for &node in &r.nodes {
                for &comp in &comps {
                    out.push(DofConstraint::Fixed { node, comp });
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use pcdc_compute::gpu::{offline_kernel_sources, validate_wgsl, Precision};
    use pcdc_compute::Table;
    use pcdc_mesh::builders;

    fn ramp() -> TimeValue {
        Table::new("ramp", &[(0.0, 0.0), (1.0, 2.0)])
            .unwrap()
            .into()
    }

    /// A boundary with every kind of item (tables and constants, partial components); z
    /// components and σ_zz only in 3D, where they are allowed.
    fn every_item(sides: [&str; 4], dim: usize) -> Boundary {
        let [a, b, c, e] = sides.map(Range::group);
        let z = |v: f64| (dim == 3).then(|| TimeValue::from(v));
        Boundary::new()
            .velocity(a.clone(), [None, Some(ramp()), z(0.5)])
            .acceleration(b.clone(), [Some(ramp()), None, z(1.0)])
            .node_force(c.clone(), [Some(1.0.into()), Some(ramp()), None])
            .face_stress(
                e.clone(),
                FaceStress {
                    xx: Some(ramp()),
                    yy: Some((-2.0).into()),
                    zz: z(3.0),
                    xy: Some(ramp()),
                    yz: z(-1.5),
                    xz: (dim == 3).then(ramp),
                    normal: Some(ramp()),
                },
            )
            .fix(a)
            .constraint(b, Constraint::Line([1.0, 1.0, 1.0]))
            .constraint(c, Constraint::Plane([0.0, 2.0, 1.0]))
            .face_stress(e, FaceStress::normal(-1.0))
    }

    fn check_sources<D: Dim>(mesh: &Mesh<D>, boundary: Boundary) {
        for precision in [Precision::F64, Precision::F32] {
            let physics: Vec<Box<dyn Physics<D>>> = vec![Box::new(boundary.clone())];
            let sources = offline_kernel_sources(mesh, physics, precision).unwrap();
            let ours: Vec<&str> = sources
                .iter()
                .map(|(l, _)| l.as_str())
                .filter(|l| l.starts_with("boundary"))
                .collect();
            assert_eq!(
                ours,
                [
                    "boundary 0: velocity",
                    "boundary 1: acceleration",
                    "boundary 2: node force",
                    "boundary 3: face stress",
                    "boundary 4: constraint",
                    "boundary 5: constraint",
                    "boundary 6: constraint",
                    "boundary 7: face stress",
                ]
            );
            for (label, src) in &sources {
                if let Err(e) = validate_wgsl(src) {
                    panic!("{label} ({precision:?}) does not validate:\n{e}");
                }
            }
        }
    }

    #[test]
    fn gpu_kernels_validate_with_naga_2d_and_3d() {
        let m2 = builders::rectangle(0.0, 0.0, 1.0, 0.5, 0.25).unwrap();
        check_sources(&m2, every_item(["top", "left", "right", "bottom"], 2));
        let m3 = builders::cuboid([0.0; 3], [1.0, 0.5, 0.5], 0.5).unwrap();
        check_sources(&m3, every_item(["zmax", "xmin", "xmax", "ymin"], 3));
    }
}
