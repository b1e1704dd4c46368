//! Reduced-size Brazilian test: 4 mm mesh, platens at 0.04 m/s. The indirect tensile
//! strength 2P/(πD) must lie within 0.7–1.5 T_s.

use pcdc::compute::Backend;
use pcdc_validation::scenes::brazilian;

#[test]
fn reduced_brazilian_strength_within_band() {
    let cpu = Backend::cpu(2).unwrap();
    let mut p = brazilian::Params::reduced();
    let dir = std::env::temp_dir().join(format!("pcdc-brazilian-frames-{}", std::process::id()));
    p.output.dir = dir.clone();
    p.output.frames = 2;
    let out = brazilian::run(&cpu, &p, &mut |_| {}).unwrap();
    // The frames hold the standard arrays of `pcdc_mech::output::write_step` and the
    // scene's own per-element joint damage and broken joints (`write_step_with`).
    let pvd = std::fs::read_to_string(out.pvd.as_ref().expect("a VTU series")).unwrap();
    let last = pvd
        .lines()
        .filter_map(|l| l.split("file=\"").nth(1))
        .filter_map(|l| l.split('"').next())
        .next_back()
        .expect("a frame");
    let vtu = std::fs::read(dir.join(last)).unwrap();
    let head = String::from_utf8_lossy(&vtu[..vtu.len().min(4096)]).into_owned();
    for name in [
        "displacement",
        "velocity",
        "stress",
        "strain",
        "sigma_1",
        "sigma_min",
        "joint_damage_max",
        "broken_joints",
    ] {
        assert!(
            head.contains(&format!("Name=\"{name}\"")),
            "{last}: no array {name}"
        );
    }
    std::fs::remove_dir_all(&dir).ok();
    eprintln!(
        "brazilian reduced: P {:.1} kN/m, sigma_t {:.3} MPa, ratio {:.3}, KE/SE {:.2e}, broken {:?}, elements {}, steps {}, wall {:.1} s",
        out.peak_load / 1e3,
        out.tensile_strength / 1e6,
        out.ratio,
        out.ke_ratio,
        out.broken,
        out.elements,
        out.steps,
        out.wall_s
    );
    assert!(
        out.band_metric() <= 1.0,
        "sigma_t / Ts = {} outside {:?}",
        out.ratio,
        brazilian::RATIO_BAND
    );
    assert!(out.broken.total() > 0, "no joint broke");
}
