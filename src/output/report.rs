//! `report.json`: what a run made, for people and for scripts. Pieces (id, name, surface and
//! its source file, area, cut and fold lengths, every fold line with its kind and bend angle,
//! sheet and placement), seams (`{id, piece_a, piece_b, length_3d_mm, length_a_mm, length_b_mm,
//! notches}`, the 3D length of the seam's mesh edges and each side's as cut:
//! notch positions in mm from side A's start, and `notches_b_mm` from side B's start, which is
//! A's end; `tab` says which side has the glue tab; `"split": true` on the seams made by
//! splitting a piece too large for the sheet), sheets (size, pieces, utilisation; on a
//! roll the length used, on sheets the rectangle left free on the last sheet),
//! surfaces (source, faces, pieces, repairs made on import, and the source's own `figures` when
//! it measured some, to 6 significant digits) and the files written. Pieces and surfaces laid
//! out from charts of a smooth mesh (issue 7) carry `stretch`: `{l2, linf, flipped}` (1 = isometric); it is `null`
//! for exact unfoldings. Those whose seams were simplified (thesis §5.3) also carry `simplify`:
//! `{tolerance_mm, vertices_before, vertices_after, max_deviation_mm, max_seam_mismatch_mm}`
//! (border vertices of all its rings; the largest distance of an original border vertex from
//! the simplified border; the largest length difference between the two sides of one of its
//! seams); exact unfoldings have no such key. Pieces of a metal mesh carry
//! `bend_development` (`pattern::develop`): `{thickness_mm, k_factor, inside_radius_mm, bends:
//! [{kind, angle_deg, inside_radius_mm, k_factor, mold_line, allowance_mm, setback_mm,
//! deduction_mm, length_mm}], corner_reliefs_mm}` (the bends in the order of `fold_lines`; the
//! reliefs' radii), with `skipped` saying why when the piece could not be developed.
//!
//! When the device had no tool for some of a job's strokes, `dropped` lists per piece what was
//! left out (`{piece, name, sheet, left_out: {label, edge_ids, …: count}, reason}`) and
//! `warnings` says it in words; a job that lost nothing has neither key.
//!
//! Choices: lengths in mm and areas in mm², rounded to 1e-6 so that the file is stable across
//! platforms; keys are written in a fixed order (serde_json without preserve_order sorts them).

use crate::flatten::Flat;
use crate::nest::Layout;
use crate::pattern::FoldKind;
use serde_json::{json, Value};

/// What the report says about the run besides the layout.
#[derive(Debug, Clone, Default)]
pub struct RunInfo {
    pub name: String,
    pub spec: String,
    pub device: String,
    pub material: String,
    pub thickness_mm: f64,
    pub files: Vec<String>,
    /// Features the device cannot make (`toolpath::cuttable`), as `warnings`; none: no key.
    pub warnings: Vec<crate::toolpath::cuttable::Warning>,
    /// What the job left out for want of a tool, per piece (`dropped`, and one `warnings`
    /// entry each, only when there is something).
    pub dropped: Vec<crate::toolpath::passes::Dropped>,
    /// The tiled print document's pages (`--print`), as `print`; none: no key.
    pub print: Option<super::print::Tiling>,
}

/// `v` to 6 significant digits: the sources' figures range from residuals of 1e-12 to
/// energies of 1e4, and 6 decimals would write the small ones as 0.
pub(super) fn sig6(v: f64) -> f64 {
    if v == 0.0 || !v.is_finite() {
        return v;
    }
    format!("{v:.5e}").parse().unwrap_or(v)
}

fn r6(v: f64) -> f64 {
    (v * 1e6).round() / 1e6
}

