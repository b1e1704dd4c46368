//! The examples' command line (clap, so every example answers `--help`): the backend
//! and its precision, each also read from its environment variable.

// custom_model uses `choice` alone.
#![allow(dead_code)]

use clap::{Arg, ArgMatches, Command};
use pcdc::compute::{Backend, BackendChoice, BackendKind, Precision};

/// The example's command with `--backend` and `--precision`.
pub fn command(name: &'static str, about: &'static str) -> Command {
    Command::new(name)
        .about(about)
        .arg(
            Arg::new("backend")
                .long("backend")
                .env("PCDC_BACKEND")
                .value_parser(["cpu", "gpu"])
                .default_value("cpu")
                .help(
                    "Where the kernels run: the CPU (all cores, or PCDC_THREADS) or the best GPU",
                ),
        )
        .arg(
            Arg::new("precision")
                .long("precision")
                .env("PCDC_PRECISION")
                .value_parser(["f64", "f32"])
                .help(
                    "GPU precision (default: f64 where the adapter has it); the CPU runs f64 only",
                ),
        )
}

/// The backend the parsed arguments name (f32 on the CPU is an error).
pub fn choice(args: &ArgMatches) -> Result<BackendChoice, Box<dyn std::error::Error>> {
    let kind = BackendKind::parse(args.get_one::<String>("backend").map_or("cpu", |s| s))?;
    let precision = args
        .get_one::<String>("precision")
        .map(|p| Precision::parse(p))
        .transpose()?;
    Ok(BackendChoice::new(kind, precision)?)
}

/// Opens the backend the parsed arguments name.
pub fn backend(args: &ArgMatches) -> Result<Backend, Box<dyn std::error::Error>> {
    Ok(Backend::open(choice(args)?)?)
}

/// Adds `--element` with the given choices (the first is the default).
pub fn with_element(cmd: Command, choices: &'static [&'static str]) -> Command {
    cmd.arg(
        Arg::new("element")
            .long("element")
            .value_parser(clap::builder::PossibleValuesParser::new(choices))
            .default_value(choices[0])
            .help("The cells: simplices (tri3/tet4), Quad4, a Tri3/Quad4 mix, or Hex8"),
    )
}

/// The cells `--element` names.
pub fn element(
    args: &ArgMatches,
) -> Result<pcdc_validation::scenes::Element, Box<dyn std::error::Error>> {
    let name = args.get_one::<String>("element").map_or("tri3", |s| s);
    Ok(pcdc_validation::scenes::Element::parse(name)?)
}
