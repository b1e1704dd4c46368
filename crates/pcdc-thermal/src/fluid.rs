//! Heat in the fracture fluid (manual 7.6.2–7.6.3, eq. 102–110): conduction along the
//! flow channels, upwind advection with the channels' fluxes, exchange with the two
//! walls of each channel, fluid temperature conditions (table 15).
//!
//! The flow network is the fluid physics' (`pcdc-hydro`), read through the shared entity
//! sets `names::FLOW_NODES`, `names::FLOW_CHANNELS` and fields `names::FLOW_SATURATION`,
//! `names::CHANNEL_APERTURE`, `names::CHANNEL_FLUX` of `pcdc_compute`:
//! no crate dependency. Per channel c (measure A, aperture δ, mean flux q) and node k
//! (flow node l, saturation s_l), on the midplane of the joint's node pairs:
//!
//! * **capacity** C_l = ρ_f C_f s_l Σ_c δ_c A_c / N \[NOT IN MANUAL: saturation
//!   weighting of the digest\];
//! * **conduction (102)** along the channel, G_ij = k_f δ min(s_i, s_j) w_ij, w the
//!   linear-element weights (2D: 1/L; 3D: the cotangent weights), heat k_f … (T_j − T_i)
//!   into i, explicit; the smaller saturation keeps G/C bounded as a node dries;
//! * **advection (103–108)** \[CORRECTED: the printed eq. 108 lacks the aperture; with
//!   the unit-width flux q = δ v it is ρ_f C_f Σ T_upwind q·n ds\] in the upwind
//!   advective form C_l dT_l/dt = ρ_f C_f Σ_{j→l} F_jl (T_j − T_l) over the edges that
//!   flow into l, F the volume rate between the two nodes' control areas (2D: q·t̂;
//!   3D: q·n over the median-dual segment from the edge midpoint to the centroid, whose
//!   nodal sums are the cubic-law nodal flows). Fluid leaves a node at its own
//!   temperature and brings the upstream one; a node's net inflow (boundary flow,
//!   storage) enters at the node's temperature unless a fluid temperature condition
//!   holds it;
//! * **solid–fluid exchange (109–110)** \[CORRECTED: the 1/N_dim share of the printed
//!   eq. 109 would give each channel node the whole channel's exchange; it is 1/N, on
//!   each of the two walls\] H = h_sf A f(s_l)/N between flow node l and each wall node
//!   (the joint's side-A and side-B node of the pair), f(s) = s²(3 − 2s) the saturation
//!   weight of eq. 81; the wall node gets H (T_l − T_s), the fluid the opposite.
//!
//! **Time integration** \[NOT IN MANUAL\]. A fracture's fluid holds little heat (δ ≪ the
//! element size), so exchange and advection would force steps far below the solid's
//! (C_l/(h A) is seconds for a millimetre aperture). They are taken implicit in the
//! fluid node's own temperature (point-implicit, neighbours and walls at the start of
//! the step):
//! T_l' = [C_l T_l + Δt (ρ_f C_f Σ F_jl T_j + Σ H T_s + conduction)] /
//! [C_l + Δt (ρ_f C_f Σ F_jl + Σ H)],
//! a weighted mean of temperatures at the start of the step: stable at any step and
//! within the bounds of the inflow, wall and initial temperatures (no overshoot); the
//! walls then receive H (T_l' − T_s), so exchange conserves heat exactly. Conduction
//! along the channel stays explicit (conservative); its bound,
//! Δt ≤ 2 ρ_f C_f A / (N k_f Σ|w|) per channel node, joins the thermal stable step.
//!
//! **Energy** Σ C_s T_s + Σ C_l T_l changes by the solid's supplied heat plus, per flow
//! node, [`crate::FLUID_HEAT_BALANCE`]: what the fluid conditions put in, the advected heat
//! (net over the network: what the flow carried across its boundary), and T ΔC as the
//! fluid volume changes; to rounding.

use std::collections::HashMap;

use pcdc_compute::{ComputeError, EntitySet, Kinematics, StableStep, TimeValue};
use pcdc_mesh::{Dim, Mesh, Range};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::physics::FREE;

