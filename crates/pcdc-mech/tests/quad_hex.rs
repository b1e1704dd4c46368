//! Quad4 and Hex8 cells (mixed discretisation, `pcdc_mech::mixed`): patch tests on
//! distorted cells, stress-free rigid turns, no locking when ν → 0.5 where the
//! triangles lock, the B̄ static stiffness agreeing with the explicit forces, and bad
//! cells refused by name.

use pcdc_compute::{Backend, Simulation, StaticOptions};
use pcdc_mech::{output, Boundary, Constraint, FaceStress, LinearElastic, Mechanics};
use pcdc_mesh::{builders, Dim, Dim2, Dim3, ElementKind, Mesh, MeshError, Range};
use proptest::prelude::*;

const E: f64 = 1.0e9;

fn rock(nu: f64) -> LinearElastic {
    LinearElastic::new(E, nu, 1000.0).unwrap()
}

fn free_sim<D: Dim>(mesh: Mesh<D>, nu: f64) -> Simulation<D> {
    Simulation::builder(mesh, Backend::cpu(1).unwrap())
        .physics(Mechanics::new().material(Range::All, rock(nu)))
        .build()
        .unwrap()
}

fn max_abs(v: &[f64]) -> f64 {
    v.iter().fold(0.0f64, |m, x| m.max(x.abs()))
}

/// A pseudo-random number in [-0.5, 0.5).
fn rnd(state: &mut u64) -> f64 {
    *state = state
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    ((*state >> 11) as f64 / (1u64 << 53) as f64) - 0.5
}

/// The cells of `base` with interior nodes moved by up to `amp` (m) at random.
fn distorted<D: Dim>(base: &Mesh<D>, seed: u64, amp: f64) -> Mesh<D> {
    let boundary = base.nodes_of_faces(&base.faces().boundary);
    let mut coords = base.coords().to_vec();
    let mut state = seed.wrapping_add(17);
    for n in 0..base.n_nodes() {
        if boundary.binary_search(&(n as u32)).is_err() {
            for k in 0..D::D {
                coords[D::D * n + k] += amp * rnd(&mut state);
            }
        }
    }
    let kinds: Vec<ElementKind> = (0..base.n_cells()).map(|c| base.cell_kind(c)).collect();
    let conn: Vec<u32> = (0..base.n_cells())
        .flat_map(|c| base.cell_nodes(c).to_vec())
        .collect();
    Mesh::from_cells(coords, kinds, conn).unwrap()
}

/// A 5 x 5 square of quads whose left half is cut into triangles (a mixed mesh).
fn mixed_square() -> Mesh<Dim2> {
    let quads = builders::rectangle_quads(0.0, 0.0, 1.0, 1.0, 0.2).unwrap();
    let (mut kinds, mut conn) = (Vec::new(), Vec::new());
    for c in 0..quads.n_cells() {
        let n = quads.cell_nodes(c);
        let x = quads.node(n[0] as usize)[0];
        if x < 0.45 {
            kinds.extend([ElementKind::Tri3; 2]);
            conn.extend([n[0], n[1], n[2], n[0], n[2], n[3]]);
        } else {
            kinds.push(ElementKind::Quad4);
            conn.extend_from_slice(n);
        }
    }
    Mesh::from_cells(quads.coords().to_vec(), kinds, conn).unwrap()
}

