//! The reader of `kind = "bent-sheet"` surfaces: a flat sheet bent along a control curve
//! (Bo–Wang, `surface::geodesic`). Reads the sheet's `outline` and `holes`, the curve on the
//! sheet of each bent piece (`line`, `arc` or `flat_curve`), its control curve
//! (`control_points` or `handles`) and `length_fit`, or a list of such `pieces`, into a
//! [`crate::surface::geodesic::BentSpec`].
//!
//! ```toml
//! [[surface]]
//! kind = "bent-sheet"
//! outline = [210, 297]              # width × height from (0, 0), or [[x, y], ...]
//! holes = [[[80, 120], [130, 120], [130, 170], [80, 170]]]   # optional
//! line = [[105, 0], [105, 297]]     # a straight line on the sheet, start to end, or
//! arc = { center = [105, 0], radius = 150, start_deg = 60, end_deg = 120 }   # an arc, or
//! flat_curve = [[0, 40], [50, 48], [110, 32], [160, 40]]   # a Bézier on the sheet (§5)
//! control_points = [[0, 0, 0], [0, 100, 60], [0, 200, -60], [0, 297, 0]]   # a Bézier, or
//! control_points = { kind = "bspline", control = [...], degree = 3 }
//! handles = { start = [0, 0, 0], start_normal = [0, 0, 1], end = [0, 250, 0], end_normal = [0, 0, 1] }
//! length_fit = "scale"              # or "trim" (§4.1.3)
//! tolerance = 0.05                  # mm
//! bend_lines = "all"                # "none" or a spacing in mm
//! pieces = [{ line = ..., control_points = ... }, ...]   # several curved pieces instead
//! ```
//!
//! Choices: mesh and strip keys are refused on a bent sheet, and piece keys at the top level
//! when `pieces` is given; the surface's line is that of `line`, `arc` or `flat_curve` (or of
//! `pieces`), where errors about the geometry point; the sheet is named `sheet[K]` after its
//! entry when it has no `name`.

use super::context::{Ctx, MM_POSITIVE};
use super::names::{one_of, pick};
use super::spanned::{span, RawSurface};
use super::SpecError;
use crate::geom::curve::Curve;
use crate::surface::geodesic::{BentSpec, Control, FlatPath, LengthFit, PieceSpec, Spline};
use crate::surface::{SegmentSpec, SurfaceKind, SurfaceSpec, Units};
use glam::{DVec2, DVec3};
use std::path::Path;
use toml::Value;

