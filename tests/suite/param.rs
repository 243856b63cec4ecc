//! Parameterisation of disk charts (flatten::param) and its distortion figures
//! (flatten::distortion): an exactly developable cone flattens isometrically with every method,
//! the mushroom (not developable, one disk) beats libigl's LSCM figure, bad charts are refused
//! with messages that name the face and its line.

use crate::common::*;
use flatcut::flatten::distortion;
use flatcut::flatten::{parameterize, ChartParam, ParamError, ParamMethod};
use flatcut::geom::mesh::{Face, Mesh};
use glam::{DVec2, DVec3};
use std::f64::consts::PI;

const METHODS: [ParamMethod; 3] = [ParamMethod::Lscm, ParamMethod::Abf, ParamMethod::Best];

fn face(verts: &[usize], line: usize) -> Face {
    Face {
        verts: verts.to_vec(),
        line: Some(line),
    }
}

/// A cone frustum (apex at the origin, half-angle `half`, radii along the rulings `r0..r1`)
/// triangulated between `n` rulings and `m` rings, cut open along ruling 0 (the last ruling
/// repeats its positions with its own vertices). With `apex`, the innermost ring is the apex.
/// Every triangle lies in the plane of the apex and two rulings, so it is exactly developable.
fn cone(n: usize, m: usize, half: f64, r0: f64, r1: f64, apex: bool) -> Mesh {
    let mut vertices = Vec::new();
    let mut faces = Vec::new();
    let id = |i: usize, j: usize| i * (n + 1) + j;
    for i in 0..=m {
        let r = r0 + (r1 - r0) * i as f64 / m as f64;
        for j in 0..=n {
            let phi = 2.0 * PI * j as f64 / n as f64;
            vertices
                .push(DVec3::new(half.sin() * phi.cos(), half.sin() * phi.sin(), half.cos()) * r);
        }
    }
    for i in 0..m {
        for j in 0..n {
            let (a, b, c, d) = (id(i, j), id(i, j + 1), id(i + 1, j + 1), id(i + 1, j));
            if apex && i == 0 {
                // Ring 0 collapses to the apex: one triangle per sector.
                faces.push(face(&[a, c, d], faces.len() + 1));
                continue;
            }
            // Alternate diagonals so that no direction is favoured.
            if (i + j) % 2 == 0 {
                faces.push(face(&[a, b, c], faces.len() + 1));
                faces.push(face(&[a, c, d], faces.len() + 1));
            } else {
                faces.push(face(&[a, b, d], faces.len() + 1));
                faces.push(face(&[b, c, d], faces.len() + 1));
            }
        }
    }
    let mut mesh = Mesh { vertices, faces };
    if apex {
        // Weld ring 0 into one apex vertex (index 0), leaving the others unused.
        for f in &mut mesh.faces {
            for v in &mut f.verts {
                if *v <= n {
                    *v = 0;
                }
            }
        }
    }
    mesh
}

fn all_faces(mesh: &Mesh) -> Vec<usize> {
    (0..mesh.faces.len()).collect()
}

/// Largest relative difference between a 3D edge (or diagonal) and its flat image.
fn worst_length_error(mesh: &Mesh, p: &ChartParam) -> f64 {
    let mut worst = 0.0f64;
    for (k, &f) in p.faces.iter().enumerate() {
        let v = &mesh.faces[f].verts;
        for i in 0..v.len() {
            for j in i + 1..v.len() {
                let d3 = mesh.vertices[v[i]].distance(mesh.vertices[v[j]]);
                let d2 = p.uv[k][i].distance(p.uv[k][j]);
                worst = worst.max((d3 - d2).abs() / d3);
            }
        }
    }
    worst
}

fn assert_no_nan(p: &ChartParam) {
    for c in &p.uv {
        for q in c {
            assert!(q.is_finite(), "{q}");
        }
    }
    let s = p.stretch;
    for x in [s.l2, s.linf, s.shear_l2, s.area_2d, s.area_3d] {
        assert!(x.is_finite(), "{s:?}");
    }
}

