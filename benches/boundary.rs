//! Rose et al. boundary triangulation (issue 6): a smooth, non-planar closed boundary of 200
//! points (a taco-like ellipse folded up at both ends, with a gentle three-lobed wave), the
//! whole search (hulls, charts, branch and bound). Target: under 1 s. Also the gazebo roof
//! pattern, which runs the full 1000 iterations.
//! Run: `cargo bench --bench boundary`.

use criterion::{criterion_group, criterion_main, Criterion};
use flatcut::surface::boundary::{triangulate, Input, Options};
use glam::DVec3;
use std::f64::consts::TAU;

fn boundary(n: usize) -> Vec<DVec3> {
    (0..n)
        .map(|k| {
            let t = TAU * k as f64 / n as f64;
            let x = 100.0 * t.cos();
            DVec3::new(x, 60.0 * t.sin(), 0.006 * x * x + 4.0 * (3.0 * t).sin())
        })
        .collect()
}

fn bench(c: &mut Criterion) {
    let input = Input {
        loops: vec![boundary(200)],
        ..Default::default()
    };
    let opts = Options::default();
    let out = triangulate(&input, &opts).expect("triangulates");
    let f = &out.figures;
    eprintln!(
        "200 points: {} triangles, {} interior, {}/{} interior edges locally convex, largest dihedral {:.2}°, {} iterations, {:.3} s",
        f.triangles,
        f.interior_triangles,
        f.convex_edges,
        f.interior_edges,
        f.largest_dihedral_deg,
        f.iterations,
        f.seconds
    );
    let mut g = c.benchmark_group("boundary");
    g.sample_size(10);
    g.bench_function("smooth_200", |b| {
        b.iter(|| triangulate(std::hint::black_box(&input), &opts).expect("triangulates"))
    });
    // A branch-and-bound heavy one: the gazebo roof pattern (60 points, the full 1000
    // iterations), for reference.
    let gazebo = flatcut::geom::curve::read_csv(
        &std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("patterns/gazebo-roof.csv"),
    )
    .expect("patterns/gazebo-roof.csv");
    let gazebo = Input {
        loops: vec![gazebo],
        ..Default::default()
    };
    g.bench_function("gazebo_roof_60", |b| {
        b.iter(|| triangulate(std::hint::black_box(&gazebo), &opts).expect("triangulates"))
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
