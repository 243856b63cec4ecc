//! Polygon meshes and their edge adjacency, Newell normals ([`newell`]) and signed dihedral
//! angles ([`Mesh::signed_dihedral`]).
//!
//! A [`Mesh`] keeps polygon faces as they were modelled (a planar quad stays one face) with the
//! source line of each face, so that later stages can name it in errors. [`Topology`] lists the
//! undirected edges and, for each, the face corners that use it: corner `i` of a face is the
//! directed edge from `verts[i]` to `verts[(i + 1) % n]`.
//!
//! Choices: edges are keyed by their sorted vertex pair, so two faces share an edge exactly when
//! they share both vertex indices (vertices are welded at import, see `surface::obj`).

use glam::DVec3;
use std::collections::HashMap;

/// A polygon face: vertex indices in order (counter-clockwise seen from outside once the mesh
/// is oriented), and the 1-based line of the source file it came from, when known.
#[derive(Debug, Clone, PartialEq)]
pub struct Face {
    pub verts: Vec<usize>,
    pub line: Option<usize>,
}

/// Vertices in millimetres and polygon faces.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Mesh {
    pub vertices: Vec<DVec3>,
    pub faces: Vec<Face>,
}

/// One undirected edge: its two vertices (sorted) and the (face, corner) pairs that use it.
#[derive(Debug, Clone, PartialEq)]
pub struct Edge {
    pub verts: [usize; 2],
    pub uses: Vec<(usize, usize)>,
}

/// Edge adjacency of a mesh.
#[derive(Debug, Clone, PartialEq)]
pub struct Topology {
    pub edges: Vec<Edge>,
    /// For each face, the edge id of each corner.
    pub face_edges: Vec<Vec<usize>>,
}

/// Newell normal of a closed polygon: the sum of `p[i] × p[i + 1]` (indices cyclic). Its
/// direction is the polygon's normal (counter-clockwise seen from its tip), its length twice
/// the area of the (possibly non-planar) polygon's projection on the plane across it.
/// Axis-aligned bounding box (min, max) of 3D points; `None` for none.
pub fn bounds3<'a>(points: impl IntoIterator<Item = &'a DVec3>) -> Option<(DVec3, DVec3)> {
    let mut it = points.into_iter();
    let first = *it.next()?;
    Some(it.fold((first, first), |(lo, hi), p| (lo.min(*p), hi.max(*p))))
}

pub fn newell(p: &[DVec3]) -> DVec3 {
    let mut n = DVec3::ZERO;
    for i in 0..p.len() {
        n += p[i].cross(p[(i + 1) % p.len()]);
    }
    n
}

impl Mesh {
    /// A mesh of the given vertices and polygon faces (vertex indices, no source lines).
    pub fn from_polygons<F: AsRef<[usize]>>(vertices: Vec<DVec3>, faces: &[F]) -> Mesh {
        Mesh {
            vertices,
            faces: faces
                .iter()
                .map(|f| Face {
                    verts: f.as_ref().to_vec(),
                    line: None,
                })
                .collect(),
        }
    }

    /// Newell normal of a face: its direction is the face normal, its length twice the area of
    /// the (possibly non-planar) polygon's projection.
    pub fn newell(&self, f: usize) -> DVec3 {
        newell(&self.face_points(f))
    }

    /// Area of a face (of its projection on the best plane for non-planar polygons).
    pub fn face_area(&self, f: usize) -> f64 {
        0.5 * self.newell(f).length()
    }

    /// Area of the whole mesh: its faces' areas summed ([`Mesh::face_area`]).
    pub fn area(&self) -> f64 {
        (0..self.faces.len()).map(|f| self.face_area(f)).sum()
    }

    /// Unit normal of a face, or zero for a degenerate face.
    pub fn face_normal(&self, f: usize) -> DVec3 {
        self.newell(f).normalize_or_zero()
    }

    /// Corner positions of a face.
    pub fn face_points(&self, f: usize) -> Vec<DVec3> {
        self.faces[f]
            .verts
            .iter()
            .map(|&v| self.vertices[v])
            .collect()
    }

