//! Toolpath acceptance on the fandisk pattern: pen-up travel after ordering against collection
//! order (issue 8: at least 30 % shorter), with marks, folds and cuts all present.

use crate::common::*;

const SPEC: &str = FANDISK_SPEC;

fn fandisk_layout() -> flatcut::nest::Layout {
    let mesh_path = shared_data("meshes/fandisk.obj");
    let spec_path = mesh_path.with_file_name("fandisk-toolpath-test.toml");
    let spec = flatcut::spec::parse(SPEC, &spec_path).expect("spec");
    let (_, pieces) = flatcut::pipeline::pieces(&spec, true).expect("pieces");
    let opts = flatcut::nest::NestOptions {
        width: 297.0,
        height: Some(420.0),
        margin: 5.0,
        spacing: 3.0,
        seconds: 0.2,
        ..Default::default()
    };
    flatcut::nest::nest(pieces, &opts).expect("nest")
}

#[test]
fn fandisk_travel_at_least_30_percent_shorter_than_stroke_order() {
    require_shared!();
    let layout = fandisk_layout();
    for per_piece in [false, true] {
        let tp = flatcut::toolpath::ToolpathOptions {
            per_piece,
            ..Default::default()
        };
        let t = std::time::Instant::now();
        let job = flatcut::toolpath::plan(&layout, "fandisk", &tp);
        let took = t.elapsed();
        let (mut before, mut after, mut n) = (0.0, 0.0, 0);
        for (sheet, planned) in layout.sheets.iter().zip(&job.sheets) {
            let collected = flatcut::toolpath::unordered(&layout, sheet, &tp);
            assert_eq!(collected.len(), planned.strokes.len());
            n += collected.len();
            before += flatcut::toolpath::travel(&collected);
            after += flatcut::toolpath::travel(&planned.strokes);
        }
        eprintln!(
            "fandisk per_piece={per_piece}: {n} strokes, travel {before:.0} mm in stroke order, \
             {after:.0} mm ordered ({:.1} % shorter), ordering took {took:?}",
            100.0 * (1.0 - after / before)
        );
        assert!(n > 1000, "{n} strokes");
        if !per_piece {
            // What 2-opt adds to nearest neighbour, on all the strokes of the first sheet as
            // one group.
            use flatcut::toolpath::order;
            let all = flatcut::toolpath::unordered(&layout, &layout.sheets[0], &tp);
            let mut pen = glam::DVec2::ZERO;
            let greedy = flatcut::toolpath::travel(&order::order_with(all.clone(), &mut pen, 0));
            let t = std::time::Instant::now();
            let mut pen = glam::DVec2::ZERO;
            let full = flatcut::toolpath::travel(&order::order(all, &mut pen));
            eprintln!(
                "one group: nearest neighbour {greedy:.0} mm, with 2-opt {full:.0} mm \
                 ({:.1} % less), {:?}",
                100.0 * (1.0 - full / greedy),
                t.elapsed()
            );
            assert!(full < greedy);
        }
        assert!(after <= 0.7 * before, "{after} vs {before}");
        // Determinism.
        assert_eq!(flatcut::toolpath::plan(&layout, "fandisk", &tp), job);
    }
}

