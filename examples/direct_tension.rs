//! Validation scene 7: direct tension of a dog-bone specimen with cohesive joints on
//! every interior face (manual 7.4.3), at three mesh sizes.
//!
//! `cargo run --release --example direct_tension` prints a table, writes
//! `out/direct_tension/direct_tension.png` (neck stress against displacement) and the
//! VTU series `out/direct_tension/direct_tension.pvd` (damage, stress, displacement;
//! open in ParaView to see the crack), and ends with the RESULT line. The metric maps
//! the allowed band −5 % / +10 % of T_s onto value ≤ 1 (tol = 1).
//!
//! Backend: `--backend cpu|gpu` (default `cpu`, or `PCDC_BACKEND`) and, on the GPU,
//! `--precision f64|f32` (default f64 where the adapter supports it, or
//! `PCDC_PRECISION`); the RESULT line carries `backend=` and `precision=`, e.g.
//! `cargo run --release --example direct_tension -- --backend gpu --precision f32`.
//! Elements, joints and boundary conditions all run on the device; on lavapipe (software
//! Vulkan) the full-size run is slow: it proves the path, not GPU speed.

mod common;

const ABOUT: &str = "Validation scene 7: direct tension of a dog-bone specimen with cohesive joints on every interior face (manual 7.4.3), at three mesh sizes";

use pcdc::compute::Backend;
use pcdc_validation::plot::Plot;
use pcdc_validation::report::{out_dir, ResultLine};
use pcdc_validation::scenes::direct_tension::{self as dt, Params};

fn main() {
    pcdc_validation::report::finish(choose())
}

/// Runs the scene on the backend named on the command line.
fn choose() -> Result<Vec<ResultLine>, Box<dyn std::error::Error>> {
    let args = common::cli::command("direct_tension", ABOUT).get_matches();
    run(&common::cli::backend(&args)?)
}

fn run(backend: &Backend) -> Result<Vec<ResultLine>, Box<dyn std::error::Error>> {
    println!("backend: {}", backend.describe());
    let full = Params::full();
    println!("Direct tension, dog-bone 50 x 150 mm, neck 30 mm, arcs R = 150 mm; joints Ts = 2 MPa, c = 25 MPa, phi = 45 deg");
    println!(
        "{:>8} {:>9} {:>7} {:>10} {:>9} {:>7} {:>8} {:>8}",
        "size_m", "elements", "joints", "peak_MPa", "dev_%", "broken", "steps", "wall_s"
    );
    let mut last = None;
    for size in [0.005, 0.003, full.size] {
        let vtu_dir = (size == full.size)
            .then(|| out_dir("direct_tension"))
            .transpose()?;
        let out = dt::run(backend, &Params { size, vtu_dir })?;
        println!(
            "{:>8.4} {:>9} {:>7} {:>10.4} {:>9.2} {:>7} {:>8} {:>8.2}",
            size,
            out.elements,
            out.joints,
            out.peak / 1e6,
            100.0 * out.deviation,
            out.broken.len(),
            out.steps,
            out.wall_s
        );
        last = Some(out);
    }
    let out = last.expect("three runs");
    let stride = (out.stress.len() / 600).max(1);
    let um: Vec<f64> = out
        .displacement
        .iter()
        .step_by(stride)
        .map(|d| d * 1e6)
        .collect();
    let xmax = um.last().copied().unwrap_or(1.0);
    let plot = Plot::new(
        "Direct tension: neck stress against displacement",
        "top-bottom displacement (µm)",
        "neck stress (MPa)",
    )
    .points(
        "FDEM (2 mm mesh)",
        um,
        out.stress.iter().step_by(stride).map(|s| s / 1e6).collect(),
    )
    .line(
        "tensile strength Ts",
        vec![0.0, xmax],
        vec![dt::TS / 1e6, dt::TS / 1e6],
    );
    let png = out_dir("direct_tension")?.join("direct_tension.png");
    plot.save_png(&png)?;
    println!("plot: {}", png.display());
    let on_neck = out
        .broken
        .iter()
        .filter(|b| b[1].abs() <= 0.5 * dt::NECK)
        .count();
    println!(
        "broken joints: {} ({} within the neck band |y| <= {} m)",
        out.broken.len(),
        on_neck,
        0.5 * dt::NECK
    );
    Ok(vec![ResultLine::new(
        backend,
        "direct_tension",
        "peak_vs_ts_band",
        out.band_metric(),
        1.0,
        out.elements,
        out.steps,
        out.wall_s,
    )])
}
