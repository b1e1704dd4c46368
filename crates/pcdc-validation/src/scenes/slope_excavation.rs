//! Validation scene 6: a slope excavated in three stages under gravity, Mohr–Coulomb on
//! Quad4 cells (manual 7.2.4, 7.2.8).
//!
//! A layer [0, 80] × [0, 30] m (plane strain) of Mohr–Coulomb soil (E = 200 MPa,
//! ν = 0.3, ρ = 2000 kg/m³, c = 40 kPa, φ = 30°, ψ = 0°, σ_t = 10 kPa) on Quad4 cells
//! starts from the geostatic stress σv = −ρ g depth, σh = K0 σv (xx and zz), K0 = 0.5
//! (1 − sin φ), under gravity, on rollers at the sides and fixed at the bottom. It is
//! first relaxed to equilibrium; the far-field stresses (the mean stress of every cell
//! with centroid x < 10 m and more than one cell below the surface, at the cell
//! centroid's depth) are then compared with the closed form:
//! error = max over those cells of |σyy − σv| / |σv| and |σxx − K0 σv| / (K0 |σv|),
//! tolerance [`TOL`] (2 %). The displacements are reset (manual 7.2.8) and the cut is
//! excavated in [`STAGES`] benches of 5 m: stage k switches to null the cells right of
//! the 45° face x = 55 − y (m) with centroid 30 − 5k < y ≤ 35 − 5k, then relaxes to
//! equilibrium. Each stage reports the heave of the cut floor, the largest displacement
//! and the number of cells that have yielded, and writes a VTU step (the PVD time is the
//! stage number; `model_state_1` marks the cells that yielded in shear).
//!
//! On the regular grid the geostatic state is an exact discrete equilibrium (the
//! unbalanced-force ratio comes out zero); [`Params::distortion`] moves the interior
//! nodes at random so that the check also runs on cells that are not rectangles, where
//! the relaxation has to redistribute the stress.
//!
//! No closed form exists for the excavated states: they are a figure and numbers (the
//! cut is stable, factor of safety about 1.7 by Taylor's chart for c/(γH) = 0.13, φ = 30°,
//! β = 45°), as in FLAC's slope examples.

use std::time::Instant;

use pcdc_compute::{Backend, Simulation};
use pcdc_mech::mohr_coulomb::{state, MC_STATE};
use pcdc_mech::{
    output, reset_displacement, set_null, Boundary, Constraint, InitialStress, LinearElastic,
    Mechanics, MohrCoulomb,
};
use pcdc_mesh::{builders, Dim2, Mesh, Range};

use crate::report::SceneError;

/// Tolerance on the far-field geostatic stresses (relative).
pub const TOL: f64 = 0.02;
/// Excavation stages (benches of 5 m).
pub const STAGES: usize = 3;
/// Width and height of the layer (m).
pub const WIDTH: f64 = 80.0;
/// See [`WIDTH`].
pub const HEIGHT: f64 = 30.0;
/// Density (kg/m³).
pub const DENSITY: f64 = 2000.0;
/// Gravity (m/s²).
pub const GRAVITY: f64 = 9.81;
/// Lateral earth pressure coefficient K0 = 1 − sin φ.
pub const K0: f64 = 0.5;

/// Scene parameters.
#[derive(Clone, Debug)]
pub struct Params {
    /// Quad size (m).
    pub size: f64,
    /// Folder for the VTU/PVD series of the stages, if any.
    pub vtu_dir: Option<std::path::PathBuf>,
    /// Interior nodes moved at random (seeded) by up to this fraction of the cell size in
    /// each direction, so that the cells are not all rectangles (0: the regular grid).
    pub distortion: f64,
}

impl Params {
    /// Full size: 1 m quads (2400 cells).
    pub fn full() -> Self {
        Params {
            size: 1.0,
            vtu_dir: None,
            distortion: 0.0,
        }
    }
    /// Reduced: 2.5 m quads (384 cells).
    pub fn reduced() -> Self {
        Params {
            size: 2.5,
            vtu_dir: None,
            distortion: 0.0,
        }
    }
}

/// What one excavation stage left.
#[derive(Clone, Debug)]
pub struct Stage {
    /// Depth of the cut (m).
    pub depth: f64,
    /// Upward displacement of the cut floor's centre (m).
    pub floor_heave: f64,
    /// Largest displacement magnitude (m).
    pub max_displacement: f64,
    /// Live cells that have yielded (shear or tension, now or before).
    pub yielded_cells: usize,
    /// Centroids (x, y) of the yielded cells (m).
    pub yielded: Vec<[f64; 2]>,
    /// The free surface after the stage: (x, vertical displacement) of its nodes (m).
    pub surface: Vec<(f64, f64)>,
    /// Relaxation steps of the stage.
    pub steps: u64,
}

