//! The contact physics (2D triangles and 3D tetrahedra): a sorted-grid broad phase with
//! a skin and element-centric, deterministic assembly of Munjiza's potential contact
//! force ([`crate::triangle_pair_force`] in 2D, [`crate::tet_pair_force`] in 3D).
//!
//! Every element keeps a candidate list of elements whose bounding boxes, inflated by
//! the skin, overlap its own; the lists are rebuilt when any node has moved more than
//! half the skin since the last build, and each list is sorted by element index, so
//! the summation order does not depend on when a list was built. On the CPU each pair
//! is evaluated once, by its lower-index element (the contactor), which keeps its own
//! share and hands the target's share to a second, ordered pass: element e's forces
//! are its contactor shares in list order, then its target shares with contactors in
//! ascending order, whatever the thread count. On the GPU (one invocation per element,
//! no atomics) each element evaluates its pairs in the same canonical order and keeps
//! the share that lands on its own nodes. Either way action equals reaction exactly.
//! Elements sharing a node (one continuous body) do not contact each other.
//!
//! Per pair the physics keeps the law's history, carried across rebuilds and snapshots:
//! for `contact-m-c` the accumulated slip δ_s of the friction law (eq. 59-60) and, with
//! contact damping (eq. 61), the largest trial normal stress reached and the stress held
//! there.
//!
//! # State in fields
//!
//! Everything that evolves lives in fields, in one layout that the CPU path and the GPU
//! kernels share, so a snapshot of either backend holds the whole contact state and a
//! restore continues bit for bit:
//!
//! - [`CONTACT_REFERENCE`] (per node, D values): node positions at the last broad-phase
//!   build (NaN before the first build, which forces one);
//! - [`CONTACT_CANDIDATE_COUNT`] (per element, 1 value): the length n of the element's
//!   candidate list;
//! - [`CONTACT_CANDIDATES`] (per element, `capacity` values): the list, partner element
//!   indices stored as reals (exact: below 2^53, and below 2^24 for f32 kernels, which
//!   the GPU setup checks), strictly increasing; entries from n on are 0;
//! - [`CONTACT_HISTORY`] (per element, `capacity × s` values, s = the law's
//!   [`ContactModel::n_state`], at least 1): the history of pair k at `k s .. (k + 1) s`,
//!   in list order; both elements of a pair keep identical copies (the CPU updates the
//!   contactor's and copies a change into the target's row); entries from n s on are 0.
//!
//! The capacity per element is fixed when the simulation is built ([`Contact::capacity`];
//! default twice the largest list of the initial configuration, at least 48): a rebuild
//! that finds more candidates for an element stops the run with an error naming the
//! element, on both backends, never dropping a pair silently. The physics struct keeps
//! only parameters and data derived once from the mesh. A restore checks the lists
//! (range, order, symmetry, zero tails) before accepting them
//! ([`Physics::check_fields`]).
//!
//! Elements bonded by an intact cohesive joint do not contact each other once the bonds
//! are declared, from the mesh's interfaces with [`Contact::bonded_interfaces`] or as
//! lists with [`Contact::bonded_pairs`]; the pair becomes a contact pair as soon as the
//! joint's broken-face flag is set (the cohesive crate publishes it). With bonds
//! declared, contact also skips pairs inside intact rock: pairs sharing a vertex whose
//! bonds all hold, and every pair with a sealed element (all its vertices surrounded by
//! intact bonds); they enter the narrow phase once a joint at one of their vertices
//! breaks. The rules and why they lose no contact are in the `exclusion` module.
//!
//! The contact law (eq. 59-61) sees per pair a trial normal stress σ_try = |F_n| / A over
//! a contact measure A, a contact length h and a scalar slip increment:
//!
//! - 2D (per unit thickness): A = h, h the mean edge length of the two triangles; the
//!   tangent is the normal turned counter-clockwise and the slip increment is signed,
//!   Δδ = v_t Δt.
//! - 3D: A = h², h the mean edge length of the two tetrahedra (the manual's h is the
//!   square root of the contact area). The normal n is the direction of the contactor's
//!   total normal force; the tangential direction is that of the pair's relative
//!   tangential velocity v_t = v_rel − (v_rel · n) n, and the slip increment is
//!   Δδ = |v_t| Δt ≥ 0 along it. The accumulated slip δ_s of the law is therefore a
//!   scalar along the current sliding direction: the shear force min(P_t |δ_s| / h,
//!   tan φ σ_n) h² always opposes the current sliding velocity (purely dissipative, no
//!   stored tangential spring force when the sliding direction turns), and no shear acts
//!   while v_t = 0.

use pcdc_compute::{Components, FieldAccess, FieldKey, FieldUse, Place};
use pcdc_compute::{
    ComputeError, FieldId, FieldStore, Fingerprint, ForceContext, InitContext, Kinematics, Physics,
    StableStep,
};
use pcdc_compute::{Entity, EntityKind, KinematicNodes};
use pcdc_mesh::{Dim, Mesh};
use rayon::prelude::*;

use std::sync::Arc;

use crate::active::ActiveSet;
use crate::exclusion::BondedRegions;
use crate::model::{CachedMohrCoulomb, ContactDamping, ContactModel, Friction, MohrCoulombContact};
use crate::pair_pass::{boxes_apart, pair_pass};
use crate::{tet_pair_force, triangle_pair_force, PairForce2, PairForce3};

/// Node positions at the last broad-phase build (m), stride D (node field).
pub const CONTACT_REFERENCE: FieldKey = FieldKey::new(
    "contact_reference_positions",
    Place::Node,
    Components::Vector,
);

/// Length of every element's candidate list (element field, 1 value).
pub const CONTACT_CANDIDATE_COUNT: FieldKey = FieldKey::new(
    "contact_candidate_count",
    Place::Element,
    Components::Fixed(1),
);

/// Candidate lists: per element `capacity` partner indices, sorted, zero past the list's
/// length (element field; see the module docs).
pub const CONTACT_CANDIDATES: FieldKey =
    FieldKey::new("contact_candidates", Place::Element, Components::Declared);

/// Pair histories: per element and candidate the law's state values, in list order
/// (element field, `capacity × max(n_state, 1)` values; see the module docs).
pub const CONTACT_HISTORY: FieldKey =
    FieldKey::new("contact_pair_history", Place::Element, Components::Declared);

/// Smallest default candidate capacity per element.
const MIN_CAPACITY: usize = 48;

/// The error of an element whose candidates exceed the capacity (both backends).
pub(crate) fn overflow_message(e: u32, capacity: usize) -> String {
    format!(
        "element {e} has more than {capacity} contact candidates (the capacity per element); \
         raise Contact::capacity"
    )
}

/// Applies the contact law to a pair's normal (potential) forces: trial stress
/// σ_try = |F_n| / h, slip increment from the relative tangential velocity of the two
/// triangles (node velocities weighted by each node's share of the normal force), then
/// the normal forces are scaled to σ_n h and the shear force τ h is added along the
/// tangent with the same weights, equal and opposite on the two triangles.
fn apply_model<D: Dim>(
    pair: &mut PairForce2,
    kin: &Kinematics<'_, D>,
    c: usize,
    t: usize,
    model: &dyn ContactModel,
    h: f64,
    state: &mut [f64],
) {
    let fc = [
        pair.contactor.iter().map(|v| v[0]).sum::<f64>(),
        pair.contactor.iter().map(|v| v[1]).sum::<f64>(),
    ];
    let fn_mag = (fc[0] * fc[0] + fc[1] * fc[1]).sqrt();
    if fn_mag == 0.0 {
        model.separate(state);
        return;
    }
    let n = [fc[0] / fn_mag, fc[1] / fn_mag];
    let tang = [-n[1], n[0]];
    let weights = |forces: &[[f64; 2]; 3]| {
        let w: [f64; 3] = std::array::from_fn(|a| {
            (forces[a][0] * forces[a][0] + forces[a][1] * forces[a][1]).sqrt()
        });
        let sum: f64 = w.iter().sum();
        w.map(|x| if sum > 0.0 { x / sum } else { 1.0 / 3.0 })
    };
    let (wc, wt) = (weights(&pair.contactor), weights(&pair.target));
    let vel = |e: usize, w: &[f64; 3]| {
        let conn = kin.mesh.element(e);
        let mut v = [0.0; 2];
        for a in 0..3 {
            for d in 0..2 {
                v[d] += w[a] * kin.v[conn[a] as usize * D::D + d];
            }
        }
        v
    };
    let (vc, vt) = (vel(c, &wc), vel(t, &wt));
    let v_rel = (vc[0] - vt[0]) * tang[0] + (vc[1] - vt[1]) * tang[1];
    let s_try = fn_mag / h;
    let r = model.update_pair(c, t, s_try, v_rel * kin.dt, h, state);
    if r.normal != s_try {
        let scale = r.normal / s_try;
        for a in 0..3 {
            for k in 0..2 {
                pair.contactor[a][k] *= scale;
                pair.target[a][k] *= scale;
            }
        }
    }
    if r.shear != 0.0 {
        let ft = r.shear * h;
        for a in 0..3 {
            for d in 0..2 {
                pair.contactor[a][d] += wc[a] * ft * tang[d];
                pair.target[a][d] -= wt[a] * ft * tang[d];
            }
        }
    }
}

