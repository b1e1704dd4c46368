//! The standard FDEM benchmark scenes (`docs/design-targets.md`), shared by the
//! `fdem_step` bench and the `step_profile` example so that both measure the same step.
//!
//! - 2D ([`fdem_block_2d`]): a 0.05 × 0.10 m block of right triangles, every triangle
//!   with its own nodes, an intrinsic cohesive joint on every interior edge (3 Gauss
//!   points), optional contact; bottom held in y, top pushed down at 0.05 m/s.
//! - 3D ([`fdem_cuboid_3d`]): a 0.05 × 0.05 × 0.10 m cuboid of tetrahedra (six per
//!   cube), every tetrahedron with its own nodes, a joint on every interior face (3 Gauss
//!   points), optional contact; bottom (z = 0) held in z, top pushed down at 0.05 m/s.
//!
//! Rock: E = 30 GPa, ν = 0.25, ρ = 2600 kg/m³. Joints ([`IntrinsicCzmParams`]): φ = 30°,
//! c = 10 MPa, T_s = 2 MPa, G_I = 0.5 N/m, G_II = 5 N/m, P_open = P_tan = 10 E,
//! P_overlap = 100 E. Contact: penalty 10 E, friction 30° with shear penalty 10 E,
//! bonded neighbours excluded until their joint breaks. Time step 0.05 h / c_p (h the
//! cell size), far below the joints' stable step, as in the reference runs.

use pcdc_cohesive::{CohesiveJoints, IntrinsicCzmParams, BROKEN_FACE};
use pcdc_compute::{Backend, ComputeError, Simulation};
use pcdc_contact::Contact;
use pcdc_mech::{Boundary, LinearElastic, Mechanics};
use pcdc_mesh::{builders, split_nodes, Dim, Dim2, Dim3, Mesh, Range};

use crate::report::SceneError;

/// Young's modulus of the benchmark rock (Pa).
pub const E: f64 = 30e9;

/// Builds the scene on `mesh` (already split) with the velocity conditions given.
fn build<D: Dim>(
    mesh: Mesh<D>,
    h: f64,
    backend: Backend,
    contact: bool,
    boundary: Boundary,
) -> Result<Simulation<D>, SceneError> {
    let czm = IntrinsicCzmParams {
        friction_deg: 30.0,
        cohesion: 10e6,
        tensile_strength: 2e6,
        gf1: 0.5,
        gf2: 5.0,
        penalty_open: 10.0 * E,
        penalty_shear: 10.0 * E,
        penalty_overlap: 100.0 * E,
    }
    .build()?;
    let rock = LinearElastic::new(E, 0.25, 2600.0)?;
    let c_p = ((rock.lambda() + 2.0 * rock.shear()) / 2600.0).sqrt();
    let mut b = Simulation::builder(mesh, backend)
        .physics(Mechanics::new().material(Range::All, rock))
        .physics(CohesiveJoints::new().model(Range::All, czm));
    if contact {
        b = b.physics(
            Contact::new(10.0 * E)
                .friction(30.0, 10.0 * E)
                .bonded_interfaces(BROKEN_FACE),
        );
    }
    Ok(b.physics(boundary).time_step(0.05 * h / c_p).build()?)
}

/// A scene needs at least one cell across.
fn at_least_one_cell(cells: usize) -> Result<(), SceneError> {
    if cells == 0 {
        return Err(ComputeError::param("cells across", cells, "must be at least 1").into());
    }
    Ok(())
}

/// The 2D benchmark block with `cells_x` cells across (2 `cells_x`² cells of two
/// triangles: 50 → 10 000 triangles, 112 → 50 176, 224 → 200 704).
pub fn fdem_block_2d(
    cells_x: usize,
    backend: Backend,
    contact: bool,
) -> Result<Simulation<Dim2>, SceneError> {
    at_least_one_cell(cells_x)?;
    let h = 0.05 / cells_x as f64;
    let mesh = builders::rectangle(0.0, 0.0, 0.05, 0.10, h)?;
    let split = split_nodes(&mesh, &Range::All)?;
    let boundary = Boundary::new()
        .velocity(Range::group("bottom"), [None, Some(0.0.into()), None])
        .velocity(Range::group("top"), [None, Some((-0.05).into()), None]);
    build(split, h, backend, contact, boundary)
}

/// The 3D benchmark cuboid with `cells` cubes across (`cells` × `cells` × 2 `cells`
/// cubes of six tetrahedra: 10 → 12 000 tetrahedra, 16 → 49 152).
pub fn fdem_cuboid_3d(
    cells: usize,
    backend: Backend,
    contact: bool,
) -> Result<Simulation<Dim3>, SceneError> {
    at_least_one_cell(cells)?;
    let h = 0.05 / cells as f64;
    let mesh = builders::cuboid([0.0; 3], [0.05, 0.05, 0.10], h)?;
    let split = split_nodes(&mesh, &Range::All)?;
    let boundary = Boundary::new()
        .velocity(Range::group("zmin"), [None, None, Some(0.0.into())])
        .velocity(Range::group("zmax"), [None, None, Some((-0.05).into())]);
    build(split, h, backend, contact, boundary)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Both scenes build, step and load the sample (the top moves down, the state stays
    /// finite) on the CPU, with and without contact.
    #[test]
    fn benchmark_scenes_step() {
        for contact in [false, true] {
            let mut s2 = fdem_block_2d(6, Backend::cpu(1).unwrap(), contact).unwrap();
            assert_eq!(s2.mesh().n_elements(), 2 * 6 * 12);
            s2.run(20).unwrap();
            assert!(s2.kinematics().u.iter().all(|x| x.is_finite()));
            assert!(s2.kinematics().u.iter().any(|&x| x < 0.0));
            let mut s3 = fdem_cuboid_3d(2, Backend::cpu(1).unwrap(), contact).unwrap();
            assert_eq!(s3.mesh().n_elements(), 6 * 2 * 2 * 4);
            s3.run(20).unwrap();
            assert!(s3.kinematics().u.iter().any(|&x| x < 0.0));
        }
    }

    /// Zero cells across is a named parameter error, not a mesh-size message.
    #[test]
    fn zero_cells_is_named() {
        for e in [
            fdem_block_2d(0, Backend::cpu(1).unwrap(), false).err(),
            fdem_cuboid_3d(0, Backend::cpu(1).unwrap(), true).err(),
        ] {
            let msg = e.expect("zero cells must fail").to_string();
            assert!(msg.contains("cells across"), "{msg}");
        }
    }
}
