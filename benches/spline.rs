//! One guided-projection iteration of spline developables (issue 24, Tang et al. 2016 Fig. 17):
//! a two-strip problem of 36 control points (Fig. 13's size; the paper: 0.04 s per iteration)
//! and a 44-strip chain of 270 control points (near Fig. 12's 48 strips, 270 points; the
//! paper: 0.36 s), each also with every interior curve a fold crease (eq. 7), as the paper's
//! examples have, and a flat sheet with a fold isometric to its outline (eq. 12) and lifted by
//! handles, as Fig. 13 is (also with the fold stated, `folds`). The goal is 10× faster than the paper. Each sample times the second
//! `Problem::iterate` of a solve from a non-developable start (the set-up and the first
//! iteration, which finds the sparsity pattern and its symbolic factorisation, are not
//! timed: the pattern is kept for the iterations after it).
//! Run: `cargo bench --bench spline`.

use criterion::{criterion_group, criterion_main, BatchSize, Criterion};
use flatcut::geom::bspline::BSpline;
use flatcut::surface::spline::solve::{Crease, FoldGoal, Model, Problem};
use glam::{DVec2, DVec3};

/// `curves` wavy open cubic curves of `count` control points, 40 mm apart, twisted so that no
/// strip is developable as given; with `folds`, every interior curve is a fold crease (eq. 7).
fn chain(curves: usize, count: usize, folds: bool) -> Model {
    let c = (0..curves)
        .map(|k| {
            (0..count)
                .map(|j| {
                    let (x, y) = (j as f64 * 30.0, k as f64 * 40.0);
                    let z = 20.0 * ((j as f64) * 0.7 + (k as f64) * 0.9).sin();
                    DVec3::new(x, y, z)
                })
                .collect()
        })
        .collect();
    Model {
        basis: BSpline::new(3, count, false).expect("cubic"),
        curves: c,
        apex: None,
        fixed: Vec::new(),
        creases: if folds {
            vec![Crease::Fold; curves.saturating_sub(2)]
        } else {
            Vec::new()
        },
        folds: Vec::new(),
        target: None,
        handles: Vec::new(),
        outline: None,
    }
}

/// Fig. 13's kind of problem: a flat 330 × 200 mm sheet of three curves of 12 control points
/// with a bowed fold crease, isometric to its outline (eq. 12), its far corners lifted 60 mm
/// by handles and its first edge fixed.
fn sheet_fold() -> Model {
    let c: Vec<Vec<DVec3>> = [0.0, 1.0, 2.0]
        .iter()
        .map(|&k| {
            (0..12)
                .map(|j| {
                    let x = j as f64 * 30.0;
                    let bow = if k == 1.0 {
                        25.0 * (x / 330.0 * std::f64::consts::PI).sin()
                    } else {
                        0.0
                    };
                    DVec3::new(x, k * 100.0 + bow, 0.0)
                })
                .collect()
        })
        .collect();
    Model {
        basis: BSpline::new(3, 12, false).expect("cubic"),
        fixed: (0..12).map(|j| (0, j)).collect(),
        creases: vec![Crease::Fold],
        folds: Vec::new(),
        target: None,
        handles: vec![
            (c[2][0], DVec3::new(f64::NAN, f64::NAN, 60.0)),
            (c[2][11], DVec3::new(f64::NAN, f64::NAN, 60.0)),
        ],
        outline: Some(vec![
            DVec2::new(0.0, 0.0),
            DVec2::new(330.0, 0.0),
            DVec2::new(330.0, 200.0),
            DVec2::new(0.0, 200.0),
        ]),
        curves: c,
        apex: None,
    }
}

fn bench(c: &mut Criterion) {
    for (name, m) in [
        ("36 control points, 2 strips", chain(3, 12, false)),
        (
            "36 control points, 2 strips, fold crease, isometric to its outline, 2 handles",
            sheet_fold(),
        ),
        (
            "36 control points, 2 strips, fold crease stated as a 20° valley, isometric to its outline, 2 handles",
            Model {
                folds: vec![Some(FoldGoal {
                    valley: true,
                    angle: Some(20f64.to_radians()),
                })],
                ..sheet_fold()
            },
        ),
        (
            "36 control points, 2 strips, fold crease",
            chain(3, 12, true),
        ),
        ("270 control points, 44 strips", chain(45, 6, false)),
        (
            "270 control points, 44 strips, 43 fold creases",
            chain(45, 6, true),
        ),
    ] {
        let p = Problem::new(&m).expect("set up");
        eprintln!(
            "{name}: {} unknowns, start sine {:.3e}",
            p.unknowns(),
            p.sine()
        );
        c.bench_function(&format!("spline one iteration, {name}"), |b| {
            b.iter_batched(
                || {
                    let mut p = Problem::new(&m).expect("set up");
                    p.iterate(0.1, 0.01, 1).expect("first iteration");
                    p
                },
                |mut p| {
                    p.iterate(0.09, 0.01, 2).expect("iterate");
                    p
                },
                BatchSize::SmallInput,
            )
        });
    }
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(20).measurement_time(std::time::Duration::from_secs(3));
    targets = bench
}
criterion_main!(benches);
