//! Elastic element mechanics: objectivity, patch tests, parameter checks, determinism,
//! save/restore, watchdog and static solves against closed forms.

use pcdc_compute::{Backend, ComputeError, Simulation, StaticOptions, Table};
use pcdc_mech::{
    output, set_velocity, Boundary, Constraint, FaceStress, LinearElastic, MechError, Mechanics,
};
use pcdc_mesh::{builders, Dim, Dim2, Dim3, Mesh, Range};
use proptest::prelude::*;

const E: f64 = 1.0e9;

fn rock() -> LinearElastic {
    LinearElastic::new(E, 0.25, 1000.0).unwrap()
}

fn cpu(t: usize) -> Backend {
    Backend::cpu(t).unwrap()
}

fn free_sim<D: Dim>(mesh: Mesh<D>) -> Simulation<D> {
    Simulation::builder(mesh, cpu(1))
        .physics(Mechanics::new().material(Range::All, rock()))
        .build()
        .unwrap()
}

fn max_abs(v: &[f64]) -> f64 {
    v.iter().fold(0.0f64, |m, x| m.max(x.abs()))
}

/// Imposes `u = R(θ) X - X` and checks the stress stays zero at every angle of a turn.
#[test]
fn rigid_rotation_is_stress_free_2d_and_3d() {
    let mut s2 = free_sim(builders::disc([0.3, -0.2], 1.0, 0.2).unwrap());
    let x0 = s2.mesh().coords().to_vec();
    for k in 0..=64 {
        let t = 2.0 * std::f64::consts::PI * k as f64 / 64.0;
        let (c, s) = (t.cos(), t.sin());
        for (i, p) in x0.chunks_exact(2).enumerate() {
            s2.state.u[2 * i] = c * p[0] - s * p[1] - p[0];
            s2.state.u[2 * i + 1] = s * p[0] + c * p[1] - p[1];
        }
        let f = max_abs(s2.evaluate_forces().unwrap());
        let st = max_abs(&output::global_stress(&s2).unwrap());
        assert!(st < 1e-9 * E, "2D angle {t}: stress {st}");
        assert!(f < 1e-9 * E, "2D angle {t}: force {f}");
    }
    let mut s3 = free_sim(builders::cuboid([0.0; 3], [1.0, 0.5, 0.7], 0.25).unwrap());
    let x0 = s3.mesh().coords().to_vec();
    let axis = [1.0f64, 2.0, 2.0].map(|v| v / 3.0);
    for k in 0..=64 {
        let t = 2.0 * std::f64::consts::PI * k as f64 / 64.0;
        let (c, s) = (t.cos(), t.sin());
        for (i, p) in x0.chunks_exact(3).enumerate() {
            // Rodrigues' rotation about `axis`.
            let kx = [
                axis[1] * p[2] - axis[2] * p[1],
                axis[2] * p[0] - axis[0] * p[2],
                axis[0] * p[1] - axis[1] * p[0],
            ];
            let kd = axis[0] * p[0] + axis[1] * p[1] + axis[2] * p[2];
            for j in 0..3 {
                s3.state.u[3 * i + j] = p[j] * c + kx[j] * s + axis[j] * kd * (1.0 - c) - p[j];
            }
        }
        s3.evaluate_forces().unwrap();
        let st = max_abs(&output::global_stress(&s3).unwrap());
        assert!(st < 1e-9 * E, "3D angle {t}: stress {st}");
    }
}