#[test]
fn developable_cone_flattens_isometrically_with_every_method() {
    for (mesh, what) in [
        (cone(48, 12, 0.5, 40.0, 120.0, false), "frustum"),
        (cone(32, 10, 0.9, 0.0, 80.0, true), "cone with apex"),
    ] {
        let faces = all_faces(&mesh);
        for method in METHODS {
            let p = parameterize(&mesh, &faces, method).expect("parameterize");
            assert_no_nan(&p);
            let s = p.stretch;
            println!("{what} {method:?} -> {:?}: {s:?}", p.method);
            assert!((s.l2 - 1.0).abs() < 1e-6, "{what} {method:?}: L2 {}", s.l2);
            assert!(
                (s.linf - 1.0).abs() < 1e-6,
                "{what} {method:?}: Linf {}",
                s.linf
            );
            assert!(s.shear_l2 < 1e-6);
            assert_eq!(s.flipped, 0);
            // The layout is isometric itself, not only after normalisation.
            let err = worst_length_error(&mesh, &p);
            assert!(err < 1e-9, "{what} {method:?}: edge length error {err:e}");
            assert!((s.area_2d - s.area_3d).abs() < 1e-9 * s.area_3d);
            // Counter-clockwise, starting at the origin.
            for c in &p.uv {
                assert!(flatcut::geom::polygon::signed_area(c) > 0.0);
            }
            let lo =
                p.uv.iter()
                    .flatten()
                    .fold(DVec2::INFINITY, |a, b| a.min(*b));
            assert!(lo.length() < 1e-9, "{lo}");
            if method != ParamMethod::Best {
                assert_eq!(p.method, method);
            }
        }
    }
}

#[test]
fn results_are_deterministic() {
    let mesh = cone(24, 6, 0.7, 10.0, 50.0, false);
    // A bump makes it non-developable so the solvers have work to do.
    let mut bumpy = mesh.clone();
    for (k, v) in bumpy.vertices.iter_mut().enumerate() {
        *v += DVec3::Z * (0.7 * ((k * 7919) % 13) as f64 / 13.0);
    }
    let faces = all_faces(&bumpy);
    for method in METHODS {
        let a = parameterize(&bumpy, &faces, method).expect("a");
        let b = parameterize(&bumpy, &faces, method).expect("b");
        assert_eq!(a, b);
        assert_no_nan(&a);
        assert_eq!(a.stretch.flipped, 0);
        assert!(a.stretch.l2 > 1.0);
    }
}

#[test]
fn polygon_faces_of_a_flat_grid_keep_their_shape() {
    // 4 x 3 grid of unit squares (quads) plus one L-shaped hexagon: flat, so isometric.
    let mut vertices = Vec::new();
    for y in 0..4 {
        for x in 0..6 {
            vertices.push(DVec3::new(x as f64 * 10.0, y as f64 * 10.0, 0.0));
        }
    }
    let id = |x: usize, y: usize| y * 6 + x;
    let mut faces = Vec::new();
    for y in 0..3 {
        for x in 0..4 {
            faces.push(face(
                &[id(x, y), id(x + 1, y), id(x + 1, y + 1), id(x, y + 1)],
                faces.len() + 1,
            ));
        }
    }
    // Non-convex hexagon over columns 4..6, rows 0..2 minus the top-right square.
    faces.push(face(
        &[
            id(4, 0),
            id(5, 0),
            id(5, 1),
            id(5, 2), /* reflex below */
            id(4, 2),
            id(4, 1),
        ],
        99,
    ));
    let mesh = Mesh { vertices, faces };
    for method in METHODS {
        let p = parameterize(&mesh, &all_faces(&mesh), method).expect("grid");
        assert!((p.stretch.l2 - 1.0).abs() < 1e-9, "{:?}", p.stretch);
        assert!(worst_length_error(&mesh, &p) < 1e-9);
        assert_eq!(p.uv.last().map(|c| c.len()), Some(6));
    }
}

