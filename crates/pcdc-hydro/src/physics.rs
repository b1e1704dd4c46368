//! [`Hydro`]: the fracture-flow physics (manual 7.5): its builder, boundary conditions
//! and the stages it runs.

use rayon::prelude::*;

use pcdc_compute::names::{JOINT_DAMAGE, PORE_PRESSURE};
use pcdc_compute::{
    ComputeError, Entity, EntityKind, EntitySet, FieldContext, FieldId, FieldSchedule, FieldStore,
    FieldUse, Fingerprint, ForceContext, InitContext, KinematicNodes, Kinematics, Physics,
    SlotBlock, StableStep, TimeValue,
};
use pcdc_mesh::{Dim, Mesh, Range};

use crate::calibration;
use crate::fields::{
    CHANNEL_APERTURE, CHANNEL_FLUX, CHANNEL_LEAK_AGE, FLOW_BALANCE, FLOW_CHANNELS, FLOW_NODES,
    FLOW_PEAK_PRESSURE, FLOW_PRESSURE, FLOW_SATURATION, FLOW_STORED,
};
use crate::flow::{self, Geometry};
use crate::model::{saturation_weight, FlowModel};
use crate::network::Network;
use crate::steady;

/// Channels (or flow nodes) per rayon block: many per task, as the engine's loops do.
const CHUNK: usize = 256;

/// How the fluid and the solid exchange information (manual 7.5.2).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Coupling {
    /// Two-way: the solid's motion changes apertures and node volumes, and the fluid
    /// pressure loads both faces of every channel's joint (effective stress; joints open
    /// under pressure). The default.
    #[default]
    TwoWay,
    /// One-way: the geometry goes to the flow, the pressure does not go back (the fluid's
    /// response to a given deformation).
    OneWay,
    /// Flow only: the solid is frozen at its reference configuration, apertures stay at
    /// their initial values (steady seepage, rigid fractures). Compose no mechanics: the
    /// fluid's stable step is then the simulation's step, and the engine's node arrays get
    /// a nominal unit mass per mesh node that nothing moves (leave the simulation's
    /// gravity at zero; the fluid's own is [`Hydro::gravity`]).
    FlowOnly,
}

/// A pressure (Pa) as a function of position (m).
type PressureFn = Box<dyn Fn(&[f64]) -> f64 + Send + Sync>;

/// Initial state of the flow nodes.
enum Initial {
    /// Saturated at this pressure (Pa).
    Pressure(f64),
    /// Empty (s = 0).
    Dry,
    /// Saturated at the pressure this function gives at the node's position (Pa).
    Function(PressureFn),
}

/// A flow boundary condition (manual 7.5.4, table 11), on the flow nodes of a node range.
#[derive(Clone, Debug)]
enum Condition {
    /// Fluid pressure p (Pa).
    Pressure(Range, TimeValue),
    /// Free-surface (water level) elevation z_s (m): p = ρ_f |g| (z_s − z) where the node
    /// lies below it, a seepage face (p ≤ 0 held) above.
    Head(Range, TimeValue),
    /// Volumetric flow rate into the network (m³/s; per unit thickness in 2D), shared
    /// equally by the distinct flow nodes of the range.
    Rate(Range, TimeValue),
}

/// Which channels a pre-existing fracture takes.
#[derive(Clone, Debug)]
enum Selection {
    /// Joints whose side-A face centroid lies in the range.
    Range(Range),
    /// These joints (interface indices of the split mesh).
    Joints(Vec<u32>),
}

/// Field ids, resolved at init.
#[derive(Clone, Copy, Debug)]
struct Ids {
    content: FieldId,
    pressure: FieldId,
    peak: FieldId,
    saturation: FieldId,
    balance: FieldId,
    aperture: FieldId,
    flux: FieldId,
    leak_age: FieldId,
    pore: FieldId,
    damage: Option<FieldId>,
}

/// Data derived at init.
#[derive(Clone)]
pub(crate) struct Derived {
    pub(crate) net: Network,
    /// The joint nodes (side A, then side B) of every channel.
    pub(crate) channel_joint_nodes: Vec<u32>,
    /// Initial aperture δ⁰ of each channel (m).
    pub(crate) delta0: Vec<f64>,
    /// Whether each channel lies on a pre-existing fracture.
    pre_existing: Vec<bool>,
    /// Reference aperture δ_r of each channel with calibrated edge weights (m; 0 for the
    /// others): see [`crate::calibration`].
    pub(crate) delta_ref: Vec<f64>,
    /// Calibrated edge weights ŵ, 3 per channel (0 where `delta_ref` is 0).
    pub(crate) calib_weight: Vec<f64>,
    /// Flow node → index into `fixed_values` (pressure or head condition), or NONE.
    pub(crate) fixed: Vec<u32>,
    /// Pressure-type conditions in use: (is head, value).
    pub(crate) fixed_values: Vec<(bool, TimeValue)>,
    /// Elevation z = −ĝ·x of each flow node (m), for head conditions.
    pub(crate) elevation: Vec<f64>,
    /// Rate conditions per flow node: entries `rate_ptr[l]..rate_ptr[l + 1]` of
    /// `rate_cond` (index into `rate_values`) and `rate_share` (its share of the rate),
    /// in the order the conditions were given; read by the CPU and GPU node updates.
    pub(crate) rate_ptr: Vec<u32>,
    pub(crate) rate_cond: Vec<u32>,
    pub(crate) rate_share: Vec<f64>,
    pub(crate) rate_values: Vec<TimeValue>,
    slots: Option<SlotBlock>,
}

/// Fluid flow along the joints of a split mesh (manual 7.5): the cubic law on a channel
/// per joint, storage at a flow node per original vertex, boundary conditions, Carter
/// leak-off and the coupling to the solid. See the [crate documentation](crate) for the
/// equations.
///
/// ```
/// use pcdc_compute::{Backend, Simulation};
/// use pcdc_hydro::{Aperture, Coupling, FlowModel, Fluid, Hydro};
/// use pcdc_mesh::{builders, split_nodes, Range};
///
/// # fn main() -> Result<(), Box<dyn std::error::Error>> {
/// let mesh = split_nodes(&builders::rectangle(0.0, 0.0, 1.0, 0.2, 0.05)?, &Range::All)?;
/// let model = FlowModel::new(Fluid::water(), Aperture::fixed(1e-5)?);
/// let flow = Hydro::new(model)
///     .coupling(Coupling::FlowOnly)
///     .pressure(Range::rect(-0.01, -0.01, 0.01, 0.21), 1e5) // 0.1 MPa on the left
///     .pressure(Range::rect(0.99, -0.01, 1.01, 0.21), 0.0);
/// let mut sim = Simulation::builder(mesh, Backend::cpu(1)?).physics(flow).build()?;
/// sim.run(100)?;
/// let balance = pcdc_hydro::mass_balance(&sim)?;
/// assert!(balance.residual.abs() <= 1e-12 * balance.scale());
/// # Ok(()) }
/// ```
pub struct Hydro {
    model: FlowModel,
    pub(crate) coupling: Coupling,
    pub(crate) gravity: [f64; 3],
    bulk_scale: f64,
    only: Option<Range>,
    permeability: Option<f64>,
    impermeable: Vec<Range>,
    fractures: Vec<(Selection, f64)>,
    initial: Initial,
    conditions: Vec<Condition>,
    schedule: FieldSchedule,
    steady: bool,
    pub(crate) derived: Option<Derived>,
    /// The derivation made for the builder's first questions (sets, fields), kept for
    /// init so that the network is built once: (mesh key, data).
    prepared: std::sync::OnceLock<((usize, usize, usize), Derived)>,
    ids: Option<Ids>,
    pub(crate) geom: Geometry,
    /// Per channel node, the volume flowing in over the current field step (m³).
    share: Vec<f64>,
    /// Per channel, the volume each of its nodes loses to leak-off over the step (m³).
    leak: Vec<f64>,
    /// Pressure/head condition values, then rate values, at the current step.
    values: Vec<f64>,
}