/// The 3D form of [`apply_model`] for a tetrahedron pair: trial stress
/// σ_try = |F_n| / h², slip increment |v_t| Δt along the relative tangential velocity
/// v_t of the two tetrahedra (node velocities weighted by each node's share of the
/// normal force; see the module docs), then the normal forces are scaled to σ_n h² and
/// the shear force τ h² is added along v_t / |v_t| with the same weights, equal and
/// opposite on the two tetrahedra.
fn apply_model3<D: Dim>(
    pair: &mut crate::PairForce3,
    kin: &Kinematics<'_, D>,
    c: usize,
    t: usize,
    model: &dyn ContactModel,
    h: f64,
    state: &mut [f64],
) {
    let fc: [f64; 3] = std::array::from_fn(|d| pair.contactor.iter().map(|v| v[d]).sum::<f64>());
    let fn_mag = (fc[0] * fc[0] + fc[1] * fc[1] + fc[2] * fc[2]).sqrt();
    if fn_mag == 0.0 {
        model.separate(state);
        return;
    }
    let n = fc.map(|x| x / fn_mag);
    let weights = |forces: &[[f64; 3]; 4]| {
        let w: [f64; 4] = std::array::from_fn(|a| {
            let f = forces[a];
            (f[0] * f[0] + f[1] * f[1] + f[2] * f[2]).sqrt()
        });
        let sum: f64 = w.iter().sum();
        w.map(|x| if sum > 0.0 { x / sum } else { 0.25 })
    };
    let (wc, wt) = (weights(&pair.contactor), weights(&pair.target));
    let vel = |e: usize, w: &[f64; 4]| {
        let conn = kin.mesh.element(e);
        let mut v = [0.0; 3];
        for a in 0..4 {
            for d in 0..3 {
                v[d] += w[a] * kin.v[conn[a] as usize * D::D + d];
            }
        }
        v
    };
    let (vc, vt) = (vel(c, &wc), vel(t, &wt));
    let rel: [f64; 3] = std::array::from_fn(|d| vc[d] - vt[d]);
    let vn = rel[0] * n[0] + rel[1] * n[1] + rel[2] * n[2];
    let tv: [f64; 3] = std::array::from_fn(|d| rel[d] - vn * n[d]);
    let vt_mag = (tv[0] * tv[0] + tv[1] * tv[1] + tv[2] * tv[2]).sqrt();
    let area = h * h;
    let s_try = fn_mag / area;
    let r = model.update_pair(c, t, s_try, vt_mag * kin.dt, h, state);
    if r.normal != s_try {
        let scale = r.normal / s_try;
        for a in 0..4 {
            for k in 0..3 {
                pair.contactor[a][k] *= scale;
                pair.target[a][k] *= scale;
            }
        }
    }
    if r.shear != 0.0 && vt_mag > 0.0 {
        let ft = r.shear * area;
        let tang = tv.map(|x| x / vt_mag);
        for a in 0..4 {
            for d in 0..3 {
                pair.contactor[a][d] += wc[a] * ft * tang[d];
                pair.target[a][d] -= wt[a] * ft * tang[d];
            }
        }
    }
}

/// Potential contact between all elements of the mesh (triangles in 2D, tetrahedra in
/// 3D).
#[derive(Debug)]
pub struct Contact {
    penalty: f64,
    friction: Option<Friction>,
    damping: Option<ContactDamping>,
    custom: Option<Arc<dyn ContactModel>>,
    /// The law in force (set by init): the custom model or `contact-m-c`.
    model: Option<Arc<dyn ContactModel>>,
    n_state: usize,
    /// Elements of the mesh (set by init; bounds the candidate indices of a restore).
    n_elements: usize,
    skin: Option<f64>,
    /// Candidate capacity per element set by the user.
    capacity: Option<usize>,
    bonds: Option<Bonds>,
    /// Vertex topology of the bonded regions (set by init when bonds are declared).
    regions: Option<BondedRegions>,
    /// Per-step scratch (derived from the positions every step).
    scratch: StepScratch,
    /// Sealed flags and watched nodes (derived from the broken bonds when they change).
    active: ActiveSet,
    skin_used: f64,
    /// The state fields (set by init).
    ids: Option<StateIds>,
}

/// What every element's candidates look up once per step besides the sealed flags
/// ([`ActiveSet`]): the box of an unsealed element's current corners (lows then highs,
/// stride 2 D), so that the first test of the pair potential costs a few loads per
/// candidate.
#[derive(Debug, Default)]
struct StepScratch {
    boxes: Vec<f64>,
    /// Per block of elements, the target shares of the pairs its elements evaluated
    /// (target element, forces), in evaluation order: kept between steps so that the
    /// pair pass allocates nothing once warm.
    shares2: Vec<Vec<(u32, [f64; 6])>>,
    shares3: Vec<Vec<(u32, [f64; 12])>>,
    /// Per block, the pair histories its contactors changed, to copy into the targets'
    /// rows: (target, contactor, the `ns` values), flat.
    mirrors: Vec<Vec<f64>>,
}

/// The contact physics' fields and their strides (see the module docs).
#[derive(Clone, Copy, Debug)]
struct StateIds {
    reference: FieldId,
    count: FieldId,
    candidates: FieldId,
    history: FieldId,
    /// Candidates per element.
    capacity: usize,
    /// History values per pair in the history field (the law's count, at least 1).
    stride: usize,
}

/// Element pairs bonded through a face (e.g. by a cohesive joint) and the face field
/// that says when the bond is broken.
#[derive(Clone, Debug)]
struct Bonds {
    /// Take the bonds from the mesh's interfaces at init (filling `elements` and `faces`).
    from_mesh: bool,
    /// Elements of each bond, stride 2.
    elements: Vec<u32>,
    /// One face of each bond.
    faces: Vec<u32>,
    /// Name of the face field: 0 = bonded (no contact), non-zero = broken (contact).
    field: String,
    id: Option<FieldId>,
    /// Per element: (bonded neighbour, face), sorted by neighbour.
    per_element: Vec<Vec<(u32, u32)>>,
}

impl Bonds {
    /// The bond face between elements `e` and `f`, if they are bonded.
    fn face(&self, e: usize, f: usize) -> Option<usize> {
        let list = &self.per_element[e];
        list.binary_search_by_key(&(f as u32), |b| b.0)
            .ok()
            .map(|i| list[i].1 as usize)
    }
}

impl Contact {
    /// Contact with normal penalty `penalty` (Pa; the manual's default is 10 E).
    pub fn new(penalty: f64) -> Self {
        Contact {
            penalty,
            friction: None,
            damping: None,
            custom: None,
            model: None,
            n_state: 0,
            n_elements: 0,
            skin: None,
            capacity: None,
            bonds: None,
            regions: None,
            scratch: StepScratch::default(),
            active: ActiveSet::default(),
            skin_used: 0.0,
            ids: None,
        }
    }

