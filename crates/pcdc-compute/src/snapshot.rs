//! Save and restore of a running simulation ([`Simulation::save`],
//! [`Simulation::restore`], [`Simulation::snapshot_bytes`],
//! [`Simulation::restore_bytes`]).
//!
//! # Format (version 4)
//!
//! A fixed 24-byte header, all integers little-endian, then a postcard payload:
//!
//! | offset | size | content |
//! |-------:|-----:|---------|
//! | 0 | 8 | magic `PCDCSNAP` |
//! | 8 | 4 | format version, `u32` ([`SNAPSHOT_VERSION`]) |
//! | 12 | 4 | CRC-32 (IEEE, as zlib and PNG) of every byte from offset 16 to the end |
//! | 16 | 8 | payload length in bytes, `u64` |
//! | 24 | n | payload (postcard): dimension, node and element counts, mesh fingerprint, physics names, per-physics fingerprints, layout fingerprint, time step, [`crate::State`], and per physics the state it keeps outside the fields ([`crate::Physics::save_state`]) |
//!
//! Version 4 has the layout of version 3; what changed is where the contact physics
//! keeps its state: its candidate lists and pair histories are fields (in
//! [`crate::State`]) instead of its own bytes, so a version-3 file of a scene with
//! contact could not be continued and every version-3 file is refused by its version.
//!
//! # What a restore checks, in order
//!
//! 1. the magic (a version-2 file, which began with the postcard text
//!    `pcdc-snapshot-2`, is recognised and named as such);
//! 2. the format version: another version is [`ComputeError::SnapshotVersion`], naming
//!    both;
//! 3. the length: a file shorter or longer than its header declares is truncated or
//!    padded ([`ComputeError::SnapshotCorrupt`]);
//! 4. the checksum (CRC-32 finds every single-bit flip and every burst of up to 32 bits);
//! 5. the payload decodes completely, with no bytes left over;
//! 6. the scene ([`ComputeError::SnapshotMismatch`], naming what differs): dimension,
//!    node and element counts, then the **mesh fingerprint** (FNV-1a of the dimension,
//!    the bits of every node coordinate and the element connectivity: a different mesh
//!    with the same counts is refused), the physics names in order, each physics'
//!    **parameter fingerprint** ([`crate::Physics::fingerprint`]), and the **layout
//!    fingerprint** of the composition: every declared field (name, location,
//!    components, initial value), the node of every force slot of every physics, and the
//!    bits of the lumped physical mass of every node (which covers densities);
//! 7. the values: field layout and array lengths equal the simulation's, the time step
//!    is positive and finite, the time finite, every displacement and velocity finite
//!    and no node displaced beyond the simulation's runaway limit (the watchdog's own
//!    criterion, so a state saved after a divergence is refused); the step counter is
//!    not tied to the time, because the time step may change during a run;
//! 8. each physics checks the values of its fields in [`crate::Physics::check_fields`]
//!    (e.g. the contact physics range-checks every candidate index of its lists) and
//!    the state it keeps outside them in [`crate::Physics::restore_state`].
//!
//! Nothing is changed unless every check passes: a physics whose state was already
//! restored when a later one fails gets its previous state back. A damaged or foreign
//! snapshot is therefore an error, never a panic and never a half-restored simulation.
//! Simulation settings that are not physics (gravity, safety factor, fixed step,
//! damping switches, runaway limit) are not fingerprinted: a restore may change them.

use std::path::Path;

use pcdc_mesh::Dim;
use serde::{Deserialize, Serialize};

use crate::{ComputeError, Fingerprint, Simulation, State};

/// Magic bytes at the start of every snapshot.
pub const SNAPSHOT_MAGIC: [u8; 8] = *b"PCDCSNAP";

/// The snapshot format version this build writes and reads.
pub const SNAPSHOT_VERSION: u32 = 4;

/// Header length in bytes (magic, version, checksum, payload length).
pub const SNAPSHOT_HEADER_LEN: usize = 24;

/// Version 2 files were a bare postcard struct whose first field was this text.
const LEGACY_PREFIX: &[u8] = b"pcdc-snapshot-";