/// A free body given a rigid spin turns through a full revolution dynamically without
/// spurious stress (centrifugal stress ρω²R² is 1e-10 E here).
#[test]
fn free_spin_through_a_full_turn() {
    let mesh = builders::disc([0.0, 0.0], 1.0, 0.4).unwrap();
    let mut sim = Simulation::builder(mesh, cpu(2))
        .physics(
            Mechanics::new().material(Range::All, LinearElastic::new(E, 0.25, 1000.0).unwrap()),
        )
        .build()
        .unwrap();
    // ωR/c = 2e-4: real centrifugal stress ~ (ωR/c)² E = 4e-8 E, far below the bound.
    let omega = 2e-4 * (E / 1000.0f64).sqrt();
    let x0 = sim.mesh().coords().to_vec();
    for (i, p) in x0.chunks_exact(2).enumerate() {
        sim.state.v[2 * i] = -omega * p[1];
        sim.state.v[2 * i + 1] = omega * p[0];
    }
    let turn = 2.0 * std::f64::consts::PI / omega;
    sim.run_until(turn).unwrap();
    let st = max_abs(&output::global_stress(&sim).unwrap());
    let centrifugal = 1000.0 * omega * omega * 1.0;
    assert!(
        st < 1e-6 * E,
        "stress after one turn {st:e} (centrifugal scale {centrifugal:e})"
    );
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]

    /// Patch test on randomly distorted meshes: a linear displacement field gives the same
    /// stress in every element (to 1e-10 relative), equal to the closed form for the
    /// imposed deformation gradient, and zero force at interior nodes.
    #[test]
    fn patch_test_2d(seed in 0u64..10_000, a in proptest::array::uniform4(-1e-3f64..1e-3)) {
        let mesh = distorted_rectangle(seed);
        let mut sim = free_sim(mesh);
        let x0 = sim.mesh().coords().to_vec();
        for (i, p) in x0.chunks_exact(2).enumerate() {
            sim.state.u[2 * i] = a[0] * p[0] + a[1] * p[1];
            sim.state.u[2 * i + 1] = a[2] * p[0] + a[3] * p[1];
        }
        let f = sim.evaluate_forces().unwrap().to_vec();
        let stress = output::global_stress(&sim).unwrap();
        // Closed form: F = I + A, R from the polar decomposition, ε = RᵀF - I, σ = R (C:ε) Rᵀ.
        let fm = [1.0 + a[0], a[1], a[2], 1.0 + a[3]];
        let (c, s) = pcdc_mech::kinematics::polar_2d(&fm);
        let u = [c * fm[0] + s * fm[2], c * fm[1] + s * fm[3], -s * fm[0] + c * fm[2], -s * fm[1] + c * fm[3]];
        let eps = [u[0] - 1.0, u[3] - 1.0, 0.0, 0.5 * (u[1] + u[2]), 0.0, 0.0];
        let sl = rock().stress_of(&eps);
        let g = [c * c * sl[0] - 2.0 * c * s * sl[3] + s * s * sl[1], s * s * sl[0] + 2.0 * c * s * sl[3] + c * c * sl[1], c * s * (sl[0] - sl[1]) + (c * c - s * s) * sl[3]];
        let scale = g.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        for e in stress.chunks_exact(3) {
            for k in 0..3 {
                prop_assert!((e[k] - g[k]).abs() <= 1e-10 * scale, "stress {:?} vs {:?}", e, g);
            }
        }
        let boundary = sim.mesh().nodes_of_faces(&sim.mesh().faces().boundary);
        let fscale = scale * 0.1;
        for n in 0..sim.mesh().n_nodes() {
            if boundary.binary_search(&(n as u32)).is_err() {
                prop_assert!(f[2 * n].abs() < 1e-10 * fscale && f[2 * n + 1].abs() < 1e-10 * fscale, "interior node {} force {} {}", n, f[2 * n], f[2 * n + 1]);
            }
        }
    }

    /// Element forces are self-equilibrated: zero resultant and zero moment (the Cauchy
    /// stress is symmetric), for random deformed tetrahedra.
    #[test]
    fn element_forces_balance_3d(d in proptest::collection::vec(-0.05f64..0.05, 12)) {
        let coords = vec![0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0];
        let mut sim = free_sim(Mesh::<Dim3>::new(coords, vec![0, 1, 2, 3]).unwrap());
        sim.state.u.copy_from_slice(&d);
        let f = sim.evaluate_forces().unwrap().to_vec();
        let x = sim.positions();
        let scale = max_abs(&f).max(1.0);
        for k in 0..3 {
            let sum: f64 = (0..4).map(|n| f[3 * n + k]).sum();
            prop_assert!(sum.abs() < 1e-9 * scale);
        }
        let mut m = [0.0; 3];
        for n in 0..4 {
            let (p, q) = (&x[3 * n..3 * n + 3], &f[3 * n..3 * n + 3]);
            m[0] += p[1] * q[2] - p[2] * q[1];
            m[1] += p[2] * q[0] - p[0] * q[2];
            m[2] += p[0] * q[1] - p[1] * q[0];
        }
        prop_assert!(max_abs(&m) < 1e-9 * scale, "moment {:?}", m);
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 12, ..ProptestConfig::default() })]

    /// 3D patch test: a linear displacement field on a distorted tetrahedral mesh gives
    /// the same stress in every element (1e-10 relative) and zero interior forces.
    #[test]
    fn patch_test_3d(seed in 0u64..10_000, a in proptest::array::uniform9(-1e-3f64..1e-3)) {
        let base = builders::cuboid([0.0; 3], [1.0, 1.0, 1.0], 0.34).unwrap();
        let boundary = base.nodes_of_faces(&base.faces().boundary);
        let mut coords = base.coords().to_vec();
        let mut state = seed.wrapping_mul(6364136223846793005).wrapping_add(1);
        for n in 0..base.n_nodes() {
            if boundary.binary_search(&(n as u32)).is_err() {
                for k in 0..3 {
                    state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
                    coords[3 * n + k] += 0.05 * (((state >> 11) as f64 / (1u64 << 53) as f64) - 0.5);
                }
            }
        }
        let mut sim = free_sim(Mesh::<Dim3>::new(coords, base.elements().to_vec()).unwrap());
        let x0 = sim.mesh().coords().to_vec();
        for (i, p) in x0.chunks_exact(3).enumerate() {
            for r in 0..3 {
                sim.state.u[3 * i + r] = a[3 * r] * p[0] + a[3 * r + 1] * p[1] + a[3 * r + 2] * p[2];
            }
        }
        let f = sim.evaluate_forces().unwrap().to_vec();
        let stress = output::global_stress(&sim).unwrap();
        let first: Vec<f64> = stress[..6].to_vec();
        let scale = max_abs(&first);
        prop_assert!(scale > 0.0);
        for e in stress.chunks_exact(6) {
            for k in 0..6 {
                prop_assert!((e[k] - first[k]).abs() <= 1e-10 * scale, "stress {:?} vs {:?}", e, first);
            }
        }
        // Small-strain check of the level: σ ≈ C : sym(A) to first order; the
        // finite-strain kinematics differ at second order, E |A|², which dominates when A
        // is mostly a rotation (a small symmetric part).
        let eps = [a[0], a[4], a[8], 0.5 * (a[1] + a[3]), 0.5 * (a[5] + a[7]), 0.5 * (a[2] + a[6])];
        let lin = rock().stress_of(&eps);
        let a_max = max_abs(&a);
        let second_order = 2.0 * rock().young() * a_max * a_max;
        for k in 0..6 {
            prop_assert!((lin[k] - first[k]).abs() <= 5e-3 * scale + second_order, "{:?} vs {:?}", lin, first);
        }
        for n in 0..sim.mesh().n_nodes() {
            if boundary.binary_search(&(n as u32)).is_err() {
                for k in 0..3 {
                    prop_assert!(f[3 * n + k].abs() < 1e-10 * scale * 0.1, "interior node {} force {}", n, f[3 * n + k]);
                }
            }
        }
    }
}

