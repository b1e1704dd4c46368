//! Static mode (manual 7.2.7, "dynamic off").
//!
//! * [`Simulation::relax`]: dynamic relaxation. Nodal masses are scaled so that every
//!   element is stable at one common pseudo time step, element viscous damping is
//!   switched off and local non-viscous damping (Cundall's, α = 0.8) is used instead.
//!   (Kinetic damping, zeroing velocities at kinetic-energy peaks, was tried first: with
//!   modes near the stability limit the leapfrog's half-step velocities alternate, and
//!   zeroing them injected energy.) Convergence is declared when the
//!   unbalanced-force ratio ‖F_unbalanced‖₂ / ‖F_gross‖₂ falls below the tolerance,
//!   where F_gross sums the absolute force contributions at every free dof.
//! * [`Simulation::solve_linear`]: a direct sparse Cholesky solve (faer) of the
//!   small-displacement stiffness `K Δu = F(u)`, repeated with the same factorisation
//!   until the same ratio is met (a couple of iterations absorb the co-rotational
//!   geometric terms). Only for physics that provide a linear stiffness.

use faer::linalg::solvers::Solve;
use faer::sparse::{SparseColMat, Triplet};

use crate::physics::DofConstraint;
use crate::{ComputeError, Simulation};
use pcdc_mesh::Dim;

/// Local damping coefficient used by dynamic relaxation.
const RELAX_DAMPING: f64 = 0.8;

/// Options of the static solvers.
#[derive(Clone, Debug)]
pub struct StaticOptions {
    /// Unbalanced-force ratio at which the solution counts as converged (default 1e-6).
    pub tolerance: f64,
    /// Maximum relaxation steps or direct-solve iterations (default 200 000).
    pub max_steps: u64,
    /// Steps between convergence checks in relaxation (default 20).
    pub check_every: u64,
}

impl Default for StaticOptions {
    fn default() -> Self {
        StaticOptions {
            tolerance: 1e-6,
            max_steps: 200_000,
            check_every: 20,
        }
    }
}

/// Outcome of a static solve.
#[derive(Clone, Debug, PartialEq)]
pub struct StaticReport {
    /// Relaxation steps or direct-solve iterations taken.
    pub steps: u64,
    /// Final unbalanced-force ratio.
    pub ratio: f64,
}

impl<D: Dim> Simulation<D> {
    /// Unbalanced-force ratio at the current state, ignoring constrained dofs.
    fn unbalanced_ratio(&mut self, free: &[bool]) -> Result<f64, ComputeError> {
        let gross = self.compute_forces(true)?.expect("gross requested");
        let d = D::D;
        let (mut num, mut den) = (0.0, 0.0);
        for (i, (&f, &g)) in self.force.iter().zip(&gross).enumerate() {
            if free[i] {
                // Gravity is a load like any other.
                let w = self.mass_phys[i / d] * self.gravity[i % d];
                num += (f + w) * (f + w);
                den += (g + w.abs()) * (g + w.abs());
            }
        }
        Ok(if den > 0.0 {
            (num / den).sqrt()
        } else {
            num.sqrt()
        })
    }

    /// Dofs left free by the kinematic conditions: a dof counts as constrained when the
    /// physics' kinematic conditions overwrite a probe velocity there.
    fn free_dofs(&mut self) -> Vec<bool> {
        let probe_value = 1.234_567e-3;
        let mut v = vec![probe_value; self.state.v.len()];
        let mut fields = self.state.fields.clone();
        for p in &mut self.physics {
            let mut ctx = crate::physics::VelocityContext {
                mesh: &self.mesh,
                u: &self.state.u,
                v: &mut v,
                time: self.state.time,
                dt: self.dt,
                fields: &mut fields,
            };
            p.apply_kinematics(&mut ctx);
        }
        v.iter().map(|&x| x == probe_value).collect()
    }

    /// Brings the model to static equilibrium by dynamic relaxation (see module docs).
    /// Time does not advance; velocities are zero on return.
    pub fn relax(&mut self, opts: &StaticOptions) -> Result<StaticReport, ComputeError> {
        check_opts(opts)?;
        let saved_dt = self.dt;
        let saved_damping = self.damping;
        let saved_time = self.state.time;
        // Mass scaling: every element critical at 1/0.9 pseudo-seconds, stepping at 1.
        self.dt = 1.0;
        let mut scaled = vec![0.0; self.mass.len()];
        for p in &self.physics {
            p.add_mass(&self.mesh, &self.state.fields, &mut scaled, Some(1.0 / 0.9));
        }
        // Nodes that dropped out (no mass) keep a unit integration mass.
        self.mass = self.integration_mass(&scaled);
        self.damping = false;
        let saved_alpha = self.local_damping;
        self.local_damping = RELAX_DAMPING;
        self.state.v.fill(0.0);
        // Relaxation is not a physical process (scaled masses, pseudo-time): the energy
        // balance pauses and restarts from the relaxed state.
        let energy = self.energy.take();
        let free = self.free_dofs();
        let result = self.relax_loop(opts, &free);
        self.energy = energy.map(|mut t| {
            t.rebase();
            t
        });
        self.device_fresh = false;
        self.mass = self.integration_mass(&self.mass_phys);
        self.local_damping = saved_alpha;
        self.dt = saved_dt;
        self.damping = saved_damping;
        self.state.time = saved_time;
        self.state.v.fill(0.0);
        result
    }

