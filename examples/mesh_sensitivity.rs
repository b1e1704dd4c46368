//! Mesh sensitivity of the virtual laboratory (issue 19): the UCS and Brazilian tests
//! with the calibrated parameters of the main job on five seeded unstructured meshes at
//! three element sizes (2, 3 and 4 mm): mean and spread (sample standard deviation) of
//! the peak strength, the modulus and the Brazilian strength, and the orientation of the
//! broken joints in the UCS samples (share of broken-joint length per 30° sector of the
//! trace's direction, 90° = parallel to the load), with one structured steep-crossed
//! 2 mm run for contrast.
//!
//! `cargo run --release --example mesh_sensitivity` prints the tables and writes them
//! into `docs/validation.md` (the section `mesh-sensitivity`, which
//! `validation_report` keeps) and `out/mesh_sensitivity/runs.csv` (every run). About
//! thirteen minutes on 2 cores. `--seeds N` and `--sizes a,b,c` (m) change the study.
//! A study, not a validation against a closed form: it prints no RESULT line.

mod common;

use clap::{value_parser, Arg};
use pcdc::compute::Backend;
use pcdc_validation::report::{out_dir, ResultLine};

use pcdc_validation::scenes::platen_test::Crack;
use pcdc_validation::scenes::{brazilian, ucs};

const ABOUT: &str = "Mesh sensitivity: UCS and Brazilian on five seeded unstructured meshes at three sizes (strength and modulus mean and spread, crack orientation), written into docs/validation.md";

/// Sectors of the crack-orientation histogram (degrees).
const SECTORS: usize = 6;

fn main() {
    pcdc_validation::report::finish(choose())
}

fn choose() -> Result<Vec<ResultLine>, Box<dyn std::error::Error>> {
    let args = common::cli::command("mesh_sensitivity", ABOUT)
        .arg(
            Arg::new("seeds")
                .long("seeds")
                .default_value("5")
                .value_parser(value_parser!(u64))
                .help("Meshes per size (seeds 0..N)"),
        )
        .arg(
            Arg::new("sizes")
                .long("sizes")
                .default_value("0.002,0.003,0.004")
                .value_delimiter(',')
                .value_parser(value_parser!(f64))
                .help("Element sizes (m)"),
        )
        .get_matches();
    let seeds = *args.get_one::<u64>("seeds").expect("defaulted");
    let sizes: Vec<f64> = args
        .get_many::<f64>("sizes")
        .expect("defaulted")
        .copied()
        .collect();
    run(&common::cli::backend(&args)?, seeds, &sizes)
}

/// Length share of broken joints per sector of direction (sums to 1).
fn histogram(cracks: &[Crack]) -> [f64; SECTORS] {
    let mut h = [0.0; SECTORS];
    for c in cracks {
        let k = ((c.angle_deg / (180.0 / SECTORS as f64)) as usize).min(SECTORS - 1);
        h[k] += c.length;
    }
    let total: f64 = h.iter().sum();
    h.map(|v| v / total.max(f64::MIN_POSITIVE))
}

fn mean_sd(v: &[f64]) -> (f64, f64) {
    let n = v.len() as f64;
    let m = v.iter().sum::<f64>() / n;
    let var = v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (n - 1.0).max(1.0);
    (m, var.sqrt())
}

