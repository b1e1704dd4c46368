//! The fluid mass balance: injected = stored change + leaked + outflow, to rounding.

use pcdc_compute::{ComputeError, Simulation};
use pcdc_mesh::Dim;

use crate::fields::{FLOW_BALANCE, FLOW_STORED};

/// Fluid volumes (m³; m² per unit thickness in 2D) since the start of a run, summed over
/// the flow nodes.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct MassBalance {
    /// Content at the start, Σ W₀.
    pub initial: f64,
    /// Stored change, Σ (W − W₀).
    pub change: f64,
    /// Injected by rate conditions (negative: extracted).
    pub injected: f64,
    /// Added by pressure and head conditions (negative: outflow through them).
    pub boundary: f64,
    /// Lost to leak-off.
    pub leaked: f64,
    /// change − injected − boundary + leaked: zero to rounding.
    pub residual: f64,
}

impl MassBalance {
    /// Content now, Σ W.
    pub fn stored(&self) -> f64 {
        self.initial + self.change
    }

    /// The largest of the terms that move fluid (|stored change|, |injected|,
    /// |boundary|, leaked), the scale of a relative residual; never zero.
    pub fn scale(&self) -> f64 {
        self.change
            .abs()
            .max(self.injected.abs())
            .max(self.boundary.abs())
            .max(self.leaked.abs())
            .max(f64::MIN_POSITIVE)
    }

    /// `residual / scale()`.
    pub fn relative(&self) -> f64 {
        self.residual / self.scale()
    }
}

/// The mass balance of the fluid of `sim` (which must compose [`crate::Hydro`]).
pub fn mass_balance<D: Dim>(sim: &Simulation<D>) -> Result<MassBalance, ComputeError> {
    let w = sim.field(FLOW_STORED)?;
    let b = sim.field(FLOW_BALANCE)?;
    let mut m = MassBalance::default();
    for (l, &wl) in w.iter().enumerate() {
        m.change += wl;
        m.initial += b[4 * l];
        m.injected += b[4 * l + 1];
        m.boundary += b[4 * l + 2];
        m.leaked += b[4 * l + 3];
    }
    m.residual = m.change - m.injected - m.boundary + m.leaked;
    Ok(m)
}

/// History columns of the mass balance, to add to a [`pcdc_compute::History`] with
/// `history.probe(name, probe)`: `injected`, `stored_change`, `leaked`, `boundary` (m³)
/// and `balance_residual` (m³, zero to rounding). NaN in a simulation without
/// [`crate::Hydro`].
pub fn balance_probes<D: Dim>() -> Vec<(&'static str, pcdc_compute::Probe<D>)> {
    type Term = fn(&MassBalance) -> f64;
    let terms: [(&'static str, Term); 5] = [
        ("injected", |b| b.injected),
        ("stored_change", |b| b.change),
        ("leaked", |b| b.leaked),
        ("boundary", |b| b.boundary),
        ("balance_residual", |b| b.residual),
    ];
    terms
        .into_iter()
        .map(|(name, f)| {
            let probe = pcdc_compute::Probe::Custom(Box::new(move |sim: &Simulation<D>| {
                mass_balance(sim).map_or(f64::NAN, |b| f(&b))
            }));
            (name, probe)
        })
        .collect()
}