impl Hydro {
    /// Flow with `model` on every joint, two-way coupled, no gravity, saturated at zero
    /// pressure, no boundary condition (a closed network), sub-cycled automatically.
    pub fn new(model: FlowModel) -> Self {
        Hydro {
            model,
            coupling: Coupling::TwoWay,
            gravity: [0.0; 3],
            bulk_scale: 1.0,
            only: None,
            permeability: None,
            impermeable: Vec::new(),
            fractures: Vec::new(),
            initial: Initial::Pressure(0.0),
            conditions: Vec::new(),
            schedule: FieldSchedule::Auto,
            steady: false,
            derived: None,
            prepared: std::sync::OnceLock::new(),
            ids: None,
            geom: Geometry::default(),
            share: Vec::new(),
            leak: Vec::new(),
            values: Vec::new(),
        }
    }

    /// The coupling mode ([`Coupling`]).
    pub fn coupling(mut self, mode: Coupling) -> Self {
        self.coupling = mode;
        self
    }

    /// The gravity the fluid feels (m/s², e.g. `[0, -9.81, 0]`): the head of eq. 74 and
    /// hydrostatic conditions. Independent of the simulation's gravity on the solid.
    pub fn gravity(mut self, g: [f64; 3]) -> Self {
        self.gravity = g;
        self
    }

    /// Scales the fluid bulk modulus in the storage equation by `factor`, in (0, 1],
    /// for speed: the fluid's stable step grows as 1/K_f and its stiffness on the solid
    /// falls with K_f. Transients slow down by the same factor (the diffusivity is
    /// K_f δ²/(12 μ)); steady states do not change. Measured on validation scene 11
    /// (transient flow along a fracture, `cargo run --release --example fracture_flow`),
    /// against the unscaled closed form at the same physical times: scale 1, 0.5 and 0.1
    /// take 25 600, 12 800 and 2 560 steps and miss by 8.8e-5, 0.31 and 0.84 of p_A. Use
    /// it where the fluid's transient is not what is measured (steady seepage, or a
    /// fluid stiffness that would otherwise set the mechanical step).
    pub fn bulk_modulus_scale(mut self, factor: f64) -> Self {
        self.bulk_scale = factor;
        self
    }

    /// Calibrates the virtual aperture of every intact channel to the rock mass
    /// permeability `k` (m²) instead of one uniform δ⁰ (\[NOT IN MANUAL: the manual says
    /// the virtual aperture is calibrated, not how\]). 2D: each channel's conductance
    /// δ³/(12 μ L) equals the linear finite-element conductance of isotropic Darcy flow
    /// across its edge, (k/μ)(cot α + cot β)/2 (α, β the angles opposite the edge in
    /// its two triangles), so δ⁰ = (6 k L (cot α + cot β))^⅓ and the intact network is
    /// that discretisation whatever the mesh (an edge with cot α + cot β ≤ 0, of a
    /// non-Delaunay pair, gets δ_min). 3D: one aperture per face cannot carry a
    /// tetrahedron's six edge conductances with its four faces, so each intact channel
    /// gets δ⁰ = (18 k (V_A + V_B) / (4 A))^⅓ (A its area, V_A, V_B its tetrahedra: the
    /// storage volume of randomly oriented channels of that permeability) and calibrated
    /// edge weights that split every tetrahedron's finite-element edge conductance
    /// between the two faces on the edge; the intact network is then that
    /// discretisation too, and a joint that opens moves to the cubic law of its own
    /// geometry ([`crate::calibration`]; measured on validation scene 9: 0.31 %
    /// at 5 cm where the per-face mean calibration missed by 3.0 %). Pre-existing
    /// fractures keep their own aperture and the cubic law; δ⁰ is still clamped to
    /// [δ_min, δ_max] as eq. 79 says.
    pub fn rock_permeability(mut self, k: f64) -> Self {
        self.permeability = Some(k);
        self
    }

    /// Channels only on the joints whose face centroid lies in `range` (default: every
    /// joint), e.g. a single fracture in otherwise impermeable rock.
    pub fn network_on(mut self, range: Range) -> Self {
        self.only = Some(range);
        self
    }

    /// Makes the joints of elements whose centroid lies in `range` impermeable (no
    /// channel).
    pub fn impermeable(mut self, range: Range) -> Self {
        self.impermeable.push(range);
        self
    }

    /// A pre-existing fracture: the channels on joints whose face centroid lies in
    /// `range` start at initial aperture `aperture` (m) instead of the virtual one, and
    /// leak from the start when leak-off is on.
    pub fn fracture(mut self, range: Range, aperture: f64) -> Self {
        self.fractures.push((Selection::Range(range), aperture));
        self
    }

    /// A pre-existing fracture on these joints (interface indices of the split mesh, e.g.
    /// from `pcdc_cohesive::Fracture` mapping).
    pub fn fracture_joints(mut self, joints: Vec<u32>, aperture: f64) -> Self {
        self.fractures.push((Selection::Joints(joints), aperture));
        self
    }

    /// Every flow node saturated at pressure `p` (Pa) at the start (default 0).
    pub fn initial_pressure(mut self, p: f64) -> Self {
        self.initial = Initial::Pressure(p);
        self
    }

    /// Every flow node saturated at the pressure `f(x)` (Pa) of its position x (m), e.g.
    /// hydrostatic.
    pub fn initial_pressure_fn(
        mut self,
        f: impl Fn(&[f64]) -> f64 + Send + Sync + 'static,
    ) -> Self {
        self.initial = Initial::Function(Box::new(f));
        self
    }

    /// Every flow node empty at the start (saturation 0).
    pub fn initially_dry(mut self) -> Self {
        self.initial = Initial::Dry;
        self
    }

    /// Fluid pressure `p` (Pa; constant or a time table) held at the flow nodes of the
    /// nodes in `range` (table 11 `p`). A later pressure or head condition on the same
    /// flow node replaces an earlier one.
    pub fn pressure(mut self, range: Range, p: impl Into<TimeValue>) -> Self {
        self.conditions.push(Condition::Pressure(range, p.into()));
        self
    }

    /// A free surface (water level) at elevation `z_s` (m, along −g; constant or a time
    /// table) over the nodes of `range` (table 11 `f-s`): the hydrostatic pressure
    /// ρ_f |g| (z_s − z) where a node lies below it; above it, a seepage face
    /// (\[NOT IN MANUAL\]: the face is open to the air, so fluid reaching it leaves at
    /// atmospheric pressure, p ≤ 0 held, and none enters; a dry node stays dry). Needs
    /// [`Hydro::gravity`].
    pub fn head(mut self, range: Range, z_s: impl Into<TimeValue>) -> Self {
        self.conditions.push(Condition::Head(range, z_s.into()));
        self
    }