/// Thermal properties of the fracture fluid (manual table 13, `t-f`): conductivity k_f
/// (W/(m·K), ≥ 0; 0 leaves out conduction along the channels, as Lauwerier's solution
/// does), specific heat C_f (J/(kg·K), > 0), density ρ_f (kg/m³, > 0) and the
/// solid–fluid transfer coefficient h_sf (W/(m²·K), ≥ 0, eq. 109). Checked by
/// [`FluidHeat::new`] and on deserialisation.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "RawFluidHeat")]
pub struct FluidHeat {
    conductivity: f64,
    capacity: f64,
    density: f64,
    transfer: f64,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawFluidHeat {
    conductivity: f64,
    capacity: f64,
    density: f64,
    transfer: f64,
}

impl TryFrom<RawFluidHeat> for FluidHeat {
    type Error = ComputeError;
    fn try_from(r: RawFluidHeat) -> Result<Self, ComputeError> {
        FluidHeat::new(r.conductivity, r.capacity, r.density, r.transfer)
    }
}

impl FluidHeat {
    /// k_f (W/(m·K)), C_f (J/(kg·K)), ρ_f (kg/m³), h_sf (W/(m²·K)).
    pub fn new(
        conductivity: f64,
        capacity: f64,
        density: f64,
        transfer: f64,
    ) -> Result<Self, ComputeError> {
        let checks = [
            (
                "fluid conductivity k_f (conductivity)",
                conductivity,
                conductivity >= 0.0,
                "W/(m·K)",
            ),
            (
                "fluid specific heat C_f (capacity)",
                capacity,
                capacity > 0.0,
                "J/(kg·K)",
            ),
            (
                "fluid density ρ_f (density)",
                density,
                density > 0.0,
                "kg/m³",
            ),
            (
                "solid–fluid transfer coefficient h_sf (transfer)",
                transfer,
                transfer >= 0.0,
                "W/(m²·K)",
            ),
        ];
        for (name, v, ok, unit) in checks {
            if !(ok && v.is_finite()) {
                let sign = if name.contains("conductivity") || name.contains("transfer") {
                    "non-negative"
                } else {
                    "positive"
                };
                return Err(ComputeError::param(
                    name,
                    v,
                    format!("must be {sign} and finite ({unit})"),
                ));
            }
        }
        Ok(FluidHeat {
            conductivity,
            capacity,
            density,
            transfer,
        })
    }

    /// Water at 20 °C (k_f 0.6 W/(m·K), C_f 4186 J/(kg·K), ρ_f 1000 kg/m³) with the
    /// transfer coefficient h_sf (W/(m²·K)).
    pub fn water(transfer: f64) -> Result<Self, ComputeError> {
        Self::new(0.6, 4186.0, 1000.0, transfer)
    }

