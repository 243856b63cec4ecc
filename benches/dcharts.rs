//! D-Charts (issue 7) on the acceptance meshes: segmentation alone, and segmentation plus
//! laying every chart flat (what `flatcut flatten MESH --segment dcharts` does before the
//! pattern stage), on fandisk (12 946 faces; target: under 1 s) and mushroom (4 608 faces).
//! Run: `cargo bench --bench dcharts`.

use criterion::{criterion_group, criterion_main, Criterion};
use flatcut::flatten::charts::{self, FlattenOptions};
use flatcut::geom::mesh::Mesh;
use flatcut::surface::dcharts::{self, DChartsOptions};
use flatcut::surface::Surface;
use std::path::Path;

fn load(name: &str) -> Option<Mesh> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../shared/data/meshes")
        .join(name);
    let raw = flatcut::surface::obj::read(&path).ok()?;
    Some(flatcut::surface::obj::validate(raw, 1.0).ok()?.0)
}

fn segment_and_flatten(mesh: &Mesh) -> usize {
    let seg = dcharts::segment(mesh, &DChartsOptions::default()).expect("segment");
    let s = Surface {
        name: "bench".into(),
        mesh: mesh.clone(),
        charts: Some(seg.chart),
        cuts: seg.cuts,
        ..Default::default()
    };
    charts::charts(s, &FlattenOptions::default())
        .expect("flatten")
        .islands
        .len()
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("dcharts");
    g.sample_size(10);
    for name in ["fandisk.obj", "mushroom.obj"] {
        let Some(mesh) = load(name) else {
            eprintln!("{name}: not found beside the checkout (../shared/data/meshes); skipped");
            continue;
        };
        let stem = name.trim_end_matches(".obj");
        g.bench_function(format!("segment {stem}"), |b| {
            b.iter(|| dcharts::segment(&mesh, &DChartsOptions::default()).expect("segment"))
        });
        g.bench_function(format!("segment+flatten {stem}"), |b| {
            b.iter(|| segment_and_flatten(&mesh))
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
