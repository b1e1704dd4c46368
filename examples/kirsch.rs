//! Validation scene 1 (Kirsch): a circular hole under far-field stress, solved by the
//! direct sparse solve and by dynamic relaxation at three mesh sizes.
//!
//! `cargo run --release --example kirsch` prints an error table, writes
//! `out/kirsch/kirsch.png` and the finest solutions as `out/kirsch/kirsch_*.pvd`
//! (open in ParaView: displacement, stress, principal stresses), and ends with one
//! RESULT line per solver.
//!
//! Backend: `--backend cpu|gpu` (default `cpu`, or `PCDC_BACKEND`) and, on the GPU,
//! `--precision f64|f32` (default f64 where the adapter supports it, or
//! `PCDC_PRECISION`); the RESULT lines carry `backend=` and `precision=`, e.g.
//! `cargo run --release --example kirsch -- --backend gpu --precision f32`. The direct
//! solve factorises on the host (faer) and is the same on both backends, so with
//! `--backend gpu` only dynamic relaxation runs (on the device) and the example ends
//! with its one RESULT line.
//!
//! Cells: `--element tri3|quad4|mixed` (default `tri3`): the graded triangle ring, a polar
//! grid of Quad4 cells, or the same grid alternating Quad4 and Tri3 cells; the RESULT
//! scene is then `kirsch_quad4` or `kirsch_mixed`.

mod common;

const ABOUT: &str = "Validation scene 1 (Kirsch): a circular hole under far-field stress, solved by the direct sparse solve and by dynamic relaxation at three mesh sizes";

use pcdc::compute::{Backend, BackendKind};
use pcdc_validation::plot::Plot;
use pcdc_validation::report::{out_dir, ResultLine};
use pcdc_validation::scenes::kirsch::{self, Params, Solver};
use pcdc_validation::scenes::Element;

fn main() {
    pcdc_validation::report::finish(choose())
}

/// Runs the scene on the backend named on the command line.
fn choose() -> Result<Vec<ResultLine>, Box<dyn std::error::Error>> {
    let args = common::cli::with_element(
        common::cli::command("kirsch", ABOUT),
        &["tri3", "quad4", "mixed"],
    )
    .get_matches();
    run(&common::cli::backend(&args)?, common::cli::element(&args)?)
}

fn run(backend: &Backend, element: Element) -> Result<Vec<ResultLine>, Box<dyn std::error::Error>> {
    println!("backend: {}", backend.describe());
    let full = Params {
        element,
        ..Params::full()
    };
    let scene = match element {
        Element::Simplex => "kirsch".to_string(),
        e => format!("kirsch_{}", e.name()),
    };
    println!("cells: {}", element.name());
    println!("Kirsch: hole radius a = {} m, ring to 25a, E = 50 GPa, nu = 0.25, P1 = 10 MPa (x), P2 = 5 MPa (y)", full.radius);
    println!(
        "{:>10} {:>10} {:>9} {:>10} {:>8} {:>9}",
        "solver", "size/a", "elements", "error", "steps", "wall_s"
    );
    let mut finals = Vec::new();
    let solvers: &[Solver] = match backend.kind() {
        BackendKind::Cpu => &[Solver::Direct, Solver::Relaxation],
        // The direct solve is a host solve, identical on both backends.
        BackendKind::Gpu => &[Solver::Relaxation],
    };
    for &solver in solvers {
        for size in [0.1, 0.05, full.size_at_hole] {
            let vtu_dir = (size == full.size_at_hole)
                .then(|| out_dir(&scene))
                .transpose()?;
            let p = Params {
                size_at_hole: size,
                vtu_dir,
                ..full.clone()
            };
            let out = kirsch::run(backend, &p, solver)?;
            println!(
                "{:>10} {:>10.3} {:>9} {:>10.4} {:>8} {:>9.3}",
                solver.name(),
                size,
                out.elements,
                out.error,
                out.steps,
                out.wall_s
            );
            if size == full.size_at_hole {
                finals.push(out);
            }
        }
    }
    let a = full.radius;
    let rs: Vec<f64> = (0..200).map(|i| 1.0 + 4.0 * i as f64 / 199.0).collect();
    let mut plot = Plot::new(
        "Kirsch: stresses along θ = 0 (compression positive)",
        "r / a",
        "stress (MPa)",
    )
    .line(
        "σθ exact (eq. 49)",
        rs.clone(),
        rs.iter().map(|r| kirsch::exact(r * a, a).0 / 1e6).collect(),
    )
    .line(
        "σr exact (eq. 50)",
        rs.clone(),
        rs.iter().map(|r| kirsch::exact(r * a, a).1 / 1e6).collect(),
    );
    for out in &finals {
        plot = plot
            .points(
                format!("σθ {}", out.solver.name()),
                out.r_over_a.clone(),
                out.sigma_theta.iter().map(|s| s / 1e6).collect(),
            )
            .points(
                format!("σr {}", out.solver.name()),
                out.r_over_a.clone(),
                out.sigma_r.iter().map(|s| s / 1e6).collect(),
            );
    }
    let png = out_dir(&scene)?.join(format!("{scene}.png"));
    plot.save_png(&png)?;
    println!("plot: {}", png.display());
    Ok(finals
        .iter()
        .map(|out| {
            ResultLine::new(
                backend,
                &scene,
                &format!("max_rel_err_{}", out.solver.name()),
                out.error,
                kirsch::TOL,
                out.elements,
                out.steps,
                out.wall_s,
            )
        })
        .collect())
}
