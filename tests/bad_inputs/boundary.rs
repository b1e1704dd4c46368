//! Mechanical boundary conditions, checked when the simulation is built.

use pcdc_compute::{Backend, Simulation};
use pcdc_mech::{set_velocity, Boundary, Constraint, FaceStress, LinearElastic, Mechanics};
use pcdc_mesh::{builders, Dim2, Range};

use crate::{case, run};

/// A 2D elastic square with `bc`.
fn sim(bc: Boundary) -> Result<Simulation<Dim2>, pcdc_compute::ComputeError> {
    let mesh = builders::rectangle(0.0, 0.0, 1.0, 1.0, 0.5).unwrap();
    let rock = LinearElastic::new(30e9, 0.25, 2600.0).unwrap();
    Simulation::builder(mesh, Backend::cpu(1)?)
        .physics(Mechanics::new().material(Range::All, rock))
        .physics(bc)
        .build()
}

/// Builds the square with `bc`; `Ok(())` when the simulation builds.
fn build(bc: Boundary) -> Result<(), pcdc_compute::ComputeError> {
    sim(bc).map(|_| ())
}

/// Sets an initial velocity on the square's top nodes.
fn initial_velocity(v: [f64; 3]) -> Result<usize, pcdc_mech::MechError> {
    set_velocity(&mut sim(Boundary::new()).unwrap(), &top(), v)
}

fn b() -> Boundary {
    Boundary::new()
}

fn top() -> Range {
    Range::group("top")
}

#[test]
fn bad_boundary_conditions_are_named_errors() {
    run(
        "boundary conditions",
        vec![
            case("velocity z in 2D", "velocity component 2 (z)", || {
                build(b().velocity(top(), [None, Some(0.0.into()), Some(1.0.into())]))
            }),
            case(
                "acceleration z in 2D",
                "acceleration component 2 (z)",
                || build(b().acceleration(top(), [None, None, Some(1.0.into())])),
            ),
            case("node force z in 2D", "node force component 2 (z)", || {
                build(b().node_force(top(), [Some(1.0.into()), None, Some(1.0.into())]))
            }),
            case("face stress zz in 2D", "face stress zz", || {
                build(b().face_stress(top(), FaceStress::diagonal(0.0, -1e6, -1e6)))
            }),
            case("face stress yz in 2D", "face stress yz", || {
                build(b().face_stress(
                    top(),
                    FaceStress {
                        yz: Some(1e6.into()),
                        ..Default::default()
                    },
                ))
            }),
            case("NaN face shear", "face stress xy = NaN", || {
                build(b().face_stress(top(), FaceStress::shear_xy(f64::NAN)))
            }),
            case("NaN velocity", "velocity component 1 = NaN", || {
                build(b().velocity(top(), [None, Some(f64::NAN.into()), None]))
            }),
            case(
                "infinite node force",
                "node force component 0 = inf",
                || build(b().node_force(top(), [Some(f64::INFINITY.into()), None, None])),
            ),
            case("NaN face pressure", "face stress normal = NaN", || {
                build(b().face_stress(top(), FaceStress::normal(f64::NAN)))
            }),
            case("zero constraint direction", "constraint direction", || {
                build(b().constraint(top(), Constraint::Line([0.0; 3])))
            }),
            case(
                "z-only constraint in 2D",
                "non-zero in its first 2 components",
                || build(b().constraint(top(), Constraint::Line([0.0, 0.0, 1.0]))),
            ),
            case("NaN constraint normal", "constraint direction", || {
                build(b().constraint(top(), Constraint::Plane([f64::NAN, 1.0, 0.0])))
            }),
            case("range selecting no node", "selects no node", || {
                build(b().fix(Range::Ball {
                    center: [9.0, 9.0, 0.0],
                    radius: 0.1,
                }))
            }),
            case(
                "range selecting no face",
                "selects no boundary face",
                || {
                    build(
                        b().face_stress(Range::rect(0.4, 0.4, 0.6, 0.6), FaceStress::normal(-1.0)),
                    )
                },
            ),
            case("ill-formed range", "ball radius NaN", || {
                build(b().fix(Range::Ball {
                    center: [0.0; 3],
                    radius: f64::NAN,
                }))
            }),
            case(
                "initial velocity z in 2D",
                "velocity z component = 1",
                || initial_velocity([0.0, 0.0, 1.0]),
            ),
            case("NaN initial velocity", "must be finite", || {
                initial_velocity([f64::NAN, 0.0, 0.0])
            }),
            case("unknown group", "no node group named 'lid'", || {
                build(b().fix(Range::group("lid")))
            }),
        ],
    );
}