/// Imposes u = A x and checks one stress in every element and zero interior forces.
fn patch<D: Dim>(mesh: Mesh<D>, a: &[f64], nu: f64) -> Result<(), TestCaseError> {
    let d = D::D;
    let mut sim = free_sim(mesh, nu);
    let x0 = sim.mesh().coords().to_vec();
    for (i, p) in x0.chunks_exact(d).enumerate() {
        for r in 0..d {
            sim.state.u[d * i + r] = (0..d).map(|c| a[d * r + c] * p[c]).sum();
        }
    }
    let f = sim.evaluate_forces().unwrap().to_vec();
    let stress = output::global_stress(&sim).unwrap();
    let nsym = D::NSYM;
    let first = stress[..nsym].to_vec();
    let scale = max_abs(&first);
    prop_assert!(scale > 0.0);
    for e in stress.chunks_exact(nsym) {
        for k in 0..nsym {
            prop_assert!(
                (e[k] - first[k]).abs() <= 1e-9 * scale,
                "stress {:?} vs {:?}",
                e,
                first
            );
        }
    }
    let boundary = sim.mesh().nodes_of_faces(&sim.mesh().faces().boundary);
    for n in 0..sim.mesh().n_nodes() {
        if boundary.binary_search(&(n as u32)).is_err() {
            for k in 0..d {
                prop_assert!(
                    f[d * n + k].abs() < 1e-9 * scale * 0.1,
                    "interior node {} force {}",
                    n,
                    f[d * n + k]
                );
            }
        }
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 16, ..ProptestConfig::default() })]

    /// Patch test on distorted Quad4 and mixed Tri3/Quad4 meshes, compressible and
    /// nearly incompressible.
    #[test]
    fn patch_test_quad4(seed in 0u64..10_000, a in proptest::array::uniform4(-1e-3f64..1e-3),
                        nu in prop::sample::select(vec![0.25, 0.4999])) {
        let base = builders::rectangle_quads(0.0, 0.0, 1.0, 1.0, 0.2).unwrap();
        patch(distorted(&base, seed, 0.1), &a, nu)?;
        patch(distorted(&mixed_square(), seed, 0.1), &a, nu)?;
    }

    /// Patch test on distorted Hex8 meshes.
    #[test]
    fn patch_test_hex8(seed in 0u64..10_000, a in proptest::array::uniform9(-1e-3f64..1e-3)) {
        let base = builders::cuboid_hexes([0.0; 3], [1.0, 1.0, 1.0], 0.34).unwrap();
        patch(distorted(&base, seed, 0.1), &a, 0.3)?;
    }
}

/// A rigid turn of quads and hexes, in steps through a full revolution, leaves no stress.
#[test]
fn rigid_turn_is_stress_free() {
    let mut s2 = free_sim(
        builders::ring_quads([0.2, 0.1], 0.5, 2.0, 0.2).unwrap(),
        0.3,
    );
    let x0 = s2.mesh().coords().to_vec();
    for k in 0..=32 {
        let t = 2.0 * std::f64::consts::PI * k as f64 / 32.0;
        let (c, s) = (t.cos(), t.sin());
        for (i, p) in x0.chunks_exact(2).enumerate() {
            s2.state.u[2 * i] = c * p[0] - s * p[1] - p[0];
            s2.state.u[2 * i + 1] = s * p[0] + c * p[1] - p[1];
        }
        let f = max_abs(s2.evaluate_forces().unwrap());
        let st = max_abs(&output::global_stress(&s2).unwrap());
        assert!(
            st < 1e-9 * E && f < 1e-9 * E,
            "2D angle {t}: stress {st}, force {f}"
        );
    }
    let mesh = builders::cuboid_hexes([0.0; 3], [1.0, 0.5, 0.7], 0.25).unwrap();
    let mut s3 = free_sim(distorted(&mesh, 3, 0.05), 0.3);
    let x0 = s3.mesh().coords().to_vec();
    let axis = [1.0f64, 2.0, 2.0].map(|v| v / 3.0);
    for k in 0..=32 {
        let t = 2.0 * std::f64::consts::PI * k as f64 / 32.0;
        let (c, s) = (t.cos(), t.sin());
        for (i, p) in x0.chunks_exact(3).enumerate() {
            let kx = [
                axis[1] * p[2] - axis[2] * p[1],
                axis[2] * p[0] - axis[0] * p[2],
                axis[0] * p[1] - axis[1] * p[0],
            ];
            let kd = axis[0] * p[0] + axis[1] * p[1] + axis[2] * p[2];
            for r in 0..3 {
                let q = p[r] * c + kx[r] * s + axis[r] * kd * (1.0 - c);
                s3.state.u[3 * i + r] = q - p[r];
            }
        }
        let f = max_abs(s3.evaluate_forces().unwrap());
        let st = max_abs(&output::global_stress(&s3).unwrap());
        assert!(
            st < 1e-9 * E && f < 1e-9 * E,
            "3D angle {t}: stress {st}, force {f}"
        );
    }
}

