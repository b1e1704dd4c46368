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
        "host_element",
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

/// The shipped 3D block (`meshes/make_specimens.py`): a bolt along a Gmsh curve group
/// embedded in tetrahedra, chained from the collar, pulled at its head. The grout hands
/// the pull to the rock along the bolt: the axial force falls from the head towards the
/// tail.
#[test]
fn a_bolt_along_a_3d_gmsh_curve_group_is_chained_and_carries_a_pull() {
    use pcdc_mesh::gmsh::{read_msh_with, ImportOptions};
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../meshes/bolted_block_s50mm.msh"
    );
    let import = read_msh_with::<pcdc_mesh::Dim3>(path, &ImportOptions::default()).unwrap();
    let m = BoltMaterial::new(BoltProperties::steel_rebar(0.02)).unwrap();
    let bolt = Bolt::from_line_group("B", &import, "bolt", [0.2, 0.2, 0.7], m).unwrap();
    let pts = bolt.points();
    let close = |a: [f64; 3], b: [f64; 3]| (0..3).all(|k| (a[k] - b[k]).abs() < 1e-9);
    assert!(close(pts[0], [0.2, 0.2, 0.6]), "head {:?}", pts[0]);
    assert!(
        close(*pts.last().unwrap(), [0.25, 0.22, 0.1]),
        "tail {:?}",
        pts.last()
    );
    let exact = 0.3 + (0.05f64.powi(2) + 0.02f64.powi(2) + 0.2f64.powi(2)).sqrt();
    assert!(
        (bolt.length() - exact).abs() < 1e-9,
        "{} vs {exact}",
        bolt.length()
    );
    assert_eq!(bolt.segments(), import.lines["bolt"].len());
    assert!(bolt.segments() >= 8, "{} segments", bolt.segments());
    // Head chosen by `head_near`: from the tail's side the chain runs the other way.
    let reversed = Bolt::from_line_group("R", &import, "bolt", [0.25, 0.22, 0.0], m).unwrap();
    assert!(close(reversed.points()[0], [0.25, 0.22, 0.1]));
    let e = Bolt::from_line_group("X", &import, "nowhere", [0.0; 3], m).unwrap_err();
    assert!(e.to_string().contains("nowhere"), "{e}");

    let bolts = Bolts::new().bolt(bolt).unwrap();
    let pull = bolts
        .boundary()
        .velocity("B", BoltNodes::Head, [None, None, Some(0.05.into())])
        .unwrap();
    let mut sim = Simulation::builder(import.mesh, Backend::cpu(1).unwrap())
        .physics(
            Mechanics::new().material(Range::All, LinearElastic::new(10e9, 0.2, 2500.0).unwrap()),
        )
        .physics(Boundary::new().fix(Range::group("bottom")))
        .physics(bolts)
        .physics(pull)
        .build()
        .unwrap();
    sim.run(300).unwrap();
    let axial = sim.field(pcdc_bolt::BOLT_AXIAL_FORCE).unwrap();
    eprintln!("axial force from the head (N): {axial:?}");
    assert!(axial[0] > 0.0, "the head segment is in tension: {axial:?}");
    assert!(
        axial[axial.len() - 1].abs() < 0.5 * axial[0],
        "the grout takes the pull off along the bolt: {axial:?}"
    );
}
