//! Wang–Tang strip triangulation at m = n = 2000 (issue 4): GODT+GMBT (fewest invalid bridges,
//! then least bending energy, one dynamic program on the dual-node graph), and GODT and GMBT
//! alone. Target: GODT + GMBT under 100 ms. Run: `cargo bench --bench strip`.

use criterion::{criterion_group, criterion_main, Criterion};
use flatcut::surface::strip::{Method, Strip};
use glam::DVec3;
use std::f64::consts::PI;

/// A lace-like strip: two wavy 3D curves along half a hem, `m` points each.
fn lace(m: usize) -> Strip {
    let curve = |r0: f64, z0: f64, a: f64, f: f64, ph: f64, za: f64| -> Vec<DVec3> {
        (0..m)
            .map(|k| {
                let u = PI * k as f64 / (m - 1) as f64;
                let r = r0 + a * (f * u + ph).sin();
                DVec3::new(r * u.cos(), r * u.sin(), z0 + za * (1.3 * f * u).sin())
            })
            .collect()
    };
    Strip::raw(
        curve(150.0, 0.0, 6.0, 90.0, 0.0, 4.0),
        curve(170.0, 30.0, 8.0, 70.0, 1.0, 6.0),
    )
}

fn bench(c: &mut Criterion) {
    let s = lace(2000);
    let mt = s.metrics(&s.triangulate(Method::GodtGmbt));
    eprintln!(
        "m = n = 2000: GODT+GMBT {} of {} interior bridges locally convex",
        mt.convex, mt.interior
    );
    // On a shared machine wall time overstates the cost: also report this thread's CPU time
    // (Linux: /proc/thread-self/schedstat, first field, ns on a CPU).
    let cpu = || -> Option<f64> {
        let t = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
        t.split_whitespace().next()?.parse::<f64>().ok()
    };
    if let Some(c0) = cpu() {
        let w0 = std::time::Instant::now();
        for _ in 0..5 {
            std::hint::black_box(s.triangulate(Method::GodtGmbt));
        }
        let wall = w0.elapsed().as_secs_f64() / 5.0 * 1e3;
        if let Some(c1) = cpu() {
            eprintln!(
                "godt+gmbt 2000x2000: {:.1} ms CPU, {wall:.1} ms wall per run",
                (c1 - c0) / 5.0 / 1e6
            );
        }
    }
    let mut g = c.benchmark_group("strip");
    g.sample_size(10);
    g.bench_function("godt+gmbt 2000x2000", |b| {
        b.iter(|| s.triangulate(Method::GodtGmbt))
    });
    g.bench_function("godt 2000x2000", |b| b.iter(|| s.triangulate(Method::Godt)));
    g.bench_function("gmbt 2000x2000", |b| b.iter(|| s.triangulate(Method::Gmbt)));
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