#[test]
fn mushroom_disk_beats_libigl_lscm() {
    require_shared!();
    let path = shared_data("meshes/mushroom.obj");
    let raw = flatcut::surface::obj::read(&path).expect("read mushroom");
    let (mesh, _warnings) = flatcut::surface::obj::validate(raw, 100.0).expect("validate");
    assert_eq!(mesh.faces.len(), 4608);
    // One component, one boundary loop: a disk.
    let topo = mesh.topology();
    assert_eq!(topo.boundary_loops(&mesh), 1);
    let euler = mesh.vertices.len() as i64 - topo.edges.len() as i64 + mesh.faces.len() as i64;
    assert_eq!(euler, 1);
    let faces = all_faces(&mesh);
    let mut figures = Vec::new();
    for method in METHODS {
        let p = parameterize(&mesh, &faces, method).expect("mushroom");
        assert_no_nan(&p);
        println!(
            "mushroom {method:?} -> {:?}: L2 {:.4} Linf {:.4} shear {:.4} flipped {}",
            p.method, p.stretch.l2, p.stretch.linf, p.stretch.shear_l2, p.stretch.flipped
        );
        figures.push(p.stretch);
    }
    let best = figures[2];
    assert_eq!(best.flipped, 0);
    assert!(
        best.l2 < 2.585,
        "L2 {} does not beat libigl's LSCM 2.585",
        best.l2
    );
    // Best keeps the better of the two.
    assert!(
        best.l2 <= figures[0].l2.min(figures[1].l2) || figures[0].flipped + figures[1].flipped > 0
    );
}

#[test]
fn angle_defect_is_zero_on_the_developable_cone_and_sums_by_gauss_bonnet() {
    let mesh = cone(32, 8, 0.6, 20.0, 60.0, false);
    let d = distortion::angle_defect(&mesh);
    assert!(d.iter().all(|x| x.abs() < 1e-12));
    // A closed octahedron: total defect 4π, each vertex 2π − 4·(π/3).
    let o = Mesh {
        vertices: vec![
            DVec3::X,
            DVec3::Y,
            -DVec3::X,
            -DVec3::Y,
            DVec3::Z,
            -DVec3::Z,
        ],
        faces: [
            [0, 1, 4],
            [1, 2, 4],
            [2, 3, 4],
            [3, 0, 4],
            [1, 0, 5],
            [2, 1, 5],
            [3, 2, 5],
            [0, 3, 5],
        ]
        .iter()
        .map(|f| face(f, 1))
        .collect(),
    };
    let d = distortion::angle_defect(&o);
    assert!((d.iter().sum::<f64>() - 4.0 * PI).abs() < 1e-12);
    assert!(d.iter().all(|x| (x - 2.0 * PI / 3.0).abs() < 1e-12));
}

// ---- bad charts ----

fn err(mesh: &Mesh, faces: &[usize]) -> ParamError {
    for method in METHODS {
        assert!(
            parameterize(mesh, faces, method).is_err(),
            "{method:?} accepted it"
        );
    }
    parameterize(mesh, faces, ParamMethod::Best).expect_err("refused")
}

fn square_grid(n: usize) -> Mesh {
    let mut vertices = Vec::new();
    for y in 0..=n {
        for x in 0..=n {
            vertices.push(DVec3::new(x as f64, y as f64, 0.0));
        }
    }
    let id = |x: usize, y: usize| y * (n + 1) + x;
    let mut faces = Vec::new();
    for y in 0..n {
        for x in 0..n {
            let l = faces.len();
            faces.push(face(&[id(x, y), id(x + 1, y), id(x + 1, y + 1)], 10 + l));
            faces.push(face(&[id(x, y), id(x + 1, y + 1), id(x, y + 1)], 11 + l));
        }
    }
    Mesh { vertices, faces }
}

#[test]
fn degenerate_triangle_is_refused_naming_face_and_line() {
    let mut m = square_grid(2);
    // A sliver: vertex 9 almost on the edge 0-1 (angle at it ~ π, tip angles ~ 1e-4).
    m.vertices.push(DVec3::new(0.5, -1e-4, 0.0));
    m.faces.push(face(&[0, 9, 1], 77));
    let e = err(&m, &all_faces(&m));
    assert!(
        matches!(
            e,
            ParamError::Degenerate {
                face: 8,
                line: Some(77),
                ..
            }
        ),
        "{e:?}"
    );
    let msg = e.to_string();
    assert!(
        msg.contains("face 8") && msg.contains("line 77") && msg.contains("degenerate"),
        "{msg}"
    );
    // A zero-area face (repeated vertex) too.
    let mut m = square_grid(1);
    m.faces.push(face(&[0, 1, 1], 5));
    assert!(matches!(
        err(&m, &all_faces(&m)),
        ParamError::Degenerate { face: 2, .. }
    ));
}

