//! Readers shared by several kinds of surface: curves (an inline list of points, or a table of
//! kind `points`, `csv`, `circle`, `ellipse`, `rect`, `bezier` or `bspline`, see
//! [`crate::geom::curve::Curve`]), 3D points and point lists, and `bend_lines`. Strips read
//! their `p` and `q` with them, bent sheets their `control_points`, boundaries their loops
//! (the format is in [`super`]'s doc, under Strips).
//!
//! Choices: points have 2 or 3 coordinates (z = 0 when left out); a table without `kind` but
//! with `points` is a point list; a curve's keys are checked here and its messages name the
//! line of the key that holds the curve (TOML gives no spans inside a value). Curves are read
//! here and sampled by the kind that uses them.

use super::context::Ctx;
use super::names::one_of;
use super::spanned::Val;
use super::SpecError;
use crate::geom::curve::Curve;
use glam::DVec3;
use std::path::Path;
use toml::{Spanned, Value};

impl Ctx<'_> {
    /// `bend_lines` of a strip or a bent sheet: "all" (default), "none", "shop" (equal shares
    /// of the bend on lines at least 20 mm apart) or a spacing in mm.
    pub(super) fn bend_lines(
        &self,
        v: &Option<Spanned<Val>>,
        key: &str,
    ) -> Result<crate::surface::strip::BendLines, SpecError> {
        use crate::surface::strip::BendLines;
        let Some(v) = v else {
            return Ok(BendLines::All);
        };
        match v.get_ref() {
            Val::Str(t) if t.trim().eq_ignore_ascii_case("all") => Ok(BendLines::All),
            Val::Str(t) if t.trim().eq_ignore_ascii_case("none") => Ok(BendLines::None),
            Val::Str(t) if t.trim().eq_ignore_ascii_case("shop") => Ok(BendLines::Shop),
            Val::Num(x) if x.is_finite() && *x > 0.0 => Ok(BendLines::Spacing(*x)),
            _ => Err(self.expected(
                v,
                &format!("{key}.bend_lines"),
                "\"all\", \"none\", \"shop\" or a positive spacing in millimetres",
            )),
        }
    }

    /// A curve: an inline list of points, or a table with a `kind` (see the module doc).
    pub(super) fn curve(
        &self,
        v: &toml::Value,
        key: &str,
        line: usize,
        dir: &Path,
    ) -> Result<Curve, SpecError> {
        let t = match v {
            Value::Array(items) => {
                return Ok(Curve::Points {
                    points: self.points(items, key, line)?,
                    closed: false,
                })
            }
            Value::Table(t) => t,
            other => {
                return Err(self.invalid(
                    line,
                    key,
                    format!(
                        "must be a list of points [[x, y, z], ...] or a table with `kind`, got {}",
                        other.type_str()
                    ),
                ))
            }
        };
        let kind = self.curve_kind(t, key, line)?;
        let table = CurveTable {
            ctx: self,
            t,
            key,
            line,
            kind: &kind,
        };
        table.check_keys()?;
        table.build(dir)
    }

    /// A curve table's `kind`, lower-case; `points` when it is left out but `points` is given.
    fn curve_kind(&self, t: &toml::Table, key: &str, line: usize) -> Result<String, SpecError> {
        match t.get("kind") {
            None if t.contains_key("points") => Ok("points".to_string()),
            None => Err(self.invalid(
                line,
                &format!("{key}.kind"),
                format!(
                    "missing: a curve table needs `kind`, {}",
                    one_of(&CURVE_KINDS)
                ),
            )),
            Some(Value::String(k))
                if CURVE_KINDS.iter().any(|x| x.eq_ignore_ascii_case(k.trim())) =>
            {
                Ok(k.trim().to_ascii_lowercase())
            }
            Some(other) => Err(self.invalid(
                line,
                &format!("{key}.kind"),
                format!("must be {}, got {other}", one_of(&CURVE_KINDS)),
            )),
        }
    }

    pub(super) fn points(
        &self,
        items: &[toml::Value],
        key: &str,
        line: usize,
    ) -> Result<Vec<DVec3>, SpecError> {
        items
            .iter()
            .enumerate()
            .map(|(k, it)| match it {
                Value::Array(a) => self.point(a, &format!("{key}[{}]", k + 1), line),
                other => Err(self.invalid(
                    line,
                    &format!("{key}[{}]", k + 1),
                    format!("must be a point [x, y] or [x, y, z], got {other}"),
                )),
            })
            .collect()
    }

    pub(super) fn point(
        &self,
        a: &[toml::Value],
        key: &str,
        line: usize,
    ) -> Result<DVec3, SpecError> {
        let v: Option<Vec<f64>> = a
            .iter()
            .map(|x| match x {
                Value::Integer(i) => Some(*i as f64),
                Value::Float(f) if f.is_finite() => Some(*f),
                _ => None,
            })
            .collect();
        match v {
            Some(v) if v.len() == 2 || v.len() == 3 => {
                Ok(DVec3::new(v[0], v[1], v.get(2).copied().unwrap_or(0.0)))
            }
            _ => Err(self.invalid(
                line,
                key,
                "must be a point of 2 or 3 finite numbers, [x, y] or [x, y, z]".to_string(),
            )),
        }
    }
}

/// The kinds of curve table.
const CURVE_KINDS: [&str; 7] = [
    "points", "csv", "circle", "ellipse", "rect", "bezier", "bspline",
];

