//! The reader of `kind = "spline"` surfaces (Tang et al. 2016, `surface::spline`): B-spline
//! curves of one degree and control-point count, or one curve and an `apex`, made developable
//! by guided projection, with `creases`, `folds`, `fixed` control points and the solver's
//! settings.
//!
//! Choices: `curves` is a list of inline control-point lists (each curve's line is its own,
//! so a curve with the wrong count is reported where it stands); `folds` takes one entry per
//! interior curve, a name or `{ kind, angle_deg }` (degrees in the file, radians inside);
//! `fixed` takes a curve number
//! (the whole curve), `[curve, point]` (1-based) or `"apex"`; the shape checks of
//! [`crate::surface::spline::model`] (counts, degree, creases on straight curves) run here, so
//! their messages name the line of the key concerned. Mesh, strip and bent-sheet keys are
//! refused, except `outline` and `handles` (with their spline meanings) and `side` and
//! `k_factor` (as strips); `max_iterations` is shared with boundaries (the same meaning).

use super::context::{Ctx, MM_POSITIVE};
use super::spanned::{span, List, RawSurface};
use super::SpecError;
use crate::surface::spline::target::Target;
use crate::surface::spline::{Crease, FoldGoal, SolveOptions, SplineError, SplineSpec};
use crate::surface::{SegmentSpec, SurfaceKind, SurfaceSpec, Units};
use glam::DVec3;
use std::path::Path;
use toml::{Spanned, Value};

/// The default `max_iterations` with a `target`: a fit converges linearly at the end, so it
/// gets more rounds than a solve of constraints alone.
const TARGET_MAX_ITERATIONS: usize = 150;

