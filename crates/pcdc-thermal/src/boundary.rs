//! Thermal boundary conditions (manual 7.6.8, tables 14 and 16; eq. 100–101).
//!
//! * **Temperature** on nodes (table 14): held at T(t) (a constant or a time table).
//! * **Heat flux** on boundary faces (table 16, `heat-flux`): a flux density q_n (W/m²,
//!   positive **into** the body; in 2D per metre of thickness, so a face of length L
//!   receives q_n L watts per metre). \[AMBIGUOUS in the manual: it prints J/s, a total
//!   power; a density is what a user can carry from one mesh to another.\]
//! * **Convection** on boundary faces (eq. 100, table 16 `transfer-coefficient`,
//!   `environment-temperature`): q_n = h (T_env(t) − T), h ≥ 0 (W/(m²·K)).
//!
//! Each face gives each of its N nodes the share 1/N of its rate (eq. 101), with the
//! node's own temperature in the convection term (lumped, as the digest proposes, so the
//! explicit step stays stable for h A/N ≤ 2 C_l / Δt).

use pcdc_compute::{ComputeError, TimeValue};
use pcdc_mesh::{Dim, Mesh, Range};

/// A face condition: a flux density or a convection to an environment.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum FaceHeat {
    /// q_n (W/m², into the body).
    Flux(TimeValue),
    /// h (W/(m²·K)) and T_env (K).
    Convection(f64, TimeValue),
}

/// The face conditions as node entries: for node n, entries `start[n]..start[n + 1]`
/// of (condition index, face measure share A/N).
#[derive(Clone, Debug, Default)]
pub(crate) struct NodeEntries {
    pub start: Vec<u32>,
    pub cond: Vec<u32>,
    pub share: Vec<f64>,
}

impl NodeEntries {
    /// Entries of the boundary faces each condition's range selects, in condition order
    /// then face order per node (a fixed order: the sums are deterministic).
    pub fn build<D: Dim>(
        mesh: &Mesh<D>,
        conditions: &[(Range, FaceHeat)],
    ) -> Result<Self, ComputeError> {
        let n = mesh.n_nodes();
        let npf = D::NODES_PER_FACE;
        let mut per_node: Vec<Vec<(u32, f64)>> = vec![Vec::new(); n];
        let mut normal = [0.0; 3];
        for (c, (range, _)) in conditions.iter().enumerate() {
            let faces = mesh.select_boundary_faces(range).map_err(|e| {
                ComputeError::param(
                    format!("thermal face condition {c}"),
                    "range",
                    e.to_string(),
                )
            })?;
            if faces.is_empty() {
                return Err(ComputeError::param(
                    format!("thermal face condition {c}"),
                    "range",
                    "selects no boundary face",
                ));
            }
            for f in faces {
                let a = mesh.face_measure_normal(f as usize, &mut normal[..D::D]);
                for &node in mesh.face(f as usize) {
                    per_node[node as usize].push((c as u32, a / npf as f64));
                }
            }
        }
        let mut out = NodeEntries {
            start: Vec::with_capacity(n + 1),
            ..Default::default()
        };
        out.start.push(0);
        for list in per_node {
            for (c, s) in list {
                out.cond.push(c);
                out.share.push(s);
            }
            out.start.push(out.cond.len() as u32);
        }
        Ok(out)
    }
}

/// Checks a face condition's parameters.
pub(crate) fn check(index: usize, heat: &FaceHeat) -> Result<(), ComputeError> {
    match heat {
        FaceHeat::Flux(q) => q.check(&format!("heat flux of thermal face condition {index}")),
        FaceHeat::Convection(h, t) => {
            if !(*h >= 0.0 && h.is_finite()) {
                return Err(ComputeError::param(
                    format!("transfer coefficient h of thermal face condition {index}"),
                    h,
                    "must be non-negative and finite (W/(m²·K))",
                ));
            }
            t.check(&format!(
                "environment temperature of thermal face condition {index}"
            ))
        }
    }
}
