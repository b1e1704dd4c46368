//! Steady flow in a rigid network ([`crate::Hydro::steady_flow`]): the pressures at which
//! every free flow node's net inflow vanishes, from one sparse direct solve.
//!
//! With the same discretisation as the explicit steps (edge rates
//! Q_ij = k w_ij (ψ_i − ψ_j), k = δ³/(12 μ_d) saturated, ψ = p − ρ_f g·m), steady state
//! at a free node l is Σ_edges k w (ψ_l − ψ_j) = R_l, R_l the rate conditions' share; a
//! pressure condition fixes p_l. Written for p this is the network's weighted Laplacian
//! L p = R + ρ_f Σ k w (g·m_l − g·m_j), reduced to the free nodes (the fixed pressures
//! move to the right-hand side) and solved by a sparse LU factorisation (faer, the
//! workspace's sparse solver, as `Simulation::solve_linear` uses: the cotangent weights
//! of obtuse 3D channels may be negative, so LU rather than Cholesky).

use faer::linalg::solvers::Solve;
use faer::sparse::{SparseColMat, Triplet};

use pcdc_compute::ComputeError;

use crate::flow::{self, Geometry, EDGES3};
use crate::network::Network;

/// What the steady solve needs besides the network and geometry.
pub(crate) struct Inputs<'a> {
    /// Flow node → index into `fixed` values, or [`Network::NONE`].
    pub fixed_of: &'a [u32],
    /// Pressure (Pa) of each pressure condition.
    pub fixed: &'a [f64],
    /// Rate conditions per node (CSR): condition index and share.
    pub rate_ptr: &'a [u32],
    pub rate_cond: &'a [u32],
    pub rate_share: &'a [f64],
    /// Rate (m³/s) of each rate condition.
    pub rates: &'a [f64],
    /// Fluid density ρ_f (kg/m³) and dynamic viscosity μ_d (Pa·s).
    pub rho: f64,
    pub mu: f64,
}

/// The edges (local i, local j, weight slot) of a channel with `npc` nodes.
fn edges(npc: usize) -> &'static [(usize, usize, usize)] {
    const E2: [(usize, usize, usize); 1] = [(0, 1, 0)];
    const E3: [(usize, usize, usize); 3] = [(0, 1, 0), (1, 2, 1), (2, 0, 2)];
    if npc == 2 {
        &E2
    } else {
        debug_assert_eq!(EDGES3.len(), 3);
        &E3
    }
}

