//! The speed-against-error report: every validation scene at three mesh sizes on every
//! backend and precision available; writes `docs/validation.md` and
//! `docs/validation-error-vs-time.png` (see `pcdc_validation::table`).
//!
//! ```sh
//! cargo run --release --example validation_report
//! ```
//!
//! Options:
//! - `--cases kirsch,wave_speed,...` only these scenes (default: all);
//! - `--backends cpu,gpu-f64,gpu-f32` only these backends (default: all available);
//! - `--resume` keep the rows already in `out/validation/rows.csv` and run only the
//!   missing ones (without it the cache starts afresh); with no cache (a fresh
//!   checkout) it starts from the rows of the committed `docs/validation.md`.
//!
//! The table and the plot are written from every cached row, so a report can be built
//! one case or backend at a time. Each row is printed as it finishes.

use std::io::Write;

use clap::builder::PossibleValuesParser;
use clap::{Arg, ArgAction, Command};
use pcdc::compute::{Backend, BackendKind};
use pcdc_validation::table::{self, Row};

fn is_gpu(b: &Backend) -> bool {
    b.kind() == BackendKind::Gpu
}

fn main() {
    if let Err(e) = run() {
        eprintln!("error: {e}");
        std::process::exit(1);
    }
}

fn machine(backends: &[Backend]) -> String {
    let cpu = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split(':').nth(1))
                .map(|m| m.trim().to_string())
        })
        .unwrap_or_else(|| "unknown CPU".into());
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
    let mut s = format!("{cpu}, {threads} threads");
    // Wall times depend on what else ran: say how loaded the machine was.
    if let Some(load) = std::fs::read_to_string("/proc/loadavg")
        .ok()
        .and_then(|l| l.split_whitespace().nth(1).map(str::to_string))
    {
        s.push_str(&format!(
            " (5-minute load average {load} when the report was written)"
        ));
    }
    for b in backends {
        if let Some(g) = b.as_gpu() {
            s.push_str(&format!(
                "; {}: {}",
                table::backend_label(b),
                g.adapter_name()
            ));
        }
    }
    s
}

