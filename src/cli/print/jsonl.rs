//! The JSON Lines printer: one record per input, in input order, tagged with its schema
//! (`docs/json.md`). The schema and status come after the record's own fields, as they always have.

use super::Record;
use bumpbake::scene::set_key;
use bumpbake::Error;
use serde_json::{json, Map, Value};
use std::path::Path;

/// The record of an input that went well.
pub fn ok<R: Record>(r: &R) -> Value {
    let mut v = serde_json::to_value(r).expect("report serialises");
    set_key(&mut v, "schema", json!(R::SCHEMA));
    if R::OK_STATUS {
        set_key(&mut v, "status", json!("ok"));
    }
    v
}

/// The record of an input that could not be used: the one line people see, and the exit code
/// the input alone would have given.
pub fn error<R: Record>(input: &Path, e: &Error) -> Value {
    let mut m = Map::new();
    m.insert("schema".into(), json!(R::SCHEMA));
    m.insert(R::INPUT_FIELD.into(), json!(input));
    m.insert("status".into(), json!("error"));
    m.insert("exit_code".into(), json!(e.exit_code()));
    m.insert("error".into(), json!(e.to_string()));
    Value::Object(m)
}
