//! Validation scene 12: fluid injection into rock under anisotropic in-situ stress, a
//! hydraulic fracture (manual 7.5.8).
//!
//! `cargo run --release --example injection` prints the breakdown pressure, the
//! fracture's length and orientation and the mass balance, writes
//! `out/injection/history.csv` (time, injection pressure, injected volume, balance
//! terms, fracture length, largest aperture), `out/injection/injection.png` (injection
//! pressure and fracture length against time), the flow network as a ParaView series
//! (`out/injection/network.pvd`), and ends with RESULT lines. Backend:
//! `--backend cpu|gpu`, `--precision f64|f32`.

mod common;

const ABOUT: &str = "Validation scene 12: fluid injection under anisotropic in-situ stress";

use pcdc::compute::Backend;
use pcdc_validation::plot::Plot;
use pcdc_validation::report::{out_dir, ResultLine};
use pcdc_validation::scenes::injection::{self as scene, Params};

fn main() {
    pcdc_validation::report::finish(choose())
}

fn choose() -> Result<Vec<ResultLine>, Box<dyn std::error::Error>> {
    let args = common::cli::command("injection", ABOUT).get_matches();
    run(&common::cli::backend(&args)?)
}

fn run(backend: &Backend) -> Result<Vec<ResultLine>, Box<dyn std::error::Error>> {
    println!("backend: {}", backend.describe());
    let p = Params::full();
    println!(
        "disc r = {} m, sigma_x = {} MPa, sigma_y = {} MPa, T_s = {} MPa, Q = {:e} m²/s for {} s, {} cm elements",
        scene::RADIUS,
        scene::SIGMA_X * 1e-6,
        scene::SIGMA_Y * 1e-6,
        scene::TENSILE * 1e-6,
        scene::RATE,
        p.duration,
        p.size * 100.0
    );
    let dir = out_dir("injection")?;
    let o = scene::run_with_output(backend, &p, Some(&dir))?;
    println!(
        "elements {}, channels {}, steps {}, wall {:.1} s",
        o.elements, o.channels, o.steps, o.wall_s
    );
    println!(
        "breakdown pressure {:.3} MPa (highest of {} samples {:.3} MPa, at t = {:.4e} s; |sigma_min| = {} MPa)",
        o.breakdown * 1e-6,
        p.samples,
        o.sampled_peak * 1e-6,
        o.breakdown_time,
        scene::SIGMA_Y.abs() * 1e-6
    );
    println!(
        "fracture: length {:.3} m along x, extent {:.3} m across; balance {:.1e}",
        o.length, o.width, o.balance
    );
    let h = &o.history;
    println!(
        "{:>10} {:>10} {:>12} {:>10} {:>12}",
        "t_s", "p_MPa", "injected_m2", "length_m", "aperture_m"
    );
    let n = h.column(0).len();
    for i in (0..n).step_by((n / 10).max(1)) {
        println!(
            "{:>10.3e} {:>10.4} {:>12.4e} {:>10.3} {:>12.4e}",
            h.column(0)[i],
            h.column(1)[i] * 1e-6,
            h.column(2)[i],
            h.column(7)[i],
            h.column(8)[i]
        );
    }
    h.write_csv(dir.join("history.csv"))?;
    let t: Vec<f64> = h.column(0).iter().map(|t| t * 1e3).collect();
    let plot = Plot::new(
        "Fluid injection: pressure and fracture length",
        "t (ms)",
        "p (MPa), length (dm)",
    )
    .points(
        "injection pressure (MPa)",
        t.clone(),
        h.column(1).iter().map(|p| p * 1e-6).collect(),
    )
    .points(
        "fracture length (dm)",
        t,
        h.column(7).iter().map(|l| l * 10.0).collect(),
    );
    let png = dir.join("injection.png");
    plot.save_png(&png)?;
    println!("plot: {}", png.display());
    let line = |metric: &str, value: f64, tol: f64| {
        ResultLine::new(
            backend,
            "injection",
            metric,
            value,
            tol,
            o.elements,
            o.steps,
            o.wall_s,
        )
    };
    Ok(vec![
        line("width_over_length", o.orientation(), scene::ORIENTATION_TOL),
        line(
            "min_stress_over_breakdown",
            o.min_stress_over_breakdown(),
            1.0,
        ),
        line("mass_balance_rel", o.balance, scene::BALANCE_TOL),
    ])
}
