//! Boundary conditions on bolt nodes (manual 7.9.4, tables 20-21): prescribed velocity
//! or acceleration per component, and node forces, each a constant or a time table.

use pcdc_compute::TimeValue;

use crate::BoltError;

/// Which nodes of a bolt a condition acts on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BoltNodes {
    /// Node 0, at the head.
    Head,
    /// The last node, at the tail.
    Tail,
    /// Node `i` counted from the head.
    Node(usize),
    /// Every node of the bolt.
    All,
}

/// What a condition prescribes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum BcKind {
    /// Velocity (m/s), table 20 `v-x`, `v-y`, `v-z`.
    Velocity,
    /// Acceleration (m/s²), table 20 `a-x`, `a-y`, `a-z`: the velocity is integrated.
    Acceleration,
    /// Force (N per bolt; divided by the spacing in 2D like the bolt's strengths),
    /// table 21 `f-x`, `f-y`, `f-z`.
    Force,
}

/// One condition as the user gave it.
#[derive(Clone, Debug)]
pub(crate) struct BoltBc {
    pub bolt: String,
    pub nodes: BoltNodes,
    pub kind: BcKind,
    pub values: [Option<TimeValue>; 3],
}

/// A condition resolved to simulation nodes.
#[derive(Clone, Debug)]
pub(crate) struct ResolvedBc {
    pub kind: BcKind,
    /// Simulation node, and its index in the bolt-node set.
    pub nodes: Vec<(u32, u32)>,
    pub values: [Option<TimeValue>; 3],
    /// Force scale (1 / spacing in 2D).
    pub scale: f64,
}

impl BoltBc {
    /// The bolt-local node indices this condition names, for a bolt of `n` nodes.
    pub fn local_nodes(&self, n: usize) -> Result<Vec<usize>, BoltError> {
        match self.nodes {
            BoltNodes::Head => Ok(vec![0]),
            BoltNodes::Tail => Ok(vec![n - 1]),
            BoltNodes::All => Ok((0..n).collect()),
            BoltNodes::Node(i) if i < n => Ok(vec![i]),
            BoltNodes::Node(i) => Err(BoltError::Geometry {
                bolt: self.bolt.clone(),
                reason: format!("a boundary condition names node {i}, but the bolt has {n} nodes"),
            }),
        }
    }
}