    /// k_f (W/(m·K)).
    pub fn conductivity(&self) -> f64 {
        self.conductivity
    }
    /// C_f (J/(kg·K)).
    pub fn capacity(&self) -> f64 {
        self.capacity
    }
    /// ρ_f (kg/m³).
    pub fn density(&self) -> f64 {
        self.density
    }
    /// h_sf (W/(m²·K)).
    pub fn transfer(&self) -> f64 {
        self.transfer
    }
    /// Volumetric heat capacity ρ_f C_f (J/(m³·K)).
    pub fn volumetric_capacity(&self) -> f64 {
        self.density * self.capacity
    }
}

/// The saturation weight f(s) = s²(3 − 2s) of eq. 81 (the fluid physics' own).
#[inline]
pub(crate) fn saturation_weight(s: f64) -> f64 {
    let s = s.clamp(0.0, 1.0);
    s * s * (3.0 - 2.0 * s)
}

/// The flow network as the heat sees it, rebuilt from the fluid's entity sets.
#[derive(Clone, Debug, Default)]
pub(crate) struct Net {
    pub(crate) npc: usize,
    /// Flow node of each channel node, stride `npc`.
    pub(crate) channel_nodes: Vec<u32>,
    /// Joint nodes of each channel: side A then side B, stride `2 npc`.
    pub(crate) walls: Vec<u32>,
    /// Flow node → its channel-node slots (c · npc + k), ascending (CSR).
    pub(crate) inc_ptr: Vec<u32>,
    pub(crate) incidence: Vec<u32>,
    /// Mesh node → the slots whose walls it lies on, ascending (CSR).
    pub(crate) wall_ptr: Vec<u32>,
    pub(crate) wall_slots: Vec<u32>,
    /// Fluid temperature condition of each flow node, or [`FREE`].
    pub(crate) fixed_of: Vec<u32>,
    /// A mesh node standing for each flow node.
    pub(crate) node_rep: Vec<u32>,
}

impl Net {
    pub(crate) fn n_nodes(&self) -> usize {
        self.node_rep.len()
    }
    pub(crate) fn n_channels(&self) -> usize {
        self.channel_nodes.len() / self.npc.max(1)
    }
}

/// CSR of `pairs` (key, value) with `n` keys, values ascending per key.
fn csr(n: usize, pairs: &[(u32, u32)]) -> (Vec<u32>, Vec<u32>) {
    let mut ptr = vec![0u32; n + 1];
    for &(k, _) in pairs {
        ptr[k as usize + 1] += 1;
    }
    for i in 0..n {
        ptr[i + 1] += ptr[i];
    }
    let mut fill = ptr.clone();
    let mut out = vec![0u32; pairs.len()];
    let mut sorted = pairs.to_vec();
    sorted.sort_unstable();
    for (k, v) in sorted {
        out[fill[k as usize] as usize] = v;
        fill[k as usize] += 1;
    }
    (ptr, out)
}

/// The network of the fluid physics' sets on `mesh`, with the fluid temperature
/// conditions `fixed` resolved to flow nodes.
pub(crate) fn network<D: Dim>(
    mesh: &Mesh<D>,
    nodes: &EntitySet,
    channels: &EntitySet,
    fixed: &[(Range, TimeValue)],
) -> Result<Net, ComputeError> {
    let npc = D::NODES_PER_FACE;
    let joints = mesh.interfaces();
    if channels.nodes_per_entity() != npc || nodes.nodes_per_entity() != 1 {
        return Err(ComputeError::param(
            "fluid heat",
            "flow network sets",
            "do not have the layout of pcdc-hydro's network (1 node per flow node, the face \
             nodes per channel)",
        ));
    }
    let mut flow_of_master: HashMap<u32, u32> = HashMap::new();
    for (l, &n) in nodes.nodes().iter().enumerate() {
        flow_of_master.insert(joints.master_of(n), l as u32);
    }
    let mut joint_of: HashMap<&[u32], usize> = HashMap::new();
    for j in 0..joints.len() {
        joint_of.insert(&joints.joint_nodes(j)[..npc], j);
    }
    let nc = channels.len();
    let mut net = Net {
        npc,
        channel_nodes: Vec::with_capacity(nc * npc),
        walls: Vec::with_capacity(nc * 2 * npc),
        node_rep: nodes.nodes().to_vec(),
        ..Net::default()
    };
    for c in 0..nc {
        let side_a = channels.entity(c);
        let Some(&j) = joint_of.get(side_a) else {
            return Err(ComputeError::param(
                "fluid heat",
                format!("flow channel {c}"),
                "lies on no joint of the mesh (a network built on another mesh?)",
            ));
        };
        for &a in side_a {
            let Some(&l) = flow_of_master.get(&joints.master_of(a)) else {
                return Err(ComputeError::param(
                    "fluid heat",
                    format!("flow channel {c}"),
                    "has a node with no flow node",
                ));
            };
            net.channel_nodes.push(l);
        }
        net.walls.extend_from_slice(joints.joint_nodes(j));
    }
    let inc: Vec<(u32, u32)> = net
        .channel_nodes
        .iter()
        .enumerate()
        .map(|(e, &l)| (l, e as u32))
        .collect();
    (net.inc_ptr, net.incidence) = csr(net.n_nodes(), &inc);
    let mut walls = Vec::with_capacity(nc * 2 * npc);
    for c in 0..nc {
        for k in 0..npc {
            let e = (c * npc + k) as u32;
            walls.push((net.walls[c * 2 * npc + k], e));
            walls.push((net.walls[c * 2 * npc + npc + k], e));
        }
    }
    (net.wall_ptr, net.wall_slots) = csr(mesh.n_nodes(), &walls);
    net.fixed_of = vec![FREE; net.n_nodes()];
    for (i, (range, t)) in fixed.iter().enumerate() {
        t.check(&format!("fluid temperature condition {i}"))?;
        let sel = mesh.select_nodes(range).map_err(|e| {
            ComputeError::param(
                format!("fluid temperature condition {i}"),
                "range",
                e.to_string(),
            )
        })?;
        let mut any = false;
        for n in sel {
            if let Some(&l) = flow_of_master.get(&joints.master_of(n)) {
                net.fixed_of[l as usize] = i as u32;
                any = true;
            }
        }
        if !any {
            return Err(ComputeError::param(
                format!("fluid temperature condition {i}"),
                format!("{range:?}"),
                "selects no node of the flow network",
            ));
        }
    }
    Ok(net)
}

/// Midplane points of channel `c` (the means of its joint's node pairs).
#[inline]
fn midplane<D: Dim>(kin: &Kinematics<'_, D>, net: &Net, c: usize) -> [[f64; 3]; 3] {
    let npc = net.npc;
    let w = &net.walls[c * 2 * npc..(c + 1) * 2 * npc];
    let mut m = [[0.0; 3]; 3];
    for k in 0..npc {
        let (a, b) = (
            kin.position(w[k] as usize),
            kin.position(w[npc + k] as usize),
        );
        for q in 0..D::D {
            m[k][q] = 0.5 * (a[q] + b[q]);
        }
    }
    m
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// The geometry of one channel: its measure A, the conduction weights w of its edges
/// and, from its mean flux q, the volume rate F_ij between the control areas of its
/// nodes (edges 2D: (0,1); 3D: (0,1), (1,2), (2,0)).
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct ChannelGeometry {
    pub(crate) measure: f64,
    pub(crate) weight: [f64; 3],
    pub(crate) rate: [f64; 3],
}

/// The edges (i, j, opposite k) of a channel with `npc` nodes.
pub(crate) fn edges(npc: usize) -> &'static [(usize, usize, usize)] {
    const E2: [(usize, usize, usize); 1] = [(0, 1, 0)];
    const E3: [(usize, usize, usize); 3] = [(0, 1, 2), (1, 2, 0), (2, 0, 1)];
    if npc == 2 {
        &E2
    } else {
        &E3
    }
}

/// [`ChannelGeometry`] of the channel with midplane points `m` and mean flux `q`.
pub(crate) fn channel_geometry(npc: usize, m: &[[f64; 3]; 3], q: [f64; 3]) -> ChannelGeometry {
    let mut g = ChannelGeometry::default();
    if npc == 2 {
        let t = sub(m[1], m[0]);
        let len = dot(t, t).sqrt();
        if len > 0.0 {
            g.measure = len;
            g.weight[0] = 1.0 / len;
            g.rate[0] = dot(q, t) / len;
        }
        return g;
    }
    let nrm = cross(sub(m[1], m[0]), sub(m[2], m[0]));
    let twice = dot(nrm, nrm).sqrt();
    if twice == 0.0 {
        return g;
    }
    g.measure = 0.5 * twice;
    let centroid: [f64; 3] = std::array::from_fn(|d| (m[0][d] + m[1][d] + m[2][d]) / 3.0);
    for (e, &(i, j, k)) in edges(3).iter().enumerate() {
        g.weight[e] = dot(sub(m[i], m[k]), sub(m[j], m[k])) / (4.0 * g.measure);
        let mid: [f64; 3] = std::array::from_fn(|d| 0.5 * (m[i][d] + m[j][d]));
        // The dual segment's in-plane normal, of its length, pointing from i to j.
        let seg = sub(centroid, mid);
        let mut n = cross(seg, nrm);
        n = [n[0] / twice, n[1] / twice, n[2] / twice];
        if dot(n, sub(m[j], m[i])) < 0.0 {
            n = [-n[0], -n[1], -n[2]];
        }
        g.rate[e] = dot(q, n);
    }
    g
}

/// Per channel node (slot), what the fluid node update gathers.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Slot {
    /// δ A / N (m³; m² in 2D): the slot's share of the node's volume.
    pub(crate) volume: f64,
    /// Exchange H with each of the two walls, h_sf A f(s_l) / N (W/K).
    pub(crate) exchange: f64,
    /// ρ_f C_f Σ F over the edges flowing into the node (W/K).
    pub(crate) inflow: f64,
    /// ρ_f C_f Σ F T_upstream over the same edges (W).
    pub(crate) inflow_heat: f64,
    /// Conducted heat rate into the node along the channel (W).
    pub(crate) conducted: f64,
}

