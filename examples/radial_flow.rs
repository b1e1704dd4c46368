//! Validation scene 9: steady radial flow in a ring (manual 7.5.5), 2D ring and 3D
//! thick-walled cylinder, three element sizes, against eq. 89.
//!
//! `cargo run --release --example radial_flow` prints an error table, writes
//! `out/radial_flow/radial_flow.png` (p/p_i of every flow node against r, over the closed
//! form) and ends with the RESULT line (worst of 2D and 3D at the finest size). Backend:
//! `--backend cpu|gpu`, `--precision f64|f32`.

mod common;

const ABOUT: &str = "Validation scene 9: steady radial flow in a ring, 2D and 3D, three sizes";

use pcdc::compute::Backend;
use pcdc_validation::plot::Plot;
use pcdc_validation::report::{out_dir, ResultLine};
use pcdc_validation::scenes::radial_flow::{self, Params, SIZES};

fn main() {
    pcdc_validation::report::finish(choose())
}

fn choose() -> Result<Vec<ResultLine>, Box<dyn std::error::Error>> {
    let args = common::cli::command("radial_flow", ABOUT).get_matches();
    run(&common::cli::backend(&args)?)
}

fn run(backend: &Backend) -> Result<Vec<ResultLine>, Box<dyn std::error::Error>> {
    println!("backend: {}", backend.describe());
    println!(
        "ring r_i = {} m, r_o = {} m, p_i = {} MPa, p_o = {} MPa, water, virtual aperture 10 µm",
        radial_flow::R_IN,
        radial_flow::R_OUT,
        radial_flow::P_IN * 1e-6,
        radial_flow::P_OUT * 1e-6
    );
    println!(
        "{:>4} {:>8} {:>9} {:>9} {:>10} {:>10} {:>8} {:>8}",
        "dim", "size_m", "elements", "channels", "error", "balance", "steps", "wall_s"
    );
    let mut finals = Vec::new();
    for size in SIZES {
        let p = Params { size };
        for (dim, out) in [
            ("2d", radial_flow::run_2d(backend, &p)?),
            ("3d", radial_flow::run_3d(backend, &p)?),
        ] {
            println!(
                "{:>4} {:>8.4} {:>9} {:>9} {:>10.3e} {:>10.1e} {:>8} {:>8.3}",
                dim,
                size,
                out.elements,
                out.channels,
                out.error,
                out.balance,
                out.steps,
                out.wall_s
            );
            if size == Params::full().size {
                finals.push((dim, out));
            }
        }
    }
    let rr: Vec<f64> = (0..=100)
        .map(|i| radial_flow::R_IN + (radial_flow::R_OUT - radial_flow::R_IN) * i as f64 / 100.0)
        .collect();
    let (_, o) = &finals[0];
    let plot = Plot::new("Steady radial flow in a ring (2D)", "r (m)", "p / p_i")
        .line(
            "exact, eq. 89",
            rr.clone(),
            rr.iter()
                .map(|&r| radial_flow::exact(r) / radial_flow::P_IN)
                .collect(),
        )
        .points("FDEM flow nodes", o.r.clone(), o.p.clone());
    let png = out_dir("radial_flow")?.join("radial_flow.png");
    plot.save_png(&png)?;
    println!("plot: {}", png.display());
    let worst = finals
        .iter()
        .max_by(|a, b| a.1.error.total_cmp(&b.1.error))
        .expect("two runs");
    Ok(vec![ResultLine::new(
        backend,
        "radial_flow",
        "max_err_p_over_dp",
        worst.1.error,
        radial_flow::TOL,
        finals.iter().map(|f| f.1.elements).sum(),
        finals.iter().map(|f| f.1.steps).sum(),
        finals.iter().map(|f| f.1.wall_s).sum(),
    )])
}
