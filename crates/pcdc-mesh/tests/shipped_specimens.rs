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
