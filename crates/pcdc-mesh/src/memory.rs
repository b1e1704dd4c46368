//! Memory guard: requests are sized in bytes, not in element counts.
//!
//! Builders (and the scene files of the `pcdc` crate) estimate the memory a request needs
//! before allocating it and refuse what exceeds the *memory limit* with a
//! [`MeshError::MemoryLimit`] that gives the estimate, the limit and the parameter that
//! asked for it.
//!
//! The limit, in bytes, is the first of:
//!
//! 1. the value set by [`set_memory_limit`] (process-wide; `None` clears it);
//! 2. the environment variable [`MEMORY_LIMIT_ENV`] (`PCDC_MEMORY_LIMIT`): a whole number
//!    of bytes with an optional binary suffix `K`, `M`, `G`, `T` (or `KiB`, `MiB`, `GiB`,
//!    `TiB`), e.g. `PCDC_MEMORY_LIMIT=64G`; a malformed or zero value is an error naming
//!    the variable and its value (never silently ignored);
//! 3. [`DEFAULT_MEMORY_FRACTION`] (one half) of the machine's physical memory, read from
//!    `MemTotal` in `/proc/meminfo` on Linux, or of [`FALLBACK_PHYSICAL_MEMORY`] (8 GiB)
//!    where that cannot be read.
//!
//! The estimates ([`mesh_bytes`]) are upper bounds of the peak memory while the mesh is
//! built (coordinates, connectivity, faces and the face lookup table); a simulation on the
//! mesh needs more, which callers that know it add on top.

use std::sync::atomic::{AtomicU64, Ordering};

use crate::{Dim, MeshError};

/// Environment variable that sets the memory limit (bytes, optional `K`/`M`/`G`/`T`
/// binary suffix).
pub const MEMORY_LIMIT_ENV: &str = "PCDC_MEMORY_LIMIT";

/// Fraction of the physical memory used as the default limit (1/2: leaves room for the
/// operating system, other processes and the allocations the estimates do not cover).
pub const DEFAULT_MEMORY_FRACTION: f64 = 0.5;

/// Physical memory assumed where it cannot be read (no `/proc/meminfo`): 8 GiB.
pub const FALLBACK_PHYSICAL_MEMORY: u64 = 8 << 30;

/// Bytes of one entry of the face lookup table built with the faces (a 12-byte key, a
/// 4-byte value and the hash table's control byte and spare capacity, rounded up).
const FACE_MAP_ENTRY: f64 = 32.0;

/// Limit set by [`set_memory_limit`]; 0 means "not set".
static LIMIT: AtomicU64 = AtomicU64::new(0);

/// Sets the process-wide memory limit (bytes); `None` returns to the environment
/// variable or the default. A limit of 0 is treated as `None`.
pub fn set_memory_limit(bytes: Option<u64>) {
    LIMIT.store(bytes.unwrap_or(0), Ordering::Relaxed);
}

/// The memory limit in bytes (see the [module documentation](self) for its sources).
///
/// # Errors
///
/// [`MeshError::MemoryLimitSetting`] when [`MEMORY_LIMIT_ENV`] is set to a malformed or
/// zero value.
pub fn memory_limit() -> Result<u64, MeshError> {
    let set = LIMIT.load(Ordering::Relaxed);
    if set > 0 {
        return Ok(set);
    }
    if let Ok(v) = std::env::var(MEMORY_LIMIT_ENV) {
        return parse_bytes(&v);
    }
    let physical = physical_memory().unwrap_or(FALLBACK_PHYSICAL_MEMORY);
    Ok((physical as f64 * DEFAULT_MEMORY_FRACTION) as u64)
}

/// Physical memory of the machine in bytes (`MemTotal` of `/proc/meminfo`), if known.
pub fn physical_memory() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemTotal:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    kib.checked_mul(1024).filter(|&b| b > 0)
}

/// Parses a byte count with an optional binary suffix (`K`, `M`, `G`, `T`, or with `iB`).
fn parse_bytes(s: &str) -> Result<u64, MeshError> {
    let bad = |reason: &'static str| MeshError::MemoryLimitSetting {
        value: s.to_string(),
        reason,
    };
    let t = s.trim();
    let split = t.find(|c: char| !c.is_ascii_digit()).unwrap_or(t.len());
    let (digits, suffix) = t.split_at(split);
    let shift = match suffix.trim() {
        "" | "B" => 0,
        "K" | "KiB" | "k" => 10,
        "M" | "MiB" => 20,
        "G" | "GiB" => 30,
        "T" | "TiB" => 40,
        _ => {
            return Err(bad(
                "expected a whole number of bytes with an optional K, M, G or T suffix",
            ))
        }
    };
    let n: u64 = digits.parse().map_err(|_| {
        bad("expected a whole number of bytes with an optional K, M, G or T suffix")
    })?;
    if n == 0 {
        return Err(bad("must be positive"));
    }
    n.checked_mul(1 << shift)
        .ok_or_else(|| bad("does not fit in 64 bits"))
}

