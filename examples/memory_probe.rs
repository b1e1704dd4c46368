//! Prints the element count and memory of the benchmark scenes (peak RSS from
//! /proc/self/status and `Simulation::state_bytes`).
use pcdc_compute::{Backend, Simulation};
use pcdc_mech::{Boundary, LinearElastic, Mechanics};
use pcdc_mesh::{builders, Range};

fn peak_kb() -> u64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("VmHWM"))
                .and_then(|l| l.split_whitespace().nth(1)?.parse().ok())
        })
        .unwrap_or(0)
}

fn main() {
    clap::Command::new("memory_probe")
        .about("Prints the element count and memory of the benchmark scenes")
        .get_matches();
    let base = peak_kb();
    let mesh = builders::rectangle(0.0, 0.0, 0.05, 0.10, 0.05 / 224.0).unwrap();
    let n = mesh.n_elements();
    let rock = LinearElastic::new(30e9, 0.25, 2600.0).unwrap();
    let mut sim = Simulation::builder(mesh, Backend::cpu(1).unwrap())
        .physics(Mechanics::new().material(Range::All, rock))
        .physics(
            Boundary::new()
                .velocity(Range::group("bottom"), [None, Some(0.0.into()), None])
                .velocity(Range::group("top"), [None, Some((-0.05).into()), None]),
        )
        .build()
        .unwrap();
    sim.run(10).unwrap();
    println!(
        "tri3: {n} elements, state_bytes {:.0} B/element, peak RSS growth {:.0} B/element",
        sim.state_bytes() as f64 / n as f64,
        (peak_kb() - base) as f64 * 1024.0 / n as f64
    );
    let tet = builders::cuboid([0.0; 3], [0.05, 0.05, 0.0962], 0.05 / 26.0).unwrap();
    println!("tet4: {} elements", tet.n_elements());
}
