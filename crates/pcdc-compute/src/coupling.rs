//! Coupling inputs of plugin models: the fields (temperature, pore pressure, ...) that
//! the models of a physics declare they read, resolved once at init into one value row
//! per entity (element, joint). Shared by the physics that call plugin models
//! (`pcdc-mech`'s constitutive models, `pcdc-cohesive`'s joint models); each of them
//! gathers the values at its own entities (the topology differs) into
//! [`CouplingInputs::values`] and passes a model its row.

use crate::gpu::{Access, GpuData, GpuSetup, Kernel};
use crate::{ComputeError, FieldId, FieldKey, FieldStore, Location};
use pcdc_mesh::Dim;

/// One coupling field, as found in the field store at init.
#[derive(Clone, Copy, Debug)]
pub struct CouplingField {
    /// The field.
    pub id: FieldId,
    /// A node field (the physics interpolates it at its entity); else an element field.
    pub node: bool,
    /// Values per node or element.
    pub components: usize,
}

/// The coupling inputs of a physics' models (all empty when no model declares any).
#[derive(Clone, Debug, Default)]
pub struct CouplingInputs {
    /// The keys the models declare, each once, in order of first declaration.
    pub keys: Vec<FieldKey>,
    /// The fields of `keys`.
    pub fields: Vec<CouplingField>,
    /// Per model: indices into `fields` of its keys, in its declaration order.
    pub of_model: Vec<Vec<usize>>,
    /// Per model: its number of coupling values (the components of its keys).
    pub len_of_model: Vec<usize>,
    /// Values per entity in `values`: the largest of `len_of_model` (0: no coupling).
    pub stride: usize,
    /// Each entity's values in its model's order, `stride` per entity; the physics
    /// refreshes them at the start of every force evaluation (scratch, not state).
    pub values: Vec<f64>,
}

impl CouplingInputs {
    /// The keys that `models` (each model's declared keys) read, each once, in order of
    /// first declaration: what the physics declares as lagged reads.
    pub fn keys<'a>(models: impl IntoIterator<Item = &'a [FieldKey]>) -> Vec<FieldKey> {
        let mut keys: Vec<FieldKey> = Vec::new();
        for m in models {
            for k in m {
                if !keys.contains(k) {
                    keys.push(*k);
                }
            }
        }
        keys
    }

    /// Resolves the keys of `models` (name, declared keys; in the physics' model order)
    /// in `fields`, with a value row for each of `entities` entities (allocated only when
    /// a model reads a field). A key on a face or an entity set is an error naming the
    /// model (`kind`: "joint model", "constitutive model").
    pub fn resolve(
        models: &[(&str, &[FieldKey])],
        fields: &FieldStore,
        entities: usize,
        kind: &str,
    ) -> Result<Self, ComputeError> {
        let keys = Self::keys(models.iter().map(|m| m.1));
        if keys.is_empty() {
            return Ok(Self::default());
        }
        let mut resolved = Vec::with_capacity(keys.len());
        for k in &keys {
            let id = fields.id(k)?;
            let spec = fields.spec(id);
            let node = match spec.location {
                Location::Node => true,
                Location::Element => false,
                other => {
                    let model = models.iter().find(|m| m.1.contains(k)).map_or("?", |m| m.0);
                    return Err(ComputeError::param(
                        format!("coupling field '{k}' of {kind} '{model}'"),
                        format!("{other:?}"),
                        format!("a {kind} reads node or element fields only"),
                    ));
                }
            };
            resolved.push(CouplingField {
                id,
                node,
                components: spec.components,
            });
        }
        let of_model: Vec<Vec<usize>> = models
            .iter()
            .map(|m| {
                m.1.iter()
                    .filter_map(|k| keys.iter().position(|u| u == k))
                    .collect()
            })
            .collect();
        let len_of_model: Vec<usize> = of_model
            .iter()
            .map(|ix| ix.iter().map(|&i| resolved[i].components).sum())
            .collect();
        let stride = len_of_model.iter().copied().max().unwrap_or(0);
        Ok(CouplingInputs {
            keys,
            fields: resolved,
            of_model,
            len_of_model,
            stride,
            values: vec![0.0; entities * stride],
        })
    }

    /// Binds the coupling fields to `kernel` (`cpl0`, `cpl1`, ... in the order of
    /// [`CouplingInputs::keys`], read only) and the table `table` (uploaded as `label`):
    /// per model its value count and the offset of its map, then the maps (per value,
    /// its index in the kernel's array of all coupling values, fields in key order).
    pub fn bind<D: Dim>(
        &self,
        setup: &mut GpuSetup<'_, D>,
        mut kernel: Kernel,
        table_name: &str,
        label: &str,
    ) -> Result<Kernel, ComputeError> {
        let mut first = Vec::with_capacity(self.fields.len());
        let mut at = 0u32;
        for f in &self.fields {
            first.push(at);
            at += f.components as u32;
        }
        let nm = self.of_model.len();
        let mut table: Vec<u32> = Vec::with_capacity(2 * nm);
        let mut maps: Vec<u32> = Vec::new();
        for (m, ix) in self.of_model.iter().enumerate() {
            table.push(self.len_of_model[m] as u32);
            table.push((2 * nm + maps.len()) as u32);
            for &u in ix {
                let f = &self.fields[u];
                maps.extend((0..f.components as u32).map(|c| first[u] + c));
            }
        }
        table.extend(maps);
        let table = setup.upload(label, GpuData::U32(table));
        kernel = kernel.bind(table_name, table, Access::Read);
        for (i, k) in self.keys.iter().enumerate() {
            kernel = kernel.bind(&format!("cpl{i}"), setup.field(k)?, Access::Read);
        }
        Ok(kernel)
    }
}