    fn relax_loop(
        &mut self,
        opts: &StaticOptions,
        free: &[bool],
    ) -> Result<StaticReport, ComputeError> {
        let mut ratio = f64::INFINITY;
        let mut it = 0;
        while it < opts.max_steps {
            // Whole check intervals at once: on the GPU they run without a read-back.
            let k = opts.check_every.min(opts.max_steps - it);
            self.run(k)?;
            it += k;
            // The device holds the state just read back: the force evaluation and the
            // next run need not upload it again (no user code runs in between).
            self.device_fresh = true;
            if it % opts.check_every == 0 {
                ratio = self.unbalanced_ratio(free)?;
                self.device_fresh = true;
                if ratio <= opts.tolerance {
                    return Ok(StaticReport { steps: it, ratio });
                }
            }
        }
        Err(ComputeError::NotConverged {
            steps: opts.max_steps,
            ratio,
            tol: opts.tolerance,
        })
    }

    /// Solves the static problem directly with a sparse Cholesky factorisation of the
    /// linear stiffness (faer), see module docs. Every composed physics must provide a
    /// linear stiffness and axis-aligned constraints.
    pub fn solve_linear(&mut self, opts: &StaticOptions) -> Result<StaticReport, ComputeError> {
        check_opts(opts)?;
        let d = D::D;
        let ndof = self.n_nodes() * d;
        let mut trip = Vec::new();
        for p in &self.physics {
            p.linear_stiffness(&self.mesh, &self.state.fields, &mut trip)?;
        }
        let mut cons = Vec::new();
        for p in &self.physics {
            p.dof_constraints(&self.mesh, &mut cons);
        }
        let mut free = vec![true; ndof];
        for c in cons {
            match c {
                DofConstraint::Fixed { node, comp } => free[node as usize * d + comp] = false,
                DofConstraint::Oblique { node } => {
                    return Err(ComputeError::NotLinear(format!(
                        "node {node} is constrained along a direction that is not a coordinate axis; use relax()"
                    )))
                }
            }
        }
        let mut map = vec![usize::MAX; ndof];
        let mut nfree = 0;
        for i in 0..ndof {
            if free[i] {
                map[i] = nfree;
                nfree += 1;
            }
        }
        if nfree == 0 {
            return Ok(StaticReport {
                steps: 0,
                ratio: 0.0,
            });
        }
        // Lower triangle of the reduced stiffness, duplicates summed.
        let mut lower: Vec<(usize, usize, f64)> = trip
            .into_iter()
            .filter_map(|(r, c, v)| {
                let (r, c) = (map[r], map[c]);
                (r != usize::MAX && c != usize::MAX && r >= c).then_some((r, c, v))
            })
            .collect();
        lower.sort_unstable_by_key(|&(r, c, _)| (c, r));
        let mut merged: Vec<Triplet<usize, usize, f64>> = Vec::with_capacity(lower.len());
        for (r, c, v) in lower {
            match merged.last_mut() {
                Some(t) if t.row == r && t.col == c => t.val += v,
                _ => merged.push(Triplet::new(r, c, v)),
            }
        }
        let k = SparseColMat::<usize, f64>::try_new_from_triplets(nfree, nfree, &merged)
            .map_err(|e| ComputeError::Solver(format!("{e:?}")))?;
        let llt = k
            .sp_cholesky(faer::Side::Lower)
            .map_err(|e| ComputeError::Solver(format!("Cholesky factorisation failed ({e:?})")))?;
        self.state.v.fill(0.0);
        let saved_damping = self.damping;
        self.damping = false;
        let mut ratio = f64::INFINITY;
        let mut result = Err(ComputeError::NotConverged {
            steps: opts.max_steps,
            ratio,
            tol: opts.tolerance,
        });
        for it in 1..=opts.max_steps {
            self.compute_forces(false)?;
            let mut rhs = faer::Mat::<f64>::from_fn(nfree, 1, |i, _| 0.0 * i as f64);
            for i in 0..ndof {
                if map[i] != usize::MAX {
                    // Internal and applied forces plus gravity.
                    rhs[(map[i], 0)] = self.force[i] + self.mass_phys[i / d] * self.gravity[i % d];
                }
            }
            llt.solve_in_place(rhs.as_mut());
            for i in 0..ndof {
                if map[i] != usize::MAX {
                    self.state.u[i] += rhs[(map[i], 0)];
                }
            }
            if self.state.u.iter().any(|x| !x.is_finite()) {
                self.damping = saved_damping;
                return Err(ComputeError::Solver("solution is not finite".into()));
            }
            ratio = self.unbalanced_ratio(&free)?;
            if ratio <= opts.tolerance {
                result = Ok(StaticReport { steps: it, ratio });
                break;
            }
            result = Err(ComputeError::NotConverged {
                steps: it,
                ratio,
                tol: opts.tolerance,
            });
        }
        self.damping = saved_damping;
        result
    }
}

fn check_opts(opts: &StaticOptions) -> Result<(), ComputeError> {
    if opts.tolerance.is_nan() || opts.tolerance <= 0.0 {
        return Err(ComputeError::param(
            "tolerance",
            opts.tolerance,
            "must be positive",
        ));
    }
    if opts.max_steps == 0 || opts.check_every == 0 {
        return Err(ComputeError::param(
            "max_steps/check_every",
            opts.max_steps.min(opts.check_every),
            "must be at least 1",
        ));
    }
    Ok(())
}
