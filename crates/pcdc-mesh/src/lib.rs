//! # pcdc-mesh
//!
//! Struct-of-arrays meshes for the pcdc-rs FDEM SDK (manual chapter 4): dimension types
//! ([`Dim2`], [`Dim3`]), the [`Mesh`] of Tri3 or Tet4 elements with its faces and
//! groups, [`Range`] selections, checks on build, specimen builders, Gmsh MSH 4.1 import
//! and VTU/PVD output for ParaView.
//!
//! Units are SI throughout: coordinates in metres.

#![warn(missing_docs)]
// Index loops mirror the tensor notation of the manual's equations.
#![allow(clippy::needless_range_loop)]

mod dim;
mod error;
mod mesh;
mod range;

pub use dim::{Dim, Dim2, Dim3, ElementKind};
pub use error::MeshError;
pub use mesh::{Faces, Groups, Mesh, DEGENERATE_REL, NO_NEIGHBOR};
pub use range::{PointPredicate, Range};

pub mod builders;
pub mod gmsh;
pub mod vtu;
