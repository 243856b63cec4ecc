//! Bent sheets (issue 5): bending an A4 sheet into an S (patterns/bent-a4.toml's curve) at
//! 0.1 mm tolerance and unfolding it again. Target: under 10 ms (the paper's method is
//! interactive). Run: `cargo bench --bench bent`.

use criterion::{criterion_group, criterion_main, Criterion};
use flatcut::geom::curve::Curve;
use flatcut::surface::geodesic::{self, BentSpec, Control, FlatPath, LengthFit, PieceSpec};
use flatcut::surface::strip::BendLines;
use glam::{DVec2, DVec3};

fn a4(tolerance: f64) -> BentSpec {
    BentSpec {
        outline: vec![
            DVec2::ZERO,
            DVec2::new(210.0, 0.0),
            DVec2::new(210.0, 297.0),
            DVec2::new(0.0, 297.0),
        ],
        holes: vec![],
        pieces: vec![PieceSpec {
            path: FlatPath::Line([DVec2::new(105.0, 0.0), DVec2::new(105.0, 297.0)]),
            control: Control::Curve(Curve::Bezier {
                control: vec![
                    DVec3::new(105.0, 0.0, 0.0),
                    DVec3::new(105.0, 110.0, 90.0),
                    DVec3::new(105.0, 190.0, -90.0),
                    DVec3::new(105.0, 297.0, 0.0),
                ],
            }),
            fit: LengthFit::Scale,
        }],
        tolerance,
        bend_lines: BendLines::All,
    }
}

fn bend_and_unfold(spec: &BentSpec) -> flatcut::flatten::Flat {
    let b = geodesic::bend(spec).expect("bends");
    let surface = flatcut::surface::Surface {
        name: "a4".into(),
        mesh: b.mesh,
        bends: Some(b.bends),
        ..Default::default()
    };
    flatcut::flatten::unfold(surface, &Default::default()).expect("unfolds")
}

fn bench(c: &mut Criterion) {
    let spec = a4(0.1);
    let b = geodesic::bend(&spec).unwrap();
    eprintln!(
        "A4 S at 0.1 mm: {} rulings, {} triangles, folded line within {:.4} mm of the curve",
        b.rulings.len(),
        b.mesh.faces.len(),
        b.drifts[0]
    );
    // On a shared machine wall time overstates the cost: also report this thread's CPU time.
    let cpu = || -> Option<f64> {
        let t = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
        t.split_whitespace().next()?.parse::<f64>().ok()
    };
    if let Some(c0) = cpu() {
        let w0 = std::time::Instant::now();
        for _ in 0..20 {
            std::hint::black_box(bend_and_unfold(&spec));
        }
        let wall = w0.elapsed().as_secs_f64() / 20.0 * 1e3;
        if let Some(c1) = cpu() {
            eprintln!(
                "bend + unfold A4 at 0.1 mm: {:.2} ms CPU, {wall:.2} ms wall per run",
                (c1 - c0) / 20.0 / 1e6
            );
        }
    }
    let mut g = c.benchmark_group("bent");
    g.bench_function("bend+unfold A4 0.1mm", |b| {
        b.iter(|| bend_and_unfold(&spec))
    });
    g.bench_function("bend A4 0.1mm", |b| b.iter(|| geodesic::bend(&spec)));
    let fine = a4(0.01);
    g.bench_function("bend+unfold A4 0.01mm", |b| {
        b.iter(|| bend_and_unfold(&fine))
    });
    // A curve on the sheet (§5): the lamp-shade band bent onto its cone by its middle arc.
    let band = flatcut::spec::load(std::path::Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/patterns/bent-arc-band.toml"
    )))
    .expect("pattern loads")
    .surfaces[0]
        .bent
        .clone()
        .expect("a bent sheet");
    g.bench_function("bend+unfold arc band 0.1mm", |b| {
        b.iter(|| bend_and_unfold(&band))
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
