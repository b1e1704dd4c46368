//! The fragmentation hard case at reduced size: a jointed block (1 cm triangles) thrown
//! into a closed box shatters; over 100 000 steps the energy never exceeds the initial
//! energy plus the external work by more than 1 %, no node penetrates a foreign element
//! by more than 5 % of its size, and no watchdog stops the run.

use pcdc::compute::CpuBackend;
use pcdc::scenes::fragmentation::{run, Params, ENERGY_TOL, PENETRATION_TOL};

#[test]
fn fragments_in_a_box_stay_stable_for_100k_steps() {
    let p = Params {
        size: 0.01,
        steps: 100_000,
        check_every: 1000,
    };
    let o = run(&CpuBackend::new(0).unwrap(), &p).expect("no watchdog stop");
    println!(
        "elements {}, dt {:.2e} s, broken {}/{}, worst excess {:.3e} at {}, penetration {:.3e}, {:.1} s",
        o.elements,
        o.dt,
        o.broken,
        o.joints,
        o.worst_energy_excess,
        o.worst_step,
        o.worst_penetration,
        o.wall_s
    );
    assert_eq!(o.steps, p.steps);
    // It does fragment: a scene where nothing breaks would not test broken joints.
    assert!(
        o.broken * 10 > o.joints,
        "only {} of {} joints broke",
        o.broken,
        o.joints
    );
    assert!(
        o.worst_energy_excess <= ENERGY_TOL,
        "energy excess {}",
        o.worst_energy_excess
    );
    assert!(
        o.worst_penetration <= PENETRATION_TOL,
        "penetration {}",
        o.worst_penetration
    );
}