/// Build the report.
pub fn build(info: &RunInfo, flats: &[Flat], layout: &Layout) -> Value {
    let source = |surface: &str| {
        flats
            .iter()
            .find(|f| f.surface.name == surface)
            .map(|f| f.surface.source.display().to_string())
            .unwrap_or_default()
    };
    let pieces: Vec<Value> = layout
        .pieces
        .iter()
        .zip(&layout.placements)
        .map(|(p, at)| {
            let pts: Vec<_> = p.outline.iter().flatten().map(|q| at.apply(*q)).collect();
            let (lo, hi) = crate::geom::polygon::bounds(pts).unwrap_or_default();
            let count = |k| p.folds.iter().filter(|f| f.kind == k && !f.tab).count();
            let mut v = json!({
                "id": p.id,
                "name": p.name,
                "surface": p.surface,
                "source": source(&p.surface),
                "faces": p.faces.len(),
                "area_mm2": r6(p.area),
                "cut_length_mm": r6(p.cut_length()),
                "fold_length_mm": r6(p.fold_length()),
                "folds": { "mountain": count(FoldKind::Mountain), "valley": count(FoldKind::Valley) },
                "fold_lines": p.folds.iter().filter(|f| !f.tab).map(|f| json!({
                    "kind": f.kind,
                    "angle_deg": r6(f.angle.to_degrees()),
                    "length_mm": r6(f.a.distance(f.b)),
                })).collect::<Vec<_>>(),
                "tabs": p.seams.iter().filter(|s| s.tab).count(),
                "border_length_mm": r6(p.border.iter().map(|r| crate::geom::polygon::perimeter(r)).sum()),
                "contours": p.outline.len(),
                "edge_ids": p.marks.len(),
                "notches": p.notches.len(),
                "sheet": at.sheet + 1,
                "rotation_deg": r6(at.rotation.to_degrees()),
                "mirrored": at.mirror,
                "offset_mm": [r6(at.offset.x), r6(at.offset.y)],
                "bbox_mm": [r6(lo.x), r6(lo.y), r6(hi.x), r6(hi.y)],
                "stretch": piece_stretch(flats, p),
            });
            // Seams simplified (D-Charts pieces, thesis §5.3): only there, so that the report
            // of an exact unfolding stays as it was.
            if let Some(s) = &p.simplified {
                v["simplify"] = json!({
                    "tolerance_mm": r6(s.tolerance),
                    "vertices_before": s.vertices_before,
                    "vertices_after": s.vertices_after,
                    "max_deviation_mm": r6(s.max_deviation),
                    "max_seam_mismatch_mm": r6(s.max_seam_mismatch),
                });
            }
            // Metal meshes developed as bends: only there, so that other reports stay as
            // they were.
            if let Some(d) = &p.development {
                v["bend_development"] = development_json(p, d);
            }
            v
        })
        .collect();
    let sheets: Vec<Value> = layout
        .sheets
        .iter()
        .enumerate()
        .map(|(i, s)| {
            json!({
                "index": i + 1,
                "width_mm": r6(s.width),
                "height_mm": r6(s.height),
                "pieces": s.pieces.iter().map(|&k| layout.pieces[k].id).collect::<Vec<_>>(),
                "utilisation": r6(layout.utilisation(i)),
            })
        })
        .collect();
    let surfaces = surfaces_json(flats);
    let seams = seams_json(layout);
    let total = |g: &dyn Fn(&crate::pattern::Piece) -> f64| r6(layout.pieces.iter().map(g).sum());
    let mut rep = json!({
        "name": info.name,
        "spec": info.spec,
        "device": info.device,
        "material": { "kind": info.material, "thickness_mm": info.thickness_mm },
        "roll": layout.roll,
        "roll_length_mm": layout.roll_length().map(r6),
        "remnant_mm": layout.remnant.map(|(lo, hi)| [r6(lo.x), r6(lo.y), r6(hi.x), r6(hi.y)]),
        "margin_mm": layout.margin,
        "spacing_mm": layout.spacing,
        "surfaces": surfaces,
        "pieces": pieces,
        "seams": seams,
        "sheets": sheets,
        "totals": {
            "pieces": layout.pieces.len(),
            "sheets": layout.sheets.len(),
            "area_mm2": total(&|p| p.area),
            "cut_length_mm": total(&|p| p.cut_length()),
            "fold_length_mm": total(&|p| p.fold_length()),
        },
        "files": info.files,
    });
    // Only when there is something, so that the report of a job that lost nothing stays as
    // it was.
    let mut warnings = info.warnings.clone();
    warnings.extend(
        info.dropped
            .iter()
            .map(|d| crate::toolpath::cuttable::Warning {
                piece: d.name.clone(),
                kind: "left-out",
                message: format!("left out: {} ({})", d.describe(), d.reason),
            }),
    );
    if !info.dropped.is_empty() {
        rep["dropped"] = json!(info.dropped);
    }
    if let Some(p) = &info.print {
        rep["print"] = json!(p);
    }
    if !warnings.is_empty() {
        rep["warnings"] = json!(warnings);
    }
    rep
}

