//! The Brazilian (indirect tensile) test: a 50 mm rock disc (0.05 m) with a cohesive
//! joint on every interior face, compressed along a diameter between two steel platens;
//! plane strain, per unit thickness (t = 1 m).
//!
//! `cargo run --release --example brazilian` shows a progress bar (on a terminal),
//! prints the peak load, the indirect tensile strength σ_t = 2P/(πD) and σ_t / T_s,
//! and writes under `out/brazilian/`: `brazilian_load.csv` and `.png` (load against
//! platen closure), `brazilian_cracks.png` and the ParaView series `brazilian.pvd`.
//! The RESULT metric max(0.7 / ratio, ratio / 1.5) is ≤ 1 exactly when σ_t / T_s lies in
//! 0.7–1.5.
//!
//! From a file: `cargo run --release --example scene -- scenes/brazilian.toml`.

mod common;

const ABOUT: &str = "The Brazilian (indirect tensile) test: a 50 mm rock disc (0.05 m) with a cohesive joint on every interior face, compressed along a diameter between two steel platens; plane strain, per unit thickness (t = 1 m)";

use pcdc::compute::Backend;
use pcdc_validation::report::{out_dir, ResultLine};
use pcdc_validation::scenes::brazilian;

fn main() {
    pcdc_validation::report::finish(choose())
}

fn choose() -> Result<Vec<ResultLine>, Box<dyn std::error::Error>> {
    let args = common::cli::command("brazilian", ABOUT).get_matches();
    run(&common::cli::backend(&args)?)
}

fn run(backend: &Backend) -> Result<Vec<ResultLine>, Box<dyn std::error::Error>> {
    println!("backend: {}", backend.describe());
    let mut p = brazilian::Params::full();
    p.output.dir = out_dir("brazilian")?;
    Ok(vec![common::run_brazilian(backend, &p)?])
}
