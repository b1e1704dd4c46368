//! The bolts as one physics: bolt nodes with their own lumped masses, axial bar forces,
//! grout coupling to the host elements, face plates; and [`BoltBoundary`], the
//! conditions on bolt nodes (a physics of its own, whose forces count as applied loads).

use pcdc_compute::{
    names, ComputeError, Entity, EntityKind, EntitySet, FieldId, FieldStore, FieldUse, Fingerprint,
    ForceContext, InitContext, KinematicNodes, Kinematics, Physics, StableStep, VelocityContext,
};
use pcdc_mesh::{Dim, Mesh};

use crate::boundary::{BcKind, BoltBc, BoltNodes, ResolvedBc};
use crate::fields::*;
use crate::host::Locator;
use crate::material::AxialLaw;
use crate::path::{self, PathElement, PathNodes};
use crate::walk::{self, blocks, relative_disp, Active, BLOCK_NODES, PARALLEL_FROM};
use crate::{Bolt, BoltError, NAME};

/// A segment: its two simulation nodes, reference length and law.
#[derive(Clone, Debug)]
pub(crate) struct Segment {
    pub n: [u32; 2],
    /// Reference vector from node 0 to node 1 (m; z = 0 in 2D).
    pub dx: [f64; 3],
    pub l0: f64,
    pub law: AxialLaw,
    /// E_b A_b / L₀ (N/m), as [`AxialLaw::update`] computes it.
    pub k: f64,
    /// An elongation (m) below which the strain is surely below the failure strain
    /// (`walk::fail_below`), so that the walk divides by L₀ only near failure.
    pub fail_below: f64,
    /// Axial damping coefficient (N·s/m).
    pub damping: f64,
}

/// A bolt node: its simulation node, candidate hosts, the grout's stiffnesses over its
/// tributary length, its bond factor, neighbouring segments and plate. Its current host
/// and grout point are state (the field [`BOLT_ANCHOR`]).
#[derive(Clone, Debug)]
pub(crate) struct BoltNode {
    pub node: u32,
    /// Its candidate hosts: `[first, end)` in [`Bolts::path`] (the elements its bolt's
    /// path crosses between its neighbours; see `path.rs`).
    pub cand: [u32; 2],
    /// K_b,r,s l (N/m), 0 on the free length.
    pub k_axial: f64,
    /// Lateral grout stiffness × l (N/m).
    pub k_normal: f64,
    /// Lateral grout damping D_b,f · 2 √(k_normal m) (N·s/m), 0 without damping.
    pub c_lateral: f64,
    /// Tributary length over the spacing (m): bond capacity = S_b(σn) × this.
    pub bond_length: f64,
    /// The bond capacity without confinement, S_b(0) × `bond_length` (N): the capacity
    /// never falls below it (S_b grows with σn ≥ 0), so a grout force within it is
    /// elastic whatever the confinement, and the host's stress need not be read.
    pub cap_unconfined: f64,
    /// Bond constants (eq. 146-147): π (D_b + 2 T_g), C_r,g, tan φ_r,g, π D_b, C_b,g,
    /// tan φ_b,g.
    pub bond: [f64; 6],
    /// Segments before and after (u32::MAX: none).
    pub prev: u32,
    pub next: u32,
    /// Face plate stiffness (N/m), 0 without.
    pub plate: f64,
    /// Lumped mass (kg, per unit thickness in 2D).
    pub mass: f64,
}

pub(crate) const NONE: u32 = u32::MAX;

/// Fully grouted rock bolts and cables (manual 7.9): compose after the mechanics (the
/// grout's confinement reads the host elements' stress of the previous step).
///
/// Each bolt adds its nodes to the simulation (physics-owned degrees of freedom with
/// lumped masses ρ_b A_b (L_b0 + L_b1)/2, integrated with the mesh nodes). Per step:
/// the axial force of every segment (eq. 138-142), the grout force at every bolt node
/// against its host element's motion interpolated at the node (eq. 143-147), the
/// reaction to the host's nodes with the same weights (action = reaction exactly), the
/// face plate at the head, and the axial damping (eq. 148). See the crate docs.
#[derive(Clone)]
pub struct Bolts {
    bolts: Vec<Bolt>,
    pub(crate) segments: Vec<Segment>,
    pub(crate) nodes: Vec<BoltNode>,
    /// The elements along every bolt's path, bolt after bolt: the candidate hosts, each
    /// with force slots of its own.
    pub(crate) path: Vec<PathElement>,
    /// The mesh nodes of the path elements, each with a force slot.
    pub(crate) path_nodes: PathNodes,
    /// Nodes, segments and path nodes of each bolt.
    pub(crate) spans: Vec<Span>,
    /// First segment index of each bolt.
    segment_offset: Vec<usize>,
    pub(crate) ids: Option<Ids>,
    /// The first bolt of each work block (see [`crate::walk::blocks`]): the unit of
    /// parallel work.
    pub(crate) blocks: Vec<usize>,
    /// [`crate::walk::PARALLEL_FROM`] and [`crate::walk::BLOCK_NODES`] (tests vary them).
    pub(crate) blocking: (usize, usize),
    /// Whether nodes are re-found when they leave their hosts ([`Bolts::fixed_hosts`]).
    relocate: bool,
    /// Each bolt node's current host, cached for the walk (see [`Active`]).
    pub(crate) active: Vec<Active>,
}