fn run(
    backend: &Backend,
    seeds: u64,
    sizes: &[f64],
) -> Result<Vec<ResultLine>, Box<dyn std::error::Error>> {
    println!("backend: {}", backend.describe());
    let start = std::time::Instant::now();
    let base = ucs::Params::full();
    let mut csv = String::from("size_m,seed,ucs_pa,young_pa,poisson,brazilian_pa,ucs_elements,ucs_wall_s,brazilian_wall_s\n");
    let mut table = String::new();
    let mut hist_rows = String::new();
    let (mut runs, mut steps) = (0usize, 0u64);
    let mut first_cv = None;
    for &size in sizes {
        let (mut ucs_v, mut e_v, mut bts_v) = (Vec::new(), Vec::new(), Vec::new());
        let mut hist = [0.0; SECTORS];
        for seed in 0..seeds {
            let mut p = base.clone();
            p.sample.mesh_size = size;
            p.sample.seed = seed;
            p.output.frames = 0;
            p.loading.stop_fraction = 0.7;
            let u = ucs::run(backend, &p, &mut |_| {})?;
            let mut b = brazilian::Params::full();
            b.disc.mesh_size = size;
            b.disc.seed = seed;
            b.rock = base.rock.clone();
            b.joints = base.joints.clone();
            b.output.frames = 0;
            let bo = brazilian::run(backend, &b, &mut |_| {})?;
            println!(
                "size {:.1} mm, seed {seed}: UCS {:.2} MPa, E {:.3} GPa, nu {:.3}, Brazilian {:.3} MPa ({:.0} + {:.0} s)",
                size * 1e3,
                u.ucs / 1e6,
                u.young / 1e9,
                u.poisson,
                bo.tensile_strength / 1e6,
                u.wall_s,
                bo.wall_s
            );
            csv.push_str(&format!(
                "{size},{seed},{},{},{},{},{},{},{}\n",
                u.ucs,
                u.young,
                u.poisson,
                bo.tensile_strength,
                u.sample_elements,
                u.wall_s,
                bo.wall_s
            ));
            let h = histogram(&u.cracks);
            for k in 0..SECTORS {
                hist[k] += h[k] / seeds as f64;
            }
            ucs_v.push(u.ucs / 1e6);
            e_v.push(u.young / 1e9);
            bts_v.push(bo.tensile_strength / 1e6);
            runs += 2;
            steps += u.steps + bo.steps;
        }
        let (mu, su) = mean_sd(&ucs_v);
        let (me, se) = mean_sd(&e_v);
        let (mb, sb) = mean_sd(&bts_v);
        first_cv.get_or_insert(su / mu);
        table.push_str(&format!(
            "| {:.0} | {} | {:.1} ± {:.1} ({:.1} %) | {:.3} ± {:.3} ({:.2} %) | {:.2} ± {:.2} ({:.1} %) |\n",
            size * 1e3,
            seeds,
            mu,
            su,
            100.0 * su / mu,
            me,
            se,
            100.0 * se / me,
            mb,
            sb,
            100.0 * sb / mb
        ));
        hist_rows.push_str(&format!(
            "| unstructured, {:.0} mm, mean of {seeds} | {} |\n",
            size * 1e3,
            hist.iter()
                .map(|v| format!("{:.1}", 100.0 * v))
                .collect::<Vec<_>>()
                .join(" | ")
        ));
    }
    // Contrast: the structured steep-crossed pattern, 2 mm.
    let mut p = base.clone();
    p.sample.pattern = ucs::MeshPattern::SteepCrossed;
    p.output.frames = 0;
    p.loading.stop_fraction = 0.7;
    let s = ucs::run(backend, &p, &mut |_| {})?;
    steps += s.steps;
    runs += 1;
    hist_rows.push_str(&format!(
        "| structured steep-crossed, 2 mm (contrast) | {} |\n",
        histogram(&s.cracks)
            .iter()
            .map(|v| format!("{:.1}", 100.0 * v))
            .collect::<Vec<_>>()
            .join(" | ")
    ));
    let wall = start.elapsed().as_secs_f64();
    let sectors: Vec<String> = (0..SECTORS)
        .map(|k| format!("{}–{}°", k * 180 / SECTORS, (k + 1) * 180 / SECTORS))
        .collect();
    let section = format!(
        "## Mesh sensitivity of the virtual laboratory\n\n\
         Written by `cargo run --release --example mesh_sensitivity` ({runs} runs, {wall:.0} s, {}). \
         The UCS and Brazilian tests of the main job (parameters calibrated on the 2 mm mesh, seed 0, for E = 30 GPa, ν = 0.25, UCS = 100 MPa, Brazilian 8 MPa; `ucs::calibrated_rock`, `ucs::calibrated_joints`) on unstructured meshes of seeds 0–{} at each size; UCS runs stop at 70 % of the peak. Mean ± sample standard deviation (coefficient of variation).\n\n\
         | size (mm) | meshes | UCS (MPa) | E (GPa) | Brazilian 2P/(πD) (MPa) |\n|---|---|---|---|---|\n{table}\n\
         Broken-joint length of the UCS samples per sector of the crack trace's direction (%; 90° is parallel to the load, isotropic cracking would put 16.7 % in each):\n\n\
         | mesh | {} |\n|---|{}\n{hist_rows}",
        backend.describe(),
        seeds - 1,
        sectors.join(" | "),
        "---|".repeat(SECTORS)
    );
    println!("\n{section}");
    let doc = std::path::Path::new("docs/validation.md");
    let md = std::fs::read_to_string(doc).unwrap_or_default();
    std::fs::write(
        doc,
        pcdc_validation::table::replace_section(&md, "mesh-sensitivity", &section),
    )?;
    let dir = out_dir("mesh_sensitivity")?;
    std::fs::write(dir.join("runs.csv"), csv)?;
    println!(
        "wrote the section mesh-sensitivity of {} and {}/runs.csv",
        doc.display(),
        dir.display()
    );
    // A study, not a validation against a closed form: no RESULT line (nothing to pass
    // or fail); the spread is the finding.
    let cv = first_cv.unwrap_or(f64::NAN);
    println!(
        "UCS coefficient of variation at {:.0} mm: {:.1} % over {seeds} meshes ({steps} steps in all)",
        sizes.first().copied().unwrap_or(f64::NAN) * 1e3,
        100.0 * cv
    );
    Ok(Vec::new())
}
