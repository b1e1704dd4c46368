//! Geostatic initial stress (manual 7.2.8): a layer on rollers under gravity with
//! σv = −ρ g depth and σh = K0 σv starts in equilibrium, so a static relaxation moves it
//! by nothing measurable and keeps the stresses.

use pcdc_compute::{Backend, Simulation, StaticOptions};
use pcdc_mech::{output, Boundary, InitialStress, LinearElastic, Mechanics};
use pcdc_mesh::{builders, Range};

#[test]
fn geostatic_stress_is_in_equilibrium_under_gravity() {
    let (rho, g, h) = (2000.0, 9.81, 10.0);
    let mesh = builders::rectangle(0.0, 0.0, 20.0, h, 1.0).unwrap();
    for k0 in [0.3, 0.5, 1.2] {
        let rock = LinearElastic::new(1e9, 0.3, rho).unwrap();
        let field = InitialStress::Geostatic {
            surface: h,
            density: rho,
            gravity: g,
            k0,
        };
        let mut sim = Simulation::builder(mesh.clone(), Backend::cpu(1).unwrap())
            .gravity([0.0, -g, 0.0])
            .physics(
                Mechanics::new()
                    .material(Range::All, rock)
                    .initial_stress_field(Range::All, field),
            )
            .physics(
                Boundary::new()
                    .velocity(Range::group("left"), [Some(0.0.into()), None, None])
                    .velocity(Range::group("right"), [Some(0.0.into()), None, None])
                    .velocity(Range::group("bottom"), [None, Some(0.0.into()), None]),
            )
            .build()
            .unwrap();
        let before = output::global_stress(&sim).unwrap();
        sim.relax(&StaticOptions::default()).unwrap();
        let after = output::global_stress(&sim).unwrap();
        let u = sim.state.u.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        // Settlement of the self-weight without initial stress: ρ g h² / (2 M) ≈ 1e-3 m.
        assert!(u < 1e-9, "K0 {k0}: moved {u} m");
        let sv_max = rho * g * h;
        let mut c = [0.0; 2];
        for e in 0..sim.mesh().n_elements() {
            sim.mesh().element_centroid(e, &mut c);
            let sv = -rho * g * (h - c[1]);
            assert!(
                (after[3 * e + 1] - sv).abs() <= 1e-6 * sv_max,
                "σv at {c:?}"
            );
            assert!(
                (after[3 * e] - k0 * sv).abs() <= 1e-6 * sv_max,
                "σh at {c:?}"
            );
            assert!((after[3 * e] - before[3 * e]).abs() <= 1e-6 * sv_max);
        }
        let zz = sim.field("stress_zz").unwrap();
        sim.mesh().element_centroid(0, &mut c);
        assert!((zz[0] + k0 * rho * g * (h - c[1])).abs() <= 1e-6 * sv_max);
    }
}

#[test]
fn bad_initial_stress_is_a_build_error() {
    let mesh = builders::rectangle(0.0, 0.0, 1.0, 1.0, 0.5).unwrap();
    let rock = LinearElastic::new(1e9, 0.3, 2000.0).unwrap();
    let err = Simulation::builder(mesh, Backend::cpu(1).unwrap())
        .physics(
            Mechanics::new()
                .material(Range::All, rock)
                .initial_stress_field(
                    Range::All,
                    InitialStress::Geostatic {
                        surface: 1.0,
                        density: 2000.0,
                        gravity: 0.0,
                        k0: 0.5,
                    },
                ),
        )
        .build()
        .err()
        .expect("refused")
        .to_string();
    assert!(err.contains("gravity"), "{err}");
}
