//! The thermal physics: [`Thermal`], its builder and its stages.

use std::sync::Arc;

use pcdc_compute::gpu::GpuSetup;
use pcdc_compute::names::{JOINT_DAMAGE, JOINT_OPENING, JOINT_SLIDING, TEMPERATURE};
use pcdc_compute::{
    ComputeError, Entity, EntityKind, FieldContext, FieldId, FieldSchedule, FieldStore, FieldUse,
    ForceContext, InitContext, KinematicNodes, Kinematics, Physics, StableStep, TimeValue,
};
use pcdc_mesh::{Dim, Mesh, Range};
use rayon::prelude::*;

use crate::boundary::{self, FaceHeat, NodeEntries};
use crate::conduction::{self, Geometry};
use crate::contact;
use crate::fields::{
    FLUID_HEAT_BALANCE, FLUID_HEAT_CAPACITY, FLUID_TEMPERATURE, HEAT_CAPACITY, HEAT_FLUX,
    HEAT_SUPPLIED,
};
use crate::fluid::{self, FluidHeat};
use crate::HeatMaterial;
use pcdc_compute::names::{
    CHANNEL_APERTURE, CHANNEL_FLUX, FLOW_CHANNELS, FLOW_NODES, FLOW_SATURATION,
};

/// Elements (or nodes) per parallel block.
const CHUNK: usize = 2048;
/// No temperature condition on a node.
pub(crate) const FREE: u32 = u32::MAX;

/// How heat crosses the joints of a split (FDEM) mesh.
///
/// \[NOT IN MANUAL: the manual conducts through contact only (eq. 111–112) and is
/// silent on intact joints.\] An intact joint is rock that has not cracked, so by default
/// it conducts as the rock does: the split copies of a vertex joined by intact joints
/// form one thermal node (their rates and capacities are summed, they share one
/// temperature), exactly the conduction of the unsplit mesh, with no interface
/// conductance to choose and no smaller stable step. A broken joint insulates, so cracks
/// act as the thermal barriers they are, unless its faces still touch and a contact
/// conductance is given ([`Thermal::contact_conductance`], eq. 111–112).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum JointHeat {
    /// Intact joints conduct, broken ones (damage 1, `names::JOINT_DAMAGE`, owned by
    /// the cohesive joints, which must then be composed) insulate. The default.
    #[default]
    FollowDamage,
    /// Every joint conducts, broken or not (the damage is not read).
    Conducting,
    /// No joint conducts: every element is thermally isolated from its neighbours.
    Insulating,
}

/// A user function of position, for the initial temperature.
type PointFn = Arc<dyn Fn(&[f64]) -> f64 + Send + Sync>;

#[derive(Clone)]
enum Initial {
    Uniform(f64),
    Function(PointFn),
    Nodes(Arc<Vec<f64>>),
}

/// Heat conduction in the solid with boundary heat (manual 7.6.1–7.6.2, 7.6.8); see the
/// crate documentation for the equations.
///
/// ```
/// use pcdc_compute::{names, Backend, Simulation};
/// use pcdc_mesh::{builders, Range};
/// use pcdc_thermal::{HeatMaterial, Thermal};
///
/// # fn main() -> Result<(), Box<dyn std::error::Error>> {
/// let mesh = builders::rectangle(0.0, 0.0, 1.0, 0.1, 0.05)?;
/// let granite = HeatMaterial::new(3.0, 800.0, 2700.0)?; // k, C_s, ρ
/// let heat = Thermal::new()
///     .material(Range::All, granite)
///     .initial_temperature(20.0)
///     .temperature(Range::group("left"), 100.0)
///     .heat_only(); // no mechanics: one thermal step per step
/// let mut sim = Simulation::builder(mesh, Backend::cpu(1)?).physics(heat).build()?;
/// sim.run(100)?;
/// let t = sim.field(names::TEMPERATURE)?;
/// assert!(t.iter().all(|&t| (20.0..=100.0).contains(&t)));
/// # Ok(())
/// # }
/// ```
#[derive(Clone)]
pub struct Thermal {
    materials: Vec<(Range, HeatMaterial)>,
    initial: Initial,
    fixed: Vec<(Range, TimeValue)>,
    faces: Vec<(Range, FaceHeat)>,
    joints: JointHeat,
    schedule: FieldSchedule,
    heat_only: bool,
    fluid: Option<FluidHeat>,
    fluid_fixed: Vec<(Range, TimeValue)>,
    fluid_initial: Option<f64>,
    contact: Option<f64>,
    derived: Option<Derived>,
}

impl Default for Thermal {
    fn default() -> Self {
        Self::new()
    }
}

