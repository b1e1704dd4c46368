//! Thermally driven cracking of a ring with weak joints (manual 7.6.10): the inner
//! surface is heated, the outer one held, and radial cracks open from the outer surface
//! where the closed-form hoop tension first reaches the joints' tensile strength.
//!
//! `cargo run --release --example thermal_cracking` runs three element sizes and prints,
//! for each, the closed-form normal traction σ_n on the first joint to soften (from the
//! computed temperature field, at that joint's radius and direction) over T_s, the
//! closed-form σ_θ(r_o)/T_s at that moment, where the joint is, and the crack count; then it
//! reruns the coarsest size with twice slower loading to show the onset is
//! quasi-static. It writes `out/thermal_cracking/cracks.png` (broken joints at four
//! times, finest size), `out/thermal_cracking/onset.png` (σ_θ(r_o)/T_s and the onset
//! against time) and ends with the RESULT line (|σ_θ(r_o)/T_s − 1| at the onset, finest
//! size; infinite if the first joint is not at the outer surface). Backend: `--backend cpu|gpu`, `--precision f64|f32`.

mod common;

const ABOUT: &str = "Thermal cracking of a heated ring with weak joints (manual 7.6.10)";

use pcdc::compute::Backend;
use pcdc_validation::plot::Plot;
use pcdc_validation::report::{out_dir, ResultLine};
use pcdc_validation::scenes::thermal_cracking::{self as tc, Params};

fn main() {
    pcdc_validation::report::finish(choose())
}

fn choose() -> Result<Vec<ResultLine>, Box<dyn std::error::Error>> {
    let args = common::cli::command("thermal_cracking", ABOUT).get_matches();
    run(&common::cli::backend(&args)?)
}

fn run(backend: &Backend) -> Result<Vec<ResultLine>, Box<dyn std::error::Error>> {
    println!("backend: {}", backend.describe());
    println!(
        "ring r_i = {} m, r_o = {} m, outer held at {} °C, joints T_s = {} MPa; steady ΔT_c = {:.2} K, \
         L²/κ = {:.0} s",
        tc::R_IN,
        tc::R_OUT,
        tc::T_OUT,
        tc::TS * 1e-6,
        tc::delta_t_crit(),
        tc::diffusion_time()
    );
    println!(
        "{:>7} {:>8} {:>7} {:>9} {:>8} {:>9} {:>8} {:>8} {:>7} {:>8} {:>8}  thermal schedule",
        "size_m",
        "elements",
        "joints",
        "σθ/Ts",
        "error",
        "ΔTi/ΔTc",
        "r_on_m",
        "tilt_deg",
        "broken",
        "steps",
        "wall_s"
    );
    let line = |p: &Params, o: &tc::Outcome| {
        println!(
            "{:>7.4} {:>8} {:>7} {:>9.4} {:>8.4} {:>10.4} {:>9.3} {:>8.4} {:>8.1} {:>7} {:>8} {:>8.1}  {} \
             (transits {}, density {:.3e} kg/m³)",
            p.size,
            o.elements,
            o.joints,
            o.onset_ratio,
            o.error,
            o.outer_ratio,
            o.onset_rise,
            o.onset_radius,
            o.onset_tilt_deg,
            o.snapshots.last().map_or(0, |s| s.broken.len()),
            o.steps,
            o.wall_s,
            o.every,
            p.transits,
            o.scaled_density
        );
    };
    let mut last = None;
    let mut first = None;
    for size in tc::SIZES {
        let p = Params::new(size);
        let o = tc::run(backend, &p)?;
        line(&p, &o);
        if first.is_none() {
            first = Some(o.onset_ratio);
        }
        last = Some(o);
    }
    // The loading rate: the coarsest size again, twice as slow.
    let mut slow = Params::new(tc::SIZES[0]);
    slow.transits *= 2.0;
    let o_slow = tc::run(backend, &slow)?;
    line(&slow, &o_slow);
    println!(
        "twice slower loading moves the onset ratio by {:+.4}",
        o_slow.onset_ratio - first.expect("three sizes")
    );
    let o = last.expect("three sizes");
    println!(
        "first softening joint at r = {:.4} m (closed-form σ_θ peak at r = {:.4} m), {:.1}° from radial",
        o.onset_radius, o.peak_radius, o.onset_tilt_deg
    );
    for s in &o.snapshots {
        println!(
            "  t = {:>6.0} s  inner rise {:>6.2} K  broken joints {:>5}  softening {:>5}",
            s.time,
            s.inner_rise,
            s.broken.len(),
            s.softening
        );
    }
    let dir = out_dir("thermal_cracking")?;
    let circle = |r: f64| {
        let n = 200;
        let a: Vec<f64> = (0..=n)
            .map(|i| 2.0 * std::f64::consts::PI * i as f64 / n as f64)
            .collect();
        (
            a.iter().map(|t| r * t.cos()).collect::<Vec<_>>(),
            a.iter().map(|t| r * t.sin()).collect::<Vec<_>>(),
        )
    };
    let (xi, yi) = circle(tc::R_IN);
    let (xo, yo) = circle(tc::R_OUT);
    let mut plot = Plot::new(
        "Thermal cracking: broken joints over time",
        "x (m)",
        "y (m)",
    )
    .size(900, 900)
    .line("r_i", xi, yi)
    .line("r_o", xo, yo);
    // Latest first, so the earlier (fewer) cracks are drawn on top.
    for s in o.snapshots.iter().rev().filter(|s| !s.broken.is_empty()) {
        plot = plot.points(
            format!("t = {:.0} s, ΔT_i = {:.1} K", s.time, s.inner_rise),
            s.broken.iter().map(|p| p[0]).collect(),
            s.broken.iter().map(|p| p[1]).collect(),
        );
    }
    let cracks = dir.join("cracks.png");
    plot.save_png(&cracks)?;
    let t_on = o.history.iter().find(|h| h[2] > 0.0).map_or(0.0, |h| h[0]);
    let onset = Plot::new(
        "Thermal cracking: closed-form hoop stress at r_o",
        "time (s)",
        "σ_θ(r_o) / T_s",
    )
    .line(
        "σ_θ(r_o)/T_s of the computed T field",
        o.history.iter().map(|h| h[0]).collect(),
        o.history.iter().map(|h| h[1]).collect(),
    )
    .line(
        "T_s",
        vec![0.0, o.history.last().map_or(1.0, |h| h[0])],
        vec![1.0, 1.0],
    )
    .line("first joint softens", vec![t_on, t_on], vec![0.0, 1.5]);
    let onset_png = dir.join("onset.png");
    onset.save_png(&onset_png)?;
    println!("plots: {}, {}", cracks.display(), onset_png.display());
    if !o.located {
        println!(
            "the first softening joint is not within two sizes of the closed-form peak radius"
        );
    }
    Ok(vec![ResultLine::new(
        backend,
        "thermal_cracking",
        "onset_traction_over_ts_error",
        if o.located { o.error } else { f64::INFINITY },
        tc::TOL,
        o.elements,
        o.steps,
        o.wall_s,
    )])
}
