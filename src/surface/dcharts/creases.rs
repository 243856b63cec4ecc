//! Which meshes are segmented, and what a pattern scores inside a chart: [`is_smooth`] tells a
//! mesh sampled from a smooth surface (segmented into charts) from a polyhedral model
//! (unfolded face by face), and [`creases`] lists the edges inside a chart that bend sharply
//! enough to be scored as fold lines (the thesis' §5.3 pattern keeps chart boundaries as cuts
//! and says nothing of creases inside a chart: they are flatcut's choice, see [`CREASE_DEG`]).

use crate::geom::mesh::Mesh;
use crate::surface::Bend;

/// Whether a mesh is smooth, i.e. better segmented into charts than unfolded face by face:
/// at least 30 % of its interior edges bend gently (between 0.5° and 20°). Polyhedral models
/// (flat panels, triangulated or not) bend only at a few sharp folds; meshes sampled from
/// smooth surfaces bend a little at almost every edge.
pub fn is_smooth(mesh: &Mesh) -> bool {
    let topo = mesh.topology();
    let mut interior = 0usize;
    let mut gentle = 0usize;
    for e in &topo.edges {
        if let [(f, _), (g, _)] = e.uses[..] {
            interior += 1;
            let a = mesh
                .face_normal(f)
                .angle_between(mesh.face_normal(g))
                .to_degrees();
            if (0.5..20.0).contains(&a) {
                gentle += 1;
            }
        }
    }
    interior >= 20 && gentle as f64 >= 0.3 * interior as f64
}

/// Edges inside a chart that bend by more than `min_deg` degrees: the creases a pattern should
/// score (the smooth bends in between need no fold line). Signed angle in degrees, positive for
/// a mountain (convex seen from the printed side).
pub(super) fn creases(mesh: &Mesh, chart: &[usize], min_deg: f64) -> Vec<Bend> {
    let topo = mesh.topology();
    let mut out = Vec::new();
    for e in &topo.edges {
        let [(f, i), (g, _)] = e.uses[..] else {
            continue;
        };
        if chart.get(f) != chart.get(g) {
            continue;
        }
        let Some(signed) = mesh.signed_dihedral(f, i, g) else {
            continue;
        };
        if signed.abs().to_degrees() <= min_deg {
            continue;
        }
        out.push(Bend {
            verts: e.verts,
            angle_deg: signed.to_degrees(),
        });
    }
    out
}

/// Bends above this many degrees inside a chart are creases, scored as fold lines; gentler
/// ones are the smooth bending of the material.
pub(super) const CREASE_DEG: f64 = 20.0;
