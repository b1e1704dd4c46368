//! The null model (manual 7.2.8): switching the upper half of a block to null leaves the
//! lower half moving exactly as a block of that half alone (same triangles, same
//! gravity, same loads), on the CPU and, to rounding, on the GPU.

use pcdc_compute::gpu::gpu_test_backend;
use pcdc_compute::{Backend, Precision, Simulation};
use pcdc_mech::{set_null, Boundary, LinearElastic, Mechanics};
use pcdc_mesh::{builders, Dim2, Mesh, Range};

fn sim(mesh: Mesh<Dim2>, backend: Backend) -> Simulation<Dim2> {
    let rock = LinearElastic::new(1e9, 0.25, 2000.0)
        .unwrap()
        .with_damping(0.2)
        .unwrap();
    Simulation::builder(mesh, backend)
        .gravity([0.0, -9.81, 0.0])
        .physics(
            Mechanics::new()
                .material(Range::All, rock)
                .initial_stress(Range::All, [-1e5, -2e5, -1e5, 3e4, 0.0, 0.0]),
        )
        .physics(Boundary::new().velocity(
            Range::group("bottom"),
            [Some(0.0.into()), Some(0.0.into()), None],
        ))
        .build()
        .unwrap()
}

/// Displacements of the lower half after 300 steps: the two-part block with its upper
/// half null, and the lower half alone, node by node (matched by position).
fn halves(backend: Backend) -> (Vec<f64>, Vec<f64>, usize) {
    let h = 0.1;
    let mut whole = sim(
        builders::rectangle(0.0, 0.0, 1.0, 2.0, h).unwrap(),
        backend.clone(),
    );
    let upper = Range::HalfSpace {
        point: [0.0, 1.0, 0.0],
        normal: [0.0, 1.0, 0.0],
    };
    let n = set_null(&mut whole, &upper).unwrap();
    let mut half = sim(builders::rectangle(0.0, 0.0, 1.0, 1.0, h).unwrap(), backend);
    assert_eq!(
        whole.dt(),
        half.dt(),
        "the stable step comes from the live elements"
    );
    whole.run(300).unwrap();
    half.run(300).unwrap();
    let (mut a, mut b) = (Vec::new(), Vec::new());
    for i in 0..half.mesh().n_nodes() {
        let x = half.mesh().node(i);
        let j = (0..whole.mesh().n_nodes())
            .find(|&j| {
                let y = whole.mesh().node(j);
                (x[0] - y[0]).abs() < 1e-12 && (x[1] - y[1]).abs() < 1e-12
            })
            .expect("the lower half's nodes are in the whole block");
        a.extend_from_slice(&whole.state.u[2 * j..2 * j + 2]);
        b.extend_from_slice(&half.state.u[2 * i..2 * i + 2]);
    }
    // The upper nodes that dropped out did not move.
    for j in 0..whole.mesh().n_nodes() {
        if whole.mesh().node(j)[1] > 1.0 + 1e-9 {
            assert_eq!(&whole.state.u[2 * j..2 * j + 2], &[0.0, 0.0]);
        }
    }
    let stress = whole.field("stress").unwrap();
    let mut c = [0.0; 2];
    for e in 0..whole.mesh().n_elements() {
        whole.mesh().element_centroid(e, &mut c);
        if c[1] > 1.0 {
            assert_eq!(&stress[3 * e..3 * e + 3], &[0.0; 3]);
        }
    }
    (a, b, n)
}

fn max_diff(a: &[f64], b: &[f64]) -> (f64, f64) {
    let scale = b.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let d = a
        .iter()
        .zip(b)
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
    (d, scale)
}

#[test]
fn null_half_leaves_the_other_half_as_if_alone() {
    let (a, b, n) = halves(Backend::cpu(1).unwrap());
    assert_eq!(n, 200);
    let (d, scale) = max_diff(&a, &b);
    assert!(scale > 1e-6, "the lower half moved ({scale} m)");
    // Same arithmetic up to the order of the sums at the interface nodes.
    assert!(d <= 1e-12 * scale, "differs by {d} of {scale}");
}

#[test]
fn null_half_on_the_gpu_matches_the_cpu() {
    let Some(gpu) = gpu_test_backend(Some(Precision::F64)) else {
        return;
    };
    let (cpu, _, _) = halves(Backend::cpu(1).unwrap());
    let (dev, alone, _) = halves(gpu);
    let (d, scale) = max_diff(&dev, &cpu);
    println!("null model, GPU f64 against CPU: {d:.3e} of {scale:.3e} m");
    assert!(d <= 1e-12 * scale, "GPU differs by {d}");
    let (d, _) = max_diff(&dev, &alone);
    assert!(
        d <= 1e-12 * scale,
        "GPU half differs from the block alone by {d}"
    );
}

#[test]
fn nulling_every_element_is_an_error_not_an_infinite_step() {
    let mut s = sim(
        builders::rectangle(0.0, 0.0, 1.0, 1.0, 0.5).unwrap(),
        Backend::cpu(1).unwrap(),
    );
    let err = set_null(&mut s, &Range::All).unwrap_err().to_string();
    assert!(err.contains("time step"), "{err}");
}
