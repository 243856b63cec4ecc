//! Toolpath acceptance on the fandisk pattern: pen-up travel after ordering against collection
//! order (issue 8: at least 30 % shorter), with marks, folds and cuts all present.

mod common;
use common::*;

const SPEC: &str = r#"
name = "fandisk"
[[surface]]
kind = "mesh"
path = "fandisk.obj"
scale = 100
units = "mm"
[sheet]
width = 297
height = 420
margin = 5
spacing = 3
"#;

#[test]
fn fandisk_travel_at_least_30_percent_shorter_than_stroke_order() {
    let mesh_path = shared_data("meshes/fandisk.obj");
    let spec_path = mesh_path.with_file_name("fandisk-toolpath-test.toml");
    let spec = flatcut::spec::parse(SPEC, &spec_path).expect("spec");
    let (_, pieces) = flatcut::cli::pieces(&spec, true).expect("pieces");
    let opts = flatcut::nest::NestOptions {
        width: 297.0,
        height: Some(420.0),
        margin: 5.0,
        spacing: 3.0,
    };
    let layout = flatcut::nest::nest(pieces, &opts).expect("nest");
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
        assert!(after <= 0.7 * before, "{after} vs {before}");
        // Determinism.
        assert_eq!(flatcut::toolpath::plan(&layout, "fandisk", &tp), job);
    }
}
