//! Biaxial compression series with servo-controlled confinement (the virtual rock
//! laboratory, issue 19): the UCS quick start's sample with its sides held at σ3 = 0, 5,
//! 10 and 20 MPa by servo walls (PI-controlled velocity, `pcdc::mech::StressServo`),
//! loaded axially to failure; the peaks give the Mohr-Coulomb envelope of the jointed
//! rock, compared with the joints' c and φ.
//!
//! `cargo run --release --example biaxial` (`--reduced` for the 5 mm mesh) prints each
//! test (σ3, peak σ1, the confining stress's largest deviation before the peak, broken
//! joints) and the fitted envelope, and writes `out/biaxial/biaxial.csv` and
//! `biaxial_envelope.png` (peaks and fitted line). The RESULT metric is the largest
//! deviation of the confining stress from σ3 up to 95 % of the peak over 1 %: ≤ 1 when
//! the servo held the confinement through the pre-peak of every test; the deviation in
//! the last 5 % before the peak, where the failure band forms, is printed beside it.

mod common;

use clap::{Arg, ArgAction};
use pcdc::compute::Backend;
use pcdc_validation::report::{out_dir, ResultLine};
use pcdc_validation::scenes::biaxial::{self, CONFINEMENT_TOL};

const ABOUT: &str = "Biaxial compression series with servo-controlled confinement: sigma3 = 0, 5, 10, 20 MPa on the UCS sample, Mohr-Coulomb envelope of the jointed rock";

fn main() {
    pcdc_validation::report::finish(choose())
}

fn choose() -> Result<Vec<ResultLine>, Box<dyn std::error::Error>> {
    let args = common::cli::command("biaxial", ABOUT)
        .arg(
            Arg::new("reduced")
                .long("reduced")
                .action(ArgAction::SetTrue)
                .help("5 mm mesh (the tests' size) instead of 2 mm"),
        )
        .get_matches();
    let p = if args.get_flag("reduced") {
        biaxial::Params::reduced()
    } else {
        biaxial::Params::full()
    };
    run(&common::cli::backend(&args)?, &p)
}

fn run(
    backend: &Backend,
    p: &biaxial::Params,
) -> Result<Vec<ResultLine>, Box<dyn std::error::Error>> {
    println!("backend: {}", backend.describe());
    println!(
        "sample {} x {} m, mesh {} m; joints c = {:.2} MPa, phi = {} deg, Ts = {:.2} MPa; servo response {:.1e} s",
        p.sample.sample.height,
        p.sample.sample.width,
        p.sample.sample.mesh_size,
        p.sample.joints.cohesion / 1e6,
        p.sample.joints.friction_deg,
        p.sample.joints.tensile_strength / 1e6,
        p.response_time
    );
    match &p.membrane {
        Some(m) => println!(
            "walls: {} per side, behind membranes {} mm thick, E = {} GPa",
            p.segments,
            1e3 * m.thickness,
            m.young / 1e9
        ),
        None => println!("walls: {} per side, on the rock", p.segments),
    }
    println!(
        "{:>10} {:>12} {:>16} {:>8} {:>18} {:>14} {:>8} {:>8}",
        "sigma3 MPa",
        "sigma1 MPa",
        "pre-peak dev %",
        "held %",
        "95-100 % peak dev %",
        "strain at peak",
        "broken",
        "wall s"
    );
    let out = biaxial::run(backend, p, &mut |t| {
        println!(
            "{:>10.2} {:>12.2} {:>16.3} {:>8.1} {:>18.3} {:>14.4e} {:>8} {:>8.1}",
            t.sigma3 / 1e6,
            t.sigma1 / 1e6,
            100.0 * t.deviation,
            100.0 * t.held,
            100.0 * t.deviation_at_failure,
            t.strain_at_peak,
            t.broken,
            t.outcome.wall_s
        );
    })?;
    println!(
        "envelope sigma1 = {:.3} sigma3 + {:.2} MPa (r2 = {:.4}): phi = {:.2} deg, c = {:.2} MPa; joints phi = {} deg, c = {:.2} MPa",
        out.slope,
        out.sigma_c / 1e6,
        out.r2,
        out.friction_deg,
        out.cohesion / 1e6,
        p.sample.joints.friction_deg,
        p.sample.joints.cohesion / 1e6
    );
    let dir = out_dir("biaxial")?;
    let mut csv = String::from("sigma3_pa,sigma1_pa,max_confinement_deviation_pre_peak,max_confinement_deviation_95_to_100pct_of_peak,strain_at_peak,broken_joints\n");
    for t in &out.tests {
        csv.push_str(&format!(
            "{},{},{},{},{},{}\n",
            t.sigma3, t.sigma1, t.deviation, t.deviation_at_failure, t.strain_at_peak, t.broken
        ));
    }
    std::fs::write(dir.join("biaxial.csv"), csv)?;
    let s3: Vec<f64> = out.tests.iter().map(|t| t.sigma3 / 1e6).collect();
    let s1: Vec<f64> = out.tests.iter().map(|t| t.sigma1 / 1e6).collect();
    let top = s3.iter().fold(0.0f64, |m, &v| m.max(v));
    pcdc_validation::plot::Plot::new(
        "Biaxial series: peak axial stress against confinement",
        "sigma3 (MPa)",
        "peak sigma1 (MPa)",
    )
    .points("peaks (servo-confined tests)", s3, s1)
    .line(
        format!(
            "Mohr-Coulomb fit: phi = {:.1} deg, c = {:.1} MPa",
            out.friction_deg,
            out.cohesion / 1e6
        ),
        vec![0.0, top],
        vec![
            out.sigma_c / 1e6,
            (out.sigma_c + out.slope * top * 1e6) / 1e6,
        ],
    )
    .save_png(dir.join("biaxial_envelope.png"))?;
    println!(
        "written: {}/biaxial.csv, biaxial_envelope.png",
        dir.display()
    );
    let steps = out.tests.iter().map(|t| t.outcome.steps).sum();
    let elements = out.tests.first().map_or(0, |t| t.outcome.elements);
    Ok(vec![ResultLine::new(
        backend,
        "biaxial",
        "max_confinement_deviation_over_1pct",
        out.max_deviation() / CONFINEMENT_TOL,
        1.0,
        elements,
        steps,
        out.wall_s,
    )])
}
