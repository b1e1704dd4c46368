//! What bolts add to the FDEM tunnel scene's step (`tunnel_bolts`), measured by
//! alternating unbolted and bolted runs of freshly built scenes and keeping the best of
//! each: on a shared or virtual machine whose speed drifts by tens of percent within a
//! minute, the alternation puts both variants under the same drift, where criterion's
//! rows (`cargo bench --bench bolted_tunnel`, the reference for throughput) time them
//! minutes apart. The scene build is not timed.
//!
//! ```sh
//! cargo run --release --example bolt_overhead -- --threads 1,2 --per 50 --rounds 8
//! ```
//!
//! `--only bolted` (or `alone`) times one variant, so that a profiler sees one of them:
//! `perf record -F 10000 target/release/examples/bolt_overhead --threads 1 --only bolted`.

use std::time::Instant;

use clap::{value_parser, Arg, Command};
use pcdc_compute::Backend;
use pcdc_validation::scenes::tunnel_bolts::{bolt_pattern, simulation};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args = Command::new("bolt_overhead")
        .about("Step time of the FDEM tunnel with and without a bolt pattern, alternated")
        .arg(
            Arg::new("threads")
                .long("threads")
                .value_delimiter(',')
                .value_parser(value_parser!(usize))
                .default_value("1,2")
                .help("CPU thread counts to measure"),
        )
        .arg(
            Arg::new("per")
                .long("per")
                .value_parser(value_parser!(u64).range(1..))
                .default_value("50")
                .help("One bolt (10 segments) per this many elements"),
        )
        .arg(
            Arg::new("rounds")
                .long("rounds")
                .value_parser(value_parser!(u64).range(1..))
                .default_value("8")
                .help("Alternations (each times one unbolted and one bolted run)"),
        )
        .arg(
            Arg::new("steps")
                .long("steps")
                .value_parser(value_parser!(u64).range(1..))
                .default_value("200")
                .help("Steps per timed run"),
        )
        .arg(
            Arg::new("size")
                .long("size")
                .value_parser(value_parser!(f64))
                .default_value("0.1")
                .help("Element size at the wall (m)"),
        )
        .arg(
            Arg::new("only")
                .long("only")
                .value_parser(["alone", "bolted"])
                .help("Time one variant only (e.g. under a profiler); no overhead is printed"),
        )
        .get_matches();
    let per = *args.get_one::<u64>("per").expect("default") as usize;
    let rounds = *args.get_one::<u64>("rounds").expect("default");
    let steps = *args.get_one::<u64>("steps").expect("default");
    let size = *args.get_one::<f64>("size").expect("default");
    let only = args.get_one::<String>("only").map(|s| s == "bolted");
    for &t in args.get_many::<usize>("threads").expect("default") {
        let backend = Backend::cpu(t)?;
        let ne = simulation(&backend, size, None)?.mesh().n_elements();
        let n_bolts = (ne / per).max(1);
        let mut best = [f64::INFINITY; 2];
        let probe = simulation(&backend, size, Some(bolt_pattern(n_bolts)?))?;
        for (a, b) in probe.physics_beside() {
            println!("threads {t}: '{b}' runs beside '{a}'");
        }
        for _ in 0..rounds {
            for (i, bolts) in [None, Some(n_bolts)].into_iter().enumerate() {
                if only.is_some_and(|b| b != (i == 1)) {
                    continue;
                }
                let pattern = bolts.map(bolt_pattern).transpose()?;
                let mut sim = simulation(&backend, size, pattern)?;
                let t0 = Instant::now();
                sim.run(steps)?;
                best[i] = best[i].min(t0.elapsed().as_secs_f64());
            }
        }
        if only.is_some() {
            let i = usize::from(only == Some(true));
            println!(
                "threads {t}: {ne} elements, {} bolts: {:.2} ms per {steps} steps (best of {rounds})",
                if i == 1 { n_bolts } else { 0 },
                best[i] * 1e3
            );
            continue;
        }
        println!(
            "threads {t}: {ne} elements, {n_bolts} bolts: alone {:.2} ms, bolted {:.2} ms \
             per {steps} steps (best of {rounds}): {:+.1} %",
            best[0] * 1e3,
            best[1] * 1e3,
            (best[1] / best[0] - 1.0) * 100.0
        );
    }
    Ok(())
}