    /// Uses a user contact law instead of the built-in `contact-m-c` (its normal penalty
    /// replaces the one given to [`Contact::new`]; `friction` and `damping` are ignored).
    pub fn with_model(mut self, model: impl ContactModel + 'static) -> Self {
        self.custom = Some(Arc::new(model));
        self
    }

    /// Contact without a contact law (manual table 1): each element's surface friction
    /// angle (degrees) and contact penalty (Pa), e.g. from
    /// `pcdc_mech::Mechanics::surface_properties`; a pair takes the smaller of its two
    /// elements' values ([`crate::SurfaceContact`]). Replaces the penalty given to
    /// [`Contact::new`]; `friction` and `damping` are ignored.
    pub fn surface_defaults(self, friction_deg: Vec<f64>, penalty: Vec<f64>) -> Self {
        self.with_model(crate::SurfaceContact {
            friction_deg,
            penalty,
        })
    }

    /// Adds Coulomb friction (eq. 59-60, eq. 59 corrected): friction angle (degrees) and
    /// shear penalty P_t (Pa; τ = P_t δ_s / h before sliding, 10 E is a sensible value).
    pub fn friction(mut self, angle_deg: f64, shear_penalty: f64) -> Self {
        self.friction = Some(Friction {
            angle_deg,
            penalty: shear_penalty,
        });
        self
    }

    /// Adds contact damping (eq. 61, keywords `damping-t` and `damping-b` of table 8):
    /// transition stress T (Pa) and exponent b (≥ 1).
    pub fn damping(mut self, transition: f64, exponent: f64) -> Self {
        self.damping = Some(ContactDamping {
            transition,
            exponent,
        });
        self
    }

    /// Declares bonded element pairs that must not contact each other while bonded:
    /// `elements` holds the two elements of each bond (stride 2), `faces` one face per bond
    /// (the bond's face on either side), and `broken_field` names a face field that is 0
    /// while the bond holds and non-zero once it is broken. For FDEM regions from
    /// `pcdc_mesh::split_nodes`, [`Contact::bonded_interfaces`] says the same in one
    /// call.
    pub fn bonded_pairs(
        mut self,
        elements: &[u32],
        faces: &[u32],
        broken_field: impl AsRef<str>,
    ) -> Self {
        let broken_field = broken_field.as_ref();
        self.bonds = Some(Bonds {
            from_mesh: false,
            elements: elements.to_vec(),
            faces: faces.to_vec(),
            field: broken_field.to_string(),
            id: None,
            per_element: Vec::new(),
        });
        self
    }

    /// Declares the interfaces of the simulation's mesh ([`pcdc_mesh::Mesh::interfaces`],
    /// made by [`pcdc_mesh::split_nodes`]) as bonded pairs: the two elements of each
    /// interface do not contact each other while the face field `broken_field` is 0 on
    /// the interface's side-A face. With `pcdc_cohesive::BROKEN_FACE` the faces of
    /// broken cohesive joints become contact faces. The same as [`Contact::bonded_pairs`]
    /// with the interfaces' elements and side-A faces, read from the mesh at init (a mesh
    /// without interfaces has no bonds); it replaces an earlier bond declaration.
    pub fn bonded_interfaces(mut self, broken_field: impl AsRef<str>) -> Self {
        self.bonds = Some(Bonds {
            from_mesh: true,
            elements: Vec::new(),
            faces: Vec::new(),
            field: broken_field.as_ref().to_string(),
            id: None,
            per_element: Vec::new(),
        });
        self
    }

    /// Candidate-list capacity per element, on both backends (default: twice the
    /// largest list of the initial configuration, at least 48). The lists and pair
    /// histories are fields of this fixed size (see the module docs), so the capacity is
    /// part of the simulation's layout: a broad-phase build that finds more candidates
    /// for an element stops the run with an error naming the element, and a snapshot
    /// restores only into a simulation of the same capacity.
    pub fn capacity(mut self, capacity: usize) -> Self {
        self.capacity = Some(capacity);
        self
    }

    /// The former name of [`Contact::capacity`] (the capacity now applies on both
    /// backends).
    #[deprecated(note = "use Contact::capacity: the capacity applies on both backends")]
    pub fn gpu_capacity(self, capacity: usize) -> Self {
        self.capacity(capacity)
    }

    /// The law in force: the custom model or the built-in `contact-m-c`.
    fn law(&self) -> Arc<dyn ContactModel> {
        match &self.custom {
            Some(m) => m.clone(),
            None => Arc::new(CachedMohrCoulomb::new(MohrCoulombContact {
                normal_penalty: self.penalty,
                friction: self.friction,
                damping: self.damping,
            })),
        }
    }

    /// The skin for `mesh`: the one set, or half the smallest element edge.
    fn skin_for<D: Dim>(&self, mesh: &Mesh<D>) -> f64 {
        self.skin
            .unwrap_or_else(|| 0.5 * mesh.edge_length_range().0)
    }

    /// The candidate capacity per element for `mesh`: the one set, or twice the largest
    /// list of the CPU broad phase on the initial configuration, at least 48 (an invalid
    /// skin, which init reports, gives the minimum).
    fn capacity_for<D: Dim>(&self, mesh: &Mesh<D>) -> usize {
        if let Some(c) = self.capacity {
            return c;
        }
        let skin = self.skin_for(mesh);
        if !(skin > 0.0 && skin.is_finite()) || mesh.n_elements() == 0 {
            return MIN_CAPACITY;
        }
        let zeros = vec![0.0; mesh.n_nodes() * D::D];
        let mass = vec![0.0; mesh.n_nodes()];
        let kin = Kinematics {
            mesh,
            coords: mesh.coords(),
            mass: &mass,
            u: &zeros,
            v: &zeros,
            time: 0.0,
            dt: 0.0,
            step: 0,
            damping: false,
        };
        let lists = if D::D == 3 {
            grid_candidates_3d(&element_boxes_3d(&kin, 0.5 * skin), mesh.elements())
        } else {
            grid_candidates(&element_boxes(&kin, 0.5 * skin), mesh.elements())
        };
        (2 * lists.iter().map(Vec::len).max().unwrap_or(0)).max(MIN_CAPACITY)
    }

    /// Skin distance of the broad phase (m); default half the smallest element edge.
    pub fn skin(mut self, skin: f64) -> Self {
        self.skin = Some(skin);
        self
    }

    fn element_xy<D: Dim>(kin: &Kinematics<'_, D>, e: usize) -> [[f64; 2]; 3] {
        let c = kin.mesh.element(e);
        let mut t = [[0.0; 2]; 3];
        for a in 0..3 {
            t[a] = [kin.x(c[a] as usize, 0), kin.x(c[a] as usize, 1)];
        }
        t
    }

    fn element_xyz<D: Dim>(kin: &Kinematics<'_, D>, e: usize) -> [[f64; 3]; 4] {
        let c = kin.mesh.element(e);
        let mut t = [[0.0; 3]; 4];
        for a in 0..4 {
            let n = c[a] as usize;
            t[a] = [kin.x(n, 0), kin.x(n, 1), kin.x(n, 2)];
        }
        t
    }