fn run() -> Result<(), Box<dyn std::error::Error>> {
    let args = Command::new("validation_report")
        .about("Every validation scene at three mesh sizes on every available backend: writes docs/validation.md and its plot")
        .arg(
            Arg::new("cases")
                .long("cases")
                .value_delimiter(',')
                .value_parser(PossibleValuesParser::new(table::CASES))
                .help("Only these scenes (default: all)"),
        )
        .arg(
            Arg::new("backends")
                .long("backends")
                .value_delimiter(',')
                .value_parser(["cpu", "gpu-f64", "gpu-f32"])
                .help("Only these backends (default: all available)"),
        )
        .arg(
            Arg::new("resume")
                .long("resume")
                .action(ArgAction::SetTrue)
                .help("Keep the rows cached in out/validation/rows.csv and run only the missing ones"),
        )
        .get_matches();
    let cases: Vec<String> = match args.get_many::<String>("cases") {
        Some(c) => c.cloned().collect(),
        None => table::CASES.iter().map(|c| c.to_string()).collect(),
    };
    let mut backends = table::available_backends();
    if let Some(only) = args.get_many::<String>("backends") {
        let only: Vec<String> = only.cloned().collect();
        backends.retain(|b| only.contains(&table::backend_label(b)));
    }
    let dir = pcdc_validation::report::out_dir("validation")?;
    let cache = dir.join("rows.csv");
    let mut rows: Vec<Row> = Vec::new();
    if args.get_flag("resume") {
        if let Ok(text) = std::fs::read_to_string(&cache) {
            rows = text.lines().filter_map(Row::from_csv).collect();
        } else if let Ok(md) = std::fs::read_to_string("docs/validation.md") {
            // No cache (a fresh checkout): continue from the committed table.
            rows = table::rows_from_markdown(&md);
            let text: String = rows.iter().map(|r| r.to_csv() + "\n").collect();
            std::fs::write(&cache, text)?;
            println!(
                "no row cache: {} rows taken from docs/validation.md",
                rows.len()
            );
        }
    } else {
        std::fs::write(&cache, "")?;
    }
    println!("{} cached rows; backends: {}", rows.len(), {
        let l: Vec<String> = backends.iter().map(table::backend_label).collect();
        l.join(", ")
    });
    for b in &backends {
        for case in &cases {
            for job in table::jobs(case, is_gpu(b)) {
                let probe = Row {
                    case: job.case.into(),
                    variant: job.variant.into(),
                    size: job.mesh_size(),
                    elements: 0,
                    backend: b.kind().name().into(),
                    precision: table::backend_label(b)
                        .trim_start_matches("gpu-")
                        .replace("cpu", "f64"),
                    error: 0.0,
                    tol: String::new(),
                    pass: false,
                    steps: 0,
                    wall_s: 0.0,
                };
                if rows.iter().any(|r| r.key() == probe.key()) {
                    continue;
                }
                print!(
                    "{:<16} {:<11} size {:<8} {:<8} ... ",
                    job.case,
                    job.variant,
                    job.mesh_size(),
                    table::backend_label(b)
                );
                std::io::stdout().flush()?;
                match table::run_job(b, &job) {
                    Ok(row) => {
                        println!(
                            "{} elements, error {:.3e}, {} steps, {:.1} s{}",
                            row.elements,
                            row.error,
                            row.steps,
                            row.wall_s,
                            if row.pass { "" } else { "  ** FAIL **" }
                        );
                        let mut f = std::fs::OpenOptions::new().append(true).open(&cache)?;
                        writeln!(f, "{}", row.to_csv())?;
                        rows.push(row);
                    }
                    Err(e) => println!("not run: {e}"),
                }
            }
        }
    }
    // Jobs of every case on every available backend that have no row yet: say so.
    let mut missing = Vec::new();
    for b in &table::available_backends() {
        for case in table::CASES {
            let n = table::jobs(case, is_gpu(b)).len();
            let have = rows
                .iter()
                .filter(|r| {
                    r.case == *case
                        && format!("{}-{}", r.backend, r.precision)
                            == table::backend_label(b).replace("cpu", "cpu-f64")
                })
                .count();
            if have < n {
                missing.push(format!(
                    "{case} on {} ({have} of {n} rows)",
                    table::backend_label(b)
                ));
            }
        }
    }
    let mut here = machine(&backends);
    // Rows kept by --resume may come from another machine: name the earlier CPUs.
    if args.get_flag("resume") {
        let cpu = |line: &str| {
            line.split([',', ';'])
                .next()
                .unwrap_or("")
                .trim()
                .to_string()
        };
        let mut earlier: Vec<String> = std::fs::read_to_string("docs/validation.md")
            .ok()
            .and_then(|md| {
                md.lines()
                    .find_map(|l| l.strip_prefix("Machine: ").map(str::to_string))
            })
            .map(|line| {
                let mut v = vec![cpu(&line)];
                if let Some(rest) = line.split("earlier rows were measured on: ").nth(1) {
                    v.extend(rest.trim_end_matches('.').split(" / ").map(str::to_string));
                }
                v
            })
            .unwrap_or_default();
        let now = cpu(&here);
        earlier.retain(|c| !c.is_empty() && *c != now);
        earlier.dedup();
        if !earlier.is_empty() {
            here.push_str(&format!(
                "; earlier rows were measured on: {}",
                earlier.join(" / ")
            ));
        }
    }
    let mut md = table::markdown(&rows, &here);
    if !missing.is_empty() {
        md.push_str(&format!(
            "\nNot measured yet (run the command with `--resume` to add them): {}.\n",
            missing.join("; ")
        ));
    }
    // Sections other commands keep in the file (the mesh-sensitivity table).
    if let Ok(old) = std::fs::read_to_string("docs/validation.md") {
        md.push_str(&table::kept_sections(&old));
    }
    std::fs::create_dir_all("docs")?;
    std::fs::write("docs/validation.md", md)?;
    table::plot(
        &rows,
        std::path::Path::new("docs/validation-error-vs-time.png"),
    )?;
    println!(
        "wrote docs/validation.md and docs/validation-error-vs-time.png ({} rows)",
        rows.len()
    );
    let failed = rows.iter().filter(|r| !r.pass).count();
    println!(
        "RESULT case=validation_report metric=failed_rows value={failed} tol=0 pass={} elements={} steps={} wall_s={:.1} backend=all precision=all",
        failed == 0,
        rows.iter().map(|r| r.elements).sum::<usize>(),
        rows.iter().map(|r| r.steps).sum::<u64>(),
        rows.iter().map(|r| r.wall_s).sum::<f64>()
    );
    Ok(())
}
