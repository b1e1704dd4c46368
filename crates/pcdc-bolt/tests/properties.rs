//! Property tests of the bolt laws and of the coupling: the axial force stays within
//! the yield limits and the grout force within the bond strength for any history;
//! elastic states are left alone; action equals reaction between bolt and host for any
//! placement; a rigid motion of rock and bolt together gives no force.

use pcdc_bolt::{grout_force, AxialLaw, Bolt, BoltMaterial, BoltProperties, Bolts, SegmentState};
use pcdc_compute::{Backend, Simulation};
use pcdc_mech::{LinearElastic, Mechanics};
use pcdc_mesh::{builders, Range};
use proptest::prelude::*;

fn law(ft: f64, fc: f64) -> AxialLaw {
    AxialLaw {
        ea: 1e8,
        tensile: ft,
        compressive: fc,
        failure_strain: 0.05,
    }
}

proptest! {
    #[test]
    fn axial_force_stays_within_the_yield_limits(
        ft in 1e3..1e6f64,
        fc in 1e3..1e6f64,
        steps in prop::collection::vec(-1e-3..1e-3f64, 1..60),
    ) {
        let (l, l0) = (law(ft, fc), 0.5);
        let (mut elong, mut plastic, mut broken) = (0.0, 0.0, false);
        for du in steps {
            elong += du;
            let (f, p, st) = l.update(elong, l0, plastic, broken);
            prop_assert!(f <= ft * (1.0 + 1e-12) && f >= -fc * (1.0 + 1e-12), "{f}");
            // On the limit exactly when yielding; elastic: the force of the elastic strain.
            match st {
                SegmentState::YieldTension => prop_assert_eq!(f, ft),
                SegmentState::YieldCompression => prop_assert_eq!(f, -fc),
                SegmentState::Elastic => {
                    prop_assert_eq!(p, plastic);
                    prop_assert!((f - l.ea / l0 * (elong - p)).abs() <= 1e-9 * ft);
                }
                SegmentState::Broken => {
                    prop_assert_eq!(f, 0.0);
                    prop_assert!(broken || elong / l0 >= 0.05);
                }
            }
            // Broken is for good.
            if broken {
                prop_assert_eq!(st, SegmentState::Broken);
            }
            broken = st == SegmentState::Broken;
            plastic = p;
        }
    }

    #[test]
    fn grout_force_stays_within_the_bond_strength(
        cap in 1.0..1e5f64,
        k in 1e5..1e9f64,
        steps in prop::collection::vec(-1e-3..1e-3f64, 1..60),
    ) {
        let (mut delta, mut slip) = (0.0, 0.0);
        for dd in steps {
            delta += dd;
            let (f, s) = grout_force(delta, slip, k, cap);
            prop_assert!(f.abs() <= cap * (1.0 + 1e-12), "{f} > {cap}");
            if f.abs() < cap {
                // Below the bond: no new slip, elastic force.
                prop_assert_eq!(s, slip);
                prop_assert!((f - k * (delta - s)).abs() <= 1e-9 * cap);
            }
            slip = s;
        }
    }
}

fn block_with_bolt(head: [f64; 3], tail: [f64; 3]) -> Simulation<pcdc_mesh::Dim2> {
    let mesh = builders::rectangle(0.0, 0.0, 1.0, 0.5, 0.1).unwrap();
    let props = BoltProperties {
        cohesion_rock_grout: 1e4,
        tensile_yield_force: 1e4,
        ..BoltProperties::steel_rebar(0.02)
    };
    let bolt = Bolt::straight("B", head, tail, 5, BoltMaterial::new(props).unwrap()).unwrap();
    let bolts = Bolts::new().bolt(bolt).unwrap();
    Simulation::builder(mesh, Backend::cpu(1).unwrap())
        .physics(
            Mechanics::new().material(Range::All, LinearElastic::new(1e9, 0.2, 2000.0).unwrap()),
        )
        .physics(bolts)
        .build()
        .unwrap()
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]

    #[test]
    fn action_equals_reaction_for_any_placement(
        hx in 0.0..1.0f64, hy in 0.0..0.5f64, tx in 0.0..1.0f64, ty in 0.0..0.5f64,
        seed in prop::collection::vec(-1e-3..1e-3f64, 8),
    ) {
        prop_assume!(((hx - tx).powi(2) + (hy - ty).powi(2)).sqrt() > 0.1);
        let mut sim = block_with_bolt([hx, hy, 0.0], [tx, ty, 0.0]);
        // Any deformed state: displace every node (mesh and bolt) pseudo-randomly.
        for (i, u) in sim.state.u.iter_mut().enumerate() {
            *u = seed[i % seed.len()] * ((i * 7919) % 13) as f64 / 13.0;
        }
        let f = sim.evaluate_forces().unwrap().to_vec();
        let (fx, fy) = f.chunks(2).fold((0.0, 0.0), |(a, b), c| (a + c[0], b + c[1]));
        let scale = f.iter().map(|v| v.abs()).fold(0.0, f64::max);
        prop_assert!(scale > 0.0);
        prop_assert!(fx.abs() <= 1e-9 * scale && fy.abs() <= 1e-9 * scale, "{fx} {fy} of {scale}");
    }

    #[test]
    fn a_rigid_motion_of_rock_and_bolt_gives_no_force(
        angle in -3.2..3.2f64, cx in -1.0..1.0f64, cy in -1.0..1.0f64,
    ) {
        let mut sim = block_with_bolt([0.05, 0.21, 0.0], [0.93, 0.34, 0.0]);
        let x0 = sim.reference_coords().to_vec();
        let (c, s) = (angle.cos(), angle.sin());
        for (p, u) in x0.chunks(2).zip(sim.state.u.chunks_mut(2)) {
            u[0] = c * p[0] - s * p[1] + cx - p[0];
            u[1] = s * p[0] + c * p[1] + cy - p[1];
        }
        let f = sim.evaluate_forces().unwrap().to_vec();
        let axial = sim.field(pcdc_bolt::BOLT_AXIAL_FORCE).unwrap();
        let grout = sim.field(pcdc_bolt::BOLT_GROUT_FORCE).unwrap();
        // Forces of a 1 mm stretch would be 1e4 N: rounding of a rotation is far below.
        for v in f.iter().chain(axial).chain(grout) {
            prop_assert!(v.abs() < 1e-3, "{v}");
        }
    }
}