/// Weed lines on the fandisk sheet: a border and lines through the waste, none of which comes
/// within the clearance of a piece's outline (so none crosses or touches one), and all cut
/// after every piece.
#[test]
fn fandisk_weed_lines_cross_and_touch_no_piece() {
    require_shared!();
    use flatcut::toolpath::{weed, StrokeRole};
    let layout = fandisk_layout();
    let w = weed::WeedOptions::default();
    let tp = flatcut::toolpath::ToolpathOptions {
        weed: Some(w.clone()),
        ..Default::default()
    };
    let job = flatcut::toolpath::plan(&layout, "fandisk", &tp);
    let sheet = &job.sheets[0];
    let first_weed = sheet
        .strokes
        .iter()
        .position(|s| s.role == StrokeRole::Weed)
        .expect("weed lines");
    assert!(sheet.strokes[first_weed..]
        .iter()
        .all(|s| s.role == StrokeRole::Weed));
    let weeds = &sheet.strokes[first_weed..];
    assert!(weeds.len() >= 10, "{} weed strokes", weeds.len());
    let outlines: Vec<&flatcut::toolpath::Stroke> = sheet
        .strokes
        .iter()
        .filter(|s| s.role == StrokeRole::Cut && s.closed)
        .collect();
    let mut least = f64::INFINITY;
    for wl in weeds {
        for a in wl.points.windows(2) {
            for o in &outlines {
                for b in o.points.windows(2) {
                    least = least.min(flatcut::geom::polygon::segment_segment_distance(
                        a[0], a[1], b[0], b[1],
                    ));
                }
            }
        }
    }
    let cut: f64 = weeds.iter().map(|s| s.length()).sum();
    eprintln!(
        "fandisk weeding: {} strokes, {cut:.0} mm, {least:.3} mm from the nearest outline",
        weeds.len()
    );
    assert!(
        least >= w.clearance - 1e-9,
        "a weed line comes {least} mm from an outline"
    );
}

/// The flags end to end: a drag knife with perforated folds and weed lines on the cube.
#[test]
fn cut_flags_knife_perforation_and_weeding() {
    let dir = scratch("toolpath-flags");
    let o = flatcut(&[
        "cut",
        "patterns/cube.toml",
        "--device",
        "graphtec-ce6000",
        "--folds",
        "perforate",
        "--weed",
        "--dry-run",
        "-q",
        "-o",
        dir.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let plt = std::fs::read_to_string(dir.join("cube.plt")).unwrap();
    let svg = std::fs::read_to_string(dir.join("cube.svg")).unwrap();
    assert!(svg.contains("weed"), "weed layer in the SVG");
    // Without the flags: fewer strokes (no dashes, no weed lines).
    let plain = scratch("toolpath-flags-plain");
    let o = flatcut(&[
        "cut",
        "patterns/cube.toml",
        "--device",
        "graphtec-ce6000",
        "--dry-run",
        "-q",
        "-o",
        plain.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let plain_plt = std::fs::read_to_string(plain.join("cube.plt")).unwrap();
    let ups = |t: &str| t.matches("PU").count();
    assert!(
        ups(&plt) > ups(&plain_plt) + 10,
        "{} vs {}",
        ups(&plt),
        ups(&plain_plt)
    );
    // The perforation is cut at the perforate tool's full force, the plain folds scored.
    assert!(plt.contains("FS120;") && !plt.contains("FS50;"), "{plt}");
    assert!(plain_plt.contains("FS50;"));
    // A device without a perforating tool refuses, naming its tools.
    let o = flatcut(&[
        "cut",
        "patterns/cube.toml",
        "--device",
        "hpgl-pens",
        "--folds",
        "perforate",
        "--dry-run",
        "-q",
        "-o",
        dir.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("no perforate tool"), "{}", stderr(&o));
    // --knife-offset 0 turns compensation off: no precut, holder on the design.
    let off = scratch("toolpath-flags-off");
    let o = flatcut(&[
        "cut",
        "patterns/cube.toml",
        "--device",
        "sim-dragknife",
        "--knife-offset",
        "0",
        "--dry-run",
        "-q",
        "-o",
        off.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let on = scratch("toolpath-flags-on");
    let o = flatcut(&[
        "cut",
        "patterns/cube.toml",
        "--device",
        "sim-dragknife",
        "--dry-run",
        "-q",
        "-o",
        on.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let first_pu = |t: &str| t.lines().find(|l| l.starts_with("PU")).unwrap().to_string();
    let on_plt = std::fs::read_to_string(on.join("cube.plt")).unwrap();
    let off_plt = std::fs::read_to_string(off.join("cube.plt")).unwrap();
    // The precut starts half way into the cube's 10 mm margin, the holder 0.25 mm ahead:
    // (5.25, 5) mm = (210, 200) plotter units.
    assert_eq!(first_pu(&on_plt), "PU210,200;");
    assert_ne!(first_pu(&off_plt), "PU210,200;");
}