    /// Injection at volumetric rate `q` (m³/s, per unit thickness in 2D; negative
    /// extracts; constant or a time table) into the flow nodes of `range`, shared equally
    /// by them (table 11 `f-r`).
    pub fn rate(mut self, range: Range, q: impl Into<TimeValue>) -> Self {
        self.conditions.push(Condition::Rate(range, q.into()));
        self
    }

    /// How the fluid stage is sub-cycled against the mechanical step (default
    /// [`FieldSchedule::Auto`], from the two stable steps).
    pub fn schedule(mut self, schedule: FieldSchedule) -> Self {
        self.schedule = schedule;
        self
    }

    /// Steady flow in a rigid network: at build the pressures are solved once for a zero
    /// net inflow at every free flow node (the explicit steps' discretisation, solved
    /// by one sparse LU factorisation), and the fluid is not stepped afterwards: pressures, fluxes and
    /// saturation (1) stay as solved, with no fluid step to limit the simulation's. For a
    /// slow process carried by a flow that settles quickly, e.g. heat carried along a
    /// fracture (`pcdc_thermal`'s fluid heat, the Lauwerier scene). Needs
    /// [`Coupling::FlowOnly`], constant pressure and rate conditions with at least one
    /// pressure condition in every connected part of the network, no free-surface
    /// condition and no leak-off (each would make the flow transient); the steady
    /// pressure must be non-negative everywhere. Runs on both backends (the GPU reads the
    /// solved fields).
    pub fn steady_flow(mut self) -> Self {
        self.steady = true;
        self
    }

    /// The flow model.
    pub fn model(&self) -> &FlowModel {
        &self.model
    }

    /// The network, once the simulation is built.
    pub fn network(&self) -> Option<&Network> {
        self.derived.as_ref().map(|d| &d.net)
    }

    /// K_f as used by the storage equation (Pa): the model's times the scale.
    pub fn bulk_modulus(&self) -> f64 {
        self.model.fluid.bulk_modulus * self.bulk_scale
    }

    fn follows_solid(&self) -> bool {
        self.coupling != Coupling::FlowOnly
    }

    pub(crate) fn reads_damage(&self) -> bool {
        self.model.leak_off.is_some() && self.follows_solid()
    }

    fn check(&self) -> Result<(), ComputeError> {
        self.model.check()?;
        if self.steady {
            let why = if self.coupling != Coupling::FlowOnly {
                Some("needs Coupling::FlowOnly (a network that follows the solid changes)")
            } else if self.model.leak_off.is_some() {
                Some("cannot leak off (leak-off decays in time)")
            } else if matches!(self.initial, Initial::Dry) {
                Some("is saturated: leave out initially_dry")
            } else if self
                .conditions
                .iter()
                .any(|c| matches!(c, Condition::Head(..)))
            {
                Some("takes pressure and rate conditions only (a free surface is found by the transient flow)")
            } else if self.conditions.iter().any(|c| match c {
                Condition::Pressure(_, v) | Condition::Rate(_, v) | Condition::Head(_, v) => {
                    !matches!(v, TimeValue::Const(_))
                }
            }) {
                Some("needs constant conditions (a time table makes the flow transient)")
            } else {
                None
            };
            if let Some(why) = why {
                return Err(ComputeError::param("Hydro::steady_flow", "set", why));
            }
        }
        if !(self.bulk_scale > 0.0 && self.bulk_scale <= 1.0) {
            return Err(ComputeError::param(
                "bulk_modulus_scale",
                self.bulk_scale,
                "must lie in (0, 1]",
            ));
        }
        if self.gravity.iter().any(|g| !g.is_finite()) {
            return Err(ComputeError::param(
                "fluid gravity (m/s²)",
                format!("{:?}", self.gravity),
                "must be finite",
            ));
        }
        for (_, a) in &self.fractures {
            if !(*a >= 0.0 && a.is_finite()) {
                return Err(ComputeError::param(
                    "fracture initial aperture (m)",
                    a,
                    "must be non-negative and finite",
                ));
            }
        }
        if let Initial::Pressure(p) = self.initial {
            if !(p >= 0.0 && p.is_finite()) {
                return Err(ComputeError::param(
                    "initial fluid pressure (Pa)",
                    p,
                    "must be non-negative and finite",
                ));
            }
        }
        for c in &self.conditions {
            match c {
                Condition::Pressure(_, v) => {
                    v.check("pressure condition (Pa)")?;
                    if let TimeValue::Const(p) = v {
                        if *p < 0.0 {
                            return Err(ComputeError::param(
                                "pressure condition (Pa)",
                                p,
                                "must be non-negative (the fluid carries no tension)",
                            ));
                        }
                    }
                }
                Condition::Head(_, v) => {
                    v.check("free-surface condition (m)")?;
                    if self.gravity.iter().all(|&g| g == 0.0) {
                        return Err(ComputeError::param(
                            "free-surface condition",
                            "fluid gravity 0",
                            "a water level needs the fluid's gravity: set Hydro::gravity",
                        ));
                    }
                }
                Condition::Rate(_, v) => v.check("flow-rate condition (m³/s)")?,
            }
        }
        Ok(())
    }