/// One curve table of a known `kind`, read key by key with messages that name `{key}.{k}` at
/// the line of the curve.
struct CurveTable<'c, 'a> {
    ctx: &'c Ctx<'a>,
    t: &'c toml::Table,
    key: &'c str,
    line: usize,
    kind: &'c str,
}

impl CurveTable<'_, '_> {
    fn bad(&self, k: &str, msg: String) -> SpecError {
        self.ctx.invalid(self.line, k, msg)
    }

    /// Keys other than `kind` must be among those of the curve's kind.
    fn check_keys(&self) -> Result<(), SpecError> {
        let (key, kind) = (self.key, self.kind);
        let allowed: &[&str] = match kind {
            "points" => &["points", "closed"],
            "csv" => &["path", "closed"],
            "circle" => &["center", "radius", "diameter"],
            "ellipse" => &["center", "rx", "ry"],
            "rect" => &["center", "width", "height", "corner_radius"],
            "bezier" => &["control"],
            _ => &["control", "degree", "closed"],
        };
        for k in self.t.keys() {
            if k != "kind" && !allowed.contains(&k.as_str()) {
                return Err(self.bad(
                    &format!("{key}.{k}"),
                    format!(
                        "unknown key for a {kind} curve; expected {}",
                        one_of(allowed)
                    ),
                ));
            }
        }
        Ok(())
    }

    /// A finite number, if given.
    fn num(&self, k: &str) -> Result<Option<f64>, SpecError> {
        let key = self.key;
        match self.t.get(k) {
            None => Ok(None),
            Some(Value::Integer(i)) => Ok(Some(*i as f64)),
            Some(Value::Float(f)) if f.is_finite() => Ok(Some(*f)),
            Some(other) => Err(self.bad(
                &format!("{key}.{k}"),
                format!("must be a finite number, got {other}"),
            )),
        }
    }

    /// A finite number that must be given.
    fn need(&self, k: &str) -> Result<f64, SpecError> {
        let (key, kind) = (self.key, self.kind);
        self.num(k)?.ok_or_else(|| {
            self.bad(
                &format!("{key}.{k}"),
                format!("missing: a {kind} curve needs `{k}`"),
            )
        })
    }

    /// A list of points that must be given.
    fn list(&self, k: &str) -> Result<Vec<DVec3>, SpecError> {
        let (key, kind) = (self.key, self.kind);
        match self.t.get(k) {
            Some(Value::Array(items)) => self.ctx.points(items, &format!("{key}.{k}"), self.line),
            Some(other) => Err(self.bad(
                &format!("{key}.{k}"),
                format!("must be a list of points [[x, y, z], ...], got {other}"),
            )),
            None => Err(self.bad(
                &format!("{key}.{k}"),
                format!("missing: a {kind} curve needs `{k}`"),
            )),
        }
    }

    /// `closed`, default false.
    fn closed(&self) -> Result<bool, SpecError> {
        match self.t.get("closed") {
            None => Ok(false),
            Some(Value::Boolean(b)) => Ok(*b),
            Some(other) => Err(self.bad(
                &format!("{}.closed", self.key),
                format!("must be true or false, got {other}"),
            )),
        }
    }

    /// `center`, default the origin.
    fn center(&self) -> Result<DVec3, SpecError> {
        match self.t.get("center") {
            None => Ok(DVec3::ZERO),
            Some(Value::Array(a)) => self
                .ctx
                .point(a, &format!("{}.center", self.key), self.line),
            Some(other) => Err(self.bad(
                &format!("{}.center", self.key),
                format!("must be [x, y] or [x, y, z], got {other}"),
            )),
        }
    }

    /// The curve; `closed` and `center` are read first, whatever the kind.
    fn build(&self, dir: &Path) -> Result<Curve, SpecError> {
        let key = self.key;
        let closed = self.closed()?;
        let center = self.center()?;
        Ok(match self.kind {
            "points" => Curve::Points {
                points: self.list("points")?,
                closed,
            },
            "csv" => match self.t.get("path") {
                Some(Value::String(p)) if !p.trim().is_empty() => Curve::Csv {
                    path: dir.join(p),
                    closed,
                },
                _ => return Err(self.bad(
                    &format!("{key}.path"),
                    "must be a non-empty string naming a CSV file, relative to the spec's folder"
                        .into(),
                )),
            },
            "circle" => {
                let radius = match (self.num("radius")?, self.num("diameter")?) {
                    (Some(r), None) => r,
                    (None, Some(d)) => 0.5 * d,
                    _ => {
                        return Err(self.bad(
                            &format!("{key}.radius"),
                            "a circle needs exactly one of `radius` and `diameter`".into(),
                        ))
                    }
                };
                Curve::Circle { center, radius }
            }
            "ellipse" => Curve::Ellipse {
                center,
                rx: self.need("rx")?,
                ry: self.need("ry")?,
            },
            "rect" => Curve::Rect {
                center,
                width: self.need("width")?,
                height: self.need("height")?,
                corner_radius: self.num("corner_radius")?.unwrap_or(0.0),
            },
            "bezier" => Curve::Bezier {
                control: self.list("control")?,
            },
            _ => {
                let degree = match self.num("degree")? {
                    None => 3,
                    Some(d) if (1.0..=10.0).contains(&d) && d.fract() == 0.0 => d as usize,
                    Some(d) => {
                        return Err(self.bad(
                            &format!("{key}.degree"),
                            format!("must be a whole number from 1 to 10, got {d}"),
                        ))
                    }
                };
                Curve::BSpline {
                    control: self.list("control")?,
                    degree,
                    closed,
                }
            }
        })
    }
}
