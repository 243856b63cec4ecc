//! Issue 6 acceptance: developable boundary triangulations (Rose et al.) — triangulation
//! invariants, planar boundaries, the example patterns' figures, darts, holes, rulings, and bad
//! input through the CLI (exit 1, one line naming the key and line).

mod common;
use common::*;
use flatcut::flatten::{unfold, UnfoldOptions};
use flatcut::geom::mesh::Mesh;
use flatcut::surface::boundary::{triangulate, BoundaryError, Dart, Input, Options};
use flatcut::surface::Surface;
use glam::{DQuat, DVec3};
use std::collections::HashMap;
use std::f64::consts::{PI, TAU};

fn csv(name: &str) -> Vec<DVec3> {
    flatcut::geom::curve::read_csv(&manifest(&format!("patterns/{name}.csv"))).expect("csv")
}

/// Boundary triangulation invariants: every face a triangle over boundary vertices, every edge
/// used once (boundary) or twice in opposite directions (interior), the boundary edges exactly
/// the loops' edges in their direction (holes: either direction), one boundary component per
/// loop, and an Euler characteristic of a disk with holes.
fn check_boundary_triangulation(mesh: &Mesh, loops: &[Vec<usize>]) {
    let mut directed: HashMap<(usize, usize), usize> = HashMap::new();
    for f in &mesh.faces {
        assert_eq!(f.verts.len(), 3);
        let v = &f.verts;
        assert!(v[0] != v[1] && v[1] != v[2] && v[0] != v[2], "degenerate face {v:?}");
        for k in 0..3 {
            *directed.entry((v[k], v[(k + 1) % 3])).or_default() += 1;
        }
    }
    for (&(a, b), &c) in &directed {
        assert_eq!(c, 1, "directed edge {a}->{b} used {c} times (not manifold/oriented)");
    }
    let boundary: Vec<(usize, usize)> = directed
        .keys()
        .filter(|(a, b)| !directed.contains_key(&(*b, *a)))
        .copied()
        .collect();
    let mut expected: Vec<(usize, usize)> = Vec::new();
    for (l, ids) in loops.iter().enumerate() {
        for k in 0..ids.len() {
            let (a, b) = (ids[k], ids[(k + 1) % ids.len()]);
            if l == 0 || directed.contains_key(&(a, b)) {
                expected.push((a, b));
            } else {
                expected.push((b, a));
            }
        }
    }
    let mut got = boundary.clone();
    got.sort_unstable();
    expected.sort_unstable();
    assert_eq!(got, expected, "the boundary is exactly the input loops");
    // No interior vertices: every vertex used is on a loop.
    let on_loop: std::collections::HashSet<usize> = loops.iter().flatten().copied().collect();
    for f in &mesh.faces {
        for v in &f.verts {
            assert!(on_loop.contains(v), "interior vertex {v}");
        }
    }
    let n: usize = loops.iter().map(|l| l.len()).sum();
    let e = directed.len() - boundary.len() / 2 - boundary.len() / 2 + boundary.len();
    let e = (directed.len() + boundary.len()) / 2;
    let _ = e;
    let edges = (directed.len() + boundary.len()) / 2;
    let euler = n as i64 - edges as i64 + mesh.faces.len() as i64;
    assert_eq!(euler, 2 - loops.len() as i64 - (loops.len() as i64 - 1), "Euler χ");
}

fn surface(mesh: Mesh) -> Surface {
    Surface {
        name: "b".into(),
        source: "b".into(),
        mesh,
        ..Default::default()
    }
}

/// Unfold and check every edge length to 1e-9 relative; returns the flat.
fn check_unfolds(mesh: &Mesh) -> flatcut::flatten::Flat {
    let flat = unfold(surface(mesh.clone()), &UnfoldOptions::default()).expect("unfolds");
    for (f, face) in mesh.faces.iter().enumerate() {
        for i in 0..3 {
            let l3 = mesh.vertices[face.verts[i]].distance(mesh.vertices[face.verts[(i + 1) % 3]]);
            let l2 = flat.face_2d[f][i].distance(flat.face_2d[f][(i + 1) % 3]);
            assert!((l3 - l2).abs() <= 1e-9 * l3, "face {f} edge {i}: {l3} vs {l2}");
        }
    }
    flat
}

fn one_loop(n: usize) -> Vec<Vec<usize>> {
    vec![(0..n).collect()]
}

#[test]
fn boundary_patterns_are_boundary_triangulations_with_figures() {
    for (name, min_convex) in [
        ("taco", 0.9),
        ("tulip-petal", 0.9),
        ("gazebo-roof", 0.0),
        ("shoe-upper", 0.0),
    ] {
        let pts = csv(name);
        let n = pts.len();
        let out = triangulate(
            &Input {
                loops: vec![pts.clone()],
                ..Default::default()
            },
            &Options::default(),
        )
        .unwrap();
        assert_eq!(out.mesh.vertices, pts, "{name}: vertices are the input points");
        check_boundary_triangulation(&out.mesh, &one_loop(n));
        assert_eq!(out.mesh.faces.len(), n - 2);
        check_unfolds(&out.mesh);
        let f = &out.figures;
        eprintln!(
            "{name}: {n} points, {} interior triangles, {}/{} locally convex ({:.3}), largest dihedral {:.2}°, fairness {:.4}, {} iterations, {:.3} s, warnings {:?}",
            f.interior_triangles,
            f.convex_edges,
            f.interior_edges,
            f.convex_fraction(),
            f.largest_dihedral_deg,
            f.fairness,
            f.iterations,
            f.seconds,
            out.warnings
        );
        assert!(
            f.convex_fraction() >= min_convex,
            "{name}: locally convex fraction {}",
            f.convex_fraction()
        );
        assert!(out.warnings.is_empty(), "{name}: {:?}", out.warnings);
    }
}
