//! Field storage: one contiguous `f64` array per declared field.
//!
//! Only the fields that the composed physics declare are allocated: a scene with no
//! fluid carries no fluid arrays. Every field has exactly one owner: a physics states
//! for each field it touches whether it owns, writes or reads it ([`FieldUse`], built
//! from a typed [`FieldKey`]); the simulation builder refuses a field with two owners,
//! a field used without an owner, and a reader that runs before the field's writers.
//! Physics look fields up once at build time and keep the [`FieldId`].

use serde::{Deserialize, Serialize};

use pcdc_mesh::{Dim, Mesh};

use crate::ComputeError;

/// Well-known fields shared between physics crates: typed keys, so a reader in one crate
/// and the owner in another agree on the name and the layout without depending on each
/// other. A crate declares the keys of its private fields itself.
pub mod names {
    use super::{Components, FieldKey, Place};

    /// The entity set of the mesh's interfaces (face-joints made by
    /// `pcdc_mesh::split_nodes`, in the order of `Mesh::interfaces`; empty on an
    /// unsplit mesh), each entity joining the nodes of its two faces.
    pub const JOINTS: &str = "joints";

    /// Element Cauchy stress (Pa), symmetric tensor, stride NSYM. Owner: mechanics.
    pub const STRESS: FieldKey = FieldKey::new("stress", Place::Element, Components::Sym);
    /// Element out-of-plane stress σzz in plane strain (Pa), 2D only. Owner: mechanics.
    pub const STRESS_ZZ: FieldKey =
        FieldKey::new("stress_zz", Place::Element, Components::Fixed(1));
    /// Element strain in the co-rotated frame, symmetric tensor (tensor components, not
    /// engineering shear). Owner: mechanics.
    pub const STRAIN: FieldKey = FieldKey::new("strain", Place::Element, Components::Sym);
    /// Element rotation of the co-rotated frame: 2D angle (rad) or 3D rotation matrix (9,
    /// row-major). Owner: mechanics.
    pub const ROTATION: FieldKey = FieldKey::new("rotation", Place::Element, Components::Declared);
    /// Element constitutive state variables (model-defined, fixed count per element).
    /// Owner: mechanics.
    pub const MODEL_STATE: FieldKey =
        FieldKey::new("model_state", Place::Element, Components::Declared);
    /// 1 for an element switched to the null model (manual 7.2.8: excavated, it has no
    /// stiffness, mass, gravity or stress), 0 for a live one. Owner: mechanics
    /// (`pcdc_mech::set_null`).
    pub const ELEMENT_NULL: FieldKey =
        FieldKey::new("element_null", Place::Element, Components::Fixed(1));
    /// Normal opening of each joint, one per interface of the split mesh in its order
    /// (`pcdc_mesh::Mesh::interfaces`): o = δ̄·n (m), δ̄ the mean gap of the node pairs,
    /// n the unit normal below; positive when open. Owner: cohesive joints.
    pub const JOINT_OPENING: FieldKey =
        FieldKey::new("joint_opening", Place::Set(JOINTS), Components::Fixed(1));
    /// Sliding of each joint: s = δ̄ − o n (m), a vector in global axes orthogonal to the
    /// normal (|s| is the sliding distance). Owner: cohesive joints.
    pub const JOINT_SLIDING: FieldKey =
        FieldKey::new("joint_sliding", Place::Set(JOINTS), Components::Vector);
    /// Unit normal of each joint's midplane, from side A to side B of its interface.
    /// Owner: cohesive joints.
    pub const JOINT_NORMAL: FieldKey =
        FieldKey::new("joint_normal", Place::Set(JOINTS), Components::Vector);
    /// Largest damage D over each joint's integration points (1 value per joint; 1 =
    /// broken), as the joints publish it: fluid flow starts leak-off when a joint breaks,
    /// bolts may read it. Owner: cohesive joints.
    pub const JOINT_DAMAGE: FieldKey =
        FieldKey::new("joint_damage", Place::Set(JOINTS), Components::Fixed(1));
    /// Node temperature T (K), one value per node. Owner: the thermal physics (the
    /// future `pcdc-thermal`). Constitutive and joint models read it as a coupling
    /// input (e.g. thermal strain α ΔT).
    pub const TEMPERATURE: FieldKey =
        FieldKey::new("temperature", Place::Node, Components::Fixed(1));
    /// The entity set of the flow network's nodes (one per original mesh vertex that a
    /// permeable joint touches; entity `l` joins one mesh node standing for it, whose
    /// split copies share it through `Mesh::interfaces().master_of`). Owner: the fluid
    /// physics (`pcdc-hydro`).
    pub const FLOW_NODES: &str = "flow_nodes";
    /// The entity set of the flow network's channels (one per permeable joint; entity
    /// `c` joins the side-A nodes of its joint, whose masters name its flow nodes).
    /// Owner: the fluid physics.
    pub const FLOW_CHANNELS: &str = "flow_channels";
    /// Saturation s of each flow node (-, in [0, 1]). Owner: the fluid physics.
    pub const FLOW_SATURATION: FieldKey = FieldKey::new(
        "flow_saturation",
        Place::Set(FLOW_NODES),
        Components::Fixed(1),
    );
    /// Hydraulic aperture δ of each channel (m) at the last fluid step. Owner: the fluid
    /// physics.
    pub const CHANNEL_APERTURE: FieldKey = FieldKey::new(
        "channel_aperture",
        Place::Set(FLOW_CHANNELS),
        Components::Fixed(1),
    );
    /// Mean flux q of each channel (m²/s: volume per unit time and unit width; mean
    /// velocity q/δ), a vector in global axes in the channel's plane, at the last fluid
    /// step. Owner: the fluid physics.
    pub const CHANNEL_FLUX: FieldKey = FieldKey::new(
        "channel_flux",
        Place::Set(FLOW_CHANNELS),
        Components::Vector,
    );
    /// Node pore (fluid) pressure p (Pa, compression positive), one value per node.
    /// Owner: the fluid physics (the future `pcdc-hydro`). Constitutive and joint models
    /// read it as a coupling input (e.g. effective stress σ' = σ + b p I).
    pub const PORE_PRESSURE: FieldKey =
        FieldKey::new("pore_pressure", Place::Node, Components::Fixed(1));
}