/// Inner-wall displacement of a thick cylinder (plane strain, Lamé) under an inner
/// pressure, from the direct static solve, against the closed form
/// u(a) = (1 + ν) p a² / (E (b² − a²)) ((1 − 2ν) a + b²/a).
fn lame_error(mesh: Mesh<Dim2>, nu: f64) -> (f64, u64) {
    let (a, b, p) = (1.0, 4.0, 1.0e6);
    let mut sim = Simulation::builder(mesh, Backend::cpu(1).unwrap())
        .physics(Mechanics::new().material(Range::All, rock(nu)))
        .physics(
            Boundary::new()
                .face_stress(Range::group("inner"), FaceStress::normal(-p))
                .constraint(
                    Range::plane([0.0; 3], [0.0, 1.0, 0.0], 1e-9),
                    Constraint::Line([1.0, 0.0, 0.0]),
                )
                .constraint(
                    Range::plane([0.0; 3], [1.0, 0.0, 0.0], 1e-9),
                    Constraint::Line([0.0, 1.0, 0.0]),
                ),
        )
        .build()
        .unwrap();
    let rep = sim.solve_linear(&StaticOptions::default()).unwrap();
    let exact = (1.0 + nu) * p * a * a / (E * (b * b - a * a)) * ((1.0 - 2.0 * nu) * a + b * b / a);
    let inner = sim.mesh().select_nodes(&Range::group("inner")).unwrap();
    let mut worst = 0.0f64;
    for &n in &inner {
        let x = sim.mesh().node(n as usize);
        let u = &sim.state.u[2 * n as usize..2 * n as usize + 2];
        let ur = (u[0] * x[0] + u[1] * x[1]) / a;
        worst = worst.max((ur - exact).abs() / exact);
    }
    (worst, rep.steps)
}

/// With ν = 0.4999 the triangles lock (the wall barely moves) while the Quad4 cells of
/// the same polar grid match Lamé's solution; both agree with it at ν = 0.3. The direct
/// solve needs at most three steps, so the B̄ stiffness is the one the explicit forces
/// derive from.
#[test]
fn quads_do_not_lock_where_triangles_do() {
    let size = 0.1;
    let quads = || builders::ring_quads([0.0; 2], 1.0, 4.0, size).unwrap();
    // The same grid cut into triangles (each quad on its shorter diagonal).
    let tris = || {
        let q = quads();
        Mesh::<Dim2>::new(q.coords().to_vec(), q.elements().to_vec())
            .map(|mut m| {
                let inner = q.groups().nodes["inner"].clone();
                let faces: Vec<u32> = m
                    .faces()
                    .boundary
                    .iter()
                    .copied()
                    .filter(|&f| {
                        m.face(f as usize)
                            .iter()
                            .all(|n| inner.binary_search(n).is_ok())
                    })
                    .collect();
                m.add_node_group("inner", inner).unwrap();
                m.add_face_group("inner", faces).unwrap();
                m
            })
            .unwrap()
    };
    let (q3, steps_q3) = lame_error(quads(), 0.3);
    let (t3, _) = lame_error(tris(), 0.3);
    let (q5, steps_q5) = lame_error(quads(), 0.4999);
    let (t5, _) = lame_error(tris(), 0.4999);
    println!("Lamé inner displacement error: ν 0.3 quads {q3:.2e} triangles {t3:.2e}; ν 0.4999 quads {q5:.2e} triangles {t5:.2e}");
    assert!(q3 < 0.02 && t3 < 0.02, "ν = 0.3: {q3} {t3}");
    assert!(q5 < 0.02, "quads at ν = 0.4999: {q5}");
    assert!(t5 > 0.2, "triangles at ν = 0.4999 should lock: {t5}");
    assert!(steps_q3 <= 3 && steps_q5 <= 3, "{steps_q3} {steps_q5}");
}