#[test]
fn several_components_are_refused() {
    let mut m = square_grid(2);
    let base = m.vertices.len();
    for p in [
        DVec3::new(5.0, 0.0, 0.0),
        DVec3::new(6.0, 0.0, 0.0),
        DVec3::new(5.0, 1.0, 0.0),
    ] {
        m.vertices.push(p);
    }
    m.faces.push(face(&[base, base + 1, base + 2], 42));
    let e = err(&m, &all_faces(&m));
    assert!(
        matches!(
            e,
            ParamError::SeveralComponents {
                count: 2,
                face: 8,
                line: Some(42)
            }
        ),
        "{e:?}"
    );
    assert!(e.to_string().contains("2 separate components"), "{e}");
    // Touching at a single vertex is not connected either (and is a non-manifold vertex).
    let mut m = square_grid(1);
    m.vertices.push(DVec3::new(2.0, 1.0, 0.0));
    m.vertices.push(DVec3::new(2.0, 2.0, 0.0));
    m.faces.push(face(&[3, 4, 5], 9));
    let e = err(&m, &all_faces(&m));
    assert!(
        matches!(
            e,
            ParamError::SeveralComponents { .. } | ParamError::NonManifoldVertex { .. }
        ),
        "{e:?}"
    );
}

#[test]
fn non_manifold_edge_is_refused() {
    let mut m = square_grid(1);
    // A fin on the diagonal 0-3: third triangle on that edge.
    m.vertices.push(DVec3::new(0.5, 0.5, 1.0));
    m.faces.push(face(&[0, 3, 4], 31));
    let e = err(&m, &all_faces(&m));
    assert!(
        matches!(
            e,
            ParamError::NonManifoldEdge {
                face: 2,
                line: Some(31),
                a: 0,
                b: 3,
                count: 3
            }
        ),
        "{e:?}"
    );
    assert!(e.to_string().contains("non-manifold edge 0-3"), "{e}");
}

#[test]
fn closed_holed_and_miswound_charts_are_refused() {
    // Closed: a tetrahedron.
    let t = Mesh {
        vertices: vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z],
        faces: vec![
            face(&[0, 2, 1], 1),
            face(&[0, 1, 3], 2),
            face(&[1, 2, 3], 3),
            face(&[2, 0, 3], 4),
        ],
    };
    assert!(matches!(err(&t, &[0, 1, 2, 3]), ParamError::Closed { .. }));
    // The same with a face left out is a disk.
    let p = parameterize(&t, &[0, 1, 2], ParamMethod::Best).expect("open tetrahedron");
    assert_eq!(p.stretch.flipped, 0);
    // A hole: the 3 x 3 grid without its middle square.
    let g = square_grid(3);
    let ring: Vec<usize> = (0..18).filter(|&f| f / 2 != 4).collect();
    let e = err(&g, &ring);
    assert!(matches!(e, ParamError::Holes { loops: 2, .. }), "{e:?}");
    // Miswound: one triangle reversed.
    let mut g = square_grid(2);
    g.faces[3].verts.reverse();
    let e = err(&g, &all_faces(&g));
    assert!(matches!(e, ParamError::Inconsistent { .. }), "{e:?}");
    // Bad lists.
    let g = square_grid(1);
    assert_eq!(err(&g, &[]), ParamError::Empty);
    assert!(matches!(
        err(&g, &[0, 5]),
        ParamError::FaceOutOfRange { face: 5, count: 2 }
    ));
    assert!(matches!(
        err(&g, &[0, 1, 0]),
        ParamError::DuplicateFace { face: 0, .. }
    ));
    let mut g = square_grid(1);
    g.vertices[3].x = f64::NAN;
    assert!(matches!(
        err(&g, &[0, 1]),
        ParamError::BadVertex { vertex: 3, .. }
    ));
}

#[test]
fn cylinder_disk_flattens_nearly_isometrically() {
    require_shared!();
    // cylinder.obj is one disk (a single boundary loop, Euler characteristic 1).
    let path = shared_data("meshes/cylinder.obj");
    let raw = flatcut::surface::obj::read(&path).expect("read cylinder");
    let (mesh, _) = flatcut::surface::obj::validate(raw, 100.0).expect("validate");
    let faces = all_faces(&mesh);
    for method in METHODS {
        let p = parameterize(&mesh, &faces, method).expect("cylinder");
        assert_no_nan(&p);
        println!(
            "cylinder {method:?} -> {:?}: L2 {:.6} Linf {:.6} shear {:.2e} flipped {}",
            p.method, p.stretch.l2, p.stretch.linf, p.stretch.shear_l2, p.stretch.flipped
        );
        assert_eq!(p.stretch.flipped, 0);
    }
}