    /// Edge adjacency.
    pub fn topology(&self) -> Topology {
        let mut index: HashMap<(usize, usize), usize> = HashMap::new();
        let mut edges: Vec<Edge> = Vec::new();
        let mut face_edges = Vec::with_capacity(self.faces.len());
        for (f, face) in self.faces.iter().enumerate() {
            let n = face.verts.len();
            let mut ids = Vec::with_capacity(n);
            for i in 0..n {
                let a = face.verts[i];
                let b = face.verts[(i + 1) % n];
                let key = (a.min(b), a.max(b));
                let id = *index.entry(key).or_insert_with(|| {
                    edges.push(Edge {
                        verts: [key.0, key.1],
                        uses: Vec::new(),
                    });
                    edges.len() - 1
                });
                edges[id].uses.push((f, i));
                ids.push(id);
            }
            face_edges.push(ids);
        }
        Topology { edges, face_edges }
    }

    /// Axis-aligned bounding box (min, max); zero for an empty mesh.
    pub fn bounds(&self) -> (DVec3, DVec3) {
        bounds3(&self.vertices).unwrap_or((DVec3::ZERO, DVec3::ZERO))
    }

    /// Signed bend angle (radians) at the edge of corner `i` of face `f`, shared with face
    /// `g`: the angle between their normals, positive where the surface is convex (a mountain
    /// fold seen from the printed side, i.e. `n_f × n_g` along the edge as `f` runs it);
    /// `None` when a normal is degenerate.
    pub fn signed_dihedral(&self, f: usize, i: usize, g: usize) -> Option<f64> {
        let nf = self.face_normal(f);
        let ng = self.face_normal(g);
        let (a, b) = Topology::corner_verts(self, f, i);
        let dir = self.vertices[b] - self.vertices[a];
        let angle = nf.angle_between(ng);
        if !angle.is_finite() {
            return None;
        }
        Some(if nf.cross(ng).dot(dir) >= 0.0 {
            angle
        } else {
            -angle
        })
    }
}

impl Topology {
    /// Directed start and end vertex of corner `i` of face `f`.
    pub fn corner_verts(mesh: &Mesh, f: usize, i: usize) -> (usize, usize) {
        let v = &mesh.faces[f].verts;
        (v[i], v[(i + 1) % v.len()])
    }

    /// Number of boundary loops (chains of edges used by exactly one face).
    pub fn boundary_loops(&self, mesh: &Mesh) -> usize {
        // Boundary edges as directed (a -> b) in their face; walk by start vertex.
        let mut next: HashMap<usize, Vec<usize>> = HashMap::new();
        let mut count_edges = 0;
        for e in &self.edges {
            if e.uses.len() == 1 {
                let (f, i) = e.uses[0];
                let (a, b) = Self::corner_verts(mesh, f, i);
                next.entry(a).or_default().push(b);
                count_edges += 1;
            }
        }
        let mut loops = 0;
        let mut starts: Vec<usize> = next.keys().copied().collect();
        starts.sort_unstable();
        let mut remaining = count_edges;
        for s in starts {
            while let Some(b) = next.get_mut(&s).and_then(|v| v.pop()) {
                loops += 1;
                remaining -= 1;
                let mut cur = b;
                while cur != s {
                    match next.get_mut(&cur).and_then(|v| v.pop()) {
                        Some(n) => {
                            remaining -= 1;
                            cur = n;
                        }
                        None => break,
                    }
                }
            }
        }
        debug_assert_eq!(remaining, 0);
        loops
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn quad_pair() -> Mesh {
        Mesh {
            vertices: vec![
                DVec3::new(0.0, 0.0, 0.0),
                DVec3::new(1.0, 0.0, 0.0),
                DVec3::new(1.0, 1.0, 0.0),
                DVec3::new(0.0, 1.0, 0.0),
                DVec3::new(2.0, 0.0, 0.0),
                DVec3::new(2.0, 1.0, 0.0),
            ],
            faces: vec![
                Face {
                    verts: vec![0, 1, 2, 3],
                    line: None,
                },
                Face {
                    verts: vec![1, 4, 5, 2],
                    line: None,
                },
            ],
        }
    }

    #[test]
    fn topology_counts_shared_and_boundary_edges() {
        let m = quad_pair();
        let t = m.topology();
        assert_eq!(t.edges.len(), 7);
        let shared: Vec<_> = t.edges.iter().filter(|e| e.uses.len() == 2).collect();
        assert_eq!(shared.len(), 1);
        assert_eq!(shared[0].verts, [1, 2]);
        assert_eq!(t.boundary_loops(&m), 1);
        assert!((m.face_area(0) - 1.0).abs() < 1e-12);
        assert!((m.face_normal(1) - DVec3::Z).length() < 1e-12);
    }
}
