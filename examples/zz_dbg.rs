use pcdc::compute::{Backend, Simulation};
use pcdc_mech::{Boundary, LinearElastic, Mechanics, MohrCoulomb};
use pcdc_mesh::{builders, Range};
fn main() {
    let e = LinearElastic::new(30e9, 0.25, 2600.0).unwrap();
    let rock = MohrCoulomb::new(e, 0.1e6, 30.0, 5.0, 0.05e6).unwrap();
    for d3 in [false, true] {
        let mut push = [None, None, None];
        let mut hold = [None, None, None];
        let y = if d3 { 2 } else { 1 };
        push[y] = Some((-0.05).into());
        hold[y] = Some(0.0.into());
        macro_rules! go {
            ($mesh:expr, $b:expr, $t:expr) => {{
                let mut sim = Simulation::builder($mesh, Backend::cpu(1).unwrap())
                    .physics(
                        Mechanics::new()
                            .material(Range::All, rock.clone())
                            .initial_stress(Range::All, [-10e6, -10e6, -10e6, 0.0, 0.0, 0.0]),
                    )
                    .physics(
                        Boundary::new()
                            .velocity(Range::group($b), hold.clone())
                            .velocity(Range::group($t), push.clone()),
                    )
                    .build()
                    .unwrap();
                sim.run(20).unwrap();
                pcdc_mech::mohr_coulomb::SOLVES.store(0, std::sync::atomic::Ordering::Relaxed);
                for w in &pcdc_mech::mohr_coulomb::WIN {
                    w.store(0, std::sync::atomic::Ordering::Relaxed);
                }
                sim.run(20).unwrap();
                let n = sim.mesh().n_elements() * 20;
                println!(
                    "d3 {d3}: solves per element-step {:.3}",
                    pcdc_mech::mohr_coulomb::SOLVES.load(std::sync::atomic::Ordering::Relaxed)
                        as f64
                        / n as f64
                );
                for (m, w) in pcdc_mech::mohr_coulomb::WIN.iter().enumerate() {
                    let c = w.load(std::sync::atomic::Ordering::Relaxed);
                    if c > 0 {
                        println!("  mask {m:06b}: {:.3}", c as f64 / n as f64);
                    }
                }
            }};
        }
        if d3 {
            go!(
                builders::cuboid([0.0; 3], [0.05, 0.05, 0.1], 0.005).unwrap(),
                "zmin",
                "zmax"
            )
        } else {
            go!(
                builders::rectangle(0.0, 0.0, 0.05, 0.1, 0.002).unwrap(),
                "bottom",
                "top"
            )
        }
    }
}
