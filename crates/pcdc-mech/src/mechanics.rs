//! The element mechanics physics: constant-strain Tri3/Tet4 elements with objective
//! co-rotated kinematics ([`crate::kinematics`]), any [`ConstitutiveModel`] per element
//! range, viscous damping (manual eq. 17-19), lumped mass (eq. 16), the stable time
//! step and the linear stiffness for the direct static solve.
//!
//! Fields: `stress` (co-rotated Cauchy stress, Pa, stride NSYM), `strain` (co-rotated
//! strain, stride NSYM), in 2D `stress_zz` (plane-strain σ_zz), in 3D `rotation` (the
//! element rotation R, 9 values row-major), and `model_state` when a model has history
//! variables. It reads (lagged) the coupling fields its models ask for
//! ([`ConstitutiveModel::coupling`]) and passes each model their values at the element
//! ([`crate::ModelInput::coupling`]); when no model asks, it declares and gathers
//! nothing.

use std::sync::Arc;

use pcdc_compute::coupling::CouplingInputs;
use pcdc_compute::gpu::{splice_models, Access, GpuData, GpuSetup, Kernel, Phase};
use pcdc_compute::{
    names, ComputeError, FieldId, FieldStore, Fingerprint, ForceContext, InitContext, Kinematics,
    Physics, StableStep,
};
use pcdc_compute::{Backend, FieldKey, FieldUse, KinematicNodes};
use pcdc_compute::{Entity, EntityKind};
use pcdc_mesh::{Dim, Mesh, Range};
use rayon::prelude::*;

use crate::initial_stress::InitialStress;
use crate::kinematics::{dm_inv_2d, polar_2d_h, polar_3d};
use crate::mixed::{trace_2d, MixedCells};
use crate::model::{double_dot, ConstitutiveModel, LinearElastic, Sym6};
use crate::MechError;

mod element;

const CHUNK: usize = 256;

/// Ratio of the exact critical step `2/ω_max` of a lumped-mass simplex to `h/c_p`
/// (h = smallest height), lower bound over element shapes, so that `κ h / c_p` never
/// overestimates the stable step. Measured from the element eigenvalues: Tri3 0.82
/// (equilateral) to 0.94; Tet4 0.84 (corner), 0.67 (regular), 0.51 (worst of 2000
/// random shapes).
const fn shape_factor(dim: usize) -> f64 {
    if dim == 2 {
        0.8
    } else {
        0.45
    }
}

/// Per-element constant data derived from the reference mesh.
#[derive(Clone, Debug, Default)]
struct ElementGeometry {
    /// Inverse reference edge matrix D_m⁻¹, row-major D×D per element: row j is ∇N_{j+1}.
    dm_inv: Vec<f64>,
    /// Reference area/volume V₀ (m² or m³).
    volume: Vec<f64>,
    /// Mean edge length L for the critical damping coefficient (eq. 18), m.
    mean_edge: Vec<f64>,
    /// Smallest height (area·2/longest edge or volume·3/largest face), m.
    height: Vec<f64>,
    /// Space dimension.
    dim: usize,
}

/// Per-element contact properties of the surfaces (manual table 1): friction angle
/// (degrees, default 0) and contact penalty (Pa, default 10 E).
#[derive(Clone, Debug, PartialEq)]
pub struct SurfaceProperties {
    /// Friction angle per element (degrees).
    pub friction_deg: Vec<f64>,
    /// Contact penalty per element (Pa).
    pub penalty: Vec<f64>,
}

/// Element mechanics: materials assigned by range; later assignments override earlier.
#[derive(Debug, Default)]
pub struct Mechanics {
    assignments: Vec<Assignment>,
    /// Assignments by element list: (index into `assignments`, elements).
    explicit: Vec<(usize, Vec<u32>)>,
    initial_stress: Vec<(Range, InitialStress)>,
    models: Vec<Arc<dyn ConstitutiveModel>>,
    /// Per model (as `models`): the constants the element loop reads.
    consts: Vec<ModelConsts>,
    material: Vec<u16>,
    n_state: usize,
    geo: ElementGeometry,
    ids: Option<Ids>,
    coupling: CouplingInputs,
    /// Cell data when the mesh has Quad4/Hex8 cells ([`crate::mixed`]).
    mixed: Option<MixedCells>,
    /// Per element: the trace of its co-rotated strain this step (mixed cells only).
    trace: Vec<f64>,
}

/// A material assignment: the range, the model, and λ and 2μ (Pa) when the model is
/// the built-in [`LinearElastic`].
type Assignment = (Range, Arc<dyn ConstitutiveModel>, Option<(f64, f64)>);

/// Constants of one model that the element loop reads every step, cached at init: the
/// built-in linear elastic law is applied inline (no call through the trait object)
/// and the viscous coefficient needs no square root per element.
#[derive(Clone, Copy, Debug)]
struct ModelConsts {
    /// λ and 2μ (Pa) when the model is [`LinearElastic`], whose update
    /// σ += λ tr(Δε) I + 2μ Δε is then evaluated in the element loop.
    elastic: Option<(f64, f64)>,
    /// 2 D_f (the viscous damping factor doubled, eq. 18-19).
    damp2: f64,
    /// √(ρ E) (Pa·s/m): `D_f C = 2 D_f L √(ρE)` with the element's mean edge L.
    sqrt_rho_e: f64,
}

#[derive(Clone, Copy, Debug)]
struct Ids {
    stress: FieldId,
    strain: FieldId,
    extra: FieldId,
    state: FieldId,
    null: FieldId,
}

/// Material assignments resolved on a mesh: the model index of every element and the
/// models in assignment order.
type Resolved = (Vec<u16>, Vec<Arc<dyn ConstitutiveModel>>);

impl Mechanics {
    /// Element mechanics with no material yet.
    pub fn new() -> Self {
        Self::default()
    }

    /// Assigns a constitutive model to the elements in `range` (by centroid).
    pub fn material(mut self, range: Range, model: impl ConstitutiveModel + 'static) -> Self {
        let elastic = (&model as &dyn std::any::Any)
            .downcast_ref::<LinearElastic>()
            .map(|m| (m.lambda(), 2.0 * m.shear()));
        self.assignments.push((range, Arc::new(model), elastic));
        self
    }

    /// Assigns a constitutive model to the listed elements (e.g. one class of a
    /// heterogeneous property, `pcdc_mesh::property::classes`); later assignments
    /// override earlier ones. An index beyond the mesh is an error when the simulation
    /// is built.
    pub fn material_for(self, elements: Vec<u32>, model: impl ConstitutiveModel + 'static) -> Self {
        let at = self.assignments.len();
        let mut m = self.material(Range::custom(|_| false), model);
        m.explicit.push((at, elements));
        m
    }

    /// Assigns a shared model (e.g. a user plugin behind an `Arc`).
    pub fn material_arc(mut self, range: Range, model: Arc<dyn ConstitutiveModel>) -> Self {
        self.assignments.push((range, model, None));
        self
    }

    /// Initial stress (Pa, tension positive; xx, yy, zz, xy, yz, xz) of the elements in
    /// `range` (manual chapter 4, item 8); later calls override earlier ones.
    pub fn initial_stress(mut self, range: Range, stress: Sym6) -> Self {
        self.initial_stress
            .push((range, InitialStress::Uniform(stress)));
        self
    }