/// The slots of channel `c` at fluid temperatures `tf` and saturations `s`.
#[allow(clippy::too_many_arguments)]
#[inline]
pub(crate) fn channel_slots(
    fluid: &FluidHeat,
    npc: usize,
    nodes: &[u32],
    geo: &ChannelGeometry,
    aperture: f64,
    tf: &[f64],
    s: &[f64],
    out: &mut [Slot],
) {
    let rc = fluid.volumetric_capacity();
    for k in 0..npc {
        let l = nodes[k] as usize;
        out[k] = Slot {
            volume: aperture * geo.measure / npc as f64,
            exchange: fluid.transfer * geo.measure * saturation_weight(s[l]) / npc as f64,
            ..Slot::default()
        };
    }
    for (e, &(i, j, _)) in edges(npc).iter().enumerate() {
        let (a, b) = (nodes[i] as usize, nodes[j] as usize);
        let f = geo.rate[e] * rc;
        // Upwind: the flow from i to j brings T_i into j, and the reverse.
        if f > 0.0 {
            out[j].inflow += f;
            out[j].inflow_heat += f * tf[a];
        } else if f < 0.0 {
            out[i].inflow -= f;
            out[i].inflow_heat -= f * tf[b];
        }
        let g = fluid.conductivity * aperture * s[a].min(s[b]).clamp(0.0, 1.0) * geo.weight[e];
        let heat = g * (tf[b] - tf[a]);
        out[i].conducted += heat;
        out[j].conducted -= heat;
    }
}

