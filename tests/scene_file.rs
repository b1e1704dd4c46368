//! Scene files: the shipped TOML files are the defaults, a scene survives a TOML round
//! trip, and unknown keys and bad values are errors that name the key.

use pcdc_validation::scenes::file::{SceneFile, SceneFileError};
use pcdc_validation::scenes::{brazilian, ucs};

fn shipped(name: &str) -> SceneFile {
    let path = format!("{}/scenes/{name}", env!("CARGO_MANIFEST_DIR"));
    SceneFile::read(&path).unwrap_or_else(|e| panic!("{path}: {e}"))
}

#[test]
fn shipped_files_hold_the_defaults() {
    assert_eq!(shipped("ucs.toml"), SceneFile::Ucs(ucs::Params::default()));
    assert_eq!(
        shipped("brazilian.toml"),
        SceneFile::Brazilian(brazilian::Params::default())
    );
}

#[test]
fn round_trip_through_toml() {
    let mut u = ucs::Params::default();
    u.sample.mesh_size = 0.003;
    u.rock.poisson = 0.2;
    u.joints.gf2 = 7.5;
    u.loading.record_every = 17;
    u.output.frames = 0;
    let mut b = brazilian::Params::default();
    b.disc.diameter = 0.042;
    b.contact.friction_deg = 20.0;
    for scene in [SceneFile::Ucs(u), SceneFile::Brazilian(b)] {
        let text = scene.to_toml().unwrap();
        assert_eq!(SceneFile::from_toml(&text).unwrap(), scene, "{text}");
    }
}

#[test]
fn omitted_keys_take_the_defaults() {
    let s = SceneFile::from_toml("scene = \"ucs\"\n[sample]\nmesh_size = 0.004\n").unwrap();
    let mut expected = ucs::Params::default();
    expected.sample.mesh_size = 0.004;
    assert_eq!(s, SceneFile::Ucs(expected));
}