/// The payload as written (borrows the state instead of copying it).
#[derive(Serialize)]
struct PayloadRef<'a> {
    dim: &'a str,
    n_nodes: u64,
    n_elements: u64,
    mesh: u64,
    physics: Vec<String>,
    physics_params: Vec<u64>,
    layout: u64,
    dt: f64,
    state: &'a State,
    physics_state: Vec<Vec<u8>>,
}

/// The payload as read (same field order and types as [`PayloadRef`]).
#[derive(Deserialize)]
struct Payload {
    dim: String,
    n_nodes: u64,
    n_elements: u64,
    mesh: u64,
    physics: Vec<String>,
    physics_params: Vec<u64>,
    layout: u64,
    dt: f64,
    state: State,
    physics_state: Vec<Vec<u8>>,
}

fn corrupt(what: impl Into<String>) -> ComputeError {
    ComputeError::SnapshotCorrupt(what.into())
}

fn mismatch(what: impl Into<String>) -> ComputeError {
    ComputeError::SnapshotMismatch(what.into())
}

/// Wraps a payload in the header.
fn seal(payload: &[u8]) -> Vec<u8> {
    let mut out = Vec::with_capacity(SNAPSHOT_HEADER_LEN + payload.len());
    out.extend_from_slice(&SNAPSHOT_MAGIC);
    out.extend_from_slice(&SNAPSHOT_VERSION.to_le_bytes());
    out.extend_from_slice(&[0; 4]);
    out.extend_from_slice(&(payload.len() as u64).to_le_bytes());
    out.extend_from_slice(payload);
    let crc = crc32fast::hash(&out[16..]);
    out[12..16].copy_from_slice(&crc.to_le_bytes());
    out
}

/// Little-endian integer at `at` (the caller has checked the length).
fn le_u32(bytes: &[u8], at: usize) -> u32 {
    let mut b = [0; 4];
    b.copy_from_slice(&bytes[at..at + 4]);
    u32::from_le_bytes(b)
}

/// The version of a pre-header (version 2) snapshot, if `bytes` is one.
fn legacy_version(bytes: &[u8]) -> Option<u32> {
    let (&len, rest) = bytes.split_first()?;
    let text = rest.get(..len as usize)?;
    let digits = text.strip_prefix(LEGACY_PREFIX)?;
    std::str::from_utf8(digits).ok()?.parse().ok()
}

/// Checks the header (magic, version, length, checksum) and returns the payload.
fn open(bytes: &[u8]) -> Result<&[u8], ComputeError> {
    if bytes.get(..8) != Some(&SNAPSHOT_MAGIC[..]) {
        if let Some(found) = legacy_version(bytes) {
            return Err(ComputeError::SnapshotVersion {
                found,
                supported: SNAPSHOT_VERSION,
            });
        }
        if bytes.len() < 8 && SNAPSHOT_MAGIC.starts_with(bytes) {
            return Err(corrupt(format!(
                "truncated: {} bytes, the header alone has {SNAPSHOT_HEADER_LEN}",
                bytes.len()
            )));
        }
        return Err(corrupt(
            "not a pcdc snapshot (the file does not start with PCDCSNAP)",
        ));
    }
    if bytes.len() < SNAPSHOT_HEADER_LEN {
        return Err(corrupt(format!(
            "truncated: {} bytes, the header alone has {SNAPSHOT_HEADER_LEN}",
            bytes.len()
        )));
    }
    let version = le_u32(bytes, 8);
    if version != SNAPSHOT_VERSION {
        return Err(ComputeError::SnapshotVersion {
            found: version,
            supported: SNAPSHOT_VERSION,
        });
    }
    let stored_crc = le_u32(bytes, 12);
    let mut len = [0; 8];
    len.copy_from_slice(&bytes[16..24]);
    let declared = u64::from_le_bytes(len);
    let payload = &bytes[SNAPSHOT_HEADER_LEN..];
    if declared != payload.len() as u64 {
        let what = if declared > payload.len() as u64 {
            "truncated"
        } else {
            "has extra bytes"
        };
        return Err(corrupt(format!(
            "{what}: the header declares a payload of {declared} bytes, the file holds {}",
            payload.len()
        )));
    }
    let crc = crc32fast::hash(&bytes[16..]);
    if crc != stored_crc {
        return Err(corrupt(format!(
            "checksum mismatch (stored {stored_crc:08x}, computed {crc:08x}): the file was damaged after it was written"
        )));
    }
    Ok(payload)
}