/// What init derives from the mesh (read by the GPU program, `crate::gpu`).
#[derive(Clone, Default)]
pub(crate) struct Derived {
    pub(crate) geo: Geometry,
    /// Material index of each element.
    pub(crate) material: Vec<u32>,
    /// k_ij of each material.
    pub(crate) k: Vec<[[f64; 3]; 3]>,
    /// Lumped heat capacity C_l of each node (J/K; J/(m·K) in 2D).
    pub(crate) capacity: Vec<f64>,
    /// Node → element-rate slots (e · N_e + a), ascending.
    pub(crate) slot_start: Vec<u32>,
    pub(crate) slots: Vec<u32>,
    pub(crate) entries: NodeEntries,
    /// Temperature condition of each node, or [`FREE`].
    pub(crate) fixed_of: Vec<u32>,
    pub(crate) groups: Groups,
    /// Joints that no longer conduct (broken, with [`JointHeat::FollowDamage`]).
    pub(crate) broken: Vec<bool>,
    pub(crate) stable: Option<StableStep>,
    /// Gershgorin row sums Σ_b |K_lb| of each node (convection included), W/K.
    rows: Vec<f64>,
    pub(crate) ids: Option<Ids>,
    pub(crate) fluid: Option<FluidState>,
    /// Joint node pairs for the contact conductance (eq. 111–112).
    pub(crate) contact: Option<contact::Pairs>,
    // Work arrays.
    pub(crate) rates: Vec<f64>,
    pub(crate) node_rate: Vec<f64>,
    pub(crate) node_bnd: Vec<f64>,
    pub(crate) group_temp: Vec<[f64; 2]>,
}

/// The fluid heat's network, field ids and work arrays.
#[derive(Clone)]
pub(crate) struct FluidState {
    pub(crate) net: fluid::Net,
    ids: FluidIds,
    slots: Vec<fluid::Slot>,
    /// The fluid temperatures after the fluid update of the current step.
    t_new: Vec<f64>,
    scratch: Vec<f64>,
}

#[derive(Clone, Copy)]
struct FluidIds {
    temp: FieldId,
    capacity: FieldId,
    balance: FieldId,
    saturation: FieldId,
    aperture: FieldId,
    flux: FieldId,
}

#[derive(Clone, Copy)]
pub(crate) struct Ids {
    temp: FieldId,
    flux: FieldId,
    supplied: FieldId,
    capacity: FieldId,
    damage: Option<FieldId>,
    /// Opening and sliding of the joints, with a contact conductance.
    touch: Option<(FieldId, FieldId)>,
}

/// Thermal nodes: the mesh nodes joined through conducting joints (CSR, members
/// ascending, groups ordered by their first member).
#[derive(Clone, Debug, Default)]
pub(crate) struct Groups {
    pub(crate) of: Vec<u32>,
    pub(crate) start: Vec<u32>,
    pub(crate) members: Vec<u32>,
}

impl Groups {
    /// The groups of `n` nodes joined by the node pairs of the conducting joints.
    pub(crate) fn build<D: Dim>(mesh: &Mesh<D>, conducts: impl Fn(usize) -> bool) -> Self {
        let n = mesh.n_nodes();
        let mut parent: Vec<u32> = (0..n as u32).collect();
        fn find(p: &mut [u32], mut x: u32) -> u32 {
            while p[x as usize] != x {
                p[x as usize] = p[p[x as usize] as usize];
                x = p[x as usize];
            }
            x
        }
        let joints = mesh.interfaces();
        for j in 0..joints.len() {
            if !conducts(j) {
                continue;
            }
            let Some(iface) = joints.get(j) else { continue };
            for (a, b) in iface.node_pairs() {
                let (ra, rb) = (find(&mut parent, a), find(&mut parent, b));
                // The smaller root wins: groups are named by their first member.
                let (lo, hi) = if ra < rb { (ra, rb) } else { (rb, ra) };
                parent[hi as usize] = lo;
            }
        }
        let mut of = vec![0u32; n];
        let mut index_of_root = vec![u32::MAX; n];
        let mut count = Vec::new();
        for v in 0..n as u32 {
            let r = find(&mut parent, v);
            if index_of_root[r as usize] == u32::MAX {
                index_of_root[r as usize] = count.len() as u32;
                count.push(0u32);
            }
            let g = index_of_root[r as usize];
            of[v as usize] = g;
            count[g as usize] += 1;
        }
        let mut start = Vec::with_capacity(count.len() + 1);
        start.push(0u32);
        for c in &count {
            start.push(start.last().copied().unwrap_or(0) + c);
        }
        let mut fill: Vec<u32> = start[..count.len()].to_vec();
        let mut members = vec![0u32; n];
        for v in 0..n {
            let g = of[v] as usize;
            members[fill[g] as usize] = v as u32;
            fill[g] += 1;
        }
        Groups { of, start, members }
    }