/// Where a field key lives.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Place {
    /// One value set per mesh node.
    Node,
    /// One value set per element.
    Element,
    /// One value set per face.
    Face,
    /// One value set per entity of a named entity set ([`crate::EntitySet`]): the mesh's
    /// interfaces are [`names::JOINTS`]; a physics declares its own sets with
    /// [`crate::Physics::entity_sets`].
    Set(&'static str),
}

/// Values per entity of a field key.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Components {
    /// A fixed count.
    Fixed(usize),
    /// One per dimension (a vector).
    Vector,
    /// The independent components of a symmetric tensor (3 in 2D, 6 in 3D).
    Sym,
    /// Chosen by the owner when it declares the field (e.g. model state variables).
    Declared,
}

impl Components {
    fn resolve<D: Dim>(self) -> Option<usize> {
        match self {
            Components::Fixed(n) => Some(n),
            Components::Vector => Some(D::D),
            Components::Sym => Some(D::NSYM),
            Components::Declared => None,
        }
    }
}

/// A typed field key: the name and the layout of a field, declared as a `const` by the
/// crate that owns the field (or in [`names`] for fields several crates share). A
/// physics states how it uses each field with [`FieldKey::own`], [`FieldKey::write`],
/// [`FieldKey::read`] or [`FieldKey::read_lagged`] in [`crate::Physics::fields`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FieldKey {
    name: &'static str,
    place: Place,
    components: Components,
}

impl FieldKey {
    /// A key.
    pub const fn new(name: &'static str, place: Place, components: Components) -> Self {
        FieldKey {
            name,
            place,
            components,
        }
    }

    /// The field's name.
    pub const fn name(&self) -> &'static str {
        self.name
    }

    /// Where the field lives.
    pub const fn place(&self) -> Place {
        self.place
    }

    /// Values per entity, as declared by the key.
    pub const fn components(&self) -> Components {
        self.components
    }

    fn usage<D: Dim>(self, access: FieldAccess) -> FieldUse {
        FieldUse {
            name: self.name.to_string(),
            place: Some(self.place),
            components: self.components.resolve::<D>(),
            initial: 0.0,
            access,
        }
    }

    /// This physics owns the field: it declares it (allocated, initial value 0), writes
    /// it, and is the only one that may own it. For [`Components::Declared`] keys use
    /// [`FieldKey::own_sized`].
    pub fn own<D: Dim>(self) -> FieldUse {
        self.usage::<D>(FieldAccess::Own)
    }

    /// Owns a field whose component count only the owner knows (e.g.
    /// [`Components::Declared`]: model state variables).
    pub fn own_sized<D: Dim>(self, components: usize) -> FieldUse {
        let mut u = self.usage::<D>(FieldAccess::Own);
        u.components = Some(components);
        u
    }

    /// This physics writes a field another physics owns (e.g. a reset), within the step.
    pub fn write<D: Dim>(self) -> FieldUse {
        self.usage::<D>(FieldAccess::Write)
    }

    /// This physics reads the field's value of the current step: its owner and writers
    /// must run before it.
    pub fn read<D: Dim>(self) -> FieldUse {
        self.usage::<D>(FieldAccess::Read)
    }

    /// This physics reads the field's value as left by the previous step (no order
    /// constraint: an explicit coupling lagged by one step).
    pub fn read_lagged<D: Dim>(self) -> FieldUse {
        self.usage::<D>(FieldAccess::ReadLagged)
    }
}