    /// The derivation for `mesh`, made once and kept (a different mesh is derived
    /// afresh).
    fn prepared<D: Dim>(
        &self,
        mesh: &Mesh<D>,
    ) -> Result<std::borrow::Cow<'_, Derived>, ComputeError> {
        let key = mesh_key(mesh);
        if let Some((k, d)) = self.prepared.get() {
            if *k == key {
                return Ok(std::borrow::Cow::Borrowed(d));
            }
            return self.derive(mesh).map(std::borrow::Cow::Owned);
        }
        let d = self.derive(mesh)?;
        Ok(std::borrow::Cow::Borrowed(
            &self.prepared.get_or_init(|| (key, d)).1,
        ))
    }

    /// Builds the network and resolves fractures and conditions on `mesh`.
    fn derive<D: Dim>(&self, mesh: &Mesh<D>) -> Result<Derived, ComputeError> {
        self.check()?;
        let net = Network::build(mesh, self.only.as_ref(), &self.impermeable)?;
        let mut delta0 = vec![self.model.aperture.initial; net.n_channels()];
        let mut pre_existing = vec![false; net.n_channels()];
        let mut delta_ref = vec![0.0; net.n_channels()];
        let k_or_zero = self.permeability.unwrap_or(0.0);
        for (sel, a) in &self.fractures {
            let channels = match sel {
                Selection::Range(r) => net.channels_in(mesh, r)?,
                Selection::Joints(js) => {
                    let mut out = Vec::with_capacity(js.len());
                    for &j in js {
                        match net.joint.binary_search(&j) {
                            Ok(c) => out.push(c as u32),
                            Err(_) => {
                                return Err(ComputeError::param(
                                    "fracture joint",
                                    j,
                                    format!(
                                        "not a permeable joint of the mesh ({} joints)",
                                        mesh.interfaces().len()
                                    ),
                                ))
                            }
                        }
                    }
                    out
                }
            };
            if channels.is_empty() {
                return Err(ComputeError::param(
                    "fracture",
                    format!("{sel:?}"),
                    "selects no permeable joint",
                ));
            }
            for c in channels {
                delta0[c as usize] = *a;
                pre_existing[c as usize] = true;
            }
        }
        if let Some(k) = self.permeability {
            if !(k > 0.0 && k.is_finite()) {
                return Err(ComputeError::param(
                    "rock mass permeability (m²)",
                    k,
                    "must be positive and finite",
                ));
            }
            for (c, &j) in net.joint.iter().enumerate() {
                if !pre_existing[c] {
                    delta0[c] =
                        calibration::aperture(mesh, j as usize, k).max(self.model.aperture.min);
                    if D::D == 3 {
                        delta_ref[c] = self.model.aperture.hydraulic(delta0[c], 0.0);
                    }
                }
            }
        }
        let calib_weight = calibration::edge_weights(mesh, &net, &delta_ref, k_or_zero);
        let up = unit_up(self.gravity);
        let elevation: Vec<f64> = net
            .node_mesh
            .iter()
            .map(|&n| {
                let x = mesh.node(n as usize);
                (0..D::D).map(|k| up[k] * x[k]).sum::<f64>()
            })
            .collect();
        let mut fixed = vec![Network::NONE; net.n_nodes()];
        let mut fixed_values = Vec::new();
        let mut rates = Vec::new();
        let mut rate_values = Vec::new();
        for c in &self.conditions {
            match c {
                Condition::Pressure(r, v) | Condition::Head(r, v) => {
                    let head = matches!(c, Condition::Head(..));
                    let what = if head {
                        "free-surface condition"
                    } else {
                        "pressure condition"
                    };
                    let nodes = net.select(mesh, r, what)?;
                    let i = fixed_values.len() as u32;
                    fixed_values.push((head, v.clone()));
                    for f in nodes {
                        fixed[f as usize] = i;
                    }
                }
                Condition::Rate(r, v) => {
                    let nodes = net.select(mesh, r, "flow-rate condition")?;
                    let share = 1.0 / nodes.len() as f64;
                    let i = rate_values.len();
                    rate_values.push(v.clone());
                    rates.extend(nodes.into_iter().map(|f| (f, i, share)));
                }
            }
        }
        // Per node, in the order given (a counting sort keeps it).
        let mut rate_ptr = vec![0u32; net.n_nodes() + 1];
        for &(l, _, _) in &rates {
            rate_ptr[l as usize + 1] += 1;
        }
        for l in 0..net.n_nodes() {
            rate_ptr[l + 1] += rate_ptr[l];
        }
        let mut fill = rate_ptr.clone();
        let mut rate_cond = vec![0u32; rates.len()];
        let mut rate_share = vec![0.0; rates.len()];
        for &(l, i, share) in &rates {
            let at = fill[l as usize] as usize;
            rate_cond[at] = i as u32;
            rate_share[at] = share;
            fill[l as usize] += 1;
        }
        let mut channel_joint_nodes = Vec::with_capacity(net.n_channels() * 2 * net.npc);
        for &j in &net.joint {
            channel_joint_nodes.extend_from_slice(mesh.interfaces().joint_nodes(j as usize));
        }
        Ok(Derived {
            net,
            channel_joint_nodes,
            delta0,
            pre_existing,
            delta_ref,
            calib_weight,
            fixed,
            fixed_values,
            elevation,
            rate_ptr,
            rate_cond,
            rate_share,
            rate_values,
            slots: None,
        })
    }

    /// Channel geometry and node volumes from positions `kin` (the solid's current
    /// configuration, or the reference one in flow-only mode).
    fn update_geometry<D: Dim>(&mut self, kin: &Kinematics<'_, D>) {
        let d = self.derived.as_ref().expect("init ran");
        let (net, npc, dd) = (&d.net, D::NODES_PER_FACE, D::D);
        let jn = &d.channel_joint_nodes;
        let follows = self.follows_solid();
        let model = self.model.aperture;
        let g = self.gravity;
        let geom = &mut self.geom;
        let nc = net.n_channels();
        geom.measure.resize(nc, 0.0);
        geom.aperture.resize(nc, 0.0);
        geom.weight.resize(nc * 3, 0.0);
        geom.gravity_potential.resize(nc * npc, 0.0);
        geom.grad.resize(nc * npc * dd, 0.0);
        let delta0 = &d.delta0;
        geom.measure
            .par_chunks_mut(CHUNK)
            .zip(geom.aperture.par_chunks_mut(CHUNK))
            .zip(geom.weight.par_chunks_mut(CHUNK * 3))
            .zip(geom.gravity_potential.par_chunks_mut(CHUNK * npc))
            .zip(geom.grad.par_chunks_mut(CHUNK * npc * dd))
            .enumerate()
            .for_each(|(b, ((((measure, aperture), weight), gpot), grad))| {
                for i in 0..measure.len() {
                    let c = b * CHUNK + i;
                    let nodes = &jn[c * 2 * npc..(c + 1) * 2 * npc];
                    let out =
                        ChannelGeometryOut::at(i, npc, dd, measure, aperture, weight, gpot, grad);
                    let calib = (d.delta_ref[c], &d.calib_weight[c * 3..c * 3 + 3]);
                    channel_geometry(kin, nodes, follows, &model, delta0[c], calib, g, out);
                }
            });
        let inv = 1.0 / npc as f64;
        let (measure, aperture) = (&geom.measure, &geom.aperture);
        geom.node_volume.resize(net.n_nodes(), 0.0);
        geom.node_volume
            .par_chunks_mut(CHUNK)
            .enumerate()
            .for_each(|(b, vol)| {
                for (i, v) in vol.iter_mut().enumerate() {
                    let l = b * CHUNK + i;
                    let mut sum = 0.0;
                    for &e in &net.incidence[net.inc_ptr[l] as usize..net.inc_ptr[l + 1] as usize] {
                        let c = e as usize / npc;
                        sum += measure[c] * aperture[c] * inv;
                    }
                    *v = sum;
                }
            });
    }

    /// The fluid's critical step (before the safety factor): flow only, the Gershgorin
    /// bound min_l V_l / (K_f Σ_c |k w|) at the current apertures; coupled, the bound
    /// min_c 12 μ_d A_c / (N K_f Σ_j max_δ δ² |w_kj(δ)|) that holds for any aperture in
    /// [δ_min, δ_max] a channel may reach (the node ratio V/ΣC is at least its channels'
    /// smallest; δ² |w| peaks at δ_max for the cubic law, at δ_r or δ_max for calibrated
    /// weights).
    fn fluid_step(&self) -> Option<StableStep> {
        let d = self.derived.as_ref()?;
        let (net, npc, geom) = (&d.net, d.net.npc, &self.geom);
        let mu = self.model.fluid.dynamic_viscosity();
        let bulk = self.bulk_modulus();
        let edge_sum = |c: usize, k: usize| -> f64 {
            let w = &geom.weight[c * 3..c * 3 + 3];
            if npc == 2 {
                w[0].abs()
            } else {
                // Node k touches edges (k, k+1) and (k+2, k): slots k and (k + 2) % 3.
                w[k].abs() + w[(k + 2) % 3].abs()
            }
        };
        let mut best: Option<(f64, Entity)> = None;
        let mut consider = |dt: f64, e: Entity| {
            if dt.is_finite() && best.is_none_or(|(b, _)| dt < b) {
                best = Some((dt, e));
            }
        };
        if self.follows_solid() {
            let dmax = self.model.aperture.max;
            for c in 0..net.n_channels() {
                let dr = d.delta_ref[c];
                // Per edge, the largest δ² |w_eff(δ)| over [δ_min, δ_max]: δ_max² |w| for
                // the cubic law; for calibrated weights (w_eff = w + β (ŵ − w)) the larger
                // of its values at δ_r and δ_max (a δ² + b/δ, a ≥ 0, peaks at an end).
                let mut m = [0.0; 3];
                for (e, &(i, j, _)) in
                    flow::EDGES3
                        .iter()
                        .enumerate()
                        .take(if npc == 2 { 1 } else { 3 })
                {
                    // Calibrated channels are 3D only (gradient stride 3).
                    let w = if dr > 0.0 {
                        let gi = &geom.grad[(c * npc + i) * 3..(c * npc + i + 1) * 3];
                        let gj = &geom.grad[(c * npc + j) * 3..(c * npc + j + 1) * 3];
                        -geom.measure[c] * (gi[0] * gj[0] + gi[1] * gj[1] + gi[2] * gj[2])
                    } else {
                        geom.weight[c * 3 + e]
                    };
                    m[e] = dmax * dmax * w.abs();
                    if dr > 0.0 {
                        let h = d.calib_weight[c * 3 + e].abs();
                        m[e] = (dr * dr * h).max(m[e] + dr * dr * dr * (h - w.abs()) / dmax);
                    }
                }
                for k in 0..npc {
                    let s = if npc == 2 {
                        m[0]
                    } else {
                        m[k] + m[(k + 2) % 3]
                    };
                    if s > 0.0 {
                        let dt = 12.0 * mu * geom.measure[c] / (npc as f64 * bulk * s);
                        consider(dt, Entity::new(EntityKind::Other("flow channel"), c));
                    }
                }
            }
        } else {
            for l in 0..net.n_nodes() {
                let mut cond = 0.0;
                for &e in &net.incidence[net.inc_ptr[l] as usize..net.inc_ptr[l + 1] as usize] {
                    let (c, k) = (e as usize / npc, e as usize % npc);
                    let delta = geom.aperture[c];
                    cond += delta * delta * delta / (12.0 * mu) * edge_sum(c, k);
                }
                if cond > 0.0 {
                    consider(
                        geom.node_volume[l] / (bulk * cond),
                        Entity::new(EntityKind::Other("flow node"), l),
                    );
                }
            }
        }
        best.map(|(dt, entity)| StableStep {
            dt,
            entity,
            physics: "hydro".into(),
        })
    }

    /// The mechanical step the fluid's stiffness allows (two-way only): a solid node on
    /// the faces of channels c at flow node l feels k = K_f (Σ_c A_c/N) (Σ_c A_c/N²) /
    /// V_l,min (V_l at δ_min: the closed channel, about K_f/δ per unit face area), and
    /// is stable for Δt ≤ 2 sqrt(m / 2k) (the two faces of a channel move against each
    /// other).
    fn stiffness_step<D: Dim>(&self, kin: &Kinematics<'_, D>) -> Option<StableStep> {
        let d = self.derived.as_ref()?;
        let (net, npc, geom) = (&d.net, d.net.npc, &self.geom);
        let joints = kin.mesh.interfaces();
        let bulk = self.bulk_modulus();
        let dmin = self.model.aperture.min;
        let n = npc as f64;
        // V_l at δ_min.
        let mut vmin = vec![0.0; net.n_nodes()];
        for c in 0..net.n_channels() {
            for k in 0..npc {
                vmin[net.channel_nodes[c * npc + k] as usize] += geom.measure[c] * dmin / n;
            }
        }
        // Per solid node: Σ A_c / N over the channels whose faces it lies on.
        let mut area = vec![0.0; kin.mesh.n_nodes()];
        for c in 0..net.n_channels() {
            let nodes = joints.joint_nodes(net.joint[c] as usize);
            for &s in nodes {
                area[s as usize] += geom.measure[c] / n;
            }
        }
        let mut best: Option<(f64, usize)> = None;
        for (s, &a) in area.iter().enumerate() {
            let l = net.mesh_flow[s];
            if a <= 0.0 || l == Network::NONE {
                continue;
            }
            let k = bulk * a * (a / n) / vmin[l as usize];
            let dt = 2.0 * (kin.mass[s] / (2.0 * k)).sqrt();
            if best.is_none_or(|(b, _)| dt < b) {
                best = Some((dt, l as usize));
            }
        }
        best.map(|(dt, l)| StableStep {
            dt,
            entity: Entity::new(EntityKind::Other("flow node (fluid stiffness)"), l),
            physics: "hydro".into(),
        })
    }
}