    pub(crate) fn len(&self) -> usize {
        self.start.len() - 1
    }
}

impl Thermal {
    /// No materials, initial temperature 0, no conditions (adiabatic boundary), joints
    /// [`JointHeat::FollowDamage`], schedule [`FieldSchedule::Auto`].
    pub fn new() -> Self {
        Thermal {
            materials: Vec::new(),
            initial: Initial::Uniform(0.0),
            fixed: Vec::new(),
            faces: Vec::new(),
            joints: JointHeat::default(),
            schedule: FieldSchedule::Auto,
            heat_only: false,
            fluid: None,
            fluid_fixed: Vec::new(),
            fluid_initial: None,
            contact: None,
            derived: None,
        }
    }

    /// Assigns a material to the elements in `range` (later assignments win). Every
    /// element needs one.
    pub fn material(mut self, range: Range, material: HeatMaterial) -> Self {
        self.materials.push((range, material));
        self
    }

    /// Uniform initial temperature (K or °C).
    pub fn initial_temperature(mut self, t: f64) -> Self {
        self.initial = Initial::Uniform(t);
        self
    }

    /// Initial temperature as a function of the node position (m).
    pub fn initial_temperature_fn(
        mut self,
        f: impl Fn(&[f64]) -> f64 + Send + Sync + 'static,
    ) -> Self {
        self.initial = Initial::Function(Arc::new(f));
        self
    }

    /// Initial temperature of every mesh node, in node order (e.g. the
    /// `names::TEMPERATURE` field of an earlier run on the same mesh); the length must
    /// equal the node count.
    pub fn initial_temperature_nodes(mut self, values: Vec<f64>) -> Self {
        self.initial = Initial::Nodes(Arc::new(values));
        self
    }

    /// Holds the nodes in `range` at temperature `t` (constant or time table; manual
    /// table 14). Where ranges overlap, the last condition wins.
    pub fn temperature(mut self, range: Range, t: impl Into<TimeValue>) -> Self {
        self.fixed.push((range, t.into()));
        self
    }

    /// A heat flux density q_n (W/m², positive into the body; 2D: per metre of
    /// thickness) on the boundary faces in `range` (table 16, eq. 101 shares).
    pub fn heat_flux(mut self, range: Range, q: impl Into<TimeValue>) -> Self {
        self.faces.push((range, FaceHeat::Flux(q.into())));
        self
    }

    /// Convection h (T_env − T) on the boundary faces in `range` (eq. 100–101; h ≥ 0 in
    /// W/(m²·K), T_env constant or a time table).
    pub fn convection(mut self, range: Range, h: f64, t_env: impl Into<TimeValue>) -> Self {
        self.faces
            .push((range, FaceHeat::Convection(h, t_env.into())));
        self
    }

    /// How heat crosses the joints of a split mesh ([`JointHeat`]).
    pub fn joints(mut self, joints: JointHeat) -> Self {
        self.joints = joints;
        self
    }

    /// The thermal stage's schedule relative to the mechanical step (default
    /// [`FieldSchedule::Auto`]: from the stable steps, reported by
    /// `Simulation::field_stages`).
    pub fn schedule(mut self, schedule: FieldSchedule) -> Self {
        self.schedule = schedule;
        self
    }

    /// Heat without mechanics: the physics gives every mesh node a unit mass and sets
    /// the step to its own stable step, so a simulation of this physics alone advances
    /// one thermal step per step. Composed with a mechanics it is refused at build.
    pub fn heat_only(mut self) -> Self {
        self.heat_only = true;
        self
    }

    /// Heat in the fracture fluid of the flow network (eq. 102–110; see the `fluid`
    /// section of the crate docs): conduction along the channels, upwind advection with
    /// their fluxes, exchange with the channel walls. Needs the fluid physics
    /// (`pcdc_hydro::Hydro`) composed in the same simulation. CPU and GPU.
    pub fn fluid(mut self, fluid: FluidHeat) -> Self {
        self.fluid = Some(fluid);
        self
    }

    /// Heat across broken joints whose faces still touch, through a contact conductance
    /// h_c (W/(m²·K), ≥ 0; eq. 111–112, see the crate docs): with
    /// [`JointHeat::FollowDamage`] on a split mesh whose cohesive joints publish their
    /// damage, opening and sliding (`pcdc_cohesive`). Without it a broken joint
    /// insulates.
    pub fn contact_conductance(mut self, h_c: f64) -> Self {
        self.contact = Some(h_c);
        self
    }

