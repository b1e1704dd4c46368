//! Bolts from a 2D line group, and their output: the VTU line cells ParaView opens and
//! the CSV history of the axial force along a bolt.

use pcdc_bolt::output::{AxialForceCsv, BoltSeries};
use pcdc_bolt::{Bolt, BoltMaterial, BoltNodes, BoltProperties, Bolts};
use pcdc_compute::{Backend, Simulation};
use pcdc_mech::{Boundary, LinearElastic, Mechanics};
use pcdc_mesh::{builders, Range};

#[test]
fn a_bolt_along_a_line_group_follows_its_lines_from_the_head() {
    let mesh = builders::rectangle(0.0, 0.0, 1.0, 0.5, 0.25).unwrap();
    let m = BoltMaterial::new(BoltProperties::steel_rebar(0.02)).unwrap();
    // The bottom edge: four lines, head at the right end.
    let bolt = Bolt::from_face_group("edge", &mesh, "bottom", [1.1, 0.0, 0.0], m).unwrap();
    assert_eq!(bolt.segments(), 4);
    assert_eq!(bolt.points()[0], [1.0, 0.0, 0.0]);
    assert_eq!(bolt.points()[4], [0.0, 0.0, 0.0]);
    assert!((bolt.length() - 1.0).abs() < 1e-12);
    // Not a chain: the whole boundary is a loop; a missing group is named.
    let mut looped = mesh.clone();
    let all = mesh.select_boundary_faces(&Range::All).unwrap();
    looped.add_face_group("loop", all).unwrap();
    let e = Bolt::from_face_group("L", &looped, "loop", [0.0; 3], m).unwrap_err();
    assert!(e.to_string().contains("open chain"), "{e}");
    let e = Bolt::from_face_group("L", &mesh, "nowhere", [0.0; 3], m).unwrap_err();
    assert!(e.to_string().contains("nowhere"), "{e}");
}

#[test]
fn bolts_are_written_as_vtu_lines_and_csv_histories() {
    let mesh = builders::rectangle(0.0, -0.1, 1.0, 0.2, 0.05).unwrap();
    let m = BoltMaterial::new(BoltProperties::steel_rebar(0.02)).unwrap();
    let bolts = Bolts::new()
        .bolt(Bolt::straight("B", [0.05, 0.0, 0.0], [0.95, 0.0, 0.0], 6, m).unwrap())
        .unwrap();
    let pull = bolts
        .boundary()
        .velocity("B", BoltNodes::Head, [Some((-0.1).into()), None, None])
        .unwrap();
    let mut sim = Simulation::builder(mesh, Backend::cpu(1).unwrap())
        .physics(
            Mechanics::new().material(Range::All, LinearElastic::new(10e9, 0.2, 2500.0).unwrap()),
        )
        .physics(Boundary::new().fix(Range::All))
        .physics(bolts.clone())
        .physics(pull)
        .build()
        .unwrap();
    let dir = std::env::temp_dir().join(format!("pcdc_bolt_output_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut series = BoltSeries::new(&dir, "bolts").unwrap();
    let mut csv = AxialForceCsv::new(dir.join("axial.csv"), &sim, &bolts, 0).unwrap();
    for _ in 0..3 {
        sim.run(50).unwrap();
        series.write_step(&sim).unwrap();
        csv.record(&sim, &bolts).unwrap();
    }
    let vtu = std::fs::read_to_string(dir.join("bolts_000002.vtu")).unwrap_or_else(|_| {
        String::from_utf8_lossy(&std::fs::read(dir.join("bolts_000002.vtu")).unwrap()).into()
    });
    for name in [
        "axial_force",
        "grout_force",
        "slip",
        "state",
        "NumberOfCells=\"6\"",
    ] {
        assert!(vtu.contains(name), "{name} missing from the VTU");
    }
    assert!(series.pvd_path().exists());
    let text = std::fs::read_to_string(dir.join("axial.csv")).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), 4, "{text}");
    assert_eq!(lines[0].split(',').count(), 7);
    // Pulled at the head: the first segment is in tension by the last record.
    let last: Vec<f64> = lines[3].split(',').map(|v| v.parse().unwrap()).collect();
    assert!(last[1] > 0.0, "{text}");
    std::fs::remove_dir_all(&dir).ok();
}