/// What identifies the mesh a derivation was made for.
fn mesh_key<D: Dim>(mesh: &Mesh<D>) -> (usize, usize, usize) {
    (mesh.n_nodes(), mesh.n_elements(), mesh.interfaces().len())
}

/// The unit vector along −g (up), or zero without gravity.
fn unit_up(g: [f64; 3]) -> [f64; 3] {
    let n = (g[0] * g[0] + g[1] * g[1] + g[2] * g[2]).sqrt();
    if n > 0.0 {
        [-g[0] / n, -g[1] / n, -g[2] / n]
    } else {
        [0.0; 3]
    }
}

/// Every mesh node's pore pressure from its flow node (0 off the network), in parallel.
fn copy_pore(mesh_flow: &[u32], p: &[f64], pore: &mut [f64]) {
    pore.par_chunks_mut(4 * CHUNK)
        .zip(mesh_flow.par_chunks(4 * CHUNK))
        .for_each(|(pore, flow)| {
            for (x, &f) in pore.iter_mut().zip(flow) {
                *x = if f == Network::NONE {
                    0.0
                } else {
                    p[f as usize]
                };
            }
        });
}

/// Where [`channel_geometry`] writes one channel's geometry.
struct ChannelGeometryOut<'a> {
    measure: &'a mut f64,
    aperture: &'a mut f64,
    weight: &'a mut [f64],
    gpot: &'a mut [f64],
    grad: &'a mut [f64],
}

impl<'a> ChannelGeometryOut<'a> {
    /// Channel `i` of chunks of the geometry arrays (`npc` nodes, dimension `dd`).
    #[allow(clippy::too_many_arguments)]
    #[inline]
    fn at(
        i: usize,
        npc: usize,
        dd: usize,
        measure: &'a mut [f64],
        aperture: &'a mut [f64],
        weight: &'a mut [f64],
        gpot: &'a mut [f64],
        grad: &'a mut [f64],
    ) -> Self {
        ChannelGeometryOut {
            measure: &mut measure[i],
            aperture: &mut aperture[i],
            weight: &mut weight[i * 3..i * 3 + 3],
            gpot: &mut gpot[i * npc..(i + 1) * npc],
            grad: &mut grad[i * npc * dd..(i + 1) * npc * dd],
        }
    }
}

/// One channel's geometry from the positions of its joint's `nodes` (side A, then side
/// B): measure, aperture (eq. 79), edge weights, gravity potential and gradients. The
/// one arithmetic of the geometry pass and of the fused channel pass.
#[allow(clippy::too_many_arguments)]
#[inline]
fn channel_geometry<D: Dim>(
    kin: &Kinematics<'_, D>,
    nodes: &[u32],
    follows: bool,
    model: &crate::model::Aperture,
    delta0: f64,
    calib: (f64, &[f64]),
    g: [f64; 3],
    out: ChannelGeometryOut<'_>,
) {
    // Compile-time sizes, so that the per-node loops unroll.
    let (dd, npc) = (D::D, D::NODES_PER_FACE);
    let mut mid = [[0.0; 3]; 3];
    let mut gap = [[0.0; 3]; 3];
    for k in 0..npc {
        let (xa, xb) = if follows {
            (
                kin.position(nodes[k] as usize),
                kin.position(nodes[npc + k] as usize),
            )
        } else {
            let mut xa = [0.0; 3];
            let mut xb = [0.0; 3];
            xa[..dd].copy_from_slice(kin.mesh.node(nodes[k] as usize));
            xb[..dd].copy_from_slice(kin.mesh.node(nodes[npc + k] as usize));
            (xa, xb)
        };
        for q in 0..3 {
            mid[k][q] = 0.5 * (xa[q] + xb[q]);
            gap[k][q] = xb[q] - xa[q];
        }
        out.gpot[k] = g[0] * mid[k][0] + g[1] * mid[k][1] + g[2] * mid[k][2];
    }
    let sh = flow::channel_shape(npc, &mid, &gap);
    *out.measure = sh.measure;
    *out.aperture = flow::aperture_of(model, delta0, sh.opening, follows);
    out.weight.copy_from_slice(&sh.weight);
    calibration::blend(out.weight, calib.1, calib.0, *out.aperture);
    for k in 0..npc {
        out.grad[k * dd..(k + 1) * dd].copy_from_slice(&sh.grad[k][..dd]);
    }
}

