//! The reader of `kind = "boundary"` surfaces: the developable boundary triangulation of closed
//! 3D polylines (Rose et al., `surface::boundary`). Reads the loops (`loop`, `loop_csv` or
//! `loops`), `darts`, `rulings` and the search settings into a
//! [`crate::surface::BoundarySpec`], and checks the loops with [`boundary::check`] so that a
//! bad loop is reported at its line.
//!
//! Choices: loops are closed (an inline list closes by itself, and a last point equal to the
//! first is dropped; a curve table must say `closed = true`); point lists and CSV files are
//! taken as given, other curves are sampled at `tolerance`; `smooth` resamples a closed cubic
//! B-spline through the points and cannot be combined with darts or rulings, which name
//! points; loop, point and dart numbers are counted from 1 in the file and 0-based inside.

use super::context::{Ctx, MM_POSITIVE};
use super::spanned::{span, RawSurface};
use super::SpecError;
use crate::surface::boundary::{self, BoundaryError, Dart, Input, Options};
use crate::surface::{BoundarySpec, SegmentSpec, SurfaceKind, SurfaceSpec, Units};
use glam::DVec3;
use std::path::Path;
use toml::Value;

/// A loop as read, before sampling: its value, its dotted key and its line.
type RawLoop = (Value, String, usize);

/// A ruling's two ends, (loop, point) each, 0-based.
type Ruling = [(usize, usize); 2];

