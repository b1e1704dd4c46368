//! Rock support for pcdc-rs: fully grouted rock bolts and cables (manual 7.9).
//!
//! A bolt is a polyline of two-node bar segments with nodes of its own (physics-owned
//! degrees of freedom with lumped masses, integrated by the same explicit step as the
//! mesh). Every bolt node is grouted to the element of the reference mesh that holds
//! it: the host's motion is interpolated at the node with the element's linear shape
//! functions (barycentric weights), and the grout's force goes back to the host's nodes
//! with the same weights, so action equals reaction exactly. In an FDEM mesh every
//! element has its own nodes, so when the host's fragment moves or rotates, its bolt
//! nodes follow it. No shear or bending stiffness (the manual's assumption): the bolt's
//! shear resistance across a sliding joint comes from its axial force as the bolt is
//! stretched and turned.
//!
//! # Equations (manual 7.9; corrections marked)
//!
//! Axial force of segment i with reference length L_b,i and A_b = π D_b²/4 (eq. 138-142):
//!
//! * f*_a = f_a + (E_b A_b / L_b,i) Δu_a (138-139), written in total form
//!   f*_a = (E_b A_b / L_b,i)(L − L_b,i − u_p) with the plastic elongation u_p, which is
//!   the same law summed exactly and does not drift when the segment rotates;
//! * f_a = min(f*_a, f_b,t,l) in tension (140), f_a = max(f*_a, −f_b,c,l) in compression
//!   (141, \[CORRECTED\]: the manual prints the tensile yield force in this branch);
//!   the plastic elongation moves so that the force stays on the limit;
//! * the segment breaks when (L − L_b,i)/L_b,i ≥ ε_b,t,l (142) and carries nothing from
//!   then on (\[NOT IN MANUAL\]: permanently).
//!
//! Grout at bolt node n with tributary length l_n = (L_b0 + L_b1)/2 (eq. 143-147):
//!
//! * δ = (x_n − x_host)·a, the relative displacement along the bolt's axis a at the node
//!   (mean direction of its segments) of the node against the host's material point
//!   where it was grouted; f*_s = K_b,r,s l_n (δ − s_p) (143, in total form with the slip
//!   s_p);
//! * |f_s| ≤ S_b l_n (144-145), S_b = min(S_r,g, S_b,g),
//!   S_r,g = π (D_b + 2 T_g)(C_r,g + σ_n tan φ_r,g) (146), S_b,g = π D_b (C_b,g + σ_n
//!   tan φ_b,g) (147); σ_n is the host's confining stress across the bolt, the mean
//!   compressive normal stress over the directions perpendicular to the axis (tension
//!   gives 0) \[NOT IN MANUAL: the manual says "normal stress perpendicular to the
//!   bolt"]; it is read from the previous step's stress;
//! * across the axis the grout is an elastic spring k_n l_n per node [NOT IN MANUAL:
//!   the manual ignores it, which leaves the bolt nodes free to drift sideways; FLAC's
//!   cable links are rigid across the axis, this is their explicit penalty form;
//!   `BoltProperties::normal_stiffness`, default K_b,r,s].
//!
//! Damping (eq. 148): F = D_b,f C (v_j − v_i)·e on each segment, C = 2 A_b √(E_b ρ_b)
//! (\[CORRECTED\]: printed 2 L_b √(E_b ρ_b), which is not a damping coefficient in N·s/m;
//! applied to the relative axial velocity of the segment's ends, not to the node's
//! velocity, so that a bolt in a fragment in free flight is not braked); and across the
//! axis at each node, F = D_b,f 2 √(k_n l m_n) (v_n − Σ_q w_q v_q)⊥, the same fraction of
//! the critical damping of the node's lateral grout spring on its sideways velocity
//! against the rock (\[NOT IN MANUAL\]; see "Sideways flutter" below).
//!
//! Face plate (\[NOT IN MANUAL\]): a one-sided spring at the head that pushes the head
//! back out when the bolt pulls it into the rock, with the reaction into the rock.
//! Pretension (\[NOT IN MANUAL\]): the segments of the free length start with u_p =
//! −f_pre L_b,i / (E_b A_b), i.e. shortened so that they carry f_pre when the rock has
//! not moved; with a face plate the head bears on the rock. 2D spacing ([NOT IN
//! MANUAL]): a bolt in a 2D (plane-strain) model stands for a row `spacing` apart: its
//! stiffnesses, strengths, masses, pretension, plate and node forces are divided by the
//! spacing (per unit thickness), as FLAC smears cables.
//!
//! Stable step (\[NOT IN MANUAL\]): per bolt node, Gershgorin's bound with the hosts held
//! fixed, ω² ≤ (Σ 2 E_b A_b / L_b,i + max(K_b,r,s, k_n) l_n + k_plate) / m_n, reduced
//! by √(1 + ζ²) − ζ for the axial damping; it enters the simulation's step like every
//! other physics' limit and names the limiting bolt node.
//!
//! # Sideways flutter of a bolt sliding at its bond strength
//!
//! The grout force acts along the bolt's current axis at the node, the mean direction of
//! its two segments. While a node slides at the bond strength that force has a fixed
//! size and turns with the neighbouring nodes' sideways displacements: a follower force,
//! which couples the bolt's lateral modes antisymmetrically and makes them grow slowly
//! when nothing damps them. Seen (2026-12-07) in a 0.9 m rebar dragged 15 cm through a
//! fixed block at 2 m/s with local damping 0.3 and only the axial part of the damping
//! above (D_b,f = 0.5): the nodes began to swing ±1 cm sideways after 6 000 to 12 000
//! steps (without re-location and with it), and the grout forces then changed sign. The
//! growth rate is small (about the bond force over the segment length against the
//! lateral grout stiffness), so the lateral part of the damping stops it: with it the
//! same bolt stays on the plateau all the way (test
//! `an_inclined_bolt_dragged_at_its_bond_strength_does_not_flutter`). The default
//! D_b,f is 0 (the manual's); give a bolt that will slide far a damping factor. A
//! pull-out of a few centimetres (the validation scenes, undamped) does not reach it.
//!
//! # Composing
//!
//! ```rust,ignore
//! let rebar = BoltMaterial::new(BoltProperties::steel_rebar(0.025))?;
//! let bolts = Bolts::new()
//!     .bolt(Bolt::straight("B1", [0.0, 0.0, 0.0], [2.0, 0.0, 0.0], 20, rebar)?)?;
//! let pull = bolts
//!     .boundary()
//!     .force("B1", BoltNodes::Head, [Some((-50e3).into()), None, None])?;
//! let sim = Simulation::builder(mesh, backend)
//!     .physics(Mechanics::new().material(Range::All, rock))
//!     .physics(bolts)
//!     .physics(pull)
//!     .build()?;
//! ```
//!
//! Fields (on the entity sets [`BOLT_SEGMENTS`] and [`BOLT_NODES`]): [`BOLT_AXIAL_FORCE`],
//! [`BOLT_PLASTIC_ELONGATION`], [`BOLT_STATE`], [`BOLT_GROUT_FORCE`], [`BOLT_SLIP`],
//! [`BOLT_HOST`], [`BOLT_ANCHOR`].
//! Output: [`output::BoltSeries`] writes the bolts as VTU line cells for ParaView,
//! [`output::axial_force_profile`] gives the force along a bolt and
//! [`output::AxialForceCsv`] writes its CSV history.
//!
//! On the GPU the bolts run as three force-phase kernels (segments; nodes: each node
//! gathers its two segments in a fixed order, re-locates if it must, and writes its own
//! slot; hosts: each node of a path's elements sums the reactions it receives), with
//! the CPU's arithmetic in the same order and no float atomics.
//!
//! # Re-locating
//!
//! A bolt node is grouted to a material point of its host, x_g = Σ_q w_q x_q, and its
//! relative displacement is r = x_n − x_g. When the point the node has reached along
//! the bolt, x_g + δ a, lies outside the host by more than 5 % of a weight (the host
//! broke away and moved off, or the grout slipped past it), the node is re-found
//! (\[NOT IN MANUAL\]: the manual grouts a node to "the element at its location" and
//! says no more): among the elements its bolt's reference path crosses from two nodes
//! before it to two nodes after it (two end-segment lengths beyond the head and the
//! tail), the one holding that point best becomes its host, if it holds it to within
//! 2.5 % of a weight, with that point as the new grout point. The lateral part of r is
//! kept and the axial part is carried over ([`BOLT_ANCHOR`]), so the grout's δ, force
//! and slip go on unchanged; [`BOLT_HOST`] names the host. Beyond that reach, or where
//! no element holds the point (an open crack, the air outside a spalled face), the node
//! stays with its last host. Each node of the elements on a bolt's path has a force slot
//! of the bolt's own, summing the reactions of the bolt nodes its elements host in node
//! order, so the engine's gather is fixed when the simulation is built and re-location
//! needs no host round trip on the GPU. [`Bolts::fixed_hosts`] turns re-location off
//! (the slots are then on the hosts' nodes only: cheaper where segments span several
//! elements). A node is checked only once its axial relative displacement exceeds the
//! distance its weights allow (less than the smallest height, halved for the host's
//! deformation), so nodes that stay put cost nothing.

mod bolt;
mod boundary;
mod error;
mod fields;
mod gpu;
mod host;
mod material;
pub mod output;
mod path;
mod physics;
mod walk;

pub use bolt::Bolt;
pub use boundary::BoltNodes;
pub use error::BoltError;
pub use fields::*;
pub use host::{barycentric, min_height, Host, Locator};
pub use material::{grout_force, AxialLaw, BoltMaterial, BoltProperties, SegmentState};
pub use physics::{BoltBoundary, Bolts};

/// The physics name of [`Bolts`] (errors and stable-step reports name it).
pub const NAME: &str = "bolts";