/// A bolt's share of the bolt nodes, segments and path nodes. Its force
/// slots: one per bolt node, then one per path node.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Span {
    pub nodes: usize,
    pub segments: usize,
    pub path_nodes: usize,
}

impl Span {
    /// Force slots of this bolt.
    pub fn slots(&self) -> usize {
        self.nodes + self.path_nodes
    }
}

#[derive(Clone, Copy, Debug)]
pub(crate) struct Ids {
    pub axial: FieldId,
    pub plastic: FieldId,
    pub state: FieldId,
    pub grout: FieldId,
    pub slip: FieldId,
    pub anchor: FieldId,
    pub host: FieldId,
    pub stress: FieldId,
    pub rotation: Option<FieldId>,
}

impl Default for Bolts {
    fn default() -> Self {
        Self::new()
    }
}

impl Bolts {
    /// No bolts yet.
    pub fn new() -> Self {
        Bolts {
            bolts: Vec::new(),
            segments: Vec::new(),
            nodes: Vec::new(),
            path: Vec::new(),
            path_nodes: PathNodes::default(),
            spans: Vec::new(),
            segment_offset: Vec::new(),
            ids: None,
            blocks: Vec::new(),
            blocking: (PARALLEL_FROM, BLOCK_NODES),
            relocate: true,
            active: Vec::new(),
        }
    }

    /// Keeps every bolt node grouted to the element found in the reference mesh for the
    /// whole run (no re-location, see the crate docs): the grout reactions then need
    /// force slots on the hosts' nodes only, not on every element the bolts cross. For
    /// support that does not slip or move further than an element, where the bolts'
    /// segments span several elements each (in the 22 600-element tunnel bench, 6.6
    /// elements per bolt node: measured in docs/performance.md).
    pub fn fixed_hosts(mut self) -> Self {
        self.relocate = false;
        self
    }

    /// Adds a bolt. Errors if another bolt has its name.
    pub fn bolt(mut self, bolt: Bolt) -> Result<Self, BoltError> {
        if self.bolts.iter().any(|b| b.name() == bolt.name()) {
            return Err(BoltError::Geometry {
                bolt: bolt.name().to_string(),
                reason: "another bolt has that name".into(),
            });
        }
        self.bolts.push(bolt);
        Ok(self)
    }

    /// The bolts, in the order added.
    pub fn bolts(&self) -> &[Bolt] {
        &self.bolts
    }

    /// The indices of bolt `b`'s nodes in the set [`BOLT_NODES`] (head first); `None`
    /// when there is no bolt `b`.
    pub fn node_range(&self, b: usize) -> Option<std::ops::Range<usize>> {
        let bolt = self.bolts.get(b)?;
        let first: usize = self.bolts[..b].iter().map(|x| x.points().len()).sum();
        Some(first..first + bolt.points().len())
    }

    /// The indices of bolt `b`'s segments in the set [`BOLT_SEGMENTS`] (head first);
    /// `None` when there is no bolt `b`.
    pub fn segment_range(&self, b: usize) -> Option<std::ops::Range<usize>> {
        let bolt = self.bolts.get(b)?;
        let first: usize = self.bolts[..b].iter().map(|x| x.segments()).sum();
        Some(first..first + bolt.segments())
    }

    /// A boundary physics for bolt nodes of these bolts (compose it after them).
    pub fn boundary(&self) -> BoltBoundary {
        BoltBoundary {
            bolts: self
                .bolts
                .iter()
                .enumerate()
                .map(|(b, x)| {
                    let s = x.material().properties().spacing.unwrap_or(1.0);
                    (x.name().to_string(), self.node_range(b).unwrap_or(0..0), s)
                })
                .collect(),
            items: Vec::new(),
            resolved: Vec::new(),
            accel: None,
        }
    }