/// The point-implicit update of one free flow node (module docs): the new temperature
/// from the old `t`, the capacity `c` and the gathered inflow `a_in` (W/K) with its
/// heat `b_in` (W), wall coupling `h` (W/K) with `ht` = Σ H T_s (W), conduction (W).
#[allow(clippy::too_many_arguments)]
#[inline]
pub(crate) fn implicit_update(
    t: f64,
    c: f64,
    dt: f64,
    a_in: f64,
    b_in: f64,
    h: f64,
    ht: f64,
    conducted: f64,
) -> f64 {
    let den = c + dt * (a_in + h);
    if den > 0.0 {
        (c * t + dt * (b_in + ht + conducted)) / den
    } else {
        t // no fluid, no flow, no wall: nothing changes
    }
}

/// The fluid's stable step: explicit conduction along the channels,
/// 2 ρ_f C_f A / (N k_f Σ_j |w_kj|) per channel node (independent of aperture and
/// saturation, which scale capacity and conductance alike), at the positions `kin`.
pub(crate) fn stable_step<D: Dim>(
    fluid: &FluidHeat,
    net: &Net,
    kin: &Kinematics<'_, D>,
) -> Option<StableStep> {
    if fluid.conductivity == 0.0 {
        return None;
    }
    let npc = net.npc;
    let mut best: Option<(f64, usize)> = None;
    for c in 0..net.n_channels() {
        let m = midplane(kin, net, c);
        let g = channel_geometry(npc, &m, [0.0; 3]);
        let mut row = [0.0; 3];
        for (e, &(i, j, _)) in edges(npc).iter().enumerate() {
            row[i] += g.weight[e].abs();
            row[j] += g.weight[e].abs();
        }
        for r in row.iter().take(npc) {
            if *r > 0.0 {
                let dt = 2.0 * fluid.volumetric_capacity() * g.measure
                    / (npc as f64 * fluid.conductivity * r);
                if best.is_none_or(|(b, _)| dt < b) {
                    best = Some((dt, c));
                }
            }
        }
    }
    best.map(|(dt, c)| StableStep {
        dt,
        entity: pcdc_compute::Entity::new(pcdc_compute::EntityKind::Other("flow channel"), c),
        physics: "thermal (fluid conduction)".into(),
    })
}

