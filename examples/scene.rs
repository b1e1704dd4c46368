//! Runs a scene file: `cargo run --release --example scene -- scenes/ucs.toml` (or
//! `scenes/brazilian.toml`, or your own copy). The file's first key names the scene
//! (`scene = "ucs"` or `"brazilian"`); omitted keys take the full-size defaults; an
//! unknown key or an out-of-range value stops with an error that names it. Outputs go to
//! the file's `output.dir` (default `out/ucs` or `out/brazilian`). Backend flags may
//! follow the path: `--backend cpu|gpu`, `--precision f64|f32`.

mod common;

use pcdc::compute::Backend;
use pcdc_validation::report::ResultLine;
use pcdc_validation::scenes::file::SceneFile;

fn main() {
    pcdc_validation::report::finish(choose())
}

fn choose() -> Result<Vec<ResultLine>, Box<dyn std::error::Error>> {
    let args = common::cli::command(
        "scene",
        "Runs a scene file (TOML): the UCS or Brazilian test with your own parameters",
    )
    .arg(
        clap::Arg::new("file")
            .required(true)
            .value_name("SCENE.toml")
            .help("Scene file, e.g. scenes/ucs.toml or scenes/brazilian.toml"),
    )
    .get_matches();
    let path = args.get_one::<String>("file").expect("required");
    let scene = SceneFile::read(path).map_err(|e| format!("{path}: {e}"))?;
    println!("scene file: {path}");
    run(&common::cli::backend(&args)?, &scene)
}

fn run(
    backend: &Backend,
    scene: &SceneFile,
) -> Result<Vec<ResultLine>, Box<dyn std::error::Error>> {
    println!("backend: {}", backend.describe());
    Ok(vec![match scene {
        SceneFile::Ucs(p) => common::run_ucs(backend, p)?,
        SceneFile::Brazilian(p) => common::run_brazilian(backend, p)?,
    }])
}
