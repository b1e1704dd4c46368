//! Validation scene 6: a slope cut in three 5 m benches under gravity, Mohr–Coulomb soil
//! on Quad4 cells, with the null model (manual 7.2.4, 7.2.8).
//!
//! `cargo run --release --example slope_excavation` runs the scene at 2.5 m and 1 m
//! cells, prints the far-field geostatic stress error before excavation and, per stage,
//! the floor heave, the largest displacement and the yielded cells; writes
//! `out/slope_excavation/slope_excavation_displacement.png` (vertical displacement of
//! the free surface after each stage), `out/slope_excavation/slope_excavation_plastic.png`
//! (centroids of the cells that have yielded, per stage, with the cut outline) and the
//! VTU series `out/slope_excavation/slope_excavation.pvd` of the 1 m run (one step per
//! stage; null cells have zero stress, `model_state_1` marks shear yield); ends with the
//! RESULT line (far-field σv = ρ g depth and σh = K0 σv, tolerance 2 %, the worse of
//! the regular 1 m grid and the same grid with its interior nodes moved by up to 10 %).
//!
//! Backend: `--backend cpu|gpu`, `--precision f64|f32` (see `--help`).

mod common;

const ABOUT: &str = "Validation scene 6: slope excavated in three stages under gravity, Mohr-Coulomb on Quad4 cells";

use pcdc::compute::Backend;
use pcdc_validation::plot::Plot;
use pcdc_validation::report::{out_dir, ResultLine};
use pcdc_validation::scenes::slope_excavation::{self, Params};

fn main() {
    pcdc_validation::report::finish(choose())
}

fn choose() -> Result<Vec<ResultLine>, Box<dyn std::error::Error>> {
    let args = common::cli::command("slope_excavation", ABOUT).get_matches();
    run(&common::cli::backend(&args)?)
}

fn run(backend: &Backend) -> Result<Vec<ResultLine>, Box<dyn std::error::Error>> {
    println!("backend: {}", backend.describe());
    println!(
        "layer {} x {} m, c = 40 kPa, phi = 30 deg, K0 = {}, cut 45 deg in {} benches of 5 m",
        slope_excavation::WIDTH,
        slope_excavation::HEIGHT,
        slope_excavation::K0,
        slope_excavation::STAGES
    );
    let full = Params::full();
    let mut last = None;
    for size in [2.5, full.size] {
        let vtu_dir = (size == full.size)
            .then(|| out_dir("slope_excavation"))
            .transpose()?;
        let p = Params {
            size,
            vtu_dir,
            distortion: 0.0,
        };
        let out = slope_excavation::run(backend, &p)?;
        println!(
            "cells {:>5} ({size} m): far-field stress error {:.3e}, unbalanced ratio {:.1e}, {} steps, {:.2} s",
            out.cells, out.error, out.initial_ratio, out.steps, out.wall_s
        );
        println!(
            "{:>8} {:>12} {:>12} {:>8} {:>7}",
            "depth_m", "heave_mm", "max_u_mm", "yielded", "steps"
        );
        for s in &out.stages {
            println!(
                "{:>8.1} {:>12.3} {:>12.3} {:>8} {:>7}",
                s.depth,
                s.floor_heave * 1e3,
                s.max_displacement * 1e3,
                s.yielded_cells,
                s.steps
            );
        }
        last = Some(out);
    }
    let out = last.expect("two runs");
    // The geostatic check again on cells that are not rectangles (interior nodes moved
    // by up to 10 % of the cell size).
    let bent = slope_excavation::run(
        backend,
        &Params {
            distortion: 0.1,
            ..full.clone()
        },
    )?;
    println!(
        "distorted cells (10 %): far-field stress error {:.3e}, cut floor heave after stage 3 {:.3} mm",
        bent.error,
        bent.stages.last().map_or(0.0, |s| s.floor_heave * 1e3)
    );
    let dir = out_dir("slope_excavation")?;
    let mut disp = Plot::new(
        "Slope excavation: vertical displacement of the free surface",
        "x (m)",
        "u_y (mm)",
    );
    let mut plastic = Plot::new(
        "Slope excavation: cells that have yielded (centroids)",
        "x (m)",
        "y (m)",
    );
    let h = slope_excavation::HEIGHT;
    for s in &out.stages {
        let label = format!("stage {} ({} m)", (s.depth / 5.0).round(), s.depth);
        disp = disp.line_points(
            label.clone(),
            s.surface.iter().map(|p| p.0).collect(),
            s.surface.iter().map(|p| p.1 * 1e3).collect(),
        );
        plastic = plastic.points(
            label,
            s.yielded.iter().map(|c| c[0]).collect(),
            s.yielded.iter().map(|c| c[1]).collect(),
        );
    }
    let floor = h - 5.0 * slope_excavation::STAGES as f64;
    plastic = plastic.line(
        "cut outline",
        vec![0.0, 55.0 - h, 55.0 - floor, slope_excavation::WIDTH],
        vec![h, h, floor, floor],
    );
    for (plot, name) in [(disp, "displacement"), (plastic, "plastic")] {
        let png = dir.join(format!("slope_excavation_{name}.png"));
        plot.save_png(&png)?;
        println!("plot: {}", png.display());
    }
    Ok(vec![ResultLine::new(
        backend,
        "slope_excavation",
        "max_rel_err_geostatic_stress",
        out.error.max(bent.error),
        slope_excavation::TOL,
        2 * out.cells,
        out.steps,
        out.wall_s,
    )])
}
