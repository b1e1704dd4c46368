//! # pcdc-contact
//!
//! Contact between finite elements for the pcdc-rs FDEM SDK (manual 7.3), after
//! Munjiza's potential contact: the exact normal contact force between two overlapping
//! triangles in 2D ([`triangle_pair_force`], eq. 52-58) and between two overlapping
//! tetrahedra in 3D ([`tet_pair_force`], the same equations one dimension up), the
//! [`ContactModel`] plugin trait with the built-in `contact-m-c` law
//! ([`MohrCoulombContact`]: Coulomb friction with a shear penalty, eq. 59-60, and damping
//! after An and Tannant, eq. 61), and the [`Contact`] physics for `Mesh<Dim2>` and
//! `Mesh<Dim3>` (sorted-grid broad phase with a skin, deterministic element-centric
//! assembly, bonded-neighbour exclusion for FDEM regions), on the CPU and GPU backends.
//! Inside intact rock contact costs nothing: with bonds declared, pairs glued together
//! by intact joints (directly, around a shared vertex, or around a sealed element) skip
//! the narrow phase until a joint near them breaks (see [`Contact`]). On the CPU the
//! sealed flags are re-derived only when the set of broken bonds changes, and the
//! candidate lists' rebuild test watches only the nodes of unsealed elements.
//!
//! **Corrected equation.** The manual's friction law eq. 59, τ = P_t h |δ_s|, is not a
//! stress and would make results depend on the unit system; the crate uses
//! τ = P_t |δ_s| / h (P_t in Pa, like the joints' shear penalty), see [`Friction`]. The
//! contact stable step accounts for that tangential spring.
//!
//! Contact without a contact law uses the elements' own surface friction and penalty
//! (manual table 1): [`Contact::surface_defaults`] with [`SurfaceContact`].
//!
//! On the GPU backend (2D and 3D) the broad phase is a uniform grid built by counting
//! sort and the pair forces run element-centric in WGSL, repeating the CPU arithmetic
//! (f64 results match the CPU to rounding); laws supply their WGSL through
//! [`ContactModel::wgsl`] ([`WgslContactModel`]). See the `gpu` module notes in the
//! source for the kernel sequence and resources.
//!
//! All evolving contact state (candidate lists, their reference positions and the
//! per-pair histories of the law) lives in fields with one layout for both backends
//! ([`CONTACT_CANDIDATES`], [`CONTACT_CANDIDATE_COUNT`], [`CONTACT_HISTORY`],
//! [`CONTACT_REFERENCE`]; a fixed capacity per element, [`Contact::capacity`]), so a
//! snapshot of a CPU or GPU run restores it completely and the continuation is bit
//! for bit the uninterrupted run.

#![warn(missing_docs)]
// Index loops mirror the formulas.
#![allow(clippy::needless_range_loop)]

mod active;
mod exclusion;
mod gpu;
mod model;
mod pair_pass;
mod physics;
mod potential2d;
mod potential3d;
mod snapshot_state;

pub use model::{
    ContactDamping, ContactModel, ContactStress, Friction, MohrCoulombContact, SurfaceContact,
    WgslContactModel,
};
pub use physics::{
    element_boxes, element_boxes_3d, grid_candidates, grid_candidates_3d, Contact,
    CONTACT_CANDIDATES, CONTACT_CANDIDATE_COUNT, CONTACT_HISTORY, CONTACT_REFERENCE,
};
pub use potential2d::{potential, triangle_pair_force, PairForce2};
pub use potential3d::{tet_pair_force, tet_potential, PairForce3};