    /// An initial stress field (geostatic with K0, a depth gradient, principal values at
    /// an angle, see [`InitialStress`]) in the elements of `range`, evaluated at their
    /// centroids; later calls override earlier ones. Checked when the simulation is
    /// built.
    pub fn initial_stress_field(mut self, range: Range, field: InitialStress) -> Self {
        self.initial_stress.push((range, field));
        self
    }

    /// Resolves the material assignments: the model index of every element, and the
    /// models in assignment order.
    fn resolve<D: Dim>(&self, mesh: &Mesh<D>) -> Result<Resolved, MechError> {
        let ne = mesh.n_elements();
        if self.assignments.is_empty() {
            return Err(MechError::param(
                "material",
                "none",
                "assign at least one constitutive model with Mechanics::material",
            ));
        }
        if self.assignments.len() > u16::MAX as usize {
            return Err(MechError::param(
                "material count",
                self.assignments.len(),
                "at most 65535 assignments",
            ));
        }
        let mut material = vec![u16::MAX; ne];
        let mut models = Vec::new();
        for (i, (range, model, _)) in self.assignments.iter().enumerate() {
            let sel = match self.explicit.iter().find(|(at, _)| *at == i) {
                Some((_, list)) => {
                    if let Some(&bad) = list.iter().find(|&&e| e as usize >= ne) {
                        return Err(MechError::param(
                            format!("material {i} ({}) element", model.name()),
                            bad,
                            format!("the mesh has {ne} elements"),
                        ));
                    }
                    list.clone()
                }
                None => mesh.select_elements(range)?,
            };
            if sel.is_empty() {
                return Err(MechError::EmptyRange {
                    what: format!("material {} ({})", i, model.name()),
                    range: format!("{range:?}"),
                    entity: "element",
                });
            }
            check_model(i, model.as_ref())?;
            for e in sel {
                material[e as usize] = i as u16;
            }
            models.push(model.clone());
        }
        if let Some(e) = material.iter().position(|&m| m == u16::MAX) {
            return Err(MechError::param(
                format!("material of element {e}"),
                "none",
                "every element needs a constitutive model; add a Mechanics::material covering it",
            ));
        }
        Ok((material, models))
    }

    /// The contact properties of the elements' surfaces (manual table 1, keywords
    /// `friction` and `penalty`): what contact (`pcdc_contact::Contact::surface_defaults`) uses when no contact
    /// law is set. Resolves the material assignments on `mesh` (as the simulation build
    /// will), so it can be called before building.
    pub fn surface_properties<D: Dim>(
        &self,
        mesh: &Mesh<D>,
    ) -> Result<SurfaceProperties, MechError> {
        let (material, models) = self.resolve(mesh)?;
        Ok(SurfaceProperties {
            friction_deg: material
                .iter()
                .map(|&m| models[m as usize].contact_friction())
                .collect(),
            penalty: material
                .iter()
                .map(|&m| models[m as usize].contact_penalty())
                .collect(),
        })
    }

    fn ids(&self) -> Ids {
        self.ids.expect("Mechanics used before init")
    }

    /// The WGSL of the coupling inputs (only with coupling): the `Coupling` alias and
    /// `coupling_of(e, mat)`, which computes every coupling field's values at element
    /// `e` (the operations of [`Self::gather_coupling`]) and returns those of material
    /// `mat`'s model in its order (zero beyond its count), through the table
    /// `mat_coupling` ([`CouplingInputs::bind`]).
    fn coupling_wgsl<D: Dim>(&self) -> String {
        let npe = D::NODES_PER_ELEM;
        let total: usize = self.coupling.fields.iter().map(|f| f.components).sum();
        let mut src = format!(
            "alias Coupling = array<Real, {}u>;\nfn coupling_of(e: u32, mat: u32) -> Coupling {{\n    var all: array<Real, {total}u>;\n",
            self.coupling.stride
        );
        let mut at = 0;
        for (i, f) in self.coupling.fields.iter().enumerate() {
            let nc = f.components;
            src.push_str(&format!(
                "    // '{}'\n    for (var c = 0u; c < {nc}u; c = c + 1u) {{\n",
                self.coupling.keys[i]
            ));
            if f.node {
                src.push_str(&format!(
                    "        var sum = Real(0.0);\n        for (var a = 0u; a < {npe}u; a = a + 1u) {{\n            sum = sum + cpl{i}[conn[{npe}u * e + a] * {nc}u + c];\n        }}\n        all[{at}u + c] = sum / Real({npe}.0);\n"
                ));
            } else {
                src.push_str(&format!(
                    "        all[{at}u + c] = cpl{i}[e * {nc}u + c];\n"
                ));
            }
            src.push_str("    }\n");
            at += nc;
        }
        src.push_str(
            "    var out: Coupling;\n    let n = mat_coupling[2u * mat];\n    let o = mat_coupling[2u * mat + 1u];\n    for (var k = 0u; k < n; k = k + 1u) {\n        out[k] = all[mat_coupling[o + k]];\n    }\n    return out;\n}\n",
        );
        src
    }

    /// Fills `values` (stride [`CouplingInputs::stride`] per element) with every element's
    /// coupling values in its model's order: the mean of the element's node values
    /// (summed in connectivity order, then divided by the node count) for a node field,
    /// the element's value for an element field. The GPU's `coupling_of` repeats these
    /// operations.
    fn gather_coupling<D: Dim>(
        &self,
        conn: &[u32],
        fields: &FieldStore,
        values: &mut [f64],
        backend: &Backend,
    ) {
        let (npe, stride) = (D::NODES_PER_ELEM, self.coupling.stride);
        let data: Vec<&[f64]> = self
            .coupling
            .fields
            .iter()
            .map(|f| fields.get(f.id))
            .collect();
        backend.install(|| {
            values
                .par_chunks_mut(CHUNK * stride)
                .enumerate()
                .for_each(|(chunk, out)| {
                    for (i, out) in out.chunks_exact_mut(stride).enumerate() {
                        let e = chunk * CHUNK + i;
                        let mut k = 0;
                        for &u in &self.coupling.of_model[self.material[e] as usize] {
                            let (f, v) = (&self.coupling.fields[u], data[u]);
                            let nc = f.components;
                            for c in 0..nc {
                                out[k] = if f.node {
                                    let mut sum = 0.0;
                                    for &n in &conn[e * npe..(e + 1) * npe] {
                                        sum += v[n as usize * nc + c];
                                    }
                                    sum / npe as f64
                                } else {
                                    v[e * nc + c]
                                };
                                k += 1;
                            }
                        }
                    }
                });
        });
    }

    /// The model of element `e` (after init).
    pub fn model_of(&self, e: usize) -> &dyn ConstitutiveModel {
        &*self.models[self.material[e] as usize]
    }

    /// Viscous coefficient `D_f C` of element `e` with `C = 2 L √(ρE)` (eq. 18-19), Pa·s,
    /// from its model's cached constants.
    fn viscous_coefficient(&self, e: usize) -> f64 {
        let k = &self.consts[self.material[e] as usize];
        k.damp2 * self.geo.mean_edge[e] * k.sqrt_rho_e
    }

