//! D-Charts (issue 7) on the acceptance meshes: segmentation alone, and segmentation plus
//! laying every chart flat (what `flatcut flatten MESH --segment dcharts` does before the
//! pattern stage), on fandisk (12 946 faces; issue 7's target: under 1 s), mushroom (4 608),
//! homer (9 856: issue 20's "10k-face mesh", target under 1 s) and mushroom cut four times
//! finer (each triangle into four at its edge midpoints, twice: 73 728 faces, issue 20's
//! "75k-face mesh", target under 10 s). Each mesh is scaled to 300 mm across, as the command
//! line lays meshes out. Run: `cargo bench --bench dcharts`.

use criterion::{criterion_group, criterion_main, Criterion};
use flatcut::flatten::charts::{self, FlattenOptions};
use flatcut::geom::mesh::{Face, Mesh};
use flatcut::surface::dcharts::{self, DChartsOptions};
use flatcut::surface::Surface;
use std::path::Path;

fn load(name: &str) -> Option<Mesh> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../shared/data/meshes")
        .join(name);
    let raw = flatcut::surface::obj::read(&path).ok()?;
    let mut mesh = flatcut::surface::obj::validate(raw, 1.0).ok()?.0;
    let (lo, hi) = flatcut::geom::mesh::bounds3(mesh.vertices.iter())?;
    let k = 300.0 / (hi - lo).max_element();
    for v in &mut mesh.vertices {
        *v *= k;
    }
    Some(mesh)
}

/// Each triangle cut into four at its edge midpoints (shared along edges).
fn finer(mesh: &Mesh) -> Mesh {
    let mut vertices = mesh.vertices.clone();
    let mut mid = std::collections::HashMap::new();
    let mut at = |a: usize, b: usize, vertices: &mut Vec<glam::DVec3>| {
        *mid.entry((a.min(b), a.max(b))).or_insert_with(|| {
            vertices.push(0.5 * (vertices[a] + vertices[b]));
            vertices.len() - 1
        })
    };
    let mut faces = Vec::with_capacity(4 * mesh.faces.len());
    for f in &mesh.faces {
        let [a, b, c] = [f.verts[0], f.verts[1], f.verts[2]];
        let (ab, bc, ca) = (
            at(a, b, &mut vertices),
            at(b, c, &mut vertices),
            at(c, a, &mut vertices),
        );
        for verts in [[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]] {
            faces.push(Face {
                verts: verts.to_vec(),
                line: f.line,
            });
        }
    }
    Mesh { vertices, faces }
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
    let meshes = ["fandisk", "mushroom", "homer"]
        .into_iter()
        .filter_map(|stem| match load(&format!("{stem}.obj")) {
            Some(m) => Some((stem.to_string(), m)),
            None => {
                eprintln!(
                    "{stem}.obj: not found beside the checkout (../shared/data/meshes); skipped"
                );
                None
            }
        })
        .collect::<Vec<_>>();
    let fine = meshes
        .iter()
        .find(|(s, _)| s == "mushroom")
        .map(|(_, m)| ("mushroom x16".to_string(), finer(&finer(m))));
    for (stem, mesh) in meshes.iter().chain(&fine) {
        g.bench_function(format!("segment {stem}"), |b| {
            b.iter(|| dcharts::segment(mesh, &DChartsOptions::default()).expect("segment"))
        });
        g.bench_function(format!("segment+flatten {stem}"), |b| {
            b.iter(|| segment_and_flatten(mesh))
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