/// Bad cells are errors naming the cell: inverted, twisted (bow-tie), degenerate, a
/// hexahedron with a twisted face, a cell of the wrong dimension.
#[test]
fn bad_cells_are_refused_by_name() {
    let sq = vec![0.0, 0.0, 1.0, 0.0, 1.0, 1.0, 0.0, 1.0, 2.0, 0.0, 2.0, 1.0];
    let quad =
        |conn: Vec<u32>| Mesh::<Dim2>::from_cells(sq.clone(), vec![ElementKind::Quad4; 2], conn);
    let msg = |r: Result<Mesh<Dim2>, MeshError>| r.err().map(|e| e.to_string()).unwrap_or_default();
    let m = msg(quad(vec![0, 1, 2, 3, 1, 2, 5, 4]));
    assert!(m.contains("cell 1") && m.contains("inverted"), "{m}");
    let m = msg(quad(vec![0, 1, 2, 3, 1, 4, 2, 5]));
    assert!(m.contains("cell 1") && m.contains("twisted"), "{m}");
    assert!(Mesh::<Dim2>::from_cells_reoriented(
        sq.clone(),
        vec![ElementKind::Quad4; 2],
        vec![0, 1, 2, 3, 1, 2, 5, 4]
    )
    .is_ok());
    let flat = vec![0.0, 0.0, 1.0, 0.0, 2.0, 0.0, 3.0, 1e-14];
    let m = msg(Mesh::<Dim2>::from_cells(
        flat,
        vec![ElementKind::Quad4],
        vec![0, 1, 2, 3],
    ));
    assert!(m.contains("cell 0") && m.contains("degenerate"), "{m}");
    let m = msg(Mesh::<Dim2>::from_cells(
        sq.clone(),
        vec![ElementKind::Hex8],
        (0..6).chain(0..2).collect(),
    ));
    assert!(m.contains("3D cell in a 2D mesh"), "{m}");
    // A unit cube whose top face is turned by 100°: the side faces twist through.
    let mut x = Vec::new();
    for (k, t) in [(0.0, 0.0f64), (1.0, 100f64.to_radians())] {
        for (px, py) in [(-0.5, -0.5), (0.5, -0.5), (0.5, 0.5), (-0.5, 0.5)] {
            x.extend([px * t.cos() - py * t.sin(), px * t.sin() + py * t.cos(), k]);
        }
    }
    let m = Mesh::<Dim3>::from_cells(x, vec![ElementKind::Hex8], (0..8).collect())
        .err()
        .map(|e| e.to_string())
        .unwrap_or_default();
    assert!(m.contains("cell 0") && m.contains("twisted"), "{m}");
}

/// A serialised cell mesh reads back equal, and a corrupted cell table is an error.
#[test]
fn cell_meshes_round_trip_through_serde() {
    let m = builders::cuboid_hexes([0.0; 3], [1.0, 1.0, 0.5], 0.5).unwrap();
    let json = serde_json::to_string(&m).unwrap();
    let back: Mesh<Dim3> = serde_json::from_str(&json).unwrap();
    assert_eq!(back.cells(), m.cells());
    assert_eq!(back.elements(), m.elements());
    let bad = json.replacen("\"first_element\":[0,", "\"first_element\":[1,", 1);
    assert!(bad != json);
    let e = serde_json::from_str::<Mesh<Dim3>>(&bad)
        .err()
        .unwrap()
        .to_string();
    assert!(e.contains("first_element"), "{e}");
    // A split cell mesh (cells renumbered, interfaces on cell faces) reads back too.
    let split = pcdc_mesh::split_nodes(&m, &Range::All).unwrap();
    let back: Mesh<Dim3> = serde_json::from_str(&serde_json::to_string(&split).unwrap()).unwrap();
    assert_eq!(back.cells(), split.cells());
    assert_eq!(back.interfaces().len(), split.interfaces().len());
}

