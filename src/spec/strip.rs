//! The reader of `kind = "strip"` surfaces: a developable strip between two boundary curves
//! `p` and `q` (Wang–Tang, `surface::strip`), with `method`, `bend_lines`, `tolerance` and,
//! for metal, `side` and `k_factor`. The curves are read by [`super::curves`] and sampled here,
//! so a curve that cannot be sampled, or two curves that cannot make a strip, are reported at
//! the line of `p` or `q`.
//!
//! Choices: mesh keys (`path`, `scale`, `units`, `segment`, …) are refused on a strip; the
//! strip is named `strip[K]` after its entry when it has no `name`; the sheet side and K
//! factor are kept for [`crate::surface::SurfaceSpec::for_material`], since the material (and
//! the flags that may change it) is known only later.

use super::context::{Ctx, MM_POSITIVE};
use super::spanned::RawSurface;
use super::SpecError;
use crate::surface::{SegmentSpec, SheetSide, StripSpec, SurfaceKind, SurfaceSpec, Units};
use std::path::Path;

impl Ctx<'_> {
    /// One `kind = "strip"` entry.
    pub(super) fn strip_surface(
        &self,
        s: &RawSurface,
        key: &str,
        header_line: usize,
        dir: &Path,
    ) -> Result<SurfaceSpec, SpecError> {
        use crate::surface::strip::Method;
        self.no_mesh_keys(
            s,
            key,
            "is for mesh surfaces; a strip takes the curves `p` and `q`",
        )?;
        let tolerance = self
            .number(
                &s.tolerance,
                &format!("{key}.tolerance"),
                MM_POSITIVE,
                |v| v > 0.0,
            )?
            .map_or(crate::geom::curve::DEFAULT_TOLERANCE, |(v, _)| v);
        let method = self
            .choice(&s.method, &format!("{key}.method"), &Method::NAMES)?
            .unwrap_or_default();
        let side = self
            .choice(&s.side, &format!("{key}.side"), &SheetSide::NAMES)?
            .unwrap_or_default();
        let k_factor = self
            .number(
                &s.k_factor,
                &format!("{key}.k_factor"),
                "a number from 0 to 1",
                |v| (0.0..=1.0).contains(&v),
            )?
            .map_or(0.4, |(v, _)| v);
        let bend_lines = self.bend_lines(&s.bend_lines, key)?;
        let mut curves = Vec::new();
        for (name, v) in [("p", &s.p), ("q", &s.q)] {
            let ck = format!("{key}.{name}");
            let v = v.as_ref().ok_or_else(|| {
                self.invalid(
                    header_line,
                    &ck,
                    "missing: a strip needs two boundary curves `p` and `q`".to_string(),
                )
            })?;
            let line = self.line(v.span());
            let c = self.curve(v.get_ref(), &ck, line, dir)?;
            let sampled = c.sample(tolerance).map_err(|e| {
                use crate::geom::curve::CurveError as E;
                let sub = match &e {
                    E::NotPositive { what, .. } => format!("{ck}.{what}"),
                    E::CornerRadius { .. } => format!("{ck}.corner_radius"),
                    _ => ck.clone(),
                };
                self.invalid(line, &sub, e.to_string())
            })?;
            curves.push((c, sampled, line));
        }
        let (qc, qs, q_line) = curves
            .pop()
            .ok_or_else(|| self.invalid(header_line, key, "no q".into()))?;
        let (pc, ps, p_line) = curves
            .pop()
            .ok_or_else(|| self.invalid(header_line, key, "no p".into()))?;
        if let Err(e) = crate::surface::strip::Strip::new(&ps, &qs) {
            return Err(self.invalid(q_line, &format!("{key}.q"), e.to_string()));
        }
        let name = self
            .file_name(&s.name, &format!("{key}.name"))?
            .unwrap_or_else(|| format!("strip{}", key.trim_start_matches("surface")));
        Ok(SurfaceSpec {
            kind: SurfaceKind::Strip,
            path: self.path.to_path_buf(),
            scale: 1.0,
            units: Units::Mm,
            size: None,
            name,
            line: p_line,
            strip: Some(StripSpec {
                p: pc,
                q: qc,
                method,
                bend_lines,
                tolerance,
                neutral_offset: 0.0,
                sheet: Some((side, k_factor)),
            }),
            bent: None,
            boundary: None,
            spline: None,
            segment: SegmentSpec::default(),
        })
    }
}