impl<D: Dim> Physics<D> for Hydro {
    fn name(&self) -> &str {
        "hydro"
    }

    fn entity_sets(&self, mesh: &Mesh<D>) -> Vec<EntitySet> {
        // Errors surface in init (the same derivation); an invalid network gives no sets
        // here, and init reports why.
        let Ok(d) = self.prepared(mesh) else {
            return Vec::new();
        };
        let joints = mesh.interfaces();
        let npc = d.net.npc;
        let mut channel_nodes = Vec::with_capacity(d.net.n_channels() * npc);
        for &j in &d.net.joint {
            channel_nodes.extend_from_slice(&joints.joint_nodes(j as usize)[..npc]);
        }
        [
            EntitySet::new(FLOW_NODES, 1, d.net.node_mesh.clone()),
            EntitySet::new(FLOW_CHANNELS, npc, channel_nodes),
        ]
        .into_iter()
        .filter_map(Result::ok)
        .collect()
    }

    fn fields(&self, mesh: &Mesh<D>) -> Vec<FieldUse> {
        // Without a valid network there are no sets to put the fields on: declare none,
        // and let init report why.
        if self.prepared(mesh).is_err() {
            return Vec::new();
        }
        let mut f = vec![
            FLOW_STORED.own::<D>(),
            FLOW_PRESSURE.own::<D>(),
            FLOW_PEAK_PRESSURE.own::<D>(),
            FLOW_SATURATION.own::<D>().initial(1.0),
            FLOW_BALANCE.own::<D>(),
            CHANNEL_APERTURE.own::<D>(),
            CHANNEL_FLUX.own::<D>(),
            CHANNEL_LEAK_AGE.own::<D>().initial(-1.0),
            PORE_PRESSURE.own::<D>(),
        ];
        if self.reads_damage() {
            f.push(JOINT_DAMAGE.read::<D>());
        }
        f
    }

    fn init(&mut self, ctx: &mut InitContext<'_, D>) -> Result<(), ComputeError> {
        let key = mesh_key(ctx.mesh);
        let mut derived = match self.prepared.take() {
            Some((k, d)) if k == key => d,
            _ => self.derive(ctx.mesh)?,
        };
        let fields = &mut *ctx.fields;
        let ids = Ids {
            content: fields.id(FLOW_STORED)?,
            pressure: fields.id(FLOW_PRESSURE)?,
            peak: fields.id(FLOW_PEAK_PRESSURE)?,
            saturation: fields.id(FLOW_SATURATION)?,
            balance: fields.id(FLOW_BALANCE)?,
            aperture: fields.id(CHANNEL_APERTURE)?,
            flux: fields.id(CHANNEL_FLUX)?,
            leak_age: fields.id(CHANNEL_LEAK_AGE)?,
            pore: fields.id(PORE_PRESSURE)?,
            damage: if self.reads_damage() {
                Some(fields.id(JOINT_DAMAGE)?)
            } else {
                None
            },
        };
        if self.coupling == Coupling::TwoWay {
            let joints = ctx.mesh.interfaces();
            let mut nodes = Vec::with_capacity(derived.net.n_channels() * 2 * derived.net.npc);
            for &j in &derived.net.joint {
                nodes.extend_from_slice(joints.joint_nodes(j as usize));
            }
            derived.slots = Some(ctx.register_slots(&nodes)?);
        }
        let nc = derived.net.n_channels();
        let npc = derived.net.npc;
        // Pre-existing fractures leak from the start.
        if self.model.leak_off.is_some() {
            let age = ctx.fields.get_mut(ids.leak_age);
            for (c, &pre) in derived.pre_existing.iter().enumerate() {
                if pre {
                    age[c] = 0.0;
                }
            }
        }
        self.derived = Some(derived);
        self.ids = Some(ids);
        self.share = vec![0.0; nc * npc];
        self.leak = vec![0.0; nc];
        // The initial geometry (reference configuration, u = 0) and state.
        let coords = ctx.mesh.coords().to_vec();
        let zeros = vec![0.0; coords.len()];
        let mass = vec![1.0; ctx.mesh.n_nodes()];
        let kin = Kinematics {
            mesh: ctx.mesh,
            coords: &coords,
            mass: &mass,
            u: &zeros,
            v: &zeros,
            time: 0.0,
            dt: 0.0,
            step: 0,
            damping: false,
        };
        self.update_geometry(&kin);
        ctx.fields
            .get_mut(ids.aperture)
            .copy_from_slice(&self.geom.aperture);
        let d = self.derived.as_ref().expect("set above");
        let bulk = self.bulk_modulus();
        let nf = d.net.n_nodes();
        let mut p0 = vec![0.0; nf];
        let mut s0 = vec![1.0; nf];
        for l in 0..nf {
            match &self.initial {
                Initial::Pressure(p) => p0[l] = *p,
                Initial::Dry => s0[l] = 0.0,
                Initial::Function(f) => {
                    let x = ctx.mesh.node(d.net.node_mesh[l] as usize);
                    let p = f(x);
                    if !(p >= 0.0 && p.is_finite()) {
                        return Err(ComputeError::param(
                            format!("initial fluid pressure at flow node {l} ({x:?})"),
                            p,
                            "must be non-negative and finite",
                        ));
                    }
                    p0[l] = p;
                }
            }
        }
        if self.steady {
            let fixed: Vec<f64> = d.fixed_values.iter().map(|(_, v)| v.at(0.0)).collect();
            let rates: Vec<f64> = d.rate_values.iter().map(|v| v.at(0.0)).collect();
            let inputs = steady::Inputs {
                fixed_of: &d.fixed,
                fixed: &fixed,
                rate_ptr: &d.rate_ptr,
                rate_cond: &d.rate_cond,
                rate_share: &d.rate_share,
                rates: &rates,
                rho: self.model.fluid.density,
                mu: self.model.fluid.dynamic_viscosity(),
            };
            p0 = steady::pressures(&d.net, &self.geom, &inputs)?;
            let q = steady::fluxes(&d.net, &self.geom, &p0, D::D, inputs.rho, inputs.mu);
            ctx.fields.get_mut(ids.flux).copy_from_slice(&q);
        }
        let vol = &self.geom.node_volume;
        let content: Vec<f64> = (0..nf)
            .map(|l| {
                if s0[l] == 0.0 {
                    0.0
                } else {
                    flow::content_at(p0[l], vol[l], bulk)
                }
            })
            .collect();
        let [p, s, bal] = ctx
            .fields
            .get_many_mut([ids.pressure, ids.saturation, ids.balance]);
        p.copy_from_slice(&p0);
        s.copy_from_slice(&s0);
        for l in 0..nf {
            bal[l * 4] = content[l];
        }
        ctx.fields.get_mut(ids.peak).copy_from_slice(&p0);
        let pore = ctx.fields.get_mut(ids.pore);
        for (n, &f) in d.net.mesh_flow.iter().enumerate() {
            pore[n] = if f == Network::NONE {
                0.0
            } else {
                p0[f as usize]
            };
        }
        Ok(())
    }