    /// Holds the fluid of the flow nodes whose vertices lie in `range` at temperature
    /// `t` (constant or time table; manual table 15), e.g. the fluid entering at an
    /// injection node. Needs [`Thermal::fluid`]; the last condition wins.
    pub fn fluid_temperature(mut self, range: Range, t: impl Into<TimeValue>) -> Self {
        self.fluid_fixed.push((range, t.into()));
        self
    }

    /// Uniform initial fluid temperature (K or °C). By default each flow node's fluid
    /// starts at the initial temperature of the solid node standing for it.
    pub fn initial_fluid_temperature(mut self, t: f64) -> Self {
        self.fluid_initial = Some(t);
        self
    }

    /// The fluid heat's network, initial state and stable steps (init).
    fn init_fluid<D: Dim>(
        &self,
        fl: &FluidHeat,
        ctx: &mut InitContext<'_, D>,
        d: &mut Derived,
    ) -> Result<FluidState, ComputeError> {
        let (Some(nodes), Some(channels)) =
            (ctx.entity_set(FLOW_NODES), ctx.entity_set(FLOW_CHANNELS))
        else {
            return Err(ComputeError::param(
                "Thermal::fluid",
                "no flow network",
                "heat in the fracture fluid needs the flow network: compose the fluid physics \
                 (pcdc_hydro::Hydro) in the same simulation",
            ));
        };
        let net = fluid::network(ctx.mesh, nodes, channels, &self.fluid_fixed)?;
        let fields = &mut *ctx.fields;
        let ids = FluidIds {
            temp: fields.id(FLUID_TEMPERATURE)?,
            capacity: fields.id(FLUID_HEAT_CAPACITY)?,
            balance: fields.id(FLUID_HEAT_BALANCE)?,
            saturation: fields.id(FLOW_SATURATION)?,
            aperture: fields.id(CHANNEL_APERTURE)?,
            flux: fields.id(CHANNEL_FLUX)?,
        };
        // The reference configuration, as the fluid physics' init uses.
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
        // Stable steps: the walls' exchange joins the solid rows; the fluid's conduction.
        let walls = fluid::wall_rows(fl, &net, &kin);
        for (r, w) in d.rows.iter_mut().zip(&walls) {
            *r += w;
        }
        d.stable = solid_stable(&d.capacity, &d.rows);
        if let Some(f) = fluid::stable_step(fl, &net, &kin) {
            if d.stable.as_ref().is_none_or(|s| f.dt < s.dt) {
                d.stable = Some(f);
            }
        }
        // Initial temperatures and heat content.
        let solid = fields.get(d.ids.expect("set").temp).to_vec();
        let nf = net.n_nodes();
        let npc = net.npc;
        let mut vol = vec![0.0; nf];
        {
            let aperture = fields.get(ids.aperture);
            for c in 0..net.n_channels() {
                let mut m = [[0.0; 3]; 3];
                for k in 0..npc {
                    let (a, b) = (
                        net.walls[c * 2 * npc + k] as usize,
                        net.walls[c * 2 * npc + npc + k] as usize,
                    );
                    for q in 0..D::D {
                        m[k][q] = 0.5 * (coords[a * D::D + q] + coords[b * D::D + q]);
                    }
                }
                let g = fluid::channel_geometry(npc, &m, [0.0; 3]);
                for k in 0..npc {
                    vol[net.channel_nodes[c * npc + k] as usize] +=
                        aperture[c] * g.measure / npc as f64;
                }
            }
        }
        let sat = fields.get(ids.saturation).to_vec();
        let t0: Vec<f64> = (0..nf)
            .map(|l| match net.fixed_of[l] {
                FREE => self
                    .fluid_initial
                    .unwrap_or(solid[net.node_rep[l] as usize]),
                f => self.fluid_fixed[f as usize].1.at(0.0),
            })
            .collect();
        if let Some(t) = self.fluid_initial {
            if !t.is_finite() {
                return Err(ComputeError::param(
                    "initial fluid temperature",
                    t,
                    "must be finite",
                ));
            }
        }
        let c0: Vec<f64> = (0..nf)
            .map(|l| fl.volumetric_capacity() * sat[l].clamp(0.0, 1.0) * vol[l])
            .collect();
        fields.get_mut(ids.temp).copy_from_slice(&t0);
        fields.get_mut(ids.capacity).copy_from_slice(&c0);
        let bal = fields.get_mut(ids.balance);
        for l in 0..nf {
            bal[l * 4] = c0[l] * t0[l];
        }
        Ok(FluidState {
            slots: vec![fluid::Slot::default(); net.n_channels() * npc],
            t_new: t0,
            scratch: Vec::new(),
            net,
            ids,
        })
    }

    fn reads_damage<D: Dim>(&self, mesh: &Mesh<D>) -> bool {
        self.joints == JointHeat::FollowDamage && !mesh.interfaces().is_empty()
    }

