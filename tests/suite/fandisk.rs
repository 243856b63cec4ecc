//! The acceptance mesh: `../shared/data/meshes/fandisk.obj` (12,946 triangles) cut end to end.
//! Every face keeps its edge lengths on the sheet, no piece overlaps itself or another, and all
//! lie inside the sheet margins.

use crate::common::*;
use flatcut::geom::polygon;
use glam::DVec2;

const SPEC: &str = FANDISK_SPEC;

#[test]
fn fandisk_unfolds_isometrically_without_overlap_inside_the_sheet() {
    require_shared!();
    let mesh_path = shared_data("meshes/fandisk.obj");
    assert!(mesh_path.is_file(), "{} missing", mesh_path.display());
    let spec_path = mesh_path.with_file_name("fandisk-test.toml");
    let spec = flatcut::spec::parse(SPEC, &spec_path).expect("spec");
    let (flats, pieces) = flatcut::pipeline::pieces(&spec, true).expect("pieces");
    let flat = &flats[0];
    assert_eq!(flat.surface.mesh.faces.len(), 12_946);
    // Unfolded at one size whatever the spec says (issue 20, item 5), where the unfolder's
    // 0.02 mm tolerance is relatively finer than at the spec's 100×: 8 islands, was 7.
    assert!(flat.islands.len() <= 8, "{} islands", flat.islands.len());
    assert!(flatcut::flatten::unfold::find_overlap(flat).is_none());

    let opts = flatcut::nest::NestOptions {
        width: 297.0,
        height: Some(420.0),
        margin: 5.0,
        spacing: 3.0,
        seconds: 0.2,
        ..Default::default()
    };
    let layout = flatcut::nest::nest(pieces, &opts).expect("nest");
    let mesh = &flat.surface.mesh;
    let mut checked = 0;
    for (piece, at) in layout.pieces.iter().zip(&layout.placements) {
        for &f in &piece.faces {
            let v = &mesh.faces[f].verts;
            let placed: Vec<DVec2> = flat.face_2d[f].iter().map(|p| at.apply(*p)).collect();
            for i in 0..v.len() {
                for k in i + 1..v.len() {
                    let d3 = mesh.vertices[v[i]].distance(mesh.vertices[v[k]]);
                    let d2 = placed[i].distance(placed[k]);
                    assert!((d3 - d2).abs() <= 1e-9 * d3, "face {f}: {d3} vs {d2}");
                }
            }
            // Same orientation: a mirror image would not fold back into the part.
            assert!(polygon::signed_area(&placed) > 0.0);
            // Inside the margins; the cut outline, which is what the nest places, leaves out
            // features narrower than 0.1 mm, so a face corner may stand up to CLEAN_MM beyond it.
            let tol = flatcut::pattern::allowance::CLEAN_MM;
            for p in &placed {
                assert!(p.x >= 5.0 - tol && p.x <= 292.0 + tol, "{p}");
                assert!(p.y >= 5.0 - tol && p.y <= 415.0 + tol, "{p}");
            }
            checked += 1;
        }
    }
    assert_eq!(checked, 12_946);
    // Pieces apart from each other by the spacing: outlines checked exactly (dense nesting
    // interleaves them, so bounding boxes say nothing).
    flatcut::nest::verify(&layout).expect("outlines apart");
}

#[test]
fn fandisk_cuts_end_to_end() {
    require_shared!();
    let dir = scratch("fandisk-cli");
    std::fs::write(
        dir.join("fandisk.toml"),
        SPEC.replace(
            "fandisk.obj",
            &shared_data("meshes/fandisk.obj").to_string_lossy(),
        ),
    )
    .unwrap();
    let out = dir.join("out");
    let o = flatcut(&[
        "cut",
        dir.join("fandisk.toml").to_str().unwrap(),
        "--device",
        "hpgl-pens",
        "--dry-run",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let plt = std::fs::read_to_string(out.join("fandisk.plt")).unwrap();
    let strokes = flatcut::output::hpgl::parse(&plt).unwrap();
    // Every recorded point lies inside the sheet margins (40 plotter units per mm).
    for s in &strokes {
        for &(x, y) in &s.points {
            assert!(
                (200..=292 * 40).contains(&x) && (200..=415 * 40).contains(&y),
                "({x},{y})"
            );
        }
    }
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap()).unwrap();
    assert_eq!(report["surfaces"][0]["faces"], 12_946);
    let cut = report["totals"]["cut_length_mm"].as_f64().unwrap();
    let plotted: f64 = strokes
        .iter()
        .filter(|s| s.pen == 1)
        .map(|s| {
            s.points
                .windows(2)
                .map(|w| {
                    let (dx, dy) = ((w[1].0 - w[0].0) as f64, (w[1].1 - w[0].1) as f64);
                    (dx * dx + dy * dy).sqrt() / 40.0
                })
                .sum::<f64>()
        })
        .sum();
    // Rounding to 0.025 mm moves each of the few thousand outline points by at most 0.018 mm.
    assert!(
        (plotted - cut).abs() < 0.01 * cut,
        "plotted {plotted} vs {cut}"
    );
}
