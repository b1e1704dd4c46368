//! Validation scene 15: elastic pull-out of a fully grouted rock bolt from a rigid
//! block, against F(x) = F0 sinh(β(L − x)) / sinh(βL) (manual 7.9), three segment
//! lengths.
//!
//! `cargo run --release --example bolt_pullout` prints an error table, writes
//! `out/bolt_pullout/axial_force.png` (axial force along the bolt over the closed form)
//! and ends with the RESULT line (finest segments). Backend: `--backend cpu|gpu`,
//! `--precision f64|f32`.

mod common;

const ABOUT: &str = "Validation scene 15: elastic pull-out of a fully grouted bolt";

use pcdc::compute::Backend;
use pcdc_validation::plot::Plot;
use pcdc_validation::report::{out_dir, ResultLine};
use pcdc_validation::scenes::bolt_pullout::{self as bp, Params};

fn main() {
    pcdc_validation::report::finish(choose())
}

fn choose() -> Result<Vec<ResultLine>, Box<dyn std::error::Error>> {
    let args = common::cli::command("bolt_pullout", ABOUT).get_matches();
    run(&common::cli::backend(&args)?)
}

fn run(backend: &Backend) -> Result<Vec<ResultLine>, Box<dyn std::error::Error>> {
    println!("backend: {}", backend.describe());
    println!(
        "bolt L = {} m, K = {:.2e} N/m/m, β = {:.4} 1/m (βL = {:.2}), F0 = {} kN",
        bp::LENGTH,
        bp::STIFFNESS,
        bp::beta(),
        bp::beta() * bp::LENGTH,
        bp::F0 / 1e3
    );
    println!(
        "{:>9} {:>9} {:>10} {:>8} {:>8}",
        "segment_m", "segments", "error", "steps", "wall_s"
    );
    let mut last = None;
    for size in bp::SIZES {
        let out = bp::run_elastic(backend, &Params { size })?;
        println!(
            "{:>9.4} {:>9} {:>10.3e} {:>8} {:>8.2}",
            size, out.segments, out.error, out.steps, out.wall_s
        );
        last = Some(out);
    }
    let out = last.expect("three sizes");
    let xs: Vec<f64> = (0..=200).map(|i| bp::LENGTH * i as f64 / 200.0).collect();
    let png = out_dir("bolt_pullout")?.join("axial_force.png");
    Plot::new(
        "Elastic pull-out: axial force along the bolt",
        "distance from the head x (m)",
        "axial force (kN)",
    )
    .line(
        "F0 sinh(β(L−x))/sinh(βL)",
        xs.clone(),
        xs.iter().map(|&x| bp::exact(x) / 1e3).collect(),
    )
    .points(
        "FDEM (segment midpoints)",
        out.profile.iter().map(|p| p.0).collect(),
        out.profile.iter().map(|p| p.1 / 1e3).collect(),
    )
    .save_png(&png)?;
    println!("plot: {}", png.display());
    Ok(vec![ResultLine::new(
        backend,
        "bolt_pullout",
        "max_err_F_over_F0",
        out.error,
        bp::TOL,
        out.segments,
        out.steps,
        out.wall_s,
    )])
}