/// A rectangle mesh with interior nodes moved randomly by up to 30 % of the cell size.
fn distorted_rectangle(seed: u64) -> Mesh<Dim2> {
    let base = builders::rectangle(0.0, 0.0, 1.0, 1.0, 0.2).unwrap();
    let boundary = base.nodes_of_faces(&base.faces().boundary);
    let mut coords = base.coords().to_vec();
    let mut state = seed
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    let mut rnd = || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((state >> 11) as f64 / (1u64 << 53) as f64) - 0.5
    };
    for n in 0..base.n_nodes() {
        if boundary.binary_search(&(n as u32)).is_err() {
            coords[2 * n] += 0.06 * rnd();
            coords[2 * n + 1] += 0.06 * rnd();
        }
    }
    Mesh::new(coords, base.elements().to_vec()).unwrap()
}

#[test]
fn invalid_parameters_are_errors() {
    assert!(matches!(
        LinearElastic::new(1e9, 0.5, 1000.0),
        Err(MechError::InvalidParameter { .. })
    ));
    let e = LinearElastic::new(-1e9, 0.25, 1000.0).unwrap_err();
    assert!(e.to_string().contains("Young"), "{e}");
    assert!(LinearElastic::new(1e9, 0.25, 0.0).is_err());
    assert!(LinearElastic::new(1e9, 0.25, 1.0)
        .unwrap()
        .with_damping(-1.0)
        .is_err());
    assert!(LinearElastic::from_bulk_shear(1e9, -1.0, 1000.0).is_err());
    // K/G giving ν < 0 (an auxetic material) is accepted: K and G are positive.
    let auxetic = LinearElastic::from_bulk_shear(1e9, 2e9, 1000.0).unwrap();
    assert!(
        (auxetic.poisson() + 0.1).abs() < 1e-12,
        "{}",
        auxetic.poisson()
    );
    assert!(LinearElastic::new(1e9, -1.0, 1000.0).is_err());
    assert!(LinearElastic::new(1e9, 0.5, 1000.0).is_err());
    // A mesh without a material for every element is an error naming the element.
    let mesh = builders::rectangle(0.0, 0.0, 1.0, 1.0, 0.5).unwrap();
    let err = Simulation::builder(mesh, cpu(1))
        .physics(Mechanics::new().material(Range::rect(0.0, 0.0, 0.5, 1.0), rock()))
        .build()
        .err()
        .unwrap();
    assert!(err.to_string().contains("element"), "{err}");
    // A boundary range that selects nothing is an error.
    let mesh = builders::rectangle(0.0, 0.0, 1.0, 1.0, 0.5).unwrap();
    let err = Simulation::builder(mesh, cpu(1))
        .physics(Mechanics::new().material(Range::All, rock()))
        .physics(Boundary::new().fix(Range::rect(5.0, 5.0, 6.0, 6.0)))
        .build()
        .err()
        .unwrap();
    assert!(err.to_string().contains("selects no node"), "{err}");
}

/// Build errors name the physics they come from: the boundary conditions' errors say
/// "mechanical boundary" (they used to say "mechanics", pointing the user at the
/// elements), the elements' errors keep "mechanics".
#[test]
fn build_errors_name_their_physics() {
    let build = |mech: Mechanics, bc: Boundary| {
        let mesh = builders::rectangle(0.0, 0.0, 1.0, 1.0, 0.5).unwrap();
        Simulation::builder(mesh, cpu(1))
            .physics(mech)
            .physics(bc)
            .build()
            .err()
            .expect("an error")
            .to_string()
    };
    let mech = || Mechanics::new().material(Range::All, rock());
    for (bc, expect) in [
        (
            Boundary::new().fix(Range::rect(5.0, 5.0, 6.0, 6.0)),
            "mechanical boundary: boundary condition 0 (constraint): the range",
        ),
        (
            Boundary::new().face_stress(Range::group("top"), FaceStress::diagonal(0.0, 1.0, 1.0)),
            "mechanical boundary: invalid parameter face stress zz",
        ),
        (
            Boundary::new().face_stress(Range::group("top"), FaceStress::normal(f64::NAN)),
            "mechanical boundary: invalid parameter face stress normal = NaN",
        ),
        (
            Boundary::new().velocity(
                Range::group("top"),
                [Some(f64::INFINITY.into()), None, None],
            ),
            "mechanical boundary: invalid parameter velocity component 0 = inf",
        ),
    ] {
        let msg = build(mech(), bc);
        assert!(msg.starts_with(expect), "{msg}");
        assert!(!msg.contains("mechanics"), "{msg}");
    }
    let msg = build(
        mech().initial_stress(Range::All, [f64::NAN, 0.0, 0.0, 0.0, 0.0, 0.0]),
        Boundary::new(),
    );
    assert!(
        msg.starts_with("mechanics: invalid parameter initial stress"),
        "{msg}"
    );
}

