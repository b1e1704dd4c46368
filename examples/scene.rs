//! Runs a scene file: `cargo run --release --example scene -- scenes/ucs.toml` (or
//! `scenes/brazilian.toml`, or your own copy). The file's first key names the scene
//! (`scene = "ucs"` or `"brazilian"`); omitted keys take the full-size defaults; an
//! unknown key or an out-of-range value stops with an error that names it. Outputs go to
//! the file's `output.dir` (default `out/ucs` or `out/brazilian`). Backend flags may
//! follow the path: `--backend cpu|gpu`, `--precision f64|f32`.

mod common;

use pcdc::compute::{Backend, BackendChoice, BackendKind, CpuBackend, WgpuBackend};
use pcdc::report::{check_backend_args, ResultLine, BACKEND_USAGE};
use pcdc::scenes::file::SceneFile;

fn main() {
    pcdc::report::finish(choose())
}

fn choose() -> Result<Vec<ResultLine>, Box<dyn std::error::Error>> {
    let mut args: Vec<String> = std::env::args().skip(1).collect();
    let usage =
        format!("usage: cargo run --release --example scene -- <scene.toml> [{BACKEND_USAGE}]");
    if args.is_empty() || args[0].starts_with('-') {
        return Err(usage.into());
    }
    let path = args.remove(0);
    check_backend_args(&args)?;
    let choice = BackendChoice::parse(&args)?;
    let scene = SceneFile::read(&path).map_err(|e| format!("{path}: {e}"))?;
    println!("scene file: {path}");
    match choice.kind {
        BackendKind::Cpu => run(&CpuBackend::new(0)?, &scene),
        BackendKind::Gpu => run(&WgpuBackend::new(choice.precision)?, &scene),
    }
}

fn run<B: Backend>(
    backend: &B,
    scene: &SceneFile,
) -> Result<Vec<ResultLine>, Box<dyn std::error::Error>> {
    println!("backend: {}", pcdc::report::describe_backend(backend));
    Ok(vec![match scene {
        SceneFile::Ucs(p) => common::run_ucs(backend, p)?,
        SceneFile::Brazilian(p) => common::run_brazilian(backend, p)?,
    }])
}