    /// Builds segments, nodes and the paths' elements (hosts located in the reference
    /// mesh).
    /// Returns the initial [`BOLT_ANCHOR`] and [`BOLT_HOST`] values.
    fn build<D: Dim>(
        &mut self,
        mesh: &Mesh<D>,
        first: usize,
    ) -> Result<(Vec<f64>, Vec<f64>), BoltError> {
        let d = D::D;
        let two_d = d == 2;
        let locator = Locator::new(mesh);
        self.segments.clear();
        self.nodes.clear();
        self.path.clear();
        self.path_nodes = PathNodes::default();
        self.spans.clear();
        self.segment_offset.clear();
        let (mut anchor0, mut host0) = (Vec::new(), Vec::new());
        let mut node = first as u32;
        let mut x = vec![0.0; (d + 1) * d];
        for bolt in &self.bolts {
            let props = bolt.material().properties();
            if !two_d && props.spacing.is_some() {
                return Err(BoltError::param(
                    format!("spacing of bolt '{}'", bolt.name()),
                    props.spacing.unwrap_or(1.0),
                    "applies to 2D models only (a 3D model places every bolt)",
                ));
            }
            let eff = bolt.material().effective(two_d);
            let pts = bolt.points();
            let n = pts.len();
            let route = path::bolt_path(&locator, pts, self.relocate).map_err(|k| {
                BoltError::OutsideMesh {
                    bolt: bolt.name().to_string(),
                    node: k,
                    position: pts[k][..d].to_vec(),
                }
            })?;
            let path0 = self.path.len();
            self.path
                .extend(route.elements.iter().map(|&e| path::path_element(mesh, e)));
            self.spans.push(Span {
                nodes: n,
                segments: n - 1,
                path_nodes: 0,
            });
            self.segment_offset.push(self.segments.len());
            let seg0 = self.segments.len() as u32;
            for s in 0..n - 1 {
                let l0 = bolt.segment_length(s);
                self.segments.push(Segment {
                    n: [node + s as u32, node + s as u32 + 1],
                    dx: std::array::from_fn(|k| pts[s + 1][k] - pts[s][k]),
                    l0,
                    law: eff.axial,
                    k: eff.axial.ea / l0,
                    fail_below: walk::fail_below(eff.axial.failure_strain, l0),
                    damping: eff.damping,
                });
            }
            let free = bolt.free();
            for k in 0..n {
                let lp = if k > 0 {
                    bolt.segment_length(k - 1)
                } else {
                    0.0
                };
                let ln = if k + 1 < n {
                    bolt.segment_length(k)
                } else {
                    0.0
                };
                let l = 0.5 * (lp + ln);
                let grouted = free <= 0.0 || bolt.arc_length(k) >= free * (1.0 - 1e-9);
                let window = route.windows[k];
                let (local, host) = route.hosts[k];
                let index = self.nodes.len() as u32;
                for pe in &mut self.path[path0 + window[0]..path0 + window[1]] {
                    pe.node_range = [pe.node_range[0].min(index), pe.node_range[1].max(index + 1)];
                }
                // The grout point: the node itself in its host, no offset, and the
                // distance it may move along the bolt before it could leave the host.
                mesh.element_coords(host.element, &mut x);
                let wmin = host.weights[..=d]
                    .iter()
                    .cloned()
                    .fold(f64::INFINITY, f64::min);
                anchor0.push((local - window[0]) as f64);
                anchor0.extend_from_slice(&host.weights[..=d]);
                anchor0.extend(std::iter::repeat_n(0.0, d));
                anchor0.push(walk::margin(wmin, crate::host::min_height(d, &x)));
                anchor0.push(0.0);
                host0.push(host.element as f64);
                let bond = bolt.material().bond_constants();
                self.nodes.push(BoltNode {
                    node: node + k as u32,
                    cand: [(path0 + window[0]) as u32, (path0 + window[1]) as u32],
                    k_axial: if grouted { eff.shear * l } else { 0.0 },
                    k_normal: eff.normal * l,
                    c_lateral: eff.damping_factor
                        * 2.0
                        * (eff.normal * l * eff.mass_per_length * l).sqrt(),
                    bond_length: l * eff.bond_per_spacing,
                    cap_unconfined: crate::material::bond_strength(&bond, 0.0)
                        * (l * eff.bond_per_spacing),
                    bond,
                    prev: if k > 0 { seg0 + k as u32 - 1 } else { NONE },
                    next: if k + 1 < n { seg0 + k as u32 } else { NONE },
                    plate: if k == 0 {
                        bolt.plate().map_or(0.0, |p| p * eff.bond_per_spacing)
                    } else {
                        0.0
                    },
                    mass: eff.mass_per_length * l,
                });
            }
            let added = self.path_nodes.add_bolt(d, &mut self.path, path0);
            if let Some(span) = self.spans.last_mut() {
                span.path_nodes = added;
            }
            node += n as u32;
        }
        Ok((anchor0, host0))
    }

    /// Whether segment `s` lies in its bolt's free length (its midpoint does).
    fn segment_is_free(&self, b: usize, local: usize) -> bool {
        let bolt = &self.bolts[b];
        let mid = bolt.arc_length(local) + 0.5 * bolt.segment_length(local);
        mid < bolt.free()
    }
}