    fn element_dt(&self, e: usize, damped: bool) -> f64 {
        let m = self.model_of(e);
        let c = (m.wave_modulus() / m.density()).sqrt();
        let share = self.mixed.as_ref().map_or(1.0, |mx| mx.dt_factor[e]);
        let h = self.geo.height[e] * shape_factor(self.geo.dim) * share;
        if !damped || m.damp_factor() == 0.0 {
            return h / c;
        }
        // Viscous stress D_f C ε̇ is stiffness-proportional damping β = D_f C / M,
        // ξ(ω) = β ω / 2 at the element's highest frequency ω = 2c/h; central difference
        // is stable for dt ≤ (2/ω)(√(1+ξ²) − ξ).
        let beta = self.viscous_coefficient(e) / m.wave_modulus();
        let omega = 2.0 * c / h;
        let xi = 0.5 * beta * omega;
        (2.0 / omega) * ((1.0 + xi * xi).sqrt() - xi)
    }
}

fn geometry<D: Dim>(mesh: &Mesh<D>) -> ElementGeometry {
    let (d, npe) = (D::D, D::NODES_PER_ELEM);
    let ne = mesh.n_elements();
    let mut g = ElementGeometry {
        dm_inv: vec![0.0; ne * d * d],
        volume: vec![0.0; ne],
        mean_edge: vec![0.0; ne],
        height: vec![0.0; ne],
        dim: d,
    };
    let mut x = [0.0; 12];
    for e in 0..ne {
        mesh.element_coords(e, &mut x[..npe * d]);
        let vol = D::signed_measure(&x[..npe * d]);
        g.volume[e] = vol;
        let (mut sum, mut cnt) = (0.0, 0.0);
        let mut longest = 0.0f64;
        for a in 0..npe {
            for b in a + 1..npe {
                let l = (0..d)
                    .map(|k| (x[a * d + k] - x[b * d + k]).powi(2))
                    .sum::<f64>()
                    .sqrt();
                sum += l;
                cnt += 1.0;
                longest = longest.max(l);
            }
        }
        g.mean_edge[e] = sum / cnt;
        if d == 2 {
            g.height[e] = 2.0 * vol / longest;
            g.dm_inv[e * 4..e * 4 + 4].copy_from_slice(&dm_inv_2d(&x[..6]));
        } else {
            let mut max_face = 0.0f64;
            let mut n = [0.0; 3];
            for f in 0..4 {
                let ln = D::face_local_nodes(f);
                let mut fx = [0.0; 9];
                for (k, &l) in ln.iter().enumerate() {
                    fx[3 * k..3 * k + 3].copy_from_slice(&x[3 * l..3 * l + 3]);
                }
                max_face = max_face.max(D::face_measure_normal(&fx, &mut n));
            }
            g.height[e] = 3.0 * vol / max_face;
            let m = [
                x[3] - x[0],
                x[6] - x[0],
                x[9] - x[0],
                x[4] - x[1],
                x[7] - x[1],
                x[10] - x[1],
                x[5] - x[2],
                x[8] - x[2],
                x[11] - x[2],
            ];
            let it = crate::kinematics::inv_transpose3(&m);
            // (D_m⁻¹)[j][k] = (D_m⁻ᵀ)[k][j]
            for j in 0..3 {
                for k in 0..3 {
                    g.dm_inv[e * 9 + 3 * j + k] = it[3 * k + j];
                }
            }
        }
    }
    g
}

/// Inputs shared by all elements of one force evaluation.
pub(crate) struct StepInputs<'a> {
    pub(crate) conn: &'a [u32],
    pub(crate) u: &'a [f64],
    pub(crate) v: &'a [f64],
    pub(crate) damping: bool,
}

impl Mechanics {
    /// The trace of every mixed-cell element's co-rotated strain (the first pass of the
    /// mixed discretisation, [`crate::mixed`]); in 3D it also finds and stores the
    /// element rotation, which the element pass then uses.
    fn mixed_traces<D: Dim>(
        &self,
        mx: &MixedCells,
        inp: &StepInputs<'_>,
        extra: &mut [f64],
        trace: &mut [f64],
        backend: &Backend,
    ) {
        let d = D::D;
        backend.install(|| {
            if d == 2 {
                trace.par_iter_mut().enumerate().for_each(|(e, t)| {
                    if mx.is_mixed(e) {
                        *t = trace_2d(&self.displacement_gradient_2d(e, inp));
                    }
                });
            } else {
                trace
                    .par_iter_mut()
                    .zip(extra.par_chunks_mut(9))
                    .enumerate()
                    .for_each(|(e, (t, rot))| {
                        if mx.is_mixed(e) {
                            let f = self.deformation_gradient_3d(e, inp);
                            let r_prev: [f64; 9] = (&*rot).try_into().expect("9 values");
                            let r = polar_3d(&f, &r_prev);
                            rot.copy_from_slice(&r);
                            let u = crate::kinematics::mul3_tn(&r, &f);
                            *t = (u[0] - 1.0) + (u[4] - 1.0) + (u[8] - 1.0);
                        }
                    });
            }
        });
    }

    /// The third pass of the mixed discretisation: the nodal forces of a mixed-cell
    /// element take the cell's mean pressure instead of its own, `f_a += −V_e (p̄ − p_e)
    /// R ∇N_a`, so that they are the B̄ forces conjugate to the mixed strain
    /// ([`crate::mixed`]); `p` is the in-plane mean (σ_xx + σ_yy)/2 in plane strain,
    /// tr σ / 3 in 3D.
    #[allow(clippy::too_many_arguments)]
    fn mixed_pressure_forces<D: Dim>(
        &self,
        mx: &MixedCells,
        inp: &StepInputs<'_>,
        stress: &[f64],
        extra: &[f64],
        null: &[f64],
        slots: &mut [f64],
        backend: &Backend,
    ) {
        let (d, npe, nsym) = (D::D, D::NODES_PER_ELEM, D::NSYM);
        let mean = |k: usize| {
            let s = &stress[k * nsym..];
            if d == 2 {
                0.5 * (s[0] + s[1])
            } else {
                (s[0] + s[1] + s[2]) / 3.0
            }
        };
        backend.install(|| {
            slots
                .par_chunks_mut(npe * d)
                .enumerate()
                .for_each(|(e, sl)| {
                    if !mx.is_mixed(e) || null[e] != 0.0 {
                        return;
                    }
                    let f = mx.first[e] as usize;
                    let mut pbar = 0.0;
                    for k in f..f + mx.count[e] as usize {
                        pbar += mx.weight[k] * mean(k);
                    }
                    let dp = (pbar - mean(e)) * self.geo.volume[e];
                    let m = &self.geo.dm_inv[e * d * d..(e + 1) * d * d];
                    if d == 2 {
                        let (co, si, _) = polar_2d_h(&self.displacement_gradient_2d(e, inp));
                        let mut f0 = [0.0; 2];
                        for a in 0..2 {
                            let g = [m[2 * a], m[2 * a + 1]];
                            let fa = [-dp * (co * g[0] - si * g[1]), -dp * (si * g[0] + co * g[1])];
                            sl[2 * (a + 1)] += fa[0];
                            sl[2 * (a + 1) + 1] += fa[1];
                            f0[0] -= fa[0];
                            f0[1] -= fa[1];
                        }
                        sl[0] += f0[0];
                        sl[1] += f0[1];
                    } else {
                        let r = &extra[9 * e..9 * e + 9];
                        let mut f0 = [0.0; 3];
                        for a in 0..3 {
                            for i in 0..3 {
                                let fa = -dp
                                    * (r[3 * i] * m[3 * a]
                                        + r[3 * i + 1] * m[3 * a + 1]
                                        + r[3 * i + 2] * m[3 * a + 2]);
                                sl[3 * (a + 1) + i] += fa;
                                f0[i] -= fa;
                            }
                        }
                        for i in 0..3 {
                            sl[i] += f0[i];
                        }
                    }
                });
        });
    }