    /// Critical step of 3D contact. A face of area A of one tetrahedron pressed flat by
    /// δ into a face of the other, whose height over that face is H, loads each of its
    /// three nodes with about p (4 δ / H) A / 3 from the target's potential and as much
    /// again from the reaction of the target face inside the contactor's potential: a
    /// node stiffness (8/3) p A / H = (8/9) p A² / V (H = 3 V / A), taken with the
    /// largest face of the element and doubled, k_e = (16/9) p A² / V, because a node
    /// lies on three faces of its element and near edges and corners more than one of
    /// them is loaded. A node sums k_e over its elements (conservative for nodes shared
    /// by a continuous body) and, as in 2D, dt = 2 √(m / (2 k)) for two equal masses
    /// pressed together. (Measured on an impact of two FDEM cubes, every tetrahedron
    /// with its own nodes: the single-face estimate was the critical step itself; this
    /// one is √2 below it, before the simulation's safety factor.)
    ///
    /// The friction spring (eq. 59 corrected) gives a pair the tangential stiffness
    /// τ h² / δ_s = P_t h, h the mean edge length of the two elements: a node sums
    /// P_t × its elements' longest edge, and takes the larger of its normal and
    /// tangential sums (they act in orthogonal directions).
    fn stable_step_3d<D: Dim>(kin: &Kinematics<'_, D>, penalty: f64, shear: f64) -> StableStep {
        let mut k = vec![0.0; kin.mesh.n_nodes()];
        let mut kt = vec![0.0; kin.mesh.n_nodes()];
        for e in 0..kin.mesh.n_elements() {
            let t = Self::element_xyz(kin, e);
            let edge =
                |a: usize, b: usize| -> [f64; 3] { std::array::from_fn(|d| t[b][d] - t[a][d]) };
            let cross = |u: [f64; 3], v: [f64; 3]| {
                [
                    u[1] * v[2] - u[2] * v[1],
                    u[2] * v[0] - u[0] * v[2],
                    u[0] * v[1] - u[1] * v[0],
                ]
            };
            let norm = |u: [f64; 3]| (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]).sqrt();
            let c = cross(edge(0, 2), edge(0, 3));
            let e1 = edge(0, 1);
            let vol = (e1[0] * c[0] + e1[1] * c[1] + e1[2] * c[2]).abs() / 6.0;
            let area_max = [(1, 2, 3), (0, 2, 3), (0, 1, 3), (0, 1, 2)]
                .iter()
                .map(|&(a, b, d)| 0.5 * norm(cross(edge(a, b), edge(a, d))))
                .fold(0.0, f64::max);
            let edge_max = [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)]
                .iter()
                .map(|&(a, b)| norm(edge(a, b)))
                .fold(0.0, f64::max);
            if vol > 0.0 {
                let ke = 16.0 / 9.0 * penalty * area_max * area_max / vol;
                for &n in kin.mesh.element(e) {
                    k[n as usize] += ke;
                    kt[n as usize] += shear * edge_max;
                }
            }
        }
        for (kn, &t) in k.iter_mut().zip(&kt) {
            *kn = kn.max(t);
        }
        let (mut best, mut which) = (f64::INFINITY, 0);
        for (n, (&m, &kn)) in kin.mass.iter().zip(&k).enumerate() {
            // A node without mass dropped out with its null elements: contact skips it.
            if kn > 0.0 && m > 0.0 {
                let dt = 2.0 * (m / (2.0 * kn)).sqrt();
                if dt < best {
                    best = dt;
                    which = n;
                }
            }
        }
        StableStep {
            dt: best,
            entity: Entity::new(EntityKind::Other("contact at node"), which),
            physics: "contact".into(),
        }
    }

    /// Rebuilds the candidate lists: element boxes inflated by half the skin, then the
    /// sorted grid ([`grid_candidates`] in 2D, [`grid_candidates_3d`] in 3D).
    fn build<D: Dim>(&self, kin: &Kinematics<'_, D>) -> Vec<Vec<u32>> {
        if D::D == 3 {
            let boxes = element_boxes_3d(kin, 0.5 * self.skin_used);
            return grid_candidates_3d(&boxes, kin.mesh.elements());
        }
        let boxes = element_boxes(kin, 0.5 * self.skin_used);
        grid_candidates(&boxes, kin.mesh.elements())
    }
}

/// Axis-aligned boxes `[x_min, y_min, x_max, y_max]` (m) of the current triangles,
/// inflated by `margin` on every side (2D meshes; [`element_boxes_3d`] in 3D).
pub fn element_boxes<D: Dim>(kin: &Kinematics<'_, D>, margin: f64) -> Vec<[f64; 4]> {
    (0..kin.mesh.n_elements())
        .map(|e| {
            let t = Contact::element_xy(kin, e);
            let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
            for p in &t {
                for k in 0..2 {
                    lo[k] = lo[k].min(p[k] - margin);
                    hi[k] = hi[k].max(p[k] + margin);
                }
            }
            [lo[0], lo[1], hi[0], hi[1]]
        })
        .collect()
}

/// The broad phase: for every triangle, the sorted list of triangles whose boxes overlap
/// its own and that share no node with it (`conn`: 3 nodes per triangle). Boxes are
/// binned on a uniform grid of cell size = the largest box extent and each box looks in
/// its own and the eight neighbouring cells. A compact domain uses a dense grid filled
/// by counting sort (O(n)); scattered bodies use sorted cell keys (O(n log n)). No
/// pointer structure, deterministic. (Measured against parry's BVH in
/// `benches/broad_phase.rs`: the grid is the faster; see docs/performance.md.)
pub fn grid_candidates(boxes: &[[f64; 4]], conn: &[u32]) -> Vec<Vec<u32>> {
    let ne = boxes.len();
    let cell = boxes
        .iter()
        .map(|b| (b[2] - b[0]).max(b[3] - b[1]))
        .fold(0.0f64, f64::max)
        .max(f64::MIN_POSITIVE);
    let origin = boxes
        .iter()
        .fold([f64::INFINITY; 2], |o, b| [o[0].min(b[0]), o[1].min(b[1])]);
    let key = |x: f64, y: f64| -> (i64, i64) {
        (
            ((x - origin[0]) / cell).floor() as i64,
            ((y - origin[1]) / cell).floor() as i64,
        )
    };
    let keys: Vec<(i64, i64)> = boxes
        .iter()
        .map(|b| key(0.5 * (b[0] + b[2]), 0.5 * (b[1] + b[3])))
        .collect();
    let (ncx, ncy) = keys
        .iter()
        .fold((0i64, 0i64), |(a, b), k| (a.max(k.0 + 1), b.max(k.1 + 1)));
    // Test one candidate pair: boxes overlap and no shared node.
    let accept = |e: usize, f: usize| -> bool {
        let (b, o) = (boxes[e], boxes[f]);
        f != e
            && !(o[0] > b[2] || b[0] > o[2] || o[1] > b[3] || b[1] > o[3])
            && !conn[3 * f..3 * f + 3]
                .iter()
                .any(|n| conn[3 * e..3 * e + 3].contains(n))
    };
    if (ncx as u128) * (ncy as u128) <= (4 * ne + 1024) as u128 {
        // Compact domain: a dense grid, cells filled by counting sort (CSR), O(n).
        let (ncx, ncy) = (ncx as usize, ncy as usize);
        let cell_of = |k: (i64, i64)| k.0 as usize + k.1 as usize * ncx;
        let mut start = vec![0u32; ncx * ncy + 1];
        for k in &keys {
            start[cell_of(*k) + 1] += 1;
        }
        for c in 0..ncx * ncy {
            start[c + 1] += start[c];
        }
        let mut fill = start.clone();
        let mut items = vec![0u32; ne];
        for (e, k) in keys.iter().enumerate() {
            let c = cell_of(*k);
            items[fill[c] as usize] = e as u32;
            fill[c] += 1;
        }
        return (0..ne)
            .into_par_iter()
            .map(|e| {
                let (cx, cy) = keys[e];
                let mut list = Vec::new();
                for y in (cy - 1).max(0)..=(cy + 1).min(ncy as i64 - 1) {
                    for x in (cx - 1).max(0)..=(cx + 1).min(ncx as i64 - 1) {
                        let c = cell_of((x, y));
                        for &f in &items[start[c] as usize..start[c + 1] as usize] {
                            if accept(e, f as usize) {
                                list.push(f);
                            }
                        }
                    }
                }
                list.sort_unstable();
                list
            })
            .collect();
    }
    // Scattered bodies (e.g. fragments far apart): sorted cell keys, binary search.
    let mut keyed: Vec<((i64, i64), u32)> = keys
        .iter()
        .enumerate()
        .map(|(e, k)| (*k, e as u32))
        .collect();
    keyed.sort_unstable();
    let find = |k: (i64, i64)| -> &[((i64, i64), u32)] {
        let start = keyed.partition_point(|x| x.0 < k);
        let end = keyed.partition_point(|x| x.0 <= k);
        &keyed[start..end]
    };
    (0..ne)
        .into_par_iter()
        .map(|e| {
            let (cx, cy) = keys[e];
            let mut list = Vec::new();
            for dx in -1..=1 {
                for dy in -1..=1 {
                    for &(_, f) in find((cx + dx, cy + dy)) {
                        if accept(e, f as usize) {
                            list.push(f);
                        }
                    }
                }
            }
            list.sort_unstable();
            list
        })
        .collect()
}

