//! Degrees of freedom a physics owns: a free mass point added by a physics (not a mesh
//! node) falls under gravity and is pushed by a constant force through the physics'
//! slots, as the central-difference closed form says, on the CPU and on the GPU.

use pcdc_compute::gpu::{Access, GpuData, GpuSetup, Kernel, Phase};
use pcdc_compute::{
    Backend, ComputeError, FieldStore, ForceContext, InitContext, Physics, Simulation,
};
use pcdc_mesh::{builders, Dim2, Mesh};

const MASS: f64 = 2.5; // kg
const PUSH: f64 = 3.0; // N, along x
const G: f64 = 9.81; // m/s²
const DT: f64 = 1e-3; // s
const START: [f64; 2] = [5.0, 7.0]; // m

/// Adds one mass point with a constant force along x; gives the mesh nodes unit masses.
struct Particle {
    node: usize,
}

impl Physics<Dim2> for Particle {
    fn name(&self) -> &str {
        "particle"
    }
    fn init(&mut self, ctx: &mut InitContext<'_, Dim2>) -> Result<(), ComputeError> {
        let block = ctx.add_nodes(&START, &[MASS])?;
        self.node = block.first;
        ctx.register_slots(&[block.first as u32])?;
        Ok(())
    }
    fn add_mass(&self, m: &Mesh<Dim2>, _f: &FieldStore, mass: &mut [f64], _s: Option<f64>) {
        mass[..m.n_nodes()].iter_mut().for_each(|x| *x += 1.0);
    }
    fn compute_forces(&mut self, ctx: &mut ForceContext<'_, Dim2>) -> Result<(), ComputeError> {
        ctx.slots[0] = PUSH;
        ctx.slots[1] = 0.0;
        Ok(())
    }
    fn gpu_setup(&mut self, setup: &mut GpuSetup<'_, Dim2>) -> Result<(), ComputeError> {
        let push = setup.upload("push", GpuData::Real(vec![PUSH, 0.0]));
        let slots = setup.slots();
        setup.kernel(
            Phase::Forces,
            Kernel::new("push", "fn kernel(i: u32) { slots[i] = push[i]; }", 2)
                .bind("slots", slots, Access::ReadWrite)
                .bind("push", push, Access::Read),
        )
    }
}

fn sim(backend: Backend) -> Simulation<Dim2> {
    let mesh = builders::rectangle(0.0, 0.0, 1.0, 1.0, 0.5).unwrap();
    Simulation::builder(mesh, backend)
        .time_step(DT)
        .gravity([0.0, -G, 0.0])
        .physics(Particle { node: 0 })
        .build()
        .unwrap()
}

/// Central differences from rest: u_n = a dt² n (n + 1) / 2 (v at the half step).
fn closed_form(a: f64, n: u64) -> f64 {
    a * DT * DT * (n * (n + 1)) as f64 / 2.0
}

fn check(s: &Simulation<Dim2>, n: u64, tol: f64) {
    let mesh_nodes = s.mesh().n_nodes();
    assert_eq!(s.n_nodes(), mesh_nodes + 1);
    let p = mesh_nodes;
    assert_eq!(&s.reference_coords()[2 * p..], &START);
    assert_eq!(s.mass()[p], MASS);
    let (ux, uy) = (s.state.u[2 * p], s.state.u[2 * p + 1]);
    let (ex, ey) = (closed_form(PUSH / MASS, n), closed_form(-G, n));
    assert!((ux - ex).abs() <= tol * ex.abs(), "x: {ux} vs {ex}");
    assert!((uy - ey).abs() <= tol * ey.abs(), "y: {uy} vs {ey}");
    // Against the continuous closed form ½ a t², the half-step start offsets it by
    // ½ a dt t: relative dt / t.
    let t = n as f64 * DT;
    let cont = -0.5 * G * t * t;
    assert!(
        ((uy - cont) / cont).abs() <= 1.01 * DT / t,
        "{uy} vs {cont}"
    );
    // A mesh node falls freely too (no forces on it).
    assert!((s.state.u[1] - ey).abs() <= tol * ey.abs());
}

#[test]
fn an_added_mass_point_falls_and_is_pushed_as_the_closed_form_says() {
    let mut s = sim(Backend::cpu(1).unwrap());
    s.run(1000).unwrap();
    check(&s, 1000, 1e-12);
    assert_eq!(s.positions().len(), 2 * s.n_nodes());
}