impl<D: Dim> Physics<D> for Bolts {
    fn name(&self) -> &str {
        NAME
    }

    fn entity_sets(&self, mesh: &Mesh<D>) -> Vec<EntitySet> {
        // Added nodes are numbered from the mesh's node count (the engine shifts them).
        let first = mesh.n_nodes() as u32;
        let mut seg = Vec::new();
        let mut nodes = Vec::new();
        let mut n = first;
        for b in &self.bolts {
            for s in 0..b.segments() as u32 {
                seg.extend_from_slice(&[n + s, n + s + 1]);
            }
            nodes.extend(n..n + b.points().len() as u32);
            n += b.points().len() as u32;
        }
        vec![
            EntitySet::new(BOLT_SEGMENTS, 2, seg).expect("two nodes per segment"),
            EntitySet::new(BOLT_NODES, 1, nodes).expect("one node per entity"),
        ]
    }

    fn fields(&self, _mesh: &Mesh<D>) -> Vec<FieldUse> {
        let mut f = vec![
            BOLT_AXIAL_FORCE.own::<D>(),
            BOLT_PLASTIC_ELONGATION.own::<D>(),
            BOLT_STATE.own::<D>(),
            BOLT_GROUT_FORCE.own::<D>(),
            BOLT_SLIP.own::<D>(),
            BOLT_ANCHOR.own_sized::<D>(anchor_len(D::D)),
            BOLT_HOST.own::<D>(),
            names::STRESS.read_lagged::<D>(),
        ];
        if D::D == 3 {
            f.push(names::ROTATION.read_lagged::<D>());
        }
        f
    }

    fn init(&mut self, ctx: &mut InitContext<'_, D>) -> Result<(), ComputeError> {
        if self.bolts.is_empty() {
            return Err(ComputeError::param(
                "bolts",
                0,
                "add at least one bolt (Bolts::bolt)",
            ));
        }
        let d = D::D;
        let first = ctx.n_nodes();
        let (anchor0, host0) = self.build(ctx.mesh, first)?;
        let mut coords = Vec::with_capacity(self.nodes.len() * d);
        for b in &self.bolts {
            for p in b.points() {
                coords.extend_from_slice(&p[..d]);
            }
        }
        let mass: Vec<f64> = self.nodes.iter().map(|n| n.mass).collect();
        let block = ctx.add_nodes(&coords, &mass)?;
        debug_assert_eq!(block.first, first);
        // Slots, bolt after bolt: one per bolt node, then one per node of the elements
        // on its path (the grout reactions of the nodes they host, summed in node order).
        let mut slot_nodes = Vec::new();
        let (mut i, mut j) = (0, 0);
        for span in &self.spans {
            slot_nodes.extend(self.nodes[i..i + span.nodes].iter().map(|n| n.node));
            let pn = &self.path_nodes.nodes[j..j + span.path_nodes];
            slot_nodes.extend(pn.iter().map(|p| p.node));
            (i, j) = (i + span.nodes, j + span.path_nodes);
        }
        ctx.register_slots(&slot_nodes)?;
        let ids = Ids {
            axial: ctx.fields.id(BOLT_AXIAL_FORCE)?,
            plastic: ctx.fields.id(BOLT_PLASTIC_ELONGATION)?,
            state: ctx.fields.id(BOLT_STATE)?,
            grout: ctx.fields.id(BOLT_GROUT_FORCE)?,
            slip: ctx.fields.id(BOLT_SLIP)?,
            anchor: ctx.fields.id(BOLT_ANCHOR)?,
            host: ctx.fields.id(BOLT_HOST)?,
            stress: ctx.fields.id(names::STRESS)?,
            rotation: if d == 3 {
                Some(ctx.fields.id(names::ROTATION)?)
            } else {
                None
            },
        };
        // Pretension: the free segments' natural length is shorter by f_pre L0 / EA.
        let mut plastic = vec![0.0; self.segments.len()];
        for (b, bolt) in self.bolts.iter().enumerate() {
            let pre = bolt.material().effective(d == 2).pretension;
            for local in 0..bolt.segments() {
                if pre > 0.0 && self.segment_is_free(b, local) {
                    let s = &self.segments[self.segment_offset[b] + local];
                    plastic[self.segment_offset[b] + local] = -pre * s.l0 / s.law.ea;
                }
            }
        }
        ctx.fields.get_mut(ids.plastic).copy_from_slice(&plastic);
        ctx.fields.get_mut(ids.anchor).copy_from_slice(&anchor0);
        ctx.fields.get_mut(ids.host).copy_from_slice(&host0);
        let alen = anchor_len(d);
        self.active = self
            .nodes
            .iter()
            .enumerate()
            .map(|(i, n)| {
                let j = n.cand[0] as usize + anchor0[i * alen] as usize;
                Active::of(j, &self.path[j])
            })
            .collect();
        self.ids = Some(ids);
        self.blocks = blocks(&self.spans, self.blocking);
        Ok(())
    }

