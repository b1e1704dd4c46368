//! Validation scene 4: energy of an undamped free vibration over ten periods, 2D and 3D,
//! three mesh sizes.
//!
//! `cargo run --release --example vibration_energy` prints a drift table, writes
//! `out/vibration_energy/vibration_energy.png` and ends with the RESULT line (worst of
//! 2D and 3D at the finest size).
//!
//! Cells: `--element tet4|hex8` (default `tet4`); with `hex8` only the 3D bar runs, on
//! Hex8 cells, and the RESULT case gets the suffix `_hex8`.
//!
//! Backend: `--backend cpu|gpu` (default `cpu`, or `PCDC_BACKEND`) and, on the GPU,
//! `--precision f64|f32` (default f64 where the adapter supports it, or
//! `PCDC_PRECISION`); the RESULT line carries `backend=` and `precision=`, e.g.
//! `cargo run --release --example vibration_energy -- --backend gpu --precision f32`.

mod common;

const ABOUT: &str = "Validation scene 4: energy of an undamped free vibration over ten periods, 2D and 3D, three mesh sizes";

use pcdc::compute::Backend;
use pcdc_validation::plot::Plot;
use pcdc_validation::report::{out_dir, ResultLine};
use pcdc_validation::scenes::vibration_energy::{self, Params};
use pcdc_validation::scenes::Element;

fn main() {
    pcdc_validation::report::finish(choose())
}

/// Runs the scene on the backend named on the command line.
fn choose() -> Result<Vec<ResultLine>, Box<dyn std::error::Error>> {
    let args = common::cli::with_element(
        common::cli::command("vibration_energy", ABOUT),
        &["tet4", "hex8"],
    )
    .get_matches();
    run(&common::cli::backend(&args)?, common::cli::element(&args)?)
}

fn run(backend: &Backend, element: Element) -> Result<Vec<ResultLine>, Box<dyn std::error::Error>> {
    let hex8 = element == Element::Hex8;
    let case = if hex8 {
        "vibration_energy_hex8"
    } else {
        "vibration_energy"
    };
    println!("backend: {}", backend.describe());
    let full = Params::full();
    println!(
        "Undamped free vibration of an elastic block, {} periods of its first extensional mode",
        full.periods
    );
    println!(
        "{:>4} {:>8} {:>9} {:>11} {:>8} {:>8}",
        "dim", "size_m", "elements", "drift", "steps", "wall_s"
    );
    let mut finals = Vec::new();
    for size in [4.0 * full.size, 2.0 * full.size, full.size] {
        let p = Params {
            size,
            ..full.clone()
        };
        let runs = if hex8 {
            vec![("hex8", vibration_energy::run_3d_hex8(backend, &p)?)]
        } else {
            vec![
                ("2d", vibration_energy::run_2d(backend, &p)?),
                ("3d", vibration_energy::run_3d(backend, &p)?),
            ]
        };
        for (dim, out) in runs {
            println!(
                "{:>4} {:>8.4} {:>9} {:>11.3e} {:>8} {:>8.3}",
                dim, size, out.elements, out.drift, out.steps, out.wall_s
            );
            if size == full.size {
                finals.push((dim, out));
            }
        }
    }
    let mut plot = Plot::new(
        "Undamped vibration: energy / initial energy",
        "t / T",
        "E / E0",
    );
    for (dim, out) in &finals {
        let stride = (out.t_over_period.len() / 400).max(1);
        let t: Vec<f64> = out.t_over_period.iter().step_by(stride).copied().collect();
        plot = plot
            .points(
                format!("total {dim}"),
                t.clone(),
                out.energy.iter().step_by(stride).copied().collect(),
            )
            .line(
                format!("strain {dim}"),
                t,
                out.strain_energy.iter().step_by(stride).copied().collect(),
            );
    }
    plot = plot.line("exact total", vec![0.0, full.periods], vec![1.0, 1.0]);
    let png = out_dir(case)?.join(format!("{case}.png"));
    plot.save_png(&png)?;
    println!("plot: {}", png.display());
    let worst = finals
        .iter()
        .max_by(|a, b| a.1.drift.total_cmp(&b.1.drift))
        .expect("two runs");
    Ok(vec![ResultLine::new(
        backend,
        case,
        "max_rel_energy_drift",
        worst.1.drift,
        vibration_energy::TOL,
        finals.iter().map(|f| f.1.elements).sum(),
        finals.iter().map(|f| f.1.steps).sum(),
        finals.iter().map(|f| f.1.wall_s).sum(),
    )])
}
