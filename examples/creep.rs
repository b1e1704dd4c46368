//! Validation scene 5: Burgers creep under a constant deviatoric stress (manual 7.2.5),
//! plane strain (Tri3) and 3D (Tet4).
//!
//! `cargo run --release --example creep` runs each dimension with 10, 20 and 40 creep
//! steps over five Kelvin times at τ = 1 MPa and at τ = 1 kPa, prints the error against
//! the closed form e(t) = τ/(2G_M) + τ t/(2η_M) + τ/(2G_K)(1 − exp(−G_K t/η_K)) and the
//! observed order of the Crank–Nicolson scheme (2 expected; at 1 MPa the large-strain
//! floor of about e/4 shows once the step is fine, see `scenes::creep`), writes `out/creep/creep.png` (strain
//! against creep time, 20 steps, with the closed form) and ends with the RESULT lines
//! (20 steps, tolerance 2 %).
//!
//! Backend: `--backend cpu|gpu`, `--precision f64|f32` (see `--help`).

mod common;

const ABOUT: &str = "Validation scene 5: Burgers creep under a constant deviator (manual 7.2.5), plane strain and 3D, with the Crank-Nicolson order";

use pcdc::compute::Backend;
use pcdc_validation::plot::Plot;
use pcdc_validation::report::{out_dir, ResultLine};
use pcdc_validation::scenes::creep::{self, Dimension, Params};

fn main() {
    pcdc_validation::report::finish(choose())
}

fn choose() -> Result<Vec<ResultLine>, Box<dyn std::error::Error>> {
    let args = common::cli::command("creep", ABOUT).get_matches();
    run(&common::cli::backend(&args)?)
}

fn run(backend: &Backend) -> Result<Vec<ResultLine>, Box<dyn std::error::Error>> {
    println!("backend: {}", backend.describe());
    println!("Burgers: G_M = 1 GPa, K = 2 GPa, G_K = 2 GPa, eta_K = 4e14 Pa s, eta_M = 2e15 Pa s; tau = 1 MPa");
    println!(
        "{:>4} {:>9} {:>6} {:>9} {:>12} {:>7} {:>10} {:>8}",
        "dim", "tau_Pa", "steps", "elements", "error", "order", "relax", "wall_s"
    );
    let mut lines = Vec::new();
    let mut plot = Plot::new(
        "Burgers creep under a constant deviator",
        "creep time (days)",
        "deviatoric strain e_xx (1e-4)",
    );
    for dim in [Dimension::Two, Dimension::Three] {
        let label = if dim == Dimension::Two { "2d" } else { "3d" };
        for tau in [creep::TAU, creep::TAU_CONVERGENCE] {
            let full = Params {
                tau,
                ..Params::full(dim)
            };
            let mut last: Option<f64> = None;
            for steps in [10, 20, 40] {
                let o = creep::run(
                    backend,
                    &Params {
                        steps,
                        ..full.clone()
                    },
                )?;
                let order = last.map_or(String::from("-"), |e| {
                    format!("{:.2}", (e / o.error).log2())
                });
                println!(
                    "{:>4} {:>9} {:>6} {:>9} {:>12.3e} {:>7} {:>10} {:>8.2}",
                    label, tau, steps, o.elements, o.error, order, o.steps, o.wall_s
                );
                last = Some(o.error);
                if steps == full.steps && tau == creep::TAU {
                    let days: Vec<f64> = o.time.iter().map(|t| t / 86400.0).collect();
                    plot = plot.points(
                        format!("FDEM {label}, {steps} creep steps"),
                        days.clone(),
                        o.strain.iter().map(|e| e * 1e4).collect(),
                    );
                    if dim == Dimension::Two {
                        plot = plot.line(
                            "closed form",
                            days,
                            o.exact.iter().map(|e| e * 1e4).collect(),
                        );
                    }
                    lines.push(ResultLine::new(
                        backend,
                        "creep",
                        &format!("strain_rel_err_{label}"),
                        o.error,
                        creep::TOL,
                        o.elements,
                        o.steps,
                        o.wall_s,
                    ));
                }
            }
        }
    }
    let png = out_dir("creep")?.join("creep.png");
    plot.save_png(&png)?;
    println!("plot: {}", png.display());
    Ok(lines)
}
