//! Pull-out of a fully grouted rock bolt to failure under confinement (manual 7.9): the
//! peak load against the bond strength times the length, S_b L (eq. 144–147), and the
//! plateau after it, three segment lengths.
//!
//! `cargo run --release --example bolt_pullout_failure` prints a table, writes
//! `out/bolt_pullout_failure/load_slip.png` (pull-out load against head displacement)
//! and ends with the RESULT line (finest segments). Backend: `--backend cpu|gpu`,
//! `--precision f64|f32`.

mod common;

const ABOUT: &str = "Pull-out of a fully grouted bolt to failure: peak = bond strength x length";

use pcdc::compute::Backend;
use pcdc_validation::plot::Plot;
use pcdc_validation::report::{out_dir, ResultLine};
use pcdc_validation::scenes::bolt_pullout::{self as bp, Params};

fn main() {
    pcdc_validation::report::finish(choose())
}

fn choose() -> Result<Vec<ResultLine>, Box<dyn std::error::Error>> {
    let args = common::cli::command("bolt_pullout_failure", ABOUT).get_matches();
    run(&common::cli::backend(&args)?)
}

fn run(backend: &Backend) -> Result<Vec<ResultLine>, Box<dyn std::error::Error>> {
    println!("backend: {}", backend.describe());
    println!(
        "bolt L = {} m under σn = {} MPa: S_b L = {:.2} kN (yield {:.1} kN); pulled at {} m/s to {} mm",
        bp::LENGTH_FAILURE,
        bp::CONFINEMENT / 1e6,
        bp::capacity() / 1e3,
        bp::rebar().tensile_yield_force / 1e3,
        bp::PULL_VELOCITY,
        bp::PULL_DISTANCE * 1e3
    );
    println!(
        "{:>9} {:>9} {:>10} {:>10} {:>10} {:>9} {:>8} {:>8}",
        "segment_m", "segments", "peak/SL", "error", "end/peak", "F/F_yield", "steps", "wall_s"
    );
    let mut last = None;
    for size in bp::SIZES {
        let out = bp::run_failure(backend, &Params { size })?;
        println!(
            "{:>9.4} {:>9} {:>10.6} {:>10.3e} {:>10.6} {:>9.3} {:>8} {:>8.2}",
            size,
            out.segments,
            out.peak_ratio,
            out.error,
            out.end_ratio,
            out.axial_ratio,
            out.steps,
            out.wall_s
        );
        last = Some(out);
    }
    let out = last.expect("three sizes");
    if out.axial_ratio >= 1.0 {
        return Err("the bar yielded before the bond failed: the scene measures nothing".into());
    }
    let png = out_dir("bolt_pullout_failure")?.join("load_slip.png");
    let umax = bp::PULL_DISTANCE * 1e3;
    Plot::new(
        "Pull-out to failure: load against head displacement",
        "head displacement (mm)",
        "pull-out load (kN)",
    )
    .line(
        "FDEM",
        out.curve.iter().map(|c| c.0 * 1e3).collect(),
        out.curve.iter().map(|c| c.1 / 1e3).collect(),
    )
    .line(
        "S_b L",
        vec![0.0, umax],
        vec![bp::capacity() / 1e3, bp::capacity() / 1e3],
    )
    .save_png(&png)?;
    println!("plot: {}", png.display());
    Ok(vec![ResultLine::new(
        backend,
        "bolt_pullout_failure",
        "peak_over_SbL_error",
        out.error,
        bp::TOL_PEAK,
        out.segments,
        out.steps,
        out.wall_s,
    )])
}
