//! CPU–GPU parity of the thermal physics (f64 to 1e-12) and naga validation of its
//! kernels: conduction with two materials (one anisotropic), a held temperature and a
//! heat flux from time tables, convection; alone (2D, 3D) and under a mechanics with
//! thermal stress (`ThermalStrain`, 2D, sub-cycled every 20 steps).

use pcdc_compute::gpu::{gpu_test_backend, offline_kernel_sources, validate_wgsl, GpuSetup};
use pcdc_compute::{names, Backend, FieldSchedule, Precision, Simulation, SubCycle, Table};
use pcdc_compute::{ComputeError, FieldUse, ForceContext, InitContext, Physics};
use pcdc_mech::{Boundary, LinearElastic, Mechanics, ThermalStrain};
use pcdc_mesh::{builders, Dim, Mesh, Range};
use pcdc_thermal::{Conductivity, HeatMaterial, JointHeat, Thermal, HEAT_FLUX, HEAT_SUPPLIED};

fn heat<D: Dim>(mesh: &Mesh<D>) -> Thermal {
    let (lo, hi) = mesh.bounding_box();
    let (left, right) = if D::D == 2 {
        ("left", "right")
    } else {
        ("xmin", "xmax")
    };
    let aniso = HeatMaterial::with_conductivity(
        Conductivity::Anisotropic([3.0, 1.5, 2.0, 0.4, 0.1, 0.2]),
        900.0,
        2600.0,
    )
    .unwrap();
    let ramp = Table::new("t", &[(0.0, 20.0), (50.0, 150.0), (500.0, 80.0)]).unwrap();
    let flux = Table::new("t", &[(0.0, 0.0), (100.0, 5e3)]).unwrap();
    Thermal::new()
        .material(Range::All, HeatMaterial::new(2.5, 800.0, 2700.0).unwrap())
        .material(
            Range::Ball {
                center: [0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]), 0.0],
                radius: 0.03,
            },
            aniso,
        )
        .initial_temperature_fn(|x| 20.0 + 100.0 * x[0] * x[1])
        .temperature(Range::group(left), ramp)
        .heat_flux(Range::group(right), flux)
        .convection(
            Range::group(if D::D == 2 { "top" } else { "zmax" }),
            25.0,
            5.0,
        )
        .joints(JointHeat::Conducting)
}

fn rel_diff(a: &[f64], b: &[f64]) -> f64 {
    let scale = a.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    a.iter()
        .zip(b)
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()))
        / scale
}

fn fields<D: Dim>(sim: &Simulation<D>) -> [Vec<f64>; 3] {
    [
        names::TEMPERATURE.name(),
        HEAT_FLUX.name(),
        HEAT_SUPPLIED.name(),
    ]
    .map(|n| sim.field(n).unwrap().to_vec())
}

fn heat_only<D: Dim>(mesh: Mesh<D>, backend: Backend) -> [Vec<f64>; 3] {
    let mut sim = Simulation::builder(mesh.clone(), backend)
        .physics(heat(&mesh).heat_only())
        .build()
        .unwrap();
    sim.run(300).unwrap();
    fields(&sim)
}

fn check(cpu: &[Vec<f64>; 3], gpu: &[Vec<f64>; 3], label: &str) {
    let d: Vec<f64> = cpu.iter().zip(gpu).map(|(a, b)| rel_diff(a, b)).collect();
    println!(
        "{label}: temperature {:.2e}, heat flux {:.2e}, heat supplied {:.2e}",
        d[0], d[1], d[2]
    );
    assert!(d.iter().all(|&x| x <= 1e-12), "{label}: {d:?}");
}

#[test]
fn heat_only_gpu_matches_cpu_2d_and_3d() {
    let Some(gpu) = gpu_test_backend(Some(Precision::F64)) else {
        return;
    };
    let m2 = builders::rectangle(0.0, 0.0, 0.2, 0.1, 0.01).unwrap();
    let cpu = heat_only(m2.clone(), Backend::cpu(1).unwrap());
    check(&cpu, &heat_only(m2, gpu.clone()), "2D heat only");
    let m3 = builders::cuboid([0.0; 3], [0.1, 0.05, 0.05], 0.0125).unwrap();
    let cpu = heat_only(m3.clone(), Backend::cpu(1).unwrap());
    check(&cpu, &heat_only(m3, gpu), "3D heat only");
}

