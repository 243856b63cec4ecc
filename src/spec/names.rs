//! The names a user writes for the stages' enums: [`FromStr`] for [`SurfaceKind`], [`Units`],
//! [`MaterialKind`] and [`Segment`] from their `NAMES` tables, used by the spec reader and by
//! the command line's flags (`--material`, `--segment`).
//!
//! Choices: names are matched ignoring ASCII case and surrounding blanks; an unknown one is
//! answered with the list of the allowed names, in table order.

use crate::surface::{MaterialKind, Segment, SurfaceKind, Units};
use std::str::FromStr;

/// "one of a, b, c"
pub(super) fn one_of(names: &[&str]) -> String {
    format!("one of {}", names.join(", "))
}

/// Finds `s` among `(name, value)` pairs, ignoring ASCII case; the error lists the names.
pub(super) fn pick<T: Copy>(s: &str, table: &[(&str, T)]) -> Result<T, String> {
    table
        .iter()
        .find(|(name, _)| name.eq_ignore_ascii_case(s.trim()))
        .map(|&(_, v)| v)
        .ok_or_else(|| {
            let names: Vec<&str> = table.iter().map(|(n, _)| *n).collect();
            format!("expected {}, got {s:?}", one_of(&names))
        })
}

impl FromStr for SurfaceKind {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        pick(s, &Self::NAMES)
    }
}

impl FromStr for Units {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        pick(s, &Self::NAMES)
    }
}

/// Parses `paper`, `fabric` or `metal` (any ASCII case); the error lists the allowed values.
impl FromStr for MaterialKind {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        pick(s, &Self::NAMES)
    }
}

impl FromStr for Segment {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        pick(s, &Self::NAMES)
    }
}
