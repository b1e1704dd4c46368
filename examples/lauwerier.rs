//! Validation scene 14: heat exchange between the flowing fluid of a fracture and the
//! rock, Lauwerier (manual 7.6.11, eq. 117–118 corrected), three element sizes.
//!
//! `cargo run --release --example lauwerier` prints an error table, writes
//! `out/lauwerier/lauwerier.png` (fluid temperature along the fracture ab and rock
//! temperature along cd, 5 m above it, at 50 and 150 days, over the closed forms) and
//! ends with the RESULT line (finest size). Backend: `--backend cpu|gpu`,
//! `--precision f64|f32` (the fluid heat runs on the CPU only for now: the GPU backend
//! is refused by name).

mod common;

const ABOUT: &str = "Validation scene 14: Lauwerier heat exchange along a fracture with flow";

use pcdc::compute::Backend;
use pcdc_validation::plot::Plot;
use pcdc_validation::report::{out_dir, ResultLine};
use pcdc_validation::scenes::lauwerier::{self as lw, Params};

fn main() {
    pcdc_validation::report::finish(choose())
}

fn choose() -> Result<Vec<ResultLine>, Box<dyn std::error::Error>> {
    let args = common::cli::command("lauwerier", ABOUT).get_matches();
    run(&common::cli::backend(&args)?)
}

fn run(backend: &Backend) -> Result<Vec<ResultLine>, Box<dyn std::error::Error>> {
    println!("backend: {}", backend.describe());
    println!(
        "fracture δ = {} mm, v = {} mm/s, T_i = {} °C, T_a = {} °C, rock κ = {:.3e} m²/s, \
         h_sf = {} W/(m²·K); compared at 50 and 150 days",
        lw::APERTURE * 1e3,
        lw::VELOCITY * 1e3,
        lw::T_I,
        lw::T_A,
        lw::kappa(),
        lw::TRANSFER
    );
    println!(
        "{:>8} {:>9} {:>10} {:>10} {:>10} {:>8} {:>9} {:>8}",
        "size_m", "elements", "error", "err_fluid", "err_rock", "steps", "dt_s", "wall_s"
    );
    let mut last = None;
    for size in lw::SIZES {
        let out = lw::run(backend, &Params { size })?;
        println!(
            "{:>8.4} {:>9} {:>10.3e} {:>10.3e} {:>10.3e} {:>8} {:>9.1} {:>8.2}",
            size,
            out.elements,
            out.error,
            out.error_fluid,
            out.error_rock,
            out.steps,
            out.dt,
            out.wall_s
        );
        last = Some(out);
    }
    let out = last.expect("three sizes");
    let xs: Vec<f64> = (0..=200)
        .map(|i| lw::LENGTH * 0.6 * i as f64 / 200.0)
        .collect();
    let mut plot = Plot::new(
        "Lauwerier: fluid (ab) and rock 5 m away (cd)",
        "x (m)",
        "T (°C)",
    );
    for p in &out.profiles {
        let days = (p.time / 86400.0).round();
        plot = plot
            .line(
                format!("fluid, exact, {days} d"),
                xs.clone(),
                xs.iter()
                    .map(|&x| lw::exact(x, 0.0, p.time, out.velocity))
                    .collect(),
            )
            .points(
                format!("fluid, FDEM, {days} d"),
                p.fluid.iter().map(|a| a.0).collect(),
                p.fluid.iter().map(|a| a.1).collect(),
            )
            .line(
                format!("rock, exact, {days} d"),
                xs.clone(),
                xs.iter()
                    .map(|&x| lw::exact(x, lw::Y_CD, p.time, out.velocity))
                    .collect(),
            )
            .points(
                format!("rock, FDEM, {days} d"),
                p.rock.iter().map(|a| a.0).collect(),
                p.rock.iter().map(|a| a.1).collect(),
            );
    }
    let png = out_dir("lauwerier")?.join("lauwerier.png");
    plot.save_png(&png)?;
    println!("plot: {}", png.display());
    Ok(vec![ResultLine::new(
        backend,
        "lauwerier",
        "max_err_T_over_dT",
        out.error,
        lw::TOL,
        out.elements,
        out.steps,
        out.wall_s,
    )])
}