/// Axis-aligned boxes `[x_min, y_min, z_min, x_max, y_max, z_max]` (m) of the current
/// tetrahedra of a 3D mesh, inflated by `margin` (m) on every side.
pub fn element_boxes_3d<D: Dim>(kin: &Kinematics<'_, D>, margin: f64) -> Vec<[f64; 6]> {
    (0..kin.mesh.n_elements())
        .map(|e| {
            let t = Contact::element_xyz(kin, e);
            let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
            for p in &t {
                for k in 0..3 {
                    lo[k] = lo[k].min(p[k] - margin);
                    hi[k] = hi[k].max(p[k] + margin);
                }
            }
            [lo[0], lo[1], lo[2], hi[0], hi[1], hi[2]]
        })
        .collect()
}

/// The 3D broad phase, as [`grid_candidates`] one dimension up: for every tetrahedron,
/// the sorted list of tetrahedra whose boxes (from [`element_boxes_3d`]) overlap its own
/// and that share no node with it (`conn`: 4 nodes per tetrahedron). Boxes are binned on
/// a uniform grid of cell size = the largest box extent and each box looks in its own
/// and the 26 neighbouring cells; a dense counting-sort grid for compact domains, sorted
/// cell keys for scattered bodies. Deterministic.
pub fn grid_candidates_3d(boxes: &[[f64; 6]], conn: &[u32]) -> Vec<Vec<u32>> {
    type Key = (i64, i64, i64);
    let ne = boxes.len();
    let cell = boxes
        .iter()
        .map(|b| (b[3] - b[0]).max(b[4] - b[1]).max(b[5] - b[2]))
        .fold(0.0f64, f64::max)
        .max(f64::MIN_POSITIVE);
    let origin = boxes.iter().fold([f64::INFINITY; 3], |o, b| {
        [o[0].min(b[0]), o[1].min(b[1]), o[2].min(b[2])]
    });
    let coord = |x: f64, k: usize| ((x - origin[k]) / cell).floor() as i64;
    let keys: Vec<Key> = boxes
        .iter()
        .map(|b| {
            (
                coord(0.5 * (b[0] + b[3]), 0),
                coord(0.5 * (b[1] + b[4]), 1),
                coord(0.5 * (b[2] + b[5]), 2),
            )
        })
        .collect();
    let (ncx, ncy, ncz) = keys.iter().fold((0i64, 0i64, 0i64), |(a, b, c), k| {
        (a.max(k.0 + 1), b.max(k.1 + 1), c.max(k.2 + 1))
    });
    // Test one candidate pair: boxes overlap and no shared node.
    let accept = |e: usize, f: usize| -> bool {
        let (b, o) = (boxes[e], boxes[f]);
        f != e
            && !(o[0] > b[3]
                || b[0] > o[3]
                || o[1] > b[4]
                || b[1] > o[4]
                || o[2] > b[5]
                || b[2] > o[5])
            && !conn[4 * f..4 * f + 4]
                .iter()
                .any(|n| conn[4 * e..4 * e + 4].contains(n))
    };
    if (ncx as u128) * (ncy as u128) * (ncz as u128) <= (4 * ne + 1024) as u128 {
        // Compact domain: a dense grid, cells filled by counting sort (CSR), O(n).
        let (nx, ny, nz) = (ncx as usize, ncy as usize, ncz as usize);
        let cell_of = |k: Key| k.0 as usize + nx * (k.1 as usize + ny * k.2 as usize);
        let mut start = vec![0u32; nx * ny * nz + 1];
        for k in &keys {
            start[cell_of(*k) + 1] += 1;
        }
        for c in 0..nx * ny * nz {
            start[c + 1] += start[c];
        }
        let mut fill = start.clone();
        let mut items = vec![0u32; ne];
        for (e, k) in keys.iter().enumerate() {
            let c = cell_of(*k);
            items[fill[c] as usize] = e as u32;
            fill[c] += 1;
        }
        return (0..ne)
            .into_par_iter()
            .map(|e| {
                let (cx, cy, cz) = keys[e];
                let mut list = Vec::new();
                for z in (cz - 1).max(0)..=(cz + 1).min(ncz - 1) {
                    for y in (cy - 1).max(0)..=(cy + 1).min(ncy - 1) {
                        for x in (cx - 1).max(0)..=(cx + 1).min(ncx - 1) {
                            let c = cell_of((x, y, z));
                            for &f in &items[start[c] as usize..start[c + 1] as usize] {
                                if accept(e, f as usize) {
                                    list.push(f);
                                }
                            }
                        }
                    }
                }
                list.sort_unstable();
                list
            })
            .collect();
    }
    // Scattered bodies: sorted cell keys, binary search.
    let mut keyed: Vec<(Key, u32)> = keys
        .iter()
        .enumerate()
        .map(|(e, k)| (*k, e as u32))
        .collect();
    keyed.sort_unstable();
    let find = |k: Key| -> &[(Key, u32)] {
        let start = keyed.partition_point(|x| x.0 < k);
        let end = keyed.partition_point(|x| x.0 <= k);
        &keyed[start..end]
    };
    (0..ne)
        .into_par_iter()
        .map(|e| {
            let (cx, cy, cz) = keys[e];
            let mut list = Vec::new();
            for dz in -1..=1 {
                for dy in -1..=1 {
                    for dx in -1..=1 {
                        for &(_, f) in find((cx + dx, cy + dy, cz + dz)) {
                            if accept(e, f as usize) {
                                list.push(f);
                            }
                        }
                    }
                }
            }
            list.sort_unstable();
            list
        })
        .collect()
}

/// Writes freshly built candidate lists into the state fields, carrying the history of
/// pairs that stay candidates (both lists are sorted: a binary search in the old list)
/// and zeroing the entries past each new list. An element with more candidates than
/// the capacity is an error, raised before any field changes.
fn store_lists(
    fresh: &[Vec<u32>],
    fields: &mut FieldStore,
    ids: StateIds,
) -> Result<(), ComputeError> {
    let (cap, s) = (ids.capacity, ids.stride);
    if let Some(e) = fresh.iter().position(|l| l.len() > cap) {
        return Err(ComputeError::physics(
            "contact",
            overflow_message(e as u32, cap),
        ));
    }
    let [count, cand, hist] = fields.get_many_mut([ids.count, ids.candidates, ids.history]);
    count
        .par_iter_mut()
        .zip(cand.par_chunks_mut(cap))
        .zip(hist.par_chunks_mut(cap * s))
        .zip(fresh.par_iter())
        .for_each_init(
            || (Vec::new(), Vec::new()),
            |(old, old_hist): &mut (Vec<u32>, Vec<f64>), (((n, row), hrow), list)| {
                let n_old = (*n as usize).min(cap);
                old.clear();
                old.extend(row[..n_old].iter().map(|&f| f as u32));
                old_hist.clear();
                old_hist.extend_from_slice(&hrow[..n_old * s]);
                for (k, &f) in list.iter().enumerate() {
                    row[k] = f as f64;
                    let h = &mut hrow[k * s..(k + 1) * s];
                    match old.binary_search(&f) {
                        Ok(j) => h.copy_from_slice(&old_hist[j * s..(j + 1) * s]),
                        Err(_) => h.fill(0.0),
                    }
                }
                let m = list.len();
                if n_old > m {
                    row[m..n_old].fill(0.0);
                    hrow[m * s..n_old * s].fill(0.0);
                }
                *n = m as f64;
            },
        );
    Ok(())
}

