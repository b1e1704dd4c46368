//! Running a light physics beside a heavier one in the CPU forces stage
//! ([`Physics::runs_beside`]): which pairs may, and the store that holds the light one's
//! fields while both run.

use pcdc_mesh::{Dim, Mesh};

use crate::{ComputeError, FieldId, FieldStore, Physics};

/// Which physics run beside which, fixed when the simulation is built.
pub(crate) struct Beside {
    /// For each physics, the light physics that runs beside it.
    pub partner: Vec<Option<usize>>,
    /// Whether a physics runs beside an earlier one (and is skipped in its own turn).
    pub skip: Vec<bool>,
    /// For each physics, the fields it declares (moved to `side` while it runs beside).
    pub ids: Vec<Vec<FieldId>>,
    /// The light physics' fields while it runs (empty otherwise).
    pub side: FieldStore,
}

impl Beside {
    /// Pairs every physics that [`Physics::runs_beside`] with the earliest earlier
    /// physics it may run beside: one that does not run beside itself, hosts no other,
    /// and shares no field with it, nor does any physics between them. None for a single
    /// thread, where the pair would run one after the other anyway.
    pub fn plan<D: Dim>(
        mesh: &Mesh<D>,
        physics: &[Box<dyn Physics<D>>],
        fields: &FieldStore,
        threads: usize,
    ) -> Result<Self, ComputeError> {
        let n = physics.len();
        let mut ids = Vec::with_capacity(n);
        for p in physics {
            let mut list = Vec::new();
            for u in p.fields(mesh) {
                let id = fields.id(&u.name)?;
                if !list.contains(&id) {
                    list.push(id);
                }
            }
            ids.push(list);
        }
        let mut partner = vec![None; n];
        let mut skip = vec![false; n];
        if threads > 1 {
            for l in 0..n {
                if !physics[l].runs_beside() {
                    continue;
                }
                let mut best = None;
                for h in (0..l).rev() {
                    if ids[h].iter().any(|id| ids[l].contains(id)) {
                        break;
                    }
                    if !physics[h].runs_beside() && !skip[h] && partner[h].is_none() {
                        best = Some(h);
                    }
                }
                if let Some(h) = best {
                    partner[h] = Some(l);
                    skip[l] = true;
                }
            }
        }
        Ok(Beside {
            partner,
            skip,
            ids,
            side: fields.empty_like(),
        })
    }

    /// Moves physics `l`'s fields between `main` and the side store (there and back).
    pub fn swap(&mut self, main: &mut FieldStore, l: usize) {
        for &id in &self.ids[l] {
            main.swap_field(&mut self.side, id);
        }
    }
}
