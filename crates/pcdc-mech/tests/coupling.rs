//! Coupling inputs of constitutive models: a model declares the fields it reads
//! (`ConstitutiveModel::coupling`) and receives their values at each element in
//! `ModelInput::coupling`, on the CPU and in its WGSL body.
//!
//! The thermo-elastic test model adds the thermal stress increment −3Kα ΔT I to linear
//! elasticity (σ = C:(ε − α (T − T0) I) in total form, 3K = E / (1 − 2ν)). Closed forms
//! used below, with ΔT = T − T0 uniform, tension positive:
//!
//! * Fully clamped block (ε = 0, plane strain in 2D or 3D): σxx = σyy = σzz =
//!   −3Kα ΔT = −E α ΔT / (1 − 2ν), no shear.
//! * Plane-strain block confined laterally (εxx = 0, ε_zz = 0) with its top free
//!   (σyy = 0): σyy = (λ + 2μ) εyy − 3Kα ΔT = 0 gives
//!   εyy = 3Kα ΔT / (λ + 2μ) = (1 + ν)/(1 − ν) α ΔT (as 3K = E/(1−2ν) and
//!   λ + 2μ = E(1−ν) / ((1+ν)(1−2ν))), and σxx = σzz = λ εyy − 3Kα ΔT
//!   = −3Kα ΔT · 2μ/(λ + 2μ) = −E α ΔT / (1 − ν) (as 2μ/(λ + 2μ) = (1−2ν)/(1−ν)).
//!   (The block free in its plane, σxx = σyy = 0, ε = (1 + ν) α ΔT, σzz = −E α ΔT, is
//!   stress-free in the plane, so the static solver's force-ratio test cannot converge
//!   on it: no nodal force is left to compare with.)

use pcdc_compute::gpu::{gpu_test_backend, offline_kernel_sources};
use pcdc_compute::{
    names, Backend, Components, ComputeError, FieldKey, FieldStore, FieldUse, ForceContext,
    InitContext, Physics, Place, Precision, Simulation, StaticOptions,
};
use pcdc_mech::{
    Boundary, ConstitutiveModel, LinearElastic, Mechanics, ModelInput, MohrCoulomb, Sym6,
    ThermalStrain, WgslModel,
};
use pcdc_mesh::{builders, Dim, Mesh, Range};

const E: f64 = 30e9;
const NU: f64 = 0.25;
const RHO: f64 = 2600.0;
/// Linear thermal expansion coefficient α (1/K).
const ALPHA: f64 = 1e-5;
/// Reference temperature T0 (K).
const T0: f64 = 293.15;
/// Temperature change ΔT (K).
const DT: f64 = 100.0;

/// A test element field (say, a saturation), to exercise element-placed coupling.
const SATURATION: FieldKey = FieldKey::new("test_saturation", Place::Element, Components::Fixed(1));

/// Linear elasticity plus an isotropic coupling stress: for each declared field i,
/// σ_kk −= c_i (v_i − v_i,prev) (k = xx, yy, zz), v_i,prev kept in the history (state
/// i), starting at `reference[i]`. With TEMPERATURE and c = 3Kα it is thermo-elasticity;
/// with PORE_PRESSURE and c = b (Biot) it turns effective into total stress.
#[derive(Debug)]
struct Coupled {
    elastic: LinearElastic,
    keys: Vec<FieldKey>,
    coef: Vec<f64>,
    reference: Vec<f64>,
}

impl Coupled {
    fn thermal() -> Self {
        let elastic = LinearElastic::new(E, NU, RHO).unwrap();
        let c = 3.0 * elastic.bulk() * ALPHA;
        Coupled {
            elastic,
            keys: vec![names::TEMPERATURE],
            coef: vec![c],
            reference: vec![T0],
        }
    }
}

