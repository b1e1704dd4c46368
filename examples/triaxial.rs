//! Validation: drained triaxial compression at σ3 = 0, 2, 5, 10 MPa and direct tension of
//! one Mohr–Coulomb block (manual 7.2.4), in plane strain (Tri3) and in 3D (Tet4).
//!
//! `cargo run --release --example triaxial` prints each run's plateau stress against
//! σ1 = σ3 N_φ + 2c√N_φ (and σ_t in tension) and its dilatancy ratio dε_v/dε_a against
//! the flow rule's N_ψ − 1, writes `out/triaxial/triaxial.png` (axial stress against
//! axial strain, closed forms as lines) and the VTU series `out/triaxial/triaxial.pvd`
//! of the 3D run at σ3 = 10 MPa (stress, strain and the plastic history
//! `model_state_0..5`: shear now/past, tension now/past, κ_s, κ_t), and ends with the
//! RESULT lines (plateau error, tolerance 1 %; dilatancy error, 2 %; per dimension).
//!
//! Backend: `--backend cpu|gpu`, `--precision f64|f32` (see `--help`).

mod common;

const ABOUT: &str = "Validation: triaxial compression and direct tension of one Mohr-Coulomb block (manual 7.2.4), plane strain and 3D";

use pcdc::compute::Backend;
use pcdc_validation::plot::Plot;
use pcdc_validation::report::{out_dir, ResultLine};
use pcdc_validation::scenes::triaxial::{self as tx, Dimension, Params};

fn main() {
    pcdc_validation::report::finish(choose())
}

fn choose() -> Result<Vec<ResultLine>, Box<dyn std::error::Error>> {
    let args = common::cli::command("triaxial", ABOUT).get_matches();
    run(&common::cli::backend(&args)?)
}

fn run(backend: &Backend) -> Result<Vec<ResultLine>, Box<dyn std::error::Error>> {
    println!("backend: {}", backend.describe());
    println!(
        "Mohr-Coulomb block: E = {} GPa, nu = {}, c = {} MPa, phi = {} deg, psi = {} deg, sigma_t = {} MPa",
        tx::E * 1e-9,
        tx::NU,
        tx::COHESION * 1e-6,
        tx::FRICTION,
        tx::DILATION,
        tx::TENSILE * 1e-6
    );
    println!(
        "{:>4} {:>9} {:>11} {:>11} {:>9} {:>10} {:>10} {:>8}",
        "dim", "s3_MPa", "plateau", "closed", "err_%", "dilat", "closed", "steps"
    );
    let mut lines = Vec::new();
    let mut plot = Plot::new(
        "Triaxial tests of a Mohr-Coulomb block (3D)",
        "axial strain (‰)",
        "axial stress (MPa)",
    );
    for dim in [Dimension::Two, Dimension::Three] {
        let mut p = Params::full(dim);
        if dim == Dimension::Three {
            p.vtu_dir = Some(out_dir("triaxial")?);
        }
        let o = tx::run(backend, &p)?;
        let label = if dim == Dimension::Two { "2d" } else { "3d" };
        for c in &o.curves {
            println!(
                "{:>4} {:>9} {:>11.4} {:>11.4} {:>9.3} {:>10.4} {:>10.4} {:>8}",
                label,
                c.confinement
                    .map_or("tension".to_string(), |s| format!("{:.0}", s * 1e-6)),
                c.plateau * 1e-6,
                c.expected * 1e-6,
                100.0 * c.error(),
                c.dilatancy,
                c.dilatancy_expected,
                c.steps
            );
            if dim == Dimension::Three {
                let name = c.confinement.map_or("tension".to_string(), |s| {
                    format!("σ3 = {:.0} MPa", s * 1e-6)
                });
                let strain: Vec<f64> = c.axial_strain.iter().map(|e| e * 1e3).collect();
                let xmax = strain.last().copied().unwrap_or(1.0);
                plot = plot
                    .points(
                        format!("FDEM, {name}"),
                        strain,
                        c.axial_stress.iter().map(|s| s * 1e-6).collect(),
                    )
                    .line(
                        format!("closed form, {name}"),
                        vec![0.0, xmax],
                        vec![c.expected * 1e-6; 2],
                    );
            }
        }
        let metric = |m: &str| format!("{m}_{label}");
        lines.push(ResultLine::new(
            backend,
            "triaxial",
            &metric("plateau_rel_err"),
            o.error,
            tx::TOL,
            o.elements,
            o.steps,
            o.wall_s,
        ));
        lines.push(ResultLine::new(
            backend,
            "triaxial",
            &metric("dilatancy_rel_err"),
            o.dilatancy_error,
            tx::DILATANCY_TOL,
            o.elements,
            o.steps,
            o.wall_s,
        ));
    }
    let png = out_dir("triaxial")?.join("triaxial.png");
    plot.save_png(&png)?;
    println!("plot: {}", png.display());
    Ok(lines)
}
