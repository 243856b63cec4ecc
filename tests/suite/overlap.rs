//! Issue 20: no piece overlaps itself or another (deliverable 1), and the exit-2 cases of
//! deliverable 6, each named after what it was. Overlap is exact and triangle-level
//! (`flatten::overlap`): two faces of one piece, or of two nested pieces, whose interiors
//! intersect.

use crate::common::*;
use flatcut::flatten::overlap;
use glam::{DVec2, DVec3};
use std::path::Path;

/// A spec for mesh file `path` at `scale` with `segment` ("faces", "dcharts" or "" for the
/// mesh's default), on a 610 mm roll.
fn spec_text(path: &Path, scale: f64, segment: &str) -> String {
    let seg = if segment.is_empty() {
        String::new()
    } else {
        format!("segment = \"{segment}\"\n")
    };
    format!(
        "name = \"t\"\n[[surface]]\nkind = \"mesh\"\npath = \"{}\"\nscale = {scale}\nunits = \"mm\"\n{seg}[material]\nkind = \"paper\"\n[sheet]\nwidth = 610\nroll = true\nmargin = 10\nspacing = 5\n",
        path.display()
    )
}

fn spec(path: &Path, scale: f64, segment: &str) -> flatcut::spec::Spec {
    flatcut::spec::parse(
        &spec_text(path, scale, segment),
        &path.with_file_name("overlap-test.toml"),
    )
    .expect("spec")
}

/// Nested with `flatcut flatten`'s strip, then checked: no two faces of one piece overlap, no
/// two faces of different pieces overlap once placed, every point inside the margins.
fn check_run(spec: &flatcut::spec::Spec, dir: &Path) -> usize {
    let extras = flatcut::pipeline::Extras {
        output: Some(dir.to_path_buf()),
        alternatives: None,
        surface_obj: None,
        uv_obj: None,
        quiet: true,
    };
    let run = flatcut::pipeline::flatten(spec, &Default::default(), &extras).expect("flatten");
    for flat in &run.flats {
        let pairs = overlap::island_pairs(flat);
        for (k, p) in pairs.iter().enumerate() {
            assert!(
                p.is_empty(),
                "piece {} overlaps itself: {} face pairs",
                k + 1,
                p.len()
            );
        }
    }
    // Between pieces, as placed (one surface: faces are its faces).
    let flat = &run.flats[0];
    let mut tris = overlap::Triangles::new();
    let mut piece_of = vec![usize::MAX; flat.face_2d.len()];
    let mut ext = 0.0f64;
    for (k, (piece, at)) in run
        .layout
        .pieces
        .iter()
        .zip(&run.layout.placements)
        .enumerate()
    {
        for &f in &piece.faces {
            let placed: Vec<DVec2> = flat.face_2d[f].iter().map(|p| at.apply(*p)).collect();
            ext = ext.max(overlap::extent([placed.as_slice()]));
            tris.push(f, &placed);
            piece_of[f] = k;
        }
    }
    let between = tris.overlapping(overlap::exact_eps(ext), 10, &|a, b| {
        piece_of[a] != piece_of[b]
    });
    assert!(
        between.is_empty(),
        "faces of two pieces overlap: {between:?}"
    );
    flatcut::nest::verify(&run.layout).expect("inside the sheet, apart");
    run.layout.pieces.len()
}

#[test]
fn no_piece_overlaps_itself_or_another_at_300_mm() {
    require_shared!();
    for mesh in ["fandisk", "mushroom", "cylinder"] {
        for segment in ["faces", "dcharts"] {
            let path = shared_data(&format!("meshes/{mesh}.obj"));
            let spec = spec(&path, 300.0, segment);
            if segment == "faces" && mesh != "cylinder" {
                // Dozens of pieces: checked inside each piece (nesting them all is slow).
                let (flats, _) = flatcut::pipeline::pieces(&spec, true).expect("pieces");
                let pairs = overlap::island_pairs(&flats[0]);
                assert!(pairs.iter().all(|p| p.is_empty()), "{mesh} {segment}");
                continue;
            }
            let dir = scratch(&format!("overlap-{mesh}-{segment}"));
            let n = check_run(&spec, &dir);
            assert!(n >= 1, "{mesh} {segment}");
        }
    }
}

/// `flatcut flatten FILE ARGS…` exits 0 (it exited 2, "flatcut bug").
fn flatten_exits_0(input: &Path, args: &[&str], name: &str) {
    let dir = scratch(name);
    let mut a = vec![
        "flatten",
        input.to_str().unwrap(),
        "-q",
        "-o",
        dir.to_str().unwrap(),
    ];
    a.extend_from_slice(args);
    let o = flatcut(&a);
    assert!(o.status.success(), "{:?}: {}", o.status.code(), stderr(&o));
}

