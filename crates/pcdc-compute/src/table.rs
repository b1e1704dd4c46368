//! Time tables: piecewise-linear functions of time, wherever the manual marks a value
//! `<table>` (boundary velocities, forces, stresses, ...).

use serde::{Deserialize, Serialize};

use crate::ComputeError;

/// A piecewise-linear table `value(t)` through sorted points; constant beyond its ends.
///
/// Its points are private: [`Table::new`] and deserialisation share one check (at least
/// one point, finite entries, strictly increasing times, as many times as values), so a
/// table from a file can neither panic when evaluated nor run silently out of order.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "RawTable")]
pub struct Table {
    t: Vec<f64>,
    v: Vec<f64>,
}

/// The serialised form of a [`Table`] (times in s, values), checked before it becomes one.
#[derive(Deserialize)]
struct RawTable {
    t: Vec<f64>,
    v: Vec<f64>,
}

impl TryFrom<RawTable> for Table {
    type Error = ComputeError;

    fn try_from(raw: RawTable) -> Result<Self, ComputeError> {
        if raw.t.len() != raw.v.len() {
            return Err(ComputeError::InvalidTable {
                name: "(deserialised)".into(),
                reason: format!("{} times (t) but {} values (v)", raw.t.len(), raw.v.len()),
            });
        }
        let points: Vec<(f64, f64)> = raw.t.into_iter().zip(raw.v).collect();
        Table::new("(deserialised)", &points)
    }
}

impl Table {
    /// Builds a table from `(time [s], value)` points. Errors on an empty table, a
    /// non-finite entry, or times that are not strictly increasing (naming the entry).
    pub fn new(name: &str, points: &[(f64, f64)]) -> Result<Self, ComputeError> {
        let err = |reason: String| ComputeError::InvalidTable {
            name: name.to_string(),
            reason,
        };
        if points.is_empty() {
            return Err(err(
                "empty table: give at least one (time, value) point".into()
            ));
        }
        for (i, &(t, v)) in points.iter().enumerate() {
            if !t.is_finite() || !v.is_finite() {
                return Err(err(format!("entry {i} ({t}, {v}) is not finite")));
            }
            if i > 0 && t <= points[i - 1].0 {
                return Err(err(format!(
                    "times must increase strictly: entry {i} has t = {t} after t = {}",
                    points[i - 1].0
                )));
            }
        }
        Ok(Table {
            t: points.iter().map(|p| p.0).collect(),
            v: points.iter().map(|p| p.1).collect(),
        })
    }

    /// Value at time `t` (s): linear between points, constant outside.
    pub fn eval(&self, t: f64) -> f64 {
        let n = self.t.len();
        if t <= self.t[0] {
            return self.v[0];
        }
        if t >= self.t[n - 1] {
            return self.v[n - 1];
        }
        let i = self.t.partition_point(|&ti| ti <= t); // t[i-1] <= t < t[i]
        let (t0, t1, v0, v1) = (self.t[i - 1], self.t[i], self.v[i - 1], self.v[i]);
        v0 + (v1 - v0) * (t - t0) / (t1 - t0)
    }

    /// The table's points.
    pub fn points(&self) -> impl Iterator<Item = (f64, f64)> + '_ {
        self.t.iter().copied().zip(self.v.iter().copied())
    }
}

/// A value that is either constant or a time table.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum TimeValue {
    /// A constant.
    Const(f64),
    /// A piecewise-linear table of time.
    Table(Table),
    /// A value the program sets between steps (a servo, a controller): read when the
    /// condition is applied, on either backend (GPU conditions read their values on the
    /// host each step). Not in scene files: it cannot be serialised.
    #[serde(skip)]
    Control(Control),
}

impl TimeValue {
    /// Value at time `t` (s).
    pub fn at(&self, t: f64) -> f64 {
        match self {
            TimeValue::Const(c) => *c,
            TimeValue::Table(tab) => tab.eval(t),
            TimeValue::Control(c) => c.get(),
        }
    }

