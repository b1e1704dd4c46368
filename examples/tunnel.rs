//! Validation: a circular opening in Mohr–Coulomb rock under hydrostatic in-situ stress
//! against Salençon's closed form (manual 7.2.4; FLAC's classic Mohr–Coulomb check).
//!
//! `cargo run --release --example tunnel` runs the ring at a/20, a/30 and a/40 at the
//! hole, prints the stress error along θ = 0 and the plastic radius against R_p, writes
//! `out/tunnel/tunnel.png` (σθ and σr against r/a with the closed form) and the VTU file
//! `out/tunnel/tunnel.pvd` of the finest run (stress and the plastic history
//! `model_state_0..5`; `model_state_1` shows the plastic zone), and ends with the RESULT
//! lines (stress error, tolerance 5 % of max σθ; plastic radius, 5 %).
//!
//! Backend: `--backend cpu|gpu`, `--precision f64|f32` (see `--help`).

mod common;

const ABOUT: &str = "Validation: circular opening in Mohr-Coulomb rock under hydrostatic stress against Salencon's closed form";

use pcdc::compute::Backend;
use pcdc_validation::plot::Plot;
use pcdc_validation::report::{out_dir, ResultLine};
use pcdc_validation::scenes::tunnel::{self, Params};

fn main() {
    pcdc_validation::report::finish(choose())
}

fn choose() -> Result<Vec<ResultLine>, Box<dyn std::error::Error>> {
    let args = common::cli::command("tunnel", ABOUT).get_matches();
    run(&common::cli::backend(&args)?)
}

fn run(backend: &Backend) -> Result<Vec<ResultLine>, Box<dyn std::error::Error>> {
    println!("backend: {}", backend.describe());
    println!(
        "p0 = {} MPa, c = {} MPa, phi = {} deg, a = 1 m; closed-form plastic radius {:.4} m",
        tunnel::P0 * 1e-6,
        tunnel::COHESION * 1e-6,
        tunnel::FRICTION,
        tunnel::plastic_radius()
    );
    println!(
        "{:>8} {:>9} {:>10} {:>10} {:>9} {:>8} {:>8}",
        "size/a", "elements", "stress_%", "Rp_m", "Rp_err_%", "steps", "wall_s"
    );
    let mut last = None;
    for size in [0.05, 1.0 / 30.0, Params::full().size_at_hole] {
        let full = size == Params::full().size_at_hole;
        let vtu_dir = full.then(|| out_dir("tunnel")).transpose()?;
        let o = tunnel::run(
            backend,
            &Params {
                size_at_hole: size,
                vtu_dir,
            },
        )?;
        println!(
            "{:>8.4} {:>9} {:>10.3} {:>10.4} {:>9.3} {:>8} {:>8.2}",
            size,
            o.elements,
            100.0 * o.error,
            o.plastic_radius,
            100.0 * o.radius_error(),
            o.steps,
            o.wall_s
        );
        last = Some(o);
    }
    let o = last.expect("three runs");
    let rs: Vec<f64> = (0..200).map(|i| 1.0 + 4.0 * i as f64 / 199.0).collect();
    let plot = Plot::new(
        "Opening in Mohr-Coulomb rock: stresses along theta = 0",
        "r / a",
        "stress (MPa, compression positive)",
    )
    .points(
        "FDEM sigma_theta (a/40)",
        o.r_over_a.clone(),
        o.sigma_theta.iter().map(|s| s * 1e-6).collect(),
    )
    .points(
        "FDEM sigma_r (a/40)",
        o.r_over_a.clone(),
        o.sigma_r.iter().map(|s| s * 1e-6).collect(),
    )
    .line(
        "Salencon sigma_theta",
        rs.clone(),
        rs.iter().map(|&r| tunnel::exact(r).0 * 1e-6).collect(),
    )
    .line(
        "Salencon sigma_r",
        rs.clone(),
        rs.iter().map(|&r| tunnel::exact(r).1 * 1e-6).collect(),
    );
    let png = out_dir("tunnel")?.join("tunnel.png");
    plot.save_png(&png)?;
    println!("plot: {}", png.display());
    Ok(vec![
        ResultLine::new(
            backend,
            "tunnel",
            "stress_rel_err",
            o.error,
            tunnel::TOL,
            o.elements,
            o.steps,
            o.wall_s,
        ),
        ResultLine::new(
            backend,
            "tunnel",
            "plastic_radius_rel_err",
            o.radius_error(),
            tunnel::RADIUS_TOL,
            o.elements,
            o.steps,
            o.wall_s,
        ),
    ])
}