impl ConstitutiveModel for Coupled {
    fn name(&self) -> &str {
        "test-coupled-elastic"
    }
    fn density(&self) -> f64 {
        self.elastic.density()
    }
    fn young(&self) -> f64 {
        self.elastic.young()
    }
    fn wave_modulus(&self) -> f64 {
        ConstitutiveModel::wave_modulus(&self.elastic)
    }
    fn damp_factor(&self) -> f64 {
        0.0
    }
    fn n_state(&self) -> usize {
        self.keys.len()
    }
    fn init_state_into(&self, state: &mut [f64]) {
        state.copy_from_slice(&self.reference);
    }
    fn coupling(&self) -> &[FieldKey] {
        &self.keys
    }
    /// The law at the reference values (no coupling change).
    fn update(&self, strain: &Sym6, dstrain: &Sym6, stress: &mut Sym6, state: &mut [f64]) {
        self.elastic.update(strain, dstrain, stress, state);
    }
    fn update_with(&self, input: &ModelInput<'_>, stress: &mut Sym6, state: &mut [f64]) {
        let ds = self.elastic.stress_of(input.dstrain);
        for k in 0..6 {
            stress[k] += ds[k];
        }
        for (i, &v) in input.coupling.iter().enumerate() {
            let th = self.coef[i] * (v - state[i]);
            state[i] = v;
            stress[0] -= th;
            stress[1] -= th;
            stress[2] -= th;
        }
    }
    fn linear_tangent(&self) -> Option<[[f64; 6]; 6]> {
        self.elastic.linear_tangent()
    }
    fn wgsl(&self) -> Option<WgslModel> {
        let n = self.keys.len();
        // `coupling` exists only when a model of the mechanics declares coupling fields:
        // a model that declares none must not name it.
        let gather = if n == 0 {
            String::new()
        } else {
            format!(
                "for (var i = 0u; i < {n}u; i = i + 1u) {{
    let th = param(p, 2u + i) * (coupling[i] - (*state)[i]);
    (*state)[i] = coupling[i];
    s[0] = s[0] - th;
    s[1] = s[1] - th;
    s[2] = s[2] - th;
}}"
            )
        };
        let body = format!(
            "let l = param(p, 0u);
let mu = param(p, 1u);
let tr = dstrain[0] + dstrain[1] + dstrain[2];
var s = stress;
s[0] = s[0] + (l * tr + 2.0 * mu * dstrain[0]);
s[1] = s[1] + (l * tr + 2.0 * mu * dstrain[1]);
s[2] = s[2] + (l * tr + 2.0 * mu * dstrain[2]);
s[3] = s[3] + 2.0 * mu * dstrain[3];
s[4] = s[4] + 2.0 * mu * dstrain[4];
s[5] = s[5] + 2.0 * mu * dstrain[5];
{gather}
return s;"
        );
        let mut params = vec![self.elastic.lambda(), self.elastic.shear()];
        params.extend_from_slice(&self.coef);
        Some(WgslModel {
            key: format!("test_coupled_{n}"),
            body,
            params,
            ..Default::default()
        })
    }
}

/// A test physics that owns one field and holds it at given values (per node or per
/// element, by the key's place); no forces, no GPU kernel needed.
struct Given {
    name: String,
    key: FieldKey,
    values: Vec<f64>,
}

impl Given {
    /// The field `key` at `f(x)` for every node (node key) or element centroid.
    fn at<D: Dim>(mesh: &Mesh<D>, key: FieldKey, f: impl Fn(&[f64]) -> f64) -> Self {
        let values = match key.place() {
            Place::Node => (0..mesh.n_nodes()).map(|n| f(mesh.node(n))).collect(),
            _ => (0..mesh.n_elements())
                .map(|e| {
                    let mut c = [0.0; 3];
                    for &n in mesh.element(e) {
                        for (c, x) in c.iter_mut().zip(mesh.node(n as usize)) {
                            *c += x / D::NODES_PER_ELEM as f64;
                        }
                    }
                    f(&c[..D::D])
                })
                .collect(),
        };
        Given {
            name: format!("given {}", key.name()),
            key,
            values,
        }
    }

    fn uniform<D: Dim>(mesh: &Mesh<D>, key: FieldKey, v: f64) -> Self {
        Self::at(mesh, key, |_| v)
    }
}

impl<D: Dim> Physics<D> for Given {
    fn name(&self) -> &str {
        &self.name
    }
    fn fields(&self, _mesh: &Mesh<D>) -> Vec<FieldUse> {
        vec![self.key.own::<D>()]
    }
    fn init(&mut self, ctx: &mut InitContext<'_, D>) -> Result<(), ComputeError> {
        let id = ctx.fields.id(self.key)?;
        ctx.fields.get_mut(id).copy_from_slice(&self.values);
        Ok(())
    }
    fn compute_forces(&mut self, _ctx: &mut ForceContext<'_, D>) -> Result<(), ComputeError> {
        Ok(())
    }
    fn linear_stiffness(
        &self,
        _mesh: &Mesh<D>,
        _fields: &FieldStore,
        _triplets: &mut Vec<(usize, usize, f64)>,
    ) -> Result<bool, ComputeError> {
        Ok(false)
    }
    fn gpu_setup(
        &mut self,
        _setup: &mut pcdc_compute::gpu::GpuSetup<'_, D>,
    ) -> Result<(), ComputeError> {
        Ok(())
    }
}

