//! A bolted direct shear test (issue 18): the shear force of a frictional joint crossed
//! by an inclined grouted bolt against T = (σn A + P sin θ) tan φ + P cos θ, with the
//! bolt yielding in tension as the joint slides; three element sizes.
//!
//! `cargo run --release --example bolted_shear` prints a table, writes
//! `out/bolted_shear/shear.png` (shear force and bolt force against shear displacement,
//! with the closed form) and ends with the RESULT line (finest size). Backend:
//! `--backend cpu|gpu`, `--precision f64|f32`.

mod common;

const ABOUT: &str = "Bolted direct shear: dowel contribution of an inclined grouted bolt";

use pcdc::compute::Backend;
use pcdc_validation::plot::Plot;
use pcdc_validation::report::{out_dir, ResultLine};
use pcdc_validation::scenes::bolted_shear::{self as bs, Params};

fn main() {
    pcdc_validation::report::finish(choose())
}

fn choose() -> Result<Vec<ResultLine>, Box<dyn std::error::Error>> {
    let args = common::cli::command("bolted_shear", ABOUT).get_matches();
    run(&common::cli::backend(&args)?)
}

fn run(backend: &Backend) -> Result<Vec<ResultLine>, Box<dyn std::error::Error>> {
    println!("backend: {}", backend.describe());
    println!(
        "joint φ = {}°, σn = {} MPa over {} m; bolt θ = {}°, yield {} kN; sheared {} mm",
        bs::FRICTION,
        bs::SIGMA_N / 1e6,
        bs::LENGTH,
        bs::THETA,
        bs::bolt_props().tensile_yield_force / 1e3,
        bs::SHEAR * 1e3
    );
    println!(
        "{:>8} {:>9} {:>10} {:>8} {:>10} {:>10} {:>8} {:>8}",
        "size_m", "elements", "error", "yielded", "T_end_kN", "P_end_kN", "steps", "wall_s"
    );
    let mut last = None;
    for size in bs::SIZES {
        let out = bs::run(backend, &Params::new(size))?;
        let end = out.samples.last().copied().expect("samples");
        println!(
            "{:>8.4} {:>9} {:>10.3e} {:>8} {:>10.2} {:>10.2} {:>8} {:>8.2}",
            size,
            out.elements,
            out.error,
            out.yielded,
            end.force / 1e3,
            end.bolt_force / 1e3,
            out.steps,
            out.wall_s
        );
        last = Some(out);
    }
    let out = last.expect("three sizes");
    println!("finest size, window means from {} mm:", bs::FROM * 1e3);
    println!(
        "{:>8} {:>10} {:>10} {:>10} {:>10}",
        "from_mm", "T_kN", "exact_kN", "P_kN", "err_share"
    );
    let base = bs::SIGMA_N * bs::LENGTH * bs::FRICTION.to_radians().tan();
    for w in &out.windows {
        println!(
            "{:>8.2} {:>10.2} {:>10.2} {:>10.2} {:>10.4}",
            w[0] * 1e3,
            w[1] / 1e3,
            w[2] / 1e3,
            w[3] / 1e3,
            (w[1] - w[2]) / (w[2] - base)
        );
    }
    let mm: Vec<f64> = out.samples.iter().map(|s| s.shear * 1e3).collect();
    let png = out_dir("bolted_shear")?.join("shear.png");
    Plot::new(
        "Bolted direct shear",
        "shear displacement (mm)",
        "force (kN per m)",
    )
    .line(
        "shear force T (FDEM)",
        mm.clone(),
        out.samples.iter().map(|s| s.force / 1e3).collect(),
    )
    .points(
        "(σn A + P sin θ) tan φ + P cos θ",
        mm.clone(),
        out.samples.iter().map(|s| s.exact / 1e3).collect(),
    )
    .line(
        "bolt axial force P",
        mm,
        out.samples.iter().map(|s| s.bolt_force / 1e3).collect(),
    )
    .save_png(&png)?;
    println!("plot: {}", png.display());
    if !out.yielded {
        return Err("the bolt did not yield: the test stops too early".into());
    }
    Ok(vec![ResultLine::new(
        backend,
        "bolted_shear",
        "max_err_T_over_bolt_share",
        out.error,
        bs::TOL,
        out.elements,
        out.steps,
        out.wall_s,
    )])
}
