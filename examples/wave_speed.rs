//! Validation scene 3: P-wave speed in a bar on rollers, 2D and 3D, three mesh sizes.
//!
//! `cargo run --release --example wave_speed` prints an error table, writes
//! `out/wave_speed/wave_speed.png` (probe velocities against time, with the analytic
//! arrival times) and ends with the RESULT line (worst of 2D and 3D at the finest size).
//!
//! Cells: `--element tet4|hex8` (default `tet4`); with `hex8` only the 3D bar runs, on
//! Hex8 cells, and the RESULT case gets the suffix `_hex8`.
//!
//! Backend: `--backend cpu|gpu` (default `cpu`, or `PCDC_BACKEND`) and, on the GPU,
//! `--precision f64|f32` (default f64 where the adapter supports it, or
//! `PCDC_PRECISION`); the RESULT line carries `backend=` and `precision=`, e.g.
//! `cargo run --release --example wave_speed -- --backend gpu --precision f32`.

mod common;

const ABOUT: &str =
    "Validation scene 3: P-wave speed in a bar on rollers, 2D and 3D, three mesh sizes";

use pcdc::compute::Backend;
use pcdc_validation::plot::Plot;
use pcdc_validation::report::{out_dir, ResultLine};
use pcdc_validation::scenes::wave_speed::{self, Params};
use pcdc_validation::scenes::Element;

fn main() {
    pcdc_validation::report::finish(choose())
}

/// Runs the scene on the backend named on the command line.
fn choose() -> Result<Vec<ResultLine>, Box<dyn std::error::Error>> {
    let args =
        common::cli::with_element(common::cli::command("wave_speed", ABOUT), &["tet4", "hex8"])
            .get_matches();
    run(&common::cli::backend(&args)?, common::cli::element(&args)?)
}

fn run(backend: &Backend, element: Element) -> Result<Vec<ResultLine>, Box<dyn std::error::Error>> {
    let hex8 = element == Element::Hex8;
    let case = if hex8 {
        "wave_speed_hex8"
    } else {
        "wave_speed"
    };
    println!("backend: {}", backend.describe());
    let full = Params::full();
    println!(
        "P-wave speed, bar 1 m on rollers, E = 30 GPa, nu = 0.25, rho = 2600: c = {:.2} m/s",
        wave_speed::c_exact()
    );
    println!(
        "{:>4} {:>8} {:>9} {:>10} {:>9} {:>7} {:>8}",
        "dim", "size_m", "elements", "c_num", "error", "steps", "wall_s"
    );
    let mut finals = Vec::new();
    for size in [4.0 * full.size, 2.0 * full.size, full.size] {
        let p = Params { size };
        let runs = if hex8 {
            vec![("hex8", wave_speed::run_3d_hex8(backend, &p)?)]
        } else {
            vec![
                ("2d", wave_speed::run_2d(backend, &p)?),
                ("3d", wave_speed::run_3d(backend, &p)?),
            ]
        };
        for (dim, out) in runs {
            println!(
                "{:>4} {:>8.4} {:>9} {:>10.2} {:>9.5} {:>7} {:>8.3}",
                dim, size, out.elements, out.c_num, out.error, out.steps, out.wall_s
            );
            if size == full.size {
                finals.push((dim, out));
            }
        }
    }
    let c = wave_speed::c_exact();
    let (_, o2) = &finals[0];
    let tmax = o2.t.last().copied().unwrap_or(0.0) * 1e3;
    let step = |x: f64| -> (Vec<f64>, Vec<f64>) {
        let ta = x / c * 1e3;
        (vec![0.0, ta, ta, tmax], vec![0.0, 0.0, 0.1, 0.1])
    };
    let (sx1, sy1) = step(0.25);
    let (sx2, sy2) = step(0.75);
    let ms: Vec<f64> = o2.t.iter().map(|t| t * 1e3).collect();
    let plot = Plot::new(
        if hex8 {
            "Velocity step in a bar on rollers (3D, Hex8)"
        } else {
            "Velocity step in a bar on rollers (2D)"
        },
        "time (ms)",
        "mean x-velocity (m/s)",
    )
    .line("exact front at x = 0.25 m", sx1, sy1)
    .line("exact front at x = 0.75 m", sx2, sy2)
    .points("FDEM x = 0.25 m", ms.clone(), o2.v1.clone())
    .points("FDEM x = 0.75 m", ms, o2.v2.clone());
    let png = out_dir(case)?.join(format!("{case}.png"));
    plot.save_png(&png)?;
    println!("plot: {}", png.display());
    let worst = finals
        .iter()
        .max_by(|a, b| a.1.error.total_cmp(&b.1.error))
        .expect("two runs");
    Ok(vec![ResultLine::new(
        backend,
        case,
        "rel_err_p_wave_speed",
        worst.1.error,
        wave_speed::TOL,
        finals.iter().map(|f| f.1.elements).sum(),
        finals.iter().map(|f| f.1.steps).sum(),
        finals.iter().map(|f| f.1.wall_s).sum(),
    )])
}