impl Ctx<'_> {
    /// One `kind = "spline"` entry.
    pub(super) fn spline_surface(
        &self,
        s: &RawSurface,
        key: &str,
        header_line: usize,
        dir: &Path,
    ) -> Result<SurfaceSpec, SpecError> {
        self.no_other_keys_on_spline(s, key)?;
        let k = |name: &str| format!("{key}.{name}");
        let target = self.spline_target(s, key, dir)?;
        let (curves, lines, curves_line) = if s.curves.is_none() && target.is_some() {
            let line = span(&s.target).map_or(header_line, |sp| self.line(sp));
            (Vec::new(), Vec::new(), line)
        } else {
            self.spline_curves(s, key, header_line)?
        };
        let apex = match &s.apex {
            None => None,
            Some(v) => {
                let line = self.line(v.span());
                match v.get_ref() {
                    Value::Array(a) => Some(self.point(a, &k("apex"), line)?),
                    other => {
                        return Err(self.invalid(
                            line,
                            &k("apex"),
                            format!("must be a point [x, y, z], got {other}"),
                        ))
                    }
                }
            }
        };
        let degree = self
            .number(&s.degree, &k("degree"), "2, 3, 4 or 5", |v| {
                v.fract() == 0.0 && (2.0..=5.0).contains(&v)
            })?
            .map_or(3, |(v, _)| v as usize);
        let closed = self.boolean(&s.closed, &k("closed"))?.unwrap_or(false);
        let creases = self.spline_creases(s, key)?;
        let folds = self.spline_folds(s, key)?;
        let fixed = self.spline_fixed(s, key, &curves, apex.is_some())?;
        let handles = self.spline_handles(s, key)?;
        let outline = self.spline_outline(s, key, &curves)?;
        let d = SolveOptions::default();
        let count = |v: &super::context::Opt, name: &str, min: f64| {
            self.number(
                v,
                &k(name),
                &format!("a whole number from {min} to 1000"),
                |x| x.fract() == 0.0 && (min..=1000.0).contains(&x),
            )
        };
        let iterations = count(&s.iterations, "iterations", 0.0)?.map(|(v, _)| v as usize);
        let max_iterations =
            count(&s.max_iterations, "max_iterations", 1.0)?.map(|(v, _)| v as usize);
        let eps = |v: &super::context::Opt, name: &str| {
            self.number(v, &k(name), "a positive number (at most 1e3)", |x| {
                x > 0.0 && x <= 1e3
            })
        };
        let options = SolveOptions {
            iterations: iterations.unwrap_or(d.iterations),
            max_iterations: max_iterations.unwrap_or(if target.is_some() {
                TARGET_MAX_ITERATIONS
            } else {
                d.max_iterations
            }),
            epsilon1: eps(&s.epsilon1, "epsilon1")?.map_or(d.epsilon1, |(v, _)| v),
            epsilon2: eps(&s.epsilon2, "epsilon2")?.map_or(d.epsilon2, |(v, _)| v),
            ..d
        };
        let tolerance = self
            .number(&s.tolerance, &k("tolerance"), MM_POSITIVE, |v| v > 0.0)?
            .map_or(0.05, |(v, _)| v);
        let bend_lines = self.bend_lines(&s.bend_lines, key)?;
        let side = self
            .choice(&s.side, &k("side"), &crate::surface::SheetSide::NAMES)?
            .unwrap_or_default();
        let k_factor = self
            .number(&s.k_factor, &k("k_factor"), "a number from 0 to 1", |v| {
                (0.0..=1.0).contains(&v)
            })?
            .map_or(0.4, |(v, _)| v);
        let spec = SplineSpec {
            sheet: (side, k_factor),
            neutral_offset: 0.0,
            curves,
            apex,
            degree,
            closed,
            fixed,
            creases,
            folds,
            target,
            handles,
            outline,
            options,
            tolerance,
            bend_lines,
        };
        if let Err(SplineError::Shape { key: sub, message }) = crate::surface::spline::model(&spec)
        {
            let line = self.spline_key_line(s, &sub, &lines).unwrap_or(curves_line);
            return Err(self.invalid(line, &k(&sub), message));
        }
        let name = self
            .file_name(&s.name, &k("name"))?
            .unwrap_or_else(|| format!("spline{}", key.trim_start_matches("surface")));
        Ok(SurfaceSpec {
            kind: SurfaceKind::Spline,
            path: self.path.to_path_buf(),
            scale: 1.0,
            units: Units::Mm,
            size: None,
            name,
            line: curves_line,
            strip: None,
            bent: None,
            boundary: None,
            spline: Some(spec),
            segment: SegmentSpec::default(),
        })
    }

    /// `curves`: a list of control-point lists; with each curve's line, and the line of
    /// `curves`.
    #[allow(clippy::type_complexity)]
    fn spline_curves(
        &self,
        s: &RawSurface,
        key: &str,
        header_line: usize,
    ) -> Result<(Vec<Vec<DVec3>>, Vec<usize>, usize), SpecError> {
        let ck = format!("{key}.curves");
        const WHAT: &str =
            "a list of curves, each a list of control points [[x, y, z], ...]: two or more, or one with `apex`";
        let Some(v) = &s.curves else {
            return Err(self.invalid(header_line, &ck, format!("missing: must be {WHAT}")));
        };
        let line = self.line(v.span());
        let items: &Vec<Spanned<Value>> = match v.get_ref() {
            List::Items(items) => items,
            List::Wrong(w) => {
                return Err(self.invalid(line, &ck, format!("must be {WHAT}, got {w}")))
            }
        };
        let mut curves = Vec::with_capacity(items.len());
        let mut lines = Vec::with_capacity(items.len());
        for (i, c) in items.iter().enumerate() {
            let cl = self.line(c.span());
            let key_i = format!("{ck}[{}]", i + 1);
            match c.get_ref() {
                Value::Array(points) => curves.push(self.points(points, &key_i, cl)?),
                other => {
                    return Err(self.invalid(
                        cl,
                        &key_i,
                        format!("must be a list of control points [[x, y, z], ...], got {other}"),
                    ))
                }
            }
            lines.push(cl);
        }
        Ok((curves, lines, line))
    }

    /// `target`: a mesh file (OBJ, STL, PLY, OFF) or a CSV point cloud, as a path or a table
    /// `{ path, scale, units }`, read at its size in millimetres.
    fn spline_target(
        &self,
        s: &RawSurface,
        key: &str,
        dir: &Path,
    ) -> Result<Option<Target>, SpecError> {
        let tk = format!("{key}.target");
        let Some(v) = &s.target else {
            return Ok(None);
        };
        let line = self.line(v.span());
        const WHAT: &str =
            "a file name (a mesh or a CSV point cloud) or a table { path, scale, units }";
        let (path, scale, units) = match v.get_ref() {
            Value::String(p) if !p.trim().is_empty() => (p.clone(), 1.0, Units::Mm),
            Value::Table(t) => {
                if let Some(bad) = t
                    .keys()
                    .find(|k| !matches!(k.as_str(), "path" | "scale" | "units"))
                {
                    return Err(self.invalid(
                        line,
                        &format!("{tk}.{bad}"),
                        "is not a target key; a target takes `path`, `scale` and `units`".into(),
                    ));
                }
                let path = match t.get("path") {
                    Some(Value::String(p)) if !p.trim().is_empty() => p.clone(),
                    other => {
                        return Err(self.invalid(
                            line,
                            &format!("{tk}.path"),
                            match other {
                                None => "missing: a target table needs `path`".into(),
                                Some(o) => format!("must be a file name, got {o}"),
                            },
                        ))
                    }
                };
                let scale = match t.get("scale") {
                    None => 1.0,
                    Some(Value::Integer(i)) if *i > 0 => *i as f64,
                    Some(Value::Float(f)) if f.is_finite() && *f > 0.0 => *f,
                    Some(o) => {
                        return Err(self.invalid(
                            line,
                            &format!("{tk}.scale"),
                            format!("must be a positive number, got {o}"),
                        ))
                    }
                };
                let units = match t.get("units") {
                    None => Units::Mm,
                    Some(Value::String(u)) => super::names::pick(u, &Units::NAMES)
                        .map_err(|m| self.invalid(line, &format!("{tk}.units"), m))?,
                    Some(o) => {
                        return Err(self.invalid(
                            line,
                            &format!("{tk}.units"),
                            format!("must be one of mm, cm, m, in, got {o}"),
                        ))
                    }
                };
                (path, scale, units)
            }
            other => return Err(self.invalid(line, &tk, format!("must be {WHAT}, got {other}"))),
        };
        let file = dir.join(&path);
        let f = scale * units.mm();
        let is_csv = file
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("csv"));
        let target = if is_csv {
            let pts = crate::geom::curve::read_csv(&file)
                .map_err(|e| self.invalid(line, &tk, e.to_string()))?;
            Target::from_points(pts.into_iter().map(|p| p * f).collect())
        } else {
            let mut raw = crate::surface::import::read(&file)
                .map_err(|e| self.invalid(line, &tk, e.to_string()))?;
            raw.mesh.vertices.iter_mut().for_each(|p| *p *= f);
            Target::from_mesh(&raw.mesh)
        };
        if target.points.len() < 3 {
            return Err(self.invalid(
                line,
                &tk,
                format!(
                    "{}: {} usable points; a target needs at least 3",
                    file.display(),
                    target.points.len()
                ),
            ));
        }
        Ok(Some(target))
    }

    /// `handles = [{ at = [x, y, z], to = [x, y, z] }, ...]`: a point of the surface as given
    /// (its nearest point is taken) dragged towards `to`, or with `lift = H` only raised by H
    /// (its x and y left free).
    fn spline_handles(&self, s: &RawSurface, key: &str) -> Result<Vec<(DVec3, DVec3)>, SpecError> {
        let hk = format!("{key}.handles");
        let Some(v) = &s.handles else {
            return Ok(Vec::new());
        };
        let line = self.line(v.span());
        const WHAT: &str = "a list of tables { at = [x, y, z], to = [x, y, z] }";
        let Value::Array(items) = v.get_ref() else {
            return Err(self.invalid(line, &hk, format!("must be {WHAT}, got {}", v.get_ref())));
        };
        let mut out = Vec::new();
        for (i, it) in items.iter().enumerate() {
            let ik = format!("{hk}[{}]", i + 1);
            let Value::Table(t) = it else {
                return Err(self.invalid(
                    line,
                    &ik,
                    format!("must be a table {{ at = [x, y, z], to = [x, y, z] }}, got {it}"),
                ));
            };
            if let Some(bad) = t
                .keys()
                .find(|k| !matches!(k.as_str(), "at" | "to" | "lift"))
            {
                return Err(self.invalid(
                    line,
                    &format!("{ik}.{bad}"),
                    "is not a handle key; a handle takes `at` and `to` or `lift`".into(),
                ));
            }
            let pt = |name: &str| -> Result<DVec3, SpecError> {
                match t.get(name) {
                    Some(Value::Array(a)) => self.point(a, &format!("{ik}.{name}"), line),
                    Some(o) => Err(self.invalid(
                        line,
                        &format!("{ik}.{name}"),
                        format!("must be a point [x, y, z], got {o}"),
                    )),
                    None => Err(self.invalid(
                        line,
                        &format!("{ik}.{name}"),
                        "missing: a handle needs `at` and `to`".into(),
                    )),
                }
            };
            let at = pt("at")?;
            match (t.get("to"), t.get("lift")) {
                (Some(_), Some(_)) => {
                    return Err(self.invalid(
                        line,
                        &format!("{ik}.lift"),
                        "a handle takes `to` or `lift`, not both".into(),
                    ))
                }
                (None, Some(v)) => {
                    let lift = match v {
                        Value::Integer(i) => *i as f64,
                        Value::Float(f) if f.is_finite() => *f,
                        o => {
                            return Err(self.invalid(
                                line,
                                &format!("{ik}.lift"),
                                format!("must be a height in mm, got {o}"),
                            ))
                        }
                    };
                    out.push((at, DVec3::new(f64::NAN, f64::NAN, at.z + lift)));
                }
                _ => out.push((at, pt("to")?)),
            }
        }
        Ok(out)
    }

    /// `outline`: the flat sheet the surface stays isometric to, `[width, height]` from the
    /// origin or a list of `[x, y]` points, in the plane z = 0 where every curve must start.
    fn spline_outline(
        &self,
        s: &RawSurface,
        key: &str,
        curves: &[Vec<DVec3>],
    ) -> Result<Option<Vec<glam::DVec2>>, SpecError> {
        use glam::DVec2;
        let ok = format!("{key}.outline");
        let Some(v) = &s.outline else {
            return Ok(None);
        };
        let line = self.line(v.span());
        let num = |x: &Value| match x {
            Value::Integer(i) => Some(*i as f64),
            Value::Float(f) if f.is_finite() => Some(*f),
            _ => None,
        };
        let poly: Vec<DVec2> = match v.get_ref() {
            Value::Array(a) if a.len() == 2 && a.iter().all(|x| num(x).is_some()) => {
                let (w, h) = (num(&a[0]).unwrap_or(0.0), num(&a[1]).unwrap_or(0.0));
                if !(w > 0.0 && h > 0.0) {
                    return Err(self.invalid(
                        line,
                        &ok,
                        format!("the sheet must have a positive width and height, got {w} x {h}"),
                    ));
                }
                vec![
                    DVec2::ZERO,
                    DVec2::new(w, 0.0),
                    DVec2::new(w, h),
                    DVec2::new(0.0, h),
                ]
            }
            Value::Array(a) if a.len() >= 3 => self
                .points(a, &ok, line)?
                .into_iter()
                .map(|p| p.truncate())
                .collect(),
            other => {
                return Err(self.invalid(
                    line,
                    &ok,
                    format!(
                    "must be [width, height] or a list of three or more [x, y] points, got {other}"
                ),
                ))
            }
        };
        if curves.is_empty() {
            return Err(self.invalid(line, &ok, "needs `curves` drawn on the flat sheet".into()));
        }
        for (c, curve) in curves.iter().enumerate() {
            for (i, p) in curve.iter().enumerate() {
                if p.z.abs() > 1e-6 || !inside(&poly, p.truncate()) {
                    return Err(self.invalid(line, &ok, format!(
                        "control point {} of curve {} ({}, {}, {}) is not on the flat sheet: with an outline, every curve starts in the plane z = 0 inside it",
                        i + 1, c + 1, p.x, p.y, p.z
                    )));
                }
            }
        }
        Ok(Some(poly))
    }

    /// `creases`: one name per interior curve.
    fn spline_creases(&self, s: &RawSurface, key: &str) -> Result<Vec<Crease>, SpecError> {
        let ck = format!("{key}.creases");
        let Some(v) = &s.creases else {
            return Ok(Vec::new());
        };
        let line = self.line(v.span());
        let names: Vec<&str> = Crease::NAMES.iter().map(|(n, _)| *n).collect();
        let expected = format!(
            "a list with one of {} per interior curve",
            super::names::one_of(&names)
        );
        let Value::Array(items) = v.get_ref() else {
            return Err(self.invalid(
                line,
                &ck,
                format!("must be {expected}, got {}", v.get_ref()),
            ));
        };
        items
            .iter()
            .enumerate()
            .map(|(i, it)| {
                let found = match it {
                    Value::String(t) => super::names::pick(t, &Crease::NAMES).ok(),
                    _ => None,
                };
                found.ok_or_else(|| {
                    self.invalid(
                        line,
                        &format!("{ck}[{}]", i + 1),
                        format!("must be {}, got {it}", super::names::one_of(&names)),
                    )
                })
            })
            .collect()
    }

    /// `folds`: per interior curve `"mountain"`, `"valley"`, `"none"` or
    /// `{ kind = "mountain" | "valley", angle_deg = A }` (the mean fold angle, degrees).
    fn spline_folds(&self, s: &RawSurface, key: &str) -> Result<Vec<Option<FoldGoal>>, SpecError> {
        let fk = format!("{key}.folds");
        let Some(v) = &s.folds else {
            return Ok(Vec::new());
        };
        let line = self.line(v.span());
        let expected = "\"mountain\", \"valley\", \"none\" or { kind = \"mountain\" or \"valley\", angle_deg = the mean fold angle in degrees, more than 0 and less than 180 }";
        let Value::Array(items) = v.get_ref() else {
            return Err(self.invalid(
                line,
                &fk,
                format!(
                    "must be a list with one of {expected} per interior curve, got {}",
                    v.get_ref()
                ),
            ));
        };
        items
            .iter()
            .enumerate()
            .map(|(i, it)| {
                let bad = |what: String| self.invalid(line, &format!("{fk}[{}]", i + 1), what);
                match it {
                    Value::String(t) => super::names::pick(t, &FOLD_KINDS)
                        .map(|k| {
                            k.map(|valley| FoldGoal {
                                valley,
                                angle: None,
                            })
                        })
                        .map_err(|_| bad(format!("must be {expected}, got {it}"))),
                    Value::Table(t) => fold_table(t).map(Some).map_err(bad),
                    _ => Err(bad(format!("must be {expected}, got {it}"))),
                }
            })
            .collect()
    }

    /// `fixed`: curve numbers, `[curve, point]` pairs (1-based) or `"apex"`, as 0-based
    /// (curve, point) pairs; curve `curves.len()` is the apex. A pair out of range is left to
    /// the shape check.
    fn spline_fixed(
        &self,
        s: &RawSurface,
        key: &str,
        curves: &[Vec<DVec3>],
        has_apex: bool,
    ) -> Result<Vec<(usize, usize)>, SpecError> {
        let n_curves = curves.len();
        let fk = format!("{key}.fixed");
        let Some(v) = &s.fixed else {
            return Ok(Vec::new());
        };
        let line = self.line(v.span());
        const WHAT: &str =
            "a list of curve numbers (the whole curve), [curve, point] pairs counted from 1, or \"apex\"";
        let Value::Array(items) = v.get_ref() else {
            return Err(self.invalid(line, &fk, format!("must be {WHAT}, got {}", v.get_ref())));
        };
        let whole = |x: &Value| match x {
            Value::Integer(i) if *i >= 1 => Some(*i as usize - 1),
            _ => None,
        };
        let mut out = Vec::new();
        for (i, it) in items.iter().enumerate() {
            let bad = || {
                self.invalid(
                    line,
                    &format!("{fk}[{}]", i + 1),
                    format!(
                        "must be a curve number, [curve, point] (from 1) or \"apex\", got {it}"
                    ),
                )
            };
            match it {
                Value::String(t) if t.trim().eq_ignore_ascii_case("apex") => {
                    if !has_apex {
                        return Err(self.invalid(
                            line,
                            &format!("{fk}[{}]", i + 1),
                            "names the apex, but the surface has no `apex`".into(),
                        ));
                    }
                    out.push((n_curves, 0));
                }
                Value::Integer(_) => {
                    let c = whole(it).ok_or_else(bad)?;
                    if c >= n_curves {
                        return Err(self.invalid(
                            line,
                            &format!("{fk}[{}]", i + 1),
                            format!(
                                "curve {} does not exist: there are {n_curves} curves",
                                c + 1
                            ),
                        ));
                    }
                    out.extend((0..curves[c].len()).map(|p| (c, p)));
                }
                Value::Array(pair) if pair.len() == 2 => {
                    let (c, p) = (
                        whole(&pair[0]).ok_or_else(bad)?,
                        whole(&pair[1]).ok_or_else(bad)?,
                    );
                    out.push((c, p));
                }
                _ => return Err(bad()),
            }
        }
        Ok(out)
    }

    /// The line of a spline key named by a shape error (`curves[2]`, `creases[1]`, ...).
    fn spline_key_line(&self, s: &RawSurface, sub: &str, lines: &[usize]) -> Option<usize> {
        let base = sub.split('[').next().unwrap_or(sub);
        let index = sub
            .split('[')
            .nth(1)
            .and_then(|t| t.trim_end_matches(']').parse::<usize>().ok());
        match base {
            "curves" => index.and_then(|i| lines.get(i.checked_sub(1)?).copied()),
            "creases" => span(&s.creases).map(|sp| self.line(sp)),
            "folds" => span(&s.folds).map(|sp| self.line(sp)),
            "fixed" => span(&s.fixed).map(|sp| self.line(sp)),
            "apex" => span(&s.apex).map(|sp| self.line(sp)),
            "degree" => span(&s.degree).map(|sp| self.line(sp)),
            "target" => span(&s.target).map(|sp| self.line(sp)),
            "closed" => span(&s.closed).map(|sp| self.line(sp)),
            _ => None,
        }
    }

    /// Keys of other kinds on a spline are mistakes (`outline` and `handles` of bent sheets
    /// and `max_iterations` of boundaries are the spline's own, `side` and `k_factor` as
    /// strips).
    fn no_other_keys_on_spline(&self, s: &RawSurface, key: &str) -> Result<(), SpecError> {
        const WHY: &str = "is not a spline key; a spline takes `curves` (and `apex`), `target`, `handles`, `outline`, `degree`, `closed`, `side`, `k_factor`, `creases`, `folds`, `fixed`, `iterations`, `max_iterations`, `epsilon1`, `epsilon2`, `tolerance` and `bend_lines`";
        self.no_mesh_keys(s, key, WHY)?;
        self.refuse(
            key,
            &[
                ("p", span(&s.p)),
                ("q", span(&s.q)),
                ("method", span(&s.method)),
            ],
            WHY,
        )?;
        self.no_bent_keys(s, key, &["outline", "handles"])?;
        self.no_boundary_keys(s, key, &["max_iterations"])
    }
}