impl<D: Dim> Simulation<D> {
    /// Saves the running state to a file (format in the [`crate::snapshot`] module
    /// docs); see [`Simulation::restore`].
    pub fn save(&self, path: impl AsRef<Path>) -> Result<(), ComputeError> {
        let path = path.as_ref();
        let bytes = self.snapshot_bytes()?;
        std::fs::write(path, bytes).map_err(|source| ComputeError::Io {
            path: path.display().to_string(),
            source,
        })
    }

    /// Encodes the running state: header, checksum, scene fingerprints and state.
    pub fn snapshot_bytes(&self) -> Result<Vec<u8>, ComputeError> {
        let payload = PayloadRef {
            dim: D::NAME,
            n_nodes: self.mesh.n_nodes() as u64,
            n_elements: self.mesh.n_elements() as u64,
            mesh: self.mesh_fingerprint(),
            physics: self.physics_names(),
            physics_params: self.physics.iter().map(|p| p.fingerprint()).collect(),
            layout: self.layout_fingerprint(),
            dt: self.dt,
            state: &self.state,
            physics_state: self
                .physics
                .iter()
                .map(|p| p.save_state())
                .collect::<Result<_, _>>()?,
        };
        let payload =
            postcard::to_stdvec(&payload).map_err(|e| ComputeError::Encoding(e.to_string()))?;
        Ok(seal(&payload))
    }

    /// Restores a state saved by [`Simulation::save`] into a simulation built from the
    /// same scene (same mesh and physics); continuing then equals the uninterrupted run
    /// bit for bit. A damaged, foreign or older snapshot is an error and leaves the
    /// simulation unchanged (see the [`crate::snapshot`] module docs for the checks).
    pub fn restore(&mut self, path: impl AsRef<Path>) -> Result<(), ComputeError> {
        let path = path.as_ref();
        let bytes = std::fs::read(path).map_err(|source| ComputeError::Io {
            path: path.display().to_string(),
            source,
        })?;
        self.restore_bytes(&bytes)
    }

    /// Restores from bytes made by [`Simulation::snapshot_bytes`]; as
    /// [`Simulation::restore`].
    pub fn restore_bytes(&mut self, bytes: &[u8]) -> Result<(), ComputeError> {
        let payload = open(bytes)?;
        let (snap, rest): (Payload, _) = postcard::take_from_bytes(payload)
            .map_err(|e| ComputeError::Encoding(e.to_string()))?;
        if !rest.is_empty() {
            return Err(corrupt(format!(
                "{} bytes left after the payload",
                rest.len()
            )));
        }
        self.check_scene(&snap)?;
        self.check_values(&snap)?;
        for p in &self.physics {
            p.check_fields(&snap.state.fields)?;
        }
        self.restore_physics(&snap.physics_state)?;
        self.state = snap.state;
        self.dt = snap.dt;
        // The energy balance is not part of a snapshot: it restarts from the restored state.
        if let Some(t) = self.energy.as_mut() {
            t.rebase();
        }
        self.device_fresh = false;
        Ok(())
    }

    /// Fingerprint of the mesh: dimension, node coordinates (bits) and connectivity.
    fn mesh_fingerprint(&self) -> u64 {
        Fingerprint::new()
            .str(D::NAME)
            .f64s(self.mesh.coords())
            .u32s(self.mesh.elements())
            .finish()
    }

    /// Fingerprint of what the composition derived from the mesh: declared fields, the
    /// node of every force slot per physics, and the lumped physical masses.
    fn layout_fingerprint(&self) -> u64 {
        let mut h = Fingerprint::new();
        for s in self.state.fields.specs() {
            h = h
                .str(&s.name)
                .debug(&s.location)
                .u64(s.components as u64)
                .f64(s.initial);
        }
        for r in &self.slot_ranges {
            h = h.u64(r.start as u64).u64(r.end as u64);
        }
        h.u32s(&self.gather_ptr)
            .u32s(&self.gather_idx)
            .f64s(&self.mass_phys)
            .finish()
    }

