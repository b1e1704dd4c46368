//! Validation scene 8, the UCS quick start of the manual (chapter 3): a 108 × 52 mm rock
//! sample (0.108 × 0.052 m: the manual's millimetres in SI) on an unstructured 2 mm mesh
//! with a cohesive joint on every interior face, its parameters calibrated
//! (`cargo run --release --example calibrate`) to E = 30 GPa, ν = 0.25, UCS = 100 MPa,
//! crushed between two steel platens until the stress falls to 30 % of the peak; plane
//! strain.
//!
//! `cargo run --release --example ucs` shows a progress bar (on a terminal), prints the
//! summary table (peak strength, Young's modulus from the linear part, strain at peak,
//! broken joints by mode, the quasi-static check) and writes under `out/ucs/`:
//! `ucs_stress_strain.csv` and `.png`, `ucs_cracks.png` and the ParaView series
//! `ucs.pvd` (damage and broken joints per element). It ends with the RESULT line, whose
//! metric max(E error / 2 %, 5 / (UCS/T_s), (UCS/T_s) / 20, (last/peak) / 0.3) is ≤ 1
//! exactly when the modulus is within 2 % of the target E, UCS / T_s lies in 5–20 and
//! the run went on to 30 % of the peak.
//!
//! The same scene from a file: `cargo run --release --example scene -- scenes/ucs.toml`.
//! Backend: `--backend cpu|gpu`; on the GPU the scene runs only where every composed
//! physics has a kernel (otherwise it stops with a clear error when the simulation is
//! built); it reads the platen reactions back ten times per recorded sample.

mod common;

const ABOUT: &str = "Validation scene 8, the UCS quick start of the manual (chapter 3): a 108 × 52 mm rock sample (0.108 × 0.052 m) on an unstructured 2 mm mesh with a cohesive joint on every interior face, calibrated to E = 30 GPa, nu = 0.25, UCS = 100 MPa, crushed between two steel platens to 30 % of the peak; plane strain";

use pcdc::compute::Backend;
use pcdc_validation::report::{out_dir, ResultLine};
use pcdc_validation::scenes::ucs;

fn main() {
    pcdc_validation::report::finish(choose())
}

fn choose() -> Result<Vec<ResultLine>, Box<dyn std::error::Error>> {
    let args = common::cli::command("ucs", ABOUT).get_matches();
    run(&common::cli::backend(&args)?)
}

fn run(backend: &Backend) -> Result<Vec<ResultLine>, Box<dyn std::error::Error>> {
    println!("backend: {}", backend.describe());
    let mut p = ucs::Params::full();
    p.output.dir = out_dir("ucs")?;
    Ok(vec![common::run_ucs(backend, &p)?])
}
