//! The null model in an FDEM scene (manual 7.2.8): joints to null elements become free
//! faces and contact skips null elements, on the CPU and the GPU. A jointed block with
//! contact whose upper half is switched to null moves, under gravity on a fixed base,
//! as the lower half alone, element by element (the joints and contact of the lower
//! half are the same; the broken joints at the cut and the null elements add no force).
//!
//! One difference remains, and the tolerance is set by it: on the cut, a vertex whose
//! bonds to the null elements are broken counts as open for contact, so two live
//! elements that share only that vertex may touch, where on an outer boundary the
//! vertex stays intact and the pair is skipped. Here it moves the lower half by 3e-7 of
//! its displacement (checked at 1e-6); the GPU repeats the CPU to 1e-12.

use pcdc::compute::gpu::gpu_test_backend;
use pcdc::compute::{Backend, Precision, Simulation};
use pcdc_cohesive::{CohesiveJoints, IntrinsicCzmParams, BROKEN_FACE};
use pcdc_contact::Contact;
use pcdc_mech::{set_null, Boundary, Constraint, LinearElastic, Mechanics};
use pcdc_mesh::{builders, split_nodes, Dim2, Range};

fn block(height: f64, backend: Backend) -> Simulation<Dim2> {
    let e = 1e9;
    let mesh = builders::rectangle(0.0, 0.0, 1.0, height, 0.125).unwrap();
    let split = split_nodes(&mesh, &Range::All).unwrap();
    let rock = LinearElastic::new(e, 0.25, 2000.0)
        .unwrap()
        .with_damping(0.2)
        .unwrap();
    let czm = IntrinsicCzmParams {
        friction_deg: 30.0,
        cohesion: 4e6,
        tensile_strength: 1e6,
        gf1: 10.0,
        gf2: 50.0,
        penalty_open: 10.0 * e,
        penalty_shear: 10.0 * e,
        penalty_overlap: 10.0 * e,
    }
    .build()
    .unwrap();
    Simulation::builder(split, backend)
        .gravity([0.0, -9.81, 0.0])
        .physics(
            Mechanics::new()
                .material(Range::All, rock)
                .initial_stress(Range::All, [-1e5, -2e5, -1e5, 3e4, 0.0, 0.0]),
        )
        .physics(CohesiveJoints::new().model(Range::All, czm))
        .physics(
            Contact::new(10.0 * e)
                .friction(30.0, 10.0 * e)
                .bonded_interfaces(BROKEN_FACE),
        )
        .physics(
            Boundary::new().constraint(Range::group("bottom"), Constraint::Line([1.0, 0.0, 0.0])),
        )
        .build()
        .unwrap()
}

/// Displacements of the lower half's element nodes after `steps`: the two-part block
/// with its upper half null, and the lower half alone.
fn halves(backend: Backend, steps: u64) -> (Vec<f64>, Vec<f64>, usize) {
    let mut whole = block(2.0, backend.clone());
    let upper = Range::HalfSpace {
        point: [0.0, 1.0, 0.0],
        normal: [0.0, 1.0, 0.0],
    };
    let nulled = set_null(&mut whole, &upper).unwrap();
    let mut half = block(1.0, backend);
    assert_eq!(
        whole.dt(),
        half.dt(),
        "the stable step comes from the live part"
    );
    // The joints on the cut are broken: free faces.
    let damage = whole.field("joint_damage").unwrap();
    let cut = whole
        .mesh()
        .interfaces()
        .elements()
        .chunks_exact(2)
        .zip(damage)
        .filter(|(p, &d)| {
            let mut c = [0.0; 2];
            let centre = |e: u32, c: &mut [f64; 2]| {
                whole.mesh().element_centroid(e as usize, c);
                c[1] > 1.0
            };
            let (a, b) = (centre(p[0], &mut c), centre(p[1], &mut c));
            assert!(!(a || b) || d >= 1.0, "a joint to a null element holds");
            a != b
        })
        .count();
    assert!(cut > 0);
    whole.run(steps).unwrap();
    half.run(steps).unwrap();
    let (mut a, mut b) = (Vec::new(), Vec::new());
    // The rectangle numbers its elements row by row from the bottom, and the split keeps
    // their order: the lower half's elements come first in both meshes.
    for e in 0..half.mesh().n_elements() {
        let (cw, ch) = (whole.mesh().element(e), half.mesh().element(e));
        for (&nw, &nh) in cw.iter().zip(ch) {
            assert_eq!(
                whole.mesh().node(nw as usize),
                half.mesh().node(nh as usize)
            );
            a.extend_from_slice(&whole.state.u[2 * nw as usize..2 * nw as usize + 2]);
            b.extend_from_slice(&half.state.u[2 * nh as usize..2 * nh as usize + 2]);
        }
    }
    (a, b, nulled)
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
fn null_half_of_a_jointed_block_leaves_the_other_half_as_if_alone() {
    let (a, b, n) = halves(Backend::cpu(1).unwrap(), 400);
    assert_eq!(n, 128);
    let (d, scale) = max_diff(&a, &b);
    println!("CPU: max |Δu| {d:.3e} m of {scale:.3e} m");
    assert!(scale > 1e-7, "the block must move");
    assert!(d <= 1e-6 * scale, "{d} of {scale}");
}

#[test]
fn null_half_of_a_jointed_block_on_the_gpu() {
    let Some(gpu) = gpu_test_backend(Some(Precision::F64)) else {
        return;
    };
    let (a, b, _) = halves(gpu, 400);
    let (d, scale) = max_diff(&a, &b);
    let (cpu, _, _) = halves(Backend::cpu(1).unwrap(), 400);
    let (dc, _) = max_diff(&a, &cpu);
    println!("GPU f64: max |Δu| {d:.3e} m of {scale:.3e} m; against the CPU {dc:.3e} m");
    assert!(
        d <= 1e-6 * scale && dc <= 1e-12 * scale,
        "{d} {dc} of {scale}"
    );
}