#[test]
fn thermo_mechanical_gpu_matches_cpu() {
    let Some(gpu) = gpu_test_backend(Some(Precision::F64)) else {
        return;
    };
    let run = |backend: Backend| {
        let mesh = builders::rectangle(0.0, 0.0, 0.2, 0.1, 0.01).unwrap();
        let rock = ThermalStrain::new(LinearElastic::new(30e9, 0.25, 2700.0).unwrap(), 8e-6, 20.0)
            .unwrap();
        let mut sim = Simulation::builder(mesh.clone(), backend)
            .physics(Mechanics::new().material(Range::All, rock))
            .physics(Boundary::new().fix(Range::group("bottom")))
            .physics(heat(&mesh).schedule(FieldSchedule::Fixed(SubCycle::Every(20))))
            .build()
            .unwrap();
        sim.run(400).unwrap();
        let mut f = fields(&sim).to_vec();
        f.push(sim.field(names::STRESS).unwrap().to_vec());
        f
    };
    let (c, g) = (run(Backend::cpu(1).unwrap()), run(gpu));
    let d: Vec<f64> = c.iter().zip(&g).map(|(a, b)| rel_diff(a, b)).collect();
    println!("thermo-mechanical: temperature, flux, supplied, stress {d:?}");
    assert!(
        c[3].iter().any(|&s| s != 0.0),
        "the heat must stress the block"
    );
    assert!(d.iter().all(|&x| x <= 1e-12), "{d:?}");
}

#[test]
fn kernels_validate_with_naga() {
    let m2 = builders::rectangle(0.0, 0.0, 0.2, 0.1, 0.05).unwrap();
    let m3 = builders::cuboid([0.0; 3], [0.1, 0.05, 0.05], 0.025).unwrap();
    for p in [Precision::F64, Precision::F32] {
        let s2 =
            offline_kernel_sources::<_>(&m2, vec![Box::new(heat(&m2).heat_only())], p).unwrap();
        let s3 =
            offline_kernel_sources::<_>(&m3, vec![Box::new(heat(&m3).heat_only())], p).unwrap();
        let thermal: Vec<_> = s2
            .iter()
            .chain(&s3)
            .filter(|(l, _)| l.starts_with("thermal"))
            .collect();
        assert_eq!(thermal.len(), 8, "four kernels in 2D and 3D");
        for (label, src) in thermal {
            if let Err(e) = validate_wgsl(src) {
                panic!("{label} ({}) does not validate:\n{e}", p.name());
            }
        }
        // Joints that follow the damage: the per-vertex kernel.
        let s2 = pcdc_mesh::split_nodes(&m2, &Range::All).unwrap();
        let s3 = pcdc_mesh::split_nodes(&m3, &Range::All).unwrap();
        let k2 = offline_kernel_sources::<_>(
            &s2,
            vec![
                Box::new(heat(&s2).joints(JointHeat::FollowDamage).heat_only()),
                Box::new(DamageOwner { crack_x: None }),
            ],
            p,
        )
        .unwrap();
        let k3 = offline_kernel_sources::<_>(
            &s3,
            vec![
                Box::new(heat(&s3).joints(JointHeat::FollowDamage).heat_only()),
                Box::new(DamageOwner { crack_x: None }),
            ],
            p,
        )
        .unwrap();
        let c2 = offline_kernel_sources::<_>(
            &s2,
            vec![
                Box::new(
                    heat(&s2)
                        .joints(JointHeat::FollowDamage)
                        .contact_conductance(100.0)
                        .heat_only(),
                ),
                Box::new(CrackOwner {
                    crack_x: 0.1,
                    opening: 0.0,
                }),
            ],
            p,
        )
        .unwrap();
        let c3 = offline_kernel_sources::<_>(
            &s3,
            vec![
                Box::new(
                    heat(&s3)
                        .joints(JointHeat::FollowDamage)
                        .contact_conductance(100.0)
                        .heat_only(),
                ),
                Box::new(CrackOwner {
                    crack_x: 0.05,
                    opening: 0.0,
                }),
            ],
            p,
        )
        .unwrap();
        let vertex: Vec<_> = k2
            .iter()
            .chain(&k3)
            .chain(&c2)
            .chain(&c3)
            .filter(|(l, _)| l == "thermal vertex groups" || l == "thermal contact")
            .collect();
        assert_eq!(
            vertex.len(),
            6,
            "the vertex kernel in 2D and 3D, twice, and contact"
        );
        for (label, src) in vertex {
            if let Err(e) = validate_wgsl(src) {
                panic!("{label} ({}) does not validate:\n{e}", p.name());
            }
        }
    }
}

