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

use clap::{Arg, Command};
use pcdc::compute::{Backend, Simulation, StaticOptions};
use pcdc::mech::{output, Boundary, FaceStress, LinearElastic, Mechanics};
use pcdc::mesh::{gmsh, vtu::PvdSeries, Dim2, Range};
use pcdc_validation::report::out_dir;

fn main() {
    if let Err(e) = run() {
        eprintln!("error: {e}");
        std::process::exit(1);
    }
}

fn run() -> Result<(), Box<dyn std::error::Error>> {
    let args = Command::new("gmsh_import")
        .about("Imports a 2D Gmsh mesh, holds one physical group, pulls another, solves statically and writes VTU")
        .arg(
            Arg::new("mesh")
                .default_value(concat!(
                    env!("CARGO_MANIFEST_DIR"),
                    "/crates/pcdc-mesh/tests/data/square.msh"
                ))
                .help("MSH 4.1 ASCII file"),
        )
        .arg(Arg::new("fixed").default_value("left").help("Physical group held fixed"))
        .arg(Arg::new("loaded").default_value("right").help("Physical group pulled"))
        .arg(
            Arg::new("stress")
                .default_value("1e6")
                .value_parser(clap::value_parser!(f64))
                .help("Normal stress on the loaded group (Pa, tension positive)"),
        )
        .get_matches();
    let path = args.get_one::<String>("mesh").expect("default").clone();
    let fixed = args.get_one::<String>("fixed").expect("default").clone();
    let loaded = args.get_one::<String>("loaded").expect("default").clone();
    let stress = *args.get_one::<f64>("stress").expect("default");
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
    let mut sim = Simulation::builder(mesh, Backend::cpu(0)?)
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
