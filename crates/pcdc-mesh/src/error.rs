//! Mesh errors: every variant names the offending entity or input line.

const GIB: f64 = (1u64 << 30) as f64;

/// Errors raised while building, importing, selecting on or writing a mesh.
#[derive(Debug, thiserror::Error)]
#[allow(missing_docs)] // variant fields are named after what they hold; variants are documented
pub enum MeshError {
    /// The coordinate array length is not a multiple of the dimension.
    #[error("coordinate array has {len} values, not a multiple of the dimension {dim}")]
    CoordLength { len: usize, dim: usize },
    /// The connectivity array length is not a multiple of the nodes per element.
    #[error("connectivity has {len} indices, not a multiple of {per_elem} nodes per element")]
    ConnectivityLength { len: usize, per_elem: usize },
    /// A node coordinate is NaN or infinite.
    #[error("node {node} has a non-finite coordinate")]
    NonFiniteCoordinate { node: usize },
    /// A node coordinate exceeds [`crate::MAX_COORD`] in magnitude.
    #[error("node {node} has a coordinate {value:e} m, beyond the limit of 1e100 m (element measures would overflow)")]
    CoordinateTooLarge { node: usize, value: f64 },
    /// An element refers to a node that does not exist.
    #[error("element {element} refers to node {node}, but the mesh has {n_nodes} nodes")]
    BadNodeIndex {
        element: usize,
        node: u32,
        n_nodes: usize,
    },
    /// An element repeats a node.
    #[error("element {element} repeats node {node}")]
    RepeatedNode { element: usize, node: u32 },
    /// An element has negative measure (clockwise triangle, negative tetrahedron).
    #[error("element {element} is inverted (signed {measure_name} {measure:e}); its nodes must be counter-clockwise (Tri3) or positively oriented (Tet4)")]
    InvertedElement {
        element: usize,
        measure: f64,
        measure_name: &'static str,
    },
    /// An element has (near) zero measure.
    #[error("element {element} is degenerate ({measure_name} {measure:e}, below {threshold:e})")]
    DegenerateElement {
        element: usize,
        measure: f64,
        threshold: f64,
        measure_name: &'static str,
    },
    /// A Quad4/Hex8 (or simplex) cell given to [`crate::Mesh::from_cells`] is invalid:
    /// wrong dimension, bad or repeated node, degenerate, inverted, twisted or
    /// non-convex.
    #[error("cell {cell} ({kind:?}) {reason}")]
    BadCell {
        cell: usize,
        kind: crate::ElementKind,
        reason: String,
    },
    /// A node is referenced by no element.
    #[error("node {node} is dangling: no element uses it")]
    DanglingNode { node: usize },
    /// A face is shared by more than two elements (non-manifold mesh).
    #[error("face with nodes {nodes:?} is shared by more than two elements (element {element} is the third)")]
    NonManifoldFace { nodes: Vec<u32>, element: usize },
    /// The mesh has no elements.
    #[error("the mesh has no elements")]
    Empty,
    /// A group name is unknown.
    #[error("no {kind} group named '{name}'")]
    UnknownGroup { kind: &'static str, name: String },
    /// A group refers to an entity that does not exist.
    #[error("{kind} group '{name}' refers to index {index}, but there are only {count}")]
    BadGroupIndex {
        kind: &'static str,
        name: String,
        index: u32,
        count: usize,
    },
    /// A geometric or builder parameter is invalid.
    #[error("invalid parameter {name} = {value}: {reason}")]
    InvalidParameter {
        name: &'static str,
        value: f64,
        reason: &'static str,
    },
    /// A request would need more memory than the limit of [`crate::memory`].
    #[error("{name} = {value}: {what} would need about {estimate:.3e} bytes ({:.2} GiB), above the memory limit of {limit} bytes ({:.2} GiB); ask for less, or raise the limit with pcdc_mesh::memory::set_memory_limit or the PCDC_MEMORY_LIMIT environment variable", estimate / GIB, *limit as f64 / GIB)]
    MemoryLimit {
        name: String,
        value: f64,
        what: String,
        estimate: f64,
        limit: u64,
    },
    /// The memory limit environment variable is malformed.
    #[error("environment variable PCDC_MEMORY_LIMIT = '{value}': {reason}")]
    MemoryLimitSetting { value: String, reason: &'static str },
    /// The mesh was split already ([`crate::split_nodes`]): it cannot be split again or
    /// joined to other bodies without losing its interfaces.
    #[error("the mesh is already split ({interfaces} interfaces): {hint}")]
    AlreadySplit {
        interfaces: usize,
        hint: &'static str,
    },
    /// A serialised mesh is inconsistent with its own elements.
    #[error("inconsistent mesh data: {0}")]
    Inconsistent(String),
    /// A meshing domain is ill-formed ([`crate::mesher`]): the message names the loop,
    /// line or edge and what is wrong with it.
    #[error("meshing domain: {what} {reason}")]
    Domain { what: String, reason: String },
    /// The mesher could not mesh a domain to the requested quality.
    #[error("mesher: {0}")]
    Mesher(String),
    /// A range is ill-formed (e.g. zero plane normal).
    #[error("invalid range: {0}")]
    InvalidRange(String),
    /// A Gmsh file could not be parsed.
    #[error("{file}:{line}: {message}")]
    Parse {
        file: String,
        line: usize,
        message: String,
    },
    /// An input/output error, with the path involved.
    #[error("{path}: {source}")]
    Io {
        path: String,
        #[source]
        source: std::io::Error,
    },
}
