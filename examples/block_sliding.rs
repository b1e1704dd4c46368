//! Validation scene 2: a block sliding with friction stops after v0² / (2 g tan φ), at
//! four initial speeds (manual 7.3.4).
//!
//! `cargo run --release --example block_sliding` prints a table, writes
//! `out/block_sliding/block_sliding.png` (distance against speed, points over the
//! closed-form curve) and ends with the RESULT line (the worst speed).
//!
//! Backend: `--backend cpu|gpu` (default `cpu`, or `PCDC_BACKEND`) and, on the GPU,
//! `--precision f64|f32` (default f64 where the adapter supports it, or
//! `PCDC_PRECISION`); the RESULT line carries `backend=` and `precision=`, e.g.
//! `cargo run --release --example block_sliding -- --backend gpu --precision f32`.

mod common;

const ABOUT: &str = "Validation scene 2: a block sliding with friction stops after v0² / (2 g tan φ), at four initial speeds (manual 7.3.4)";

use pcdc::compute::Backend;
use pcdc_validation::plot::Plot;
use pcdc_validation::report::{out_dir, ResultLine};
use pcdc_validation::scenes::block_sliding;

fn main() {
    pcdc_validation::report::finish(choose())
}

/// Runs the scene on the backend named on the command line.
fn choose() -> Result<Vec<ResultLine>, Box<dyn std::error::Error>> {
    let args = common::cli::command("block_sliding", ABOUT).get_matches();
    run(&common::cli::backend(&args)?)
}

fn run(backend: &Backend) -> Result<Vec<ResultLine>, Box<dyn std::error::Error>> {
    println!("backend: {}", backend.describe());
    println!(
        "Block sliding on a fixed base, friction angle {} deg, g = 9.81 m/s^2",
        block_sliding::PHI
    );
    println!(
        "{:>6} {:>11} {:>11} {:>9} {:>9} {:>8} {:>8}",
        "v0", "distance_m", "exact_m", "error_%", "elements", "steps", "wall_s"
    );
    let mut outs = Vec::new();
    for v0 in [1.0, 2.0, 3.0, 4.0] {
        let o = block_sliding::run(backend, v0)?;
        println!(
            "{:>6.1} {:>11.5} {:>11.5} {:>9.3} {:>9} {:>8} {:>8.2}",
            o.v0,
            o.distance,
            o.expected,
            100.0 * o.error,
            o.elements,
            o.steps,
            o.wall_s
        );
        outs.push(o);
    }
    let vs: Vec<f64> = (0..=40).map(|i| 0.1 * i as f64).collect();
    let plot = Plot::new(
        "Block sliding: stopping distance",
        "initial speed v0 (m/s)",
        "distance (m)",
    )
    .line(
        "v0² / (2 g tan φ)",
        vs.clone(),
        vs.iter().map(|&v| block_sliding::expected(v)).collect(),
    )
    .points(
        "FDEM",
        outs.iter().map(|o| o.v0).collect(),
        outs.iter().map(|o| o.distance).collect(),
    );
    let png = out_dir("block_sliding")?.join("block_sliding.png");
    plot.save_png(&png)?;
    println!("plot: {}", png.display());
    let worst = outs
        .iter()
        .max_by(|a, b| a.error.total_cmp(&b.error))
        .expect("four speeds");
    Ok(vec![ResultLine::new(
        backend,
        "block_sliding",
        "max_rel_err_stop_distance",
        worst.error,
        block_sliding::TOL,
        worst.elements,
        outs.iter().map(|o| o.steps).sum(),
        outs.iter().map(|o| o.wall_s).sum(),
    )])
}
