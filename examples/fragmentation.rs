//! Hard case: a jointed rock block thrown into a closed box shatters and its fragments
//! fly, spin and collide for 100 000 steps (issue "correctness first").
//!
//! `cargo run --release --example fragmentation` prints the energy balance and the
//! deepest penetration at each check, writes `out/fragmentation/fragmentation.png`
//! (energy excess and penetration against step, with their tolerances) and ends with
//! two RESULT lines: the worst energy excess (total energy minus the initial energy and
//! the external work, relative to the reference energy; tolerance 1 %) and the deepest
//! penetration of a node into a foreign element (relative to its size; tolerance 5 %).
//!
//! Backend: `--backend cpu|gpu` (default `cpu`, or `PCDC_BACKEND`) and, on the GPU,
//! `--precision f64|f32` (`PCDC_PRECISION`).

mod common;

const ABOUT: &str = "Hard case: a jointed rock block thrown into a closed box shatters and its fragments fly, spin and collide for 100 000 steps (issue \"correctness first\")";

use pcdc::compute::Backend;
use pcdc_validation::plot::Plot;
use pcdc_validation::report::{out_dir, ResultLine};
use pcdc_validation::scenes::fragmentation::{self, Params, ENERGY_TOL, PENETRATION_TOL};

fn main() {
    pcdc_validation::report::finish(choose())
}

/// Runs the scene on the backend named on the command line.
fn choose() -> Result<Vec<ResultLine>, Box<dyn std::error::Error>> {
    let args = common::cli::command("fragmentation", ABOUT).get_matches();
    run(&common::cli::backend(&args)?)
}

fn run(backend: &Backend) -> Result<Vec<ResultLine>, Box<dyn std::error::Error>> {
    println!("backend: {}", backend.describe());
    let p = Params::default();
    println!(
        "Jointed block (mesh {} m) thrown into a closed box: {} steps, checks every {}",
        p.size, p.steps, p.check_every
    );
    let o = fragmentation::run(backend, &p)?;
    println!(
        "{:>8} {:>14} {:>14}",
        "step", "energy_excess", "penetration"
    );
    for (step, e, pen) in o.history.iter().step_by(5) {
        println!("{step:>8} {e:>14.3e} {pen:>14.3e}");
    }
    println!(
        "elements {}, joints {} ({} broken), dt {:.3e} s, wall {:.1} s",
        o.elements, o.joints, o.broken, o.dt, o.wall_s
    );
    println!(
        "energy (J/m): initial {:.4e}, external work {:.4e}, kinetic at the end {:.4e}",
        o.initial_energy, o.external_work, o.final_kinetic
    );
    for (name, d) in &o.dissipated {
        println!("  dissipated by {name}: {d:.4e}");
    }
    println!(
        "worst energy excess {:.3e} (step {}), deepest penetration {:.3e}",
        o.worst_energy_excess, o.worst_step, o.worst_penetration
    );
    let steps: Vec<f64> = o.history.iter().map(|h| h.0 as f64).collect();
    let plot = Plot::new(
        "Fragmentation in a box: energy excess and penetration",
        "step",
        "relative value",
    )
    .points(
        "energy excess / reference",
        steps.clone(),
        o.history.iter().map(|h| h.1).collect(),
    )
    .points(
        "penetration / element size",
        steps.clone(),
        o.history.iter().map(|h| h.2).collect(),
    )
    .line(
        "energy tolerance",
        vec![0.0, p.steps as f64],
        vec![ENERGY_TOL; 2],
    )
    .line(
        "penetration tolerance",
        vec![0.0, p.steps as f64],
        vec![PENETRATION_TOL; 2],
    );
    let png = out_dir("fragmentation")?.join("fragmentation.png");
    plot.save_png(&png)?;
    println!("plot: {}", png.display());
    let line = |metric: &str, value: f64, tol: f64| {
        ResultLine::new(
            backend,
            "fragmentation",
            metric,
            value,
            tol,
            o.elements,
            o.steps,
            o.wall_s,
        )
    };
    Ok(vec![
        line("max_penetration", o.worst_penetration, PENETRATION_TOL),
        line("max_energy_excess", o.worst_energy_excess, ENERGY_TOL),
    ])
}