impl<D: Dim> Physics<D> for Contact {
    fn name(&self) -> &str {
        "contact"
    }

    fn kinematic_nodes(&self) -> KinematicNodes {
        KinematicNodes::None
    }

    fn writes_all_slots(&self) -> bool {
        true
    }

    fn fields(&self, mesh: &Mesh<D>) -> Vec<FieldUse> {
        let capacity = self.capacity_for(mesh);
        let stride = self.law().n_state().max(1);
        let mut uses = vec![
            // NaN forces a build at the first step.
            CONTACT_REFERENCE.own::<D>().initial(f64::NAN),
            CONTACT_CANDIDATE_COUNT.own::<D>(),
            CONTACT_CANDIDATES.own_sized::<D>(capacity),
            CONTACT_HISTORY.own_sized::<D>(capacity * stride),
        ];
        if let Some(b) = &self.bonds {
            // The broken-bond flags of the current step (written by the joints).
            uses.push(FieldUse {
                place: Some(Place::Face),
                components: Some(1),
                ..FieldUse::named(&b.field, FieldAccess::Read)
            });
        }
        uses
    }

    fn init(&mut self, ctx: &mut InitContext<'_, D>) -> Result<(), ComputeError> {
        let model = self.law();
        model.check()?;
        model.check_mesh(ctx.mesh.n_elements())?;
        self.n_state = model.n_state();
        self.n_elements = ctx.mesh.n_elements();
        self.model = Some(model);
        self.skin_used = self.skin_for(ctx.mesh);
        if !(self.skin_used > 0.0 && self.skin_used.is_finite()) {
            return Err(ComputeError::param(
                "contact skin",
                self.skin_used,
                "must be positive and finite",
            ));
        }
        if let Some(b) = &mut self.bonds {
            if b.from_mesh {
                let interfaces = ctx.mesh.interfaces();
                b.elements = interfaces.elements().to_vec();
                b.faces = interfaces.faces().iter().step_by(2).copied().collect();
            }
            let (ne, nf) = (ctx.mesh.n_elements(), ctx.mesh.faces().len());
            if b.elements.len() % 2 != 0 || b.elements.len() / 2 != b.faces.len() {
                return Err(ComputeError::param(
                    "contact bonded pairs",
                    format!("{} elements, {} faces", b.elements.len(), b.faces.len()),
                    "give two elements and one face per bond",
                ));
            }
            if let Some(&e) = b.elements.iter().find(|&&e| e as usize >= ne) {
                return Err(ComputeError::param(
                    "contact bonded element",
                    e,
                    format!("mesh has {ne} elements"),
                ));
            }
            if let Some(&f) = b.faces.iter().find(|&&f| f as usize >= nf) {
                return Err(ComputeError::param(
                    "contact bonded face",
                    f,
                    format!("mesh has {nf} faces"),
                ));
            }
            if [
                CONTACT_REFERENCE,
                CONTACT_CANDIDATE_COUNT,
                CONTACT_CANDIDATES,
                CONTACT_HISTORY,
            ]
            .iter()
            .any(|k| k.name() == b.field)
            {
                return Err(ComputeError::param(
                    "contact broken-bond field",
                    &b.field,
                    "must be a face field of another physics, not one of contact's own",
                ));
            }
            let id = ctx.fields.id(&b.field)?;
            if ctx.fields.get(id).len() != nf {
                return Err(ComputeError::param(
                    "contact broken-bond field",
                    &b.field,
                    "must be a face field with one value per face",
                ));
            }
            b.id = Some(id);
            let mut per = vec![Vec::new(); ne];
            for (i, pair) in b.elements.chunks_exact(2).enumerate() {
                per[pair[0] as usize].push((pair[1], b.faces[i]));
                per[pair[1] as usize].push((pair[0], b.faces[i]));
            }
            for l in &mut per {
                l.sort_unstable();
            }
            b.per_element = per;
            self.regions = Some(BondedRegions::new(ctx.mesh, &b.elements, &b.faces));
        }
        if self.capacity == Some(0) {
            return Err(ComputeError::param(
                "Contact::capacity",
                0,
                "must be at least 1 candidate per element",
            ));
        }
        let candidates = ctx.fields.id(CONTACT_CANDIDATES)?;
        let history = ctx.fields.id(CONTACT_HISTORY)?;
        let capacity = ctx.fields.spec(candidates).components;
        let stride = self.n_state.max(1);
        if ctx.fields.spec(history).components != capacity * stride {
            return Err(ComputeError::param(
                "contact pair history",
                ctx.fields.spec(history).components,
                format!("expected {capacity} candidates x {stride} values per element"),
            ));
        }
        self.ids = Some(StateIds {
            reference: ctx.fields.id(CONTACT_REFERENCE)?,
            count: ctx.fields.id(CONTACT_CANDIDATE_COUNT)?,
            candidates,
            history,
            capacity,
            stride,
        });
        ctx.register_slots(ctx.mesh.elements())?;
        Ok(())
    }

    fn gpu_setup(
        &mut self,
        setup: &mut pcdc_compute::gpu::GpuSetup<'_, D>,
    ) -> Result<(), ComputeError> {
        let model = self
            .model
            .as_deref()
            .ok_or_else(|| ComputeError::Gpu("contact: GPU setup before init".into()))?;
        let ids = self
            .ids
            .ok_or_else(|| ComputeError::Gpu("contact: GPU setup before init".into()))?;
        let input = crate::gpu::GpuContactInput {
            skin: self.skin_used,
            model,
            bonds: self
                .bonds
                .as_ref()
                .map(|b| (b.per_element.as_slice(), b.field.as_str())),
            capacity: ids.capacity,
            stride: ids.stride,
            regions: self.regions.as_ref(),
        };
        crate::gpu::setup(input, setup)
    }

    fn check_fields(&self, fields: &FieldStore) -> Result<(), ComputeError> {
        let Some(ids) = self.ids else {
            return Ok(());
        };
        crate::snapshot_state::check(
            fields.get(ids.count),
            fields.get(ids.candidates),
            fields.get(ids.history),
            self.n_elements,
            ids.capacity,
            ids.stride,
        )
    }

    fn slot_entity(&self, slot: usize) -> Option<String> {
        Some(format!(
            "contact forces on element {}",
            slot / D::NODES_PER_ELEM
        ))
    }

    fn fingerprint(&self) -> u64 {
        let mut h = Fingerprint::new()
            .f64(self.penalty)
            .debug(&self.model)
            .f64(self.skin_used)
            .u64(self.n_state as u64);
        if let Some(b) = &self.bonds {
            h = h.u32s(&b.elements).u32s(&b.faces).str(&b.field);
        }
        h.finish()
    }

    fn stable_step(&self, kin: &Kinematics<'_, D>, _fields: &FieldStore) -> Option<StableStep> {
        // A node pushed by the potential of a neighbour's sub-triangle (gradient 3/h over
        // an edge of length ~h) sees a normal stiffness of about 3 p per unit thickness.
        // The friction spring (eq. 59 corrected: τ h = P_t δ_s per unit thickness) adds
        // at most P_t along the tangent, orthogonal to the normal: the node's stiffness
        // is the larger of the two.
        let (penalty, shear) = self.model.as_ref().map_or(
            (self.penalty, self.friction.map_or(0.0, |f| f.penalty)),
            |m| (m.normal_penalty(), m.shear_penalty()),
        );
        if D::D == 3 {
            return Some(Self::stable_step_3d(kin, penalty, shear));
        }
        let k = (3.0 * penalty).max(shear);
        let (mut best, mut which) = (f64::INFINITY, 0);
        // Mesh nodes only: nodes other physics add (bolt nodes) never touch in contact.
        for (n, &m) in kin.mass.iter().enumerate().take(kin.mesh.n_nodes()) {
            // A node without mass dropped out with its null elements: contact skips it.
            if m == 0.0 {
                continue;
            }
            let dt = 2.0 * (m / (2.0 * k)).sqrt();
            if dt < best {
                best = dt;
                which = n;
            }
        }
        Some(StableStep {
            dt: best,
            entity: Entity::new(EntityKind::Other("contact at node"), which),
            physics: "contact".into(),
        })
    }