    /// Displacement gradient H = [u₁ − u₀, u₂ − u₀] D_m⁻¹ of triangle `e` (row-major).
    #[inline]
    fn displacement_gradient_2d(&self, e: usize, inp: &StepInputs<'_>) -> [f64; 4] {
        let c = &inp.conn[3 * e..3 * e + 3];
        let (n0, n1, n2) = (c[0] as usize * 2, c[1] as usize * 2, c[2] as usize * 2);
        let m = &self.geo.dm_inv[4 * e..4 * e + 4];
        let u = inp.u;
        let (d0, d1) = (u[n1] - u[n0], u[n2] - u[n0]);
        let (d2, d3) = (u[n1 + 1] - u[n0 + 1], u[n2 + 1] - u[n0 + 1]);
        [
            d0 * m[0] + d1 * m[2],
            d0 * m[1] + d1 * m[3],
            d2 * m[0] + d3 * m[2],
            d2 * m[1] + d3 * m[3],
        ]
    }

    /// Deformation gradient F = I + [u_j − u₀] D_m⁻¹ of tetrahedron `e` (row-major).
    #[inline]
    fn deformation_gradient_3d(&self, e: usize, inp: &StepInputs<'_>) -> [f64; 9] {
        let c = &inp.conn[4 * e..4 * e + 4];
        let mut du = [0.0; 9];
        let o = c[0] as usize * 3;
        for i in 0..3 {
            for j in 0..3 {
                du[3 * i + j] = inp.u[c[j + 1] as usize * 3 + i] - inp.u[o + i];
            }
        }
        let mm: [f64; 9] = self.geo.dm_inv[9 * e..9 * e + 9]
            .try_into()
            .expect("9 values");
        let mut f = crate::kinematics::mul3(&du, &mm);
        f[0] += 1.0;
        f[4] += 1.0;
        f[8] += 1.0;
        f
    }
}

impl<D: Dim> Physics<D> for Mechanics {
    fn name(&self) -> &str {
        "mechanics"
    }

    fn kinematic_nodes(&self) -> KinematicNodes {
        KinematicNodes::None
    }

    fn writes_all_slots(&self) -> bool {
        true
    }

    fn fingerprint(&self) -> u64 {
        // The resolved models (their parameters, through Debug), the model of every
        // element and the initial stresses.
        let material: Vec<u32> = self.material.iter().map(|&m| u32::from(m)).collect();
        Fingerprint::new()
            .debug(&self.models)
            .u32s(&material)
            .debug(&self.initial_stress)
            .finish()
    }

    fn fields(&self, _mesh: &Mesh<D>) -> Vec<FieldUse> {
        let n_state = self
            .assignments
            .iter()
            .map(|a| a.1.n_state())
            .max()
            .unwrap_or(0);
        let extra = if D::D == 2 {
            names::STRESS_ZZ.own::<D>()
        } else {
            names::ROTATION.own_sized::<D>(9)
        };
        let mut uses = vec![
            names::STRESS.own::<D>(),
            names::STRAIN.own::<D>(),
            extra,
            names::MODEL_STATE.own_sized::<D>(n_state.max(1)),
            crate::actions::DISPLACEMENT_RESET.own::<D>(),
            names::ELEMENT_NULL.own::<D>(),
        ];
        // Coupling inputs are read lagged: their owners (thermal, fluid) naturally come
        // after the mechanics in a composition, and a fluid physics that reads joint
        // openings must (the joints follow the mechanics), so a current-step read would
        // refuse natural compositions. Lagged, the value is the one the field holds when
        // the forces stage runs: this step's when the owner wrote it earlier in the step
        // (composed before the mechanics, or in a field stage of the previous step),
        // else the previous step's: at most one explicit step old, either way the same
        // on both backends.
        uses.extend(
            CouplingInputs::keys(self.assignments.iter().map(|a| a.1.coupling()))
                .into_iter()
                .map(|k| k.read_lagged::<D>()),
        );
        uses
    }

    fn unique(&self) -> bool {
        true
    }

    fn init(&mut self, ctx: &mut InitContext<'_, D>) -> Result<(), ComputeError> {
        let mesh = ctx.mesh;
        let ne = mesh.n_elements();
        let (material, models) = self.resolve(mesh)?;
        self.consts = models
            .iter()
            .zip(&self.assignments)
            .map(|(m, a)| ModelConsts {
                elastic: a.2,
                damp2: m.damp_factor() * 2.0,
                sqrt_rho_e: (m.density() * m.young()).sqrt(),
            })
            .collect();
        self.models = models;
        self.material = material;
        self.n_state = self.models.iter().map(|m| m.n_state()).max().unwrap_or(0);
        self.geo = geometry(mesh);
        self.mixed = MixedCells::of(mesh, &self.geo.volume);
        self.trace = if self.mixed.is_some() {
            vec![0.0; ne]
        } else {
            Vec::new()
        };
        let models: Vec<(&str, &[FieldKey])> = self
            .models
            .iter()
            .map(|m| (m.name(), m.coupling()))
            .collect();
        self.coupling = CouplingInputs::resolve(&models, ctx.fields, ne, "constitutive model")?;
        let stress = ctx.fields.id(names::STRESS)?;
        let strain = ctx.fields.id(names::STRAIN)?;
        let extra = ctx.fields.id(if D::D == 2 {
            names::STRESS_ZZ
        } else {
            names::ROTATION
        })?;
        let state = ctx.fields.id(names::MODEL_STATE)?;
        let null = ctx.fields.id(names::ELEMENT_NULL)?;
        self.ids = Some(Ids {
            stress,
            strain,
            extra,
            state,
            null,
        });
        if D::D == 3 {
            let rot = ctx.fields.get_mut(extra);
            for r in rot.chunks_exact_mut(9) {
                r.copy_from_slice(&[1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]);
            }
        }
        for (range, field) in &self.initial_stress {
            let sel = mesh.select_elements(range).map_err(MechError::from)?;
            field.check()?;
            let [st, zz] = ctx.fields.get_many_mut([stress, extra]);
            let mut c = [0.0; 3];
            for e in sel {
                let e = e as usize;
                // A Quad4/Hex8 cell starts from one stress, its centroid's.
                if mesh.cells().is_empty() {
                    mesh.element_centroid(e, &mut c[..D::D]);
                } else {
                    mesh.cell_centroid(mesh.cell_of(e), &mut c[..D::D]);
                }
                let s0 = field.at(&c, D::D);
                if D::D == 2 {
                    st[3 * e..3 * e + 3].copy_from_slice(&[s0[0], s0[1], s0[3]]);
                    zz[e] = s0[2];
                } else {
                    st[6 * e..6 * e + 6].copy_from_slice(&s0);
                }
            }
        }
        let ns = self.n_state.max(1);
        let st = ctx.fields.get_mut(state);
        for e in 0..ne {
            let m = self.models[self.material[e] as usize].clone();
            m.init_state_into(&mut st[e * ns..e * ns + m.n_state()]);
        }
        ctx.register_slots(mesh.elements())?;
        Ok(())
    }

