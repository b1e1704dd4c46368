//! # pcdc-mesh
//!
//! Struct-of-arrays meshes for the pcdc-rs FDEM SDK (manual chapter 4): dimension types
//! ([`Dim2`], [`Dim3`]), the [`Mesh`] of Tri3 or Tet4 elements with its faces and
//! groups (and, for meshes of Quad4/Hex8 cells mixed freely with simplices, the
//! [`Cells`] table of the simplices each cell is cut into, see [`cells`]), [`Range`] selections, checks on build, specimen builders, Gmsh MSH 4.1 import
//! and VTU/PVD output for ParaView; node splitting into FDEM regions ([`split_nodes`])
//! and the [`Interfaces`] (face-joints, matched node pairs, master-node map) a split
//! mesh carries for every physics to read.
//!
//! Units are SI throughout: coordinates in metres.
//!
//! ## Input checks
//!
//! Every way a mesh enters is checked the same way and fails with a [`MeshError`] that
//! names the offending entity and value, never a panic: [`Mesh::new`] (array lengths,
//! finite coordinates, node indices, repeated nodes, inverted and degenerate elements,
//! dangling nodes, manifold faces), deserialisation of a [`Mesh`] (the same checks, plus
//! stored faces and group indices consistent with the elements), the [`builders`]
//! (parameters, and the memory guard below) and [`gmsh`] import (with a byte-order mark
//! accepted and a warning, or merging, for coincident unmerged nodes).
//! [`Range::validate`] rejects selections that cannot select anything (NaN or crossed
//! box corners, zero or z-only normals in 2D, NaN radii and tolerances).
//!
//! ## Memory limit
//!
//! Sizes are guarded in bytes, not element counts: [`memory::mesh_bytes`] estimates a
//! request and [`memory::check_memory`] refuses one above [`memory::memory_limit`], by
//! default half the machine's physical memory (8 GiB assumed where `/proc/meminfo` is
//! missing), settable with [`memory::set_memory_limit`] or the `PCDC_MEMORY_LIMIT`
//! environment variable (bytes, optional `K`/`M`/`G`/`T` suffix). The error gives the
//! estimate and the limit.

#![warn(missing_docs)]
// Index loops mirror the tensor notation of the manual's equations.
#![allow(clippy::needless_range_loop)]

pub mod cells;
mod dim;
mod error;
mod interface;
mod mesh;
mod range;

pub use cells::Cells;
pub use dim::{Dim, Dim2, Dim3, ElementKind};
pub use error::MeshError;
pub use interface::{split_nodes, Interface, Interfaces};
pub use mesh::{Faces, Groups, Mesh, DEGENERATE_REL, MAX_COORD, NO_NEIGHBOR};
pub use range::{PointPredicate, Range};

pub mod builders;
pub mod gmsh;
pub mod memory;
#[cfg(feature = "mesher")]
pub mod mesher;
#[cfg(feature = "property")]
pub mod property;
pub mod vtu;
