//! Time tables: `Table::new`, deserialisation (JSON and TOML) and constant time values.

use pcdc_compute::{Table, TimeValue};

use crate::{case, run};

fn json(text: &'static str) -> Result<Table, serde_json::Error> {
    serde_json::from_str(text)
}

fn toml_table(text: &'static str) -> Result<Table, toml::de::Error> {
    toml::from_str(text)
}

#[test]
fn bad_tables_are_named_errors() {
    run(
        "tables",
        vec![
            case("empty", "table vel: empty table", || Table::new("vel", &[])),
            case("unsorted", "entry 2 has t = 1 after t = 2", || {
                Table::new("vel", &[(0.0, 1.0), (2.0, 1.0), (1.0, 0.0)])
            }),
            case("repeated time", "increase strictly", || {
                Table::new("vel", &[(0.0, 1.0), (0.0, 2.0)])
            }),
            case("NaN value", "entry 0 (0, NaN) is not finite", || {
                Table::new("vel", &[(0.0, f64::NAN)])
            }),
            case("infinite time", "entry 1 (inf, 1) is not finite", || {
                Table::new("vel", &[(0.0, 1.0), (f64::INFINITY, 1.0)])
            }),
            case("json: empty", "empty table", || json(r#"{"t":[],"v":[]}"#)),
            case("json: unsorted", "entry 1 has t = 0", || {
                json(r#"{"t":[1.0,0.0],"v":[0.0,2.0]}"#)
            }),
            case(
                "json: lengths differ",
                "2 times (t) but 1 values (v)",
                || json(r#"{"t":[0.0,1.0],"v":[0.0]}"#),
            ),
            case("json: missing values", "missing field `v`", || {
                json(r#"{"t":[0.0]}"#)
            }),
            case("toml: NaN value", "is not finite", || {
                toml_table("t = [0.0, 1.0]\nv = [0.0, nan]\n")
            }),
            case("toml: infinite time", "is not finite", || {
                toml_table("t = [0.0, inf]\nv = [0.0, 1.0]\n")
            }),
            case("constant NaN", "velocity = NaN: must be finite", || {
                TimeValue::Const(f64::NAN).check("velocity")
            }),
        ],
    );
}