    fn add_mass(&self, _mesh: &Mesh<D>, f: &FieldStore, mass: &mut [f64], scale: Option<f64>) {
        // Physical masses came with the nodes (InitContext::add_nodes). For static
        // relaxation's mass scaling (critical step `t` everywhere): each bolt node gets
        // m = S t² / 4 with S its Gershgorin row sum, and each host node the row sum the
        // grout adds to it, 2 k w_q (the grout couples it to the bolt node and to the
        // host's other nodes with weights summing to 1). Doubled: Gershgorin's bound is
        // tight for a bar chain's zig-zag mode, and the relaxation's local damping can
        // add up to the force's own magnitude to it (α ≤ 1), which made it diverge.
        let Some(t) = scale else { return };
        let q = 2.0 * t * t / 4.0;
        let d = D::D;
        let alen = anchor_len(d);
        // The current hosts (init has run: the engine lumps masses after it).
        let Some(ids) = self.ids else { return };
        let anchor = f.get(ids.anchor);
        for (i, n) in self.nodes.iter().enumerate() {
            let a = &anchor[i * alen..(i + 1) * alen];
            let host = &self.path[n.cand[0] as usize + a[0] as usize];
            let k = n.k_axial.max(n.k_normal) + n.plate;
            let mut s = k;
            for seg in [n.prev, n.next] {
                if seg != NONE {
                    let seg = &self.segments[seg as usize];
                    s += 2.0 * seg.law.ea / seg.l0;
                }
            }
            mass[n.node as usize] += s * q;
            for q_ in 0..=d {
                mass[host.nodes[q_] as usize] += 2.0 * k * a[1 + q_].abs() * q;
            }
        }
    }

    fn stable_step(&self, _kin: &Kinematics<'_, D>, _fields: &FieldStore) -> Option<StableStep> {
        // Gershgorin per bolt node (hosts taken as fixed): ω² ≤ (Σ 2 EA/L₀ + k_grout +
        // k_plate) / m; axial and lateral damping lower the step by √(1 + ζ²) − ζ.
        let mut best: Option<StableStep> = None;
        for (i, n) in self.nodes.iter().enumerate() {
            let (mut k, mut c) = (n.k_axial.max(n.k_normal) + n.plate, n.c_lateral);
            for s in [n.prev, n.next] {
                if s != NONE {
                    let seg = &self.segments[s as usize];
                    k += 2.0 * seg.law.ea / seg.l0;
                    c += 2.0 * seg.damping;
                }
            }
            let omega = (k / n.mass).sqrt();
            let zeta = c / (2.0 * n.mass * omega);
            let dt = 2.0 / omega * ((1.0 + zeta * zeta).sqrt() - zeta);
            if best.as_ref().is_none_or(|b| dt < b.dt) {
                best = Some(StableStep {
                    dt,
                    entity: Entity::new(EntityKind::Other("bolt node"), i),
                    physics: NAME.into(),
                });
            }
        }
        best
    }

    fn writes_all_slots(&self) -> bool {
        true
    }

    fn runs_beside(&self) -> bool {
        // The walk is short and serial below 2 048 bolt nodes: beside a heavy physics it
        // keeps the pool's other threads busy (docs/performance.md); it reads only the
        // fields it declares.
        true
    }

    fn kinematic_nodes(&self) -> KinematicNodes {
        // No kinematic conditions here (they are `BoltBoundary`'s): the engine keeps its
        // fused node pass.
        KinematicNodes::None
    }

    fn compute_forces(&mut self, ctx: &mut ForceContext<'_, D>) -> Result<(), ComputeError> {
        // The walk on the backend's pool (its thread count; a parallel iterator outside
        // it runs on rayon's global pool), entered once per step.
        let backend = ctx.backend;
        backend.install(|| self.walk(ctx))
    }