/// Largest wall exchange per mesh node at the positions `kin` (s = 1), for the solid's
/// stable step: Σ h_sf A / N over the slots on its walls (W/K).
pub(crate) fn wall_rows<D: Dim>(fluid: &FluidHeat, net: &Net, kin: &Kinematics<'_, D>) -> Vec<f64> {
    let npc = net.npc;
    let measure: Vec<f64> = (0..net.n_channels())
        .map(|c| channel_geometry(npc, &midplane(kin, net, c), [0.0; 3]).measure)
        .collect();
    (0..net.wall_ptr.len() - 1)
        .map(|n| {
            net.wall_slots[net.wall_ptr[n] as usize..net.wall_ptr[n + 1] as usize]
                .iter()
                .map(|&e| fluid.transfer * measure[e as usize / npc] / npc as f64)
                .sum()
        })
        .collect()
}

/// The fluid's part of a thermal step: channel pass into `slots`, then the flow nodes'
/// point-implicit update of `tf` (conditions at `t_end`), booking the balance.
#[allow(clippy::too_many_arguments)]
pub(crate) fn step<D: Dim>(
    fluid: &FluidHeat,
    net: &Net,
    fixed: &[(Range, TimeValue)],
    kin: &Kinematics<'_, D>,
    dt: f64,
    t_end: f64,
    solid: &[f64],
    inputs: (&[f64], &[f64], &[f64]),
    tf: &mut [f64],
    cap: &mut [f64],
    balance: &mut [f64],
    slots: &mut [Slot],
    scratch: &mut Vec<f64>,
) {
    const CHUNK: usize = 256;
    let (s, aperture, flux) = inputs;
    let (npc, dim) = (net.npc, D::D);
    {
        let tf = &*tf;
        slots
            .par_chunks_mut(CHUNK * npc)
            .enumerate()
            .for_each(|(b, out)| {
                for (i, out) in out.chunks_exact_mut(npc).enumerate() {
                    let c = b * CHUNK + i;
                    let m = midplane(kin, net, c);
                    let mut q = [0.0; 3];
                    q[..dim].copy_from_slice(&flux[c * dim..(c + 1) * dim]);
                    let g = channel_geometry(npc, &m, q);
                    let nodes = &net.channel_nodes[c * npc..(c + 1) * npc];
                    channel_slots(fluid, npc, nodes, &g, aperture[c], tf, s, out);
                }
            });
    }
    let rc = fluid.volumetric_capacity();
    scratch.clear();
    scratch.extend(fixed.iter().map(|(_, v)| v.at(t_end)));
    let values = &*scratch;
    let slots = &*slots;
    tf.par_chunks_mut(CHUNK)
        .zip(cap.par_chunks_mut(CHUNK))
        .zip(balance.par_chunks_mut(CHUNK * 4))
        .enumerate()
        .for_each(|(b, ((tf, cap), bal))| {
            for i in 0..tf.len() {
                let l = b * CHUNK + i;
                let (mut vol, mut a_in, mut b_in, mut h, mut ht, mut cond) =
                    (0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
                for &e in &net.incidence[net.inc_ptr[l] as usize..net.inc_ptr[l + 1] as usize] {
                    let sl = &slots[e as usize];
                    let (c, k) = (e as usize / npc, e as usize % npc);
                    vol += sl.volume;
                    a_in += sl.inflow;
                    b_in += sl.inflow_heat;
                    cond += sl.conducted;
                    h += 2.0 * sl.exchange;
                    let w = &net.walls[c * 2 * npc..(c + 1) * 2 * npc];
                    ht += sl.exchange * (solid[w[k] as usize] + solid[w[npc + k] as usize]);
                }
                let c_new = rc * s[l].clamp(0.0, 1.0) * vol;
                let t_old = tf[i];
                // The heat content follows the fluid volume at constant temperature.
                bal[i * 4 + 3] += t_old * (c_new - cap[i]);
                let free = implicit_update(t_old, c_new, dt, a_in, b_in, h, ht, cond);
                let new = match net.fixed_of[l] {
                    FREE => free,
                    f => values[f as usize],
                };
                let adv = b_in - a_in * new;
                let exch = ht - h * new;
                // What holds a condition: the change not explained by the rates.
                bal[i * 4 + 1] += c_new * (new - t_old) - dt * (adv + exch + cond);
                bal[i * 4 + 2] += dt * adv;
                tf[i] = new;
                cap[i] = c_new;
            }
        });
}

/// Heat rate from the fluid into each mesh node on a channel wall (W; W/m in 2D), at the
/// fluid's new temperatures `tf` and the solid's `solid`, in slot order.
#[inline]
pub(crate) fn wall_rate(net: &Net, slots: &[Slot], tf: &[f64], solid: &[f64], n: usize) -> f64 {
    let mut r = 0.0;
    for &e in &net.wall_slots[net.wall_ptr[n] as usize..net.wall_ptr[n + 1] as usize] {
        let l = net.channel_nodes[e as usize] as usize;
        r += slots[e as usize].exchange * (tf[l] - solid[n]);
    }
    r
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn bad_fluid_properties_are_refused_by_name() {
        for (args, name) in [
            ((-1.0, 4186.0, 1000.0, 10.0), "conductivity"),
            ((0.6, 0.0, 1000.0, 10.0), "C_f"),
            ((0.6, 4186.0, -1.0, 10.0), "density"),
            ((0.6, 4186.0, 1000.0, -5.0), "transfer"),
            ((0.6, f64::NAN, 1000.0, 5.0), "C_f"),
        ] {
            let e = FluidHeat::new(args.0, args.1, args.2, args.3)
                .unwrap_err()
                .to_string();
            assert!(e.contains(name), "{e}");
        }
        assert!(FluidHeat::new(0.0, 4186.0, 1000.0, 0.0).is_ok());
        let bad: Result<FluidHeat, _> = serde_json::from_str(
            r#"{"conductivity":0.6,"capacity":4186,"density":1000,"transfer":-1}"#,
        );
        assert!(bad.is_err());
    }

    #[test]
    fn median_dual_rates_sum_to_the_nodal_flows() {
        // A constant flux through a triangle: each node's net outflow over its dual
        // segments equals the flux through its half of the two outer edges.
        let m = [[0.0, 0.0, 0.0], [2.0, 0.1, 0.0], [0.3, 1.5, 0.2]];
        let q = [0.7, -0.4, 0.05];
        let g = channel_geometry(3, &m, q);
        let mut out = [0.0; 3];
        for (e, &(i, j, _)) in edges(3).iter().enumerate() {
            out[i] += g.rate[e];
            out[j] -= g.rate[e];
        }
        // The nodal flow of linear elements: −A ∇N_i · q (outflow positive).
        let nrm = cross(sub(m[1], m[0]), sub(m[2], m[0]));
        let a2 = dot(nrm, nrm);
        for i in 0..3 {
            let (j, k) = ((i + 1) % 3, (i + 2) % 3);
            // ∇N_i = n̂ × (x_k − x_j) / (2A) with n̂ = nrm/|nrm|: A ∇N_i = nrm × e / (2|nrm|²)·|nrm|.
            let e = sub(m[k], m[j]);
            let c = cross(nrm, e);
            let grad_a: [f64; 3] = std::array::from_fn(|d| 0.5 * c[d] / a2.sqrt());
            let flow = -dot(grad_a, q);
            assert!(
                (out[i] - flow).abs() < 1e-12,
                "node {i}: {} vs {flow}",
                out[i]
            );
        }
    }

    proptest! {
        /// The point-implicit update is a weighted mean: the new temperature lies within
        /// the old, inflow and wall temperatures, at any step (no overshoot).
        #[test]
        fn implicit_update_never_overshoots(
            t in -50.0f64..150.0, tu in -50.0f64..150.0, tw in -50.0f64..150.0,
            c in 0.0f64..1e4, a in 0.0f64..1e3, h in 0.0f64..1e3, dt in 1e-3f64..1e7,
        ) {
            let new = implicit_update(t, c, dt, a, a * tu, h, h * tw, 0.0);
            let lo = t.min(tu).min(tw);
            let hi = t.max(tu).max(tw);
            prop_assert!(new >= lo - 1e-9 * hi.abs().max(1.0) && new <= hi + 1e-9 * hi.abs().max(1.0),
                "{new} outside [{lo}, {hi}]");
        }
    }
}