    /// Dimension, counts, mesh, physics names, parameters and layout.
    fn check_scene(&self, snap: &Payload) -> Result<(), ComputeError> {
        let (nn, ne) = (self.mesh.n_nodes() as u64, self.mesh.n_elements() as u64);
        if snap.dim != D::NAME || snap.n_nodes != nn || snap.n_elements != ne {
            return Err(mismatch(format!(
                "snapshot is {} with {} nodes and {} elements; simulation is {} with {nn} nodes and {ne} elements",
                snap.dim, snap.n_nodes, snap.n_elements, D::NAME
            )));
        }
        if snap.mesh != self.mesh_fingerprint() {
            return Err(mismatch(
                "the snapshot was taken on a different mesh (same dimension and node and element counts, but other node coordinates or connectivity)",
            ));
        }
        let names = self.physics_names();
        if snap.physics != names {
            return Err(mismatch(format!(
                "the snapshot composes the physics {:?}; this simulation composes {:?}",
                snap.physics, names
            )));
        }
        if snap.physics_params.len() != names.len() {
            return Err(corrupt(format!(
                "{} physics fingerprints for {} physics",
                snap.physics_params.len(),
                names.len()
            )));
        }
        for (i, (p, &f)) in self.physics.iter().zip(&snap.physics_params).enumerate() {
            if p.fingerprint() != f {
                return Err(mismatch(format!(
                    "physics '{}' (number {}) has other parameters than when the snapshot was taken",
                    p.name(),
                    i + 1
                )));
            }
        }
        if snap.layout != self.layout_fingerprint() {
            return Err(mismatch(
                "the composed physics differ from the snapshot's: other fields, force slots or node masses (e.g. another density, material assignment or boundary range)",
            ));
        }
        Ok(())
    }

    /// Lengths and values of the state.
    fn check_values(&self, snap: &Payload) -> Result<(), ComputeError> {
        let s = &snap.state;
        if !s.fields.same_layout(&self.state.fields) {
            return Err(corrupt(
                "the field arrays differ from the declared fields in number or length",
            ));
        }
        let n = self.state.u.len();
        if s.u.len() != n || s.v.len() != n {
            return Err(corrupt(format!(
                "node arrays hold {} and {} values, expected {n}",
                s.u.len(),
                s.v.len()
            )));
        }
        if !(snap.dt > 0.0 && snap.dt.is_finite()) {
            return Err(corrupt(format!(
                "time step {:e} s is not positive and finite",
                snap.dt
            )));
        }
        if !s.time.is_finite() {
            return Err(corrupt(format!("time {} is not finite", s.time)));
        }
        let d = D::D;
        let limit2 = self.runaway * self.runaway;
        for (node, (u, v)) in s.u.chunks_exact(d).zip(s.v.chunks_exact(d)).enumerate() {
            if u.iter().chain(v).any(|x| !x.is_finite()) {
                return Err(corrupt(format!(
                    "node {node}: non-finite displacement or velocity (was the snapshot saved after a divergence?)"
                )));
            }
            if u.iter().map(|x| x * x).sum::<f64>() > limit2 {
                return Err(corrupt(format!(
                    "node {node}: displacement beyond the runaway limit {:e} m (was the snapshot saved after a divergence?)",
                    self.runaway
                )));
            }
        }
        if snap.physics_state.len() != self.physics.len() {
            return Err(corrupt(format!(
                "{} physics states for {} physics",
                snap.physics_state.len(),
                self.physics.len()
            )));
        }
        Ok(())
    }

    /// Restores every physics' own state, all or nothing: if one refuses its state,
    /// those already restored get their previous state back.
    fn restore_physics(&mut self, states: &[Vec<u8>]) -> Result<(), ComputeError> {
        let previous: Vec<Vec<u8>> = self
            .physics
            .iter()
            .map(|p| p.save_state())
            .collect::<Result<_, _>>()?;
        for i in 0..self.physics.len() {
            if let Err(e) = self.physics[i].restore_state(&states[i]) {
                for (p, old) in self.physics[..i].iter_mut().zip(&previous) {
                    // The previous state was just saved by the same physics.
                    p.restore_state(old)?;
                }
                return Err(e);
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests;
