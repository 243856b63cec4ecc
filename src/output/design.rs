//! `--spline-json`: the solved spline designs (issue 24, Tang et al. 2016) as JSON that other
//! software can read back: per spline surface its B-spline space (degree, closed, knots), the
//! solved control points of every curve (and a cone's apex), the strips (pairs of curves), the
//! crease condition on every interior curve (with its stated fold), the figures, and the development: where each
//! sampled curve lies on the flat pieces.
//!
//! Choices: millimetres throughout, 1-based curve numbers as in the spec and in messages;
//! flat points are in the piece's own plane as the flatten stage laid it out (before the nest
//! placed it on a sheet), one polyline per curve and piece it crosses (a curve that the
//! unfolding cut apart gives several); coordinates are rounded to 1e-9 mm and figures to 6
//! significant digits (as in report.json). Surfaces of other kinds are left out.

use crate::flatten::Flat;
use crate::surface::spline::Crease;
use glam::DVec2;
use serde_json::{json, Value};

fn r9(v: f64) -> f64 {
    (v * 1e9).round() / 1e9
}

/// The design document for `flats`' spline surfaces, or `None` when there is none.
pub fn spline_json(flats: &[Flat]) -> Option<String> {
    let surfaces: Vec<Value> = flats.iter().filter_map(surface_json).collect();
    if surfaces.is_empty() {
        return None;
    }
    let doc = json!({
        "format": "flatcut spline design",
        "version": 1,
        "units": "mm",
        "surfaces": surfaces,
    });
    Some(serde_json::to_string_pretty(&doc).unwrap_or_default() + "\n")
}

fn surface_json(flat: &Flat) -> Option<Value> {
    let d = flat.surface.spline.as_ref()?;
    let m = &d.model;
    let pt3 = |p: &glam::DVec3| json!([r9(p.x), r9(p.y), r9(p.z)]);
    let curves: Vec<Value> = m
        .curves
        .iter()
        .map(|c| Value::Array(c.iter().map(pt3).collect()))
        .collect();
    let strips: Vec<Value> = match m.apex {
        Some(_) => vec![json!([1, "apex"])],
        None => (1..m.curves.len()).map(|c| json!([c, c + 1])).collect(),
    };
    let name = |k: Crease| {
        Crease::NAMES
            .iter()
            .find(|(_, c)| *c == k)
            .map_or("free", |(n, _)| *n)
    };
    let creases: Vec<Value> = (1..m.curves.len().saturating_sub(1))
        .map(|c| {
            let mut v = json!({ "curve": c + 1, "condition": name(m.crease(c)) });
            // A stated fold (`folds`): its direction and the mean angle asked for.
            if let Some(f) = m.folds.get(c - 1).copied().flatten() {
                v["fold"] = json!(if f.valley { "valley" } else { "mountain" });
                if let Some(a) = f.angle {
                    v["fold_angle_deg"] = json!(r9(a.to_degrees()));
                }
            }
            v
        })
        .collect();
    let figures: serde_json::Map<String, Value> = flat
        .surface
        .figures
        .iter()
        .map(|(k, v)| (k.to_string(), json!(super::report::sig6(*v))))
        .collect();
    Some(json!({
        "name": flat.surface.name,
        "degree": m.basis.degree(),
        "closed": m.basis.closed(),
        "knots": m.basis.knots().iter().map(|k| r9(*k)).collect::<Vec<_>>(),
        "curves": curves,
        "apex": m.apex.as_ref().map(pt3),
        "fixed": m.fixed.iter().map(|&(c, i)| json!([c + 1, i + 1])).collect::<Vec<_>>(),
        "strips": strips,
        "creases": creases,
        "figures": figures,
        "development": {
            "params": d.params.iter().map(|u| r9(*u)).collect::<Vec<_>>(),
            "curves": development(flat, &d.curve_verts),
        },
    }))
}

/// Each curve's sampled vertices on the flat pieces: per curve and piece, the polylines (a
/// closed curve's seam vertex lies on the piece twice, once at each end).
fn development(flat: &Flat, curve_verts: &[Vec<usize>]) -> Vec<Value> {
    // Every face edge (v, w) with its two flat ends and its piece.
    let mut edges: std::collections::BTreeMap<(usize, usize), (DVec2, DVec2, usize)> =
        Default::default();
    for (f, face) in flat.surface.mesh.faces.iter().enumerate() {
        let island = flat.face_island.get(f).copied().unwrap_or(0);
        let n = face.verts.len();
        for i in 0..n {
            let (v, w) = (face.verts[i], face.verts[(i + 1) % n]);
            if let Some(c) = flat.face_2d.get(f) {
                let (p, q) = (c[i], c[(i + 1) % n]);
                edges.entry((v, w)).or_insert((p, q, island));
                edges.entry((w, v)).or_insert((q, p, island));
            }
        }
    }
    let curves = flat
        .surface
        .spline
        .as_ref()
        .map_or(0, |d| d.model.curves.len());
    let mut out = Vec::new();
    for (c, verts) in curve_verts.iter().enumerate().take(curves) {
        let mut run: Vec<DVec2> = Vec::new();
        let mut piece = 0;
        let mut flush = |run: &mut Vec<DVec2>, piece: usize| {
            if run.len() > 1 {
                let pts: Vec<Value> = run.iter().map(|p| json!([r9(p.x), r9(p.y)])).collect();
                out.push(json!({ "curve": c + 1, "piece": piece + 1, "points": pts }));
            }
            run.clear();
        };
        for w in verts.windows(2) {
            let Some(&(p, q, island)) = edges.get(&(w[0], w[1])) else {
                flush(&mut run, piece);
                continue;
            };
            let joined = island == piece && run.last().is_some_and(|l| l.distance(p) <= 1e-9);
            if !joined {
                flush(&mut run, piece);
                run.push(p);
                piece = island;
            }
            run.push(q);
        }
        flush(&mut run, piece);
    }
    out
}