impl Ctx<'_> {
    /// Keys only a spline takes are errors on other kinds.
    pub(super) fn no_spline_keys(&self, s: &RawSurface, key: &str) -> Result<(), SpecError> {
        self.refuse(
            key,
            &[
                ("curves", span(&s.curves)),
                ("apex", span(&s.apex)),
                ("degree", span(&s.degree)),
                ("closed", span(&s.closed)),
                ("creases", span(&s.creases)),
                ("folds", span(&s.folds)),
                ("fixed", span(&s.fixed)),
                ("iterations", span(&s.iterations)),
                ("epsilon1", span(&s.epsilon1)),
                ("epsilon2", span(&s.epsilon2)),
                ("target", span(&s.target)),
            ],
            "is for spline surfaces (kind = \"spline\")",
        )
    }
}

/// The names of `folds` entries: a direction, or none.
const FOLD_KINDS: [(&str, Option<bool>); 3] = [
    ("mountain", Some(false)),
    ("valley", Some(true)),
    ("none", None),
];

/// A `folds` entry written as `{ kind = "mountain" | "valley", angle_deg = A }`; the error
/// says what is wrong with it.
fn fold_table(t: &toml::map::Map<String, Value>) -> Result<FoldGoal, String> {
    if let Some(extra) = t
        .keys()
        .find(|k| !["kind", "angle_deg"].contains(&k.as_str()))
    {
        return Err(format!(
            "`{extra}` is not a key of a fold; it takes `kind` and `angle_deg`"
        ));
    }
    let kind = t.get("kind");
    let valley = kind
        .and_then(Value::as_str)
        .and_then(|k| super::names::pick(k, &FOLD_KINDS).ok())
        .flatten()
        .ok_or_else(|| {
            format!(
                "`kind` must be \"mountain\" or \"valley\", got {}",
                kind.map_or("nothing".into(), Value::to_string)
            )
        })?;
    let angle = match t.get("angle_deg") {
        None => None,
        Some(a) => match a.as_float().or(a.as_integer().map(|i| i as f64)) {
            Some(d) if d > 0.0 && d < 180.0 => Some(d.to_radians()),
            _ => {
                return Err(format!(
                    "`angle_deg` must be more than 0 and less than 180 (degrees), got {a}"
                ))
            }
        },
    };
    Ok(FoldGoal { valley, angle })
}

/// Whether `p` lies inside or on the polygon (edges within 1e-6 count).
fn inside(poly: &[glam::DVec2], p: glam::DVec2) -> bool {
    use crate::geom::polygon::{contains, segment_distance};
    let n = poly.len();
    (0..n).any(|i| segment_distance(p, poly[i], poly[(i + 1) % n]) <= 1e-6) || contains(poly, p)
}
