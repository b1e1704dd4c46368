//! Shared by the examples: the command line ([`cli`]), the progress bar and the runs.

// Each example uses only part of this module.
#![allow(dead_code)]

pub mod cli;

use std::io::IsTerminal;

use indicatif::{ProgressBar, ProgressStyle};
use pcdc::compute::Backend;
use pcdc_validation::report::ResultLine;
use pcdc_validation::scenes::platen_test::Progress;
use pcdc_validation::scenes::{brazilian, ucs};

/// A progress bar on stderr while stdout is a terminal, else a hidden one (no output in
/// pipes, logs and CI).
pub fn progress_bar(what: &str) -> ProgressBar {
    if !std::io::stdout().is_terminal() || !std::io::stderr().is_terminal() {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::new(1);
    let style = ProgressStyle::with_template(
        "{prefix} [{elapsed_precise}] {bar:40} {pos}/{len} steps (stops after the peak) {msg}",
    )
    .unwrap_or_else(|_| ProgressStyle::default_bar());
    bar.set_style(style);
    bar.set_prefix(what.to_string());
    bar
}

fn update(bar: &ProgressBar, p: &Progress, msg: String) {
    bar.set_length(p.max_steps);
    bar.set_position(p.step);
    bar.set_message(msg);
}

/// Runs the UCS scene with a progress bar and reports it.
pub fn run_ucs(
    backend: &Backend,
    p: &ucs::Params,
) -> Result<ResultLine, Box<dyn std::error::Error>> {
    let bar = progress_bar("ucs");
    let w = p.sample.width;
    let out = ucs::run(backend, p, &mut |pr: &Progress| {
        update(
            &bar,
            pr,
            format!(
                "stress {:.2} MPa, peak {:.2} MPa",
                pr.load / w / 1e6,
                pr.peak / w / 1e6
            ),
        )
    });
    bar.finish_and_clear();
    Ok(ucs::report(backend, p, &out?)?)
}

/// Runs the Brazilian scene with a progress bar and reports it.
pub fn run_brazilian(
    backend: &Backend,
    p: &brazilian::Params,
) -> Result<ResultLine, Box<dyn std::error::Error>> {
    let bar = progress_bar("brazilian");
    let out = brazilian::run(backend, p, &mut |pr: &Progress| {
        update(
            &bar,
            pr,
            format!(
                "load {:.1} kN/m, peak {:.1} kN/m",
                pr.load / 1e3,
                pr.peak / 1e3
            ),
        )
    });
    bar.finish_and_clear();
    Ok(brazilian::report(backend, p, &out?)?)
}