/// The FDEM node split keeps each Quad4/Hex8 cell whole: joints on the cell faces only
/// (a hexahedron face is two triangular joints), none on the diagonals inside a cell.
#[test]
fn fdem_split_keeps_cells_whole() {
    let q = builders::rectangle_quads(0.0, 0.0, 1.0, 1.0, 0.25).unwrap();
    let s = pcdc_mesh::split_nodes(&q, &Range::All).unwrap();
    assert_eq!(s.cells().len(), 16);
    assert_eq!(s.n_nodes(), 16 * 4);
    assert_eq!(s.interfaces().len(), 2 * 4 * 3);
    let h = builders::cuboid_hexes([0.0; 3], [1.0; 3], 0.5).unwrap();
    let s = pcdc_mesh::split_nodes(&h, &Range::All).unwrap();
    assert_eq!(s.n_nodes(), 8 * 8);
    assert_eq!(s.interfaces().len(), 2 * 3 * 4);
    // Every joint pairs two different cells.
    for j in s.interfaces().iter() {
        let el = j.elements;
        assert_ne!(s.cell_of(el[0] as usize), s.cell_of(el[1] as usize));
    }
}

/// The nodal forces of mixed cells are the B̄ forces conjugate to the mixed strain: for
/// any virtual displacement δu, f·δu = −Σ_e V_e σ_e : δε'_e with
/// δε'_e = sym ∇δu_e + (θ̄ − θ_e)/d I. The stress differs between the simplices of a
/// cell (set at random, as plastic flow leaves it), so a force taken from each
/// simplex's own pressure would fail this by the pressure difference.
#[test]
fn mixed_forces_are_conjugate_to_the_mixed_strain() {
    fn check<D: Dim>(mesh: Mesh<D>) {
        let d = D::D;
        let mut sim = free_sim(mesh, 0.3);
        // A different stress in every simplex (as plastic flow leaves it).
        let id = sim.state.fields.id("stress").unwrap();
        for (i, v) in sim.state.fields.get_mut(id).iter_mut().enumerate() {
            *v = 1e6 * (((i * 7_654_321) % 1_000) as f64 / 1_000.0 - 0.5);
        }
        let f = sim.evaluate_forces().unwrap().to_vec();
        let stress = sim.field("stress").unwrap().to_vec();
        let mesh = sim.mesh();
        let du: Vec<f64> = (0..mesh.n_nodes() * d)
            .map(|i| ((i * 7919) % 101) as f64 / 101.0 - 0.5)
            .collect();
        let power: f64 = f.iter().zip(&du).map(|(a, b)| a * b).sum();
        // −Σ V σ : δε' with the element gradients from the reference coordinates.
        let npe = D::NODES_PER_ELEM;
        let mut sym = vec![[0.0; 6]; mesh.n_elements()];
        let mut vol = vec![0.0; mesh.n_elements()];
        for e in 0..mesh.n_elements() {
            let mut x = [0.0; 12];
            mesh.element_coords(e, &mut x[..npe * d]);
            vol[e] = mesh.element_measure(e);
            let conn = mesh.element(e);
            // ∇δu = [δu_a − δu_0] D_m⁻¹ via solving D_mᵀ.
            let dm = |i: usize, j: usize| x[(j + 1) * d + i] - x[i];
            let g = if d == 2 {
                let det = dm(0, 0) * dm(1, 1) - dm(0, 1) * dm(1, 0);
                let inv = [
                    dm(1, 1) / det,
                    -dm(0, 1) / det,
                    -dm(1, 0) / det,
                    dm(0, 0) / det,
                ];
                let mut h = [[0.0; 3]; 3];
                for i in 0..2 {
                    let dd = |a: usize| du[conn[a] as usize * 2 + i] - du[conn[0] as usize * 2 + i];
                    for j in 0..2 {
                        h[i][j] = dd(1) * inv[j] + dd(2) * inv[2 + j];
                    }
                }
                h
            } else {
                let m: Vec<f64> = (0..9).map(|k| dm(k / 3, k % 3)).collect();
                // (D_m⁻¹)[a][j] = (D_m⁻ᵀ)[j][a], from the kinematics' own inverse-transpose.
                let m: [f64; 9] = m.try_into().unwrap();
                let it = pcdc_mech::kinematics::inv_transpose3(&m);
                let mm: Vec<f64> = (0..9).map(|k| it[3 * (k % 3) + k / 3]).collect();
                let mut h = [[0.0; 3]; 3];
                for i in 0..3 {
                    let dd = |a: usize| du[conn[a] as usize * 3 + i] - du[conn[0] as usize * 3 + i];
                    for j in 0..3 {
                        h[i][j] = (0..3).map(|a| dd(a + 1) * mm[3 * a + j]).sum();
                    }
                }
                h
            };
            sym[e] = [
                g[0][0],
                g[1][1],
                g[2][2],
                0.5 * (g[0][1] + g[1][0]),
                0.5 * (g[1][2] + g[2][1]),
                0.5 * (g[0][2] + g[2][0]),
            ];
        }
        let mut work = 0.0;
        let mut naive = 0.0;
        for c in 0..mesh.n_cells() {
            let els = mesh.cell_elements(c);
            let tr = |e: usize| sym[e][0] + sym[e][1] + if d == 3 { sym[e][2] } else { 0.0 };
            let total: f64 = els.clone().map(|e| vol[e]).sum();
            let mean: f64 = els.clone().map(|e| vol[e] * tr(e)).sum::<f64>() / total;
            for e in els {
                let s = &stress[e * D::NSYM..(e + 1) * D::NSYM];
                let mut eps = sym[e];
                let corr = (mean - tr(e)) / d as f64;
                for v in eps.iter_mut().take(d) {
                    *v += corr;
                }
                let (sd, nd) = if d == 2 {
                    (
                        s[0] * eps[0] + s[1] * eps[1] + 2.0 * s[2] * eps[3],
                        s[0] * sym[e][0] + s[1] * sym[e][1] + 2.0 * s[2] * sym[e][3],
                    )
                } else {
                    let dot = |v: &[f64; 6]| {
                        s[0] * v[0]
                            + s[1] * v[1]
                            + s[2] * v[2]
                            + 2.0 * (s[3] * v[3] + s[4] * v[4] + s[5] * v[5])
                    };
                    (dot(&eps), dot(&sym[e]))
                };
                work -= vol[e] * sd;
                naive -= vol[e] * nd;
            }
        }
        let scale = power.abs().max(work.abs());
        println!(
            "{}: f·δu {power:.6e}, −Σ V σ:δε' {work:.6e}, with the own pressures {naive:.6e}",
            D::NAME
        );
        assert!((power - work).abs() < 1e-9 * scale, "{power} vs {work}");
        assert!(
            (naive - work).abs() > 1e-6 * scale,
            "the test must see the pressure difference"
        );
    }
    check(distorted(
        &builders::rectangle_quads(0.0, 0.0, 1.0, 1.0, 0.2).unwrap(),
        5,
        0.1,
    ));
    check(distorted(
        &builders::cuboid_hexes([0.0; 3], [1.0; 3], 0.34).unwrap(),
        5,
        0.1,
    ));
}

