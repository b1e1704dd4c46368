//! Field storage: one contiguous `f64` array per declared field.
//!
//! Only the fields that the composed physics declare are allocated: a scene with no
//! fluid carries no fluid arrays. Physics look fields up once by name at build time and
//! keep the [`FieldId`].

use serde::{Deserialize, Serialize};

use crate::ComputeError;

/// Well-known field names shared between physics crates.
pub mod names {
    /// Element Cauchy stress (Pa), symmetric tensor, stride NSYM.
    pub const STRESS: &str = "stress";
    /// Element out-of-plane stress σzz in plane strain (Pa), 2D only.
    pub const STRESS_ZZ: &str = "stress_zz";
    /// Element strain in the co-rotated frame, symmetric tensor (engineering shear not used: tensor components).
    pub const STRAIN: &str = "strain";
    /// Element rotation of the co-rotated frame: 2D angle (rad) or 3D rotation matrix (9, row-major).
    pub const ROTATION: &str = "rotation";
    /// Element constitutive state variables (model-defined, fixed count per element).
    pub const MODEL_STATE: &str = "model_state";
}

/// Where a field lives.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Location {
    /// One value set per node.
    Node,
    /// One value set per element.
    Element,
    /// One value set per face.
    Face,
    /// One value set per entity of a physics-defined set of the given size (e.g. joints).
    Entities(usize),
}

/// The declaration of a field by a physics.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FieldSpec {
    /// Field name (see [`names`]).
    pub name: String,
    /// Entity kind it is stored on.
    pub location: Location,
    /// Values per entity.
    pub components: usize,
    /// Initial value of every component.
    pub initial: f64,
}

impl FieldSpec {
    /// A field declaration.
    pub fn new(name: &str, location: Location, components: usize) -> Self {
        FieldSpec {
            name: name.to_string(),
            location,
            components,
            initial: 0.0,
        }
    }
}

/// Handle to a field in a [`FieldStore`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct FieldId(usize);

impl FieldId {
    /// Position of the field in declaration order.
    pub fn index(self) -> usize {
        self.0
    }
}

/// The declared fields of a simulation.
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct FieldStore {
    specs: Vec<FieldSpec>,
    data: Vec<Vec<f64>>,
}

impl FieldStore {
    /// Declares a field (idempotent for identical layouts) and allocates it for `count`
    /// entities.
    pub fn declare(&mut self, spec: FieldSpec, count: usize) -> Result<FieldId, ComputeError> {
        if let Some(i) = self.specs.iter().position(|s| s.name == spec.name) {
            let s = &self.specs[i];
            if s.location != spec.location || s.components != spec.components {
                return Err(ComputeError::FieldConflict {
                    name: spec.name.clone(),
                    a: format!("{:?}x{}", s.location, s.components),
                    b: format!("{:?}x{}", spec.location, spec.components),
                });
            }
            return Ok(FieldId(i));
        }
        self.data.push(vec![spec.initial; count * spec.components]);
        self.specs.push(spec);
        Ok(FieldId(self.specs.len() - 1))
    }

    /// The handle of a declared field.
    pub fn id(&self, name: &str) -> Result<FieldId, ComputeError> {
        self.specs
            .iter()
            .position(|s| s.name == name)
            .map(FieldId)
            .ok_or_else(|| {
                ComputeError::UnknownField(
                    name.to_string(),
                    self.specs
                        .iter()
                        .map(|s| s.name.as_str())
                        .collect::<Vec<_>>()
                        .join(", "),
                )
            })
    }

    /// Declaration of a field.
    pub fn spec(&self, id: FieldId) -> &FieldSpec {
        &self.specs[id.0]
    }

    /// All declarations, in declaration order.
    pub fn specs(&self) -> &[FieldSpec] {
        &self.specs
    }

    /// Values of a field.
    pub fn get(&self, id: FieldId) -> &[f64] {
        &self.data[id.0]
    }

    /// Mutable values of a field.
    pub fn get_mut(&mut self, id: FieldId) -> &mut [f64] {
        &mut self.data[id.0]
    }

    /// Mutable access to several distinct fields at once (panics only on repeated ids,
    /// a programming error inside a physics, never on user input).
    pub fn get_many_mut<const N: usize>(&mut self, ids: [FieldId; N]) -> [&mut [f64]; N] {
        for i in 0..N {
            for j in i + 1..N {
                assert_ne!(ids[i], ids[j], "get_many_mut: repeated field");
            }
        }
        let mut out: [Option<&mut [f64]>; N] = std::array::from_fn(|_| None);
        for (k, d) in self.data.iter_mut().enumerate() {
            if let Some(slot) = ids.iter().position(|id| id.0 == k) {
                out[slot] = Some(d.as_mut_slice());
            }
        }
        out.map(|o| o.expect("field id from this store"))
    }

    /// Whether another store has the same declarations and array lengths.
    pub fn same_layout(&self, other: &FieldStore) -> bool {
        // Initial values are not compared: they may be NaN on purpose.
        self.specs.len() == other.specs.len()
            && self.data.len() == other.data.len()
            && self.specs.iter().zip(&other.specs).all(|(a, b)| {
                a.name == b.name && a.location == b.location && a.components == b.components
            })
            && self
                .data
                .iter()
                .zip(&other.data)
                .all(|(a, b)| a.len() == b.len())
    }

    /// Total bytes held by all fields.
    pub fn bytes(&self) -> usize {
        self.data.iter().map(|d| d.len() * 8).sum()
    }
}
