//! Parameterisation speed: LSCM on a 100k-triangle disk (issue 7 acceptance), ABF++ on a
//! smaller one, and the stretch metric.
//!
//! The disk: a 224 x 224 grid of squares split into triangles (100,352 triangles), mapped onto
//! a round disk of radius 100 mm and lifted into a smooth dome, so it is not developable and
//! the solver has real work to do.

use criterion::{criterion_group, criterion_main, Criterion};
use flatcut::flatten::{distortion, parameterize, ParamMethod};
use flatcut::geom::mesh::{Face, Mesh};
use glam::DVec3;
use std::hint::black_box;

fn dome_disk(n: usize) -> Mesh {
    let mut vertices = Vec::with_capacity((n + 1) * (n + 1));
    for j in 0..=n {
        for i in 0..=n {
            // Square [-1, 1]² onto the unit disk (elliptical grid mapping), then a dome.
            let x = 2.0 * i as f64 / n as f64 - 1.0;
            let y = 2.0 * j as f64 / n as f64 - 1.0;
            let u = x * (1.0 - 0.5 * y * y).sqrt();
            let v = y * (1.0 - 0.5 * x * x).sqrt();
            let z = 30.0 * (-(u * u + v * v) * 2.0).exp();
            vertices.push(DVec3::new(100.0 * u, 100.0 * v, z));
        }
    }
    let id = |i: usize, j: usize| j * (n + 1) + i;
    let mut faces = Vec::with_capacity(2 * n * n);
    for j in 0..n {
        for i in 0..n {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            // Split along the diagonal that avoids slivers at the mapped corners.
            let (t1, t2) = if (i < n / 2) == (j < n / 2) {
                ([a, b, c], [a, c, d])
            } else {
                ([a, b, d], [b, c, d])
            };
            for t in [t1, t2] {
                faces.push(Face {
                    verts: t.to_vec(),
                    line: None,
                });
            }
        }
    }
    Mesh { vertices, faces }
}

fn bench(c: &mut Criterion) {
    let big = dome_disk(224);
    let all: Vec<usize> = (0..big.faces.len()).collect();
    assert_eq!(all.len(), 100_352);
    let mut g = c.benchmark_group("param");
    g.sample_size(10);
    g.bench_function("LSCM on a 100k-triangle disk", |b| {
        b.iter(|| {
            let p =
                parameterize(black_box(&big), black_box(&all), ParamMethod::Lscm).expect("lscm");
            assert_eq!(p.stretch.flipped, 0);
            p
        })
    });
    let small = dome_disk(70);
    let some: Vec<usize> = (0..small.faces.len()).collect();
    g.bench_function("ABF++ on a 10k-triangle disk", |b| {
        b.iter(|| parameterize(black_box(&small), black_box(&some), ParamMethod::Abf).expect("abf"))
    });
    let p = parameterize(&big, &all, ParamMethod::Lscm).expect("lscm");
    g.bench_function("stretch of a 100k-triangle layout", |b| {
        b.iter(|| distortion::stretch(black_box(&big), black_box(&all), black_box(&p.uv)))
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
