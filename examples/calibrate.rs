//! Micro-to-macro calibration (the virtual rock laboratory, issue 19): finds the element
//! E, ν and the joints' cohesion and tensile strength that make unstructured jointed
//! samples show the laboratory's E, ν, UCS and Brazilian tensile strength, by closed-form
//! start and virtual UCS and Brazilian tests (`pcdc_validation::calibration`).
//!
//! `cargo run --release --example calibrate` calibrates for E = 30 GPa, ν = 0.25,
//! UCS = 100 MPa, Brazilian strength 8 MPa on 2 mm meshes; `--young`, `--poisson`,
//! `--ucs`, `--tensile` (Pa), `--mesh-size` (m), `--seed`, `--meshes` (meshes averaged
//! per round, so that the parameters fit the rock rather than one mesh) and
//! `--max-rounds` change that. It prints every round, then how many virtual tests it ran and how long it took,
//! and writes under `out/calibrate/`: `calibrated.toml` (the `[rock]` and `[joints]`
//! tables to paste into a UCS or Brazilian scene file) and `report.csv` (one line per
//! round: parameters tried, measured values, errors). The RESULT metric is the largest
//! of |E error| / 2 %, |ν error| / 2 %, |UCS error| / 5 % and |tensile error| / 5 % of
//! the calibrated round: ≤ 1 when it reached the targets.

mod common;

use clap::{value_parser, Arg};
use pcdc::compute::Backend;
use pcdc_validation::calibration::{self, Settings, Targets};
use pcdc_validation::report::{out_dir, ResultLine};
use pcdc_validation::scenes::{brazilian, ucs};

const ABOUT: &str = "Micro-to-macro calibration: element and joint parameters that give unstructured jointed samples the laboratory's E, nu, UCS and Brazilian strength, from virtual UCS and Brazilian tests";

fn main() {
    pcdc_validation::report::finish(choose())
}

fn arg(name: &'static str, default: &'static str, help: &'static str) -> Arg {
    Arg::new(name)
        .long(name)
        .default_value(default)
        .value_parser(value_parser!(f64))
        .help(help)
}

fn choose() -> Result<Vec<ResultLine>, Box<dyn std::error::Error>> {
    let args = common::cli::command("calibrate", ABOUT)
        .arg(arg(
            "young",
            "30e9",
            "Target Young's modulus of the sample (Pa)",
        ))
        .arg(arg(
            "poisson",
            "0.25",
            "Target Poisson's ratio of the sample",
        ))
        .arg(arg(
            "ucs",
            "100e6",
            "Target uniaxial compressive strength (Pa)",
        ))
        .arg(arg(
            "tensile",
            "8e6",
            "Target Brazilian tensile strength 2P/(pi D) (Pa)",
        ))
        .arg(arg(
            "mesh-size",
            "0.002",
            "Element size of the virtual specimens (m)",
        ))
        .arg(
            Arg::new("seed")
                .long("seed")
                .default_value("0")
                .value_parser(value_parser!(u64))
                .help("Seed of the unstructured meshes"),
        )
        .arg(
            Arg::new("meshes")
                .long("meshes")
                .default_value("1")
                .value_parser(value_parser!(u64))
                .help(
                    "Meshes per round (seeds seed, seed+1, ...), whose results each round averages",
                ),
        )
        .arg(
            Arg::new("max-rounds")
                .long("max-rounds")
                .default_value("6")
                .value_parser(value_parser!(usize))
                .help("Most rounds of virtual tests (a UCS and a Brazilian test each)"),
        )
        .get_matches();
    let f = |k: &str| *args.get_one::<f64>(k).expect("defaulted");
    let targets = Targets {
        young: f("young"),
        poisson: f("poisson"),
        ucs: f("ucs"),
        tensile: f("tensile"),
    };
    let settings = Settings {
        mesh_size: f("mesh-size"),
        seed: *args.get_one::<u64>("seed").expect("defaulted"),
        max_rounds: *args.get_one::<usize>("max-rounds").expect("defaulted"),
        meshes: *args.get_one::<u64>("meshes").expect("defaulted"),
        ..Settings::default()
    };
    run(&common::cli::backend(&args)?, &targets, &settings)
}

