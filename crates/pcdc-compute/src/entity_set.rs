//! Named entity sets: the entities a physics-defined field lives on (joints, later flow
//! channels, bolt segments), each with its node connectivity, so that a physics reading
//! another's per-entity field also knows which nodes every entity joins.
//!
//! The mesh's interfaces (after [`pcdc_mesh::split_nodes`]) are always the set
//! [`crate::names::JOINTS`] (empty on an unsplit mesh); a physics declares its own sets
//! with [`crate::Physics::entity_sets`]. A field on a set is declared with
//! [`crate::Place::Set`].

use crate::ComputeError;

/// A named set of entities, each joining `nodes_per_entity` nodes.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct EntitySet {
    name: String,
    nodes_per_entity: usize,
    nodes: Vec<u32>,
}

impl EntitySet {
    /// A set named `name` whose entity `i` joins
    /// `nodes[i * nodes_per_entity..(i + 1) * nodes_per_entity]` (node indices of the
    /// simulation; checked when the simulation is built).
    pub fn new(
        name: impl Into<String>,
        nodes_per_entity: usize,
        nodes: Vec<u32>,
    ) -> Result<Self, ComputeError> {
        let name = name.into();
        if nodes_per_entity == 0 || nodes.len() % nodes_per_entity != 0 {
            return Err(ComputeError::param(
                format!("entity set '{name}'"),
                format!("{} nodes, {nodes_per_entity} per entity", nodes.len()),
                "give a positive count of nodes per entity that divides the node list",
            ));
        }
        Ok(EntitySet {
            name,
            nodes_per_entity,
            nodes,
        })
    }

    /// Adds `by` to every node index at or above `from` (the engine's shift of a
    /// physics' added nodes to their simulation indices).
    pub(crate) fn shift_nodes_from(&mut self, from: u32, by: u32) {
        for n in &mut self.nodes {
            if *n >= from {
                *n += by;
            }
        }
    }

    /// The set's name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Number of entities.
    pub fn len(&self) -> usize {
        self.nodes.len() / self.nodes_per_entity
    }

    /// Whether the set has no entity.
    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }

    /// Nodes joined by each entity.
    pub fn nodes_per_entity(&self) -> usize {
        self.nodes_per_entity
    }

    /// The nodes of entity `i`.
    pub fn entity(&self, i: usize) -> &[u32] {
        &self.nodes[i * self.nodes_per_entity..(i + 1) * self.nodes_per_entity]
    }

    /// All node indices, entity after entity.
    pub fn nodes(&self) -> &[u32] {
        &self.nodes
    }
}
