//! Scene files (TOML): values out of range, physically absurd values, meshes over the
//! memory limit, and malformed files.

use pcdc_validation::scenes::file::SceneFile;

use crate::{case, run};

fn ucs(extra: &'static str) -> Result<SceneFile, pcdc_validation::scenes::file::SceneFileError> {
    SceneFile::from_toml(&format!("scene = \"ucs\"\n{extra}"))
}

fn brazilian(
    extra: &'static str,
) -> Result<SceneFile, pcdc_validation::scenes::file::SceneFileError> {
    SceneFile::from_toml(&format!("scene = \"brazilian\"\n{extra}"))
}

const LOADING: &str =
    "stop_fraction = 0.7\nmax_closure = 0.005\nrecord_every = 100\nramp_time = 5e-5\n";

fn loading(
    first: &'static str,
) -> Result<SceneFile, pcdc_validation::scenes::file::SceneFileError> {
    SceneFile::from_toml(&format!("scene = \"ucs\"\n[loading]\n{first}\n{LOADING}"))
}

#[test]
fn bad_scene_files_are_named_errors() {
    run(
        "scene files",
        vec![
            case(
                "platen velocity 1e6 m/s",
                "loading.platen_velocity = 1000000: must be at most 10 m/s",
                || loading("platen_velocity = 1e6"),
            ),
            case(
                "negative platen velocity",
                "loading.platen_velocity = -0.1",
                || loading("platen_velocity = -0.1"),
            ),
            case("ramp time 100 s", "loading.ramp_time = 100", || {
                SceneFile::from_toml("scene = \"ucs\"\n[loading]\nplaten_velocity = 0.1\nstop_fraction = 0.7\nmax_closure = 0.005\nrecord_every = 100\nramp_time = 100.0\n")
            }),
            case(
                "1000 m sample",
                "sample.height = 1000: must be at most 10 m",
                || ucs("[sample]\nheight = 1000.0\n"),
            ),
            case("NaN sample width", "sample.width = NaN", || {
                ucs("[sample]\nwidth = nan\n")
            }),
            case("50 m disc", "disc.diameter = 50", || {
                brazilian("[disc]\ndiameter = 50.0\n")
            }),
            case("20 m platens", "platens.width = 20", || {
                ucs("[platens]\nwidth = 20.0\n")
            }),
            case("E = 1e20 Pa", "rock.young = 100000000000000000000", || {
                ucs("[rock]\nyoung = 1e20\n")
            }),
            case("ν = 0.5", "rock.poisson = 0.5", || {
                ucs("[rock]\npoisson = 0.5\n")
            }),
            case("ν = NaN", "rock.poisson = NaN", || {
                brazilian("[rock]\npoisson = nan\n")
            }),
            case("density 1e7", "rock.density = 10000000", || {
                ucs("[rock]\ndensity = 1e7\n")
            }),
            case("platen ν = -1", "platens.poisson = -1", || {
                ucs("[platens]\npoisson = -1.0\n")
            }),
            case("negative T_s", "joints.tensile_strength = -1", || {
                ucs("[joints]\ntensile_strength = -1.0\n")
            }),
            case(
                "cohesion 1e12 Pa",
                "joints.cohesion = 1000000000000",
                || ucs("[joints]\ncohesion = 1e12\n"),
            ),
            case("G_f1 1e9 N/m", "joints.gf1 = 1000000000", || {
                brazilian("[joints]\ngf1 = 1e9\n")
            }),
            case(
                "overlap penalty 1e6 E",
                "joints.penalty_overlap = 1000000",
                || ucs("[joints]\npenalty_overlap = 1e6\n"),
            ),
            case("contact penalty 1e5 E", "contact.penalty = 100000", || {
                ucs("[contact]\npenalty = 1e5\n")
            }),
            case("contact friction 95°", "contact.friction_deg = 95", || {
                ucs("[contact]\nfriction_deg = 95.0\n")
            }),
            case("mesh size over the sample", "sample.mesh_size = 1", || {
                ucs("[sample]\nmesh_size = 1.0\n")
            }),
            case(
                "UCS mesh over the memory limit",
                "sample.mesh_size = 0.00001: the FDEM scene of about",
                || ucs("[sample]\nmesh_size = 1e-5\n"),
            ),
            case(
                "disc mesh over the memory limit",
                "above the memory limit",
                || brazilian("[disc]\nmesh_size = 1e-5\n"),
            ),
            case("frames 1e6", "output.frames = 1000000", || {
                ucs("[output]\ndir = \"out\"\nframes = 1000000\n")
            }),
            case("partial [loading]", "missing field `ramp_time`", || {
                ucs("[loading]\nplaten_velocity = 0.1\n")
            }),
            case("unknown key", "unknown field `hieght`", || {
                ucs("[sample]\nhieght = 0.1\n")
            }),
            case(
                "unknown scene",
                "scene = \"triaxial\" is not a scene",
                || SceneFile::from_toml("scene = \"triaxial\"\n"),
            ),
            case("missing scene", "missing key `scene`", || {
                SceneFile::from_toml("[sample]\nheight = 0.1\n")
            }),
            case("not TOML", "line 2", || {
                SceneFile::from_toml("scene = \"ucs\"\n[sample\n")
            }),
            case(
                "missing file",
                "cannot read scene file /nonexistent/x.toml",
                || SceneFile::read("/nonexistent/x.toml"),
            ),
        ],
    );
}
