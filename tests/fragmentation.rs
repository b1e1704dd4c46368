//! The fragmentation hard case at reduced size: a jointed block (1 cm triangles) thrown
//! into a closed box shatters; over 100 000 steps the energy never exceeds the initial
//! energy plus the external work by more than 1 %, no node penetrates a foreign element
//! by more than 5 % of its size, and no watchdog stops the run.

use pcdc::compute::Backend;
use pcdc_validation::scenes::fragmentation::{run, Params, ENERGY_TOL, PENETRATION_TOL};

#[test]
fn fragments_in_a_box_stay_stable_for_100k_steps() {
    let p = Params {
        size: 0.01,
        steps: 100_000,
        check_every: 1000,
    };
    let o = run(&Backend::cpu(0).unwrap(), &p).expect("no watchdog stop");
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

/// CPU results do not depend on the thread count: the shattering block (broken joints,
/// contact between fragments, the per-step sealed flags and boxes of contact) on 1 and 2
/// threads, bit for bit after 8 000 steps.
#[test]
fn fragmentation_is_bit_identical_across_thread_counts() {
    let p = Params {
        size: 0.01,
        steps: 8_000,
        check_every: 2_000,
    };
    let one = run(&Backend::cpu(1).unwrap(), &p).unwrap();
    let two = run(&Backend::cpu(2).unwrap(), &p).unwrap();
    assert!(
        one.broken > 0,
        "nothing broke: the run does not test contact"
    );
    assert_eq!(one.broken, two.broken);
    assert_eq!(one.state_hash, two.state_hash, "1 and 2 threads differ");
}

/// The same scene on the GPU (f64): 10 000 steps at 1 cm (the impact and the shattering)
/// in CI; the energy balance (accumulated on the device) and the penetration stay within
/// the bounds. The full 100 000 steps: `cargo test --release --test fragmentation --
/// --ignored` (about 15 min on lavapipe).
#[test]
fn fragments_on_the_gpu_f64_stay_stable() {
    gpu_run(10_000);
}

/// 100 000 steps on the GPU (f64); ignored in CI for its length on a software adapter.
#[test]
#[ignore]
fn fragments_on_the_gpu_f64_stay_stable_for_100k_steps() {
    gpu_run(100_000);
}

fn gpu_run(steps: u64) {
    let Some(gpu) = pcdc::compute::gpu::gpu_test_backend(Some(pcdc::compute::Precision::F64))
    else {
        return;
    };
    let p = Params {
        size: 0.01,
        steps,
        check_every: 1000,
    };
    let o = run(&gpu, &p).expect("no watchdog stop");
    println!(
        "GPU f64: {} steps, broken {}/{}, worst excess {:.3e} at {}, penetration {:.3e}, {:.1} s",
        o.steps,
        o.broken,
        o.joints,
        o.worst_energy_excess,
        o.worst_step,
        o.worst_penetration,
        o.wall_s
    );
    assert_eq!(o.steps, steps);
    assert!(o.broken > 0, "nothing broke");
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