fn field_names(fields: &FieldStore) -> Vec<String> {
    fields.specs().iter().map(|s| s.name.clone()).collect()
}

/// −E α ΔT / (1 − 2ν): the stress of a fully clamped block (Pa).
fn clamped_stress() -> f64 {
    -E * ALPHA * DT / (1.0 - 2.0 * NU)
}

/// Checks every element's stress of a fully clamped block against the closed form.
fn check_clamped<D: Dim>(sim: &Simulation<D>) {
    let s = sim.field(names::STRESS).unwrap();
    let expect = clamped_stress();
    let mut worst = 0.0f64;
    for e in 0..sim.mesh().n_elements() {
        let (normal, shear): (Vec<f64>, Vec<f64>) = if D::D == 2 {
            let zz = sim.field(names::STRESS_ZZ).unwrap()[e];
            (vec![s[3 * e], s[3 * e + 1], zz], vec![s[3 * e + 2]])
        } else {
            (
                s[6 * e..6 * e + 3].to_vec(),
                s[6 * e + 3..6 * e + 6].to_vec(),
            )
        };
        for v in normal {
            worst = worst.max(((v - expect) / expect).abs());
        }
        for v in shear {
            worst = worst.max((v / expect).abs());
        }
    }
    println!(
        "{} clamped: σ = {:.6e} Pa expected, worst relative error {worst:.2e}",
        D::NAME,
        expect
    );
    assert!(worst < 1e-12, "worst relative error {worst:e}");
}

/// 2D plane strain, fully clamped: σxx = σyy = σzz = −E α ΔT / (1 − 2ν) in every
/// element, every step. The temperature owner is composed after the mechanics (a
/// lagged read needs no order) and holds T0 + ΔT from the start.
#[test]
fn clamped_plane_strain_block_thermal_stress() {
    let mesh = builders::rectangle(0.0, 0.0, 0.2, 0.1, 0.02).unwrap();
    let heat = Given::uniform(&mesh, names::TEMPERATURE, T0 + DT);
    let mut sim = Simulation::builder(mesh, Backend::cpu(2).unwrap())
        .physics(Mechanics::new().material(Range::All, Coupled::thermal()))
        .physics(Boundary::new().fix(Range::All))
        .physics(heat)
        .build()
        .unwrap();
    sim.run(5).unwrap();
    check_clamped(&sim);
    assert!(sim.state.u.iter().all(|&u| u == 0.0));
}

/// 3D, fully clamped: the same closed form for the three normal stresses.
#[test]
fn clamped_3d_block_thermal_stress() {
    let mesh = builders::cuboid([0.0; 3], [0.1, 0.05, 0.05], 0.025).unwrap();
    let heat = Given::uniform(&mesh, names::TEMPERATURE, T0 + DT);
    let mut sim = Simulation::builder(mesh, Backend::cpu(2).unwrap())
        .physics(heat)
        .physics(Mechanics::new().material(Range::All, Coupled::thermal()))
        .physics(Boundary::new().fix(Range::All))
        .build()
        .unwrap();
    sim.run(3).unwrap();
    check_clamped(&sim);
}