    fn derive<D: Dim>(&self, mesh: &Mesh<D>) -> Result<Derived, ComputeError> {
        let (d, npe, ne, nn) = (D::D, D::NODES_PER_ELEM, mesh.n_elements(), mesh.n_nodes());
        if self.materials.is_empty() {
            return Err(ComputeError::param(
                "thermal material",
                "none",
                "give every element a HeatMaterial (Thermal::material)",
            ));
        }
        let mut material = vec![u32::MAX; ne];
        let mut k = Vec::with_capacity(self.materials.len());
        for (m, (range, mat)) in self.materials.iter().enumerate() {
            mat.check_dim(d)?;
            k.push(mat.conductivity().tensor(d));
            let sel = mesh.select_elements(range).map_err(|e| {
                ComputeError::param(format!("thermal material {m}"), "range", e.to_string())
            })?;
            for e in sel {
                material[e as usize] = m as u32;
            }
        }
        if let Some(e) = material.iter().position(|&m| m == u32::MAX) {
            return Err(ComputeError::param(
                format!("element {e}"),
                "no thermal material",
                "every element needs a HeatMaterial (Thermal::material)",
            ));
        }
        let geo = Geometry::of(mesh)?;
        let conn = mesh.elements();
        // Lumped capacity (eq. 94) and the node → slot map.
        let mut capacity = vec![0.0; nn];
        let mut count = vec![0u32; nn];
        for e in 0..ne {
            let mat = &self.materials[material[e] as usize].1;
            let c = mat.density() * mat.capacity() * geo.measure[e] / npe as f64;
            for &n in &conn[e * npe..(e + 1) * npe] {
                capacity[n as usize] += c;
                count[n as usize] += 1;
            }
        }
        let mut slot_start = Vec::with_capacity(nn + 1);
        slot_start.push(0u32);
        for c in &count {
            slot_start.push(slot_start.last().copied().unwrap_or(0) + c);
        }
        let mut fill: Vec<u32> = slot_start[..nn].to_vec();
        let mut slots = vec![0u32; ne * npe];
        for (s, &n) in conn.iter().enumerate() {
            slots[fill[n as usize] as usize] = s as u32;
            fill[n as usize] += 1;
        }
        for (i, (_, heat)) in self.faces.iter().enumerate() {
            boundary::check(i, heat)?;
        }
        let entries = NodeEntries::build(mesh, &self.faces)?;
        let mut fixed_of = vec![FREE; nn];
        for (c, (range, t)) in self.fixed.iter().enumerate() {
            t.check(&format!("temperature of thermal condition {c}"))?;
            let nodes = mesh.select_nodes(range).map_err(|e| {
                ComputeError::param(
                    format!("thermal temperature condition {c}"),
                    "range",
                    e.to_string(),
                )
            })?;
            if nodes.is_empty() {
                return Err(ComputeError::param(
                    format!("thermal temperature condition {c}"),
                    "range",
                    "selects no node",
                ));
            }
            for n in nodes {
                fixed_of[n as usize] = c as u32;
            }
        }
        let nj = mesh.interfaces().len();
        let broken = vec![self.joints == JointHeat::Insulating; nj];
        let groups = Groups::build(mesh, |j| !broken[j]);
        // Stable step: Gershgorin on C⁻¹K per node, convection included; valid for any
        // grouping (a group's ratio is at least its members' smallest).
        let mut rows = vec![0.0; nn];
        let mut local = [0.0; 4];
        for e in 0..ne {
            local.fill(0.0);
            let g = &geo.grad[e * npe * d..(e + 1) * npe * d];
            conduction::row_sums(
                d,
                g,
                geo.measure[e],
                &k[material[e] as usize],
                &mut local[..npe],
            );
            for (a, &n) in conn[e * npe..(e + 1) * npe].iter().enumerate() {
                rows[n as usize] += local[a];
            }
        }
        for n in 0..nn {
            for i in entries.start[n] as usize..entries.start[n + 1] as usize {
                if let FaceHeat::Convection(h, _) = &self.faces[entries.cond[i] as usize].1 {
                    rows[n] += h * entries.share[i];
                }
            }
        }
        let contact = match self.contact {
            None => None,
            Some(h) => {
                if mesh.interfaces().is_empty() || self.joints != JointHeat::FollowDamage {
                    return Err(ComputeError::param(
                        "contact conductance",
                        h,
                        "acts across broken joints: it needs a split mesh and \
                         JointHeat::FollowDamage (the default)",
                    ));
                }
                let p = contact::pairs(mesh, h)?;
                for (r, c) in rows.iter_mut().zip(contact::rows(&p, nn)) {
                    *r += c;
                }
                Some(p)
            }
        };
        let stable = solid_stable(&capacity, &rows);
        Ok(Derived {
            rates: vec![0.0; ne * npe],
            node_rate: vec![0.0; nn],
            node_bnd: vec![0.0; nn],
            group_temp: vec![[0.0; 2]; groups.len()],
            geo,
            material,
            k,
            capacity,
            slot_start,
            slots,
            entries,
            fixed_of,
            groups,
            broken,
            stable,
            rows,
            ids: None,
            fluid: None,
            contact,
        })
    }
}