/// The steady pressure of every flow node (Pa), or why there is none.
pub(crate) fn pressures(
    net: &Network,
    geom: &Geometry,
    inp: &Inputs<'_>,
) -> Result<Vec<f64>, ComputeError> {
    let (nf, nc, npc) = (net.n_nodes(), net.n_channels(), net.npc);
    // Every connected part of the network needs a pressure condition, or its pressure
    // level is undetermined.
    let mut parent: Vec<usize> = (0..nf).collect();
    fn find(p: &mut [usize], mut x: usize) -> usize {
        while p[x] != x {
            p[x] = p[p[x]];
            x = p[x];
        }
        x
    }
    for c in 0..nc {
        let nodes = &net.channel_nodes[c * npc..(c + 1) * npc];
        for k in 1..npc {
            let (a, b) = (
                find(&mut parent, nodes[0] as usize),
                find(&mut parent, nodes[k] as usize),
            );
            parent[a.max(b)] = a.min(b);
        }
    }
    let mut anchored = vec![false; nf];
    for l in 0..nf {
        if inp.fixed_of[l] != Network::NONE {
            let r = find(&mut parent, l);
            anchored[r] = true;
        }
    }
    if let Some(l) = (0..nf).find(|&l| !anchored[find(&mut parent, l)]) {
        return Err(ComputeError::param(
            "steady flow",
            format!("flow node {l}"),
            "lies in a part of the network with no pressure condition, whose steady pressure \
             is undetermined: give every connected part a pressure condition",
        ));
    }
    let mut map = vec![usize::MAX; nf];
    let mut nfree = 0;
    for l in 0..nf {
        if inp.fixed_of[l] == Network::NONE {
            map[l] = nfree;
            nfree += 1;
        }
    }
    let mut p = vec![0.0; nf];
    for l in 0..nf {
        if inp.fixed_of[l] != Network::NONE {
            p[l] = inp.fixed[inp.fixed_of[l] as usize];
        }
    }
    if nfree == 0 {
        return Ok(p);
    }
    let mut rhs = faer::Mat::<f64>::zeros(nfree, 1);
    for l in 0..nf {
        if map[l] == usize::MAX {
            continue;
        }
        for r in inp.rate_ptr[l] as usize..inp.rate_ptr[l + 1] as usize {
            rhs[(map[l], 0)] += inp.rates[inp.rate_cond[r] as usize] * inp.rate_share[r];
        }
    }
    let mut trip: Vec<(usize, usize, f64)> = Vec::new();
    for c in 0..nc {
        let k = flow::conductivity(geom.aperture[c], 1.0, inp.mu);
        let nodes = &net.channel_nodes[c * npc..(c + 1) * npc];
        for &(i, j, e) in edges(npc) {
            let g = k * geom.weight[c * 3 + e];
            let (a, b) = (nodes[i] as usize, nodes[j] as usize);
            // The gravity part of ψ_a − ψ_b moves to the right-hand side.
            let dg = inp.rho
                * (geom.gravity_potential[c * npc + i] - geom.gravity_potential[c * npc + j]);
            for (x, y, s) in [(a, b, 1.0), (b, a, -1.0)] {
                if map[x] == usize::MAX {
                    continue;
                }
                trip.push((map[x], map[x], g));
                rhs[(map[x], 0)] += s * g * dg;
                if map[y] == usize::MAX {
                    rhs[(map[x], 0)] += g * p[y];
                } else {
                    trip.push((map[x], map[y], -g));
                }
            }
        }
    }
    trip.sort_unstable_by_key(|&(r, c, _)| (c, r));
    let mut merged: Vec<Triplet<usize, usize, f64>> = Vec::with_capacity(trip.len());
    for (r, c, v) in trip {
        match merged.last_mut() {
            Some(t) if t.row == r && t.col == c => t.val += v,
            _ => merged.push(Triplet::new(r, c, v)),
        }
    }
    let a = SparseColMat::<usize, f64>::try_new_from_triplets(nfree, nfree, &merged)
        .map_err(|e| ComputeError::Solver(format!("steady flow matrix: {e:?}")))?;
    let lu = a
        .sp_lu()
        .map_err(|e| ComputeError::Solver(format!("steady flow: LU failed ({e:?})")))?;
    lu.solve_in_place(rhs.as_mut());
    for l in 0..nf {
        if map[l] != usize::MAX {
            p[l] = rhs[(map[l], 0)];
        }
    }
    if let Some(l) = p.iter().position(|x| !x.is_finite()) {
        return Err(ComputeError::Solver(format!(
            "steady flow: the pressure at flow node {l} is not finite (a channel of zero \
             aperture cutting the network?)"
        )));
    }
    let scale = p.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    if let Some(l) = p.iter().position(|&x| x < -1e-9 * scale) {
        return Err(ComputeError::param(
            "steady flow",
            format!("pressure {:.4e} Pa at flow node {l}", p[l]),
            "is negative: the network would drain there, which a saturated steady solution \
             cannot represent (raise the pressure conditions or run the transient flow)",
        ));
    }
    for x in &mut p {
        *x = x.max(0.0);
    }
    Ok(p)
}

/// The mean flux q of every channel (m²/s, `dim` components each) at pressures `p`.
pub(crate) fn fluxes(
    net: &Network,
    geom: &Geometry,
    p: &[f64],
    dim: usize,
    rho: f64,
    mu: f64,
) -> Vec<f64> {
    let npc = net.npc;
    let mut out = vec![0.0; net.n_channels() * dim];
    for c in 0..net.n_channels() {
        let mut psi = [0.0; 3];
        let mut g3 = [[0.0; 3]; 3];
        for k in 0..npc {
            psi[k] = p[net.channel_nodes[c * npc + k] as usize]
                - rho * geom.gravity_potential[c * npc + k];
            g3[k][..dim].copy_from_slice(&geom.grad[(c * npc + k) * dim..(c * npc + k + 1) * dim]);
        }
        let q = flow::channel_flux(
            npc,
            flow::conductivity(geom.aperture[c], 1.0, mu),
            &g3,
            &psi,
        );
        out[c * dim..(c + 1) * dim].copy_from_slice(&q[..dim]);
    }
    out
}
