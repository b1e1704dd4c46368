//! A circular tunnel in jointed rock under 10 MPa in-situ stress, unsupported and with
//! a pattern of 12 radial grouted bolts (issue 18): wall convergence, broken joints and
//! bolt forces compared (no closed form).
//!
//! `cargo run --release --example tunnel_bolts` prints both runs, writes
//! `out/tunnel_bolts/convergence.png` (wall convergence around the opening, both runs)
//! and `out/tunnel_bolts/bolt_force.png` (axial force along one bolt), and ends with a
//! RESULT line whose value is the bolted over the unsupported mean convergence (it
//! passes when the bolts reduce it). `--size` sets the element size at the wall (m,
//! default 0.05). Backend: `--backend cpu|gpu`, `--precision f64|f32`.

mod common;

const ABOUT: &str = "Tunnel in jointed rock with and without rock bolts";

use clap::Arg;
use pcdc::compute::Backend;
use pcdc_validation::plot::Plot;
use pcdc_validation::report::{out_dir, ResultLine};
use pcdc_validation::scenes::tunnel_bolts::{self as tb, Params};

fn main() {
    pcdc_validation::report::finish(choose())
}

fn choose() -> Result<Vec<ResultLine>, Box<dyn std::error::Error>> {
    let args = common::cli::command("tunnel_bolts", ABOUT)
        .arg(
            Arg::new("size")
                .long("size")
                .value_parser(clap::value_parser!(f64))
                .default_value("0.05")
                .help("Element size at the wall (m)"),
        )
        .get_matches();
    let size = *args.get_one::<f64>("size").expect("default");
    run(&common::cli::backend(&args)?, size)
}

fn run(backend: &Backend, size: f64) -> Result<Vec<ResultLine>, Box<dyn std::error::Error>> {
    println!("backend: {}", backend.describe());
    println!(
        "opening a = {} m, p0 = {} MPa, jointed to r = {} m, element size {} m at the wall; {} bolts of {} m",
        tb::RADIUS,
        tb::P0 / 1e6,
        tb::JOINTED,
        size,
        tb::BOLTS,
        tb::BOLT_LENGTH
    );
    let free = tb::run(
        backend,
        &Params {
            size,
            bolted: false,
        },
    )?;
    let held = tb::run(backend, &Params { size, bolted: true })?;
    println!(
        "{:>10} {:>14} {:>14} {:>8} {:>14} {:>14} {:>8} {:>8}",
        "run",
        "mean_conv_mm",
        "max_conv_mm",
        "broken",
        "bolt_max_kN",
        "bolt_mean_kN",
        "steps",
        "wall_s"
    );
    for (name, o) in [("unbolted", &free), ("bolted", &held)] {
        println!(
            "{:>10} {:>14.4} {:>14.4} {:>8} {:>14.1} {:>14.1} {:>8} {:>8.1}",
            name,
            o.mean_convergence * 1e3,
            o.max_convergence * 1e3,
            o.broken,
            o.bolt_max / 1e3,
            o.bolt_mean / 1e3,
            o.steps,
            o.wall_s
        );
    }
    println!("joints in the jointed zone: {}", free.joints);
    let dir = out_dir("tunnel_bolts")?;
    let deg = |w: &[(f64, f64)]| w.iter().map(|p| p.0.to_degrees()).collect::<Vec<_>>();
    let mm = |w: &[(f64, f64)]| w.iter().map(|p| p.1 * 1e3).collect::<Vec<_>>();
    Plot::new(
        "Tunnel wall convergence",
        "polar angle (degrees)",
        "inward radial displacement (mm)",
    )
    .line("unbolted", deg(&free.wall), mm(&free.wall))
    .line("bolted", deg(&held.wall), mm(&held.wall))
    .save_png(dir.join("convergence.png"))?;
    Plot::new(
        "Axial force along bolt B0",
        "distance from the head (m)",
        "axial force (kN per m of tunnel)",
    )
    .line(
        "end of the run",
        held.profile.iter().map(|p| p.0).collect(),
        held.profile.iter().map(|p| p.1 / 1e3).collect(),
    )
    .save_png(dir.join("bolt_force.png"))?;
    println!("plots: {}", dir.display());
    let ratio = held.mean_convergence / free.mean_convergence;
    Ok(vec![ResultLine::new(
        backend,
        "tunnel_bolts",
        "bolted_over_unbolted_convergence",
        ratio,
        1.0,
        held.elements,
        held.steps,
        free.wall_s + held.wall_s,
    )])
}
