//! Validation scene 11: transient flow along one open fracture (manual 7.5.7), 2D and 3D,
//! three channel sizes, against Carslaw & Jaeger's series (eq. 91–92 corrected).
//!
//! `cargo run --release --example fracture_flow` prints an error table, writes
//! `out/fracture_flow/fracture_flow.png` (p/p_A at x = L/2 and x = L against T = D t/L²,
//! numerical points over the closed form) and ends with the RESULT line (worst of 2D and
//! 3D at the finest size). Backend: `--backend cpu|gpu`, `--precision f64|f32`.

mod common;

const ABOUT: &str =
    "Validation scene 11: transient flow along one open fracture, 2D and 3D, three sizes";

use pcdc::compute::Backend;
use pcdc_validation::plot::Plot;
use pcdc_validation::report::{out_dir, ResultLine};
use pcdc_validation::scenes::fracture_flow::{self, Params, LENGTH};

fn main() {
    pcdc_validation::report::finish(choose())
}

fn choose() -> Result<Vec<ResultLine>, Box<dyn std::error::Error>> {
    let args = common::cli::command("fracture_flow", ABOUT).get_matches();
    run(&common::cli::backend(&args)?)
}

fn run(backend: &Backend) -> Result<Vec<ResultLine>, Box<dyn std::error::Error>> {
    println!("backend: {}", backend.describe());
    println!(
        "fracture L = {LENGTH} m, aperture {} mm, water, p_A = {} MPa held at x = 0: D = {:.1} m²/s",
        fracture_flow::APERTURE * 1e3,
        fracture_flow::P_A * 1e-6,
        fracture_flow::diffusivity()
    );
    println!(
        "{:>4} {:>8} {:>9} {:>9} {:>10} {:>10} {:>7} {:>8}",
        "dim", "size_m", "elements", "channels", "error", "balance", "steps", "wall_s"
    );
    let full = Params::full();
    let mut finals = Vec::new();
    for size in [4.0 * full.size, 2.0 * full.size, full.size] {
        let p = Params { size };
        for (dim, out) in [
            ("2d", fracture_flow::run_2d(backend, &p)?),
            ("3d", fracture_flow::run_3d(backend, &p)?),
        ] {
            println!(
                "{:>4} {:>8.4} {:>9} {:>9} {:>10.3e} {:>10.1e} {:>7} {:>8.3}",
                dim,
                size,
                out.elements,
                out.channels,
                out.error,
                out.balance,
                out.steps,
                out.wall_s
            );
            if size == full.size {
                finals.push((dim, out));
            }
        }
    }
    // The speed option: K_f scaled, the same physical times, the unscaled closed form.
    println!(
        "\nK_f scaled (2D, size {} m), compared at the same physical times:",
        full.size
    );
    println!(
        "{:>8} {:>10} {:>8} {:>8}",
        "scale", "error", "steps", "wall_s"
    );
    for scale in [1.0, 0.5, 0.1] {
        let o = fracture_flow::run_2d_bulk_scaled(backend, &full, scale)?;
        println!(
            "{:>8} {:>10.3e} {:>8} {:>8.3}",
            scale, o.error, o.steps, o.wall_s
        );
    }
    let (_, o) = &finals[0];
    let tt: Vec<f64> = (0..=200).map(|i| i as f64 / 200.0).collect();
    let every = (o.t.len() / 60).max(1);
    let pick = |v: &[f64]| v.iter().step_by(every).copied().collect::<Vec<f64>>();
    let plot = Plot::new(
        "Transient flow along a fracture (2D)",
        "T = D t / L²",
        "p / p_A",
    )
    .line(
        "exact, x = L/2",
        tt.clone(),
        tt.iter()
            .map(|&t| fracture_flow::exact(0.5 * LENGTH, t))
            .collect(),
    )
    .line(
        "exact, x = L",
        tt.clone(),
        tt.iter()
            .map(|&t| fracture_flow::exact(LENGTH, t))
            .collect(),
    )
    .points("FDEM x = L/2", pick(&o.t), pick(&o.p_mid))
    .points("FDEM x = L", pick(&o.t), pick(&o.p_end));
    let png = out_dir("fracture_flow")?.join("fracture_flow.png");
    plot.save_png(&png)?;
    println!("plot: {}", png.display());
    let worst = finals
        .iter()
        .max_by(|a, b| a.1.error.total_cmp(&b.1.error))
        .expect("two runs");
    Ok(vec![ResultLine::new(
        backend,
        "fracture_flow",
        "max_err_p_over_pA",
        worst.1.error,
        fracture_flow::TOL,
        finals.iter().map(|f| f.1.elements).sum(),
        finals.iter().map(|f| f.1.steps).sum(),
        finals.iter().map(|f| f.1.wall_s).sum(),
    )])
}
