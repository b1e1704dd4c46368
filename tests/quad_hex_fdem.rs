//! Quad4 and Hex8 cells in FDEM regions: the split keeps each cell whole and puts
//! cohesive joints on the cell faces only, and a jointed block of quads or hexes under
//! a uniaxial face stress compresses like the continuum plus the joints' own compliance
//! (about σ h / p per joint layer, p the normal penalty).

use pcdc::compute::{Backend, Simulation, StaticOptions};
use pcdc_cohesive::{CohesiveJoints, IntrinsicCzmParams};
use pcdc_mech::{output, Boundary, Constraint, FaceStress, LinearElastic, Mechanics};
use pcdc_mesh::{builders, split_nodes, Dim, Mesh, Range};

const E: f64 = 10e9;
const NU: f64 = 0.25;
const SIGMA: f64 = -1e6;
/// Damped steps of the jointed blocks.
const STEPS: u64 = 20_000;

/// Mean top displacement of the block under σ on `top`, rollers on `bottom` and the
/// `sides` (uniaxial strain), relaxed; with joints when `fdem`.
fn top_displacement<D: Dim>(
    mesh: Mesh<D>,
    fdem: bool,
    bottom: &str,
    top: &str,
    sides: &[&str],
) -> f64 {
    let mesh = if fdem {
        split_nodes(&mesh, &Range::All).unwrap()
    } else {
        mesh
    };
    let rock = LinearElastic::new(E, NU, 2500.0)
        .unwrap()
        .with_damping(0.5)
        .unwrap();
    let up = if D::D == 2 {
        [0.0, 1.0, 0.0]
    } else {
        [0.0, 0.0, 1.0]
    };
    let mut bc = Boundary::new()
        .constraint(Range::group(bottom), Constraint::Fixed)
        .face_stress(
            Range::group(top),
            FaceStress {
                normal: Some(SIGMA.into()),
                ..Default::default()
            },
        );
    for s in sides {
        // Rollers: the side nodes move only vertically.
        bc = bc.constraint(Range::group(*s), Constraint::Line(up));
    }
    let mut b = Simulation::builder(mesh, Backend::cpu(1).unwrap())
        .physics(Mechanics::new().material(Range::All, rock))
        .physics(bc);
    if fdem {
        let czm = IntrinsicCzmParams {
            friction_deg: 30.0,
            cohesion: 1e9,
            tensile_strength: 1e9,
            gf1: 1e6,
            gf2: 1e6,
            penalty_open: 100.0 * E,
            penalty_shear: 100.0 * E,
            penalty_overlap: 100.0 * E,
        }
        .build()
        .unwrap();
        b = b.physics(CohesiveJoints::new().model(Range::All, czm));
    }
    let mut sim = b.build().unwrap();
    if fdem {
        // Dynamic relaxation scales the masses to the elements only; with joints the
        // block is brought to rest by its viscous damping instead.
        sim.run(STEPS).unwrap();
    } else {
        sim.relax(&StaticOptions {
            tolerance: 1e-8,
            max_steps: 400_000,
            check_every: 50,
        })
        .unwrap();
    }
    let u = output::displacement(&sim).unwrap();
    let nodes = sim.mesh().select_nodes(&Range::group(top)).unwrap();
    let k = D::D - 1;
    nodes.iter().map(|&n| u[n as usize * D::D + k]).sum::<f64>() / nodes.len() as f64
}

#[test]
fn jointed_quads_and_hexes_compress_like_the_continuum() {
    // Uniaxial strain: ε = σ / M, M = E (1 − ν) / ((1 + ν)(1 − 2ν)), over height 1 m.
    let m = E * (1.0 - NU) / ((1.0 + NU) * (1.0 - 2.0 * NU));
    let exact = SIGMA / m;
    let q = || builders::rectangle_quads(0.0, 0.0, 0.5, 1.0, 0.125).unwrap();
    let (c2, j2) = (
        top_displacement(q(), false, "bottom", "top", &["left", "right"]),
        top_displacement(q(), true, "bottom", "top", &["left", "right"]),
    );
    let h = || builders::cuboid_hexes([0.0; 3], [0.5, 0.5, 1.0], 0.25).unwrap();
    let sides = ["xmin", "xmax", "ymin", "ymax"];
    let (c3, j3) = (
        top_displacement(h(), false, "zmin", "zmax", &sides),
        top_displacement(h(), true, "zmin", "zmax", &sides),
    );
    println!(
        "exact {exact:.5e}; quads {c2:.5e}, jointed {j2:.5e}; hexes {c3:.5e}, jointed {j3:.5e}"
    );
    for (name, u) in [("quads", c2), ("hexes", c3)] {
        assert!(
            (u - exact).abs() < 1e-6 * exact.abs(),
            "{name}: {u} vs {exact}"
        );
    }
    // The joints (normal penalty 100 E, stress = p δ / h with h the mean edge of the two
    // simplices) add about σ h/(100 E) per joint layer: 0.9 % (quads, 7 layers of
    // h ≈ 1.14 × 0.125 m) and 0.9 % (hexes, 3 layers), a little more through the lateral
    // joints and Poisson; a joint on a cell's diagonal would add a layer per cell row.
    for (name, u) in [("jointed quads", j2), ("jointed hexes", j3)] {
        let extra = (u - exact) / exact;
        assert!(
            extra > 0.005 && extra < 0.02,
            "{name}: {u} vs {exact} ({extra:.4})"
        );
    }
}