impl std::fmt::Display for FieldKey {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name)
    }
}

impl AsRef<str> for FieldKey {
    fn as_ref(&self) -> &str {
        self.name
    }
}

/// How a physics uses a field.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FieldAccess {
    /// Declares and writes the field; exactly one physics owns each field.
    Own,
    /// Writes a field another physics owns.
    Write,
    /// Reads the current step's value (runs after the owner and the writers).
    Read,
    /// Reads the previous step's value (no order constraint).
    ReadLagged,
}

impl FieldAccess {
    /// `owns`, `writes`, `reads`, `reads (lagged)`.
    pub fn verb(self) -> &'static str {
        match self {
            FieldAccess::Own => "owns",
            FieldAccess::Write => "writes",
            FieldAccess::Read => "reads",
            FieldAccess::ReadLagged => "reads (lagged)",
        }
    }
}

/// One physics' use of one field, as returned by [`crate::Physics::fields`]. For an
/// owner the layout is complete; for other uses the parts that are known are checked
/// against the owner's declaration.
#[derive(Clone, Debug, PartialEq)]
pub struct FieldUse {
    /// Field name.
    pub name: String,
    /// Where it lives (`None`: not checked, for a field named at run time).
    pub place: Option<Place>,
    /// Values per entity (`None`: not checked, or not yet known).
    pub components: Option<usize>,
    /// Initial value of every component (owner only).
    pub initial: f64,
    /// How the physics uses it.
    pub access: FieldAccess,
}

impl FieldUse {
    /// A use of a field known only by its name (e.g. a field a user names in a
    /// parameter); its layout is taken from the owner.
    pub fn named(name: &str, access: FieldAccess) -> Self {
        FieldUse {
            name: name.to_string(),
            place: None,
            components: None,
            initial: 0.0,
            access,
        }
    }

    /// Sets the initial value of an owned field (e.g. NaN for "not yet set").
    pub fn initial(mut self, value: f64) -> Self {
        self.initial = value;
        self
    }

    /// The declaration of an owned field, with the entity counts of `mesh` and `sets`.
    pub(crate) fn spec<D: Dim>(
        &self,
        mesh: &Mesh<D>,
        sets: &[crate::EntitySet],
    ) -> Result<(FieldSpec, usize), ComputeError> {
        let missing = |what: &str| {
            ComputeError::param(
                format!("field '{}'", self.name),
                what,
                "its owner must give it (FieldKey::own_sized)",
            )
        };
        let components = self.components.ok_or_else(|| missing("component count"))?;
        let (location, count) = match self.place.ok_or_else(|| missing("place"))? {
            Place::Node => (Location::Node, mesh.n_nodes()),
            Place::Element => (Location::Element, mesh.n_elements()),
            Place::Face => (Location::Face, mesh.faces().len()),
            Place::Set(name) => {
                let set = sets.iter().find(|s| s.name() == name).ok_or_else(|| {
                    let reason = if name == names::FLOW_NODES || name == names::FLOW_CHANNELS {
                        "no composed physics provides the flow network: compose the fluid \
                         physics (pcdc_hydro::Hydro) in the same simulation"
                    } else {
                        "no entity set of that name: the mesh's interfaces are 'joints' (after \
                         split_nodes); physics declare theirs with Physics::entity_sets"
                    };
                    ComputeError::param(format!("field '{}'", self.name), name, reason)
                })?;
                (Location::Entities(set.len()), set.len())
            }
        };
        Ok((
            FieldSpec {
                name: self.name.clone(),
                location,
                components,
                initial: self.initial,
            },
            count,
        ))
    }
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
    /// One value set per entity of a named entity set ([`Place::Set`]) of the given size.
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

    /// The handle of a declared field, by name or by [`FieldKey`].
    pub fn id(&self, name: impl AsRef<str>) -> Result<FieldId, ComputeError> {
        let name = name.as_ref();
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

    /// A store with the same declarations and no values (every field empty): the other
    /// half of [`FieldStore::swap_field`].
    pub(crate) fn empty_like(&self) -> FieldStore {
        FieldStore {
            specs: self.specs.clone(),
            data: vec![Vec::new(); self.data.len()],
        }
    }

    /// Exchanges the values of field `id` with those in `other` (same declarations): a
    /// move of the array, not a copy.
    pub(crate) fn swap_field(&mut self, other: &mut FieldStore, id: FieldId) {
        std::mem::swap(&mut self.data[id.0], &mut other.data[id.0]);
    }

    /// Total bytes held by all fields.
    pub fn bytes(&self) -> usize {
        self.data.iter().map(|d| d.len() * 8).sum()
    }
}
