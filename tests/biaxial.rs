//! Biaxial test with servo-controlled confinement at reduced size (5 mm mesh): the
//! servo walls (behind the default membranes) hold σ3 within 1 % from the start of the
//! axial loading to the peak, the confined sample is stronger than the unconfined one,
//! and the fitted envelope has a positive friction angle and cohesion.

use pcdc::compute::Backend;
use pcdc_validation::scenes::biaxial::{self, CONFINEMENT_TOL};

#[test]
fn servo_holds_the_confinement_and_confinement_strengthens() {
    let cpu = Backend::cpu(2).unwrap();
    let mut p = biaxial::Params::reduced();
    p.pressures = vec![0.0, 10e6];
    let out = biaxial::run(&cpu, &p, &mut |t| {
        eprintln!(
            "sigma3 {:.1} MPa: sigma1 {:.2} MPa, deviation {:.3} %, {} steps, {:.1} s",
            t.sigma3 / 1e6,
            t.sigma1 / 1e6,
            100.0 * t.deviation,
            t.outcome.steps,
            t.outcome.wall_s
        )
    })
    .unwrap();
    eprintln!(
        "envelope: phi {:.2} deg, c {:.2} MPa",
        out.friction_deg,
        out.cohesion / 1e6
    );
    let confined = &out.tests[1];
    eprintln!(
        "pre-peak: {:.1} % of the windows within 1 %, largest deviation {:.2} %; 95-100 % of the peak: {:.2} %",
        100.0 * confined.held,
        100.0 * confined.deviation,
        100.0 * confined.deviation_at_failure
    );
    // The servo holds σ3 within 1 % through the whole pre-peak.
    assert!(
        confined.deviation <= CONFINEMENT_TOL,
        "confinement off by {:.3} %",
        100.0 * confined.deviation
    );
    // The servo recorded a confinement at every sample of the loading.
    let samples = &confined.outcome.samples;
    assert!(samples.iter().all(|s| s.confinement > 0.5 * 10e6));
    assert!(
        confined.sigma1 > out.tests[0].sigma1 + 10e6,
        "{} vs {}",
        confined.sigma1,
        out.tests[0].sigma1
    );
    assert!(out.friction_deg > 0.0 && out.cohesion > 0.0);
}

/// A servo's bad parameters are errors that name them.
#[test]
fn bad_servo_parameters_are_named() {
    use pcdc::mech::{ServoGains, StressServo};
    let g = ServoGains::for_specimen(30e9, 0.05, 1e-5, 1e7);
    let e = StressServo::new(vec![0], 0, 1.0, 0.0, 1e6, g, 1.0).unwrap_err();
    assert!(e.to_string().contains("servo area"), "{e}");
    let e = StressServo::new(vec![], 0, 1.0, 1.0, 1e6, g, 1.0).unwrap_err();
    assert!(e.to_string().contains("servo nodes"), "{e}");
    let e = StressServo::new(vec![0], 0, 0.5, 1.0, 1e6, g, 1.0).unwrap_err();
    assert!(e.to_string().contains("inward"), "{e}");
    let bad = ServoGains {
        proportional: f64::NAN,
        integral_time: 1.0,
    };
    let e = StressServo::new(vec![0], 0, 1.0, 1.0, 1e6, bad, 1.0).unwrap_err();
    assert!(e.to_string().contains("proportional"), "{e}");
    // The impedance caps the gain: K_p Z = 0.5.
    let stiff = ServoGains::for_specimen(30e9, 0.05, 1e-9, 4e7);
    assert!((stiff.proportional * 4e7 - 0.5).abs() < 1e-12);
    let mut p = biaxial::Params::reduced();
    p.pressures = vec![5e6];
    assert!(biaxial::run(&Backend::cpu(1).unwrap(), &p, &mut |_| {}).is_err());
}

/// Bad confinement parameters are errors that name them: no segments, more segments
/// than the sides' nodes allow, a membrane of zero thickness.
#[test]
fn bad_confinement_is_named() {
    use pcdc_validation::scenes::platen_test::{Confinement, Membrane};
    use pcdc_validation::scenes::ucs;
    let good = Confinement {
        stress: 5e6,
        response_time: 2.5e-5,
        max_speed: 1.0,
        tolerance: 0.005,
        segments: 1,
        membrane: Some(Membrane::default()),
    };
    assert!(good.validate().is_ok());
    let e = Confinement {
        segments: 0,
        ..good.clone()
    }
    .validate()
    .unwrap_err();
    assert!(e.to_string().contains("confinement.segments"), "{e}");
    let e = Confinement {
        membrane: Some(Membrane {
            thickness: 0.0,
            ..Membrane::default()
        }),
        ..good.clone()
    }
    .validate()
    .unwrap_err();
    assert!(
        e.to_string().contains("confinement.membrane.thickness"),
        "{e}"
    );
    // 100 segments on the 5 mm sample's sides: refused before the run.
    let mut p = ucs::Params::reduced();
    p.confinement = Some(Confinement {
        segments: 100,
        ..good
    });
    let e = ucs::run(&Backend::cpu(1).unwrap(), &p, &mut |_| {}).unwrap_err();
    assert!(e.to_string().contains("confinement.segments"), "{e}");
}