    fn add_mass(
        &self,
        mesh: &Mesh<D>,
        _fields: &FieldStore,
        mass: &mut [f64],
        _scale_to_dt: Option<f64>,
    ) {
        if self.coupling == Coupling::FlowOnly {
            for m in &mut mass[..mesh.n_nodes()] {
                *m += 1.0;
            }
        }
    }

    fn stable_step(&self, kin: &Kinematics<'_, D>, _fields: &FieldStore) -> Option<StableStep> {
        if self.steady {
            return None; // solved once, never stepped
        }
        match self.coupling {
            Coupling::FlowOnly => self.fluid_step(),
            Coupling::OneWay => None,
            Coupling::TwoWay => self.stiffness_step(kin),
        }
    }

    fn field_schedule(&self) -> Option<FieldSchedule> {
        (!self.steady).then_some(self.schedule)
    }

    fn field_stable_step(&self, _kin: &Kinematics<'_, D>, _f: &FieldStore) -> Option<StableStep> {
        if self.steady {
            return None;
        }
        self.fluid_step()
    }

    fn kinematic_nodes(&self) -> KinematicNodes {
        KinematicNodes::None
    }

    fn writes_all_slots(&self) -> bool {
        true
    }

    fn applies_loads(&self) -> bool {
        true
    }

    fn slot_entity(&self, slot: usize) -> Option<String> {
        let d = self.derived.as_ref()?;
        let c = slot / (2 * d.net.npc);
        Some(format!("flow channel {c} (joint {})", d.net.joint.get(c)?))
    }

    fn compute_forces(&mut self, ctx: &mut ForceContext<'_, D>) -> Result<(), ComputeError> {
        let ids = self.ids.expect("init ran");
        let d = self.derived.as_ref().expect("init ran");
        let (net, npc, dd) = (&d.net, D::NODES_PER_FACE, D::D);
        // The pore pressure is copied after each fluid step (it changes only there).
        if self.coupling != Coupling::TwoWay {
            return Ok(());
        }
        let p = ctx.fields.get(ids.pressure);
        let kin = &ctx.kin;
        let jn = &d.channel_joint_nodes;
        let stride = 2 * npc * dd;
        ctx.slots
            .par_chunks_mut(CHUNK * stride)
            .enumerate()
            .for_each(|(b, slots)| {
                for i in 0..slots.len() / stride {
                    let c = b * CHUNK + i;
                    let nodes = &jn[c * 2 * npc..(c + 1) * 2 * npc];
                    let mut mid = [[0.0; 3]; 3];
                    for k in 0..npc {
                        let (xa, xb) = (
                            kin.position(nodes[k] as usize),
                            kin.position(nodes[npc + k] as usize),
                        );
                        for q in 0..3 {
                            mid[k][q] = 0.5 * (xa[q] + xb[q]);
                        }
                    }
                    // A n (area times unit normal, side A to side B) without the
                    // square root: the rotated segment in 2D, half the cross product
                    // in 3D (zero on a degenerate channel, as the unit normal is).
                    let an = flow::area_normal(npc, &mid);
                    let pk: [f64; 3] = std::array::from_fn(|k| {
                        if k < npc {
                            p[net.channel_nodes[c * npc + k] as usize]
                        } else {
                            0.0
                        }
                    });
                    let out = &mut slots[i * stride..(i + 1) * stride];
                    for k in 0..npc {
                        // Consistent integration of the linear pressure over the face:
                        // ∫ N_k p dA = A (p_k + Σ p)/6 (2D) or /12 (3D).
                        let f = if npc == 2 {
                            (2.0 * pk[k] + pk[1 - k]) / 6.0
                        } else {
                            (pk[k] + pk[0] + pk[1] + pk[2]) / 12.0
                        };
                        for q in 0..dd {
                            // Side A pushed against the normal (A to B), side B along it.
                            out[k * dd + q] = -f * an[q];
                            out[(npc + k) * dd + q] = f * an[q];
                        }
                    }
                }
            });
        Ok(())
    }