/// 2D plane strain, laterally confined (left and right edges held in x, bottom edge
/// held in y, top free), static direct solve: σxx = σzz = −E α ΔT / (1 − ν), σyy =
/// σxy = 0, and the top rises by (1 + ν)/(1 − ν) α ΔT H.
#[test]
fn confined_plane_strain_block_thermal_stress() {
    let (w, h) = (0.2, 0.1);
    let mesh = builders::rectangle(0.0, 0.0, w, h, 0.02).unwrap();
    let heat = Given::uniform(&mesh, names::TEMPERATURE, T0 + DT);
    let mut hold_x = [None, None, None];
    hold_x[0] = Some(0.0.into());
    let mut hold_y = [None, None, None];
    hold_y[1] = Some(0.0.into());
    let mut sim = Simulation::builder(mesh, Backend::cpu(2).unwrap())
        .physics(heat)
        .physics(Mechanics::new().material(Range::All, Coupled::thermal()))
        .physics(
            Boundary::new()
                .velocity(Range::group("left"), hold_x.clone())
                .velocity(Range::group("right"), hold_x)
                .velocity(Range::group("bottom"), hold_y),
        )
        .build()
        .unwrap();
    let report = sim.solve_linear(&StaticOptions::default()).unwrap();
    let lateral = -E * ALPHA * DT / (1.0 - NU);
    let s = sim.field(names::STRESS).unwrap();
    let zz = sim.field(names::STRESS_ZZ).unwrap();
    let mut worst = 0.0f64;
    for e in 0..sim.mesh().n_elements() {
        let got = [s[3 * e], zz[e], s[3 * e + 1], s[3 * e + 2]];
        let want = [lateral, lateral, 0.0, 0.0];
        for (g, w) in got.iter().zip(want) {
            worst = worst.max(((g - w) / lateral).abs());
        }
    }
    let rise = (1.0 + NU) / (1.0 - NU) * ALPHA * DT * h;
    let top = sim.mesh().select_nodes(&Range::group("top")).unwrap();
    let du = top
        .iter()
        .map(|&n| ((sim.state.u[2 * n as usize + 1] - rise) / rise).abs())
        .fold(0.0f64, f64::max);
    println!(
        "confined ({} iterations, ratio {:.1e}): stresses vs (σxx = σzz = −EαΔT/(1−ν) = {lateral:.6e} Pa, σyy = σxy = 0) {worst:.2e} of σxx, top rise vs (1+ν)/(1−ν) αΔT H {du:.2e}",
        report.steps, report.ratio
    );
    assert!(worst < 1e-12, "stress off by {worst:e} of σxx");
    assert!(du < 1e-12, "top rise off by {du:e}");
}

/// The model receives the values in its declaration order: a node field as the mean of
/// the element's node values, an element field as the element's value. Two materials
/// with different lists share the gathered fields; the model without coupling gets
/// none.
#[test]
fn values_reach_the_model_in_declaration_order() {
    let mesh = builders::rectangle(0.0, 0.0, 0.2, 0.1, 0.05).unwrap();
    let temp = |x: &[f64]| T0 + 400.0 * x[0] + 300.0 * x[1];
    let pres = |x: &[f64]| 1e6 * (1.0 + x[0] - 2.0 * x[1]);
    let sat = |x: &[f64]| 0.5 + x[0] * x[1];
    let elastic = LinearElastic::new(E, NU, RHO).unwrap();
    // Pressure, then temperature, then the element field; zero coefficients: the
    // values are only recorded in the history.
    let recorder = Coupled {
        elastic: elastic.clone(),
        keys: vec![names::PORE_PRESSURE, names::TEMPERATURE, SATURATION],
        coef: vec![0.0; 3],
        reference: vec![0.0; 3],
    };
    let left = Range::HalfSpace {
        point: [0.1, 0.0, 0.0],
        normal: [-1.0, 0.0, 0.0],
    };
    let mut sim = Simulation::builder(mesh.clone(), Backend::cpu(2).unwrap())
        .physics(Given::at(&mesh, names::TEMPERATURE, temp))
        .physics(Given::at(&mesh, names::PORE_PRESSURE, pres))
        .physics(Given::at(&mesh, SATURATION, sat))
        .physics(
            Mechanics::new()
                .material(Range::All, recorder)
                .material(left, elastic),
        )
        .build()
        .unwrap();
    sim.step().unwrap();
    let state = sim.field(names::MODEL_STATE).unwrap();
    let t = sim.field(names::TEMPERATURE).unwrap();
    let p = sim.field(names::PORE_PRESSURE).unwrap();
    let s = sim.field(SATURATION).unwrap();
    let mut recorded = 0;
    for e in 0..mesh.n_elements() {
        let st = &state[3 * e..3 * e + 3];
        let c = mesh.element(e);
        let mean = |f: &[f64]| {
            let mut sum = 0.0;
            for &n in c {
                sum += f[n as usize];
            }
            sum / 3.0
        };
        let left_side = c.iter().map(|&n| mesh.node(n as usize)[0]).sum::<f64>() / 3.0 < 0.1;
        if left_side {
            // Plain elasticity: no coupling, its (unused) state stays zero.
            assert_eq!(st, &[0.0; 3], "element {e}");
        } else {
            assert_eq!(st, &[mean(p), mean(t), s[e]], "element {e}");
            recorded += 1;
        }
    }
    assert!(recorded > 0 && recorded < mesh.n_elements());
}

