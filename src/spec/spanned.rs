//! The spanned-value machinery of the spec reader: the raw serde form of a spec file, in which
//! every value is [`Spanned`] (so messages can name its line) and every value of any type is
//! accepted (so a type mistake is reported as an invalid value of its key, not as a bare TOML
//! type error).
//!
//! Choices: integers and floats both become [`Val::Num`]; a table or an array where a scalar
//! belongs is kept as [`Val::Other`] with a description for the message ("a table", "an
//! array", "a date-time"); unknown keys are refused by serde (`deny_unknown_fields`) with the
//! list of the keys allowed.

use serde::de::{self, Deserialize, Deserializer, IgnoredAny, MapAccess, SeqAccess, Visitor};
use std::fmt;
use std::marker::PhantomData;
use std::ops::Range;
use toml::Spanned;

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawSpec {
    pub(super) name: Option<Spanned<Val>>,
    pub(super) device: Option<Spanned<Val>>,
    pub(super) size: Option<Spanned<Val>>,
    pub(super) surface: Option<Spanned<List<Spanned<Tab<RawSurface>>>>>,
    pub(super) material: Option<Spanned<Tab<RawMaterial>>>,
    pub(super) sheet: Option<Spanned<Tab<RawSheet>>>,
    pub(super) pattern: Option<Spanned<Tab<RawPattern>>>,
}

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawSurface {
    pub(super) kind: Option<Spanned<Val>>,
    pub(super) path: Option<Spanned<Val>>,
    pub(super) scale: Option<Spanned<Val>>,
    pub(super) size: Option<Spanned<Val>>,
    pub(super) units: Option<Spanned<Val>>,
    pub(super) name: Option<Spanned<Val>>,
    pub(super) p: Option<Spanned<toml::Value>>,
    pub(super) q: Option<Spanned<toml::Value>>,
    pub(super) method: Option<Spanned<Val>>,
    pub(super) bend_lines: Option<Spanned<Val>>,
    pub(super) tolerance: Option<Spanned<Val>>,
    pub(super) side: Option<Spanned<Val>>,
    pub(super) k_factor: Option<Spanned<Val>>,
    pub(super) outline: Option<Spanned<toml::Value>>,
    pub(super) holes: Option<Spanned<toml::Value>>,
    pub(super) line: Option<Spanned<toml::Value>>,
    pub(super) arc: Option<Spanned<toml::Value>>,
    pub(super) flat_curve: Option<Spanned<toml::Value>>,
    pub(super) control_points: Option<Spanned<toml::Value>>,
    pub(super) handles: Option<Spanned<toml::Value>>,
    pub(super) length_fit: Option<Spanned<toml::Value>>,
    pub(super) pieces: Option<Spanned<toml::Value>>,
    #[serde(rename = "loop")]
    pub(super) loop_: Option<Spanned<toml::Value>>,
    pub(super) loop_csv: Option<Spanned<Val>>,
    pub(super) loops: Option<Spanned<toml::Value>>,
    pub(super) darts: Option<Spanned<toml::Value>>,
    pub(super) rulings: Option<Spanned<toml::Value>>,
    pub(super) max_dihedral: Option<Spanned<Val>>,
    pub(super) min_chart_area: Option<Spanned<Val>>,
    pub(super) max_iterations: Option<Spanned<Val>>,
    pub(super) smooth: Option<Spanned<Val>>,
    pub(super) good_interior: Option<Spanned<Val>>,
    pub(super) good_fairness: Option<Spanned<Val>>,
    pub(super) segment: Option<Spanned<Val>>,
    pub(super) charts: Option<Spanned<Val>>,
    pub(super) f_max: Option<Spanned<Val>>,
    pub(super) approximate: Option<Spanned<toml::Value>>,
    pub(super) simplify: Option<Spanned<Val>>,
    pub(super) curves: Option<Spanned<List<Spanned<toml::Value>>>>,
    pub(super) apex: Option<Spanned<toml::Value>>,
    pub(super) degree: Option<Spanned<Val>>,
    pub(super) closed: Option<Spanned<Val>>,
    pub(super) creases: Option<Spanned<toml::Value>>,
    pub(super) folds: Option<Spanned<toml::Value>>,
    pub(super) fixed: Option<Spanned<toml::Value>>,
    pub(super) iterations: Option<Spanned<Val>>,
    pub(super) epsilon1: Option<Spanned<Val>>,
    pub(super) epsilon2: Option<Spanned<Val>>,
    pub(super) target: Option<Spanned<toml::Value>>,
}

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawMaterial {
    pub(super) kind: Option<Spanned<Val>>,
    pub(super) thickness: Option<Spanned<Val>>,
    pub(super) k_factor: Option<Spanned<Val>>,
    pub(super) bend_radius: Option<Spanned<Val>>,
}

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawSheet {
    pub(super) width: Option<Spanned<Val>>,
    pub(super) height: Option<Spanned<Val>>,
    pub(super) roll: Option<Spanned<Val>>,
    pub(super) margin: Option<Spanned<Val>>,
    pub(super) spacing: Option<Spanned<Val>>,
}

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawPattern {
    pub(super) fold_threshold: Option<Spanned<Val>>,
    pub(super) tabs: Option<Spanned<Val>>,
    pub(super) tab_height: Option<Spanned<Val>>,
    pub(super) allowance: Option<Spanned<Val>>,
    pub(super) notches: Option<Spanned<Val>>,
    pub(super) kerf: Option<Spanned<Val>>,
    pub(super) bend_notches: Option<Spanned<Val>>,
}

