//! Validation scene 10: steady unconfined flow with a free surface (Dupuit, manual
//! 7.5.6), three element sizes, against the corrected eq. 90 and the Dupuit–Charny
//! discharge.
//!
//! `cargo run --release --example unconfined_flow` prints an error table, writes
//! `out/unconfined_flow/unconfined_flow.png` (the free surface read from the flow nodes
//! over the Dupuit parabola) and `free_surface.csv` (x, y, y_Dupuit), and ends with two RESULT lines at the finest size (free surface against the Dupuit
//! parabola, discharge against Dupuit–Charny). Backend:
//! `--backend cpu|gpu`, `--precision f64|f32`.

mod common;

const ABOUT: &str =
    "Validation scene 10: unconfined flow with a free surface (Dupuit), three sizes";

use pcdc::compute::Backend;
use pcdc_validation::plot::Plot;
use pcdc_validation::report::{out_dir, ResultLine};
use pcdc_validation::scenes::unconfined_flow::{self as scene, Params, SIZES};

fn main() {
    pcdc_validation::report::finish(choose())
}

fn choose() -> Result<Vec<ResultLine>, Box<dyn std::error::Error>> {
    let args = common::cli::command("unconfined_flow", ABOUT).get_matches();
    run(&common::cli::backend(&args)?)
}

fn run(backend: &Backend) -> Result<Vec<ResultLine>, Box<dyn std::error::Error>> {
    println!("backend: {}", backend.describe());
    println!(
        "block {} x {} m, water levels h_l = {} m, h_r = {} m, k = {:e} m², water, K_f x {:e}",
        scene::LENGTH,
        scene::HEIGHT,
        scene::H_L,
        scene::H_R,
        scene::PERMEABILITY,
        scene::BULK_SCALE
    );
    println!(
        "{:>8} {:>9} {:>9} {:>10} {:>10} {:>10} {:>9} {:>10} {:>8}",
        "size_m",
        "elements",
        "channels",
        "error",
        "Q_error",
        "balance",
        "steps",
        "time_s",
        "wall_s"
    );
    let mut last = None;
    for size in SIZES {
        let out = scene::run(backend, &Params::sized(size))?;
        println!(
            "{:>8.4} {:>9} {:>9} {:>10.3e} {:>10.3e} {:>10.1e} {:>9} {:>10.3e} {:>8.3}",
            size,
            out.elements,
            out.channels,
            out.error,
            out.discharge_error,
            out.balance,
            out.steps,
            out.time,
            out.wall_s
        );
        last = Some(out);
    }
    let o = last.expect("three sizes");
    let dir = out_dir("unconfined_flow")?;
    let mut csv = String::from("x_m,y_m,y_dupuit_m\n");
    for (x, y) in o.x.iter().zip(&o.y) {
        csv.push_str(&format!("{x},{y},{}\n", scene::exact(*x)));
    }
    std::fs::write(dir.join("free_surface.csv"), csv)?;
    let xx: Vec<f64> = (0..=100)
        .map(|i| scene::LENGTH * i as f64 / 100.0)
        .collect();
    let plot = Plot::new("Unconfined flow: free surface (Dupuit)", "x (m)", "y (m)")
        .line(
            "Dupuit, eq. 90 corrected",
            xx.clone(),
            xx.iter().map(|&x| scene::exact(x)).collect(),
        )
        .points("FDEM flow nodes", o.x.clone(), o.y.clone());
    let png = dir.join("unconfined_flow.png");
    plot.save_png(&png)?;
    println!("plot: {}", png.display());
    Ok(vec![
        ResultLine::new(
            backend,
            "unconfined_flow",
            "max_err_surface_over_hl",
            o.error,
            scene::TOL,
            o.elements,
            o.steps,
            o.wall_s,
        ),
        ResultLine::new(
            backend,
            "unconfined_flow",
            "discharge_rel_err",
            o.discharge_error,
            scene::TOL,
            o.elements,
            o.steps,
            o.wall_s,
        ),
    ])
}
