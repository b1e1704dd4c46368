//! Bad input is an error that names what is wrong (and the bolt), never a panic:
//! properties out of range (constructor, struct literal, serde), degenerate geometry, a
//! bolt outside the mesh, boundary conditions on bolts that do not exist.

use pcdc_bolt::{Bolt, BoltError, BoltMaterial, BoltNodes, BoltProperties, Bolts};
use pcdc_compute::{Backend, Simulation};
use pcdc_mech::{LinearElastic, Mechanics};
use pcdc_mesh::{builders, Dim2, Range};

fn good() -> BoltProperties {
    BoltProperties::steel_rebar(0.025)
}

#[test]
fn properties_out_of_range_are_named() {
    type Edit = fn(&mut BoltProperties);
    let cases: [(&str, Edit); 12] = [
        ("diameter", |p| p.diameter = 0.0),
        ("young", |p| p.young = -1.0),
        ("density", |p| p.density = f64::NAN),
        ("shear_stiffness", |p| p.shear_stiffness = 0.0),
        ("normal_stiffness", |p| p.normal_stiffness = Some(-5.0)),
        ("tensile_yield_force", |p| p.tensile_yield_force = -1e5),
        ("compressive_yield_force", |p| {
            p.compressive_yield_force = -1e5
        }),
        ("tension_failure_strain", |p| p.tension_failure_strain = 0.0),
        ("friction_rock_grout", |p| p.friction_rock_grout = 90.0),
        ("cohesion_grout_bolt", |p| p.cohesion_grout_bolt = -1.0),
        ("spacing", |p| p.spacing = Some(0.0)),
        ("pretension", |p| p.pretension = 1e9),
    ];
    for (name, edit) in cases {
        let mut p = good();
        edit(&mut p);
        let e = BoltMaterial::new(p).expect_err(name).to_string();
        assert!(e.contains(name), "{name}: {e}");
    }
    // Through serde: the same checks.
    let mut json = serde_json::to_value(BoltMaterial::new(good()).unwrap()).unwrap();
    json["diameter"] = serde_json::json!(-0.02);
    let e = serde_json::from_value::<BoltMaterial>(json)
        .unwrap_err()
        .to_string();
    assert!(e.contains("diameter"), "{e}");
}

#[test]
fn degenerate_geometry_names_the_bolt() {
    let m = BoltMaterial::new(good()).unwrap();
    let e = Bolt::straight("anchor-7", [1.0, 2.0, 0.0], [1.0, 2.0, 0.0], 4, m)
        .unwrap_err()
        .to_string();
    assert!(e.contains("anchor-7") && e.contains("coincide"), "{e}");
    let e = Bolt::straight("B", [0.0; 3], [1.0, 0.0, 0.0], 0, m).unwrap_err();
    assert!(matches!(e, BoltError::Geometry { .. }), "{e}");
    let e = Bolt::straight("B", [0.0; 3], [f64::INFINITY, 0.0, 0.0], 3, m).unwrap_err();
    assert!(e.to_string().contains("not finite"), "{e}");
    let bolt = Bolt::straight("B", [0.0; 3], [1.0, 0.0, 0.0], 3, m).unwrap();
    assert!(bolt.clone().free_length(1.0).is_err());
    assert!(bolt.clone().face_plate(0.0).is_err());
    assert!(Bolts::new()
        .bolt(bolt.clone())
        .unwrap()
        .bolt(bolt)
        .err()
        .expect("a second bolt B")
        .to_string()
        .contains("another bolt"));
}

fn build(bolts: Bolts, extra: Option<pcdc_bolt::BoltBoundary>) -> Result<Simulation<Dim2>, String> {
    let mesh = builders::rectangle(0.0, 0.0, 1.0, 1.0, 0.25).unwrap();
    let mut b = Simulation::builder(mesh, Backend::cpu(1).unwrap())
        .physics(
            Mechanics::new().material(Range::All, LinearElastic::new(1e9, 0.2, 2000.0).unwrap()),
        )
        .physics(bolts);
    if let Some(x) = extra {
        b = b.physics(x);
    }
    b.build().map_err(|e| e.to_string())
}

#[test]
fn a_bolt_outside_the_mesh_is_refused() {
    let m = BoltMaterial::new(good()).unwrap();
    let bolt = Bolt::straight("long one", [0.5, 0.5, 0.0], [1.5, 0.5, 0.0], 4, m).unwrap();
    let e = build(Bolts::new().bolt(bolt).unwrap(), None)
        .err()
        .expect("outside");
    assert!(
        e.contains("long one") && e.contains("outside the mesh"),
        "{e}"
    );
    // No bolts at all.
    let e = build(Bolts::new(), None).err().expect("no bolts");
    assert!(e.contains("at least one bolt"), "{e}");
}

#[test]
fn conditions_on_missing_bolts_or_nodes_are_refused() {
    let m = BoltMaterial::new(good()).unwrap();
    let bolts = Bolts::new()
        .bolt(Bolt::straight("B", [0.1, 0.5, 0.0], [0.9, 0.5, 0.0], 4, m).unwrap())
        .unwrap();
    let e = bolts
        .boundary()
        .force("C", BoltNodes::Head, [Some(1.0.into()), None, None])
        .err()
        .expect("no bolt C")
        .to_string();
    assert!(e.contains("'C'"), "{e}");
    let e = bolts
        .boundary()
        .velocity("B", BoltNodes::Node(5), [Some(1.0.into()), None, None])
        .err()
        .expect("node 5 of 5")
        .to_string();
    assert!(e.contains("node 5"), "{e}");
    let e = bolts
        .boundary()
        .force("B", BoltNodes::Tail, [Some(f64::NAN.into()), None, None])
        .err()
        .expect("NaN force");
    assert!(e.to_string().contains("finite"), "{e}");
    // Spacing is a 2D notion.
    let spaced = BoltMaterial::new(BoltProperties {
        spacing: Some(1.5),
        ..good()
    })
    .unwrap();
    let mesh = builders::cuboid([0.0; 3], [1.0, 1.0, 1.0], 0.5).unwrap();
    let e = Simulation::builder(mesh, Backend::cpu(1).unwrap())
        .physics(
            Mechanics::new().material(Range::All, LinearElastic::new(1e9, 0.2, 2000.0).unwrap()),
        )
        .physics(
            Bolts::new()
                .bolt(Bolt::straight("S", [0.2; 3], [0.8; 3], 2, spaced).unwrap())
                .unwrap(),
        )
        .build()
        .err()
        .expect("spacing in 3D")
        .to_string();
    assert!(e.contains("spacing") && e.contains("'S'"), "{e}");
}