/// Upper estimate (bytes) of the peak memory of building a mesh of dimension `D` with
/// `n_nodes` nodes and `n_elements` elements: coordinates (`8 D` bytes per node),
/// connectivity (`4` bytes per element node), faces and adjacency (`4` per face node plus
/// 17 per face) and the face lookup table (32 per face), counting every element face once.
/// Takes `f64` so that absurd requests are estimated without overflow.
pub fn mesh_bytes<D: Dim>(n_nodes: f64, n_elements: f64) -> f64 {
    let (d, npe, npf, nfe) = (
        D::D as f64,
        D::NODES_PER_ELEM as f64,
        D::NODES_PER_FACE as f64,
        D::FACES_PER_ELEM as f64,
    );
    let per_node = 8.0 * d + 1.0;
    let per_face = 4.0 * npf + 17.0 + FACE_MAP_ENTRY;
    let per_element = 4.0 * npe + nfe * per_face;
    n_nodes * per_node + n_elements * per_element
}

/// Refuses a request whose estimated memory `bytes` exceeds [`memory_limit`].
///
/// `name` and `value` are the parameter that asked for it (e.g. `"size"`, the element
/// size in m) and `what` says what would be built (e.g. `"the mesh of 4.0e9 elements"`).
///
/// # Errors
///
/// [`MeshError::MemoryLimit`] with the estimate and the limit, or the error of
/// [`memory_limit`].
pub fn check_memory(
    name: impl Into<String>,
    value: f64,
    what: impl Into<String>,
    bytes: f64,
) -> Result<(), MeshError> {
    check_memory_against(memory_limit()?, name, value, what, bytes)
}

fn check_memory_against(
    limit: u64,
    name: impl Into<String>,
    value: f64,
    what: impl Into<String>,
    bytes: f64,
) -> Result<(), MeshError> {
    if bytes.is_nan() || bytes > limit as f64 {
        return Err(MeshError::MemoryLimit {
            name: name.into(),
            value,
            what: what.into(),
            estimate: bytes,
            limit,
        });
    }
    Ok(())
}

/// [`check_memory`] for a mesh of dimension `D` of about `n_nodes` nodes and
/// `n_elements` elements, estimated by [`mesh_bytes`].
///
/// # Errors
///
/// As [`check_memory`].
pub fn check_mesh_memory<D: Dim>(
    name: impl Into<String>,
    value: f64,
    n_nodes: f64,
    n_elements: f64,
) -> Result<(), MeshError> {
    check_memory(
        name,
        value,
        format!("a mesh of about {n_elements:.3e} elements and {n_nodes:.3e} nodes"),
        mesh_bytes::<D>(n_nodes, n_elements),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Dim2, Dim3};

    #[test]
    fn parses_suffixes_and_rejects_garbage() {
        assert_eq!(parse_bytes("1024").unwrap(), 1024);
        assert_eq!(parse_bytes("3K").unwrap(), 3 << 10);
        assert_eq!(parse_bytes(" 64G ").unwrap(), 64 << 30);
        assert_eq!(parse_bytes("2TiB").unwrap(), 2 << 40);
        for bad in ["", "0", "12X", "-5", "1.5G", "99999999999999999999T"] {
            let e = parse_bytes(bad).unwrap_err();
            assert!(e.to_string().contains(MEMORY_LIMIT_ENV), "{e}");
        }
    }

    #[test]
    fn estimates_grow_with_dimension_and_count() {
        let a = mesh_bytes::<Dim2>(1e6, 2e6);
        assert!(a > 2e6 * 12.0 + 1e6 * 16.0);
        assert!(mesh_bytes::<Dim3>(1e6, 2e6) > a);
        assert!(mesh_bytes::<Dim2>(f64::INFINITY, 1.0).is_infinite());
    }

    #[test]
    fn limit_is_settable_and_refuses_with_the_estimate() {
        // A huge limit, so that the builder tests running in parallel are not affected.
        set_memory_limit(Some(1 << 62));
        assert_eq!(memory_limit().unwrap(), 1 << 62);
        set_memory_limit(None);
        assert!(memory_limit().unwrap() < 1 << 62);
        if std::path::Path::new("/proc/meminfo").exists() {
            assert!(physical_memory().is_some_and(|b| b > 1 << 20));
        }
        let bytes = mesh_bytes::<Dim2>(10.0, 10.0);
        let e = check_memory_against(1000, "size", 1e-3, "a mesh", bytes).unwrap_err();
        let msg = e.to_string();
        assert!(
            msg.contains("size = 0.001") && msg.contains("1000 bytes"),
            "{msg}"
        );
        assert!(check_memory_against(1000, "size", 1.0, "a mesh", 999.0).is_ok());
        assert!(check_memory_against(1000, "size", 1.0, "a mesh", f64::NAN).is_err());
    }
}