    fn stored_energy(&self, kin: &Kinematics<'_, D>, fields: &FieldStore) -> f64 {
        // Elastic energy of the bars and of the grout springs at the current state.
        let Some(ids) = self.ids else { return 0.0 };
        let axial = fields.get(ids.axial);
        let grout = fields.get(ids.grout);
        let anchor = fields.get(ids.anchor);
        let alen = anchor_len(D::D);
        let mut e = 0.0;
        for (s, seg) in self.segments.iter().enumerate() {
            e += 0.5 * axial[s] * axial[s] * seg.l0 / seg.law.ea;
        }
        for (i, n) in self.nodes.iter().enumerate() {
            if n.k_axial > 0.0 {
                e += 0.5 * grout[i] * grout[i] / n.k_axial;
            }
            let a = &anchor[i * alen..(i + 1) * alen];
            let host = &self.path[n.cand[0] as usize + a[0] as usize];
            let r = relative_disp(n.node, &host.nodes, a, kin);
            e += 0.5 * n.k_normal * (r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
        }
        e
    }

    fn check_fields(&self, fields: &FieldStore) -> Result<(), ComputeError> {
        let Some(ids) = self.ids else { return Ok(()) };
        if let Some(v) = fields
            .get(ids.state)
            .iter()
            .find(|v| !(**v >= 0.0 && **v <= 3.0 && v.fract() == 0.0))
        {
            return Err(ComputeError::SnapshotCorrupt(format!(
                "bolt segment state {v} is not one of 0, 1, 2, 3"
            )));
        }
        // The grout points: a candidate index in range (the step indexes with it), finite
        // weights, offsets and margins, and the host element that index names.
        let d = D::D;
        let alen = anchor_len(d);
        let (anchor, host) = (fields.get(ids.anchor), fields.get(ids.host));
        for (i, n) in self.nodes.iter().enumerate() {
            let a = &anchor[i * alen..(i + 1) * alen];
            let count = (n.cand[1] - n.cand[0]) as f64;
            let bad = if !(a[0] >= 0.0 && a[0] < count && a[0].fract() == 0.0) {
                Some(format!("candidate host {} of {count}", a[0]))
            } else if a.iter().any(|v| !v.is_finite()) || a[2 * d + 2] < 0.0 {
                Some("a weight, offset or margin that is not finite or a negative margin".into())
            } else if host[i] != self.path[n.cand[0] as usize + a[0] as usize].element as f64 {
                Some(format!(
                    "host element {} that is not its candidate's",
                    host[i]
                ))
            } else {
                None
            };
            if let Some(why) = bad {
                return Err(ComputeError::SnapshotCorrupt(format!(
                    "bolt node {i} has {why}"
                )));
            }
        }
        Ok(())
    }

    fn fingerprint(&self) -> u64 {
        // The bolts' geometry and properties (Debug prints every value exactly).
        let mut f = Fingerprint::new();
        for b in &self.bolts {
            f = f.debug(b);
        }
        f.debug(&self.relocate).finish()
    }

    fn gpu_setup(
        &mut self,
        setup: &mut pcdc_compute::gpu::GpuSetup<'_, D>,
    ) -> Result<(), ComputeError> {
        crate::gpu::bolts(self, setup)
    }

    fn slot_entity(&self, slot: usize) -> Option<String> {
        // Bolt after bolt: one slot per bolt node, then one per path node.
        let (mut first, mut pn0) = (0, 0);
        for (b, span) in self.spans.iter().enumerate() {
            let local = slot.checked_sub(first)?;
            if local < span.slots() {
                let name = self.bolts[b].name();
                return Some(if local < span.nodes {
                    format!("bolt '{name}' node {local}")
                } else {
                    let m = self.path_nodes.nodes[pn0 + local - span.nodes].node;
                    format!("bolt '{name}' grout reaction on node {m}")
                });
            }
            first += span.slots();
            pn0 += span.path_nodes;
        }
        None
    }
}

/// Boundary conditions on bolt nodes (manual 7.9.4, tables 20-21), made by
/// [`Bolts::boundary`] and composed after the bolts. Forces count as applied loads in
/// the energy balance.
pub struct BoltBoundary {
    /// Name, range in the bolt-node set and spacing of every bolt.
    bolts: Vec<(String, std::ops::Range<usize>, f64)>,
    items: Vec<BoltBc>,
    pub(crate) resolved: Vec<ResolvedBc>,
    accel: Option<FieldId>,
}

impl BoltBoundary {
    fn add(
        mut self,
        bolt: &str,
        nodes: BoltNodes,
        kind: BcKind,
        values: [Option<pcdc_compute::TimeValue>; 3],
    ) -> Result<Self, BoltError> {
        let Some((_, range, _)) = self.bolts.iter().find(|(n, _, _)| n == bolt) else {
            return Err(BoltError::Geometry {
                bolt: bolt.to_string(),
                reason: "a boundary condition names a bolt that does not exist".into(),
            });
        };
        for (k, v) in values.iter().enumerate() {
            if let Some(v) = v {
                v.check(&format!("bolt '{bolt}' boundary component {k}"))?;
            }
        }
        let item = BoltBc {
            bolt: bolt.to_string(),
            nodes,
            kind,
            values,
        };
        item.local_nodes(range.len())?;
        self.items.push(item);
        Ok(self)
    }

    /// Prescribed velocity (m/s) per component (`None`: free) on `nodes` of `bolt`.
    pub fn velocity(
        self,
        bolt: &str,
        nodes: BoltNodes,
        values: [Option<pcdc_compute::TimeValue>; 3],
    ) -> Result<Self, BoltError> {
        self.add(bolt, nodes, BcKind::Velocity, values)
    }