/// The `surfaces` entries: one per surface, with the figures its source measured.
fn surfaces_json(flats: &[Flat]) -> Vec<Value> {
    flats
        .iter()
        .map(|f| {
            let mut v = json!({
                "name": f.surface.name,
                "source": f.surface.source.display().to_string(),
                "faces": f.surface.mesh.faces.len(),
                "pieces": f.islands.len(),
                "warnings": f.surface.warnings,
                "stretch": f.surface.charts.as_ref().map(|_| stretch_json(&crate::flatten::charts::stretch(f).1)),
            });
            // Figures the source measured (boundary surfaces: interior triangles, locally
            // convex fraction, largest dihedral, iterations). No wall-clock time: two identical
            // runs give byte-identical reports.
            if !f.surface.figures.is_empty() {
                let figs: serde_json::Map<String, Value> = f
                    .surface
                    .figures
                    .iter()
                    .map(|(k, x)| (k.to_string(), json!(sig6(*x))))
                    .collect();
                v["figures"] = Value::Object(figs);
            }
            v
        })
        .collect()
}

/// The `seams` entries, by seam id: side A and side B of every seam.
fn seams_json(layout: &Layout) -> Vec<Value> {
    let mut seams: Vec<Value> = Vec::new();
    let sides = || {
        layout
            .pieces
            .iter()
            .flat_map(|p| p.seams.iter().map(move |s| (p, s)))
    };
    for (pa, a) in sides().filter(|(_, s)| s.is_a) {
        let Some((pb, b)) = sides().find(|(_, s)| s.id == a.id && !s.is_a) else {
            continue;
        };
        let mut v = json!({
            "id": a.id,
            "piece_a": pa.id,
            "piece_b": pb.id,
            "length_3d_mm": r6(a.length_3d),
            "length_a_mm": r6(a.length),
            "length_b_mm": r6(b.length),
            "edges": a.count,
            "notches": a.notches.iter().map(|&v| r6(v)).collect::<Vec<_>>(),
            "notches_b_mm": b.notches.iter().map(|&v| r6(v)).collect::<Vec<_>>(),
            "tab": match (a.tab, b.tab) {
                (true, true) => "both",
                (true, false) => "a",
                (false, true) => "b",
                (false, false) => "none",
            },
        });
        // Seams made by splitting a piece too large for the sheet: only there, so that the
        // report of a job that needed no split stays as it was.
        if a.split || b.split {
            v["split"] = json!(true);
        }
        seams.push(v);
    }
    seams.sort_by_key(|s| s["id"].as_u64());
    seams
}

/// A developed metal piece (`pattern::develop`): the sheet, each bend line (in the order of
/// `fold_lines`) with its angle, inside radius, K, allowance, setback and deduction, the
/// corner reliefs' radii, or why it was not developed.
fn development_json(p: &crate::pattern::Piece, d: &crate::pattern::develop::Development) -> Value {
    let s = &d.sheet;
    let bends: Vec<Value> = p
        .folds
        .iter()
        .filter(|f| !f.tab)
        .filter_map(|f| {
            let b = d.bend(f.edge)?;
            Some(json!({
                "kind": f.kind,
                "angle_deg": r6(b.angle.to_degrees()),
                "inside_radius_mm": r6(s.inside_radius),
                "k_factor": r6(s.k_factor),
                "mold_line": b.mold.name(),
                "allowance_mm": r6(b.allowance),
                "setback_mm": r6(b.setback),
                "deduction_mm": r6(b.deduction),
                "length_mm": r6(f.a.distance(f.b)),
            }))
        })
        .collect();
    let mut v = json!({
        "thickness_mm": r6(s.thickness),
        "k_factor": r6(s.k_factor),
        "inside_radius_mm": r6(s.inside_radius),
        "bends": bends,
        "corner_reliefs_mm": d.reliefs.iter().map(|&r| r6(r)).collect::<Vec<_>>(),
    });
    if let Some(why) = &d.skipped {
        v["skipped"] = json!(why);
    }
    v
}

/// Stretch figures (issue 7): L2 and L∞ (1 = isometric), triangles flipped.
fn stretch_json(s: &crate::flatten::Stretch) -> Value {
    json!({ "l2": r6(s.l2), "linf": r6(s.linf), "flipped": s.flipped })
}

/// Stretch of a piece laid out from a charted (smooth) surface; `null` for exact unfoldings.
fn piece_stretch(flats: &[Flat], p: &crate::pattern::Piece) -> Value {
    let Some(flat) = flats
        .iter()
        .find(|f| f.surface.name == p.surface && f.surface.charts.is_some())
    else {
        return Value::Null;
    };
    stretch_json(&crate::flatten::charts::stretch_of(flat, &p.faces))
}