/// Joints that follow the damage on a split mesh: the device finds the thermal nodes
/// within each vertex from the damage every step. A vertical crack (its joints broken
/// from the start) stops the heat: the CPU and GPU agree to 1e-12 and nothing crosses.
#[test]
fn damage_following_joints_match_the_cpu_and_insulate() {
    let mesh = builders::rectangle(0.0, 0.0, 0.2, 0.1, 0.0125).unwrap();
    let split = pcdc_mesh::split_nodes(&mesh, &Range::All).unwrap();
    let run = |backend: Backend| {
        let thermal = Thermal::new()
            .material(Range::All, HeatMaterial::new(3.0, 800.0, 2700.0).unwrap())
            .initial_temperature(20.0)
            .temperature(Range::group("left"), 100.0)
            .joints(JointHeat::FollowDamage)
            .heat_only();
        let mut sim = Simulation::builder(split.clone(), backend)
            .physics(thermal)
            .physics(DamageOwner { crack_x: Some(0.1) })
            .build()
            .unwrap();
        sim.run(400).unwrap();
        fields(&sim)
    };
    let cpu = run(Backend::cpu(1).unwrap());
    let t = &cpu[0];
    let mut crossed = 0.0f64;
    for (n, &tn) in t.iter().enumerate() {
        if split.node(n)[0] > 0.1 + 1e-9 {
            crossed = crossed.max((tn - 20.0).abs());
        }
    }
    assert_eq!(crossed, 0.0, "heat crossed the crack");
    assert!(t.iter().any(|&x| x > 30.0), "heat entered the left part");
    let Some(gpu) = gpu_test_backend(Some(Precision::F64)) else {
        return;
    };
    check(&cpu, &run(gpu), "2D cracked, FollowDamage");
}

/// Owns `names::JOINT_DAMAGE`, standing in for the cohesive joints: all intact, or
/// broken (1) on the joints of the vertical line x = `crack_x`.
struct DamageOwner {
    crack_x: Option<f64>,
}

/// Like [`DamageOwner`], and owns the joints' opening (`opening` on every joint) and
/// sliding (0), as the cohesive joints publish them.
struct CrackOwner {
    crack_x: f64,
    opening: f64,
}

impl<D: Dim> Physics<D> for CrackOwner {
    fn name(&self) -> &str {
        "crack owner"
    }
    fn fields(&self, _mesh: &Mesh<D>) -> Vec<FieldUse> {
        vec![
            names::JOINT_DAMAGE.own::<D>(),
            names::JOINT_OPENING.own::<D>().initial(self.opening),
            names::JOINT_SLIDING.own::<D>(),
        ]
    }
    fn init(&mut self, ctx: &mut InitContext<'_, D>) -> Result<(), ComputeError> {
        DamageOwner {
            crack_x: Some(self.crack_x),
        }
        .init(ctx)
    }
    fn compute_forces(&mut self, _ctx: &mut ForceContext<'_, D>) -> Result<(), ComputeError> {
        Ok(())
    }
    fn gpu_setup(&mut self, _setup: &mut GpuSetup<'_, D>) -> Result<(), ComputeError> {
        Ok(())
    }
}

