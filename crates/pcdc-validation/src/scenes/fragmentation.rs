//! Hard case: a jointed rock block thrown into a closed box fragments, and the run stays
//! stable over a long time (issue "correctness first").
//!
//! A 0.08 × 0.05 m block of FDEM triangles (every triangle with its own nodes, an
//! intrinsic cohesive joint on every interior edge) flies at 20 m/s, spinning at
//! 100 rad/s, into the wall of a closed 0.3 × 0.2 m box with rigid walls (elastic elements whose
//! nodes are all fixed), under gravity. It shatters on the walls and the fragments
//! bounce around, rotate and collide for the rest of the run. Contact acts between the
//! fragments, between fragments and walls and on the faces of broken joints; broken
//! joints transfer no force.
//!
//! Rock: E = 30 GPa, ν = 0.25, ρ = 2600 kg/m³, no element damping (nothing hides an
//! energy defect). Joints: φ = 30°, c = 4 MPa, T_s = 1 MPa, G_f1 = 1 N/m, G_f2 = 5 N/m,
//! penalties 10 E. Contact: penalty 10 E, friction 30° with shear penalty 10 E.
//!
//! Measured: the energy balance ([`pcdc_compute::EnergyBalance`]), whose excess, total
//! energy minus the initial energy and the external work, must stay below
//! [`ENERGY_TOL`] of the reference energy at every check; and the deepest penetration of
//! a node into an element of another body or fragment, which must stay below
//! [`PENETRATION_TOL`] of that element's mean edge length. The run also has the energy
//! watchdog on at twice the tolerance, and the divergence watchdog, so a defect stops it
//! with the step and the entity at fault.

use std::time::Instant;

use pcdc::fdem::Fdem;
use pcdc_cohesive::IntrinsicCzmParams;
use pcdc_compute::{Backend, Fingerprint, Simulation};
use pcdc_contact::Contact;
use pcdc_mech::{Boundary, LinearElastic};
use pcdc_mesh::{builders, split_nodes, Dim2, Mesh, Range};

use crate::report::SceneError;

/// Largest energy excess allowed, relative to max(E_0 + W_ext, largest total energy).
pub const ENERGY_TOL: f64 = 0.01;
/// Deepest penetration allowed, relative to the penetrated element's mean edge length.
pub const PENETRATION_TOL: f64 = 0.05;

const E: f64 = 30e9;
const BOX_W: f64 = 0.3;
const BOX_H: f64 = 0.2;
/// The block: lower-left corner, width, height (m); 2 cm from the right wall.
const BLOCK: [f64; 4] = [0.2, 0.08, 0.08, 0.05];
const WALL: f64 = 0.02;

/// Parameters of a run.
#[derive(Clone, Debug)]
pub struct Params {
    /// Mesh size of the block (m).
    pub size: f64,
    /// Steps to run.
    pub steps: u64,
    /// Steps between two measurements (energy and penetration).
    pub check_every: u64,
}

impl Default for Params {
    /// The example's scene: 5 mm triangles, 100 000 steps.
    fn default() -> Self {
        Params {
            size: 0.005,
            steps: 100_000,
            check_every: 1000,
        }
    }
}

/// What a run measured.
#[derive(Clone, Debug)]
pub struct Outcome {
    /// Largest energy excess over the checks, relative to the reference energy.
    pub worst_energy_excess: f64,
    /// Step of the largest excess.
    pub worst_step: u64,
    /// Deepest penetration over the checks, relative to the element size.
    pub worst_penetration: f64,
    /// Broken joints at the end, and joints in all.
    pub broken: usize,
    /// Joints in all.
    pub joints: usize,
    /// Energy at the start, E_0 (J per m of thickness).
    pub initial_energy: f64,
    /// External work at the end (J/m): gravity and the walls.
    pub external_work: f64,
    /// Kinetic energy at the end (J/m).
    pub final_kinetic: f64,
    /// Energy dissipated at the end (J/m) by each internal physics.
    pub dissipated: Vec<(String, f64)>,
    /// Elements.
    pub elements: usize,
    /// Steps run.
    pub steps: u64,
    /// Time step (s).
    pub dt: f64,
    /// Wall time (s).
    pub wall_s: f64,
    /// Hash ([`Fingerprint`]) of the bits of the final displacements and velocities:
    /// equal hashes mean bit-identical runs (e.g. on different thread counts).
    pub state_hash: u64,
    /// (step, relative excess, relative penetration) at each check.
    pub history: Vec<(u64, f64, f64)>,
}

