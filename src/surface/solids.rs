//! Small polyhedra for the example patterns in `patterns/` and for tests: a cube, a regular
//! tetrahedron, an n-facet lampshade (an open truncated cone made of planar trapezoids) and a
//! house-shaped box with a gable roof. All faces are planar polygons wound counter-clockwise
//! seen from outside; sizes in millimetres. [`to_obj`] writes a mesh as OBJ text with a
//! comment saying how it was made, so `patterns/*.obj` are generated, never hand-edited
//! (`cargo run --example make_patterns`).

use crate::geom::mesh::Mesh;
use glam::DVec3;
use std::fmt::Write;

fn mesh(vertices: Vec<DVec3>, faces: &[&[usize]]) -> Mesh {
    Mesh::from_polygons(vertices, faces)
}

/// An axis-aligned box `w × d × h`, six quads.
pub fn cuboid(w: f64, d: f64, h: f64) -> Mesh {
    let v = |x: f64, y: f64, z: f64| DVec3::new(x * w, y * d, z * h);
    mesh(
        vec![
            v(0., 0., 0.),
            v(1., 0., 0.),
            v(1., 1., 0.),
            v(0., 1., 0.),
            v(0., 0., 1.),
            v(1., 0., 1.),
            v(1., 1., 1.),
            v(0., 1., 1.),
        ],
        &[
            &[0, 3, 2, 1],
            &[4, 5, 6, 7],
            &[0, 1, 5, 4],
            &[1, 2, 6, 5],
            &[2, 3, 7, 6],
            &[3, 0, 4, 7],
        ],
    )
}

/// A regular tetrahedron with edge length `a`.
pub fn tetrahedron(a: f64) -> Mesh {
    let h = a * (2.0f64 / 3.0).sqrt();
    let r = a / 3.0f64.sqrt();
    let base: Vec<DVec3> = (0..3)
        .map(|k| {
            let t = k as f64 * std::f64::consts::TAU / 3.0;
            DVec3::new(r * t.cos(), r * t.sin(), 0.0)
        })
        .collect();
    mesh(
        vec![base[0], base[1], base[2], DVec3::new(0.0, 0.0, h)],
        &[&[0, 2, 1], &[0, 1, 3], &[1, 2, 3], &[2, 0, 3]],
    )
}

/// An open truncated cone (no top, no bottom) of `n` planar trapezoids between a bottom circle
/// of diameter `d_bottom` and a top circle of diameter `d_top`, `height` apart.
pub fn lampshade(n: usize, d_bottom: f64, d_top: f64, height: f64) -> Mesh {
    let n = n.max(3);
    let mut vertices = Vec::with_capacity(2 * n);
    for k in 0..n {
        let t = k as f64 * std::f64::consts::TAU / n as f64;
        vertices.push(DVec3::new(
            0.5 * d_bottom * t.cos(),
            0.5 * d_bottom * t.sin(),
            0.0,
        ));
    }
    for k in 0..n {
        let t = k as f64 * std::f64::consts::TAU / n as f64;
        vertices.push(DVec3::new(
            0.5 * d_top * t.cos(),
            0.5 * d_top * t.sin(),
            height,
        ));
    }
    let faces: Vec<Vec<usize>> = (0..n)
        .map(|k| vec![k, (k + 1) % n, n + (k + 1) % n, n + k])
        .collect();
    let refs: Vec<&[usize]> = faces.iter().map(|f| f.as_slice()).collect();
    mesh(vertices, &refs)
}