/// Any TOML value, reduced to what the checks need. Integers and floats both become `Num`.
#[derive(Debug, Clone, PartialEq)]
pub(super) enum Val {
    Num(f64),
    Str(String),
    Bool(bool),
    /// A value of another type, described for messages ("a table", "an array", ...).
    Other(&'static str),
}

/// A number as TOML would write it (`nan`, `inf`, `-3`, `0.25`).
pub(super) fn fmt_num(v: f64) -> String {
    if v.is_nan() {
        "nan".to_string()
    } else if v.is_infinite() {
        if v > 0.0 { "inf" } else { "-inf" }.to_string()
    } else {
        format!("{v}")
    }
}

impl fmt::Display for Val {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Val::Num(v) => f.write_str(&fmt_num(*v)),
            Val::Str(s) => write!(f, "{s:?}"),
            Val::Bool(b) => write!(f, "{b}"),
            Val::Other(what) => f.write_str(what),
        }
    }
}

/// Name under which toml hands a date-time to `deserialize_any` (as a one-entry map).
pub(super) const TOML_DATETIME_KEY: &str = "$__toml_private_datetime";

struct ValVisitor;

impl<'de> Visitor<'de> for ValVisitor {
    type Value = Val;

    fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("any value")
    }
    fn visit_bool<E>(self, v: bool) -> Result<Val, E> {
        Ok(Val::Bool(v))
    }
    fn visit_i64<E>(self, v: i64) -> Result<Val, E> {
        Ok(Val::Num(v as f64))
    }
    fn visit_u64<E>(self, v: u64) -> Result<Val, E> {
        Ok(Val::Num(v as f64))
    }
    fn visit_f64<E>(self, v: f64) -> Result<Val, E> {
        Ok(Val::Num(v))
    }
    fn visit_str<E>(self, v: &str) -> Result<Val, E> {
        Ok(Val::Str(v.to_string()))
    }
    fn visit_string<E>(self, v: String) -> Result<Val, E> {
        Ok(Val::Str(v))
    }
    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Val, A::Error> {
        while seq.next_element::<IgnoredAny>()?.is_some() {}
        Ok(Val::Other("an array"))
    }
    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Val, A::Error> {
        let mut what = "a table";
        if let Some(key) = map.next_key::<String>()? {
            if key == TOML_DATETIME_KEY {
                what = "a date-time";
            }
            map.next_value::<IgnoredAny>()?;
            while map.next_entry::<IgnoredAny, IgnoredAny>()?.is_some() {}
        }
        Ok(Val::Other(what))
    }
}

impl<'de> Deserialize<'de> for Val {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_any(ValVisitor)
    }
}

/// Scalar `visit_*` methods that turn the value into `$wrap(Val)`.
macro_rules! wrong_scalars {
    ($wrap:path) => {
        fn visit_bool<E>(self, v: bool) -> Result<Self::Value, E> {
            Ok($wrap(Val::Bool(v)))
        }
        fn visit_i64<E>(self, v: i64) -> Result<Self::Value, E> {
            Ok($wrap(Val::Num(v as f64)))
        }
        fn visit_u64<E>(self, v: u64) -> Result<Self::Value, E> {
            Ok($wrap(Val::Num(v as f64)))
        }
        fn visit_f64<E>(self, v: f64) -> Result<Self::Value, E> {
            Ok($wrap(Val::Num(v)))
        }
        fn visit_str<E>(self, v: &str) -> Result<Self::Value, E> {
            Ok($wrap(Val::Str(v.to_string())))
        }
    };
}

/// A table deserialised as `T`, or a value of another type kept for the message.
pub(super) enum Tab<T> {
    Table(T),
    Wrong(Val),
}

struct TabVisitor<T>(PhantomData<T>);

impl<'de, T: Deserialize<'de>> Visitor<'de> for TabVisitor<T> {
    type Value = Tab<T>;

    fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("a table")
    }
    wrong_scalars!(Tab::Wrong);
    fn visit_seq<A: SeqAccess<'de>>(self, seq: A) -> Result<Self::Value, A::Error> {
        ValVisitor.visit_seq(seq).map(Tab::Wrong)
    }
    fn visit_map<A: MapAccess<'de>>(self, map: A) -> Result<Self::Value, A::Error> {
        T::deserialize(de::value::MapAccessDeserializer::new(map)).map(Tab::Table)
    }
}

impl<'de, T: Deserialize<'de>> Deserialize<'de> for Tab<T> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_any(TabVisitor(PhantomData))
    }
}

/// An array of `T`, or a value of another type kept for the message.
pub(super) enum List<T> {
    Items(Vec<T>),
    Wrong(Val),
}

struct ListVisitor<T>(PhantomData<T>);

impl<'de, T: Deserialize<'de>> Visitor<'de> for ListVisitor<T> {
    type Value = List<T>;

    fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("an array")
    }
    wrong_scalars!(List::Wrong);
    fn visit_seq<A: SeqAccess<'de>>(self, seq: A) -> Result<Self::Value, A::Error> {
        Vec::<T>::deserialize(de::value::SeqAccessDeserializer::new(seq)).map(List::Items)
    }
    fn visit_map<A: MapAccess<'de>>(self, map: A) -> Result<Self::Value, A::Error> {
        ValVisitor.visit_map(map).map(List::Wrong)
    }
}

impl<'de, T: Deserialize<'de>> Deserialize<'de> for List<T> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_any(ListVisitor(PhantomData))
    }
}

/// Where a key stands in the file, if it is given.
pub(super) fn span<T>(v: &Option<Spanned<T>>) -> Option<Range<usize>> {
    v.as_ref().map(|v| v.span())
}