/// The solid's stable step 2 C_l / Σ|K_lb| over the nodes, with the limiting node.
fn solid_stable(capacity: &[f64], rows: &[f64]) -> Option<StableStep> {
    (0..capacity.len())
        .filter(|&n| rows[n] > 0.0)
        .map(|n| (2.0 * capacity[n] / rows[n], n))
        .min_by(|a, b| a.0.total_cmp(&b.0))
        .map(|(dt, n)| StableStep {
            dt,
            entity: Entity::new(EntityKind::Node, n),
            physics: "thermal".into(),
        })
}

impl<D: Dim> Physics<D> for Thermal {
    fn name(&self) -> &str {
        "thermal"
    }

    fn fields(&self, mesh: &Mesh<D>) -> Vec<FieldUse> {
        let mut f = vec![
            TEMPERATURE.own::<D>(),
            HEAT_FLUX.own::<D>(),
            HEAT_SUPPLIED.own::<D>(),
            HEAT_CAPACITY.own::<D>(),
        ];
        if self.reads_damage(mesh) {
            f.push(JOINT_DAMAGE.read_lagged::<D>());
            if self.contact.is_some() {
                f.push(JOINT_OPENING.read_lagged::<D>());
                f.push(JOINT_SLIDING.read_lagged::<D>());
            }
        }
        if self.fluid.is_some() {
            f.extend([
                FLUID_TEMPERATURE.own::<D>(),
                FLUID_HEAT_CAPACITY.own::<D>(),
                FLUID_HEAT_BALANCE.own::<D>(),
                FLOW_SATURATION.read_lagged::<D>(),
                CHANNEL_APERTURE.read_lagged::<D>(),
                CHANNEL_FLUX.read_lagged::<D>(),
            ]);
        }
        f
    }

    fn init(&mut self, ctx: &mut InitContext<'_, D>) -> Result<(), ComputeError> {
        // A unit mass per node would corrupt a mechanics' dynamics: refuse the mix.
        if self.heat_only && ctx.fields.id(pcdc_compute::names::STRESS).is_ok() {
            return Err(ComputeError::param(
                "Thermal::heat_only",
                "with a mechanics",
                "is for heat alone; with a mechanics leave it out (the heat then sub-cycles \
                 against the mechanical step)",
            ));
        }
        let mut d = self.derive(ctx.mesh)?;
        let fields = &mut *ctx.fields;
        let ids = Ids {
            temp: fields.id(TEMPERATURE)?,
            flux: fields.id(HEAT_FLUX)?,
            supplied: fields.id(HEAT_SUPPLIED)?,
            capacity: fields.id(HEAT_CAPACITY)?,
            damage: if self.reads_damage(ctx.mesh) {
                Some(fields.id(JOINT_DAMAGE)?)
            } else {
                None
            },
            touch: if self.contact.is_some() && self.reads_damage(ctx.mesh) {
                Some((fields.id(JOINT_OPENING)?, fields.id(JOINT_SLIDING)?))
            } else {
                None
            },
        };
        fields.get_mut(ids.capacity).copy_from_slice(&d.capacity);
        if let Initial::Nodes(v) = &self.initial {
            if v.len() != ctx.mesh.n_nodes() {
                return Err(ComputeError::param(
                    "initial node temperatures",
                    v.len(),
                    format!("must give one value per mesh node ({})", ctx.mesh.n_nodes()),
                ));
            }
        }
        let temp = fields.get_mut(ids.temp);
        for (n, t) in temp.iter_mut().enumerate() {
            let x = ctx.mesh.node(n);
            let v = match &self.initial {
                Initial::Uniform(t) => *t,
                Initial::Function(f) => f(x),
                Initial::Nodes(v) => v[n],
            };
            if !v.is_finite() {
                return Err(ComputeError::param(
                    format!("initial temperature at node {n} ({x:?})"),
                    v,
                    "must be finite",
                ));
            }
            *t = match d.fixed_of[n] {
                FREE => v,
                c => self.fixed[c as usize].1.at(0.0),
            };
        }
        d.ids = Some(ids);
        if let Some(fl) = &self.fluid {
            d.fluid = Some(self.init_fluid(fl, ctx, &mut d)?);
        } else if !self.fluid_fixed.is_empty() || self.fluid_initial.is_some() {
            return Err(ComputeError::param(
                "fluid temperature",
                "without fluid heat",
                "fluid temperatures need Thermal::fluid (and a flow network)",
            ));
        }
        self.derived = Some(d);
        Ok(())
    }