/// A model that reads a field no composed physics owns: the builder's ownership error
/// names the field and the mechanics.
#[test]
fn missing_owner_is_a_build_error() {
    let mesh = builders::rectangle(0.0, 0.0, 0.2, 0.1, 0.05).unwrap();
    let err = Simulation::builder(mesh, Backend::cpu(1).unwrap())
        .physics(Mechanics::new().material(Range::All, Coupled::thermal()))
        .build()
        .err()
        .expect("a model reading an unowned field must not build");
    match &err {
        ComputeError::FieldWithoutOwner { field, physics, .. } => {
            assert_eq!(field, "temperature");
            assert_eq!(physics, "mechanics");
        }
        other => panic!("expected FieldWithoutOwner, got {other:?}"),
    }
    println!("{err}");
}

/// A model that reads a face field is refused at build, naming the model and field.
#[test]
fn face_field_is_refused() {
    const FACE_KEY: FieldKey = FieldKey::new("test_face_value", Place::Face, Components::Fixed(1));
    let mesh = builders::rectangle(0.0, 0.0, 0.2, 0.1, 0.05).unwrap();
    let nf = mesh.faces().len();
    let mut m = Coupled::thermal();
    m.keys = vec![FACE_KEY];
    let owner = Given {
        name: "faces".into(),
        key: FACE_KEY,
        values: vec![0.0; nf],
    };
    let msg = Simulation::builder(mesh, Backend::cpu(1).unwrap())
        .physics(owner)
        .physics(Mechanics::new().material(Range::All, m))
        .build()
        .err()
        .expect("a face coupling field must not build")
        .to_string();
    assert!(
        msg.contains("test_face_value") && msg.contains("test-coupled-elastic"),
        "{msg}"
    );
}

/// Models that ask for nothing declare nothing: the field list is the mechanics' own,
/// and the element kernel is the uncoupled one (no coupling argument or gather).
#[test]
fn no_coupling_declares_and_gathers_nothing() {
    let mesh = builders::rectangle(0.0, 0.0, 0.2, 0.1, 0.05).unwrap();
    let rock = LinearElastic::new(E, NU, RHO).unwrap();
    let sim = Simulation::builder(mesh.clone(), Backend::cpu(1).unwrap())
        .physics(Mechanics::new().material(Range::All, rock.clone()))
        .build()
        .unwrap();
    assert_eq!(
        field_names(&sim.state.fields),
        [
            "stress",
            "strain",
            "stress_zz",
            "model_state",
            "displacement_reset",
            "element_null"
        ]
    );
    // A temperature owner alone does not make the mechanics read it.
    let sim = Simulation::builder(mesh.clone(), Backend::cpu(1).unwrap())
        .physics(Given::uniform(&mesh, names::TEMPERATURE, T0))
        .physics(Mechanics::new().material(Range::All, rock.clone()))
        .build()
        .unwrap();
    assert_eq!(
        field_names(&sim.state.fields),
        [
            "temperature",
            "stress",
            "strain",
            "stress_zz",
            "model_state",
            "displacement_reset",
            "element_null"
        ]
    );
    let plain = offline_kernel_sources::<_>(
        &mesh,
        vec![Box::new(Mechanics::new().material(Range::All, rock))],
        Precision::F64,
    )
    .unwrap();
    let src = &plain
        .iter()
        .find(|(l, _)| l.starts_with("mechanics"))
        .unwrap()
        .1;
    assert!(!src.contains("coupling"), "{src}");
    let coupled = offline_kernel_sources::<_>(
        &mesh,
        vec![
            Box::new(Given::uniform(&mesh, names::TEMPERATURE, T0)),
            Box::new(Mechanics::new().material(Range::All, Coupled::thermal())),
        ],
        Precision::F64,
    )
    .unwrap();
    let src = &coupled
        .iter()
        .find(|(l, _)| l.starts_with("mechanics"))
        .unwrap()
        .1;
    assert!(src.contains("coupling_of(e, mat)"), "{src}");
}