    fn field_step(&mut self, ctx: &mut FieldContext<'_, D>) -> Result<(), ComputeError> {
        let ids = self.ids.expect("init ran");
        // The geometry follows the solid: rebuilt from the new positions in the channel
        // pass (and the node volumes in the node pass) of the first fluid step after a
        // mechanical one.
        let fresh = ctx.substep == 0 && self.follows_solid();
        let dt = ctx.dt;
        let bulk = self.bulk_modulus();
        let mu = self.model.fluid.dynamic_viscosity();
        let rho = self.model.fluid.density;
        let d = self.derived.as_ref().expect("init ran");
        let (net, npc) = (&d.net, D::NODES_PER_FACE);
        // Channels: the volume each node gains over the step, and leak-off.
        {
            let keys = [ids.pressure, ids.saturation, ids.leak_age, ids.flux];
            let (p, s, leak_age, flux, damage) = match ids.damage {
                Some(did) => {
                    let [p, s, a, f, dmg] = ctx
                        .fields
                        .get_many_mut([keys[0], keys[1], keys[2], keys[3], did]);
                    (p, s, a, f, Some(&*dmg))
                }
                None => {
                    let [p, s, a, f] = ctx.fields.get_many_mut(keys);
                    (p, s, a, f, None)
                }
            };
            let (p, s) = (&*p, &*s);
            let dd = D::D;
            let leak_model = self.model.leak_off;
            let inv = 1.0 / npc as f64;
            let (aperture_model, g, kin) = (self.model.aperture, self.gravity, &ctx.kin);
            let (jn, delta0) = (&d.channel_joint_nodes, &d.delta0);
            let geom = &mut self.geom;
            self.share
                .par_chunks_mut(CHUNK * npc)
                .zip(self.leak.par_chunks_mut(CHUNK))
                .zip(flux.par_chunks_mut(CHUNK * dd))
                .zip(leak_age.par_chunks_mut(CHUNK))
                .zip(geom.measure.par_chunks_mut(CHUNK))
                .zip(geom.aperture.par_chunks_mut(CHUNK))
                .zip(geom.weight.par_chunks_mut(CHUNK * 3))
                .zip(geom.gravity_potential.par_chunks_mut(CHUNK * npc))
                .zip(geom.grad.par_chunks_mut(CHUNK * npc * dd))
                .enumerate()
                .for_each(
                    |(
                        b,
                        (
                            (((((((share, leak), flux), age), measure), aperture), weight), gpot),
                            grad,
                        ),
                    )| {
                        for i in 0..leak.len() {
                            let c = b * CHUNK + i;
                            if fresh {
                                let out = ChannelGeometryOut::at(
                                    i, npc, dd, measure, aperture, weight, gpot, grad,
                                );
                                let nodes = &jn[c * 2 * npc..(c + 1) * 2 * npc];
                                channel_geometry(
                                    kin,
                                    nodes,
                                    true,
                                    &aperture_model,
                                    delta0[c],
                                    (d.delta_ref[c], &d.calib_weight[c * 3..c * 3 + 3]),
                                    g,
                                    out,
                                );
                            }
                            // Leak-off starts where a joint has broken since the last step.
                            if let Some(damage) = damage {
                                if age[i] < 0.0 && damage[net.joint[c] as usize] >= 1.0 {
                                    age[i] = 0.0;
                                }
                            }
                            let fnodes = &net.channel_nodes[c * npc..(c + 1) * npc];
                            let (mut psi, mut fw) = ([0.0; 3], [0.0; 3]);
                            let (mut s_mean, mut p_mean) = (0.0, 0.0);
                            for k in 0..npc {
                                let l = fnodes[k] as usize;
                                psi[k] = p[l] - rho * gpot[i * npc + k];
                                fw[k] = saturation_weight(s[l]);
                                s_mean += s[l];
                                p_mean += p[l];
                            }
                            s_mean *= inv;
                            p_mean *= inv;
                            let k = flow::conductivity(aperture[i], s_mean, mu);
                            let w: &[f64; 3] =
                                weight[i * 3..i * 3 + 3].try_into().expect("3 weights");
                            let kdt = flow::conductivity(aperture[i], 1.0, mu) * dt;
                            let sh = flow::channel_shares(npc, kdt, w, &psi, &fw);
                            let mut g3 = [[0.0; 3]; 3];
                            for j in 0..npc {
                                g3[j][..dd].copy_from_slice(
                                    &grad[(i * npc + j) * dd..(i * npc + j + 1) * dd],
                                );
                            }
                            let q = flow::channel_flux(npc, k, &g3, &psi);
                            flux[i * dd..(i + 1) * dd].copy_from_slice(&q[..dd]);
                            share[i * npc..(i + 1) * npc].copy_from_slice(&sh[..npc]);
                            leak[i] = match &leak_model {
                                Some(lm) => flow::leak_per_node(
                                    lm, npc, measure[i], p_mean, s_mean, bulk, mu, age[i], dt,
                                ),
                                None => 0.0,
                            };
                            if age[i] >= 0.0 {
                                age[i] += dt;
                            }
                        }
                    },
                );
        }
        if fresh {
            ctx.fields
                .get_mut(ids.aperture)
                .copy_from_slice(&self.geom.aperture);
        }
        // Flow nodes: content, conditions, pressure and saturation. Conditions take their
        // value at the end of the mechanical step (every sub-step of it alike, as the GPU
        // reads them once per step).
        let t_end = ctx.kin.time;
        // The conditions' values now, in a buffer kept between steps.
        let mut values = std::mem::take(&mut self.values);
        values.clear();
        values.extend(d.fixed_values.iter().map(|(_, v)| v.at(t_end)));
        let (fixed_now, rate_now) = {
            values.extend(d.rate_values.iter().map(|v| v.at(t_end)));
            values.split_at(d.fixed_values.len())
        };
        let g_abs = self.gravity.iter().map(|g| g * g).sum::<f64>().sqrt();
        let [w, p, peak, s, bal] = ctx.fields.get_many_mut([
            ids.content,
            ids.pressure,
            ids.peak,
            ids.saturation,
            ids.balance,
        ]);
        let (share, leak) = (&self.share, &self.leak);
        let geom = &mut self.geom;
        let (measure, aperture) = (&geom.measure, &geom.aperture);
        let inv = 1.0 / npc as f64;
        w.par_chunks_mut(CHUNK)
            .zip(p.par_chunks_mut(CHUNK))
            .zip(peak.par_chunks_mut(CHUNK))
            .zip(s.par_chunks_mut(CHUNK))
            .zip(bal.par_chunks_mut(CHUNK * 4))
            .zip(geom.node_volume.par_chunks_mut(CHUNK))
            .enumerate()
            .for_each(|(b, (((((w, p), peak), s), bal), vol))| {
                for i in 0..w.len() {
                    let l = b * CHUNK + i;
                    let (mut gain, mut lost, mut volume) = (0.0, 0.0, 0.0);
                    for &e in &net.incidence[net.inc_ptr[l] as usize..net.inc_ptr[l + 1] as usize] {
                        gain += share[e as usize];
                        lost += leak[e as usize / npc];
                        if fresh {
                            let c = e as usize / npc;
                            volume += measure[c] * aperture[c] * inv;
                        }
                    }
                    if fresh {
                        vol[i] = volume;
                    }
                    // The change since the start, so that the balance sums changes, not
                    // contents (no cancellation against the stored volume).
                    let mut inject = 0.0;
                    for r in d.rate_ptr[l] as usize..d.rate_ptr[l + 1] as usize {
                        inject += rate_now[d.rate_cond[r] as usize] * d.rate_share[r] * dt;
                    }
                    let trial = w[i] + gain - lost + inject;
                    bal[i * 4 + 1] += inject;
                    bal[i * 4 + 3] += lost;
                    let (v, w0) = (vol[i], bal[i * 4]);
                    let mut next = trial;
                    let f = d.fixed[l];
                    if f != Network::NONE {
                        let (head, _) = d.fixed_values[f as usize];
                        let held = if head {
                            let p_h = rho * g_abs * (fixed_now[f as usize] - d.elevation[l]);
                            // Above the water level, a seepage face: the fluid may leave
                            // at atmospheric pressure, none enters.
                            if p_h > 0.0 {
                                Some(p_h)
                            } else if w0 + trial > v {
                                Some(0.0)
                            } else {
                                None
                            }
                        } else {
                            Some(fixed_now[f as usize].max(0.0))
                        };
                        if let Some(ph) = held {
                            next = flow::content_at(ph, v, bulk) - w0;
                            bal[i * 4 + 2] += next - trial;
                        }
                    }
                    w[i] = next;
                    let (pn, sn) = flow::state_of(w0 + next, v, bulk);
                    p[i] = pn;
                    peak[i] = peak[i].max(pn);
                    s[i] = sn;
                }
            });
        self.values = values;
        if let Some(l) = p.iter().position(|x| !x.is_finite()) {
            let x = ctx.kin.mesh.node(net.node_mesh[l] as usize);
            return Err(ComputeError::Diverged {
                step: ctx.kin.step,
                time: t_end,
                what: format!("fluid pressure {}", p[l]),
                entity: format!("flow node {l} at {x:?}"),
                hint: "the fluid step is above the stable one (a fixed schedule too coarse?) or an aperture beyond a-max".into(),
            });
        }
        let [p, pore] = ctx.fields.get_many_mut([ids.pressure, ids.pore]);
        copy_pore(&net.mesh_flow, p, pore);
        Ok(())
    }

    fn gpu_setup(
        &mut self,
        setup: &mut pcdc_compute::gpu::GpuSetup<'_, D>,
    ) -> Result<(), ComputeError> {
        if self.steady {
            return Ok(()); // the solved fields are uploaded with the others; no kernel
        }
        self.gpu_program(setup)
    }

    fn fingerprint(&self) -> u64 {
        let mut fp = Fingerprint::new()
            .debug(&self.model)
            .debug(&self.coupling)
            .debug(&self.gravity)
            .f64(self.bulk_scale)
            .debug(&self.conditions)
            .debug(&self.schedule)
            .debug(&self.steady);
        if let Some(d) = &self.derived {
            fp = fp
                .u32s(&d.net.joint)
                .u32s(&d.net.channel_nodes)
                .debug(&d.delta0)
                .debug(&d.delta_ref)
                .debug(&d.calib_weight);
        }
        fp.finish()
    }
}
