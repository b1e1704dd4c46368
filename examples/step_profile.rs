//! Runs the standard FDEM benchmark scene (`pcdc_validation::scenes::benchmark`) for a
//! number of steps and prints its rate: the program to run under a profiler (`perf
//! record`, `valgrind --tool=callgrind`), where criterion's harness would blur the
//! picture. The warm-up steps (first broad phase, page faults) are reported apart.
//!
//! ```sh
//! cargo run --release --example step_profile -- --dim 2 --cells 112 --contact --steps 2000
//! perf record -e cpu-clock -D 3000 target/release/examples/step_profile --contact
//! ```

use std::time::Instant;

use clap::{value_parser, Arg, ArgAction, Command};
use pcdc_compute::{Backend, Simulation};
use pcdc_mesh::Dim;
use pcdc_validation::scenes::benchmark::{fdem_block_2d, fdem_cuboid_3d};

fn measure<D: Dim>(
    mut sim: Simulation<D>,
    warmup: u64,
    steps: u64,
    single: bool,
    label: &str,
) -> Result<(), Box<dyn std::error::Error>> {
    let n = sim.mesh().n_elements();
    let t0 = Instant::now();
    sim.run(warmup)?;
    let warm = t0.elapsed().as_secs_f64();
    let t1 = Instant::now();
    if single {
        // As criterion's `b.iter(|| sim.step())`: one call per step, each handing the
        // step to the backend's pool and back.
        for _ in 0..steps {
            sim.step()?;
        }
    } else {
        sim.run(steps)?;
    }
    let wall = t1.elapsed().as_secs_f64();
    println!(
        "{label}: {n} elements, {steps} steps in {wall:.3} s = {:.3} M element-steps/s ({:.1} ns per element-step); warm-up {warmup} steps {warm:.3} s; state {:.0} B per element",
        n as f64 * steps as f64 / wall / 1e6,
        wall / (n as f64 * steps as f64) * 1e9,
        sim.state_bytes() as f64 / n as f64
    );
    Ok(())
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args = Command::new("step_profile")
        .about("Runs the standard FDEM benchmark scene and prints its rate (for profilers)")
        .arg(
            Arg::new("dim")
                .long("dim")
                .value_parser(["2", "3"])
                .default_value("2")
                .help("2: block of triangles; 3: cuboid of tetrahedra"),
        )
        .arg(
            Arg::new("cells")
                .long("cells")
                .value_parser(value_parser!(usize))
                .help("Cells across (default 112 in 2D: 50 176 triangles; 16 in 3D: 49 152 tetrahedra)"),
        )
        .arg(
            Arg::new("contact")
                .long("contact")
                .action(ArgAction::SetTrue)
                .help("Contact on (bonded neighbours excluded until their joint breaks)"),
        )
        .arg(
            Arg::new("steps")
                .long("steps")
                .value_parser(value_parser!(u64).range(1..))
                .default_value("1000")
                .help("Measured steps"),
        )
        .arg(
            Arg::new("warmup")
                .long("warmup")
                .value_parser(value_parser!(u64))
                .default_value("20")
                .help("Steps run before the measured ones (the loaded block's state evolves: joints near their peak take the damaged path)"),
        )
        .arg(
            Arg::new("single-steps")
                .long("single-steps")
                .action(ArgAction::SetTrue)
                .help("Call `step()` once per step, as the criterion bench does, instead of one `run(steps)`"),
        )
        .arg(
            Arg::new("threads")
                .long("threads")
                .value_parser(value_parser!(usize))
                .default_value("1")
                .help("CPU threads (0: all)"),
        )
        .get_matches();
    let contact = args.get_flag("contact");
    let steps = *args.get_one::<u64>("steps").expect("default");
    let threads = *args.get_one::<usize>("threads").expect("default");
    let warmup = *args.get_one::<u64>("warmup").expect("default");
    let single = args.get_flag("single-steps");
    let backend = Backend::cpu(threads)?;
    let what = if contact { "contact" } else { "joints" };
    if args.get_one::<String>("dim").map(String::as_str) == Some("3") {
        let cells = args.get_one::<usize>("cells").copied().unwrap_or(16);
        let sim = fdem_cuboid_3d(cells, backend, contact)?;
        measure(
            sim,
            warmup,
            steps,
            single,
            &format!("3D {what}, {threads} thread(s)"),
        )?;
    } else {
        let cells = args.get_one::<usize>("cells").copied().unwrap_or(112);
        let sim = fdem_block_2d(cells, backend, contact)?;
        measure(
            sim,
            warmup,
            steps,
            single,
            &format!("2D {what}, {threads} thread(s)"),
        )?;
    }
    Ok(())
}
