//! Unfolding `../shared/data/meshes/fandisk.obj` (12,946 triangles, scaled to a ~100 mm part)
//! with the default options. Reference: Blender 3.4's Export Paper Model add-on takes 467 s and
//! makes 7 islands on this mesh on this kind of machine; the target is under 0.5 s with no
//! more islands. Run: `cargo bench --bench unfold`.

use criterion::{criterion_group, criterion_main, Criterion};
use flatcut::flatten::{unfold, UnfoldOptions};
use flatcut::surface::{obj, Surface};
use std::path::Path;

fn fandisk() -> Surface {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data/meshes/fandisk.obj");
    let raw = obj::read(&path).expect("fandisk.obj (../shared/data beside the checkout)");
    let (mesh, warnings) = obj::validate(raw, 100.0).expect("valid mesh");
    Surface {
        name: "fandisk".into(),
        source: path,
        mesh,
        warnings,
        bends: None,
        charts: None,
        ..Default::default()
    }
}

fn bench(c: &mut Criterion) {
    let surface = fandisk();
    let islands = unfold(surface.clone(), &UnfoldOptions::default())
        .expect("unfold")
        .islands
        .len();
    eprintln!(
        "fandisk: {} faces, {islands} islands",
        surface.mesh.faces.len()
    );
    let mut g = c.benchmark_group("unfold");
    g.sample_size(20);
    g.bench_function("fandisk", |b| {
        b.iter(|| unfold(surface.clone(), &UnfoldOptions::default()).expect("unfold"))
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