/// Outcome of the scene.
#[derive(Clone, Debug)]
pub struct Outcome {
    /// Far-field stress error before the excavation (see module docs).
    pub error: f64,
    /// Unbalanced-force ratio after the relaxation under gravity, before the excavation.
    pub initial_ratio: f64,
    /// The stages in order.
    pub stages: Vec<Stage>,
    /// Cells of the mesh.
    pub cells: usize,
    /// Relaxation steps in all.
    pub steps: u64,
    /// Wall time (s).
    pub wall_s: f64,
}

/// The cut after stage `k` (1-based) of the excavation: right of the 45° face and above
/// the stage's floor.
fn stage_range(k: usize) -> Range {
    let (top, floor) = (HEIGHT - 5.0 * (k - 1) as f64, HEIGHT - 5.0 * k as f64);
    Range::custom(move |x| x[1] > floor && x[1] <= top + 1e-9 && x[0] > 55.0 - x[1])
}

/// The grid with its interior nodes moved by up to `p.distortion` cells (seeded).
fn distort(mesh: Mesh<Dim2>, p: &Params) -> Result<Mesh<Dim2>, SceneError> {
    if p.distortion == 0.0 {
        return Ok(mesh);
    }
    let mut coords = mesh.coords().to_vec();
    let mut state = 0x2545_f491_4f6c_dd1du64;
    for (n, x) in coords.chunks_exact_mut(2).enumerate() {
        let on_edge = x[0] < 1e-9 || x[0] > WIDTH - 1e-9 || x[1] < 1e-9 || x[1] > HEIGHT - 1e-9;
        for v in x.iter_mut() {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407 + n as u64);
            let r = (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
            if !on_edge {
                *v += 2.0 * r * p.distortion * p.size;
            }
        }
    }
    let kinds = (0..mesh.n_cells()).map(|c| mesh.cell_kind(c)).collect();
    let conn = (0..mesh.n_cells())
        .flat_map(|c| mesh.cell_nodes(c).to_vec())
        .collect();
    let mut moved = Mesh::from_cells(coords, kinds, conn)?;
    let groups = mesh.groups().clone();
    for (name, v) in groups.nodes {
        moved.add_node_group(name, v)?;
    }
    for (name, v) in groups.faces {
        moved.add_face_group(name, v)?;
    }
    for (name, v) in groups.elements {
        moved.add_element_group(name, v)?;
    }
    Ok(moved)
}

/// Runs the scene.
pub fn run(backend: &Backend, p: &Params) -> Result<Outcome, SceneError> {
    let start = Instant::now();
    let mesh = distort(
        builders::rectangle_quads(0.0, 0.0, WIDTH, HEIGHT, p.size)?,
        p,
    )?;
    let cells = mesh.n_cells();
    let e = LinearElastic::new(200e6, 0.3, DENSITY)?.with_damping(0.8)?;
    let soil = MohrCoulomb::new(e, 40e3, 30.0, 0.0, 10e3)?;
    let mut sim = Simulation::builder(mesh, backend.clone())
        .gravity([0.0, -GRAVITY, 0.0])
        .physics(
            Mechanics::new()
                .material(Range::All, soil)
                .initial_stress_field(
                    Range::All,
                    InitialStress::Geostatic {
                        surface: HEIGHT,
                        density: DENSITY,
                        gravity: GRAVITY,
                        k0: K0,
                    },
                ),
        )
        .physics(
            Boundary::new()
                .constraint(Range::group("left"), Constraint::Line([0.0, 1.0, 0.0]))
                .constraint(Range::group("right"), Constraint::Line([0.0, 1.0, 0.0]))
                .constraint(Range::group("bottom"), Constraint::Fixed),
        )
        .build()?;
    let opts = super::relax_options(backend);
    let first = sim.relax(&opts)?;
    let mut steps = first.steps;
    let error = far_field_error(&sim, p.size)?;
    let mut series = p
        .vtu_dir
        .as_ref()
        .map(|dir| pcdc_mesh::vtu::PvdSeries::new(dir, "slope_excavation"))
        .transpose()?;
    if let Some(s) = series.as_mut() {
        output::write_step(s, &sim)?;
    }
    reset_displacement(&mut sim, &Range::All)?;
    let mut stages = Vec::with_capacity(STAGES);
    for k in 1..=STAGES {
        set_null(&mut sim, &stage_range(k))?;
        let n = sim.relax(&opts)?.steps;
        steps += n;
        // The PVD time of a stage is its number (statics do not advance the clock).
        sim.state.time = k as f64;
        if let Some(s) = series.as_mut() {
            output::write_step(s, &sim)?;
        }
        stages.push(measure_stage(&sim, 5.0 * k as f64, n)?);
    }
    Ok(Outcome {
        error,
        initial_ratio: first.ratio,
        stages,
        cells,
        steps,
        wall_s: start.elapsed().as_secs_f64(),
    })
}

