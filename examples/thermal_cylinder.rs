//! Validation scene 13: steady conduction through a hollow cylinder and its plane-strain
//! thermal stresses (manual 7.6.9, eq. 114–116 corrected), three element sizes.
//!
//! `cargo run --release --example thermal_cylinder` prints an error table, writes
//! `out/thermal_cylinder/thermal_cylinder.png` (nodal-averaged σ_r and σ_θ against r,
//! over the closed forms) and ends with the RESULT line (the worse of the temperature
//! and stress errors, each over its tolerance, at the finest size). Backend:
//! `--backend cpu|gpu`, `--precision f64|f32`.

mod common;

const ABOUT: &str = "Validation scene 13: hollow cylinder, steady T(r) and thermal stresses";

use pcdc::compute::Backend;
use pcdc_validation::plot::Plot;
use pcdc_validation::report::{out_dir, ResultLine};
use pcdc_validation::scenes::thermal_cylinder::{self as tc, Params};

fn main() {
    pcdc_validation::report::finish(choose())
}

fn choose() -> Result<Vec<ResultLine>, Box<dyn std::error::Error>> {
    let args = common::cli::command("thermal_cylinder", ABOUT).get_matches();
    run(&common::cli::backend(&args)?)
}

fn run(backend: &Backend) -> Result<Vec<ResultLine>, Box<dyn std::error::Error>> {
    println!("backend: {}", backend.describe());
    println!(
        "ring r_i = {} m, r_o = {} m, T_i = {} °C, T_o = {} °C, α = {:e} 1/K, plane strain",
        tc::R_IN,
        tc::R_OUT,
        tc::T_IN,
        tc::T_OUT,
        tc::ALPHA
    );
    println!(
        "{:>8} {:>9} {:>10} {:>10} {:>8} {:>8}  thermal schedule",
        "size_m", "elements", "err_T", "err_sigma", "steps", "wall_s"
    );
    let mut last = None;
    for size in tc::SIZES {
        let o = tc::run(backend, &Params { size })?;
        println!(
            "{:>8.4} {:>9} {:>10.3e} {:>10.3e} {:>8} {:>8.3}  {}",
            size, o.elements, o.error_t, o.error_s, o.steps, o.wall_s, o.every
        );
        last = Some(o);
    }
    let o = last.expect("three sizes");
    let rr: Vec<f64> = (0..=100)
        .map(|i| tc::R_IN + (tc::R_OUT - tc::R_IN) * i as f64 / 100.0)
        .collect();
    let mpa = |v: &[f64]| v.iter().map(|s| s * 1e-6).collect::<Vec<_>>();
    let plot = Plot::new("Hollow cylinder, thermal stress", "r (m)", "stress (MPa)")
        .line(
            "σ_r exact (115)",
            rr.clone(),
            rr.iter().map(|&r| tc::stresses(r).0 * 1e-6).collect(),
        )
        .line(
            "σ_θ exact (116)",
            rr.clone(),
            rr.iter().map(|&r| tc::stresses(r).1 * 1e-6).collect(),
        )
        .points("σ_r nodes", o.r.clone(), mpa(&o.sr))
        .points("σ_θ nodes", o.r.clone(), mpa(&o.st));
    let png = out_dir("thermal_cylinder")?.join("thermal_cylinder.png");
    plot.save_png(&png)?;
    println!("plot: {}", png.display());
    // One RESULT line: the worse of the two errors, as a fraction of its tolerance.
    let ratio = (o.error_t / tc::TOL_T).max(o.error_s / tc::TOL_S);
    Ok(vec![ResultLine::new(
        backend,
        "thermal_cylinder",
        "max_err_over_tol",
        ratio,
        1.0,
        o.elements,
        o.steps,
        o.wall_s,
    )])
}
