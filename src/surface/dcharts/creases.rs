//! Which meshes are segmented, and what a pattern scores inside a chart: [`is_smooth`] tells a
//! mesh sampled from a smooth surface (segmented into charts) from a polyhedral model
//! (unfolded face by face), and [`creases`] lists the edges that bend sharply enough to be
//! scored as fold lines where a piece keeps both their faces (the thesis' §5.3 pattern keeps chart boundaries as cuts
//! and says nothing of creases inside a chart: they are flatcut's choice, see [`CREASE_DEG`]).

use crate::geom::mesh::Mesh;
use crate::surface::Bend;

/// Whether a mesh is smooth, i.e. better segmented into charts than unfolded face by face
/// (issue 20): at least [`GENTLE_SHARE`] of the edges that bend at all (0.5° or more) bend
/// gently (under [`GENTLE_DEG`]), and at least 20 do. Angles only, so the choice does not depend
/// on the model's size.
/// - Meshes sampled from smooth surfaces bend a little at almost every edge (homer, knot);
///   coarse organic models (cow, pig) still have a third of their bends under 10°.
/// - CAD parts made of developable patches (fandisk, a turbine blade) are flat at most edges,
///   but where they bend they bend gently: charts follow their patches, where an exact
///   unfolding scores every sampling edge of a curved patch as a fold.
/// - Polyhedral models (a house, a cube, a 24-facet cone, a 24 × 12 UV sphere) bend only by
///   their facets' angles, 15° and more: their folds are the model and are kept.
pub fn is_smooth(mesh: &Mesh) -> bool {
    bends(mesh).smooth()
}

/// How a mesh bends: its edges that bend at all, and those that bend gently.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Bends {
    /// Interior edges bending by 0.5° or more.
    pub bent: usize,
    /// Of those, the ones bending by less than [`GENTLE_DEG`].
    pub gentle: usize,
}

impl Bends {
    /// The share of bent edges that bend gently (0 when none bends).
    pub fn gentle_share(&self) -> f64 {
        if self.bent == 0 {
            0.0
        } else {
            self.gentle as f64 / self.bent as f64
        }
    }

    /// See [`is_smooth`].
    pub fn smooth(&self) -> bool {
        self.gentle >= 20 && self.gentle as f64 >= GENTLE_SHARE * self.bent as f64
    }
}

/// The bends of a mesh (see [`is_smooth`]).
pub fn bends(mesh: &Mesh) -> Bends {
    let topo = mesh.topology();
    let mut b = Bends { bent: 0, gentle: 0 };
    for e in &topo.edges {
        if let [(f, _), (g, _)] = e.uses[..] {
            let a = mesh
                .face_normal(f)
                .angle_between(mesh.face_normal(g))
                .to_degrees();
            if a >= 0.5 {
                b.bent += 1;
                if a < GENTLE_DEG {
                    b.gentle += 1;
                }
            }
        }
    }
    b
}

/// A bend under this many degrees is the sampling of a smooth surface ([`is_smooth`]).
pub const GENTLE_DEG: f64 = 10.0;
/// Share of the bent edges that must bend gently for a mesh to be smooth ([`is_smooth`]).
pub const GENTLE_SHARE: f64 = 0.3;

/// Edges that bend by more than `min_deg` degrees: the creases a pattern should score where
/// the piece keeps both faces (the smooth bends in between need no fold line). Edges between
/// two charts are listed too, since the flatten stage may merge the charts (the pattern stage
/// folds only joined edges). Signed angle in degrees, positive for a mountain (convex seen
/// from the printed side).
pub(super) fn creases(mesh: &Mesh, min_deg: f64) -> Vec<Bend> {
    let topo = mesh.topology();
    let mut out = Vec::new();
    for e in &topo.edges {
        let [(f, i), (g, _)] = e.uses[..] else {
            continue;
        };
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
