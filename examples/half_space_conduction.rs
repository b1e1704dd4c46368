//! Validation scene: transient conduction into a half-space after a surface temperature
//! step (issue 17), 2D strip and 3D bar, three element sizes, against
//! T = T0 + (Ts − T0) erfc(x / (2√(κt))).
//!
//! `cargo run --release --example half_space_conduction` prints an error table, writes
//! `out/half_space_conduction/half_space_conduction.png` (T of every node against x at
//! the last time, over the closed form) and ends with the RESULT line (worst of 2D and
//! 3D at the finest size). Backend: `--backend cpu|gpu`, `--precision f64|f32`.

mod common;

const ABOUT: &str =
    "Validation scene: transient conduction into a half-space, 2D and 3D, three sizes";

use pcdc::compute::Backend;
use pcdc_validation::plot::Plot;
use pcdc_validation::report::{out_dir, ResultLine};
use pcdc_validation::scenes::half_space_conduction::{self as hs, Params};

fn main() {
    pcdc_validation::report::finish(choose())
}

fn choose() -> Result<Vec<ResultLine>, Box<dyn std::error::Error>> {
    let args = common::cli::command("half_space_conduction", ABOUT).get_matches();
    run(&common::cli::backend(&args)?)
}

fn run(backend: &Backend) -> Result<Vec<ResultLine>, Box<dyn std::error::Error>> {
    println!("backend: {}", backend.describe());
    println!(
        "granite bar, κ = {:.3e} m²/s, T0 = {} °C, Ts = {} °C at x = 0, compared at t = {:.0} s and a quarter of it",
        hs::kappa(),
        hs::T0,
        hs::TS,
        hs::t_end()
    );
    println!(
        "{:>4} {:>8} {:>9} {:>10} {:>8} {:>10} {:>8}",
        "dim", "size_m", "elements", "error", "steps", "dt_s", "wall_s"
    );
    let mut finals = Vec::new();
    for (dim, sizes) in [("2d", hs::SIZES_2D), ("3d", hs::SIZES_3D)] {
        for size in sizes {
            let p = Params { size };
            let out = if dim == "2d" {
                hs::run_2d(backend, &p)?
            } else {
                hs::run_3d(backend, &p)?
            };
            println!(
                "{:>4} {:>8.4} {:>9} {:>10.3e} {:>8} {:>10.3} {:>8.3}",
                dim, size, out.elements, out.error, out.steps, out.dt, out.wall_s
            );
            if size == sizes[2] {
                finals.push((dim, out));
            }
        }
    }
    let xs: Vec<f64> = (0..=200).map(|i| 0.5 * i as f64 / 200.0).collect();
    let (_, o) = &finals[0];
    let plot = Plot::new(
        "Conduction into a half-space (2D), last time",
        "x (m)",
        "T (°C)",
    )
    .line(
        "exact, erfc",
        xs.clone(),
        xs.iter().map(|&x| hs::exact(x, hs::t_end())).collect(),
    )
    .points("FDEM nodes", o.x.clone(), o.t.clone());
    let png = out_dir("half_space_conduction")?.join("half_space_conduction.png");
    plot.save_png(&png)?;
    println!("plot: {}", png.display());
    let worst = finals
        .iter()
        .max_by(|a, b| a.1.error.total_cmp(&b.1.error))
        .expect("two runs");
    Ok(vec![ResultLine::new(
        backend,
        "half_space_conduction",
        "max_err_T_over_dT",
        worst.1.error,
        hs::TOL,
        finals.iter().map(|f| f.1.elements).sum(),
        finals.iter().map(|f| f.1.steps).sum(),
        finals.iter().map(|f| f.1.wall_s).sum(),
    )])
}