proptest! {
    #[test]
    fn bulk_shear_and_young_poisson_agree(e in 1e6f64..1e11, nu in 0.0f64..0.49) {
        let a = LinearElastic::new(e, nu, 2000.0).unwrap();
        let b = LinearElastic::from_bulk_shear(a.bulk(), a.shear(), 2000.0).unwrap();
        prop_assert!((a.lambda() - b.lambda()).abs() <= 1e-9 * e);
        prop_assert!((a.shear() - b.shear()).abs() <= 1e-9 * e);
        prop_assert!((a.young() - b.young()).abs() <= 1e-9 * e);
    }

    #[test]
    fn elastic_energy_positive_and_zero_at_zero(e in 1e6f64..1e11, nu in 0.0f64..0.49, s in proptest::array::uniform6(-1e-3f64..1e-3)) {
        use pcdc_mech::ConstitutiveModel;
        let m = LinearElastic::new(e, nu, 2000.0).unwrap();
        let mut zero = [0.0; 6];
        m.update(&[0.0; 6], &[0.0; 6], &mut zero, &mut []);
        prop_assert_eq!(zero, [0.0; 6]);
        let sig = m.stress_of(&s);
        let w = 0.5 * pcdc_mech::double_dot(&sig, &s);
        prop_assume!(s.iter().any(|v| v.abs() > 1e-9));
        prop_assert!(w > 0.0);
        // The tangent reproduces the update.
        let t = m.linear_tangent().unwrap();
        for i in 0..6 {
            let v: f64 = (0..6).map(|j| t[i][j] * s[j]).sum();
            prop_assert!((v - sig[i]).abs() <= 1e-9 * e * 1e-3);
        }
    }
}

fn loaded_block(threads: usize) -> Simulation<Dim2> {
    let mesh = builders::rectangle(0.0, 0.0, 1.0, 0.5, 0.1).unwrap();
    let vel = Table::new("top velocity", &[(0.0, 0.0), (1e-3, -0.05)]).unwrap();
    Simulation::builder(mesh, cpu(threads))
        .physics(Mechanics::new().material(Range::All, rock().with_damping(0.1).unwrap()))
        .physics(
            Boundary::new()
                .fix(Range::group("bottom"))
                .velocity(Range::group("top"), [None, Some(vel.into()), None]),
        )
        .gravity([0.0, -9.81, 0.0])
        .build()
        .unwrap()
}

#[test]
fn identical_results_for_any_thread_count() {
    let mut a = loaded_block(1);
    let mut b = loaded_block(2);
    a.run(300).unwrap();
    b.run(300).unwrap();
    assert!(a
        .state
        .u
        .iter()
        .zip(&b.state.u)
        .all(|(x, y)| x.to_bits() == y.to_bits()));
    assert!(a
        .field("stress")
        .unwrap()
        .iter()
        .zip(b.field("stress").unwrap())
        .all(|(x, y)| x.to_bits() == y.to_bits()));
}

