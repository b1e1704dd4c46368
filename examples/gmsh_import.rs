//! Import a 2D Gmsh mesh (MSH 4.1 ASCII), hold one physical group, pull another with a
//! normal stress, solve statically and write the result for ParaView.
//!
//! ```sh
//! cargo run --release --example gmsh_import -- [mesh.msh] [fixed group] [loaded group] [stress Pa]
//! ```
//! Defaults: the small square shipped with the tests
//! (`crates/pcdc-mesh/tests/data/square.msh`), groups `left` and `right`, 1 MPa of
//! tension. Physical groups of the file become node, element and face groups; export
//! from Gmsh with `-format msh41` and `Mesh.Binary = 0`.

use pcdc::compute::{CpuBackend, Simulation, StaticOptions};
use pcdc::mech::{output, Boundary, FaceStress, LinearElastic, Mechanics};
use pcdc::mesh::{gmsh, vtu::PvdSeries, Dim2, Range};
use pcdc::report::out_dir;

fn main() {
    if let Err(e) = run() {
        eprintln!("error: {e}");
        std::process::exit(1);
    }
}

fn run() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let path = args.first().cloned().unwrap_or_else(|| {
        concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/crates/pcdc-mesh/tests/data/square.msh"
        )
        .to_string()
    });
    let fixed = args.get(1).cloned().unwrap_or_else(|| "left".into());
    let loaded = args.get(2).cloned().unwrap_or_else(|| "right".into());
    let stress: f64 = match args.get(3) {
        Some(s) => s
            .parse()
            .map_err(|_| format!("stress '{s}' is not a number (Pa)"))?,
        None => 1e6,
    };
    let mesh = gmsh::read_msh::<Dim2>(&path)?;
    println!(
        "{path}: {} nodes, {} triangles",
        mesh.n_nodes(),
        mesh.n_elements()
    );
    for (kind, groups) in [
        ("node", &mesh.groups().nodes),
        ("element", &mesh.groups().elements),
        ("face", &mesh.groups().faces),
    ] {
        for (name, items) in groups {
            println!("  {kind} group '{name}': {}", items.len());
        }
    }
    let rock = LinearElastic::new(30e9, 0.25, 2600.0)?;
    let mut sim = Simulation::builder(mesh, CpuBackend::new(0)?)
        .physics(Mechanics::new().material(Range::All, rock))
        .physics(
            Boundary::new()
                .fix(Range::group(fixed.clone()))
                .face_stress(Range::group(loaded.clone()), FaceStress::normal(stress)),
        )
        .build()?;
    let report = sim.solve_linear(&StaticOptions::default())?;
    let s = output::global_stress(&sim)?;
    let umax = sim.state.u.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let smax = s.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    println!("static solve: {} iterations, unbalanced-force ratio {:.1e}; max |u| = {umax:.3e} m, max |stress| = {smax:.3e} Pa", report.steps, report.ratio);
    let dir = out_dir("gmsh_import")?;
    let mut series = PvdSeries::new(&dir, "gmsh_import")?;
    let file = output::write_step(&mut series, &sim)?;
    println!(
        "wrote {} (open {} in ParaView)",
        file.display(),
        series.pvd_path().display()
    );
    Ok(())
}
