//! The reader of `kind = "mesh"` surfaces: the mesh file (relative to the spec's folder), its
//! `scale` and `units`, and how it is cut into pieces (`segment`, `charts`, `f_max`,
//! `approximate`, `simplify`: the D-Charts options of [`crate::surface::SegmentSpec`],
//! issue 7).
//!
//! ```toml
//! segment = "dcharts"      # "faces": exact polyhedral unfolding; "dcharts": nearly developable
//!                          # charts (default: dcharts when the mesh is smooth, see
//!                          # `surface::dcharts::is_smooth`)
//! charts = 8               # initial estimate of the number of charts, integer >= 1
//! f_max = 0.2              # D-Charts fitting threshold, > 0 and <= 1
//! approximate = { iterations = 1, fixed = ["boundary", 12] }   # DCS approximation first;
//!                          # fixed: "boundary" and/or 1-based vertex numbers of the mesh
//! simplify = 0.5           # mm >= 0: largest deviation of a simplified seam between charts
//!                          # (thesis §5.3, `pattern::simplify`); 0: off; default by material
//!                          # (paper and fabric 0.5, metal 0.1); exact unfoldings never change
//! ```
//!
//! Choices: a mesh's name defaults to its file's stem; `approximate` is checked key by key
//! (`iterations` 1 to 100, `fixed` entries "boundary" or a vertex number from 1).

use super::context::Ctx;
use super::spanned::{span, RawSurface};
use super::{stem_or, SpecError};
use crate::surface::{
    ApproximateSpec, Fixed, Segment, SegmentSpec, SurfaceKind, SurfaceSpec, Units,
};
use std::path::Path;
use toml::Spanned;

impl Ctx<'_> {
    /// One `kind = "mesh"` entry: the mesh file, its scale and units, and how it is segmented.
    pub(super) fn mesh_surface(
        &self,
        s: &RawSurface,
        key: &str,
        header_line: usize,
        dir: &Path,
    ) -> Result<SurfaceSpec, SpecError> {
        let kind = SurfaceKind::Mesh;
        let path_key = format!("{key}.path");
        let rel = self.string(
            &s.path,
            &path_key,
            "a non-empty string naming the mesh file, relative to the spec's folder",
        )?;
        let (rel, line) = match (rel, &s.path) {
            (Some(rel), Some(p)) => (rel, self.line(p.span())),
            _ => {
                return Err(self.invalid(
                    header_line,
                    &path_key,
                    "missing: a mesh surface needs the path of its .obj file, \
                     relative to the spec's folder"
                        .to_string(),
                ))
            }
        };
        let path = dir.join(&rel);
        let scale = self
            .number(
                &s.scale,
                &format!("{key}.scale"),
                "a positive number",
                |v| v > 0.0,
            )?
            .map_or(1.0, |(v, _)| v);
        let units = self
            .choice(&s.units, &format!("{key}.units"), &Units::NAMES)?
            .unwrap_or_default();
        let name = self
            .file_name(&s.name, &format!("{key}.name"))?
            .unwrap_or_else(|| stem_or(&path, key));
        Ok(SurfaceSpec {
            kind,
            path,
            scale,
            units,
            size: None,
            name,
            line,
            strip: None,
            bent: None,
            boundary: None,
            spline: None,
            segment: self.segment(s, key)?,
        })
    }

    /// The issue-7 keys of a mesh surface.
    pub(super) fn segment(&self, s: &RawSurface, key: &str) -> Result<SegmentSpec, SpecError> {
        let mode = self.choice(&s.segment, &format!("{key}.segment"), &Segment::NAMES)?;
        let charts = self
            .number(
                &s.charts,
                &format!("{key}.charts"),
                "a whole number of charts, at least 1",
                |v| v >= 1.0 && v.fract() == 0.0 && v <= 1e6,
            )?
            .map(|(v, _)| v as usize);
        let f_max = self
            .number(
                &s.f_max,
                &format!("{key}.f_max"),
                "a fitting threshold, more than 0 and at most 1",
                |v| v > 0.0 && v <= 1.0,
            )?
            .map(|(v, _)| v);
        let approximate = match &s.approximate {
            None => None,
            Some(v) => Some(self.approximate(v, &format!("{key}.approximate"))?),
        };
        let simplify = self
            .number(
                &s.simplify,
                &format!("{key}.simplify"),
                "a tolerance in mm, at least 0 (0: no simplification)",
                |v| v >= 0.0,
            )?
            .map(|(v, _)| v);
        Ok(SegmentSpec {
            mode,
            charts,
            f_max,
            approximate,
            simplify,
        })
    }

    fn approximate(
        &self,
        v: &Spanned<toml::Value>,
        key: &str,
    ) -> Result<ApproximateSpec, SpecError> {
        let line = self.line(v.span());
        let bad = |k: &str, m: &str| self.invalid(line, k, m.to_string());
        let toml::Value::Table(t) = v.get_ref() else {
            return Err(bad(
                key,
                "must be a table { iterations = N, fixed = [...] }",
            ));
        };
        let mut out = ApproximateSpec {
            iterations: 1,
            fixed: Vec::new(),
        };
        for (k, val) in t {
            match k.as_str() {
                "iterations" => {
                    let n = match val {
                        toml::Value::Integer(n) if (1..=100).contains(n) => *n as usize,
                        _ => {
                            return Err(bad(
                                &format!("{key}.iterations"),
                                &format!("must be a whole number from 1 to 100, got {val}"),
                            ))
                        }
                    };
                    out.iterations = n;
                }
                "fixed" => {
                    let toml::Value::Array(items) = val else {
                        return Err(bad(
                            &format!("{key}.fixed"),
                            "must be an array of \"boundary\" and 1-based vertex numbers",
                        ));
                    };
                    for it in items {
                        let f = match it {
                            toml::Value::String(s) if s.trim().eq_ignore_ascii_case("boundary") => {
                                Fixed::Boundary
                            }
                            toml::Value::Integer(n) if *n >= 1 => Fixed::Vertex(*n as usize - 1),
                            _ => {
                                return Err(bad(
                                    &format!("{key}.fixed"),
                                    &format!(
                                        "entries must be \"boundary\" or a vertex number from 1, got {it}"
                                    ),
                                ))
                            }
                        };
                        out.fixed.push(f);
                    }
                }
                other => {
                    return Err(bad(
                        &format!("{key}.{other}"),
                        "unknown key; expected `iterations` or `fixed`",
                    ))
                }
            }
        }
        Ok(out)
    }
}

impl Ctx<'_> {
    /// Keys only a mesh surface takes are errors on other kinds, with `why`.
    pub(super) fn no_mesh_keys(
        &self,
        s: &RawSurface,
        key: &str,
        why: &str,
    ) -> Result<(), SpecError> {
        self.refuse(
            key,
            &[
                ("path", span(&s.path)),
                ("scale", span(&s.scale)),
                ("units", span(&s.units)),
                ("segment", span(&s.segment)),
                ("charts", span(&s.charts)),
                ("f_max", span(&s.f_max)),
                ("approximate", span(&s.approximate)),
                ("simplify", span(&s.simplify)),
            ],
            why,
        )
    }
}