/// Builds the box and the block: returns the mesh, the number of wall elements (the
/// first ones) and the block's elements range.
fn geometry(size: f64) -> Result<(Mesh<Dim2>, usize), SceneError> {
    let wall_size = WALL.max(size);
    let bottom = builders::rectangle(-WALL, -WALL, BOX_W + 2.0 * WALL, WALL, wall_size)?;
    let top = builders::rectangle(-WALL, BOX_H, BOX_W + 2.0 * WALL, WALL, wall_size)?;
    let left = builders::rectangle(-WALL, 0.0, WALL, BOX_H, wall_size)?;
    let right = builders::rectangle(BOX_W, 0.0, WALL, BOX_H, wall_size)?;
    let block = builders::rectangle(BLOCK[0], BLOCK[1], BLOCK[2], BLOCK[3], size)?;
    let n_walls = bottom.n_elements() + top.n_elements() + left.n_elements() + right.n_elements();
    let (mesh, _) = builders::union(&[&bottom, &top, &left, &right, &block])?;
    Ok((mesh, n_walls))
}

/// Runs the scene on `backend`.
pub fn run(backend: &Backend, p: &Params) -> Result<Outcome, SceneError> {
    let start = Instant::now();
    let (mesh, n_walls) = geometry(p.size)?;
    // FDEM region: the block (inside the box); the walls keep shared nodes.
    let inside = Range::rect(1e-9, 1e-9, BOX_W - 1e-9, BOX_H - 1e-9);
    let mut mesh = split_nodes(&mesh, &inside)?;
    let mut wall_nodes: Vec<u32> = (0..n_walls)
        .flat_map(|e| mesh.element(e).to_vec())
        .collect();
    wall_nodes.sort_unstable();
    wall_nodes.dedup();
    mesh.add_node_group("walls", wall_nodes.clone())?;
    let rock = LinearElastic::new(E, 0.25, 2600.0)?;
    let czm = IntrinsicCzmParams {
        friction_deg: 30.0,
        cohesion: 4e6,
        tensile_strength: 1e6,
        gf1: 1.0,
        gf2: 5.0,
        penalty_open: 10.0 * E,
        penalty_shear: 10.0 * E,
        penalty_overlap: 10.0 * E,
    }
    .build()?;
    let contact = Contact::new(10.0 * E).friction(30.0, 10.0 * E);
    let n_joints = mesh.interfaces().len();
    let mut sim = Simulation::builder(mesh, backend.clone())
        .group(Fdem::new(rock, czm, contact))
        .physics(Boundary::new().fix(Range::group("walls")))
        .gravity([0.0, -9.81, 0.0])
        .energy_watchdog(2.0 * ENERGY_TOL)
        .build()?;
    // Initial motion of the block: translation plus spin about its centre.
    let (cx, cy) = (BLOCK[0] + 0.5 * BLOCK[2], BLOCK[1] + 0.5 * BLOCK[3]);
    let is_wall = {
        let mut w = vec![false; sim.mesh().n_nodes()];
        for &n in &wall_nodes {
            w[n as usize] = true;
        }
        w
    };
    for n in 0..sim.mesh().n_nodes() {
        if !is_wall[n] {
            let x = sim.mesh().node(n).to_vec();
            let (rx, ry) = (x[0] - cx, x[1] - cy);
            sim.state.v[2 * n] = 20.0 - 100.0 * ry;
            sim.state.v[2 * n + 1] = -5.0 + 100.0 * rx;
        }
    }
    let owner = body_of_nodes(sim.mesh());
    let mut out = Outcome {
        worst_energy_excess: 0.0,
        worst_step: 0,
        worst_penetration: 0.0,
        broken: 0,
        joints: n_joints,
        initial_energy: 0.0,
        external_work: 0.0,
        final_kinetic: 0.0,
        dissipated: Vec::new(),
        elements: sim.mesh().n_elements(),
        steps: 0,
        dt: sim.dt(),
        wall_s: 0.0,
        state_hash: 0,
        history: Vec::new(),
    };
    let every = p.check_every.max(1);
    while sim.state.step < p.steps {
        let n = every.min(p.steps - sim.state.step);
        sim.run(n)?;
        let b = sim
            .evaluate_energy()?
            .ok_or_else(|| SceneError::Measurement("energy tracking is off".into()))?
            .clone();
        let reference = (b.initial + b.external_work).max(b.total());
        let excess = b.excess() / reference;
        let pen = deepest_penetration(sim.mesh(), &sim.positions(), &owner);
        out.history.push((sim.state.step, excess, pen));
        if excess > out.worst_energy_excess {
            out.worst_energy_excess = excess;
            out.worst_step = sim.state.step;
        }
        out.worst_penetration = out.worst_penetration.max(pen);
        out.initial_energy = b.initial;
        out.external_work = b.external_work;
        out.final_kinetic = b.kinetic;
        out.dissipated = b
            .physics
            .iter()
            .filter(|q| !q.applies_loads)
            .map(|q| (q.name.clone(), q.dissipated()))
            .collect();
    }
    out.broken = sim
        .field(pcdc_cohesive::JOINT_DAMAGE)?
        .iter()
        .filter(|&&d| d >= 1.0)
        .count();
    out.steps = sim.state.step;
    let kin = sim.kinematics();
    out.state_hash = Fingerprint::new().f64s(kin.u).f64s(kin.v).finish();
    out.wall_s = start.elapsed().as_secs_f64();
    Ok(out)
}