impl Ctx<'_> {
    /// Keys only a bent sheet takes are errors on other kinds (but those in `except`, which
    /// the kind takes with its own meaning).
    pub(super) fn no_bent_keys(
        &self,
        s: &RawSurface,
        key: &str,
        except: &[&str],
    ) -> Result<(), SpecError> {
        self.refuse_except(
            key,
            &[
                ("outline", span(&s.outline)),
                ("holes", span(&s.holes)),
                ("line", span(&s.line)),
                ("arc", span(&s.arc)),
                ("flat_curve", span(&s.flat_curve)),
                ("control_points", span(&s.control_points)),
                ("handles", span(&s.handles)),
                ("length_fit", span(&s.length_fit)),
                ("pieces", span(&s.pieces)),
            ],
            except,
            "is for bent sheets (kind = \"bent-sheet\")",
        )
    }

    /// A 2D point `[x, y]`.
    fn pt2(&self, v: &Value, key: &str, line: usize) -> Result<DVec2, SpecError> {
        let nums: Option<Vec<f64>> = match v {
            Value::Array(a) => a
                .iter()
                .map(|x| match x {
                    Value::Integer(i) => Some(*i as f64),
                    Value::Float(f) if f.is_finite() => Some(*f),
                    _ => None,
                })
                .collect(),
            _ => None,
        };
        match nums {
            Some(n) if n.len() == 2 => Ok(DVec2::new(n[0], n[1])),
            _ => Err(self.invalid(
                line,
                key,
                format!("must be a point on the sheet [x, y] of finite numbers (mm), got {v}"),
            )),
        }
    }

    /// A list of 2D points with at least `min` entries.
    fn pts2(&self, v: &Value, key: &str, line: usize, min: usize) -> Result<Vec<DVec2>, SpecError> {
        let Value::Array(items) = v else {
            return Err(self.invalid(
                line,
                key,
                format!(
                    "must be a list of points [[x, y], ...], got {}",
                    v.type_str()
                ),
            ));
        };
        if items.len() < min {
            return Err(self.invalid(
                line,
                key,
                format!("needs at least {min} points, got {}", items.len()),
            ));
        }
        items
            .iter()
            .enumerate()
            .map(|(i, it)| self.pt2(it, &format!("{key}[{}]", i + 1), line))
            .collect()
    }

    /// The curve on the sheet of one bent piece: exactly one of `line` (two points), `arc`
    /// (`{ center, radius, start_deg, end_deg }`) and `flat_curve` (Bézier control points
    /// `[[x, y], ...]` or `{ kind = "bezier" | "bspline", control, degree }`).
    fn flat_path(
        &self,
        pk: &str,
        [line, arc, curve]: [Option<&Value>; 3],
        at: usize,
    ) -> Result<FlatPath, SpecError> {
        match (line, arc, curve) {
            (Some(lv), None, None) => self.flat_line(pk, lv, at),
            (None, Some(av), None) => self.flat_arc(pk, av, at),
            (None, None, Some(cv)) => self.flat_curve(pk, cv, at),
            (None, None, None) => Err(self.invalid(
                at,
                &format!("{pk}line"),
                "missing: the curve on the sheet the control curve bends: `line = [[x0, y0], [x1, y1]]`, `arc = { center = [x, y], radius, start_deg, end_deg }` or `flat_curve = [[x, y], ...]`".to_string(),
            )),
            _ => Err(self.invalid(
                at,
                &format!("{pk}line"),
                "give exactly one of `line`, `arc` and `flat_curve` (the curve on the sheet)"
                    .to_string(),
            )),
        }
    }

    /// `line = [[x0, y0], [x1, y1]]`: a geodesic control curve.
    fn flat_line(&self, pk: &str, lv: &Value, at: usize) -> Result<FlatPath, SpecError> {
        let pts = self.pts2(lv, &format!("{pk}line"), at, 2)?;
        if pts.len() != 2 {
            return Err(self.invalid(
                at,
                &format!("{pk}line"),
                format!(
                    "must be exactly two points [[x0, y0], [x1, y1]], got {}",
                    pts.len()
                ),
            ));
        }
        Ok(FlatPath::Line([pts[0], pts[1]]))
    }

    /// `arc = { center = [x, y], radius, start_deg, end_deg }`.
    fn flat_arc(&self, pk: &str, av: &Value, at: usize) -> Result<FlatPath, SpecError> {
        let num = |v: Option<&Value>| match v {
            Some(Value::Integer(i)) => Some(*i as f64),
            Some(Value::Float(f)) if f.is_finite() => Some(*f),
            _ => None,
        };
        let ak = format!("{pk}arc");
        const KEYS: [&str; 4] = ["center", "radius", "start_deg", "end_deg"];
        let Value::Table(t) = av else {
            return Err(self.invalid(
                at,
                &ak,
                format!(
                    "must be a table {{ center = [x, y], radius, start_deg, end_deg }}, got {}",
                    av.type_str()
                ),
            ));
        };
        if let Some(k) = t.keys().find(|k| !KEYS.contains(&k.as_str())) {
            return Err(self.invalid(
                at,
                &format!("{ak}.{k}"),
                format!("unknown key; expected {}", one_of(&KEYS)),
            ));
        }
        let center = match t.get("center") {
            Some(v) => self.pt2(v, &format!("{ak}.center"), at)?,
            None => {
                return Err(self.invalid(
                    at,
                    &format!("{ak}.center"),
                    "missing: the arc's centre on the sheet [x, y] (mm)".to_string(),
                ))
            }
        };
        let get = |k: &str, what: &str| {
            num(t.get(k)).ok_or_else(|| {
                self.invalid(
                    at,
                    &format!("{ak}.{k}"),
                    format!("missing or not a finite number: {what}"),
                )
            })
        };
        let radius = get("radius", "the arc's radius (mm)")?;
        let start_deg = get(
            "start_deg",
            "the angle of the arc's start (degrees from +x)",
        )?;
        let end_deg = get(
            "end_deg",
            "the angle of the arc's end (degrees from +x; counter-clockwise when larger than start_deg)",
        )?;
        if radius <= 0.0 {
            return Err(self.invalid(
                at,
                &format!("{ak}.radius"),
                format!("must be positive (mm), got {radius}"),
            ));
        }
        let sweep = (end_deg - start_deg).abs();
        if sweep == 0.0 || sweep > 360.0 {
            return Err(self.invalid(
                at,
                &format!("{ak}.end_deg"),
                format!(
                    "the arc must turn by more than 0° and at most 360°, got start_deg {start_deg}, end_deg {end_deg}"
                ),
            ));
        }
        Ok(FlatPath::Arc {
            center,
            radius,
            start_deg,
            end_deg,
        })
    }

    /// `flat_curve`: Bézier control points on the sheet, or a `bezier` / `bspline` table.
    fn flat_curve(&self, pk: &str, cv: &Value, at: usize) -> Result<FlatPath, SpecError> {
        let ck = format!("{pk}flat_curve");
        let z =
            |p: Vec<DVec2>| -> Vec<DVec3> { p.iter().map(|q| DVec3::new(q.x, q.y, 0.0)).collect() };
        match cv {
            Value::Array(_) => Ok(FlatPath::Curve(Spline::bezier(z(self.pts2(cv, &ck, at, 3)?)))),
            Value::Table(t) => {
                const KEYS: [&str; 3] = ["kind", "control", "degree"];
                if let Some(k) = t.keys().find(|k| !KEYS.contains(&k.as_str())) {
                    return Err(self.invalid(
                        at,
                        &format!("{ck}.{k}"),
                        format!("unknown key; expected {}", one_of(&KEYS)),
                    ));
                }
                let control = match t.get("control") {
                    Some(v) => z(self.pts2(v, &format!("{ck}.control"), at, 3)?),
                    None => {
                        return Err(self.invalid(
                            at,
                            &format!("{ck}.control"),
                            "missing: the control points on the sheet [[x, y], ...]".to_string(),
                        ))
                    }
                };
                match t.get("kind").and_then(|v| v.as_str()) {
                    Some("bezier") | None => Ok(FlatPath::Curve(Spline::bezier(control))),
                    Some("bspline") => {
                        let degree = match t.get("degree") {
                            None => 3,
                            Some(Value::Integer(d)) if (2..=9).contains(d) => *d as usize,
                            Some(v) => {
                                return Err(self.invalid(
                                    at,
                                    &format!("{ck}.degree"),
                                    format!("must be an integer from 2 to 9, got {v}"),
                                ))
                            }
                        };
                        Ok(FlatPath::Curve(Spline::bspline(control, degree)))
                    }
                    Some(k) => Err(self.invalid(
                        at,
                        &format!("{ck}.kind"),
                        format!("must be \"bezier\" or \"bspline\", got \"{k}\""),
                    )),
                }
            }
            v => Err(self.invalid(
                at,
                &ck,
                format!(
                    "must be Bézier control points [[x, y], ...] or a table {{ kind = \"bspline\", control, degree }}, got {}",
                    v.type_str()
                ),
            )),
        }
    }

    /// One `kind = "bent-sheet"` entry.
    pub(super) fn bent_surface(
        &self,
        s: &RawSurface,
        key: &str,
        header_line: usize,
        dir: &Path,
    ) -> Result<SurfaceSpec, SpecError> {
        self.refuse(
            key,
            &[
                ("path", span(&s.path)),
                ("scale", span(&s.scale)),
                ("units", span(&s.units)),
            ],
            "is for mesh surfaces; a bent sheet takes `outline`, `line` (or `arc`, `flat_curve`) and `control_points` or `handles`",
        )?;
        self.refuse(
            key,
            &[("p", span(&s.p)), ("q", span(&s.q))],
            "is for strips; a bent sheet takes `line` (or `arc`, `flat_curve`) and `control_points` or `handles`",
        )?;
        self.refuse(key, &[("method", span(&s.method))], "is for strips")?;
        let tolerance = self
            .number(
                &s.tolerance,
                &format!("{key}.tolerance"),
                MM_POSITIVE,
                |v| v > 0.0,
            )?
            .map_or(crate::geom::curve::DEFAULT_TOLERANCE, |(v, _)| v);
        let bend_lines = self.bend_lines(&s.bend_lines, key)?;
        let outline = self.bent_outline(s, key, header_line)?;
        let holes = self.bent_holes(s, key)?;
        let (pieces, line_no) = match &s.pieces {
            Some(pv) => self.bent_pieces(s, key, pv, dir)?,
            None => self.bent_top_piece(s, key, header_line, dir)?,
        };
        let name = self
            .file_name(&s.name, &format!("{key}.name"))?
            .unwrap_or_else(|| format!("sheet{}", key.trim_start_matches("surface")));
        Ok(SurfaceSpec {
            kind: SurfaceKind::BentSheet,
            path: self.path.to_path_buf(),
            scale: 1.0,
            units: Units::Mm,
            size: None,
            name,
            line: line_no,
            strip: None,
            boundary: None,
            spline: None,
            segment: SegmentSpec::default(),
            bent: Some(BentSpec {
                outline,
                holes,
                pieces,
                tolerance,
                bend_lines,
            }),
        })
    }

    /// `outline`: `[width, height]` from the origin, or a list of points.
    fn bent_outline(
        &self,
        s: &RawSurface,
        key: &str,
        header_line: usize,
    ) -> Result<Vec<DVec2>, SpecError> {
        let ok = format!("{key}.outline");
        let ov = s.outline.as_ref().ok_or_else(|| {
            self.invalid(
                header_line,
                &ok,
                "missing: a bent sheet needs its flat `outline`, [width, height] or [[x, y], ...]"
                    .to_string(),
            )
        })?;
        let oline = self.line(ov.span());
        Ok(match ov.get_ref() {
            Value::Array(a) if a.len() == 2 && a.iter().all(|x| x.is_integer() || x.is_float()) => {
                let wh = self.pt2(ov.get_ref(), &ok, oline)?;
                if !(wh.x > 0.0 && wh.y > 0.0) {
                    return Err(self.invalid(
                        oline,
                        &ok,
                        format!(
                            "width and height must be positive, got [{}, {}]",
                            wh.x, wh.y
                        ),
                    ));
                }
                vec![
                    DVec2::ZERO,
                    DVec2::new(wh.x, 0.0),
                    wh,
                    DVec2::new(0.0, wh.y),
                ]
            }
            v => self.pts2(v, &ok, oline, 3)?,
        })
    }

    /// `holes`: a list of point lists, none when left out.
    fn bent_holes(&self, s: &RawSurface, key: &str) -> Result<Vec<Vec<DVec2>>, SpecError> {
        let mut holes = Vec::new();
        if let Some(hv) = &s.holes {
            let hl = self.line(hv.span());
            let hk = format!("{key}.holes");
            match hv.get_ref() {
                Value::Array(items) => {
                    for (i, it) in items.iter().enumerate() {
                        holes.push(self.pts2(it, &format!("{hk}[{}]", i + 1), hl, 3)?);
                    }
                }
                v => {
                    return Err(self.invalid(
                        hl,
                        &hk,
                        format!(
                            "must be a list of point lists [[[x, y], ...], ...], got {}",
                            v.type_str()
                        ),
                    ))
                }
            }
        }
        Ok(holes)
    }

    /// The entries of `pieces`, and the line of `pieces`.
    fn bent_pieces(
        &self,
        s: &RawSurface,
        key: &str,
        pv: &toml::Spanned<Value>,
        dir: &Path,
    ) -> Result<(Vec<PieceSpec>, usize), SpecError> {
        let pl = self.line(pv.span());
        self.refuse(
            key,
            &[
                ("line", span(&s.line)),
                ("arc", span(&s.arc)),
                ("flat_curve", span(&s.flat_curve)),
                ("control_points", span(&s.control_points)),
                ("handles", span(&s.handles)),
                ("length_fit", span(&s.length_fit)),
            ],
            "goes into each entry of `pieces` when `pieces` is given",
        )?;
        let items = match pv.get_ref() {
            Value::Array(items) if !items.is_empty() => items,
            v => {
                return Err(self.invalid(
                    pl,
                    &format!("{key}.pieces"),
                    format!(
                        "must be a non-empty list of tables {{ line, control_points }}, got {v}"
                    ),
                ))
            }
        };
        let mut pieces = Vec::new();
        for (i, it) in items.iter().enumerate() {
            let pk = format!("{key}.pieces[{}].", i + 1);
            let Value::Table(t) = it else {
                return Err(self.invalid(
                    pl,
                    pk.trim_end_matches('.'),
                    "must be a table { line | arc | flat_curve, control_points | handles }"
                        .to_string(),
                ));
            };
            const KEYS: [&str; 6] = [
                "line",
                "arc",
                "flat_curve",
                "control_points",
                "handles",
                "length_fit",
            ];
            for k in t.keys() {
                if !KEYS.contains(&k.as_str()) {
                    return Err(self.invalid(
                        pl,
                        &format!("{pk}{k}"),
                        format!("unknown key; expected {}", one_of(&KEYS)),
                    ));
                }
            }
            let path =
                self.flat_path(&pk, [t.get("line"), t.get("arc"), t.get("flat_curve")], pl)?;
            pieces.push(self.bent_piece(
                &pk,
                path,
                [
                    t.get("control_points"),
                    t.get("handles"),
                    t.get("length_fit"),
                ],
                pl,
                dir,
            )?);
        }
        Ok((pieces, pl))
    }

    /// The one piece given by the surface's own keys, and the line of its curve on the sheet
    /// (of the entry when it has none).
    fn bent_top_piece(
        &self,
        s: &RawSurface,
        key: &str,
        header_line: usize,
        dir: &Path,
    ) -> Result<(Vec<PieceSpec>, usize), SpecError> {
        let flat_key = s.line.as_ref().or(s.arc.as_ref()).or(s.flat_curve.as_ref());
        let at = flat_key.map_or(header_line, |v| self.line(v.span()));
        let cl = s
            .control_points
            .as_ref()
            .or(s.handles.as_ref())
            .map_or(at, |v| self.line(v.span()));
        let path = self.flat_path(
            &format!("{key}."),
            [
                s.line.as_ref().map(|v| v.get_ref()),
                s.arc.as_ref().map(|v| v.get_ref()),
                s.flat_curve.as_ref().map(|v| v.get_ref()),
            ],
            at,
        )?;
        let piece = self.bent_piece(
            &format!("{key}."),
            path,
            [
                s.control_points.as_ref().map(|v| v.get_ref()),
                s.handles.as_ref().map(|v| v.get_ref()),
                s.length_fit.as_ref().map(|v| v.get_ref()),
            ],
            if flat_key.is_some() { cl } else { at },
            dir,
        )?;
        Ok((vec![piece], at))
    }

    /// One piece from a table of keys (the surface itself or an entry of `pieces`): its curve
    /// on the sheet `path` and the values of `control_points`, `handles` and `length_fit`.
    fn bent_piece(
        &self,
        pk: &str,
        path: FlatPath,
        [control, handles, fit]: [Option<&Value>; 3],
        at: usize,
        dir: &Path,
    ) -> Result<PieceSpec, SpecError> {
        let control = match (control, handles) {
            (Some(_), Some(_)) | (None, None) => {
                return Err(self.invalid(
                    at,
                    &format!("{pk}control_points"),
                    "a bent sheet needs exactly one of `control_points` and `handles`".to_string(),
                ))
            }
            (Some(cv), None) => self.bent_control_points(pk, cv, at, dir)?,
            (None, Some(hv)) => self.bent_handles(pk, hv, at)?,
        };
        let fit = match fit {
            None => LengthFit::default(),
            Some(Value::String(f)) => match pick(f, &LengthFit::NAMES) {
                Ok(f) => f,
                Err(m) => {
                    return Err(self.invalid(at, &format!("{pk}length_fit"), m));
                }
            },
            Some(v) => {
                return Err(self.invalid(
                    at,
                    &format!("{pk}length_fit"),
                    format!("must be \"scale\" or \"trim\", got {v}"),
                ))
            }
        };
        Ok(PieceSpec { path, control, fit })
    }

    /// `control_points`: Bézier control points, or a `bezier` / `bspline` curve table.
    fn bent_control_points(
        &self,
        pk: &str,
        cv: &Value,
        at: usize,
        dir: &Path,
    ) -> Result<Control, SpecError> {
        let ck = format!("{pk}control_points");
        let c = self.curve(cv, &ck, at, dir)?;
        match c {
            Curve::Points { points, .. } => Ok(Control::Curve(Curve::Bezier { control: points })),
            c @ (Curve::Bezier { .. } | Curve::BSpline { .. }) => Ok(Control::Curve(c)),
            _ => Err(self.invalid(
                at,
                &ck,
                "must be Bézier control points [[x, y, z], ...] or a table with kind = \"bezier\" or \"bspline\"".to_string(),
            )),
        }
    }

    /// `handles = { start, start_normal, end, end_normal }`.
    fn bent_handles(&self, pk: &str, hv: &Value, at: usize) -> Result<Control, SpecError> {
        let hk = format!("{pk}handles");
        let Value::Table(t) = hv else {
            return Err(self.invalid(
                at,
                &hk,
                "must be a table { start, start_normal, end, end_normal }".to_string(),
            ));
        };
        for k in t.keys() {
            if !["start", "start_normal", "end", "end_normal"].contains(&k.as_str()) {
                return Err(self.invalid(
                    at,
                    &format!("{hk}.{k}"),
                    format!(
                        "unknown key; expected {}",
                        one_of(&["start", "start_normal", "end", "end_normal"])
                    ),
                ));
            }
        }
        let get = |k: &str| -> Result<DVec3, SpecError> {
            match t.get(k) {
                Some(Value::Array(a)) => self.point(a, &format!("{hk}.{k}"), at),
                _ => Err(self.invalid(
                    at,
                    &format!("{hk}.{k}"),
                    "missing or not a point [x, y, z]".to_string(),
                )),
            }
        };
        Ok(Control::Handles {
            start: get("start")?,
            start_normal: get("start_normal")?,
            end: get("end")?,
            end_normal: get("end_normal")?,
        })
    }
}