/// Deterministic pseudo-random numbers in [-1, 1).
fn noise(i: usize) -> f64 {
    let x = (i as u64 + 1).wrapping_mul(0x9E37_79B9_7F4A_7C15);
    let x = (x ^ (x >> 29)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    ((x >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
}

/// A thermally shocked block with its bottom fixed: a temperature varying over the
/// nodes, three materials (thermo-elastic everywhere; pore pressure then temperature
/// on one half, Biot b = 0.8; plain elasticity in a disc), `steps` explicit steps.
/// Returns the displacements, the stresses and the model state (the coupling values
/// each element's model received last).
fn thermal_shock<D: Dim>(
    mesh: Mesh<D>,
    backend: Backend,
    steps: u64,
) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let temp = |x: &[f64]| T0 + 50.0 + 400.0 * x[0] + 300.0 * x[1];
    let pres = |x: &[f64]| 2e6 * (1.0 + x[0] - x[1]);
    let thermal = Coupled::thermal();
    let poro = Coupled {
        elastic: LinearElastic::new(2.0 * E, 0.2, RHO).unwrap(),
        keys: vec![names::PORE_PRESSURE, names::TEMPERATURE],
        coef: vec![0.8, thermal.coef[0]],
        reference: vec![0.0, T0],
    };
    let (lo, hi) = mesh.bounding_box();
    let half = Range::HalfSpace {
        point: [0.5 * (lo[0] + hi[0]), 0.0, 0.0],
        normal: [1.0, 0.0, 0.0],
    };
    let disc = Range::Ball {
        center: [lo[0], lo[1], if D::D == 3 { lo[2] } else { 0.0 }],
        radius: 0.03,
    };
    let bottom = if D::D == 2 { "bottom" } else { "zmin" };
    let heat = Given::at(&mesh, names::TEMPERATURE, |x| {
        temp(x) + 5.0 * noise((x[0] * 1e4) as usize)
    });
    let fluid = Given::at(&mesh, names::PORE_PRESSURE, pres);
    let mut sim = Simulation::builder(mesh, backend)
        .physics(
            Mechanics::new()
                .material(Range::All, thermal)
                .material(half, poro)
                .material(disc, LinearElastic::new(E, NU, RHO).unwrap()),
        )
        .physics(Boundary::new().fix(Range::group(bottom)))
        .physics(heat)
        .physics(fluid)
        .build()
        .unwrap();
    sim.run(steps).unwrap();
    let stress = sim.field(names::STRESS).unwrap().to_vec();
    let state = sim.field(names::MODEL_STATE).unwrap().to_vec();
    (sim.state.u.clone(), stress, state)
}

fn rel_diff(a: &[f64], b: &[f64]) -> f64 {
    let scale = a.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let diff = a
        .iter()
        .zip(b)
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
    diff / scale
}

/// CPU–GPU parity in f64: the coupling values the models received (recorded in their
/// history) agree to rounding, the displacements within 1e-12 relative; the stresses
/// within `stress_tol` (1e-12 in 2D; in 3D the iterative polar decomposition leaves
/// the stresses of the uncoupled parity test 5.8e-12 apart on lavapipe, so 1e-11 as
/// there).
fn parity<D: Dim>(mesh: Mesh<D>, stress_tol: f64) {
    let Some(gpu) = gpu_test_backend(Some(Precision::F64)) else {
        return;
    };
    let steps = 200;
    let (u_cpu, s_cpu, m_cpu) = thermal_shock(mesh.clone(), Backend::cpu(1).unwrap(), steps);
    let (u_gpu, s_gpu, m_gpu) = thermal_shock(mesh, gpu.clone(), steps);
    let (du, ds, dm) = (
        rel_diff(&u_cpu, &u_gpu),
        rel_diff(&s_cpu, &s_gpu),
        rel_diff(&m_cpu, &m_gpu),
    );
    println!(
        "{} f64 thermal shock on {}: max relative difference displacement {du:.3e}, stress {ds:.3e}, coupling values {dm:.3e}",
        D::NAME,
        gpu.as_gpu().expect("a GPU backend").adapter_name()
    );
    assert!(u_cpu.iter().any(|&u| u != 0.0), "the scene must move");
    assert!(dm <= 1e-15, "coupling values differ by {dm:e}");
    assert!(du <= 1e-12, "displacement differs by {du:e}");
    assert!(ds <= stress_tol, "stress differs by {ds:e}");
}

#[test]
fn thermal_shock_tri3_gpu_matches_cpu() {
    parity(
        builders::rectangle(0.0, 0.0, 0.2, 0.1, 0.02).unwrap(),
        1e-12,
    );
}

#[test]
fn thermal_shock_tet4_gpu_matches_cpu() {
    parity(
        builders::cuboid([0.0; 3], [0.1, 0.05, 0.05], 0.025).unwrap(),
        1e-11,
    );
}

/// CPU results do not depend on the thread count with coupling either.
#[test]
fn thermal_shock_is_thread_count_independent() {
    let mesh = builders::rectangle(0.0, 0.0, 0.2, 0.1, 0.01).unwrap();
    let a = thermal_shock(mesh.clone(), Backend::cpu(1).unwrap(), 50);
    let b = thermal_shock(mesh, Backend::cpu(2).unwrap(), 50);
    assert_eq!(a, b);
}

/// `ThermalStrain` around the built-in elasticity: the clamped closed form, 2D and 3D.
#[test]
fn thermal_strain_wrapper_clamped_matches_closed_form() {
    let wrapped =
        || ThermalStrain::new(LinearElastic::new(E, NU, RHO).unwrap(), ALPHA, T0).unwrap();
    let mesh = builders::rectangle(0.0, 0.0, 0.2, 0.1, 0.02).unwrap();
    let heat = Given::uniform(&mesh, names::TEMPERATURE, T0 + DT);
    let mut sim = Simulation::builder(mesh, Backend::cpu(1).unwrap())
        .physics(Mechanics::new().material(Range::All, wrapped()))
        .physics(Boundary::new().fix(Range::All))
        .physics(heat)
        .build()
        .unwrap();
    sim.run(5).unwrap();
    check_clamped(&sim);
    let mesh = builders::cuboid([0.0; 3], [0.1, 0.05, 0.05], 0.025).unwrap();
    let heat = Given::uniform(&mesh, names::TEMPERATURE, T0 + DT);
    let mut sim = Simulation::builder(mesh, Backend::cpu(1).unwrap())
        .physics(Mechanics::new().material(Range::All, wrapped()))
        .physics(Boundary::new().fix(Range::All))
        .physics(heat)
        .build()
        .unwrap();
    sim.run(3).unwrap();
    check_clamped(&sim);
}

/// The wrapper passes mechanical strains to a plastic model: free thermal expansion
/// is stress-free (no yield however weak the rock), a clamped one gives −3KαΔT until
/// the cap of the tension cut-off or the shear surface is met (here far from it), and
/// the applied thermal strain is the last history variable.
#[test]
fn thermal_strain_wrapper_around_mohr_coulomb() {
    let e = LinearElastic::new(E, NU, RHO).unwrap();
    let weak = MohrCoulomb::new(e.clone(), 1e5, 30.0, 0.0, 1e4).unwrap();
    let m = ThermalStrain::new(weak, ALPHA, T0).unwrap();
    assert_eq!(m.n_state(), 7);
    let th = ALPHA * DT;
    let free: Sym6 = [th, th, th, 0.0, 0.0, 0.0];
    let (mut s, mut st) = ([0.0; 6], vec![0.0; 7]);
    m.update_with(&ModelInput::new(&free, &free, &[T0 + DT]), &mut s, &mut st);
    assert!(s.iter().all(|v| v.abs() < 1e-6), "{s:?}");
    assert_eq!(st[1], 0.0, "no shear yield in free expansion");
    assert!((st[6] - th).abs() < 1e-20);
    // Clamped under a strong rock: σ = −3KαΔT on the diagonal.
    let strong = MohrCoulomb::new(e, 1e9, 30.0, 0.0, 1e8).unwrap();
    let m = ThermalStrain::new(strong, ALPHA, T0).unwrap();
    let (mut s, mut st) = ([0.0; 6], vec![0.0; 7]);
    m.update_with(
        &ModelInput::new(&[0.0; 6], &[0.0; 6], &[T0 + DT]),
        &mut s,
        &mut st,
    );
    for v in &s[..3] {
        assert!(
            ((v - clamped_stress()) / clamped_stress()).abs() < 1e-12,
            "{s:?}"
        );
    }
    // Bad α: the wrong order of magnitude is refused with the parameter's name.
    let err = ThermalStrain::new(LinearElastic::new(E, NU, RHO).unwrap(), 0.5, T0).unwrap_err();
    assert!(err.to_string().contains("expansion"), "{err}");
}

/// The wrapper's WGSL validates, and an inner model used both wrapped and unwrapped
/// brings its helper functions once.
#[test]
fn thermal_strain_wrapper_kernels_validate_with_naga() {
    let e = LinearElastic::new(E, NU, RHO).unwrap();
    let mc = MohrCoulomb::new(e.clone(), 1e6, 30.0, 5.0, 0.5e6).unwrap();
    for mesh_3d in [false, true] {
        let mech = || {
            Mechanics::new()
                .material(
                    Range::All,
                    ThermalStrain::new(mc.clone(), ALPHA, T0).unwrap(),
                )
                .material(
                    Range::Ball {
                        center: [0.0; 3],
                        radius: 0.03,
                    },
                    mc.clone(),
                )
                .material(
                    Range::Ball {
                        center: [0.1, 0.0, 0.0],
                        radius: 0.03,
                    },
                    ThermalStrain::new(e.clone(), ALPHA, T0).unwrap(),
                )
        };
        for p in [Precision::F64, Precision::F32] {
            let sources = if mesh_3d {
                let mesh = builders::cuboid([0.0; 3], [0.1, 0.05, 0.05], 0.025).unwrap();
                let heat = Given::uniform(&mesh, names::TEMPERATURE, T0);
                offline_kernel_sources::<_>(&mesh, vec![Box::new(heat), Box::new(mech())], p)
            } else {
                let mesh = builders::rectangle(0.0, 0.0, 0.2, 0.1, 0.02).unwrap();
                let heat = Given::uniform(&mesh, names::TEMPERATURE, T0);
                offline_kernel_sources::<_>(&mesh, vec![Box::new(heat), Box::new(mech())], p)
            }
            .unwrap();
            for (label, src) in &sources {
                if let Err(e) = pcdc_compute::gpu::validate_wgsl(src) {
                    panic!("{label} ({}) does not validate:\n{e}", p.name());
                }
            }
            let src = &sources
                .iter()
                .find(|(l, _)| l.starts_with("mechanics"))
                .unwrap()
                .1;
            assert_eq!(
                src.matches("fn mc_return(").count(),
                1,
                "helpers spliced once"
            );
        }
    }
}

/// CPU–GPU parity (f64) of `ThermalStrain` around Mohr–Coulomb (yielding under the
/// thermal shock) and around elasticity, with plain Mohr–Coulomb in a third region.
#[test]
fn thermal_strain_wrapper_gpu_matches_cpu() {
    let Some(gpu) = gpu_test_backend(Some(Precision::F64)) else {
        return;
    };
    let run = |backend: Backend| {
        let mesh = builders::rectangle(0.0, 0.0, 0.2, 0.1, 0.02).unwrap();
        let e = LinearElastic::new(E, NU, RHO).unwrap();
        let mc = MohrCoulomb::new(e.clone(), 2e6, 30.0, 5.0, 1e6).unwrap();
        let heat = Given::at(&mesh, names::TEMPERATURE, |x| {
            T0 + 50.0 + 400.0 * x[0] + 300.0 * x[1] + 5.0 * noise((x[0] * 1e4) as usize)
        });
        let mut sim = Simulation::builder(mesh, backend)
            .physics(
                Mechanics::new()
                    .material(
                        Range::All,
                        ThermalStrain::new(mc.clone(), ALPHA, T0).unwrap(),
                    )
                    .material(
                        Range::Ball {
                            center: [0.0; 3],
                            radius: 0.03,
                        },
                        mc.clone(),
                    )
                    .material(
                        Range::Ball {
                            center: [0.2, 0.1, 0.0],
                            radius: 0.03,
                        },
                        ThermalStrain::new(e, ALPHA, T0).unwrap(),
                    ),
            )
            .physics(Boundary::new().fix(Range::group("bottom")))
            .physics(heat)
            .build()
            .unwrap();
        sim.run(200).unwrap();
        let stress = sim.field(names::STRESS).unwrap().to_vec();
        let state = sim.field(names::MODEL_STATE).unwrap().to_vec();
        (sim.state.u.clone(), stress, state)
    };
    let (u_c, s_c, m_c) = run(Backend::cpu(1).unwrap());
    let (u_g, s_g, m_g) = run(gpu.clone());
    let (du, ds, dm) = (
        rel_diff(&u_c, &u_g),
        rel_diff(&s_c, &s_g),
        rel_diff(&m_c, &m_g),
    );
    println!("thermal strain parity: displacement {du:.3e}, stress {ds:.3e}, history {dm:.3e}");
    assert!(
        m_c.chunks(7).any(|st| st[1] == 1.0),
        "some element must yield in shear"
    );
    assert!(
        du <= 1e-12 && ds <= 1e-12,
        "displacement {du:e}, stress {ds:e}"
    );
    // Known gap (issue 17 note): the accumulated plastic shear strain κ_s of a few
    // elements differs by up to 2 % between the backends while stresses and flags
    // agree. Traced (step by step): it starts at the shear–tension triple point
    // (σ2 = σ3 = σ_t on the shear plane, reached here in plane strain by an in-plane
    // tension corner with σzz on the shear plane), where two active sets are admissible
    // to rounding and the backends pick different ones: the same stress, but a different
    // share of the plastic strain counted as shear. So κ_s is compared nowhere here.
    for (k, (a, b)) in m_c.iter().zip(&m_g).enumerate() {
        if k % 7 != 4 {
            assert!(
                (a - b).abs() <= 1e-12 * a.abs().max(1e-3),
                "history {k}: {a} vs {b}"
            );
        }
    }
}
