//! Mechanical boundary conditions (manual 7.2.6, tables 4-7) as one physics:
//! node velocity and acceleration (constants or tables, per component), node forces,
//! face stresses (xx, yy, zz and a normal stress that follows the face), and move
//! constraints (fixed, along a line, in a plane).
//!
//! Sign convention: tension positive. A face stress applies the traction `t = σ n` on
//! the face's current outward normal `n`, with `σ = diag(s_xx, s_yy, s_zz) + s_n I`; a
//! compressive far-field stress or a pressure is therefore negative.

use pcdc_compute::{
    ComputeError, Backend, DofConstraint, FieldId, FieldSpec, FieldStore, ForceContext,
    InitContext, Location, Physics, SlotBlock, TimeValue, VelocityContext,
};
use pcdc_mesh::{Dim, Mesh, Range};

use crate::MechError;

/// Name of the node field holding velocities integrated from prescribed accelerations.
pub const ACCEL_VELOCITY: &str = "bc_accel_velocity";

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

/// A stress applied on boundary faces (manual table 6), Pa, tension positive.
#[derive(Clone, Debug, Default)]
pub struct FaceStress {
    /// σ_xx.
    pub xx: Option<TimeValue>,
    /// σ_yy.
    pub yy: Option<TimeValue>,
    /// σ_zz (3D).
    pub zz: Option<TimeValue>,
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

fn check(values: &Components, what: &str) -> Result<(), MechError> {
    for (k, v) in values.iter().enumerate() {
        if let Some(v) = v {
            v.check(&format!("{what} component {k}"))?;
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

    fn validate(&self) -> Result<(), MechError> {
        for it in &self.items {
            match it {
                Item::Velocity { values, .. } => check(values, "velocity")?,
                Item::Acceleration { values, .. } => check(values, "acceleration")?,
                Item::NodeForce { values, .. } => check(values, "node force")?,
                Item::FaceStress { stress, .. } => {
                    for (n, v) in [
                        ("xx", &stress.xx),
                        ("yy", &stress.yy),
                        ("zz", &stress.zz),
                        ("normal", &stress.normal),
                    ] {
                        if let Some(v) = v {
                            v.check(&format!("face stress {n}"))?;
                        }
                    }
                }
                Item::Constraint { constraint, .. } => match constraint {
                    Constraint::Fixed => {}
                    Constraint::Line(d) | Constraint::Plane(d) => {
                        if d.iter().any(|x| !x.is_finite()) || d.iter().all(|x| *x == 0.0) {
                            return Err(MechError::param(
                                "constraint direction",
                                format!("{d:?}"),
                                "must be finite and non-zero",
                            ));
                        }
                    }
                },
            }
        }
        Ok(())
    }
}

fn unit<D: Dim>(d: &[f64; 3]) -> [f64; 3] {
    let n = (0..D::D).map(|k| d[k] * d[k]).sum::<f64>().sqrt();
    let mut out = [0.0; 3];
    for k in 0..D::D {
        out[k] = d[k] / n;
    }
    out
}

impl<D: Dim, B: Backend> Physics<D, B> for Boundary {
    fn name(&self) -> &str {
        "mechanical boundary"
    }

    fn fields(&self, _mesh: &Mesh<D>) -> Vec<FieldSpec> {
        if self
            .items
            .iter()
            .any(|i| matches!(i, Item::Acceleration { .. }))
        {
            vec![FieldSpec::new(ACCEL_VELOCITY, Location::Node, D::D)]
        } else {
            Vec::new()
        }
    }

    fn init(&mut self, ctx: &mut InitContext<'_, D>) -> Result<(), ComputeError> {
        self.validate()?;
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
                    return Err(MechError::EmptyRange {
                        what: format!("boundary condition {i} ({what})"),
                        range: format!("{range:?}"),
                        entity: "boundary face",
                    }
                    .into());
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
                    return Err(MechError::EmptyRange {
                        what: format!("boundary condition {i} ({what})"),
                        range: format!("{range:?}"),
                        entity: "node",
                    }
                    .into());
                }
                if let Item::NodeForce { .. } = it {
                    r.slots = Some(ctx.register_slots(&r.nodes)?);
                }
            }
            self.resolved.push(r);
        }
        Ok(())
    }

    fn compute_forces(
        &self,
        ctx: &mut ForceContext<'_, D, B>,
    ) -> Result<(), ComputeError> {
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
                        for s in 0..npf {
                            let slot = (block.first + fi * npf + s) * d;
                            for c in 0..d {
                                ctx.slots[slot + c] = (diag[c] + sn) * n[c] * area / npf as f64;
                            }
                        }
                    }
                }
                _ => {}
            }
        }
        Ok(())
    }

    fn apply_kinematics(&self, ctx: &mut VelocityContext<'_, D>) {
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
