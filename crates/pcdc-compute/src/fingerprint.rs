//! A stable 64-bit fingerprint (FNV-1a) of meshes and physics parameters, stored in
//! snapshots so that a restore into another scene is refused.
//!
//! FNV-1a is written here rather than taken from `std::hash`: the standard hashers'
//! algorithms are unspecified and may change between Rust releases, which would make
//! every saved snapshot unreadable after a compiler upgrade. Every value is fed as
//! little-endian bytes, so a fingerprint is the same on every platform. It is not a
//! cryptographic hash: it tells scenes apart, it does not resist forgery.

use std::fmt::{Debug, Write};

const OFFSET: u64 = 0xcbf2_9ce4_8422_2325;
const PRIME: u64 = 0x0000_0100_0000_01b3;

/// An incremental FNV-1a (64-bit) hasher over little-endian bytes.
///
/// Physics use it in [`crate::Physics::fingerprint`] to summarise their parameters:
///
/// ```
/// use pcdc_compute::Fingerprint;
/// let a = Fingerprint::new().str("contact").f64(1e10).finish();
/// let b = Fingerprint::new().str("contact").f64(2e10).finish();
/// assert_ne!(a, b);
/// ```
#[derive(Clone, Copy, Debug)]
pub struct Fingerprint(u64);

impl Default for Fingerprint {
    fn default() -> Self {
        Self::new()
    }
}

impl Fingerprint {
    /// An empty fingerprint (the FNV offset basis).
    pub fn new() -> Self {
        Fingerprint(OFFSET)
    }

    /// Feeds raw bytes.
    pub fn bytes(mut self, bytes: &[u8]) -> Self {
        for &b in bytes {
            self.0 ^= u64::from(b);
            self.0 = self.0.wrapping_mul(PRIME);
        }
        self
    }

    /// Feeds an integer.
    pub fn u64(self, v: u64) -> Self {
        self.bytes(&v.to_le_bytes())
    }

    /// Feeds the bits of a float (so -0.0, 0.0 and every NaN payload differ).
    pub fn f64(self, v: f64) -> Self {
        self.u64(v.to_bits())
    }

    /// Feeds a string, preceded by its length (so "ab" + "c" differs from "a" + "bc").
    pub fn str(self, s: &str) -> Self {
        self.u64(s.len() as u64).bytes(s.as_bytes())
    }

    /// Feeds a slice of floats (bits), preceded by its length.
    pub fn f64s(self, v: &[f64]) -> Self {
        v.iter().fold(self.u64(v.len() as u64), |h, &x| h.f64(x))
    }

    /// Feeds a slice of integers, preceded by its length.
    pub fn u32s(self, v: &[u32]) -> Self {
        v.iter()
            .fold(self.u64(v.len() as u64), |h, &x| h.bytes(&x.to_le_bytes()))
    }

    /// Feeds the `Debug` text of a value, e.g. a constitutive model and its parameters
    /// (Rust prints floats with the shortest text that reads back to the same bits).
    pub fn debug(mut self, v: &impl Debug) -> Self {
        // Writing into the hasher cannot fail; a failing `Debug` impl only shortens the
        // text, which still gives a deterministic fingerprint.
        let _ = write!(self, "{v:?}");
        self.bytes(&[0xff])
    }

    /// The 64-bit value.
    pub fn finish(self) -> u64 {
        self.0
    }
}

impl Write for Fingerprint {
    fn write_str(&mut self, s: &str) -> std::fmt::Result {
        *self = self.bytes(s.as_bytes());
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn known_fnv1a_values() {
        // Reference values of 64-bit FNV-1a.
        assert_eq!(Fingerprint::new().finish(), 0xcbf2_9ce4_8422_2325);
        assert_eq!(
            Fingerprint::new().bytes(b"a").finish(),
            0xaf63_dc4c_8601_ec8c
        );
        assert_eq!(
            Fingerprint::new().bytes(b"foobar").finish(),
            0x8594_4171_f739_67e8
        );
    }

    #[test]
    fn lengths_separate_fields() {
        let a = Fingerprint::new().str("ab").str("c").finish();
        let b = Fingerprint::new().str("a").str("bc").finish();
        assert_ne!(a, b);
        assert_ne!(
            Fingerprint::new().f64(0.0).finish(),
            Fingerprint::new().f64(-0.0).finish()
        );
        assert_ne!(
            Fingerprint::new().debug(&[1.0, 2.0]).finish(),
            Fingerprint::new()
                .debug(&[1.0, 2.000_000_000_000_000_4])
                .finish()
        );
    }
}
