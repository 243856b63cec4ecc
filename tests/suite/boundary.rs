//! Issue 6 acceptance: developable boundary triangulations (Rose et al.) — triangulation
//! invariants, planar boundaries, the example patterns' figures, darts, holes, rulings, and bad
//! input through the CLI (exit 1, one line naming the key and line).

use crate::common::*;
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
        assert!(
            v[0] != v[1] && v[1] != v[2] && v[0] != v[2],
            "degenerate face {v:?}"
        );
        for k in 0..3 {
            *directed.entry((v[k], v[(k + 1) % 3])).or_default() += 1;
        }
    }
    for (&(a, b), &c) in &directed {
        assert_eq!(
            c, 1,
            "directed edge {a}->{b} used {c} times (not manifold/oriented)"
        );
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
    let edges = (directed.len() + boundary.len()) / 2;
    let euler = n as i64 - edges as i64 + mesh.faces.len() as i64;
    // A disk with h holes: χ = 1 − h.
    assert_eq!(euler, 1 - (loops.len() as i64 - 1), "Euler characteristic");
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
            assert!(
                (l3 - l2).abs() <= 1e-9 * l3,
                "face {f} edge {i}: {l3} vs {l2}"
            );
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
        assert_eq!(
            out.mesh.vertices, pts,
            "{name}: vertices are the input points"
        );
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

/// A star-shaped, non-convex planar polygon of `n` points in the xy plane.
fn star(n: usize) -> Vec<DVec3> {
    (0..n)
        .map(|k| {
            let t = TAU * k as f64 / n as f64;
            let r = if k % 2 == 0 {
                100.0
            } else {
                55.0 + 10.0 * (3.0 * t).sin()
            };
            DVec3::new(r * t.cos(), 0.7 * r * t.sin(), 0.0)
        })
        .collect()
}

fn shoelace(p: &[DVec3]) -> f64 {
    let mut a = 0.0;
    for i in 0..p.len() {
        let (u, v) = (p[i], p[(i + 1) % p.len()]);
        a += u.x * v.y - v.x * u.y;
    }
    0.5 * a.abs()
}

#[test]
fn planar_boundary_in_any_orientation_is_one_flat_piece_with_its_area() {
    let flat = star(30);
    let area = shoelace(&flat);
    for (axis, angle, shift) in [
        (DVec3::Z, 0.0, DVec3::ZERO),
        (
            DVec3::new(1.0, 2.0, 3.0),
            1.1,
            DVec3::new(40.0, -7.0, 300.0),
        ),
        (DVec3::X, PI / 2.0, DVec3::new(0.0, 0.0, -50.0)),
        (DVec3::new(-2.0, 0.5, 1.0), 2.7, DVec3::new(1e3, 1e3, 1e3)),
    ] {
        let q = DQuat::from_axis_angle(axis.normalize(), angle);
        let pts: Vec<DVec3> = flat.iter().map(|p| q * *p + shift).collect();
        let out = triangulate(
            &Input {
                loops: vec![pts.clone()],
                ..Default::default()
            },
            &Options::default(),
        )
        .unwrap();
        check_boundary_triangulation(&out.mesh, &one_loop(pts.len()));
        let f = &out.figures;
        assert!(f.largest_dihedral_deg < 1e-6, "{}", f.largest_dihedral_deg);
        let a3: f64 = (0..out.mesh.faces.len())
            .map(|k| out.mesh.face_area(k))
            .sum();
        assert!((a3 - area).abs() <= 1e-9 * area, "3D area {a3} vs {area}");
        let fl = check_unfolds(&out.mesh);
        assert_eq!(fl.islands.len(), 1, "one piece");
        let a2: f64 = fl
            .face_2d
            .iter()
            .map(|t| 0.5 * (t[1] - t[0]).perp_dot(t[2] - t[0]).abs())
            .sum();
        assert!((a2 - area).abs() <= 1e-9 * area, "flat area {a2} vs {area}");
        assert!(out.warnings.is_empty(), "{:?}", out.warnings);
    }
}

#[test]
fn planar_boundary_spec_cuts_one_piece_without_folds() {
    let dir = scratch("boundary-planar");
    let q = DQuat::from_axis_angle(DVec3::new(1.0, -1.0, 0.5).normalize(), 0.9);
    let pts: Vec<DVec3> = star(24).iter().map(|p| q * *p).collect();
    let area = shoelace(&star(24));
    let list: Vec<String> = pts
        .iter()
        .map(|p| format!("[{:?}, {:?}, {:?}]", p.x, p.y, p.z))
        .collect();
    let spec = dir.join("flat.toml");
    std::fs::write(
        &spec,
        format!(
            "name = \"flat\"\n[[surface]]\nkind = \"boundary\"\nloop = [{}]\n[sheet]\nwidth = 610\nroll = true\n",
            list.join(", ")
        ),
    )
    .unwrap();
    let out = dir.join("out");
    let o = flatcut(&[
        "cut",
        spec.to_str().unwrap(),
        "--device",
        "hpgl-pens",
        "--dry-run",
        "-q",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let r: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap()).unwrap();
    let pieces = r["pieces"].as_array().unwrap();
    assert_eq!(pieces.len(), 1);
    assert_eq!(pieces[0]["fold_lines"].as_array().unwrap().len(), 0);
    let a = pieces[0]["area_mm2"].as_f64().unwrap();
    assert!(
        (a - area).abs() <= 1e-6 * area,
        "piece area {a} vs polygon {area}"
    );
    let fig = &r["surfaces"][0]["figures"];
    assert!(fig["interior_triangles"].is_number());
    assert!(fig["largest_dihedral_deg"].as_f64().unwrap() < 1e-4);
    assert_eq!(fig["triangles"].as_f64(), Some(22.0));
}

#[test]
fn pattern_reports_carry_the_figures() {
    let out = scratch("boundary-taco");
    let o = flatcut(&[
        "cut",
        "patterns/taco.toml",
        "--device",
        "hpgl-pens",
        "--dry-run",
        "-q",
        "--alternatives",
        "3",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let r: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap()).unwrap();
    let fig = &r["surfaces"][0]["figures"];
    for k in [
        "interior_triangles",
        "locally_convex_fraction",
        "largest_dihedral_deg",
        "iterations",
    ] {
        assert!(fig[k].is_number(), "figures.{k} missing: {fig}");
    }
    // Wall-clock time stays out of the report: identical runs give identical reports.
    assert!(
        fig.get("seconds").is_none(),
        "figures.seconds in the report: {fig}"
    );
    assert!(fig["locally_convex_fraction"].as_f64().unwrap() >= 0.9);
    assert!(out.join("taco-alt-1.obj").is_file());
    let files = r["files"].as_array().unwrap();
    assert!(files.iter().any(|f| f == "taco-alt-1.obj"), "{files:?}");
}

#[test]
fn alternatives_are_distinct_boundary_triangulations() {
    let pts = csv("tulip-petal");
    let n = pts.len();
    let out = triangulate(
        &Input {
            loops: vec![pts],
            ..Default::default()
        },
        &Options {
            alternatives: 4,
            ..Default::default()
        },
    )
    .unwrap();
    assert!(!out.alternatives.is_empty(), "at least one alternative");
    assert!(out.alternatives.len() <= 3);
    let key = |m: &Mesh| {
        let mut f: Vec<Vec<usize>> = m.faces.iter().map(|f| f.verts.clone()).collect();
        f.sort();
        f
    };
    let mut keys = vec![key(&out.mesh)];
    for alt in &out.alternatives {
        check_boundary_triangulation(alt, &one_loop(n));
        let k = key(alt);
        assert!(!keys.contains(&k), "alternatives are distinct");
        keys.push(k);
    }
}

/// Where each vertex lands in the flat (the first face corner seen), for a one-island flat.
fn flat_positions(mesh: &Mesh, flat: &flatcut::flatten::Flat) -> Vec<Option<glam::DVec2>> {
    let mut at = vec![None; mesh.vertices.len()];
    for (f, face) in mesh.faces.iter().enumerate() {
        for (i, &v) in face.verts.iter().enumerate() {
            at[v].get_or_insert(flat.face_2d[f][i]);
        }
    }
    at
}

fn flat_area(flat: &flatcut::flatten::Flat) -> f64 {
    flat.face_2d
        .iter()
        .map(|p| 0.5 * (p[1] - p[0]).perp_dot(p[2] - p[0]))
        .sum()
}

#[test]
fn dart_sides_coincide_in_3d_and_open_in_the_flat_piece() {
    let pts = csv("dress-panel");
    let tip = DVec3::new(0.0, 80.0, -8.0);
    let out = triangulate(
        &Input {
            loops: vec![pts.clone()],
            darts: vec![Dart {
                at: 0,
                points: vec![tip],
                ..Default::default()
            }],
            ..Default::default()
        },
        &Options::default(),
    )
    .unwrap();
    eprintln!("dress panel: {:?}", out.figures);
    assert!(out.warnings.is_empty(), "{:?}", out.warnings);
    // The dart adds the two mouth copies and the tip in place of point 1; the copies coincide.
    let nv = out.mesh.vertices.len();
    assert_eq!(nv, pts.len() + 2);
    assert_eq!(out.mesh.vertices[1], tip);
    assert_eq!(out.mesh.vertices[0], pts[0]);
    assert_eq!(out.mesh.vertices[2], pts[0]);
    check_boundary_triangulation(&out.mesh, &one_loop(nv));
    for f in 0..out.mesh.faces.len() {
        assert!(out.mesh.face_area(f) > 1e-6, "face {f} is degenerate");
    }
    let flat = check_unfolds(&out.mesh);
    assert_eq!(flat.islands.len(), 1, "one piece");
    // The flat piece opens the dart: the two copies of the mouth land apart, the tip once.
    let at = flat_positions(&out.mesh, &flat);
    let gap = at[0].unwrap().distance(at[2].unwrap());
    eprintln!("dress panel dart: mouth opens {gap:.3} mm in the flat piece");
    assert!(gap > 1.0, "the dart opens: {gap}");
    // The flat piece's area is the 3D area.
    let a3: f64 = (0..out.mesh.faces.len())
        .map(|f| out.mesh.face_area(f))
        .sum();
    assert!((flat_area(&flat) - a3).abs() <= 1e-9 * a3);
    // The same through the spec (the pattern file).
    let spec = flatcut::spec::load(&manifest("patterns/dress-panel.toml")).unwrap();
    let s = flatcut::surface::build(&spec.surfaces[0]).unwrap();
    assert_eq!(s.mesh.vertices.len(), nv);
    assert!(s.figures.iter().any(|(k, _)| *k == "interior_triangles"));
}

/// Loops as vertex ids in the order `triangulate` numbers them (no darts).
fn loop_ids(loops: &[Vec<DVec3>]) -> Vec<Vec<usize>> {
    let mut start = 0;
    loops
        .iter()
        .map(|l| {
            let ids = (start..start + l.len()).collect();
            start += l.len();
            ids
        })
        .collect()
}

/// Triangulate several loops, check the invariants, unfold (edges to 1e-9), check the flat
/// area against the 3D area; returns the output and the flat.
fn several_loops(
    name: &str,
    loops: Vec<Vec<DVec3>>,
) -> (flatcut::surface::boundary::Output, flatcut::flatten::Flat) {
    let out = triangulate(
        &Input {
            loops: loops.clone(),
            ..Default::default()
        },
        &Options::default(),
    )
    .unwrap();
    let all: Vec<DVec3> = loops.iter().flatten().copied().collect();
    assert_eq!(
        out.mesh.vertices, all,
        "{name}: vertices are the input points"
    );
    check_boundary_triangulation(&out.mesh, &loop_ids(&loops));
    let n = all.len();
    let h = loops.len() - 1;
    assert_eq!(
        out.mesh.faces.len(),
        n + 2 * h - 2,
        "{name}: n + 2h − 2 triangles"
    );
    for f in 0..out.mesh.faces.len() {
        assert!(
            out.mesh.face_area(f) > 1e-6,
            "{name}: face {f} is degenerate"
        );
    }
    let flat = check_unfolds(&out.mesh);
    let a3: f64 = (0..out.mesh.faces.len())
        .map(|f| out.mesh.face_area(f))
        .sum();
    let a2 = flat_area(&flat);
    assert!(
        (a2 - a3).abs() <= 1e-9 * a3,
        "{name}: flat area {a2} vs {a3}"
    );
    let f = &out.figures;
    eprintln!(
        "{name}: {n} points in {} loops, {} connecting charts, {} joining edges, {} interior triangles, {}/{} locally convex, largest dihedral {:.2}°, {} iterations, {:.3} s, {} flat piece(s), warnings {:?}",
        loops.len(),
        f.connecting_charts,
        f.joining_edges,
        f.interior_triangles,
        f.convex_edges,
        f.interior_edges,
        f.largest_dihedral_deg,
        f.iterations,
        f.seconds,
        flat.islands.len(),
        out.warnings
    );
    (out, flat)
}

/// A ring of `n` points on a cylinder of radius 120 about the x axis (a bent panel).
fn bent_ring(r: f64, w: f64, n: usize, x0: f64, y0: f64) -> Vec<DVec3> {
    (0..n)
        .map(|k| {
            let t = TAU * k as f64 / n as f64;
            let (x, s) = (x0 + w * t.cos(), y0 + r * t.sin());
            DVec3::new(
                x,
                120.0 * (s / 120.0).sin(),
                120.0 * (1.0 - (s / 120.0).cos()),
            )
        })
        .collect()
}

#[test]
fn a_window_in_a_bent_panel_is_joined_by_the_shortest_edge() {
    let loops = vec![
        bent_ring(90.0, 120.0, 32, 0.0, 0.0),
        bent_ring(30.0, 40.0, 12, 10.0, 0.0),
    ];
    let (out, _) = several_loops("bent panel, one window", loops);
    assert_eq!(
        out.figures.connecting_charts + out.figures.joining_edges,
        1,
        "one connection for one hole"
    );
}

#[test]
fn a_band_between_two_non_planar_loops_is_one_connecting_chart() {
    // A lamp collar: a wavy lower rim and a smaller wavy upper rim.
    let rim = |r: f64, z: f64, a: f64, waves: f64, n: usize| -> Vec<DVec3> {
        (0..n)
            .map(|k| {
                let t = TAU * k as f64 / n as f64;
                DVec3::new(r * t.cos(), r * t.sin(), z + a * (waves * t).sin())
            })
            .collect()
    };
    let loops = vec![rim(100.0, 0.0, 8.0, 3.0, 48), rim(60.0, 80.0, 5.0, 2.0, 36)];
    let (out, flat) = several_loops("band", loops);
    assert!(
        out.figures.connecting_charts >= 1,
        "a hull chart joins the rims"
    );
    assert_eq!(out.figures.joining_edges, 0);
    assert_eq!(out.figures.interior_triangles, 0);
    assert!(out.figures.convex_fraction() >= 0.9);
    assert!(out.warnings.is_empty(), "{:?}", out.warnings);
    assert_eq!(flat.islands.len(), 1, "one piece (cut open along one edge)");
}

#[test]
fn a_panel_with_two_holes_keeps_both_holes() {
    // Planar, tilted: the flat piece is the polygon with its two holes, no folds.
    let rot = DQuat::from_axis_angle(DVec3::new(1.0, 2.0, 0.5).normalize(), 0.8);
    let ring = |cx: f64, cy: f64, rx: f64, ry: f64, n: usize| -> Vec<DVec3> {
        (0..n)
            .map(|k| {
                let t = TAU * k as f64 / n as f64;
                rot * DVec3::new(cx + rx * t.cos(), cy + ry * t.sin(), 0.0)
            })
            .collect()
    };
    let loops = vec![
        ring(0.0, 0.0, 150.0, 90.0, 40),
        ring(-60.0, 0.0, 30.0, 20.0, 12),
        ring(60.0, 10.0, 25.0, 35.0, 10),
    ];
    let (out, flat) = several_loops("planar panel, two holes", loops.clone());
    assert_eq!(flat.islands.len(), 1, "one piece with the holes cut out");
    assert!(out.figures.largest_dihedral_deg < 1e-6);
    let poly = |l: &[DVec3]| {
        let n = l.len();
        let mut a = DVec3::ZERO;
        for k in 0..n {
            a += l[k].cross(l[(k + 1) % n]);
        }
        0.5 * a.length()
    };
    let expect = poly(&loops[0]) - poly(&loops[1]) - poly(&loops[2]);
    assert!((flat_area(&flat) - expect).abs() <= 1e-9 * expect);
    assert_eq!(
        out.figures.joining_edges, 2,
        "the shortest tree over three loops"
    );
    // Bent: the same panel on a cylinder.
    let loops = vec![
        bent_ring(90.0, 150.0, 40, 0.0, 0.0),
        bent_ring(20.0, 30.0, 12, -60.0, 0.0),
        bent_ring(30.0, 25.0, 10, 60.0, 10.0),
    ];
    several_loops("bent panel, two holes", loops);
}

#[test]
fn darts_and_rulings_on_any_loop() {
    // A bent panel whose window has a dart, and a ruling joining the window to the rim.
    let loops = vec![
        bent_ring(90.0, 120.0, 32, 0.0, 0.0),
        bent_ring(30.0, 40.0, 12, 10.0, 0.0),
    ];
    let hole = &loops[1];
    // The dart runs from the window's point 7 outwards, taking the panel in 8 mm.
    let tip = hole[6] + (hole[6] - hole[0]) * 0.3 - DVec3::Z * 8.0;
    let input = Input {
        loops: loops.clone(),
        darts: vec![Dart {
            looop: 1,
            at: 6,
            points: vec![tip],
            ..Default::default()
        }],
        rulings: vec![[(0, 0), (1, 0)]],
    };
    let out = triangulate(&input, &Options::default()).unwrap();
    eprintln!("window with a dart: {:?}, {:?}", out.figures, out.warnings);
    // Loop 2 gains the dart: its point 7 becomes two copies with the tip between them.
    let n0 = loops[0].len();
    let v = &out.mesh.vertices;
    assert_eq!(v.len(), n0 + 12 + 2);
    assert_eq!(v[n0 + 6], v[n0 + 8], "the dart's sides coincide");
    assert_eq!(v[n0 + 7], tip);
    let hole_ids: Vec<usize> = (n0..n0 + 14).collect();
    check_boundary_triangulation(&out.mesh, &[(0..n0).collect(), hole_ids]);
    assert_eq!(out.figures.connecting_charts + out.figures.joining_edges, 1);
    let topo = out.mesh.topology();
    let e = topo
        .edges
        .iter()
        .find(|e| e.verts == [0, n0])
        .expect("the ruling between the loops is an edge");
    assert_eq!(e.uses.len(), 2, "interior edge");
    check_unfolds(&out.mesh);
}

#[test]
fn rulings_are_edges_of_the_result() {
    let pts = csv("taco");
    let n = pts.len();
    let out = triangulate(
        &Input {
            loops: vec![pts],
            rulings: vec![[(0, 5), (0, 30)], [(0, 12), (0, 24)]],
            ..Default::default()
        },
        &Options::default(),
    )
    .unwrap();
    check_boundary_triangulation(&out.mesh, &one_loop(n));
    let topo = out.mesh.topology();
    for (a, b) in [(5, 30), (12, 24)] {
        let e = topo
            .edges
            .iter()
            .find(|e| e.verts == [a, b])
            .expect("ruling is an edge");
        assert_eq!(e.uses.len(), 2, "interior edge");
    }
    // Crossing rulings and neighbours are refused.
    for bad in [
        vec![[(0, 5), (0, 30)], [(0, 10), (0, 40)]],
        vec![[(0, 3), (0, 4)]],
        vec![[(0, 0), (0, 99)]],
        vec![[(0, 0), (1, 2)]],
    ] {
        let e = triangulate(
            &Input {
                loops: vec![csv("taco")],
                rulings: bad,
                ..Default::default()
            },
            &Options::default(),
        )
        .unwrap_err();
        assert!(matches!(e, BoundaryError::Ruling { .. }), "{e}");
    }
}

#[test]
fn tiny_and_nasty_loops() {
    // A triangle is its own triangulation.
    let tri = vec![DVec3::ZERO, DVec3::X * 10.0, DVec3::Y * 10.0];
    let out = triangulate(
        &Input {
            loops: vec![tri],
            ..Default::default()
        },
        &Options::default(),
    )
    .unwrap();
    assert_eq!(out.mesh.faces.len(), 1);
    // A saddle (4 points, twisted) and a deep zig-zag crown: valid triangulations.
    let saddle = vec![
        DVec3::new(0.0, 0.0, 0.0),
        DVec3::new(100.0, 0.0, 30.0),
        DVec3::new(100.0, 100.0, 0.0),
        DVec3::new(0.0, 100.0, 30.0),
    ];
    let crown: Vec<DVec3> = (0..40)
        .map(|k| {
            let t = TAU * k as f64 / 40.0;
            DVec3::new(
                80.0 * t.cos(),
                80.0 * t.sin(),
                if k % 2 == 0 { 0.0 } else { 40.0 },
            )
        })
        .collect();
    for pts in [saddle, crown] {
        let n = pts.len();
        let out = triangulate(
            &Input {
                loops: vec![pts],
                ..Default::default()
            },
            &Options::default(),
        )
        .unwrap();
        check_boundary_triangulation(&out.mesh, &one_loop(n));
        check_unfolds(&out.mesh);
    }
}

/// Run, expect exit 1 and a single stderr line containing every `needle`.
fn expect_user_error(spec_text: &str, needles: &[&str]) {
    let dir = scratch(&format!("boundary-bad-{:x}", {
        use std::hash::{Hash, Hasher};
        let mut h = std::collections::hash_map::DefaultHasher::new();
        spec_text.hash(&mut h);
        h.finish()
    }));
    let spec = dir.join("bad.toml");
    std::fs::write(&spec, spec_text).unwrap();
    let o = flatcut(&[
        "cut",
        spec.to_str().unwrap(),
        "--dry-run",
        "-o",
        dir.join("out").to_str().unwrap(),
    ]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{spec_text}\n{err}");
    assert_eq!(err.trim_end().lines().count(), 1, "one line: {err}");
    for n in needles {
        assert!(err.contains(n), "{n:?} not in {err:?}");
    }
}

#[test]
fn bad_boundaries_exit_1_naming_the_problem_and_where() {
    let head = "[[surface]]\nkind = \"boundary\"\n";
    // An open polyline.
    expect_user_error(
        &format!("{head}loop = {{ kind = \"points\", points = [[0, 0, 0], [10, 0, 0], [10, 10, 5]], closed = false }}\n"),
        &["bad.toml:3", "surface[1].loop", "open polyline"],
    );
    expect_user_error(
        &format!("{head}loop = {{ kind = \"bezier\", control = [[0, 0, 0], [10, 0, 0], [10, 10, 5]] }}\n"),
        &["bad.toml:3", "open polyline"],
    );
    // Fewer than three points.
    expect_user_error(
        &format!("{head}loop = [[0, 0, 0], [10, 0, 0]]\n"),
        &["bad.toml:3", "surface[1].loop", "at least 3 points, got 2"],
    );
    // A self-intersecting loop (a bow tie).
    expect_user_error(
        &format!("{head}\nloop = [[0, 0, 0], [10, 10, 0], [10, 0, 0], [0, 10, 0]]\n"),
        &["bad.toml:4", "crosses itself", "segment 1", "segment 3"],
    );
    // Repeated consecutive points.
    expect_user_error(
        &format!("{head}loop = [[0, 0, 0], [10, 0, 0], [10, 0, 0], [0, 10, 3]]\n"),
        &["bad.toml:3", "point 3 repeats point 2"],
    );
    // Several loops: the second one is named.
    expect_user_error(
        &format!("{head}loops = [[[0, 0, 0], [100, 0, 0], [0, 100, 0]], [[1, 1, 0], [2, 1, 0]]]\n"),
        &["surface[1].loops[2]", "at least 3 points"],
    );
    // A CSV file with a repeated point: the file and the loop.
    expect_user_error(
        &format!("{head}loop_csv = \"missing.csv\"\n"),
        &["bad.toml:3", "surface[1].loop_csv", "missing.csv"],
    );
    // Settings.
    expect_user_error(
        &format!("{head}loop = [[0, 0, 0], [10, 0, 0], [0, 10, 3]]\nmax_dihedral = 0\n"),
        &["bad.toml:4", "surface[1].max_dihedral"],
    );
    expect_user_error(
        &format!(
            "{head}loop = [[0, 0, 0], [10, 0, 0], [0, 10, 3], [-5, 5, 0]]\nrulings = [[1, 2]]\n"
        ),
        &["bad.toml:4", "surface[1].rulings", "ruling 1"],
    );
    expect_user_error(
        &format!("{head}loop = [[0, 0, 0], [10, 0, 0], [0, 10, 3]]\ndarts = [{{ at = 9, points = [[1, 1, 1]] }}]\n"),
        &["bad.toml:4", "surface[1].darts", "dart 1"],
    );
    expect_user_error(
        &format!("{head}path = \"x.obj\"\nloop = [[0, 0, 0], [10, 0, 0], [0, 10, 3]]\n"),
        &["bad.toml:3", "surface[1].path"],
    );
    expect_user_error(head, &["surface[1].loop", "exactly one of"]);
    // Boundary keys on another kind.
    expect_user_error(
        "[[surface]]\nkind = \"mesh\"\npath = \"cube.obj\"\nrulings = [[1, 3]]\n",
        &["bad.toml:4", "surface[1].rulings", "boundary surfaces"],
    );
}

#[test]
fn exhausted_search_still_gives_a_boundary_triangulation() {
    // One iteration and a 1° limit: the relaxed run and the depth-first completion take over.
    let pts = csv("gazebo-roof");
    let n = pts.len();
    let out = triangulate(
        &Input {
            loops: vec![pts],
            ..Default::default()
        },
        &Options {
            max_iterations: 1,
            max_dihedral_deg: 1.0,
            ..Default::default()
        },
    )
    .unwrap();
    assert!(!out.warnings.is_empty());
    check_boundary_triangulation(&out.mesh, &one_loop(n));
    for f in 0..out.mesh.faces.len() {
        assert!(out.mesh.face_area(f) > 1e-6, "face {f} is degenerate");
    }
    check_unfolds(&out.mesh);
}

#[test]
fn same_boundary_gives_the_same_triangulation() {
    let input = Input {
        loops: vec![csv("dress-panel")],
        darts: vec![Dart {
            at: 0,
            points: vec![DVec3::new(0.0, 80.0, -0.36)],
            ..Default::default()
        }],
        ..Default::default()
    };
    let opts = Options {
        alternatives: 3,
        ..Default::default()
    };
    let a = triangulate(&input, &opts).unwrap();
    let b = triangulate(&input, &opts).unwrap();
    assert_eq!(a.mesh, b.mesh);
    assert_eq!(a.alternatives, b.alternatives);
    assert_eq!(a.figures.iterations, b.figures.iterations);
}

#[test]
fn good_enough_stops_the_search_early() {
    let input = Input {
        loops: vec![csv("gazebo-roof")],
        ..Default::default()
    };
    let full = triangulate(&input, &Options::default()).unwrap();
    let quick = triangulate(
        &input,
        &Options {
            good_interior: 100,
            good_fairness: 1e9,
            ..Default::default()
        },
    )
    .unwrap();
    assert!(
        quick.figures.iterations < full.figures.iterations,
        "{} vs {}",
        quick.figures.iterations,
        full.figures.iterations
    );
    assert!(full.figures.iterations <= 1000);
    check_boundary_triangulation(&quick.mesh, &one_loop(input.loops[0].len()));
    // The full search is at least as good.
    assert!(
        full.figures.interior_triangles <= quick.figures.interior_triangles,
        "{} vs {}",
        full.figures.interior_triangles,
        quick.figures.interior_triangles
    );
}
