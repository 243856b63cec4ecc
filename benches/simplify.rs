//! Seam simplification (issue 7, thesis §5.3, `pattern::simplify`): the pattern stage on the
//! D-Charts pieces of fandisk (12 946 faces) and mushroom (4 608 faces), with simplification
//! off and at 0.5 mm, so that its cost is the difference. Segmenting and laying flat happen
//! once, outside the timing. Run: `cargo bench --bench simplify`.

use criterion::{criterion_group, criterion_main, Criterion};
use flatcut::flatten::charts::{self, FlattenOptions};
use flatcut::flatten::Flat;
use flatcut::pattern::PatternOptions;
use flatcut::spec::MaterialKind;
use flatcut::surface::dcharts::{self, DChartsOptions};
use flatcut::surface::Surface;
use std::path::Path;

fn flat(name: &str, scale: f64) -> Option<Flat> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../shared/data/meshes")
        .join(name);
    let raw = flatcut::surface::obj::read(&path).ok()?;
    let mesh = flatcut::surface::obj::validate(raw, scale).ok()?.0;
    let seg = dcharts::segment(&mesh, &DChartsOptions::default()).ok()?;
    let s = Surface {
        name: "bench".into(),
        mesh,
        charts: Some(seg.chart),
        cuts: seg.cuts,
        ..Default::default()
    };
    charts::charts(s, &FlattenOptions::default()).ok()
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("simplify");
    g.sample_size(10);
    for (name, scale) in [("fandisk.obj", 100.0), ("mushroom.obj", 300.0)] {
        let Some(f) = flat(name, scale) else {
            eprintln!("{name}: not found beside the checkout (../shared/data/meshes); skipped");
            continue;
        };
        let flats = [f];
        let stem = name.trim_end_matches(".obj");
        for tol in [0.0, 0.5] {
            let opts = PatternOptions {
                simplify: tol,
                ..PatternOptions::for_material(MaterialKind::Paper)
            };
            g.bench_function(format!("pattern {stem} simplify {tol}"), |b| {
                b.iter(|| {
                    flatcut::pattern::build(&flats, &opts)
                        .expect("pattern")
                        .len()
                })
            });
        }
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