    /// Prescribed acceleration (m/s²) per component; the velocity is integrated from
    /// rest.
    pub fn acceleration(
        self,
        bolt: &str,
        nodes: BoltNodes,
        values: [Option<pcdc_compute::TimeValue>; 3],
    ) -> Result<Self, BoltError> {
        self.add(bolt, nodes, BcKind::Acceleration, values)
    }

    /// A force (N, per bolt: divided by the spacing in 2D) on each of `nodes`.
    pub fn force(
        self,
        bolt: &str,
        nodes: BoltNodes,
        values: [Option<pcdc_compute::TimeValue>; 3],
    ) -> Result<Self, BoltError> {
        self.add(bolt, nodes, BcKind::Force, values)
    }

    fn kinematic(&self) -> impl Iterator<Item = &ResolvedBc> {
        self.resolved.iter().filter(|r| r.kind != BcKind::Force)
    }
}

impl<D: Dim> Physics<D> for BoltBoundary {
    fn name(&self) -> &str {
        "bolt boundary"
    }

    fn fields(&self, _mesh: &Mesh<D>) -> Vec<FieldUse> {
        if self.items.iter().any(|i| i.kind == BcKind::Acceleration) {
            vec![BOLT_BC_VELOCITY.own::<D>()]
        } else {
            Vec::new()
        }
    }

    fn init(&mut self, ctx: &mut InitContext<'_, D>) -> Result<(), ComputeError> {
        let set = ctx.entity_set(BOLT_NODES).ok_or_else(|| {
            ComputeError::param(
                "bolt boundary",
                BOLT_NODES,
                "no bolts are composed before it: compose the Bolts it was made from first",
            )
        })?;
        let two_d = D::D == 2;
        self.resolved.clear();
        let mut slot_nodes = Vec::new();
        for item in &self.items {
            let (_, range, spacing) = self
                .bolts
                .iter()
                .find(|(n, _, _)| *n == item.bolt)
                .expect("checked when added");
            if range.end > set.len() {
                return Err(ComputeError::param(
                    "bolt boundary",
                    &item.bolt,
                    "made from other bolts than those composed",
                ));
            }
            let nodes: Vec<(u32, u32)> = item
                .local_nodes(range.len())?
                .into_iter()
                .map(|k| (set.nodes()[range.start + k], (range.start + k) as u32))
                .collect();
            if item.kind == BcKind::Force {
                slot_nodes.extend(nodes.iter().map(|n| n.0));
            }
            self.resolved.push(ResolvedBc {
                kind: item.kind,
                nodes,
                values: item.values.clone(),
                scale: if two_d { 1.0 / spacing } else { 1.0 },
            });
        }
        ctx.register_slots(&slot_nodes)?;
        self.accel = if self.items.iter().any(|i| i.kind == BcKind::Acceleration) {
            Some(ctx.fields.id(BOLT_BC_VELOCITY)?)
        } else {
            None
        };
        Ok(())
    }

    fn compute_forces(&mut self, ctx: &mut ForceContext<'_, D>) -> Result<(), ComputeError> {
        let d = D::D;
        let t = ctx.kin.time;
        let mut slot = 0;
        for r in self.resolved.iter().filter(|r| r.kind == BcKind::Force) {
            for _ in &r.nodes {
                for k in 0..d {
                    ctx.slots[slot * d + k] =
                        r.values[k].as_ref().map_or(0.0, |v| v.at(t)) * r.scale;
                }
                slot += 1;
            }
        }
        Ok(())
    }

    fn writes_all_slots(&self) -> bool {
        true
    }

    fn gpu_setup(
        &mut self,
        setup: &mut pcdc_compute::gpu::GpuSetup<'_, D>,
    ) -> Result<(), ComputeError> {
        crate::gpu::boundary(self, setup)
    }

    fn applies_loads(&self) -> bool {
        true
    }

    fn kinematic_nodes(&self) -> KinematicNodes {
        let nodes: Vec<u32> = self
            .kinematic()
            .flat_map(|r| r.nodes.iter().map(|n| n.0))
            .collect();
        if nodes.is_empty() {
            KinematicNodes::None
        } else {
            KinematicNodes::Nodes(nodes)
        }
    }