fn run(
    backend: &Backend,
    targets: &Targets,
    settings: &Settings,
) -> Result<Vec<ResultLine>, Box<dyn std::error::Error>> {
    println!("backend: {}", backend.describe());
    println!(
        "targets: E = {:.3} GPa, nu = {}, UCS = {:.2} MPa, Brazilian tensile strength = {:.2} MPa; meshes {} m, seeds {}-{}",
        targets.young / 1e9,
        targets.poisson,
        targets.ucs / 1e6,
        targets.tensile / 1e6,
        settings.mesh_size,
        settings.seed,
        settings.seed.saturating_add(settings.meshes.max(1) - 1)
    );
    println!(
        "{:>5} {:>10} {:>7} {:>9} {:>8} | {:>9} {:>7} {:>9} {:>8} | {:>7} {:>7} {:>7} {:>7} {:>6}",
        "round",
        "E_el GPa",
        "nu_el",
        "c MPa",
        "Ts MPa",
        "E GPa",
        "nu",
        "UCS MPa",
        "BTS MPa",
        "dE %",
        "dnu %",
        "dUCS %",
        "dBTS %",
        "s"
    );
    let cal = calibration::calibrate(
        backend,
        targets,
        &ucs::Params::full(),
        &brazilian::Params::full(),
        settings,
        &mut |k, r| {
            let e = r.errors(targets);
            println!(
                "{:>5} {:>10.3} {:>7.4} {:>9.3} {:>8.3} | {:>9.3} {:>7.4} {:>9.2} {:>8.3} | {:>7.2} {:>7.2} {:>7.2} {:>7.2} {:>6.1}",
                k,
                r.rock.young / 1e9,
                r.rock.poisson,
                r.joints.cohesion / 1e6,
                r.joints.tensile_strength / 1e6,
                r.young / 1e9,
                r.poisson,
                r.ucs / 1e6,
                r.tensile / 1e6,
                100.0 * e[0],
                100.0 * e[1],
                100.0 * e[2],
                100.0 * e[3],
                r.wall_s
            );
        },
    )?;
    let best = cal.best();
    let e = best.errors(targets);
    println!(
        "{} after {} virtual tests ({} rounds of a UCS and a Brazilian test on each of {} meshes) in {:.1} s",
        if cal.converged {
            "converged"
        } else {
            "did NOT converge; closest round"
        },
        cal.virtual_tests,
        cal.rounds.len(),
        settings.meshes,
        cal.wall_s
    );
    let dir = out_dir("calibrate")?;
    let toml = dir.join("calibrated.toml");
    std::fs::write(&toml, cal.toml_fragment())?;
    let mut csv = String::from(
        "round,element_young_pa,element_poisson,cohesion_pa,tensile_strength_pa,young_pa,poisson,ucs_pa,brazilian_pa,err_young,err_poisson,err_ucs,err_brazilian,wall_s\n",
    );
    for (k, r) in cal.rounds.iter().enumerate() {
        let e = r.errors(targets);
        csv.push_str(&format!(
            "{k},{},{},{},{},{},{},{},{},{},{},{},{},{}\n",
            r.rock.young,
            r.rock.poisson,
            r.joints.cohesion,
            r.joints.tensile_strength,
            r.young,
            r.poisson,
            r.ucs,
            r.tensile,
            e[0],
            e[1],
            e[2],
            e[3],
            r.wall_s
        ));
    }
    let report = dir.join("report.csv");
    std::fs::write(&report, csv)?;
    println!(
        "calibrated parameters: {}\nreport: {}",
        toml.display(),
        report.display()
    );
    print!("{}", cal.toml_fragment());
    let metric = (e[0].abs() / 0.02)
        .max(e[1].abs() / 0.02)
        .max(e[2].abs() / 0.05)
        .max(e[3].abs() / 0.05);
    Ok(vec![ResultLine::new(
        backend,
        "calibrate",
        "max_of_elastic_err_over_2pct_and_strength_err_over_5pct",
        metric,
        1.0,
        0,
        cal.virtual_tests as u64,
        cal.wall_s,
    )])
}