    fn add_mass(
        &self,
        mesh: &Mesh<D>,
        _fields: &FieldStore,
        mass: &mut [f64],
        _scale_to_dt: Option<f64>,
    ) {
        if self.heat_only {
            for m in &mut mass[..mesh.n_nodes()] {
                *m += 1.0;
            }
        }
    }

    fn stable_step(&self, _kin: &Kinematics<'_, D>, _fields: &FieldStore) -> Option<StableStep> {
        if self.heat_only {
            self.derived.as_ref()?.stable.clone()
        } else {
            None
        }
    }

    fn field_schedule(&self) -> Option<FieldSchedule> {
        Some(self.schedule)
    }

    fn field_stable_step(&self, _kin: &Kinematics<'_, D>, _f: &FieldStore) -> Option<StableStep> {
        self.derived.as_ref()?.stable.clone()
    }

    fn kinematic_nodes(&self) -> KinematicNodes {
        KinematicNodes::None
    }

    fn compute_forces(&mut self, _ctx: &mut ForceContext<'_, D>) -> Result<(), ComputeError> {
        Ok(()) // heat carries no force; thermal stress is the mechanics' (ThermalStrain)
    }

    fn gpu_setup(&mut self, setup: &mut GpuSetup<'_, D>) -> Result<(), ComputeError> {
        let d = self
            .derived
            .as_ref()
            .ok_or_else(|| ComputeError::Gpu("thermal: GPU setup before init".into()))?;
        let fluid = self
            .fluid
            .as_ref()
            .map(|f| (f, self.fluid_fixed.as_slice()));
        crate::gpu::program(
            d,
            &self.faces,
            &self.fixed,
            fluid,
            self.reads_damage(setup.mesh),
            setup,
        )
    }