    fn apply_kinematics(&mut self, ctx: &mut VelocityContext<'_, D>) {
        // As the mechanical boundary: velocities at the half step, accelerations at the
        // start of the step (`ctx.time` is the end of the step).
        let d = D::D;
        for r in &self.resolved {
            match r.kind {
                BcKind::Force => {}
                BcKind::Velocity => {
                    for &(n, _) in &r.nodes {
                        for k in 0..d {
                            if let Some(v) = &r.values[k] {
                                ctx.v[n as usize * d + k] = v.at(ctx.time - 0.5 * ctx.dt);
                            }
                        }
                    }
                }
                BcKind::Acceleration => {
                    let id = self.accel.expect("declared with accelerations");
                    let acc = ctx.fields.get_mut(id);
                    for &(n, b) in &r.nodes {
                        for k in 0..d {
                            if let Some(v) = &r.values[k] {
                                let w = &mut acc[b as usize * d + k];
                                *w += v.at(ctx.time - ctx.dt) * ctx.dt;
                                ctx.v[n as usize * d + k] = *w;
                            }
                        }
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Bolt, BoltMaterial, BoltProperties};
    use pcdc_compute::{Backend, Simulation};
    use pcdc_mech::{Boundary, LinearElastic, Mechanics};
    use pcdc_mesh::{builders, Dim2, Range};

    #[test]
    fn blocks_hold_whole_bolts_and_start_parallel_work_at_the_threshold() {
        // Bolts of 3, 5, 3, 4 nodes (2, 4, 2, 3 segments).
        let spans: Vec<Span> = [3, 5, 3, 4]
            .iter()
            .map(|&n| Span {
                nodes: n,
                segments: n - 1,
                path_nodes: n + 2,
            })
            .collect();
        assert_eq!(blocks(&spans, (16, 4)), vec![0]);
        assert_eq!(
            blocks(&spans, (15, 4)),
            vec![0, 2],
            "whole bolts of at least 4 nodes"
        );
        assert_eq!(blocks(&spans, (1, 1)).len(), 4);
    }

    /// A plate under gravity with 60 pretensioned, plated bolts, run with `blocking` on
    /// `threads` threads (its base held by a boundary physics, which the bolts may run
    /// beside).
    fn bolted_plate(blocking: (usize, usize), threads: usize) -> Simulation<Dim2> {
        let mesh = builders::rectangle(0.0, 0.0, 4.0, 1.0, 0.1).unwrap();
        let props = BoltProperties {
            cohesion_rock_grout: 2e3,
            pretension: 4e4,
            ..BoltProperties::steel_rebar(0.02)
        };
        let material = BoltMaterial::new(props).unwrap();
        let mut bolts = Bolts::new();
        for i in 0..60 {
            let x = 0.05 + 3.9 * i as f64 / 59.0;
            let (head, tail) = ([x, 0.97, 0.0], [x + 0.02, 0.1 + 0.01 * i as f64, 0.0]);
            let bolt = Bolt::straight(format!("B{i}"), head, tail, 10, material)
                .unwrap()
                .free_length(0.2)
                .unwrap()
                .face_plate(1e7)
                .unwrap();
            bolts = bolts.bolt(bolt).unwrap();
        }
        bolts.blocking = blocking;
        let rock = LinearElastic::new(2e8, 0.25, 2000.0).unwrap();
        Simulation::builder(mesh, Backend::cpu(threads).unwrap())
            .physics(Mechanics::new().material(Range::All, rock))
            .physics(Boundary::new().fix(Range::group("bottom")))
            .physics(bolts)
            .gravity([0.0, -9.81, 0.0])
            .build()
            .unwrap()
    }

    #[test]
    fn bolts_split_in_blocks_give_the_single_block_result_bit_for_bit() {
        let (mut one, mut split) = (bolted_plate((usize::MAX, 1), 2), bolted_plate((1, 50), 2));
        one.run(300).unwrap();
        split.run(300).unwrap();
        assert_eq!(one.state.u, split.state.u);
        for name in [BOLT_AXIAL_FORCE, BOLT_GROUT_FORCE, BOLT_SLIP, BOLT_STATE] {
            assert_eq!(
                one.field(name).unwrap(),
                split.field(name).unwrap(),
                "{name:?}"
            );
        }
        // Something happened: the bolts carry force and the grout has slipped somewhere.
        let axial = one.field(BOLT_AXIAL_FORCE).unwrap();
        assert!(axial.iter().any(|f| f.abs() > 1e3), "{axial:?}");
        assert!(one.field(BOLT_SLIP).unwrap().iter().any(|s| *s != 0.0));
    }

    #[test]
    fn bolts_beside_another_physics_give_the_one_thread_result_bit_for_bit() {
        let (mut one, mut two) = (bolted_plate(BLOCKING, 1), bolted_plate(BLOCKING, 2));
        // The bolts read the mechanics' stress, so they pair with the boundary after it.
        assert_eq!(two.physics_beside(), vec![("mechanical boundary", NAME)]);
        one.run(300).unwrap();
        two.run(300).unwrap();
        assert_eq!(one.state.u, two.state.u);
        for name in [BOLT_AXIAL_FORCE, BOLT_GROUT_FORCE, BOLT_SLIP, BOLT_ANCHOR] {
            assert_eq!(
                one.field(name).unwrap(),
                two.field(name).unwrap(),
                "{name:?}"
            );
        }
    }

    const BLOCKING: (usize, usize) = (PARALLEL_FROM, BLOCK_NODES);
}