/// A closed box `w × d` with walls `wall` high and a gable roof whose ridge (along x) is at
/// `ridge` height: floor, two side walls, two pentagonal gable ends, two roof slopes.
pub fn house(w: f64, d: f64, wall: f64, ridge: f64) -> Mesh {
    let v = |x: f64, y: f64, z: f64| DVec3::new(x, y, z);
    mesh(
        vec![
            v(0., 0., 0.),
            v(w, 0., 0.),
            v(w, d, 0.),
            v(0., d, 0.),
            v(0., 0., wall),
            v(w, 0., wall),
            v(w, d, wall),
            v(0., d, wall),
            v(0., d / 2.0, ridge),
            v(w, d / 2.0, ridge),
        ],
        &[
            &[0, 3, 2, 1],
            &[0, 1, 5, 4],
            &[2, 3, 7, 6],
            &[1, 2, 6, 9, 5],
            &[3, 0, 4, 8, 7],
            &[4, 5, 9, 8],
            &[6, 7, 8, 9],
        ],
    )
}

/// OBJ text of a mesh, with a header comment.
pub fn to_obj(mesh: &Mesh, comment: &str) -> String {
    let mut s = String::new();
    for line in comment.lines() {
        let _ = writeln!(s, "# {line}");
    }
    for p in &mesh.vertices {
        let _ = writeln!(s, "v {} {} {}", fmt(p.x), fmt(p.y), fmt(p.z));
    }
    for f in &mesh.faces {
        let idx: Vec<String> = f.verts.iter().map(|v| (v + 1).to_string()).collect();
        let _ = writeln!(s, "f {}", idx.join(" "));
    }
    s
}

fn fmt(v: f64) -> String {
    let r = (v * 1e9).round() / 1e9;
    if r == 0.0 {
        "0".into()
    } else {
        format!("{r}")
    }
}

/// The example patterns: (file stem, mesh, how it was made).
pub fn examples() -> Vec<(&'static str, Mesh, &'static str)> {
    vec![
        (
            "cube",
            cuboid(100.0, 100.0, 100.0),
            "100 mm cube: six square faces",
        ),
        (
            "tetrahedron",
            tetrahedron(90.0),
            "regular tetrahedron, 90 mm edges",
        ),
        (
            "lampshade",
            lampshade(16, 200.0, 120.0, 150.0),
            "16-facet lampshade: open truncated cone, 200 mm bottom, 120 mm top, 150 mm high",
        ),
        (
            "house",
            house(80.0, 60.0, 60.0, 95.0),
            "house-shaped box: 80 x 60 mm floor, 60 mm walls, gable roof ridge at 95 mm",
        ),
    ]
}

/// Header comment of a generated pattern OBJ.
pub fn obj_comment(what: &str) -> String {
    format!("{what}\ngenerated by flatcut (src/surface/solids.rs); run `cargo run --example make_patterns` to remake")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn solids_are_closed_or_open_as_built_and_outward() {
        for (name, m, _) in examples() {
            let t = m.topology();
            assert!(t.edges.iter().all(|e| e.uses.len() <= 2), "{name}");
            let loops = t.boundary_loops(&m);
            assert_eq!(loops, if name == "lampshade" { 2 } else { 0 }, "{name}");
            // Every face planar and facing away from the centroid.
            let c = m.vertices.iter().copied().sum::<DVec3>() / m.vertices.len() as f64;
            for (f, face) in m.faces.iter().enumerate() {
                let n = m.face_normal(f);
                let p0 = m.vertices[face.verts[0]];
                for &v in &face.verts {
                    assert!((m.vertices[v] - p0).dot(n).abs() < 1e-9, "{name} face {f}");
                }
                assert!((p0 - c).dot(n) > 0.0, "{name} face {f} faces inwards");
            }
        }
    }

    #[test]
    fn committed_obj_files_are_up_to_date() {
        for (name, m, comment) in examples() {
            let path = format!("{}/patterns/{name}.obj", env!("CARGO_MANIFEST_DIR"));
            let on_disk = std::fs::read_to_string(&path).unwrap_or_default();
            assert_eq!(
                on_disk,
                to_obj(&m, &obj_comment(comment)),
                "{path} is stale: run `cargo run --example make_patterns`"
            );
        }
    }
}
