//! Reduced-size Brazilian test: 4 mm mesh, platens at 0.04 m/s. The indirect tensile
//! strength 2P/(πD) must lie within 0.7–1.5 T_s.

use pcdc::compute::Backend;
use pcdc_validation::scenes::brazilian;

#[test]
fn reduced_brazilian_strength_within_band() {
    let cpu = Backend::cpu(2).unwrap();
    let p = brazilian::Params::reduced();
    let out = brazilian::run(&cpu, &p, &mut |_| {}).unwrap();
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
