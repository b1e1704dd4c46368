//! Output helpers: global stress, principal stresses, displacement, and a VTU/PVD
//! writer for mechanical fields that ParaView opens.

use pcdc_compute::{names, Simulation};
use pcdc_mesh::vtu::{DataArray, PvdSeries};
use pcdc_mesh::Dim;

use crate::actions::DISPLACEMENT_RESET;
use crate::kinematics::{deformation_gradient_2d, dm_inv_2d, mul3, mul3_tn, polar_2d};
use crate::MechError;

/// Element Cauchy stress in the global frame (Pa, tension positive), stride NSYM
/// (2D: xx, yy, xy; 3D: xx, yy, zz, xy, yz, xz): the co-rotated stress rotated by the
/// element's current rotation, `R σ Rᵀ`.
pub fn global_stress<D: Dim>(sim: &Simulation<D>) -> Result<Vec<f64>, MechError> {
    let s = sim.field(names::STRESS)?;
    let mesh = sim.mesh();
    let mut out = s.to_vec();
    if D::D == 2 {
        let x = sim.positions();
        let mut xr = [0.0; 6];
        for e in 0..mesh.n_elements() {
            mesh.element_coords(e, &mut xr);
            let mut xc = [0.0; 6];
            for (a, &n) in mesh.element(e).iter().enumerate() {
                xc[2 * a..2 * a + 2].copy_from_slice(&x[n as usize * 2..n as usize * 2 + 2]);
            }
            let f = deformation_gradient_2d(&xc, &dm_inv_2d(&xr));
            let (co, si) = polar_2d(&f);
            let (a, b, cxy) = (s[3 * e], s[3 * e + 1], s[3 * e + 2]);
            out[3 * e] = co * co * a - 2.0 * co * si * cxy + si * si * b;
            out[3 * e + 1] = si * si * a + 2.0 * co * si * cxy + co * co * b;
            out[3 * e + 2] = co * si * (a - b) + (co * co - si * si) * cxy;
        }
    } else {
        let rot = sim.field(names::ROTATION)?;
        for e in 0..mesh.n_elements() {
            let r: [f64; 9] = rot[9 * e..9 * e + 9].try_into().expect("9 values");
            let v = &s[6 * e..6 * e + 6];
            let m = [v[0], v[3], v[5], v[3], v[1], v[4], v[5], v[4], v[2]];
            let g = mul3(
                &r,
                &mul3_tn(&[r[0], r[3], r[6], r[1], r[4], r[7], r[2], r[5], r[8]], &m),
            );
            out[6 * e..6 * e + 6].copy_from_slice(&[g[0], g[4], g[8], g[1], g[5], g[2]]);
        }
    }
    Ok(out)
}

/// Principal stresses per element, descending (σ1 ≥ σ2 [≥ σ3]), Pa; in 2D the in-plane
/// pair.
pub fn principal_stress<D: Dim>(global: &[f64]) -> Vec<f64> {
    if D::D == 2 {
        global
            .chunks_exact(3)
            .flat_map(|s| {
                let c = 0.5 * (s[0] + s[1]);
                let r = (0.25 * (s[0] - s[1]).powi(2) + s[2] * s[2]).sqrt();
                [c + r, c - r]
            })
            .collect()
    } else {
        global
            .chunks_exact(6)
            .flat_map(|s| {
                let m =
                    nalgebra::Matrix3::new(s[0], s[3], s[5], s[3], s[1], s[4], s[5], s[4], s[2]);
                let mut ev: Vec<f64> = m.symmetric_eigenvalues().iter().copied().collect();
                ev.sort_by(|a, b| b.total_cmp(a));
                ev
            })
            .collect()
    }
}

/// Node displacement since the last [`crate::reset_displacement`] (m), stride D.
pub fn displacement<D: Dim>(sim: &Simulation<D>) -> Result<Vec<f64>, MechError> {
    let off = sim.field(DISPLACEMENT_RESET)?;
    Ok(sim.state.u.iter().zip(off).map(|(u, o)| u - o).collect())
}

/// Names of the arrays [`write_step`] writes: point data (per node) and cell data (per
/// element). Extra arrays given to [`write_step_with`] must use other names.
pub const STEP_POINT_ARRAYS: [&str; 2] = ["displacement", "velocity"];
/// See [`STEP_POINT_ARRAYS`].
pub const STEP_CELL_ARRAYS: [&str; 4] = ["stress", "strain", "sigma_1", "sigma_min"];

/// Writes one VTU step on the deformed configuration: per node the displacement since
/// the last [`crate::reset_displacement`] (m) and the velocity (m/s); per element the
/// global stress (Pa), the strain, σ1 and the smallest principal stress (Pa), and, when
/// a model has history, each history variable as `model_state_k` (for
/// [`crate::MohrCoulomb`]: 0 shear now, 1 shear past, 2 tension now, 3 tension past, 4
/// κ_s, 5 κ_t; see [`crate::mohr_coulomb::state`]). Returns
/// the path of the `.vtu` file written. Use [`write_step_with`] to add arrays.
pub fn write_step<D: Dim>(
    series: &mut PvdSeries,
    sim: &Simulation<D>,
) -> Result<std::path::PathBuf, MechError> {
    write_step_with(series, sim, &[], &[])
}