impl Ctx<'_> {
    /// One `kind = "boundary"` entry.
    pub(super) fn boundary_surface(
        &self,
        s: &RawSurface,
        key: &str,
        header_line: usize,
        dir: &Path,
    ) -> Result<SurfaceSpec, SpecError> {
        self.no_other_keys_on_boundary(s, key)?;
        let tolerance = self
            .number(
                &s.tolerance,
                &format!("{key}.tolerance"),
                MM_POSITIVE,
                |v| v > 0.0,
            )?
            .map_or(0.5, |(v, _)| v);
        let smooth = self
            .boolean(&s.smooth, &format!("{key}.smooth"))?
            .unwrap_or(false);
        let options = self.boundary_options(s, key)?;
        let raw_loops = self.boundary_raw_loops(s, key, header_line)?;
        let mut loops = Vec::new();
        for (v, k, line) in &raw_loops {
            loops.push(self.boundary_loop(v, k, *line, dir, tolerance, smooth)?);
        }
        let (darts, darts_line) = self.boundary_darts(s, key, header_line, loops.len())?;
        let (rulings, rulings_line) = self.boundary_rulings(s, key, header_line)?;
        if smooth && (!darts.is_empty() || !rulings.is_empty()) {
            return Err(self.invalid(
                header_line,
                &format!("{key}.smooth"),
                "darts and rulings name points of the loop, which smoothing resamples: use one or the other".into(),
            ));
        }
        let input = Input {
            loops,
            darts,
            rulings,
        };
        if let Err(e) = boundary::check(&input) {
            let (line, k) = match &e {
                BoundaryError::Ruling { .. } => (rulings_line, format!("{key}.rulings")),
                BoundaryError::Dart { .. } => (darts_line, format!("{key}.darts")),
                BoundaryError::TooFew { looop, .. }
                | BoundaryError::NonFinite { looop, .. }
                | BoundaryError::Repeated { looop, .. }
                | BoundaryError::Open { looop } => at_loop(&raw_loops, *looop, key, header_line),
                BoundaryError::SelfIntersecting { la, .. } => {
                    at_loop(&raw_loops, *la, key, header_line)
                }
                BoundaryError::NoLoop
                | BoundaryError::Loops(_)
                | BoundaryError::NoTriangulation => (header_line, format!("{key}.loops")),
            };
            return Err(self.invalid(line, &k, e.to_string()));
        }
        let name = self
            .file_name(&s.name, &format!("{key}.name"))?
            .unwrap_or_else(|| format!("boundary{}", key.trim_start_matches("surface")));
        Ok(SurfaceSpec {
            kind: SurfaceKind::Boundary,
            path: self.path.to_path_buf(),
            scale: 1.0,
            units: Units::Mm,
            size: None,
            name,
            line: raw_loops.first().map_or(header_line, |r| r.2),
            strip: None,
            bent: None,
            boundary: Some(BoundarySpec { input, options }),
            spline: None,
            segment: SegmentSpec::default(),
        })
    }

    /// Mesh and strip keys on a boundary are mistakes.
    fn no_other_keys_on_boundary(&self, s: &RawSurface, key: &str) -> Result<(), SpecError> {
        let other = [
            ("path", s.path.as_ref().map(|v| v.span())),
            ("scale", s.scale.as_ref().map(|v| v.span())),
            ("units", s.units.as_ref().map(|v| v.span())),
            ("method", s.method.as_ref().map(|v| v.span())),
            ("bend_lines", s.bend_lines.as_ref().map(|v| v.span())),
            ("p", s.p.as_ref().map(|v| v.span())),
            ("q", s.q.as_ref().map(|v| v.span())),
        ];
        for (k, span) in other {
            if let Some(span) = span {
                return Err(self.invalid(
                    self.line(span),
                    &format!("{key}.{k}"),
                    "is not a boundary key; a boundary takes `loop`, `loop_csv` or `loops`"
                        .to_string(),
                ));
            }
        }
        Ok(())
    }

    /// The search settings: `max_dihedral`, `min_chart_area`, `max_iterations`,
    /// `good_interior`, `good_fairness`, on top of the defaults.
    fn boundary_options(&self, s: &RawSurface, key: &str) -> Result<Options, SpecError> {
        let mut options = Options::default();
        if let Some((v, _)) = self.number(
            &s.max_dihedral,
            &format!("{key}.max_dihedral"),
            "an angle in degrees, more than 0 and at most 180",
            |v| v > 0.0 && v <= 180.0,
        )? {
            options.max_dihedral_deg = v;
        }
        if let Some((v, _)) = self.number(
            &s.min_chart_area,
            &format!("{key}.min_chart_area"),
            "a percentage of the hull's area, from 0 to less than 100",
            |v| (0.0..100.0).contains(&v),
        )? {
            options.min_chart_area = v / 100.0;
        }
        if let Some((v, _)) = self.number(
            &s.max_iterations,
            &format!("{key}.max_iterations"),
            "a whole number, 1 or more",
            |v| v >= 1.0 && v.fract() == 0.0 && v <= 1e9,
        )? {
            options.max_iterations = v as usize;
        }
        if let Some((v, _)) = self.number(
            &s.good_interior,
            &format!("{key}.good_interior"),
            "a whole number of interior triangles, 0 or more",
            |v| v >= 0.0 && v.fract() == 0.0 && v <= 1e9,
        )? {
            options.good_interior = v as usize;
        }
        if let Some((v, _)) = self.number(
            &s.good_fairness,
            &format!("{key}.good_fairness"),
            "a sum of squared angles in radians², 0 or more",
            |v| v >= 0.0,
        )? {
            options.good_fairness = v;
        }
        Ok(options)
    }

    /// The loops as given: exactly one of `loop`, `loop_csv` (as a closed `csv` curve) and
    /// `loops` (one entry each).
    fn boundary_raw_loops(
        &self,
        s: &RawSurface,
        key: &str,
        header_line: usize,
    ) -> Result<Vec<RawLoop>, SpecError> {
        let mut raw_loops: Vec<RawLoop> = Vec::new();
        let given = [s.loop_.is_some(), s.loop_csv.is_some(), s.loops.is_some()];
        if given.iter().filter(|g| **g).count() != 1 {
            return Err(self.invalid(
                header_line,
                &format!("{key}.loop"),
                "a boundary needs exactly one of `loop` (points or a closed curve), `loop_csv` (a CSV file) or `loops` (a list of loops, the first the outer one)".to_string(),
            ));
        }
        if let Some(v) = &s.loop_ {
            raw_loops.push((
                v.get_ref().clone(),
                format!("{key}.loop"),
                self.line(v.span()),
            ));
        }
        if let Some(v) = &s.loop_csv {
            let k = format!("{key}.loop_csv");
            let path = self
                .string(
                    &s.loop_csv,
                    &k,
                    "a non-empty string naming a CSV file of x,y,z points",
                )?
                .unwrap_or_default();
            let mut t = toml::map::Map::new();
            t.insert("kind".into(), Value::String("csv".into()));
            t.insert("path".into(), Value::String(path));
            t.insert("closed".into(), Value::Boolean(true));
            raw_loops.push((Value::Table(t), k, self.line(v.span())));
        }
        if let Some(v) = &s.loops {
            let k = format!("{key}.loops");
            let line = self.line(v.span());
            match v.get_ref() {
                Value::Array(items) if !items.is_empty() => {
                    for (i, it) in items.iter().enumerate() {
                        raw_loops.push((it.clone(), format!("{k}[{}]", i + 1), line));
                    }
                }
                other => {
                    return Err(self.invalid(
                        line,
                        &k,
                        format!("must be a non-empty list of loops, got {other}"),
                    ))
                }
            }
        }
        Ok(raw_loops)
    }

    /// `darts` (on `n_loops` loops), 0-based, and the line of `darts` (of the entry when it
    /// has none).
    fn boundary_darts(
        &self,
        s: &RawSurface,
        key: &str,
        header_line: usize,
        n_loops: usize,
    ) -> Result<(Vec<Dart>, usize), SpecError> {
        let mut darts = Vec::new();
        let Some(v) = &s.darts else {
            return Ok((darts, header_line));
        };
        let darts_line = self.line(v.span());
        let k = format!("{key}.darts");
        let Value::Array(items) = v.get_ref() else {
            return Err(self.invalid(
                darts_line,
                &k,
                "must be a list of tables { at = N, points = [[x, y, z], ...] }".into(),
            ));
        };
        for (i, it) in items.iter().enumerate() {
            let dk = format!("{k}[{}]", i + 1);
            darts.push(self.boundary_dart(it, &dk, darts_line, n_loops)?);
        }
        Ok((darts, darts_line))
    }

    /// One entry of `darts`: `{ at, points, width, loop }`, numbers from 1 made 0-based.
    fn boundary_dart(
        &self,
        it: &Value,
        dk: &str,
        darts_line: usize,
        n_loops: usize,
    ) -> Result<Dart, SpecError> {
        let bad = |m: &str| self.invalid(darts_line, dk, m.to_string());
        let Value::Table(t) = it else {
            return Err(bad("must be a table { at = N, points = [[x, y, z], ...] }"));
        };
        for name in t.keys() {
            if !["at", "points", "width", "loop"].contains(&name.as_str()) {
                return Err(self.invalid(
                    darts_line,
                    &format!("{dk}.{name}"),
                    "unknown key; expected one of at, points, width, loop".into(),
                ));
            }
        }
        let looop = match t.get("loop") {
            None => 0,
            Some(Value::Integer(n)) if *n >= 1 && (*n as usize) <= n_loops => (*n - 1) as usize,
            Some(_) => {
                return Err(bad(&format!(
                    "`loop` must be the number (from 1) of the loop the dart is on, at most {}",
                    n_loops
                )))
            }
        };
        let at = match t.get("at") {
            Some(Value::Integer(n)) if *n >= 1 => (*n - 1) as usize,
            _ => {
                return Err(bad(
                    "`at` must be the number (from 1) of the loop point the dart starts at",
                ))
            }
        };
        let points = match t.get("points") {
            Some(Value::Array(p)) => self.points(p, &format!("{dk}.points"), darts_line)?,
            _ => {
                return Err(bad(
                    "`points` must be the dart's points [[x, y, z], ...], ending at its tip",
                ))
            }
        };
        let width = match t.get("width") {
            None => None,
            Some(Value::Integer(n)) if *n > 0 => Some(*n as f64),
            Some(Value::Float(f)) if f.is_finite() && *f > 0.0 => Some(*f),
            Some(_) => return Err(bad("`width` must be a positive number of millimetres")),
        };
        Ok(Dart {
            looop,
            at,
            points,
            width,
        })
    }

    /// `rulings` as (loop, point) pairs, 0-based, and the line of `rulings` (of the entry when
    /// it has none).
    fn boundary_rulings(
        &self,
        s: &RawSurface,
        key: &str,
        header_line: usize,
    ) -> Result<(Vec<Ruling>, usize), SpecError> {
        let mut rulings = Vec::new();
        let Some(v) = &s.rulings else {
            return Ok((rulings, header_line));
        };
        let rulings_line = self.line(v.span());
        let k = format!("{key}.rulings");
        let msg =
            "must be a list of point-number pairs [[i, j], ...] (points of the first loop, from 1) or [[loop, i], [loop, j]] pairs (loops and points from 1)";
        let Value::Array(items) = v.get_ref() else {
            return Err(self.invalid(rulings_line, &k, msg.into()));
        };
        let num = |x: &Value| match x {
            Value::Integer(n) if *n >= 1 => Some((*n - 1) as usize),
            _ => None,
        };
        let end = |x: &Value| match x {
            Value::Integer(_) => num(x).map(|i| (0, i)),
            Value::Array(p) if p.len() == 2 => num(&p[0]).zip(num(&p[1])),
            _ => None,
        };
        for (i, it) in items.iter().enumerate() {
            match it {
                Value::Array(a)
                    if a.len() == 2
                        && end(&a[0]).is_some()
                        && end(&a[1]).is_some()
                        && matches!(a[0], Value::Integer(_))
                            == matches!(a[1], Value::Integer(_)) =>
                {
                    if let (Some(x), Some(y)) = (end(&a[0]), end(&a[1])) {
                        rulings.push([x, y]);
                    }
                }
                _ => {
                    return Err(self.invalid(rulings_line, &format!("{k}[{}]", i + 1), msg.into()))
                }
            }
        }
        Ok((rulings, rulings_line))
    }

    /// Keys only a boundary takes are errors on other kinds (but those in `except`, which the
    /// kind takes with its own meaning).
    pub(super) fn no_boundary_keys(
        &self,
        s: &RawSurface,
        key: &str,
        except: &[&str],
    ) -> Result<(), SpecError> {
        self.refuse_except(
            key,
            &[
                ("loop", span(&s.loop_)),
                ("loop_csv", span(&s.loop_csv)),
                ("loops", span(&s.loops)),
                ("darts", span(&s.darts)),
                ("rulings", span(&s.rulings)),
                ("max_dihedral", span(&s.max_dihedral)),
                ("min_chart_area", span(&s.min_chart_area)),
                ("max_iterations", span(&s.max_iterations)),
                ("smooth", span(&s.smooth)),
                ("good_interior", span(&s.good_interior)),
                ("good_fairness", span(&s.good_fairness)),
            ],
            except,
            "is for boundary surfaces (kind = \"boundary\")",
        )
    }

    /// One boundary loop: an inline list of points (closed; a last point equal to the first is
    /// dropped) or a curve table that must be closed. Point lists and CSV files are taken as
    /// given (repeated points are errors, not dropped); other curves are sampled at `tol`;
    /// `smooth` resamples a closed cubic B-spline on the points (§7).
    fn boundary_loop(
        &self,
        v: &Value,
        key: &str,
        line: usize,
        dir: &Path,
        tol: f64,
        smooth: bool,
    ) -> Result<Vec<DVec3>, SpecError> {
        use crate::geom::curve::Curve;
        let c = match (v, self.curve(v, key, line, dir)?) {
            (Value::Array(_), Curve::Points { points, .. }) => Curve::Points {
                points,
                closed: true,
            },
            (_, c) => c,
        };
        if !c.is_closed() {
            return Err(self.invalid(
                line,
                key,
                "is an open polyline: a boundary must be a closed loop (`closed = true`, or an inline list of points, which is closed)".into(),
            ));
        }
        let drop_closing = |mut p: Vec<DVec3>| {
            if p.len() > 3 && p.first() == p.last() {
                p.pop();
            }
            p
        };
        let mut pts = match &c {
            Curve::Points { points, .. } => drop_closing(points.clone()),
            Curve::Csv { path, .. } => drop_closing(
                crate::geom::curve::read_csv(path)
                    .map_err(|e| self.invalid(line, key, e.to_string()))?,
            ),
            other => {
                other
                    .sample(tol)
                    .map_err(|e| self.invalid(line, key, e.to_string()))?
                    .points
            }
        };
        if smooth && pts.len() >= 4 {
            pts = Curve::BSpline {
                control: pts,
                degree: 3,
                closed: true,
            }
            .sample(tol)
            .map_err(|e| self.invalid(line, key, e.to_string()))?
            .points;
        }
        Ok(pts)
    }
}

/// The line and key of loop `l` (0-based, as [`BoundaryError`] counts them); the
/// entry's header and key when there is no such loop.
fn at_loop(raw_loops: &[RawLoop], l: usize, key: &str, header_line: usize) -> (usize, String) {
    raw_loops
        .get(l)
        .map_or((header_line, key.to_string()), |r| (r.2, r.1.clone()))
}
