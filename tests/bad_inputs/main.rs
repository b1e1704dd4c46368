//! Bad inputs of every kind are named errors, never panics. One module per input kind.

mod snapshots;