#[test]
fn fandisk_dcharts_unscaled_piece_6_left_the_sheet() {
    require_shared!();
    // Exit 2: "piece 6 leaves the sheet at [176.69, 4.93]": a seam id beside a simplified
    // outline stood outside what was nested.
    let mesh = shared_data("meshes/fandisk.obj");
    flatten_exits_0(&mesh, &["--segment", "dcharts"], "exit2-fandisk-dcharts");
}

#[test]
fn mushroom_faces_unscaled_left_the_sheet() {
    require_shared!();
    // Exit 2: fold lines of the exact unfolding outside the cleaned cut outline.
    let mesh = shared_data("meshes/mushroom.obj");
    flatten_exits_0(&mesh, &["--segment", "faces"], "exit2-mushroom-faces");
}

/// A genus-3 solid: a `7r × 3r × r` block of voxels with three `r × r` holes through it, its
/// boundary triangulated (136 r² triangles), smoothed by `smooth` rounds of Laplacian
/// averaging, about `size` across.
pub fn genus3(r: usize, smooth: usize, size: f64) -> String {
    type P = (i64, i64, i64);
    let (nx, ny, nz) = (7 * r, 3 * r, r);
    let solid = |x: i64, y: i64, z: i64| {
        if x < 0 || y < 0 || z < 0 || x >= nx as i64 || y >= ny as i64 || z >= nz as i64 {
            return false;
        }
        let (x, y) = (x as usize / r, y as usize / r);
        !(y == 1 && (x == 1 || x == 3 || x == 5))
    };
    let mut ids: std::collections::HashMap<(i64, i64, i64), usize> = Default::default();
    let mut verts: Vec<DVec3> = Vec::new();
    let mut id = |p: (i64, i64, i64), verts: &mut Vec<DVec3>| {
        *ids.entry(p).or_insert_with(|| {
            verts.push(DVec3::new(p.0 as f64, p.1 as f64, p.2 as f64));
            verts.len() - 1
        })
    };
    let mut faces: Vec<[usize; 3]> = Vec::new();
    for x in 0..nx as i64 {
        for y in 0..ny as i64 {
            for z in 0..nz as i64 {
                if !solid(x, y, z) {
                    continue;
                }
                // Each open side: a quad, counter-clockwise seen from outside.
                let sides: [(P, [P; 4]); 6] = [
                    ((1, 0, 0), [(1, 0, 0), (1, 1, 0), (1, 1, 1), (1, 0, 1)]),
                    ((-1, 0, 0), [(0, 0, 0), (0, 0, 1), (0, 1, 1), (0, 1, 0)]),
                    ((0, 1, 0), [(0, 1, 0), (0, 1, 1), (1, 1, 1), (1, 1, 0)]),
                    ((0, -1, 0), [(0, 0, 0), (1, 0, 0), (1, 0, 1), (0, 0, 1)]),
                    ((0, 0, 1), [(0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1)]),
                    ((0, 0, -1), [(0, 0, 0), (0, 1, 0), (1, 1, 0), (1, 0, 0)]),
                ];
                for (d, q) in sides {
                    if solid(x + d.0, y + d.1, z + d.2) {
                        continue;
                    }
                    let v: Vec<usize> = q
                        .iter()
                        .map(|c| id((x + c.0, y + c.1, z + c.2), &mut verts))
                        .collect();
                    faces.push([v[0], v[1], v[2]]);
                    faces.push([v[0], v[2], v[3]]);
                }
            }
        }
    }
    for _ in 0..smooth {
        let mut sum = vec![DVec3::ZERO; verts.len()];
        let mut n = vec![0.0; verts.len()];
        for f in &faces {
            for i in 0..3 {
                sum[f[i]] += verts[f[(i + 1) % 3]];
                n[f[i]] += 1.0;
            }
        }
        for (v, (s, c)) in verts.iter_mut().zip(sum.iter().zip(&n)) {
            *v = 0.5 * *v + 0.5 * *s / *c;
        }
    }
    let scale = size / nx as f64;
    let mut text = String::new();
    for v in &verts {
        text += &format!("v {} {} {}\n", v.x * scale, v.y * scale, v.z * scale);
    }
    for f in &faces {
        text += &format!("f {} {} {}\n", f[0] + 1, f[1] + 1, f[2] + 1);
    }
    text
}

#[test]
fn genus3_paper_tabs_at_200_to_400_mm_piece_8_left_the_sheet() {
    // Exit 2: "piece 8 leaves the sheet" by 0.26 mm: glue tabs and seam ids of a genus-3 mesh
    // of about 1k faces stood past the simplified outline that was nested.
    let dir = scratch("exit2-genus3");
    let obj = dir.join("genus3.obj");
    std::fs::write(&obj, genus3(3, 3, 1.0)).unwrap();
    for size in [200.0, 400.0] {
        for segment in ["", "dcharts"] {
            let spec = dir.join(format!("g{size}{segment}.toml"));
            std::fs::write(&spec, spec_text(&obj, size, segment)).unwrap();
            flatten_exits_0(
                &spec,
                &["--tabs", "one-side"],
                &format!("exit2-genus3-{size}{segment}"),
            );
        }
    }
}