    /// Errors when a constant is not finite.
    pub fn check(&self, name: &str) -> Result<(), ComputeError> {
        match self {
            TimeValue::Const(c) if !c.is_finite() => {
                Err(ComputeError::param(name, c, "must be finite"))
            }
            _ => Ok(()),
        }
    }
}

/// A shared value set between steps ([`TimeValue::Control`]): clones share it. Setting
/// a non-finite value keeps the previous one (a controller's NaN must not reach the
/// nodes).
#[derive(Clone, Debug, Default)]
pub struct Control(std::sync::Arc<std::sync::atomic::AtomicU64>);

impl Control {
    /// A control holding `value`.
    pub fn new(value: f64) -> Self {
        let c = Control::default();
        c.set(value);
        c
    }

    /// Sets the value; ignored unless finite.
    pub fn set(&self, value: f64) {
        if value.is_finite() {
            self.0
                .store(value.to_bits(), std::sync::atomic::Ordering::Relaxed);
        }
    }

    /// The current value.
    pub fn get(&self) -> f64 {
        f64::from_bits(self.0.load(std::sync::atomic::Ordering::Relaxed))
    }
}

impl PartialEq for Control {
    /// The same shared cell.
    fn eq(&self, other: &Self) -> bool {
        std::sync::Arc::ptr_eq(&self.0, &other.0)
    }
}

impl From<Control> for TimeValue {
    fn from(c: Control) -> Self {
        TimeValue::Control(c)
    }
}

impl From<f64> for TimeValue {
    fn from(v: f64) -> Self {
        TimeValue::Const(v)
    }
}

impl From<Table> for TimeValue {
    fn from(t: Table) -> Self {
        TimeValue::Table(t)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn errors() {
        assert!(matches!(
            Table::new("v", &[]),
            Err(ComputeError::InvalidTable { .. })
        ));
        let e = Table::new("vel", &[(0.0, 1.0), (2.0, 1.0), (1.0, 0.0)]).unwrap_err();
        assert!(e.to_string().contains("entry 2"), "{e}");
        assert!(Table::new("v", &[(0.0, f64::NAN)]).is_err());
        assert!(Table::new("v", &[(0.0, 1.0), (0.0, 2.0)]).is_err());
    }

    #[test]
    fn deserialisation_is_checked_like_new() {
        let ok: Table = serde_json::from_str(r#"{"t":[0.0,1.0],"v":[0.0,2.0]}"#).unwrap();
        assert_eq!(ok.eval(0.5), 1.0);
        for (json, what) in [
            (r#"{"t":[],"v":[]}"#, "empty"),
            (r#"{"t":[1.0,0.0],"v":[0.0,2.0]}"#, "entry 1"),
            (r#"{"t":[0.0,1.0],"v":[0.0]}"#, "2 times (t) but 1 values"),
        ] {
            let e = serde_json::from_str::<Table>(json).unwrap_err().to_string();
            assert!(e.contains(what), "{json}: {e}");
        }
    }

    #[test]
    fn interpolates_and_clamps() {
        let t = Table::new("v", &[(0.0, 0.0), (1.0, 2.0), (3.0, 2.0)]).unwrap();
        assert_eq!(t.eval(-1.0), 0.0);
        assert_eq!(t.eval(0.5), 1.0);
        assert_eq!(t.eval(2.0), 2.0);
        assert_eq!(t.eval(9.0), 2.0);
    }

    proptest! {
        #[test]
        fn stays_within_bounds(vals in proptest::collection::vec(-1e3f64..1e3, 1..8), t in -1.0f64..10.0) {
            let pts: Vec<(f64, f64)> = vals.iter().enumerate().map(|(i, &v)| (i as f64, v)).collect();
            let tab = Table::new("p", &pts).unwrap();
            let y = tab.eval(t);
            let lo = vals.iter().cloned().fold(f64::INFINITY, f64::min);
            let hi = vals.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
            prop_assert!(y >= lo - 1e-9 && y <= hi + 1e-9);
            for (i, &v) in vals.iter().enumerate() {
                prop_assert_eq!(tab.eval(i as f64), v);
            }
        }
    }
}
