//! Blade-offset acceptance (issue 8): a 10 mm square cut by the simulated drag knife (0.25 mm
//! offset, `sim-dragknife`) through a real pseudo-terminal. With compensation the blade tip
//! reaches every corner within 0.05 mm; without it the trailing tip rounds them off.

use flatcut::device::sim::SimConfig;
use flatcut::device::stream;
use flatcut::device::stream::StreamOptions;
use flatcut::profile;
use flatcut::toolpath::{knife, SheetJob, Stroke, StrokeRole};
use glam::DVec2;
use std::time::Duration;

const CORNERS: [(f64, f64); 4] = [(20.0, 20.0), (30.0, 20.0), (30.0, 30.0), (20.0, 30.0)];

/// The cut paths the simulator recorded (blade tip, mm) for the square, compensated or not.
fn cut_square(compensate: bool) -> Vec<Vec<DVec2>> {
    let p = profile::find("sim-dragknife").unwrap();
    assert_eq!(p.knife_offset, 0.25);
    let mut points: Vec<DVec2> = CORNERS.iter().map(|c| DVec2::new(c.0, c.1)).collect();
    points.push(points[0]);
    let sheet = SheetJob {
        width: 100.0,
        height: 100.0,
        strokes: vec![Stroke {
            role: StrokeRole::Cut,
            points,
            closed: true,
            piece: Some(0),
            outer: true,
        }],
    };
    let mut opts = flatcut::toolpath::knife::MachineOptions::from_profile(&p, 5.0);
    if !compensate {
        opts.knife_offset = 0.0;
    }
    let prepared = knife::prepare_sheet(&sheet, &opts);
    let program = flatcut::output::program(&prepared, &p).unwrap();
    let so = StreamOptions {
        progress: false,
        ..StreamOptions::default()
    };
    let (sent, rep) = stream::stream_job(
        SimConfig::new(p.clone()),
        &program,
        &so,
        Duration::from_secs(60),
    )
    .unwrap();
    sent.unwrap();
    assert_eq!(rep.violations(), 0);
    rep.paths
        .iter()
        .filter(|q| q.tool == "cut")
        .map(|q| {
            q.points
                .iter()
                .map(|x| DVec2::new(x[0], x[1]) / p.units_per_mm)
                .collect()
        })
        .collect()
}

fn distance_to_path(c: DVec2, path: &[DVec2]) -> f64 {
    path.windows(2)
        .map(|w| flatcut::geom::polygon::segment_distance(c, w[0], w[1]))
        .fold(f64::INFINITY, f64::min)
}

/// Largest distance from a corner to the path, and from a path point to the square's outline.
fn errors(path: &[DVec2]) -> (f64, f64) {
    let corner = CORNERS
        .iter()
        .map(|c| distance_to_path(DVec2::new(c.0, c.1), path))
        .fold(0.0, f64::max);
    let ring: Vec<DVec2> = CORNERS
        .iter()
        .chain(&CORNERS[..1])
        .map(|c| DVec2::new(c.0, c.1))
        .collect();
    let outline = path
        .iter()
        .map(|p| distance_to_path(*p, &ring))
        .fold(0.0, f64::max);
    (corner, outline)
}

#[test]
fn drag_knife_corners_with_and_without_compensation() {
    let on = cut_square(true);
    // The alignment precut, then the square.
    assert_eq!(on.len(), 2, "{on:?}");
    assert!(on[0].iter().all(|p| p.y < 5.0), "precut in the margin");
    let (corner_on, outline_on) = errors(&on[1]);
    let off = cut_square(false);
    assert_eq!(off.len(), 1);
    let (corner_off, outline_off) = errors(&off[0]);
    eprintln!(
        "10 mm square, 0.25 mm offset: corner error {corner_on:.3} mm compensated \
         (path within {outline_on:.3} mm of the square), {corner_off:.3} mm uncompensated \
         (path strays {outline_off:.3} mm)"
    );
    assert!(corner_on <= 0.05, "compensated corner error {corner_on}");
    assert!(outline_on <= 0.05, "compensated path strays {outline_on}");
    assert!(corner_off > 0.1, "uncompensated corner error {corner_off}");
}