    fn add_mass(
        &self,
        mesh: &Mesh<D>,
        fields: &FieldStore,
        mass: &mut [f64],
        scale_to_dt: Option<f64>,
    ) {
        let npe = D::NODES_PER_ELEM;
        let null = fields.id(names::ELEMENT_NULL).ok().map(|id| fields.get(id));
        for (e, conn) in mesh.elements().chunks_exact(npe).enumerate() {
            // A null element has no mass (manual 7.2.8).
            if null.is_some_and(|n| n[e] != 0.0) {
                continue;
            }
            let mut m = self.model_of(e).density() * self.geo.volume[e];
            if let Some(dt) = scale_to_dt {
                let dte = self.element_dt(e, false);
                m *= ((dt / dte) * (dt / dte)).max(0.0);
            }
            // A mixed cell's simplices spread their mass over all the cell's nodes.
            let nodes = match &self.mixed {
                Some(mx) if mx.is_mixed(e) => mesh.cell_nodes(mesh.cell_of(e)),
                _ => conn,
            };
            let m = m / nodes.len() as f64;
            for &n in nodes {
                mass[n as usize] += m;
            }
        }
    }

    fn stable_step(&self, kin: &Kinematics<'_, D>, fields: &FieldStore) -> Option<StableStep> {
        let (mut best, mut which) = (f64::INFINITY, 0);
        let null = fields.id(names::ELEMENT_NULL).ok().map(|id| fields.get(id));
        for e in 0..self.material.len() {
            if null.is_some_and(|n| n[e] != 0.0) {
                continue;
            }
            let dt = self.element_dt(e, kin.damping);
            if dt < best {
                best = dt;
                which = e;
            }
        }
        // Every element null: the mechanics no longer limits the step.
        best.is_finite().then(|| StableStep {
            dt: best,
            entity: Entity::new(EntityKind::Element, which),
            physics: "mechanics".into(),
        })
    }

    fn compute_forces(&mut self, ctx: &mut ForceContext<'_, D>) -> Result<(), ComputeError> {
        let ids = self.ids();
        let (d, npe, nsym) = (D::D, D::NODES_PER_ELEM, D::NSYM);
        let nx = if d == 2 { 1 } else { 9 };
        let ns = self.n_state.max(1);
        let inp = StepInputs {
            conn: ctx.kin.mesh.elements(),
            u: ctx.kin.u,
            v: ctx.kin.v,
            damping: ctx.kin.damping,
        };
        // Coupling values first (reading other physics' fields), then the element loop.
        let cstride = self.coupling.stride;
        let mut cvalues = std::mem::take(&mut self.coupling.values);
        if cstride > 0 {
            self.gather_coupling::<D>(inp.conn, ctx.fields, &mut cvalues, ctx.backend);
        }
        let cref = &cvalues;
        let [stress, strain, extra, state, null] = ctx
            .fields
            .get_many_mut([ids.stress, ids.strain, ids.extra, ids.state, ids.null]);
        let null = &*null;
        if let Some(mx) = &self.mixed {
            let mut trace = std::mem::take(&mut self.trace);
            self.mixed_traces::<D>(mx, &inp, extra, &mut trace, ctx.backend);
            self.trace = trace;
        }
        let trace = &self.trace;
        let slots = &mut *ctx.slots;
        // Only the built-in elastic law: one element at a time, halves back to back.
        let all_inline = self.consts.iter().all(|k| k.elastic.is_some());
        ctx.backend.install(|| {
            slots
                .par_chunks_mut(CHUNK * npe * d)
                .zip(stress.par_chunks_mut(CHUNK * nsym))
                .zip(strain.par_chunks_mut(CHUNK * nsym))
                .zip(extra.par_chunks_mut(CHUNK * nx))
                .zip(state.par_chunks_mut(CHUNK * ns))
                .enumerate()
                .for_each(|(chunk, ((((sl, st), ep), ex), ms))| {
                    let first = chunk * CHUNK;
                    if all_inline {
                        self.elastic_chunk::<D>(first, &inp, sl, st, ep, ex, null, trace);
                    } else {
                        let cv = |e: usize| -> &[f64] {
                            if cstride == 0 {
                                &[]
                            } else {
                                let n = self.coupling.len_of_model[self.material[e] as usize];
                                &cref[e * cstride..e * cstride + n]
                            }
                        };
                        self.model_chunk::<D>(first, &inp, sl, st, ep, ex, ms, null, trace, cv);
                    }
                });
        });
        self.coupling.values = cvalues;
        if let Some(mx) = &self.mixed {
            self.mixed_pressure_forces::<D>(mx, &inp, stress, extra, null, slots, ctx.backend);
        }
        Ok(())
    }

