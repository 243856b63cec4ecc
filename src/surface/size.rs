//! The size of a model: its extent (the axis-aligned bounding box of its vertices), scaling a
//! built [`Surface`] to a size, and the plausibility check that refuses a model whose size as
//! read cannot be what the user meant (issue 21).
//!
//! Choices where the issue is silent:
//! - "Size" is the largest side of the bounding box in the model's own axes (what a user
//!   measures with a ruler on the assembled model), not its diagonal.
//! - Plausible is from [`MIN_MM`] (10 mm) to [`MAX_MM`] (10 m) across; outside it the run stops
//!   with one line naming the size as read, the units it was read in and the flags that fix it
//!   (`--size`, and `--units` with the first of m, in, cm that makes it plausible, or `--scale`
//!   for a model that is too large in millimetres already). A size given on purpose (`--size`,
//!   spec `size`) is never refused.
//! - Scaling a built surface scales its mesh and alternatives; bend angles, charts and cuts
//!   are unchanged (a uniform scale keeps angles).
//! - A mesh is checked, segmented and flattened at one size, [`SHAPE_MM`] across, whatever
//!   size it is cut at ([`Shape`]; issue 20, item 5): the same model at 30 mm and at 3 m gives
//!   the same pieces, bit for bit, and only the finishing in millimetres (seam
//!   simplification, tabs, splitting to fit the sheet) differs.

use super::{Surface, SurfaceError, Units};
use crate::geom::mesh::Mesh;
use glam::DVec3;
use std::path::Path;

/// Smallest plausible model, mm across.
pub const MIN_MM: f64 = 10.0;
/// Largest plausible model, mm across.
pub const MAX_MM: f64 = 10_000.0;

/// The size (mm across) at which a mesh's shape is checked, segmented and laid flat
/// ([`Shape`]).
pub const SHAPE_MM: f64 = 300.0;

/// A mesh's vertices at [`SHAPE_MM`] across and the factor from them to the surface's
/// millimetres.
#[derive(Debug, Clone, PartialEq)]
pub struct Shape {
    pub vertices: Vec<DVec3>,
    pub to_mm: f64,
}

/// The bounding box's sides (x, y, z) of the vertices used by faces; zero for no faces.
pub fn extent(mesh: &Mesh) -> DVec3 {
    let mut lo = DVec3::splat(f64::INFINITY);
    let mut hi = DVec3::splat(f64::NEG_INFINITY);
    for f in &mesh.faces {
        for &v in &f.verts {
            if let Some(p) = mesh.vertices.get(v) {
                lo = lo.min(*p);
                hi = hi.max(*p);
            }
        }
    }
    if lo.x <= hi.x {
        hi - lo
    } else {
        DVec3::ZERO
    }
}

/// The bounding box's sides of several surfaces together.
pub fn extent_of(surfaces: &[Surface]) -> DVec3 {
    let mut lo = DVec3::splat(f64::INFINITY);
    let mut hi = DVec3::splat(f64::NEG_INFINITY);
    for s in surfaces {
        for f in &s.mesh.faces {
            for &v in &f.verts {
                if let Some(p) = s.mesh.vertices.get(v) {
                    lo = lo.min(*p);
                    hi = hi.max(*p);
                }
            }
        }
    }
    if lo.x <= hi.x {
        hi - lo
    } else {
        DVec3::ZERO
    }
}

/// The factor that makes a model of `extent` `size` mm across (its largest side); 1 for a model
/// without extent (the mesh checks report that).
pub fn factor_for(extent: DVec3, size: f64) -> f64 {
    let e = extent.max_element();
    if e > 0.0 && e.is_finite() {
        size / e
    } else {
        1.0
    }
}

impl Surface {
    /// Scale the surface (its mesh and alternatives) uniformly by `f`; its [`Shape`] stays
    /// as it is, with `f` more to the millimetres.
    pub fn scale(&mut self, f: f64) {
        if let Some(s) = &mut self.shape {
            s.to_mm *= f;
        }
        for v in &mut self.mesh.vertices {
            *v *= f;
        }
        for m in &mut self.alternatives {
            for v in &mut m.vertices {
                *v *= f;
            }
        }
        if let Some(d) = &mut self.spline {
            let m = &mut d.model;
            m.curves.iter_mut().flatten().for_each(|p| *p *= f);
            if let Some(a) = &mut m.apex {
                *a *= f;
            }
        }
    }
}

/// Refuse a model `extent` (mm, as read in `units`) outside [`MIN_MM`, `MAX_MM`]: one line
/// naming `path`, the size as read and the flags that fix it.
pub fn check_plausible(path: &Path, extent: DVec3, units: Units) -> Result<(), SurfaceError> {
    let across = extent.max_element();
    if (MIN_MM..=MAX_MM).contains(&across) || across <= 0.0 || !across.is_finite() {
        return Ok(());
    }
    let raw = across / units.mm();
    let plausible = |u: Units| (MIN_MM..=MAX_MM).contains(&(raw * u.mm()));
    let (what, fix) = if across < MIN_MM {
        let unit = [Units::M, Units::In, Units::Cm]
            .into_iter()
            .find(|&u| u != units && plausible(u));
        (
            format!("too small to cut (under {MIN_MM} mm)"),
            match unit {
                Some(u) => format!(" or its units with --units {u}"),
                None => String::new(),
            },
        )
    } else {
        let unit = [Units::Mm, Units::Cm]
            .into_iter()
            .find(|&u| u != units && plausible(u));
        (
            format!("larger than {} m", MAX_MM / 1000.0),
            match unit {
                Some(u) => format!(" or its units with --units {u}"),
                None => format!(" or --scale {}", fmt(MAX_MM / 10.0 / across)),
            },
        )
    };
    Err(SurfaceError::Invalid {
        path: path.to_path_buf(),
        message: format!(
            "the model is {} mm across as read ({} × {} × {} mm, its coordinates taken as {}): {what}; give the size it should have with --size 200 (mm, its largest side){fix}",
            fmt(across),
            fmt(extent.x),
            fmt(extent.y),
            fmt(extent.z),
            unit_name(units)
        ),
    })
}

fn unit_name(u: Units) -> &'static str {
    match u {
        Units::Mm => "millimetres",
        Units::Cm => "centimetres",
        Units::M => "metres",
        Units::In => "inches",
    }
}

/// A length for a message: 4 significant digits, no trailing zeros.
fn fmt(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    let digits = (3 - v.abs().log10().floor() as i32).clamp(0, 12) as usize;
    let s = format!("{v:.digits$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn plausible_sizes_pass_and_others_name_the_fix() {
        let p = Path::new("m.obj");
        assert!(check_plausible(p, DVec3::new(100.0, 50.0, 10.0), Units::Mm).is_ok());
        let e = check_plausible(p, DVec3::new(1.0, 0.5, 0.2), Units::Mm).unwrap_err();
        let s = e.to_string();
        assert!(s.starts_with("m.obj: the model is 1 mm across"), "{s}");
        assert!(s.contains("--size 200") && s.contains("--units m"), "{s}");
        assert!(!s.contains('\n'));
        let e = check_plausible(p, DVec3::new(25_000.0, 1.0, 1.0), Units::Mm).unwrap_err();
        let s = e.to_string();
        assert!(
            s.contains("larger than 10 m") && s.contains("--scale 0.04"),
            "{s}"
        );
        let e = check_plausible(p, DVec3::new(20_000.0, 1.0, 1.0), Units::M).unwrap_err();
        assert!(e.to_string().contains("--units mm"), "{e}");
    }
}