    fn field_step(&mut self, ctx: &mut FieldContext<'_, D>) -> Result<(), ComputeError> {
        let d = self.derived.as_mut().expect("init ran");
        let ids = d.ids.expect("init ran");
        let (dim, npe) = (D::D, D::NODES_PER_ELEM);
        // Conditions take their values at the end of the mechanical step, every sub-step
        // alike (the GPU reads them once per step, as the fluid's do).
        let (dt, t_end) = (ctx.dt, ctx.kin.time);
        // Joints that broke since the last step stop conducting: their groups split.
        if let Some(id) = ids.damage {
            let damage = ctx.fields.get(id);
            let mut changed = false;
            for (b, &dmg) in d.broken.iter_mut().zip(damage) {
                if !*b && dmg >= 1.0 {
                    *b = true;
                    changed = true;
                }
            }
            if changed {
                let broken = &d.broken;
                d.groups = Groups::build(ctx.kin.mesh, |j| !broken[j]);
                d.group_temp = vec![[0.0; 2]; d.groups.len()];
            }
        }
        // The fracture fluid first, against the solid at the start of the step; the walls
        // then take the exchange at the fluid's new temperatures (fluid module docs).
        if let (Some(fs), Some(fl)) = (d.fluid.as_mut(), self.fluid.as_ref()) {
            let fi = fs.ids;
            let [temp, tf, cap, bal, s, ap, q] = ctx.fields.get_many_mut([
                ids.temp,
                fi.temp,
                fi.capacity,
                fi.balance,
                fi.saturation,
                fi.aperture,
                fi.flux,
            ]);
            ctx.backend.install(|| {
                fluid::step(
                    fl,
                    &fs.net,
                    &self.fluid_fixed,
                    &ctx.kin,
                    dt,
                    t_end,
                    temp,
                    (s, ap, q),
                    tf,
                    cap,
                    bal,
                    &mut fs.slots,
                    &mut fs.scratch,
                )
            });
            fs.t_new.copy_from_slice(tf);
        }
        // Contact across broken joints reads the joints' state at the start of the step.
        let touch = match (ids.touch, ids.damage) {
            (Some((o, s)), Some(dm)) => Some((
                ctx.fields.get(dm).to_vec(),
                ctx.fields.get(o).to_vec(),
                ctx.fields.get(s).to_vec(),
            )),
            _ => None,
        };
        let contact_state = d.contact.as_ref().zip(touch.as_ref());
        let fluid_state = d.fluid.as_ref();
        let conn = ctx.kin.mesh.elements();
        let [temp, flux, supplied] = ctx.fields.get_many_mut([ids.temp, ids.flux, ids.supplied]);
        let Derived {
            geo,
            material,
            k,
            capacity,
            slot_start,
            slots,
            entries,
            fixed_of,
            groups,
            rates,
            node_rate,
            node_bnd,
            group_temp,
            ..
        } = d;
        ctx.backend.install(|| {
            // Element pass: fluxes and nodal rates per element slot (eq. 95–98).
            let temps = &*temp;
            rates
                .par_chunks_mut(CHUNK * npe)
                .zip(flux.par_chunks_mut(CHUNK * dim))
                .enumerate()
                .for_each(|(c, (r, fl))| {
                    let first = c * CHUNK;
                    for (i, (r, fl)) in r
                        .chunks_exact_mut(npe)
                        .zip(fl.chunks_exact_mut(dim))
                        .enumerate()
                    {
                        let e = first + i;
                        let mut t = [0.0; 4];
                        for (a, &n) in conn[e * npe..(e + 1) * npe].iter().enumerate() {
                            t[a] = temps[n as usize];
                        }
                        conduction::element(
                            dim,
                            &geo.grad[e * npe * dim..(e + 1) * npe * dim],
                            geo.measure[e],
                            &k[material[e] as usize],
                            &t[..npe],
                            fl,
                            r,
                        );
                    }
                });
        });
        // (convection?, h, value): a flux density, or h and the environment temperature.
        let values: Vec<(bool, f64, f64)> = self
            .faces
            .iter()
            .map(|(_, h)| match h {
                FaceHeat::Flux(q) => (false, 0.0, q.at(t_end)),
                FaceHeat::Convection(h, te) => (true, *h, te.at(t_end)),
            })
            .collect();
        let rates = &*rates;
        ctx.backend.install(|| {
            // Node pass: gather the element slots in a fixed order, add the face heat.
            node_rate
                .par_chunks_mut(CHUNK)
                .zip(node_bnd.par_chunks_mut(CHUNK))
                .enumerate()
                .for_each(|(c, (nr, nb))| {
                    for (i, (nr, nb)) in nr.iter_mut().zip(nb.iter_mut()).enumerate() {
                        let n = c * CHUNK + i;
                        let mut s = 0.0;
                        for &k in &slots[slot_start[n] as usize..slot_start[n + 1] as usize] {
                            s += rates[k as usize];
                        }
                        let mut b = 0.0;
                        for j in entries.start[n] as usize..entries.start[n + 1] as usize {
                            let (conv, h, v) = values[entries.cond[j] as usize];
                            b += entries.share[j] * if conv { h * (v - temp[n]) } else { v };
                        }
                        *nr = s + b;
                        // The walls' exchange last (the GPU adds it in a pass of its own).
                        if let Some(fs) = fluid_state {
                            *nr += fluid::wall_rate(&fs.net, &fs.slots, &fs.t_new, temp, n);
                        }
                        // Then broken joints whose faces touch (eq. 111–112).
                        if let Some((p, (dmg, op, sl))) = contact_state {
                            *nr += contact::rate(p, n, dim, temp, dmg, op, sl);
                        }
                        *nb = b;
                    }
                });
            // Group pass: one explicit update per thermal node (eq. 94, 99 corrected).
            let (node_rate, temps) = (&*node_rate, &*temp);
            group_temp
                .par_iter_mut()
                .enumerate()
                .with_min_len(CHUNK)
                .for_each(|(g, out)| {
                    let m = &groups.members[groups.start[g] as usize..groups.start[g + 1] as usize];
                    let (mut r, mut c) = (0.0, 0.0);
                    let mut fixed = FREE;
                    for &n in m {
                        r += node_rate[n as usize];
                        c += capacity[n as usize];
                        if fixed_of[n as usize] != FREE {
                            fixed = fixed_of[n as usize];
                        }
                    }
                    let free = temps[m[0] as usize] + dt * r / c;
                    let new = if fixed == FREE {
                        free
                    } else {
                        self.fixed[fixed as usize].1.at(t_end)
                    };
                    *out = [free, new];
                });
            // Node write: temperature and the heat supplied from outside.
            let group_temp = &*group_temp;
            temp.par_chunks_mut(CHUNK)
                .zip(supplied.par_chunks_mut(CHUNK))
                .enumerate()
                .for_each(|(c, (tc, sc))| {
                    for (i, (t, s)) in tc.iter_mut().zip(sc.iter_mut()).enumerate() {
                        let n = c * CHUNK + i;
                        let [free, new] = group_temp[groups.of[n] as usize];
                        *s += dt * node_bnd[n] + capacity[n] * (new - free);
                        *t = new;
                    }
                });
        });
        Ok(())
    }
}