#[test]
fn save_restore_continues_bit_for_bit() {
    let dir = std::env::temp_dir().join(format!("pcdc-snap-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("block.snap");
    let mut a = loaded_block(2);
    a.run(150).unwrap();
    a.save(&path).unwrap();
    a.run(150).unwrap();
    let mut b = loaded_block(2);
    b.restore(&path).unwrap();
    assert_eq!(b.state.step, 150);
    b.run(150).unwrap();
    assert_eq!(a.state.time.to_bits(), b.state.time.to_bits());
    assert!(a
        .state
        .u
        .iter()
        .zip(&b.state.u)
        .all(|(x, y)| x.to_bits() == y.to_bits()));
    assert!(a
        .state
        .v
        .iter()
        .zip(&b.state.v)
        .all(|(x, y)| x.to_bits() == y.to_bits()));
    // A snapshot of another scene is refused.
    let mut other = free_sim(builders::rectangle(0.0, 0.0, 1.0, 1.0, 0.5).unwrap());
    assert!(matches!(
        other.restore(&path),
        Err(ComputeError::SnapshotMismatch(_))
    ));
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn watchdog_names_step_and_node() {
    let mesh = builders::rectangle(0.0, 0.0, 1.0, 0.5, 0.1).unwrap();
    let mut sim = Simulation::builder(mesh, cpu(1))
        .physics(Mechanics::new().material(Range::All, rock()))
        .physics(Boundary::new().fix(Range::group("bottom")))
        .gravity([0.0, -9.81, 0.0])
        .time_step(1e-3)
        .build()
        .unwrap();
    let limit = sim.time_step_limit().unwrap().clone();
    assert_eq!(
        limit.entity.kind,
        pcdc_compute::EntityKind::Element,
        "{limit:?}"
    );
    assert!(limit.dt < 1e-3);
    let err = sim.run(100_000).unwrap_err();
    let msg = err.to_string();
    assert!(matches!(err, ComputeError::Diverged { .. }), "{msg}");
    assert!(
        msg.contains("step") && msg.contains("node") && msg.contains("Hint"),
        "{msg}"
    );
}

/// Uniaxial strain column under a top stress, sides on rollers: σ_yy = p everywhere and
/// u_y(top) = p H / M with the constrained modulus M. Both static solvers.
#[test]
fn static_solvers_match_uniaxial_strain() {
    let p = -2.0e6;
    let h = 2.0;
    let build = || {
        let mesh = builders::rectangle(0.0, 0.0, 1.0, h, 0.25).unwrap();
        Simulation::builder(mesh, cpu(2))
            .physics(Mechanics::new().material(Range::All, rock()))
            .physics(
                Boundary::new()
                    .constraint(Range::group("bottom"), Constraint::Line([1.0, 0.0, 0.0]))
                    .constraint(Range::group("left"), Constraint::Line([0.0, 1.0, 0.0]))
                    .constraint(Range::group("right"), Constraint::Line([0.0, 1.0, 0.0]))
                    .face_stress(
                        Range::group("top"),
                        FaceStress {
                            yy: Some(p.into()),
                            ..Default::default()
                        },
                    ),
            )
            .build()
            .unwrap()
    };
    let m = rock().lambda() + 2.0 * rock().shear();
    let expect = p * h / m;
    let mut direct = build();
    let rep = direct
        .solve_linear(&StaticOptions {
            tolerance: 1e-9,
            ..Default::default()
        })
        .unwrap();
    let mut relaxed = build();
    let rep2 = relaxed
        .relax(&StaticOptions {
            tolerance: 1e-7,
            ..Default::default()
        })
        .unwrap();
    for (name, sim) in [("direct", &direct), ("relaxation", &relaxed)] {
        let top = sim.mesh().select_nodes(&Range::group("top")).unwrap();
        for &n in &top {
            let uy = sim.state.u[2 * n as usize + 1];
            assert!(
                (uy - expect).abs() < 1e-4 * expect.abs(),
                "{name}: u_y {uy} vs {expect}"
            );
        }
        let s = output::global_stress(sim).unwrap();
        for e in s.chunks_exact(3) {
            assert!(
                (e[1] - p).abs() < 1e-4 * p.abs(),
                "{name}: σyy {} vs {p}",
                e[1]
            );
        }
    }
    assert!(rep.steps <= 3, "{rep:?}");
    assert!(rep2.steps > 0);
}

/// A disc under a normal (follower) pressure: uniform in-plane hydrostatic stress.
#[test]
fn normal_face_stress_gives_hydrostatic_disc() {
    let mesh = builders::disc([0.0, 0.0], 1.0, 0.2).unwrap();
    let mut sim = Simulation::builder(mesh, cpu(1))
        .physics(Mechanics::new().material(Range::All, rock()))
        .physics(
            Boundary::new()
                .face_stress(Range::group("boundary"), FaceStress::normal(-1.0e6))
                .constraint(
                    Range::Ball {
                        center: [0.0; 3],
                        radius: 1e-9,
                    },
                    Constraint::Fixed,
                )
                .constraint(
                    Range::plane([0.0; 3], [0.0, 1.0, 0.0], 1e-9).and(Range::Ball {
                        center: [1.0, 0.0, 0.0],
                        radius: 1e-6,
                    }),
                    Constraint::Line([1.0, 0.0, 0.0]),
                ),
        )
        .build()
        .unwrap();
    sim.solve_linear(&StaticOptions::default()).unwrap();
    let s = output::global_stress(&sim).unwrap();
    for e in s.chunks_exact(3) {
        assert!(
            (e[0] + 1.0e6).abs() < 1e-3 * 1e6
                && (e[1] + 1.0e6).abs() < 1e-3 * 1e6
                && e[2].abs() < 1e-3 * 1e6,
            "{e:?}"
        );
    }
}

/// Pure shear σ_xy = τ on every face of a square: the static solution is the uniform
/// engineering shear strain γ = τ / G (u_x = γ y with the rotation fixed by a roller at
/// the bottom-right corner) and the stress σ_xy = τ in every element. The static
/// solution keeps the large-rotation kinematics and the tractions follow the faces, so
/// it departs from the small-strain closed form by O(γ²): about γ / 8 relative here
/// (γ = 5e-5), well inside the 1e-4 checked.
#[test]
fn shear_face_stress_gives_gamma_tau_over_g_2d() {
    let tau = 2.0e4;
    let mesh = builders::rectangle(0.0, 0.0, 1.0, 1.0, 0.25).unwrap();
    let corner = |x: f64, y: f64| Range::Ball {
        center: [x, y, 0.0],
        radius: 1e-9,
    };
    let mut sim = Simulation::builder(mesh, cpu(1))
        .physics(Mechanics::new().material(Range::All, rock()))
        .physics(
            Boundary::new()
                .face_stress(Range::All, FaceStress::shear_xy(tau))
                .fix(corner(0.0, 0.0))
                .constraint(corner(1.0, 0.0), Constraint::Line([1.0, 0.0, 0.0])),
        )
        .build()
        .unwrap();
    sim.solve_linear(&StaticOptions {
        tolerance: 1e-10,
        ..Default::default()
    })
    .unwrap();
    let gamma = tau / rock().shear();
    let x = sim.mesh().coords().to_vec();
    for (p, u) in x.chunks_exact(2).zip(sim.state.u.chunks_exact(2)) {
        let expect = [gamma * p[1], 0.0];
        for k in 0..2 {
            assert!(
                (u[k] - expect[k]).abs() < 1e-4 * gamma,
                "node at {p:?}: u = {u:?}, expected {expect:?} (γ = τ/G = {gamma:e})"
            );
        }
    }
    for s in output::global_stress(&sim).unwrap().chunks_exact(3) {
        assert!(
            s[0].abs() < 1e-4 * tau && s[1].abs() < 1e-4 * tau && (s[2] - tau).abs() < 1e-4 * tau,
            "{s:?}"
        );
    }
}

/// The three shear components on every face of a cube: γ_ij = τ_ij / G, with u_x =
/// γ_xy y + γ_xz z, u_y = γ_yz z, u_z = 0 once the rotations are fixed by a roller
/// along x at (1, 0, 0) and a plane roller at (0, 1, 0).
#[test]
fn shear_face_stress_gives_gamma_tau_over_g_3d() {
    let (txy, tyz, txz) = (2.0e4, -1.0e4, 0.5e4);
    let mesh = builders::cuboid([0.0; 3], [1.0; 3], 0.5).unwrap();
    let corner = |c: [f64; 3]| Range::Ball {
        center: c,
        radius: 1e-9,
    };
    let mut sim = Simulation::builder(mesh, cpu(1))
        .physics(Mechanics::new().material(Range::All, rock()))
        .physics(
            Boundary::new()
                .face_stress(
                    Range::All,
                    FaceStress::tensor([0.0, 0.0, 0.0, txy, tyz, txz]),
                )
                .fix(corner([0.0; 3]))
                .constraint(corner([1.0, 0.0, 0.0]), Constraint::Line([1.0, 0.0, 0.0]))
                .constraint(corner([0.0, 1.0, 0.0]), Constraint::Plane([0.0, 0.0, 1.0])),
        )
        .build()
        .unwrap();
    sim.solve_linear(&StaticOptions {
        tolerance: 1e-10,
        ..Default::default()
    })
    .unwrap();
    let g = rock().shear();
    let (gxy, gyz, gxz) = (txy / g, tyz / g, txz / g);
    let x = sim.mesh().coords().to_vec();
    for (p, u) in x.chunks_exact(3).zip(sim.state.u.chunks_exact(3)) {
        let expect = [gxy * p[1] + gxz * p[2], gyz * p[2], 0.0];
        for k in 0..3 {
            assert!(
                (u[k] - expect[k]).abs() < 1e-4 * gxy,
                "node at {p:?}: u = {u:?}, expected {expect:?}"
            );
        }
    }
    let expect = [0.0, 0.0, 0.0, txy, tyz, txz];
    for s in output::global_stress(&sim).unwrap().chunks_exact(6) {
        for k in 0..6 {
            assert!((s[k] - expect[k]).abs() < 1e-4 * txy, "{s:?} vs {expect:?}");
        }
    }
}

/// In 2D a shear component out of the plane is an error naming it, not a panic.
#[test]
fn out_of_plane_shear_face_stress_is_rejected_in_2d() {
    for (stress, name) in [
        (
            FaceStress {
                yz: Some(1.0e6.into()),
                ..Default::default()
            },
            "face stress yz",
        ),
        (
            FaceStress {
                xz: Some(Table::new("t", &[(0.0, 0.0), (1.0, 1.0)]).unwrap().into()),
                ..Default::default()
            },
            "face stress xz",
        ),
    ] {
        let mesh = builders::rectangle(0.0, 0.0, 1.0, 1.0, 0.5).unwrap();
        let err = Simulation::builder(mesh, cpu(1))
            .physics(Mechanics::new().material(Range::All, rock()))
            .physics(Boundary::new().face_stress(Range::group("top"), stress))
            .build()
            .err()
            .expect("an error")
            .to_string();
        assert!(
            err.contains(name) && err.contains("the mesh is 2D"),
            "{err}"
        );
    }
    // The constant 0 changes nothing and is accepted, as for zz.
    let mesh = builders::rectangle(0.0, 0.0, 1.0, 1.0, 0.5).unwrap();
    Simulation::builder(mesh, cpu(1))
        .physics(Mechanics::new().material(Range::All, rock()))
        .physics(Boundary::new().face_stress(
            Range::group("top"),
            FaceStress::tensor([0.0, -1.0e6, 0.0, 1.0e5, 0.0, 0.0]),
        ))
        .build()
        .unwrap();
}

#[test]
fn node_force_acceleration_and_line_constraint() {
    // A free block pushed by node forces accelerates as F/m; a node on a 45° line
    // constraint moves along it; a prescribed acceleration integrates to v = a t.
    let mesh = builders::rectangle(0.0, 0.0, 1.0, 1.0, 0.5).unwrap();
    let total_mass = 1000.0;
    let mut sim = Simulation::builder(mesh, cpu(1))
        .physics(Mechanics::new().material(Range::All, rock()))
        .physics(Boundary::new().node_force(Range::All, [Some(10.0.into()), None, None]))
        .build()
        .unwrap();
    let n = sim.mesh().n_nodes() as f64;
    let dt = sim.dt();
    sim.run(100).unwrap();
    let momentum: f64 = sim
        .state
        .v
        .chunks_exact(2)
        .zip(sim.mass())
        .map(|(v, m)| m * v[0])
        .sum();
    let expect = 10.0 * n * 100.0 * dt;
    assert!((sim.mass().iter().sum::<f64>() - total_mass).abs() < 1e-9 * total_mass);
    assert!(
        (momentum - expect).abs() < 1e-9 * expect,
        "{momentum} vs {expect}"
    );

    let mesh = builders::rectangle(0.0, 0.0, 1.0, 1.0, 0.5).unwrap();
    let mut sim = Simulation::builder(mesh, cpu(1))
        .physics(Mechanics::new().material(Range::All, rock()))
        .physics(
            Boundary::new()
                .acceleration(Range::group("bottom"), [Some(2.0.into()), None, None])
                .constraint(Range::group("top"), Constraint::Line([1.0, 1.0, 0.0])),
        )
        .build()
        .unwrap();
    set_velocity(&mut sim, &Range::group("top"), [0.3, -0.1, 0.0]).unwrap();
    sim.run(50).unwrap();
    let bottom = sim.mesh().select_nodes(&Range::group("bottom")).unwrap();
    for &b in &bottom {
        let v = sim.state.v[2 * b as usize];
        assert!((v - 2.0 * sim.state.time).abs() < 1e-9, "{v}");
    }
    let top = sim.mesh().select_nodes(&Range::group("top")).unwrap();
    for &t in &top {
        let u = &sim.state.u[2 * t as usize..2 * t as usize + 2];
        assert!((u[0] - u[1]).abs() < 1e-12 * u[0].abs().max(1e-12), "{u:?}");
    }
}

#[test]
fn damping_reduces_the_stable_step_and_dissipates() {
    let mk = |df: f64| {
        let mesh = builders::rectangle(0.0, 0.0, 1.0, 0.2, 0.05).unwrap();
        let mut sim = Simulation::builder(mesh, cpu(1))
            .physics(Mechanics::new().material(Range::All, rock().with_damping(df).unwrap()))
            .build()
            .unwrap();
        let x0 = sim.mesh().coords().to_vec();
        for (i, p) in x0.chunks_exact(2).enumerate() {
            sim.state.u[2 * i] = 1e-4 * p[0];
        }
        sim
    };
    let (mut a, mut b) = (mk(0.0), mk(1.0));
    assert!(b.dt() < 0.5 * a.dt(), "{} vs {}", b.dt(), a.dt());
    a.evaluate_forces().unwrap();
    let e0 = a.stored_energy();
    assert!(e0 > 0.0);
    a.run_until(2e-3).unwrap();
    b.run_until(2e-3).unwrap();
    let ea = a.stored_energy() + a.kinetic_energy();
    let eb = b.stored_energy() + b.kinetic_energy();
    assert!((ea - e0).abs() < 0.02 * e0, "undamped energy {ea} vs {e0}");
    assert!(eb < 0.2 * e0, "damped energy {eb} vs {e0}");
}

#[test]
fn resets_between_stages() {
    let mut sim = loaded_block(1);
    sim.run(200).unwrap();
    assert!(max_abs(&output::displacement(&sim).unwrap()) > 0.0);
    pcdc_mech::reset_displacement(&mut sim, &Range::All).unwrap();
    assert_eq!(max_abs(&output::displacement(&sim).unwrap()), 0.0);
    pcdc_mech::reset_velocity(&mut sim, &Range::All).unwrap();
    assert_eq!(max_abs(&sim.state.v), 0.0);
    pcdc_mech::reset_element_state(&mut sim, &Range::All).unwrap();
    assert_eq!(max_abs(sim.field("stress").unwrap()), 0.0);
}

#[test]
fn initial_stress_is_kept_in_equilibrium() {
    // A free body with a uniform initial stress and matching face tractions stays put.
    let mesh = builders::rectangle(0.0, 0.0, 1.0, 1.0, 0.25).unwrap();
    let s0 = [-1e6, -2e6, -0.75e6, 0.0, 0.0, 0.0];
    let mut sim = Simulation::builder(mesh, cpu(1))
        .physics(
            Mechanics::new()
                .material(Range::All, rock())
                .initial_stress(Range::All, s0),
        )
        .physics(Boundary::new().face_stress(Range::All, FaceStress::diagonal(s0[0], s0[1], 0.0)))
        .build()
        .unwrap();
    sim.run(100).unwrap();
    assert!(max_abs(&sim.state.u) < 1e-15, "{}", max_abs(&sim.state.u));
    let _ = Dim2::NAME;
}

/// `write_step_with` writes the standard arrays and the extra point and cell arrays
/// (names in the right sections, values as given); a name clash is an error and writes
/// nothing.
#[test]
fn write_step_with_adds_point_and_cell_arrays() {
    use pcdc_mesh::vtu::{DataArray, PvdSeries, VtuEncoding};
    let dir = std::env::temp_dir().join(format!("pcdc-extra-{}", std::process::id()));
    let mut sim = loaded_block(1);
    sim.run(20).unwrap();
    let (nn, ne) = (sim.mesh().n_nodes(), sim.mesh().n_elements());
    let node_ids: Vec<f64> = (0..nn).map(|i| i as f64 + 0.5).collect();
    let elem_flags: Vec<i32> = (0..ne as i32).map(|e| 7 * e).collect();
    let mut series = PvdSeries::new(&dir, "extra")
        .unwrap()
        .with_encoding(VtuEncoding::Ascii);
    let path = output::write_step_with(
        &mut series,
        &sim,
        &[DataArray::Scalar {
            name: "node_label",
            values: &node_ids,
        }],
        &[DataArray::Int {
            name: "elem_flag",
            values: &elem_flags,
        }],
    )
    .unwrap();
    let xml = std::fs::read_to_string(&path).unwrap();
    let at = |name: &str| {
        xml.find(&format!("Name=\"{name}\""))
            .unwrap_or_else(|| panic!("no array {name} in {}", path.display()))
    };
    let (pd, cd) = (
        xml.find("<PointData").unwrap(),
        xml.find("<CellData").unwrap(),
    );
    assert!(pd < cd);
    for name in output::STEP_POINT_ARRAYS.iter().chain(&["node_label"]) {
        assert!(pd < at(name) && at(name) < cd, "{name} not in PointData");
    }
    for name in output::STEP_CELL_ARRAYS.iter().chain(&["elem_flag"]) {
        assert!(cd < at(name), "{name} not in CellData");
    }
    // The values as written: the text of the array up to its closing tag.
    let values = |name: &str| -> Vec<f64> {
        let body = &xml[at(name)..];
        let body = &body[body.find('>').unwrap() + 1..body.find("</DataArray>").unwrap()];
        body.split_whitespace()
            .map(|v| v.parse().unwrap())
            .collect()
    };
    assert_eq!(values("node_label"), node_ids);
    let flags: Vec<f64> = elem_flags.iter().map(|&f| f as f64).collect();
    assert_eq!(values("elem_flag"), flags);
    assert!(xml[at("elem_flag")..].starts_with("Name=\"elem_flag\""));
    assert!(xml[..at("elem_flag")].ends_with("type=\"Int32\" "));
    // An extra array named like a standard one is refused; the series is unchanged.
    let err = output::write_step_with(
        &mut series,
        &sim,
        &[],
        &[DataArray::Scalar {
            name: "stress",
            values: &vec![0.0; ne],
        }],
    )
    .unwrap_err();
    assert!(err.to_string().contains("stress"), "{err}");
    assert_eq!(series.steps().len(), 1);
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn history_csv_and_vtu_series() {
    use pcdc_compute::{History, Probe};
    let dir = std::env::temp_dir().join(format!("pcdc-hist-{}", std::process::id()));
    let mut sim = loaded_block(1);
    let top = sim.mesh().select_nodes(&Range::group("top")).unwrap()[0];
    let mut hist = History::new()
        .probe("t", Probe::Time)
        .probe("uy_top", Probe::NodeDisplacement { node: top, comp: 1 })
        .probe(
            "syy_e0",
            Probe::Field {
                field: "stress".into(),
                index: 0,
                comp: 1,
            },
        )
        .probe("ke", Probe::KineticEnergy)
        .probe("two_t", Probe::Custom(Box::new(|s| 2.0 * s.state.time)));
    let mut series = pcdc_mesh::vtu::PvdSeries::new(&dir, "block").unwrap();
    for _ in 0..5 {
        sim.run(20).unwrap();
        hist.sample(&sim).unwrap();
        output::write_step(&mut series, &sim).unwrap();
    }
    let csv = dir.join("hist.csv");
    hist.write_csv(&csv).unwrap();
    let text = std::fs::read_to_string(&csv).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines[0], "t,uy_top,syy_e0,ke,two_t");
    assert_eq!(lines.len(), 6);
    let last: Vec<f64> = lines[5].split(',').map(|v| v.parse().unwrap()).collect();
    assert_eq!(last[0], sim.state.time);
    assert_eq!(last[1], sim.state.u[2 * top as usize + 1]);
    assert_eq!(last[4], 2.0 * sim.state.time);
    assert!(last[1] < 0.0, "top pushed down");
    let pvd = std::fs::read_to_string(dir.join("block.pvd")).unwrap();
    assert_eq!(pvd.matches("<DataSet").count(), 5);
    // A probe on a node that does not exist is an error, not a panic.
    let mut bad = History::new().probe(
        "x",
        Probe::NodeVelocity {
            node: 1_000_000,
            comp: 0,
        },
    );
    assert!(bad.sample(&sim).is_err());
    let mut bad = History::new().probe(
        "x",
        Probe::Field {
            field: "pressure".into(),
            index: 0,
            comp: 0,
        },
    );
    assert!(bad.sample(&sim).is_err());
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn corrupted_snapshots_are_errors() {
    let a = loaded_block(1);
    let bytes = a.snapshot_bytes().unwrap();
    let mut b = loaded_block(1);
    for cut in [0, 1, 10, bytes.len() / 2, bytes.len() - 1] {
        assert!(b.restore_bytes(&bytes[..cut]).is_err(), "cut at {cut}");
    }
    let mut flipped = bytes.clone();
    for i in (0..flipped.len()).step_by(97) {
        flipped[i] ^= 0x5a;
    }
    // Either refused or accepted with a consistent layout; never a panic.
    let _ = b.restore_bytes(&flipped);
    assert!(matches!(
        b.restore("/nonexistent/dir/x.snap"),
        Err(ComputeError::Io { .. })
    ));
}

/// Mechanics composed twice used to build, run and halve the stress (each instance
/// added its element forces into one stress field); now it is a build error.
#[test]
fn mechanics_composed_twice_is_an_error() {
    let mesh = builders::rectangle(0.0, 0.0, 1.0, 1.0, 0.5).unwrap();
    let err = Simulation::builder(mesh, cpu(1))
        .physics(Mechanics::new().material(Range::All, rock()))
        .physics(Mechanics::new().material(Range::All, rock()))
        .build()
        .err()
        .expect("two Mechanics must not build");
    assert!(
        matches!(&err, ComputeError::DuplicatePhysics(name) if name == "mechanics"),
        "{err}"
    );
}
