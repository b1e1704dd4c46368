//! The 3D unstructured specimens shipped in `meshes/` (made by
//! `python3 meshes/make_specimens.py` with Gmsh 4.15.2) import cleanly: positive
//! tetrahedra filling the cylinder's volume, and the physical groups as node, face and
//! element groups.

use pcdc_mesh::{gmsh, Dim3};

#[test]
fn gmsh_cylinder_imports_with_its_groups() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../meshes/cylinder_d50_h100_s6mm.msh"
    );
    let mesh = gmsh::read_msh::<Dim3>(path).unwrap();
    let volume: f64 = (0..mesh.n_elements())
        .map(|e| mesh.element_measure(e))
        .sum();
    let exact = std::f64::consts::PI * 0.025f64.powi(2) * 0.1;
    eprintln!(
        "{} tetrahedra, {} nodes, volume {:.4e} m3 ({:+.2} % of the cylinder's)",
        mesh.n_elements(),
        mesh.n_nodes(),
        volume,
        100.0 * (volume / exact - 1.0)
    );
    // Faceted curved surface: a little less than the exact volume.
    assert!(
        volume < exact && volume > 0.98 * exact,
        "{volume} vs {exact}"
    );
    let g = mesh.groups();
    for name in ["bottom", "top", "side"] {
        assert!(!g.faces[name].is_empty(), "{name}");
    }
    assert_eq!(g.elements["rock"].len(), mesh.n_elements());
    for &n in &g.nodes["top"] {
        assert!((mesh.node(n as usize)[2] - 0.1).abs() < 1e-9);
    }
    for &n in &g.nodes["bottom"] {
        assert!(mesh.node(n as usize)[2].abs() < 1e-9);
    }
}

#[test]
fn gmsh_bolted_block_imports_with_its_bolt_curve() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../meshes/bolted_block_s50mm.msh"
    );
    let import = gmsh::read_msh_with::<Dim3>(path, &gmsh::ImportOptions::default()).unwrap();
    let mesh = &import.mesh;
    let volume: f64 = (0..mesh.n_elements())
        .map(|e| mesh.element_measure(e))
        .sum();
    assert!((volume - 0.4 * 0.4 * 0.6).abs() < 1e-12, "{volume}");
    assert!((0..mesh.n_elements()).all(|e| mesh.element_measure(e) > 0.0));
    // The embedded curve: its lines join up to the polyline's length, on the mesh's
    // nodes (the curve's node group holds the same nodes).
    let lines = &import.lines["bolt"];
    let length: f64 = lines
        .iter()
        .map(|&[a, b]| {
            let (p, q) = (mesh.node(a as usize), mesh.node(b as usize));
            (0..3).map(|k| (p[k] - q[k]).powi(2)).sum::<f64>().sqrt()
        })
        .sum();
    let exact = 0.3 + (0.05f64.powi(2) + 0.02f64.powi(2) + 0.2f64.powi(2)).sqrt();
    assert!((length - exact).abs() < 1e-9, "{length} vs {exact}");
    let mut nodes: Vec<u32> = lines.iter().flatten().copied().collect();
    nodes.sort_unstable();
    nodes.dedup();
    assert_eq!(nodes, mesh.groups().nodes["bolt"]);
    for g in ["rock", "top", "bottom"] {
        assert!(!mesh.groups().nodes[g].is_empty(), "{g}");
    }
}