/// Contact conductance across a closed crack (eq. 111–112): at steady state the bar
/// carries q = ΔT / (L₁/k + 1/h_c + L₂/k) and the crack's faces differ by q/h_c; an
/// open crack carries nothing. The GPU matches the CPU to 1e-12.
#[test]
fn closed_crack_conducts_through_the_contact_conductance() {
    let mesh = builders::rectangle(0.0, 0.0, 0.2, 0.1, 0.0125).unwrap();
    let split = pcdc_mesh::split_nodes(&mesh, &Range::All).unwrap();
    let (k, h_c) = (3.0, 300.0);
    let run = |backend: Backend, opening: f64, steps: u64| {
        let thermal = Thermal::new()
            .material(Range::All, HeatMaterial::new(k, 800.0, 2700.0).unwrap())
            .initial_temperature(0.0)
            .temperature(Range::group("left"), 100.0)
            .temperature(Range::group("right"), 0.0)
            .contact_conductance(h_c)
            .heat_only();
        let mut sim = Simulation::builder(split.clone(), backend)
            .physics(thermal)
            .physics(CrackOwner {
                crack_x: 0.1,
                opening,
            })
            .build()
            .unwrap();
        sim.run(steps).unwrap();
        fields(&sim)
    };
    let closed = run(Backend::cpu(1).unwrap(), -1e-6, 20_000);
    let q = 100.0 / (0.1 / k + 1.0 / h_c + 0.1 / k);
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for (n, &t) in closed[0].iter().enumerate() {
        if (split.node(n)[0] - 0.1).abs() < 1e-9 {
            lo = lo.min(t);
            hi = hi.max(t);
        }
    }
    // Both faces at the crack: T(0.1⁻) = 100 − q L₁/k, T(0.1⁺) = q L₂/k.
    let (left, right) = (100.0 - q * 0.1 / k, q * 0.1 / k);
    assert!((hi - left).abs() < 1e-6 * 100.0, "left face {hi} vs {left}");
    assert!(
        (lo - right).abs() < 1e-6 * 100.0,
        "right face {lo} vs {right}"
    );
    let open = run(Backend::cpu(1).unwrap(), 1e-6, 2_000);
    for (n, &t) in open[0].iter().enumerate() {
        let x = split.node(n)[0];
        if x > 0.1 + 1e-9 {
            assert_eq!(t, 0.0, "heat crossed an open crack at x = {x}");
        }
    }
    // Bad input: a negative conductance, or one where no joint can break.
    let refuse = |t: Thermal| {
        Simulation::builder(split.clone(), Backend::cpu(1).unwrap())
            .physics(t.heat_only())
            .physics(CrackOwner {
                crack_x: 0.1,
                opening: 0.0,
            })
            .build()
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default()
    };
    let base = || Thermal::new().material(Range::All, HeatMaterial::new(k, 800.0, 2700.0).unwrap());
    let e = refuse(base().contact_conductance(-1.0));
    assert!(e.contains("h_c"), "{e}");
    let e = refuse(
        base()
            .joints(JointHeat::Conducting)
            .contact_conductance(10.0),
    );
    assert!(e.contains("FollowDamage"), "{e}");
    let Some(gpu) = gpu_test_backend(Some(Precision::F64)) else {
        return;
    };
    check(
        &run(Backend::cpu(1).unwrap(), -1e-6, 300),
        &run(gpu, -1e-6, 300),
        "2D closed crack, contact conductance",
    );
}

impl<D: Dim> Physics<D> for DamageOwner {
    fn name(&self) -> &str {
        "damage owner"
    }
    fn fields(&self, _mesh: &Mesh<D>) -> Vec<FieldUse> {
        vec![names::JOINT_DAMAGE.own::<D>()]
    }
    fn init(&mut self, ctx: &mut InitContext<'_, D>) -> Result<(), ComputeError> {
        let Some(x) = self.crack_x else {
            return Ok(());
        };
        let joints = ctx.mesh.interfaces();
        let broken: Vec<bool> = (0..joints.len())
            .map(|j| {
                joints
                    .joint_nodes(j)
                    .iter()
                    .all(|&n| (ctx.mesh.node(n as usize)[0] - x).abs() < 1e-9)
            })
            .collect();
        let id = ctx.fields.id(names::JOINT_DAMAGE)?;
        for (d, b) in ctx.fields.get_mut(id).iter_mut().zip(broken) {
            *d = if b { 1.0 } else { 0.0 };
        }
        Ok(())
    }
    fn compute_forces(&mut self, _ctx: &mut ForceContext<'_, D>) -> Result<(), ComputeError> {
        Ok(())
    }
    fn gpu_setup(&mut self, _setup: &mut GpuSetup<'_, D>) -> Result<(), ComputeError> {
        Ok(())
    }
}