/// Tet4 and Hex8 cells in one mesh: every other hexahedron of a block listed as the
/// Tet4 cells it is cut into conforms with the Hex8 cells around it, and the patch test
/// holds on the distorted mixed mesh.
#[test]
fn tet4_and_hex8_in_one_mesh_pass_the_patch_test() {
    let hexes = builders::cuboid_hexes([0.0; 3], [1.0; 3], 0.34).unwrap();
    let (mut kinds, mut conn) = (Vec::new(), Vec::new());
    for c in 0..hexes.n_cells() {
        if c % 2 == 0 {
            kinds.push(ElementKind::Hex8);
            conn.extend_from_slice(hexes.cell_nodes(c));
        } else {
            for e in hexes.cell_elements(c) {
                kinds.push(ElementKind::Tet4);
                conn.extend_from_slice(hexes.element(e));
            }
        }
    }
    let mixed = Mesh::<Dim3>::from_cells(hexes.coords().to_vec(), kinds, conn).unwrap();
    assert_eq!(mixed.n_elements(), hexes.n_elements());
    assert_eq!(mixed.faces().boundary.len(), hexes.faces().boundary.len());
    let a = [3e-4, -1e-4, 2e-4, 5e-5, -2e-4, 1e-4, -3e-5, 2e-4, -1e-4];
    patch(distorted(&mixed, 11, 0.1), &a, 0.3).unwrap();
}
