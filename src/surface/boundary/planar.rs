//! A planar loop needs no search: its developable is the flat polygon it bounds. Rose et al.
//! assume a non-planar polyline (a planar one makes every convex hull flat, where the chart
//! search has nothing to choose between); here one loop without darts or rulings whose points
//! all lie within `PLANAR_TOL` × its size of their mean plane is ear-clipped in that plane
//! ([`crate::geom::polygon::triangulate`]), every dihedral angle 0.
//!
//! Choices: the plane is the Newell normal through the centroid (exact for a planar polygon,
//! stable for a nearly planar one); the tolerance is relative (1e-6, 0.2 µm on a 200 mm loop),
//! well below what a cutter can tell apart, well above rounding in the input's coordinates.

use super::figures::{figures, to_mesh};
use super::loops::Prepared;
use super::{Input, Output};
use glam::{DVec2, DVec3};

/// Points off the mean plane by at most this fraction of the loop's size count as planar.
const PLANAR_TOL: f64 = 1e-6;

/// The loop's plane as (origin, unit normal), when `points` lie in one within the tolerance.
fn plane(points: &[DVec3]) -> Option<(DVec3, DVec3)> {
    let n = points.len();
    let mut normal = DVec3::ZERO;
    for i in 0..n {
        let (p, q) = (points[i], points[(i + 1) % n]);
        normal += DVec3::new(
            (p.y - q.y) * (p.z + q.z),
            (p.z - q.z) * (p.x + q.x),
            (p.x - q.x) * (p.y + q.y),
        );
    }
    let normal = normal.try_normalize()?;
    let origin = points.iter().copied().sum::<DVec3>() / n as f64;
    let size = super::checks::size(points);
    let off = points
        .iter()
        .map(|p| (*p - origin).dot(normal).abs())
        .fold(0.0, f64::max);
    (off <= PLANAR_TOL * size).then_some((origin, normal))
}

/// The flat triangulation of a single planar loop, or `None` when the input is not one.
pub(super) fn planar(input: &Input, prep: &Prepared) -> Option<Output> {
    if input.loops.len() != 1 || !input.darts.is_empty() || !input.rulings.is_empty() {
        return None;
    }
    if prep.loop_ids.len() != 1 || prep.loop_ids[0].len() != prep.verts.len() {
        return None;
    }
    let ids = &prep.loop_ids[0];
    let pts: Vec<DVec3> = ids.iter().map(|&v| prep.verts[v]).collect();
    let (origin, normal) = plane(&pts)?;
    let u = normal.any_orthonormal_vector();
    let w = normal.cross(u);
    let flat: Vec<DVec2> = pts
        .iter()
        .map(|p| DVec2::new((*p - origin).dot(u), (*p - origin).dot(w)))
        .collect();
    let faces: Vec<[usize; 3]> = crate::geom::polygon::triangulate(&flat)
        .iter()
        .map(|t| t.map(|k| ids[k]))
        .collect();
    if faces.len() + 2 != ids.len() {
        return None;
    }
    let mesh = to_mesh(&prep.verts, &faces);
    let figures = figures(&prep.verts, &faces, &prep.input_edges, &prep.loop_ids);
    Some(Output {
        mesh,
        figures,
        alternatives: Vec::new(),
        warnings: Vec::new(),
    })
}
