//! Pieces much larger than the sheet, and many large pieces on few sheets (issue 20: the
//! corpus at sizes other than 300 mm): the turbine blade at 1,500 mm on A4 in paper, from the
//! mesh to its pieces split to fit the sheet (`pipeline::pieces`), and the nest of homer cut
//! with `--segment faces` at 300 mm on A4 (171 pieces, outlines of up to thousands of
//! segments), its pieces made once before timing. Run: `cargo bench --bench pieces`.

use criterion::{criterion_group, criterion_main, Criterion};
use flatcut::spec::{Material, MaterialKind, Spec};
use flatcut::surface::Segment;
use std::hint::black_box;
use std::path::{Path, PathBuf};

fn mesh(name: &str) -> Option<PathBuf> {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../shared/data/meshes")
        .join(name);
    if p.exists() {
        Some(p)
    } else {
        eprintln!("{name}: not found beside the checkout (../shared/data/meshes); skipped");
        None
    }
}

fn spec(path: &Path, size: f64, segment: Option<Segment>) -> Spec {
    let mut spec = Spec::from_mesh(path);
    spec.size = Some(size);
    spec.material = Material {
        kind: MaterialKind::Paper,
        thickness: MaterialKind::Paper.default_thickness(),
        ..Material::default()
    };
    for s in &mut spec.surfaces {
        s.segment.mode = segment.or(s.segment.mode);
    }
    spec
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("pieces");
    g.sample_size(10);
    if let Some(blade) = mesh("blade.obj") {
        let spec = spec(&blade, 1500.0, None);
        g.bench_function("split blade 1500 mm on A4", |b| {
            b.iter(|| black_box(flatcut::pipeline::pieces(&spec, true).expect("pieces")))
        });
    }
    if let Some(homer) = mesh("homer.obj") {
        let spec = spec(&homer, 300.0, Some(Segment::Faces));
        let (_, pieces) = flatcut::pipeline::pieces(&spec, true).expect("pieces");
        let opts = flatcut::nest::NestOptions {
            width: spec.sheet.width,
            height: spec.sheet.height,
            margin: spec.sheet.margin,
            spacing: spec.sheet.spacing,
            ..Default::default()
        };
        g.bench_function("nest homer faces on A4", |b| {
            b.iter(|| black_box(flatcut::nest::nest(pieces.clone(), &opts).expect("nest")))
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