    fn compute_forces(&mut self, ctx: &mut ForceContext<'_, D>) -> Result<(), ComputeError> {
        let ids = self.ids.expect("init ran");
        let ns = self.n_state;
        let kin = &ctx.kin;
        // Where contact can happen this step (see the `exclusion` and `active` modules).
        let broken_id = self.bonds.as_ref().and_then(|b| b.id);
        let broken: &[f64] = broken_id.map_or(&[], |b| ctx.fields.get(b));
        // Null elements (excavated by the null model) are sealed.
        let null: &[f64] = ctx
            .fields
            .id(pcdc_compute::names::ELEMENT_NULL)
            .map_or(&[], |id| ctx.fields.get(id));
        let active = &mut self.active;
        let regions = self.regions.as_mut();
        let refreshed = ctx
            .backend
            .install(|| active.refresh(regions, broken, null, kin.mesh));
        // Rebuild when a node of an unsealed element moved more than half the skin since
        // the last build (a NaN reference, before the first build, always does).
        let limit2 = (0.5 * self.skin_used).powi(2);
        let dim = D::D;
        let reference = ctx.fields.get(ids.reference);
        let watched = &self.active.nodes;
        let moved = ctx.backend.install(|| {
            watched.par_chunks(4096).any(|block| {
                block.iter().any(|&n| {
                    let n = n as usize;
                    let mut d2 = 0.0;
                    for k in 0..dim {
                        let dk = kin.x(n, k) - reference[dim * n + k];
                        d2 += dk * dk;
                    }
                    d2.is_nan() || d2 > limit2
                })
            })
        });
        if moved {
            let fresh = ctx.backend.install(|| self.build(kin));
            ctx.backend
                .install(|| store_lists(&fresh, ctx.fields, ids))?;
            let reference = ctx.fields.get_mut(ids.reference);
            for n in 0..kin.mesh.n_nodes() {
                for k in 0..dim {
                    reference[dim * n + k] = kin.x(n, k);
                }
            }
        }
        let (cap, stride) = (ids.capacity, ids.stride);
        let model = self.model.as_deref().expect("init ran");
        let bonds = self.bonds.as_ref();
        let (count, cand, hist, broken): (&[f64], &[f64], &mut [f64], &[f64]) = match broken_id {
            Some(bid) => {
                let [n, c, h, b] =
                    ctx.fields
                        .get_many_mut([ids.count, ids.candidates, ids.history, bid]);
                (n, c, h, b)
            }
            None => {
                let [n, c, h] = ctx
                    .fields
                    .get_many_mut([ids.count, ids.candidates, ids.history]);
                (n, c, h, &[])
            }
        };
        let regions = self.regions.as_ref();
        // Current boxes of the unsealed elements, once per element and step.
        let ne = kin.mesh.n_elements();
        let mut scratch = std::mem::take(&mut self.scratch);
        scratch.boxes.resize(ne * 2 * dim, 0.0);
        let sealed = &self.active.sealed;
        ctx.backend.install(|| {
            scratch
                .boxes
                .par_chunks_mut(2 * dim)
                .enumerate()
                .with_min_len(1024)
                .for_each(|(e, b)| {
                    if sealed[e] {
                        return;
                    }
                    let nodes = kin.mesh.element(e);
                    for k in 0..dim {
                        let x0 = kin.x(nodes[0] as usize, k);
                        let (mut lo, mut hi) = (x0, x0);
                        for &n in &nodes[1..] {
                            let x = kin.x(n as usize, k);
                            lo = lo.min(x);
                            hi = hi.max(x);
                        }
                        b[k] = lo;
                        b[dim + k] = hi;
                    }
                })
        });
        let boxes = &scratch.boxes;
        let bx = |e: usize| &boxes[2 * dim * e..2 * dim * (e + 1)];
        // Element e's list: the first n entries of its row (n checked on restore; the
        // clamp keeps a hand-edited count in bounds).
        let list = |e: usize| {
            let n = (count[e] as usize).min(cap);
            &cand[e * cap..e * cap + n]
        };
        // Whether candidate f of (unsealed) element e skips the narrow phase this step,
        // the same in 2D and 3D: a sealed neighbour, boxes apart (the potential's own
        // first test, taken before the costlier checks: no force, and the pair's history
        // `state` restarts), a shared intact vertex, or an intact bond (see the
        // `exclusion` module).
        let skip = |e: usize, f: usize, state: &mut [f64]| {
            if sealed[f] {
                return true;
            }
            if boxes_apart(bx(e), bx(f), dim) {
                model.separate(state);
                return true;
            }
            regions.is_some_and(|r| r.share_intact_vertex(e, f))
                || bonds
                    .and_then(|b| b.face(e, f))
                    .is_some_and(|face| broken[face] == 0.0)
        };
        let row = cap * stride;
        if dim == 3 {
            // Tetrahedra: 4 nodes x 3 components of slots per element.
            let mean_edge3 = |e: usize| {
                let t = Self::element_xyz(kin, e);
                let mut sum = 0.0;
                for a in 0..4 {
                    for b in a + 1..4 {
                        let d: [f64; 3] = std::array::from_fn(|k| t[b][k] - t[a][k]);
                        sum += (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
                    }
                }
                sum / 6.0
            };
            // Contactor c < target t.
            let eval = |c: usize, t: usize, state: &mut [f64]| {
                if skip(c, t, state) {
                    return None;
                }
                let (xc, xt) = (Self::element_xyz(kin, c), Self::element_xyz(kin, t));
                let mut pair = tet_pair_force(&xc, &xt, model.pair_penalty(c, t));
                if pair == PairForce3::default() {
                    // Not touching (most candidates): no force, fresh history.
                    model.separate(state);
                    return None;
                }
                let h = 0.5 * (mean_edge3(c) + mean_edge3(t));
                apply_model3(&mut pair, kin, c, t, model, h, state);
                Some((
                    std::array::from_fn(|i| pair.contactor[i / 3][i % 3]),
                    std::array::from_fn(|i| pair.target[i / 3][i % 3]),
                ))
            };
            ctx.backend.install(|| {
                pair_pass::<12, _, _>(
                    ctx.slots,
                    hist,
                    row,
                    &list,
                    sealed,
                    refreshed,
                    &mut scratch.shares3,
                    &mut scratch.mirrors,
                    &eval,
                    stride,
                    ns,
                )
            });
            self.scratch = scratch;
            return Ok(());
        }
        let mean_edge = |e: usize| {
            let t = Self::element_xy(kin, e);
            (0..3)
                .map(|a| {
                    ((t[(a + 1) % 3][0] - t[a][0]).powi(2) + (t[(a + 1) % 3][1] - t[a][1]).powi(2))
                        .sqrt()
                })
                .sum::<f64>()
                / 3.0
        };
        // Contactor c < target t.
        let eval = |c: usize, t: usize, state: &mut [f64]| {
            if skip(c, t, state) {
                return None;
            }
            let (xc, xt) = (Self::element_xy(kin, c), Self::element_xy(kin, t));
            let mut pair = triangle_pair_force(&xc, &xt, model.pair_penalty(c, t));
            if pair == PairForce2::default() {
                // Not touching (most candidates): no force, fresh history.
                model.separate(state);
                return None;
            }
            let h = 0.5 * (mean_edge(c) + mean_edge(t));
            apply_model(&mut pair, kin, c, t, model, h, state);
            Some((
                std::array::from_fn(|i| pair.contactor[i / 2][i % 2]),
                std::array::from_fn(|i| pair.target[i / 2][i % 2]),
            ))
        };
        ctx.backend.install(|| {
            pair_pass::<6, _, _>(
                ctx.slots,
                hist,
                row,
                &list,
                sealed,
                refreshed,
                &mut scratch.shares2,
                &mut scratch.mirrors,
                &eval,
                stride,
                ns,
            )
        });
        self.scratch = scratch;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use pcdc_mesh::Dim2;
    use proptest::prelude::*;

    proptest! {
        /// Friction never exceeds tan φ times the normal force, and once sliding it
        /// opposes the relative sliding velocity of the contactor.
        #[test]
        fn friction_bounded_and_opposing(dx in -0.3f64..0.3, dy in 0.75f64..0.95, vx in -2.0f64..2.0, vy in -0.5f64..0.5, phi in 5.0f64..60.0) {
            // Target: lower triangle; contactor: the upper one, overlapping its top edge.
            let coords = vec![0.0, 0.0, 2.0, 0.0, 1.0, 1.0, dx, dy, 2.0 + dx, dy, 1.0 + dx, 1.0 + dy];
            let mesh = Mesh::<Dim2>::new(coords.clone(), vec![0, 1, 2, 3, 4, 5]).unwrap();
            let u = vec![0.0; 12];
            let mut v = vec![0.0; 12];
            for n in 3..6 {
                v[2 * n] = vx;
                v[2 * n + 1] = vy;
            }
            let mass = vec![1.0; 6];
            let kin = Kinematics { mesh: &mesh, coords: mesh.coords(), mass: &mass, u: &u, v: &v, time: 0.0, dt: 1e-3, step: 0, damping: false };
            let c = Contact::element_xy(&kin, 1);
            let t = Contact::element_xy(&kin, 0);
            let law = MohrCoulombContact {
                normal_penalty: 1e9,
                friction: Some(Friction { angle_deg: phi, penalty: 1e9 }),
                damping: None,
            };
            let mut state = [0.0; 3];
            for _ in 0..50 {
                let normal = triangle_pair_force(&c, &t, 1e9);
                prop_assume!(normal.contactor.iter().any(|f| f[0] != 0.0 || f[1] != 0.0));
                let mut pair = normal;
                apply_model(&mut pair, &kin, 1, 0, &law, 1.0, &mut state);
                let sum = |p: &[[f64; 2]; 3]| [p.iter().map(|f| f[0]).sum::<f64>(), p.iter().map(|f| f[1]).sum::<f64>()];
                let (fn_, ft_all) = (sum(&normal.contactor), sum(&pair.contactor));
                let ft = [ft_all[0] - fn_[0], ft_all[1] - fn_[1]];
                let n_mag = fn_[0].hypot(fn_[1]);
                let t_mag = ft[0].hypot(ft[1]);
                prop_assert!(t_mag <= phi.to_radians().tan() * n_mag * (1.0 + 1e-12));
                // Tangential part of the relative velocity (contactor minus target).
                let nn = [fn_[0] / n_mag, fn_[1] / n_mag];
                let vt = [vx - (vx * nn[0] + vy * nn[1]) * nn[0], vy - (vx * nn[0] + vy * nn[1]) * nn[1]];
                prop_assert!(ft[0] * vt[0] + ft[1] * vt[1] <= 1e-9 * t_mag.max(1.0), "friction {:?} along sliding {:?}", ft, vt);
                // Action equals reaction.
                let (tc, tt) = (sum(&pair.contactor), sum(&pair.target));
                prop_assert!((tc[0] + tt[0]).abs() < 1e-9 * n_mag && (tc[1] + tt[1]).abs() < 1e-9 * n_mag);
            }
        }
    }

    proptest! {
        /// 3D: friction never exceeds tan φ times the normal force, opposes the relative
        /// tangential velocity of the contactor, and action equals reaction.
        #[test]
        fn friction_3d_bounded_and_opposing(dx in -0.3f64..0.3, dy in -0.3f64..0.3, depth in 0.02f64..0.2,
                                            vx in -2.0f64..2.0, vy in -2.0f64..2.0, vz in -0.5f64..0.5, phi in 5.0f64..60.0) {
            // Target: its top face in z = 0; contactor: its bottom face `depth` below.
            let coords = vec![
                0.0, 0.0, 0.0, 2.0, 0.0, 0.0, 0.0, 2.0, 0.0, 0.6, 0.6, -1.5,
                dx, dy, -depth, 2.0 + dx, dy, -depth, dx, 2.0 + dy, -depth, 0.6 + dx, 0.6 + dy, 1.5 - depth,
            ];
            let mesh = Mesh::<pcdc_mesh::Dim3>::new_reoriented(coords, vec![0, 1, 2, 3, 4, 5, 6, 7]).unwrap();
            let u = vec![0.0; 24];
            let mut v = vec![0.0; 24];
            for n in 4..8 {
                v[3 * n] = vx;
                v[3 * n + 1] = vy;
                v[3 * n + 2] = vz;
            }
            let mass = vec![1.0; 8];
            let kin = Kinematics { mesh: &mesh, coords: mesh.coords(), mass: &mass, u: &u, v: &v, time: 0.0, dt: 1e-3, step: 0, damping: false };
            let c = Contact::element_xyz(&kin, 1);
            let t = Contact::element_xyz(&kin, 0);
            let law = MohrCoulombContact {
                normal_penalty: 1e9,
                friction: Some(Friction { angle_deg: phi, penalty: 1e12 }),
                damping: None,
            };
            let sum = |p: &[[f64; 3]; 4]| -> [f64; 3] { std::array::from_fn(|d| p.iter().map(|f| f[d]).sum::<f64>()) };
            let mut state = [0.0; 3];
            for _ in 0..50 {
                let normal = tet_pair_force(&c, &t, 1e9);
                prop_assume!(normal.contactor.iter().any(|f| f.iter().any(|&x| x != 0.0)));
                let mut pair = normal;
                apply_model3(&mut pair, &kin, 1, 0, &law, 1.0, &mut state);
                let (fn_, all) = (sum(&normal.contactor), sum(&pair.contactor));
                let ft: [f64; 3] = std::array::from_fn(|d| all[d] - fn_[d]);
                let n_mag = (fn_[0] * fn_[0] + fn_[1] * fn_[1] + fn_[2] * fn_[2]).sqrt();
                let t_mag = (ft[0] * ft[0] + ft[1] * ft[1] + ft[2] * ft[2]).sqrt();
                prop_assert!(t_mag <= phi.to_radians().tan() * n_mag * (1.0 + 1e-12));
                // Tangential part of the relative velocity (contactor minus target).
                let nn = fn_.map(|x| x / n_mag);
                let vn = vx * nn[0] + vy * nn[1] + vz * nn[2];
                let vt = [vx - vn * nn[0], vy - vn * nn[1], vz - vn * nn[2]];
                prop_assert!(ft[0] * vt[0] + ft[1] * vt[1] + ft[2] * vt[2] <= 1e-9 * t_mag.max(1.0), "friction {:?} along sliding {:?}", ft, vt);
                // Friction is tangential: no component along the normal.
                prop_assert!((ft[0] * nn[0] + ft[1] * nn[1] + ft[2] * nn[2]).abs() <= 1e-9 * n_mag);
                let (tc, tt) = (sum(&pair.contactor), sum(&pair.target));
                for d in 0..3 {
                    prop_assert!((tc[d] + tt[d]).abs() < 1e-9 * n_mag);
                }
            }
            // Sliding long enough reaches the Coulomb limit.
            let speed = (vx * vx + vy * vy).sqrt();
            if speed > 0.5 {
                let normal = tet_pair_force(&c, &t, 1e9);
                let mut pair = normal;
                apply_model3(&mut pair, &kin, 1, 0, &law, 1.0, &mut state);
                let (fn_, all) = (sum(&normal.contactor), sum(&pair.contactor));
                let n_mag = (fn_[0] * fn_[0] + fn_[1] * fn_[1] + fn_[2] * fn_[2]).sqrt();
                let t_mag = (0..3).map(|d| (all[d] - fn_[d]).powi(2)).sum::<f64>().sqrt();
                prop_assert!((t_mag - phi.to_radians().tan() * n_mag).abs() <= 1e-9 * n_mag, "{} vs {}", t_mag, phi.to_radians().tan() * n_mag);
            }
        }
    }
}