/// [`write_step`] with extra arrays: `points` (one tuple per node) and `cells` (one
/// tuple per element), written after the standard arrays of the step, e.g. a scene's
/// largest joint damage per element:
///
/// ```ignore
/// output::write_step_with(&mut series, &sim, &[], &[DataArray::Scalar {
///     name: "joint_damage_max",
///     values: &elem_damage,
/// }])?;
/// ```
///
/// # Errors
///
/// [`MechError::Mesh`] (nothing written) when an extra array has the wrong length for
/// the node or element count, an empty name, or a name already in the step
/// ([`STEP_POINT_ARRAYS`], [`STEP_CELL_ARRAYS`]) or repeated; as [`write_step`]
/// otherwise.
pub fn write_step_with<D: Dim>(
    series: &mut PvdSeries,
    sim: &Simulation<D>,
    points: &[DataArray],
    cells: &[DataArray],
) -> Result<std::path::PathBuf, MechError> {
    let disp = displacement(sim)?;
    let stress = global_stress(sim)?;
    let principal = principal_stress::<D>(&stress);
    let strain = sim.field(names::STRAIN)?;
    // The mesh's nodes only (nodes a physics added, e.g. bolt nodes, are not cells' nodes).
    let nd = sim.mesh().n_nodes() * D::D;
    let mut x = sim.positions();
    x.truncate(nd);
    let np = if D::D == 2 { 2 } else { 3 };
    let p1: Vec<f64> = principal.iter().step_by(np).copied().collect();
    let pn: Vec<f64> = principal.iter().skip(np - 1).step_by(np).copied().collect();
    let [sn, en, p1n, pnn] = STEP_CELL_ARRAYS;
    let mut cell_data = vec![
        DataArray::SymTensor {
            name: sn,
            values: &stress,
        },
        DataArray::SymTensor {
            name: en,
            values: strain,
        },
        DataArray::Scalar {
            name: p1n,
            values: &p1,
        },
        DataArray::Scalar {
            name: pnn,
            values: &pn,
        },
    ];
    // The models' history, one scalar array per variable (`model_state_0`, ...).
    let (history, names) = model_state_columns(sim, sim.mesh().n_elements());
    for (name, values) in names.iter().zip(&history) {
        cell_data.push(DataArray::Scalar { name, values });
    }
    cell_data.extend_from_slice(cells);
    let [dn, vn] = STEP_POINT_ARRAYS;
    let mut point_data = vec![
        DataArray::Vector {
            name: dn,
            values: &disp,
        },
        DataArray::Vector {
            name: vn,
            values: &sim.state.v[..nd],
        },
    ];
    point_data.extend_from_slice(points);
    let path = series.write_step(
        sim.state.time,
        sim.mesh(),
        Some(&x),
        &point_data,
        &cell_data,
    )?;
    Ok(path)
}

/// The `model_state` field (when a model has history) split into one column per
/// variable, with the VTU names `model_state_k`. The mechanics keeps one column even
/// without history; a single all-zero column is not written (so a model with exactly one
/// history variable shows it once it is non-zero).
fn model_state_columns<D: Dim>(sim: &Simulation<D>, ne: usize) -> (Vec<Vec<f64>>, Vec<String>) {
    let Ok(state) = sim.field(names::MODEL_STATE) else {
        return (Vec::new(), Vec::new());
    };
    let n = state.len().checked_div(ne).unwrap_or(0);
    // Models without history still get one (zero) column: leave it out.
    if n == 1 && state.iter().all(|&v| v == 0.0) {
        return (Vec::new(), Vec::new());
    }
    let cols = (0..n)
        .map(|k| state.iter().skip(k).step_by(n).copied().collect())
        .collect();
    (cols, (0..n).map(|k| format!("model_state_{k}")).collect())
}

/// Area/volume-weighted average of per-element values at the nodes (`ncomp` values per
/// element): the usual smoothing of constant-strain element stresses for plots and
/// comparisons at nodes.
pub fn nodal_average<D: Dim>(mesh: &pcdc_mesh::Mesh<D>, values: &[f64], ncomp: usize) -> Vec<f64> {
    let n = mesh.n_nodes();
    let mut sum = vec![0.0; n * ncomp];
    let mut w = vec![0.0; n];
    for e in 0..mesh.n_elements() {
        let v = mesh.element_measure(e);
        for &node in mesh.element(e) {
            let node = node as usize;
            w[node] += v;
            for k in 0..ncomp {
                sum[node * ncomp + k] += v * values[e * ncomp + k];
            }
        }
    }
    for node in 0..n {
        for k in 0..ncomp {
            sum[node * ncomp + k] /= w[node];
        }
    }
    sum
}