/// Per element, the elements it shares a node with count as its own body (a wall, or
/// the element itself in the FDEM region where every element has its own nodes): the
/// set of element ids per node, to tell a foreign element from the node's own.
fn body_of_nodes(mesh: &Mesh<Dim2>) -> Vec<Vec<u32>> {
    let mut of = vec![Vec::new(); mesh.n_nodes()];
    for e in 0..mesh.n_elements() {
        for &n in mesh.element(e) {
            of[n as usize].push(e as u32);
        }
    }
    of
}

/// Deepest penetration of a node into an element it does not belong to, relative to
/// that element's mean edge length: for a node strictly inside a triangle, its distance
/// to the nearest edge. A uniform grid of cell size = largest element box finds the
/// candidate triangles.
pub fn deepest_penetration(mesh: &Mesh<Dim2>, x: &[f64], own: &[Vec<u32>]) -> f64 {
    let ne = mesh.n_elements();
    let tri = |e: usize| -> [[f64; 2]; 3] {
        let c = mesh.element(e);
        std::array::from_fn(|a| [x[2 * c[a] as usize], x[2 * c[a] as usize + 1]])
    };
    let (mut lo, mut hi, mut cell) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2], 0.0f64);
    for e in 0..ne {
        let t = tri(e);
        for k in 0..2 {
            let (a, b) = (
                t.iter().map(|p| p[k]).fold(f64::INFINITY, f64::min),
                t.iter().map(|p| p[k]).fold(f64::NEG_INFINITY, f64::max),
            );
            lo[k] = lo[k].min(a);
            hi[k] = hi[k].max(b);
            cell = cell.max(b - a);
        }
    }
    if cell.is_nan() || cell <= 0.0 || !lo.iter().chain(&hi).all(|v| v.is_finite()) {
        return f64::INFINITY;
    }
    let nx = (((hi[0] - lo[0]) / cell).ceil() as usize).clamp(1, 4096);
    let ny = (((hi[1] - lo[1]) / cell).ceil() as usize).clamp(1, 4096);
    let at = |p: [f64; 2]| -> (usize, usize) {
        (
            (((p[0] - lo[0]) / cell) as usize).min(nx - 1),
            (((p[1] - lo[1]) / cell) as usize).min(ny - 1),
        )
    };
    let mut grid: Vec<Vec<u32>> = vec![Vec::new(); nx * ny];
    for e in 0..ne {
        let t = tri(e);
        let (i0, j0) = at([
            t.iter().map(|p| p[0]).fold(f64::INFINITY, f64::min),
            t.iter().map(|p| p[1]).fold(f64::INFINITY, f64::min),
        ]);
        let (i1, j1) = at([
            t.iter().map(|p| p[0]).fold(f64::NEG_INFINITY, f64::max),
            t.iter().map(|p| p[1]).fold(f64::NEG_INFINITY, f64::max),
        ]);
        for j in j0..=j1 {
            for i in i0..=i1 {
                grid[j * nx + i].push(e as u32);
            }
        }
    }
    let mut worst = 0.0f64;
    for n in 0..mesh.n_nodes() {
        let p = [x[2 * n], x[2 * n + 1]];
        let (i, j) = at(p);
        for &e in &grid[j * nx + i] {
            if own[n].contains(&e) {
                continue;
            }
            let t = tri(e as usize);
            let area2 = (t[1][0] - t[0][0]) * (t[2][1] - t[0][1])
                - (t[2][0] - t[0][0]) * (t[1][1] - t[0][1]);
            let mut depth = f64::INFINITY;
            let mut perimeter = 0.0;
            for a in 0..3 {
                let (q, r) = (t[a], t[(a + 1) % 3]);
                let len = ((r[0] - q[0]).powi(2) + (r[1] - q[1]).powi(2)).sqrt();
                perimeter += len;
                // Signed distance to the edge line, positive inside (counter-clockwise).
                let cross = (r[0] - q[0]) * (p[1] - q[1]) - (r[1] - q[1]) * (p[0] - q[0]);
                depth = depth.min(area2.signum() * cross / len);
            }
            if depth > 0.0 {
                worst = worst.max(depth / (perimeter / 3.0));
            }
        }
    }
    worst
}