#[test]
fn bad_added_nodes_are_errors() {
    struct Bad(Vec<f64>, Vec<f64>);
    impl Physics<Dim2> for Bad {
        fn name(&self) -> &str {
            "bad"
        }
        fn init(&mut self, ctx: &mut InitContext<'_, Dim2>) -> Result<(), ComputeError> {
            ctx.add_nodes(&self.0, &self.1).map(|_| ())
        }
        fn compute_forces(&mut self, _: &mut ForceContext<'_, Dim2>) -> Result<(), ComputeError> {
            Ok(())
        }
    }
    for (coords, mass, what) in [
        (vec![0.0], vec![1.0], "coordinates"),
        (vec![0.0, f64::NAN], vec![1.0], "coordinate"),
        (vec![0.0, 0.0], vec![0.0], "mass"),
    ] {
        let mesh = builders::rectangle(0.0, 0.0, 1.0, 1.0, 0.5).unwrap();
        let e = Simulation::builder(mesh, Backend::cpu(1).unwrap())
            .time_step(DT)
            .physics(Bad(coords, mass))
            .build()
            .err()
            .expect("bad added nodes must not build")
            .to_string();
        assert!(e.contains(what), "{e}");
    }
}

#[cfg(feature = "gpu")]
#[test]
fn gpu_integrates_added_nodes_the_same() {
    let Some(gpu) = pcdc_compute::gpu::gpu_test_backend(Some(pcdc_compute::Precision::F64)) else {
        return;
    };
    let mut g = sim(gpu);
    g.run(1000).unwrap();
    check(&g, 1000, 1e-12);
    let mut c = sim(Backend::cpu(1).unwrap());
    c.run(1000).unwrap();
    let p = 2 * c.mesh().n_nodes();
    assert_eq!(&g.state.u[p..], &c.state.u[p..]);
}

/// A physics that adds one node and names it in its own entity set, numbered from the
/// mesh's node count as the trait says.
struct Tagged {
    set: &'static str,
    seen: Option<u32>,
}

impl Physics<Dim2> for Tagged {
    fn name(&self) -> &str {
        self.set
    }
    fn entity_sets(&self, mesh: &Mesh<Dim2>) -> Vec<pcdc_compute::EntitySet> {
        vec![pcdc_compute::EntitySet::new(self.set, 1, vec![mesh.n_nodes() as u32]).unwrap()]
    }
    fn init(&mut self, ctx: &mut InitContext<'_, Dim2>) -> Result<(), ComputeError> {
        let block = ctx.add_nodes(&START, &[MASS])?;
        // The set already names the node's simulation index.
        self.seen = Some(ctx.entity_set(self.set).unwrap().nodes()[0]);
        assert_eq!(self.seen, Some(block.first as u32));
        Ok(())
    }
    fn add_mass(&self, m: &Mesh<Dim2>, _f: &FieldStore, mass: &mut [f64], _s: Option<f64>) {
        mass[..m.n_nodes()].iter_mut().for_each(|x| *x += 1.0);
    }
    fn compute_forces(&mut self, _: &mut ForceContext<'_, Dim2>) -> Result<(), ComputeError> {
        Ok(())
    }
}

#[test]
fn entity_sets_name_added_nodes_by_their_simulation_index() {
    let mesh = builders::rectangle(0.0, 0.0, 1.0, 1.0, 0.5).unwrap();
    let n = mesh.n_nodes() as u32;
    let s = Simulation::builder(mesh, Backend::cpu(1).unwrap())
        .time_step(DT)
        .physics(Tagged {
            set: "first",
            seen: None,
        })
        .physics(Tagged {
            set: "second",
            seen: None,
        })
        .build()
        .unwrap();
    assert_eq!(s.entity_set("first").unwrap().nodes(), &[n]);
    assert_eq!(s.entity_set("second").unwrap().nodes(), &[n + 1]);
}

#[test]
fn a_set_naming_a_node_nobody_added_is_an_error() {
    struct Liar;
    impl Physics<Dim2> for Liar {
        fn name(&self) -> &str {
            "liar"
        }
        fn entity_sets(&self, mesh: &Mesh<Dim2>) -> Vec<pcdc_compute::EntitySet> {
            vec![pcdc_compute::EntitySet::new("ghosts", 1, vec![mesh.n_nodes() as u32]).unwrap()]
        }
        fn init(&mut self, _: &mut InitContext<'_, Dim2>) -> Result<(), ComputeError> {
            Ok(())
        }
        fn compute_forces(&mut self, _: &mut ForceContext<'_, Dim2>) -> Result<(), ComputeError> {
            Ok(())
        }
    }
    let mesh = builders::rectangle(0.0, 0.0, 1.0, 1.0, 0.5).unwrap();
    let e = Simulation::builder(mesh, Backend::cpu(1).unwrap())
        .time_step(DT)
        .physics(Liar)
        .build()
        .err()
        .expect("a set naming a missing node must not build")
        .to_string();
    assert!(e.contains("entity set 'ghosts'"), "{e}");
}