fn error(text: &str) -> String {
    match SceneFile::from_toml(text) {
        Ok(s) => panic!("accepted {text:?} as {s:?}"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn unknown_keys_are_named() {
    let msg = error("scene = \"ucs\"\n[sample]\nheigth = 0.1\n");
    assert!(msg.contains("heigth") && msg.contains("height"), "{msg}");
    assert!(msg.contains("line 3"), "{msg}");
    let msg = error("scene = \"brazilian\"\n[disk]\ndiameter = 0.05\n");
    assert!(msg.contains("disk") && msg.contains("disc"), "{msg}");
    // A key of the other scene is unknown here.
    let msg = error("scene = \"brazilian\"\n[sample]\nheight = 0.1\n");
    assert!(msg.contains("sample"), "{msg}");
}

/// A UCS file with a full `[loading]` table in which `line` replaces its key's default.
fn loading(line: &str) -> String {
    let key = line.split('=').next().unwrap().trim();
    let mut text = String::from("scene = \"ucs\"\n[loading]\n");
    for default in [
        "platen_velocity = 0.1",
        "ramp_time = 5e-5",
        "stop_fraction = 0.7",
        "max_closure = 0.005",
        "record_every = 100",
    ] {
        let d = default.split('=').next().unwrap().trim();
        text.push_str(if d == key { line } else { default });
        text.push('\n');
    }
    text
}

#[test]
fn bad_values_are_named() {
    for (text, key) in [
        (
            "scene = \"ucs\"\n[sample]\nheight = -0.1\n".to_string(),
            "sample.height",
        ),
        (
            "scene = \"ucs\"\n[sample]\nmesh_size = 0.0\n".to_string(),
            "sample.mesh_size",
        ),
        (
            "scene = \"ucs\"\n[sample]\nmesh_size = 0.2\n".to_string(),
            "sample.mesh_size",
        ),
        (
            "scene = \"ucs\"\n[rock]\npoisson = 0.5\n".to_string(),
            "rock.poisson",
        ),
        (
            // ν = -1 (ν < 0 is allowed for auxetic rock, but G would be infinite).
            "scene = \"ucs\"\n[rock]\npoisson = -1.0\n".to_string(),
            "rock.poisson",
        ),
        (
            "scene = \"ucs\"\n[platens]\nwidth = 0.04\n".to_string(),
            "platens.width",
        ),
        (
            "scene = \"ucs\"\n[joints]\nfriction_deg = 90.0\n".to_string(),
            "joints.friction_deg",
        ),
        (
            "scene = \"ucs\"\n[joints]\ngf1 = -1.0\n".to_string(),
            "joints.gf1",
        ),
        (loading("stop_fraction = 1.5"), "loading.stop_fraction"),
        (loading("record_every = 0"), "loading.record_every"),
        (
            loading("platen_velocity = -0.05"),
            "loading.platen_velocity",
        ),
        (
            "scene = \"brazilian\"\n[disc]\ndiameter = -0.05\n".to_string(),
            "disc.diameter",
        ),
        (
            "scene = \"brazilian\"\n[rock]\nyoung = 0.0\n".to_string(),
            "rock.young",
        ),
        (
            "scene = \"brazilian\"\n[contact]\npenalty = -10.0\n".to_string(),
            "contact.penalty",
        ),
    ] {
        let msg = error(&text);
        assert!(msg.contains(key), "{text:?}: {msg}");
    }
    // A value of the wrong type names its key and line.
    let msg = error("scene = \"ucs\"\n[rock]\nyoung = \"stiff\"\n");
    assert!(msg.contains("young") && msg.contains("line 3"), "{msg}");
    // A [loading] table gives all its keys (the defaults differ between the scenes).
    let msg = error("scene = \"ucs\"\n[loading]\nplaten_velocity = 0.1\n");
    assert!(msg.contains("ramp_time"), "{msg}");
    // Negative integers cannot be step counts.
    let msg = error(&loading("record_every = -5"));
    assert!(msg.contains("record_every"), "{msg}");
}

#[test]
fn scene_tag_is_required_and_checked() {
    assert!(matches!(
        SceneFile::from_toml("[sample]\nheight = 0.1\n"),
        Err(SceneFileError::MissingScene)
    ));
    let msg = error("scene = \"triaxial\"\n");
    assert!(msg.contains("triaxial") && msg.contains("ucs"), "{msg}");
    let msg = error("scene = \"ucs\"\n[sample\n");
    assert!(msg.contains("line 2"), "{msg}");
}

/// A confinement survives the round trip with and without its membrane (`None` is
/// written as `membrane = "none"`: TOML has no null, and an absent key means the
/// default membrane); another word is an error that names the key.
#[test]
fn confinement_membrane_round_trips_and_none_is_a_word() {
    use pcdc_validation::scenes::platen_test::{Confinement, Membrane};
    let c = Confinement {
        stress: 5e6,
        response_time: 2.5e-5,
        max_speed: 1.0,
        tolerance: 0.005,
        segments: 1,
        membrane: Some(Membrane {
            thickness: 0.004,
            ..Membrane::default()
        }),
    };
    for membrane in [c.membrane, None] {
        let scene = SceneFile::Ucs(ucs::Params {
            confinement: Some(Confinement {
                membrane,
                ..c.clone()
            }),
            ..ucs::Params::default()
        });
        let text = scene.to_toml().unwrap();
        assert_eq!(SceneFile::from_toml(&text).unwrap(), scene, "{text}");
        if membrane.is_none() {
            assert!(text.contains("membrane = \"none\""), "{text}");
        }
    }
    let head = "scene = \"ucs\"\n[confinement]\nstress = 5e6\nresponse_time = 2.5e-5\nmax_speed = 1.0\ntolerance = 0.005\n";
    match SceneFile::from_toml(head).unwrap() {
        SceneFile::Ucs(u) => {
            assert_eq!(u.confinement.unwrap().membrane, Some(Membrane::default()))
        }
        other => panic!("{other:?}"),
    }
    let msg = error(&format!("{head}membrane = \"off\"\n"));
    assert!(msg.contains("membrane"), "{msg}");
    // A misspelt key inside the table is named.
    let msg = error(&format!("{head}[confinement.membrane]\nthicknes = 0.004\n"));
    assert!(msg.contains("thicknes"), "{msg}");
}