    fn gpu_setup(&mut self, setup: &mut GpuSetup<'_, D>) -> Result<(), ComputeError> {
        let (d, ne) = (D::D, self.material.len());
        // One WGSL function per distinct model code; parameters per material.
        let mut bodies = Vec::with_capacity(self.models.len());
        for m in &self.models {
            bodies.push(m.wgsl().ok_or_else(|| ComputeError::NoGpuKernel {
                physics: "mechanics".into(),
                reason: format!(
                    "constitutive model '{}' has no WGSL body (implement ConstitutiveModel::wgsl)",
                    m.name()
                ),
            })?);
        }
        // With coupling, every model function takes `coupling: Coupling` before `p`.
        let coupled = self.coupling.stride > 0;
        let (params, args) = if coupled {
            (
                "strain: Sym, dstrain: Sym, stress: Sym, state: ptr<function, ModelState>, coupling: Coupling, p: u32",
                "strain, dstrain, stress, state, coupling, p",
            )
        } else {
            (
                "strain: Sym, dstrain: Sym, stress: Sym, state: ptr<function, ModelState>, p: u32",
                "strain, dstrain, stress, state, p",
            )
        };
        let splice = splice_models(
            "model",
            params,
            args,
            "Sym",
            Some("stress"),
            bodies.iter().map(|w| (w.key.as_str(), w.body.as_str())),
        );
        let mut mat_info = Vec::with_capacity(2 * bodies.len());
        let mut params = Vec::new();
        for (w, kind) in bodies.iter().zip(&splice.kinds) {
            mat_info.extend([*kind, params.len() as u32]);
            params.extend_from_slice(&w.params);
        }
        if params.is_empty() {
            params.push(0.0);
        }
        // Per element: D_m⁻¹ (row-major), V₀, viscous coefficient D_f C (eq. 18-19).
        let stride = d * d + 2;
        let mut geo = Vec::with_capacity(ne * stride);
        for e in 0..ne {
            geo.extend_from_slice(&self.geo.dm_inv[e * d * d..(e + 1) * d * d]);
            geo.push(self.geo.volume[e]);
            geo.push(self.viscous_coefficient(e));
        }
        let conn = setup.upload("connectivity", GpuData::U32(setup.mesh.elements().to_vec()));
        let geo = setup.upload("element geometry", GpuData::Real(geo));
        let material = setup.upload(
            "element material",
            GpuData::U32(self.material.iter().map(|&m| m as u32).collect()),
        );
        let mat_info = setup.upload("material kinds", GpuData::U32(mat_info));
        let mat_params = setup.upload("material parameters", GpuData::Real(params));
        let ns = self.n_state.max(1);
        let template = if d == 2 {
            include_str!("shaders/element_2d.wgsl")
        } else {
            include_str!("shaders/element_3d.wgsl")
        };
        // The templates mark the model call's coupling argument with `/*coupling*/`:
        // `coupling_of(e, mat), ` with coupling, nothing (the source unchanged) without.
        let (coupling_src, template) = if coupled {
            (
                self.coupling_wgsl::<D>(),
                template.replace("/*coupling*/", "coupling_of(e, mat), "),
            )
        } else {
            (String::new(), template.replace("/*coupling*/", ""))
        };
        // Mixed Quad4/Hex8 cells: the cell's mean volumetric strain, and in 3D the
        // rotation found by the trace pass ([`crate::mixed`]).
        let mixed = self.mixed.is_some();
        let template = match (mixed, d) {
            (false, _) => template
                .replace("/*mixed*/", "")
                .replace("/*polar*/", "let r = polar_3d(f, r_prev);"),
            (true, 2) => template.replace(
                "/*mixed*/",
                "if cell_count[e] > 1u {\n        let corr = 0.5 * (cell_mean(e) - trace_2d(h0, h1, h2, h3));\n        eps[0] = eps[0] + corr;\n        eps[1] = eps[1] + corr;\n    }",
            ),
            (true, _) => template
                .replace(
                    "/*polar*/",
                    "var r = r_prev;\n    if cell_count[e] <= 1u {\n        r = polar_3d(f, r_prev);\n    }",
                )
                .replace(
                    "/*mixed*/",
                    "if cell_count[e] > 1u {\n        let corr = (cell_mean(e) - (eps[0] + eps[1] + eps[2])) / 3.0;\n        eps[0] = eps[0] + corr;\n        eps[1] = eps[1] + corr;\n        eps[2] = eps[2] + corr;\n    }",
                ),
        };
        let mixed_lib = if mixed {
            include_str!("shaders/mixed_lib.wgsl")
        } else {
            ""
        };
        // Helper functions once per distinct model code; a wrapper's functions start
        // with its inner model's (`ThermalStrain`), which are spliced once even when
        // the inner model is also used unwrapped.
        let mut functions = String::new();
        let mut seen: Vec<&str> = Vec::new();
        for w in &bodies {
            let f = w.functions.as_str();
            if seen.iter().any(|s| s.starts_with(f)) {
                continue;
            }
            let done = seen
                .iter()
                .filter(|s| !s.is_empty() && f.starts_with(**s))
                .map(|s| s.len())
                .max()
                .unwrap_or(0);
            seen.push(f);
            functions.push_str(&f[done..]);
            functions.push('\n');
        }
        let source = format!(
            "alias Sym = array<Real, 6>;\nalias ModelState = array<Real, NSTATE>;\nfn param(p: u32, k: u32) -> Real {{ return mat_params[p + k]; }}\n{coupling_src}{functions}{}{mixed_lib}{template}",
            splice.source
        );
        let polar_tol = match setup.precision() {
            pcdc_compute::Precision::F64 => 1e-15,
            pcdc_compute::Precision::F32 => 1e-6,
        };
        let extra = if d == 2 {
            ("stress_zz", setup.field(names::STRESS_ZZ)?)
        } else {
            ("rotation", setup.field(names::ROTATION)?)
        };
        let cells = self.mixed.as_ref().map(|mx| {
            let first = setup.upload("cell first element", GpuData::U32(mx.first.clone()));
            let count = setup.upload("cell element count", GpuData::U32(mx.count.clone()));
            let weight = setup.upload("cell volume share", GpuData::Real(mx.weight.clone()));
            let trace = setup.upload("cell strain trace", GpuData::Real(vec![0.0; ne]));
            [first, count, weight, trace]
        });
        let bind_cells = |k: Kernel| match cells {
            Some([first, count, weight, trace]) => k
                .bind("cell_first", first, Access::Read)
                .bind("cell_count", count, Access::Read)
                .bind("cell_weight", weight, Access::Read)
                .bind("cell_trace", trace, Access::ReadWrite),
            None => k,
        };
        if mixed {
            let (helpers, body) = if d == 2 {
                ("", include_str!("shaders/mixed_trace_2d.wgsl"))
            } else {
                let t = include_str!("shaders/element_3d.wgsl");
                let at = t
                    .find("fn kernel(e: u32)")
                    .expect("the 3D template's kernel");
                (&t[..at], include_str!("shaders/mixed_trace_3d.wgsl"))
            };
            let src = format!("alias Sym = array<Real, 6>;\n{helpers}{mixed_lib}{body}");
            let trace_kernel = Kernel::new(format!("mechanics mixed trace {}", D::NAME), src, ne)
                .const_u32("GEO", stride as u32)
                .const_real("POLAR_TOL", polar_tol)
                .bind("disp", setup.displacement(), Access::Read)
                .bind("conn", conn, Access::Read)
                .bind("geo", geo, Access::Read);
            let trace_kernel = if d == 3 {
                trace_kernel.bind("rotation", extra.1, Access::ReadWrite)
            } else {
                trace_kernel
            };
            setup.kernel(Phase::Forces, bind_cells(trace_kernel))?;
        }
        let kernel = Kernel::new(format!("mechanics {}", D::NAME), source, ne)
            .const_u32("SLOT_FIRST", setup.slot_first())
            .const_u32("NSTATE", ns as u32)
            .const_u32("GEO", stride as u32)
            .const_real("POLAR_TOL", polar_tol)
            .bind("coords", setup.coords(), Access::Read)
            .bind("disp", setup.displacement(), Access::Read)
            .bind("vel", setup.velocity(), Access::Read)
            .bind("conn", conn, Access::Read)
            .bind("geo", geo, Access::Read)
            .bind("material", material, Access::Read)
            .bind("mat_info", mat_info, Access::Read)
            .bind("mat_params", mat_params, Access::Read)
            .bind("stress", setup.field(names::STRESS)?, Access::ReadWrite)
            .bind("strain", setup.field(names::STRAIN)?, Access::ReadWrite)
            .bind(extra.0, extra.1, Access::ReadWrite)
            .bind(
                "model_state",
                setup.field(names::MODEL_STATE)?,
                Access::ReadWrite,
            )
            .bind(
                "element_null",
                setup.field(names::ELEMENT_NULL)?,
                Access::Read,
            )
            .bind("slots", setup.slots(), Access::ReadWrite);
        let kernel = bind_cells(kernel);
        let kernel = if coupled {
            self.coupling
                .bind(setup, kernel, "mat_coupling", "material coupling")?
        } else {
            kernel
        };
        setup.kernel(Phase::Forces, kernel)?;
        if mixed {
            let body = if d == 2 {
                format!(
                    "{mixed_lib}{}",
                    include_str!("shaders/mixed_pressure_2d.wgsl")
                )
            } else {
                include_str!("shaders/mixed_pressure_3d.wgsl").to_string()
            };
            let pressure = Kernel::new(format!("mechanics mixed pressure {}", D::NAME), body, ne)
                .const_u32("SLOT_FIRST", setup.slot_first())
                .const_u32("GEO", stride as u32)
                .bind("disp", setup.displacement(), Access::Read)
                .bind("conn", conn, Access::Read)
                .bind("geo", geo, Access::Read)
                .bind("stress", setup.field(names::STRESS)?, Access::Read)
                .bind(
                    "element_null",
                    setup.field(names::ELEMENT_NULL)?,
                    Access::Read,
                )
                .bind("slots", setup.slots(), Access::ReadWrite);
            let pressure = if d == 3 {
                pressure.bind("rotation", extra.1, Access::Read)
            } else {
                pressure
            };
            setup.kernel(Phase::Forces, bind_cells(pressure))?;
        }
        Ok(())
    }