/// Largest relative deviation of the far-field cell stresses (the volume-weighted mean
/// of a cell's simplices, at the cell centroid) from σv = −ρ g depth and σh = K0 σv.
fn far_field_error(sim: &Simulation<Dim2>, size: f64) -> Result<f64, SceneError> {
    let stress = output::global_stress(sim)?;
    let mesh = sim.mesh();
    let (mut worst, mut count) = (0.0f64, 0);
    let mut c = [0.0; 2];
    for cell in 0..mesh.n_cells() {
        mesh.cell_centroid(cell, &mut c);
        let depth = HEIGHT - c[1];
        if c[0] >= 10.0 || depth < size {
            continue;
        }
        let (mut s, mut vol) = ([0.0; 3], 0.0);
        for e in mesh.cell_elements(cell) {
            let v = mesh.element_measure(e);
            for k in 0..3 {
                s[k] += v * stress[3 * e + k];
            }
            vol += v;
        }
        let s = s.map(|x| x / vol);
        let sv = -DENSITY * GRAVITY * depth;
        worst = worst
            .max((s[1] - sv).abs() / sv.abs())
            .max((s[0] - K0 * sv).abs() / (K0 * sv.abs()));
        count += 1;
    }
    if count == 0 {
        return Err(SceneError::Measurement(
            "no far-field cell below the surface".into(),
        ));
    }
    Ok(worst)
}

fn measure_stage(sim: &Simulation<Dim2>, depth: f64, steps: u64) -> Result<Stage, SceneError> {
    let mesh = sim.mesh();
    let u = output::displacement(sim)?;
    let null = sim.field(pcdc_compute::names::ELEMENT_NULL)?;
    let history = sim.field("model_state")?;
    let mut live = vec![false; mesh.n_nodes()];
    let (mut yielded, mut c) = (Vec::new(), [0.0; 2]);
    for cell in 0..mesh.n_cells() {
        let els = mesh.cell_elements(cell);
        if null[els.start] != 0.0 {
            continue;
        }
        for &n in mesh.cell_nodes(cell) {
            live[n as usize] = true;
        }
        let hit = els.clone().any(|e| {
            let h = &history[e * MC_STATE..];
            h[state::SHEAR_PAST] > 0.0 || h[state::TENSION_PAST] > 0.0
        });
        if hit {
            mesh.cell_centroid(cell, &mut c);
            yielded.push(c);
        }
    }
    // The free surface: live nodes on the top boundary or shared with a null cell.
    let mut next_to_null = vec![false; mesh.n_nodes()];
    for cell in 0..mesh.n_cells() {
        if null[mesh.cell_elements(cell).start] != 0.0 {
            for &n in mesh.cell_nodes(cell) {
                next_to_null[n as usize] = true;
            }
        }
    }
    let mut top: Vec<(f64, f64, usize)> = (0..mesh.n_nodes())
        .filter(|&n| live[n] && (next_to_null[n] || mesh.node(n)[1] > HEIGHT - 1e-9))
        .map(|n| (mesh.node(n)[0], mesh.node(n)[1], n))
        .collect();
    top.sort_by(|a, b| a.0.total_cmp(&b.0));
    let surface: Vec<(f64, f64)> = top.iter().map(|t| (t.0, u[2 * t.2 + 1])).collect();
    // The cut floor's centre: the floor node nearest x = 55 − floor + 10 m.
    let floor_y = HEIGHT - depth;
    let floor_x = 55.0 - floor_y + 10.0;
    let floor_heave = top
        .iter()
        .filter(|t| (t.1 - floor_y).abs() < 0.5 * depth.min(5.0))
        .min_by(|a, b| (a.0 - floor_x).abs().total_cmp(&(b.0 - floor_x).abs()))
        .map_or(0.0, |t| u[2 * t.2 + 1]);
    let max_displacement = u
        .chunks_exact(2)
        .map(|v| v[0].hypot(v[1]))
        .fold(0.0, f64::max);
    Ok(Stage {
        depth,
        floor_heave,
        max_displacement,
        yielded_cells: yielded.len(),
        yielded,
        surface,
        steps,
    })
}