    fn linear_stiffness(
        &self,
        mesh: &Mesh<D>,
        _fields: &FieldStore,
        trip: &mut Vec<(usize, usize, f64)>,
    ) -> Result<bool, ComputeError> {
        let (d, npe) = (D::D, D::NODES_PER_ELEM);
        let mut tangents = Vec::with_capacity(mesh.n_elements());
        for e in 0..mesh.n_elements() {
            let model = self.model_of(e);
            tangents.push(model.linear_tangent().ok_or_else(|| {
                ComputeError::NotLinear(format!(
                    "model '{}' of element {e} is not linear",
                    model.name()
                ))
            })?);
        }
        let grad_of = |e: usize| {
            let m = &self.geo.dm_inv[e * d * d..(e + 1) * d * d];
            let mut grad = [[0.0; 3]; 4];
            for a in 1..npe {
                for k in 0..d {
                    grad[a][k] = m[(a - 1) * d + k];
                    grad[0][k] -= m[(a - 1) * d + k];
                }
            }
            grad
        };
        for e in 0..mesh.n_elements() {
            let t = tangents[e];
            // C_ijkl from the 6x6 tangent on tensor components.
            let voigt = |i: usize, j: usize| -> usize {
                match (i.min(j), i.max(j)) {
                    (0, 0) => 0,
                    (1, 1) => 1,
                    (2, 2) => 2,
                    (0, 1) => 3,
                    (1, 2) => 4,
                    _ => 5,
                }
            };
            let cijkl = |i: usize, j: usize, k: usize, l: usize| -> f64 {
                let b = voigt(k, l);
                t[voigt(i, j)][b] / if b >= 3 { 2.0 } else { 1.0 }
            };
            if let Some(mx) = self.mixed.as_ref().filter(|mx| mx.is_mixed(e)) {
                // The B̄ stiffness of the whole cell, once, at its first element.
                if mx.first[e] as usize == e {
                    let c = |el: usize, i: usize, j: usize, k: usize, l: usize| {
                        let b = voigt(k, l);
                        tangents[el][voigt(i, j)][b] / if b >= 3 { 2.0 } else { 1.0 }
                    };
                    crate::mixed::cell_stiffness(
                        d,
                        e..e + mx.count[e] as usize,
                        &self.geo.volume,
                        &grad_of,
                        &|el| mesh.element(el).to_vec(),
                        &c,
                        trip,
                    );
                }
                continue;
            }
            let grad = grad_of(e);
            let vol = self.geo.volume[e];
            let conn = mesh.element(e);
            for a in 0..npe {
                for b in 0..npe {
                    for i in 0..d {
                        for k in 0..d {
                            let mut kv = 0.0;
                            for j in 0..d {
                                for l in 0..d {
                                    kv += grad[a][j] * cijkl(i, j, k, l) * grad[b][l];
                                }
                            }
                            trip.push((
                                conn[a] as usize * d + i,
                                conn[b] as usize * d + k,
                                vol * kv,
                            ));
                        }
                    }
                }
            }
        }
        Ok(true)
    }

    fn slot_entity(&self, slot: usize) -> Option<String> {
        Some(format!("element {}", slot / D::NODES_PER_ELEM))
    }

    fn stored_energy(&self, _kin: &Kinematics<'_, D>, fields: &FieldStore) -> f64 {
        let ids = self.ids();
        let (st, ep, ex) = (
            fields.get(ids.stress),
            fields.get(ids.strain),
            fields.get(ids.extra),
        );
        let nsym = D::NSYM;
        (0..self.material.len())
            .map(|e| {
                let (s, t) = if D::D == 2 {
                    let s = &st[3 * e..3 * e + 3];
                    let t = &ep[3 * e..3 * e + 3];
                    (
                        [s[0], s[1], ex[e], s[2], 0.0, 0.0],
                        [t[0], t[1], 0.0, t[2], 0.0, 0.0],
                    )
                } else {
                    let s = &st[nsym * e..nsym * e + 6];
                    let t = &ep[nsym * e..nsym * e + 6];
                    (
                        [s[0], s[1], s[2], s[3], s[4], s[5]],
                        [t[0], t[1], t[2], t[3], t[4], t[5]],
                    )
                };
                0.5 * self.geo.volume[e] * double_dot(&s, &t)
            })
            .sum()
    }
}

/// Checks what the integrator takes from a constitutive model (a plugin may report
/// anything): density and P-wave modulus positive and finite, damping factor
/// non-negative and finite. The error names the material and its model.
fn check_model(i: usize, model: &dyn ConstitutiveModel) -> Result<(), MechError> {
    let checks = [
        ("density", model.density(), false),
        ("wave modulus", model.wave_modulus(), false),
        ("damping factor", model.damp_factor(), true),
    ];
    for (what, v, zero_ok) in checks {
        let ok = v.is_finite() && (v > 0.0 || (zero_ok && v == 0.0));
        if !ok {
            let sign = if zero_ok { "non-negative" } else { "positive" };
            return Err(MechError::param(
                format!("{what} of material {i} ({})", model.name()),
                v,
                format!("must be {sign} and finite"),
            ));
        }
    }
    Ok(())
}

#[cfg(test)]
mod gpu_tests {
    use super::*;
    use crate::LinearElastic;
    use pcdc_compute::gpu::{offline_kernel_sources, validate_wgsl};
    use pcdc_compute::Precision;
    use pcdc_mesh::builders;

    /// A model with two history variables and no WGSL body (CPU only).
    #[derive(Debug)]
    struct CpuOnly;
    impl ConstitutiveModel for CpuOnly {
        fn name(&self) -> &str {
            "cpu-only"
        }
        fn density(&self) -> f64 {
            2000.0
        }
        fn young(&self) -> f64 {
            1e9
        }
        fn wave_modulus(&self) -> f64 {
            1e9
        }
        fn damp_factor(&self) -> f64 {
            0.0
        }
        fn n_state(&self) -> usize {
            2
        }
        fn update(&self, _: &Sym6, _: &Sym6, _: &mut Sym6, _: &mut [f64]) {}
    }

    fn mech(e: f64) -> Mechanics {
        Mechanics::new()
            .material(Range::All, LinearElastic::new(e, 0.25, 2500.0).unwrap())
            .material(
                Range::Ball {
                    center: [0.0; 3],
                    radius: 0.6,
                },
                LinearElastic::new(2.0 * e, 0.2, 2600.0).unwrap(),
            )
    }

    #[test]
    fn element_kernels_validate_with_naga() {
        let m2 = builders::rectangle(0.0, 0.0, 1.0, 1.0, 0.25).unwrap();
        let m3 = builders::cuboid([0.0; 3], [1.0; 3], 0.5).unwrap();
        for p in [Precision::F64, Precision::F32] {
            let s2 = offline_kernel_sources::<_>(&m2, vec![Box::new(mech(1e9))], p).unwrap();
            let s3 = offline_kernel_sources::<_>(&m3, vec![Box::new(mech(1e9))], p).unwrap();
            for (label, src) in s2.iter().chain(&s3) {
                if let Err(e) = validate_wgsl(src) {
                    panic!("{label} ({}) does not validate:\n{e}", p.name());
                }
            }
            // Two materials of one model share one WGSL function.
            let (_, src) = &s2[0];
            assert_eq!(src.matches("fn model_").count(), 1);
        }
    }

    /// The mixed Quad4/Hex8 kernels: the trace pass and the element pass with the cell
    /// mean, in 2D (mixed with Tri3) and 3D.
    #[test]
    fn mixed_cell_kernels_validate_with_naga() {
        let m2 = builders::ring_mixed([1.0, 0.0], 0.3, 1.2, 0.1).unwrap();
        let m3 = builders::cuboid_hexes([0.0; 3], [1.0; 3], 0.5).unwrap();
        for p in [Precision::F64, Precision::F32] {
            let s2 = offline_kernel_sources::<_>(&m2, vec![Box::new(mech(1e9))], p).unwrap();
            let s3 = offline_kernel_sources::<_>(&m3, vec![Box::new(mech(1e9))], p).unwrap();
            for (label, src) in s2.iter().chain(&s3) {
                if let Err(e) = validate_wgsl(src) {
                    panic!("{label} ({}) does not validate:\n{e}", p.name());
                }
            }
            for s in [&s2, &s3] {
                let mech: Vec<&String> = (s.iter())
                    .filter(|(l, _)| l.starts_with("mechanics"))
                    .map(|(_, src)| src)
                    .collect();
                assert_eq!(mech.len(), 3, "the trace, element and pressure passes");
                assert!(mech[1].contains("cell_mean(e)"));
            }
        }
    }

    #[test]
    fn mohr_coulomb_kernels_validate_with_naga() {
        use crate::mohr_coulomb::{MohrCoulomb, Softening};
        let e = LinearElastic::new(1e9, 0.25, 2500.0).unwrap();
        let plain = MohrCoulomb::new(e.clone(), 1e6, 30.0, 5.0, 0.5e6).unwrap();
        let t = |p: &[(f64, f64)]| Some(pcdc_compute::Table::new("t", p).unwrap());
        let soft = plain
            .clone()
            .with_softening(Softening {
                cohesion: t(&[(0.0, 1e6), (1e-3, 0.2e6)]),
                tensile: t(&[(0.0, 0.5e6), (1e-4, 0.0)]),
                ..Default::default()
            })
            .unwrap();
        let mech = || {
            Mechanics::new()
                .material(Range::All, plain.clone())
                .material(
                    Range::Ball {
                        center: [0.0; 3],
                        radius: 0.6,
                    },
                    soft.clone(),
                )
                .material(
                    Range::Ball {
                        center: [1.0; 3],
                        radius: 0.8,
                    },
                    LinearElastic::new(2e9, 0.2, 2600.0).unwrap(),
                )
        };
        let m2 = builders::rectangle(0.0, 0.0, 1.0, 1.0, 0.25).unwrap();
        let m3 = builders::cuboid([0.0; 3], [1.0; 3], 0.5).unwrap();
        for p in [Precision::F64, Precision::F32] {
            let s2 = offline_kernel_sources::<_>(&m2, vec![Box::new(mech())], p).unwrap();
            let s3 = offline_kernel_sources::<_>(&m3, vec![Box::new(mech())], p).unwrap();
            for (label, src) in s2.iter().chain(&s3) {
                if let Err(e) = validate_wgsl(src) {
                    panic!("{label} ({}) does not validate:\n{e}", p.name());
                }
            }
            // Two Mohr–Coulomb materials share one function and one copy of its helpers.
            let (_, src) = &s2[0];
            assert_eq!(src.matches("fn model_").count(), 2);
            assert_eq!(src.matches("fn mc_return").count(), 1);
        }
    }

    #[test]
    fn burgers_kernels_validate_with_naga() {
        use crate::burgers::{Burgers, CreepClock};
        let e = LinearElastic::new(1e9, 0.25, 2500.0).unwrap();
        let b = Burgers::new(e, 2e9, 1e12, 1e13).unwrap();
        let m2 = builders::rectangle(0.0, 0.0, 1.0, 1.0, 0.25).unwrap();
        let m3 = builders::cuboid([0.0; 3], [1.0; 3], 0.5).unwrap();
        for p in [Precision::F64, Precision::F32] {
            fn physics<D: Dim>(b: &Burgers) -> Vec<Box<dyn Physics<D>>> {
                vec![
                    Box::new(Mechanics::new().material(Range::All, b.clone()).material(
                        Range::Ball {
                            center: [0.0; 3],
                            radius: 0.6,
                        },
                        LinearElastic::new(2e9, 0.2, 2600.0).unwrap(),
                    )),
                    Box::new(CreepClock::new(&[b], 0.1).unwrap()),
                ]
            }
            let s2 = offline_kernel_sources::<_>(&m2, physics(&b), p).unwrap();
            let s3 = offline_kernel_sources::<_>(&m3, physics(&b), p).unwrap();
            for (label, src) in s2.iter().chain(&s3) {
                if let Err(e) = validate_wgsl(src) {
                    panic!("{label} ({}) does not validate:\n{e}", p.name());
                }
            }
        }
    }

    #[test]
    fn model_without_wgsl_is_a_build_error_naming_it() {
        let m2 = builders::rectangle(0.0, 0.0, 1.0, 1.0, 0.5).unwrap();
        let mech = Mechanics::new().material(Range::All, CpuOnly);
        let err =
            offline_kernel_sources::<_>(&m2, vec![Box::new(mech)], Precision::F64).unwrap_err();
        let msg = err.to_string();
        assert!(msg.contains("cpu-only") && msg.contains("WGSL"), "{msg}");
    }
}
