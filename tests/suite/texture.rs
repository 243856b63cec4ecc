//! Textured papercraft (issue 25 item 3): a cube OBJ whose texture the test makes (each face
//! its own colour with an L-shaped marker) prints each face's colour inside its flat face and
//! none outside it but the bleed past cut edges, none on the glue tabs, in the PNG and in the
//! PDF (rasterised by poppler); a missing or broken texture is a warning naming the file and
//! the pieces print plain.

use crate::common::{flatcut, scratch, stderr};
use crate::pdf::poppler;
use glam::DVec2;
use std::path::Path;
use std::process::Command;

/// Face colours at least 155 apart and at least 70 from every stroke colour and its blends
/// with white and black (so an anti-aliased line never reads as a face).
const COLOURS: [[u8; 3]; 6] = [
    [210, 30, 240],
    [210, 150, 30],
    [0, 210, 60],
    [180, 0, 90],
    [30, 0, 180],
    [90, 240, 210],
];

/// Writes `cube.obj`, `cube.mtl` and `tex.png` (3 × 2 cells of 60 px, one colour each with a
/// black L) into `dir`; returns the OBJ line of each face, in face order.
fn textured_cube(dir: &Path) -> Vec<usize> {
    let (w, h) = (180u32, 120u32);
    let img = image::RgbImage::from_fn(w, h, |x, y| {
        let cell = (y / 60) * 3 + x / 60;
        let (lx, ly) = (x % 60, y % 60);
        let marker = (8..14).contains(&lx) && (8..30).contains(&ly)
            || (8..24).contains(&lx) && (24..30).contains(&ly);
        image::Rgb(if marker {
            [0, 0, 0]
        } else {
            COLOURS[cell as usize]
        })
    });
    img.save(dir.join("tex.png")).unwrap();
    std::fs::write(
        dir.join("cube.mtl"),
        "newmtl skin\nKd 1 1 1\nmap_Kd tex.png\n",
    )
    .unwrap();
    let v = [
        [0, 0, 0],
        [1, 0, 0],
        [1, 1, 0],
        [0, 1, 0],
        [0, 0, 1],
        [1, 0, 1],
        [1, 1, 1],
        [0, 1, 1],
    ];
    // Outward, counter-clockwise.
    let faces = [
        [1, 4, 3, 2],
        [5, 6, 7, 8],
        [1, 2, 6, 5],
        [2, 3, 7, 6],
        [3, 4, 8, 7],
        [4, 1, 5, 8],
    ];
    let mut lines = vec!["mtllib cube.mtl".to_string()];
    lines.extend(v.iter().map(|p| format!("v {} {} {}", p[0], p[1], p[2])));
    for k in 0..6 {
        let (cx, cy) = ((k % 3) as f64, (k / 3) as f64);
        let (u0, u1) = (cx / 3.0 + 0.01, (cx + 1.0) / 3.0 - 0.01);
        let (v1, v0) = (1.0 - cy / 2.0 - 0.01, 1.0 - (cy + 1.0) / 2.0 + 0.01);
        for (u, v) in [(u0, v0), (u1, v0), (u1, v1), (u0, v1)] {
            lines.push(format!("vt {u:.6} {v:.6}"));
        }
    }
    lines.push("usemtl skin".into());
    let mut face_lines = Vec::new();
    for (k, f) in faces.iter().enumerate() {
        let corners: Vec<String> = f
            .iter()
            .enumerate()
            .map(|(j, vi)| format!("{vi}/{}", 4 * k + j + 1))
            .collect();
        lines.push(format!("f {}", corners.join(" ")));
        face_lines.push(lines.len());
    }
    std::fs::write(dir.join("cube.obj"), lines.join("\n") + "\n").unwrap();
    face_lines
}

/// The face colour a pixel shows (within 50 of it), if any.
fn face_colour(px: [u8; 3]) -> Option<usize> {
    COLOURS.iter().position(|c| {
        let d: f64 = (0..3)
            .map(|k| (f64::from(c[k]) - f64::from(px[k])).powi(2))
            .sum();
        d.sqrt() < 50.0
    })
}

fn seg_dist(p: DVec2, a: DVec2, b: DVec2) -> f64 {
    let d = b - a;
    let t = ((p - a).dot(d) / d.length_squared().max(1e-18)).clamp(0.0, 1.0);
    p.distance(a + d * t)
}

fn inside(p: DVec2, poly: &[DVec2]) -> bool {
    let mut c = false;
    for k in 0..poly.len() {
        let (a, b) = (poly[k], poly[(k + 1) % poly.len()]);
        if (a.y > p.y) != (b.y > p.y) && p.x < a.x + (p.y - a.y) / (b.y - a.y) * (b.x - a.x) {
            c = !c;
        }
    }
    c
}

fn dist_to(p: DVec2, poly: &[DVec2]) -> f64 {
    (0..poly.len())
        .map(|k| seg_dist(p, poly[k], poly[(k + 1) % poly.len()]))
        .fold(f64::INFINITY, f64::min)
}

/// The flat faces (sheet mm, with the index of their colour) and the pieces' outer cut
/// outlines, per sheet.
struct Laid {
    faces: Vec<(Vec<DVec2>, usize)>,
    outlines: Vec<Vec<DVec2>>,
    size: DVec2,
}

fn laid(run: &flatcut::pipeline::CutRun, face_lines: &[usize]) -> Vec<Laid> {
    let layout = &run.layout;
    let mut out: Vec<Laid> = layout
        .sheets
        .iter()
        .map(|s| Laid {
            faces: Vec::new(),
            outlines: Vec::new(),
            size: DVec2::new(s.width, s.height),
        })
        .collect();
    let flat = &run.flats[0];
    for (piece, at) in layout.pieces.iter().zip(&layout.placements) {
        let l = &mut out[at.sheet];
        l.outlines
            .push(piece.outline[0].iter().map(|p| at.apply(*p)).collect());
        for &f in &piece.faces {
            let line = flat.surface.mesh.faces[f].line.unwrap();
            let colour = face_lines.iter().position(|&k| k == line).unwrap();
            let pts = flat.face_2d[f].iter().map(|p| at.apply(*p)).collect();
            l.faces.push((pts, colour));
        }
    }
    out
}

/// Checks a picture of a sheet: `pixel(p)` is the colour at sheet point `p` (mm). Returns the
/// share of samples inside faces that show their own colour.
fn check(l: &Laid, pixel: &dyn Fn(DVec2) -> Option<[u8; 3]>, what: &str) -> f64 {
    let bleed = flatcut::output::texture::BLEED_MM;
    let (mut own, mut inner) = (0usize, 0usize);
    let (mut tab_samples, mut outside_samples) = (0, 0);
    let step = 0.5;
    let (nx, ny) = ((l.size.x / step) as usize, (l.size.y / step) as usize);
    for i in 0..nx {
        for j in 0..ny {
            let p = DVec2::new((i as f64 + 0.5) * step, (j as f64 + 0.5) * step);
            let Some(px) = pixel(p) else { continue };
            let got = face_colour(px);
            let host = l.faces.iter().find(|(poly, _)| inside(p, poly));
            let (d, nearest) = l
                .faces
                .iter()
                .map(|(poly, c)| (dist_to(p, poly), *c))
                .fold((f64::INFINITY, 0), |a, b| if b.0 < a.0 { b } else { a });
            match host {
                Some((_, c)) if d > 0.4 => {
                    inner += 1;
                    if got == Some(*c) {
                        own += 1;
                    }
                    assert!(
                        got.is_none() || got == Some(*c),
                        "{what}: at {p} inside face {c} the colour of face {got:?} ({px:?})"
                    );
                }
                None if d > 0.4 => {
                    let on_piece = l.outlines.iter().any(|o| inside(p, o));
                    if on_piece {
                        // A glue tab (or another part of a piece that is no face).
                        tab_samples += 1;
                        assert!(
                            got.is_none(),
                            "{what}: at {p} on a tab, {d:.2} mm off face {nearest}, the colour of face {got:?}"
                        );
                    } else {
                        outside_samples += 1;
                        assert!(
                            got.is_none() || (got == Some(nearest) && d <= bleed + 0.4),
                            "{what}: at {p}, {d:.2} mm outside face {nearest}, the colour of face {got:?}"
                        );
                    }
                }
                _ => {}
            }
        }
    }
    assert!(
        tab_samples > 100 && outside_samples > 1000,
        "{tab_samples} {outside_samples}"
    );
    assert!(inner > 1000);
    own as f64 / inner as f64
}

#[test]
fn a_textured_cube_prints_each_face_in_its_colour() {
    let dir = scratch("texture-cube");
    let face_lines = textured_cube(&dir);
    let mut spec = flatcut::spec::load(&dir.join("cube.obj")).unwrap();
    spec.size = Some(50.0);
    let profile = flatcut::pipeline::device("sim", None, None).unwrap();
    let out = dir.join("out");
    let extras = flatcut::pipeline::Extras {
        output: Some(out.clone()),
        quiet: true,
        dpi: Some(200.0),
        ..Default::default()
    };
    let run = flatcut::pipeline::cut(
        &spec,
        &profile,
        &flatcut::pipeline::Search::default(),
        &flatcut::pipeline::Toolpath::default(),
        &extras,
    )
    .unwrap();
    assert!(run.flats[0].surface.texture.is_some());
    let sheets = laid(&run, &face_lines);
    assert_eq!(sheets.iter().map(|s| s.faces.len()).sum::<usize>(), 6);

    // The PNG: (x + 2 mm, height − y + 2 mm) at 200 dpi.
    for (k, l) in sheets.iter().enumerate() {
        let png = image::open(out.join(format!("cube-{}.png", k + 1)))
            .unwrap()
            .to_rgb8();
        let s = 200.0 / 25.4;
        let pixel = |p: DVec2| {
            let (x, y) = ((p.x + 2.0) * s, (l.size.y - p.y + 2.0) * s);
            (x >= 0.0 && y >= 0.0 && x < png.width() as f64 && y < png.height() as f64)
                .then(|| png.get_pixel(x as u32, y as u32).0)
        };
        let share = check(l, &pixel, "PNG");
        eprintln!(
            "PNG sheet {}: {:.1} % of face samples in their own colour",
            k + 1,
            share * 100.0
        );
        assert!(share > 0.85, "{share}");
    }

    // The PDF at 100 dpi.
    if !poppler() {
        return;
    }
    for (k, l) in sheets.iter().enumerate() {
        let root = out.join(format!("pdf-{}", k + 1));
        let o = Command::new("pdftoppm")
            .args(["-r", "100", "-png", "-singlefile"])
            .args(["-f", &(k + 1).to_string(), "-l", &(k + 1).to_string()])
            .arg(out.join("cube.pdf"))
            .arg(&root)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", stderr(&o));
        let r = image::open(root.with_extension("png")).unwrap().to_rgb8();
        let s = 100.0 / 25.4;
        let pixel = |p: DVec2| {
            let (x, y) = (p.x * s, (l.size.y - p.y) * s);
            (x >= 0.0 && y >= 0.0 && x < r.width() as f64 && y < r.height() as f64)
                .then(|| r.get_pixel(x as u32, y as u32).0)
        };
        let share = check(l, &pixel, "PDF");
        eprintln!(
            "PDF sheet {}: {:.1} % of face samples in their own colour",
            k + 1,
            share * 100.0
        );
        assert!(share > 0.85, "{share}");
    }
}

#[test]
fn a_missing_or_broken_texture_is_a_warning_and_prints_plain() {
    let dir = scratch("texture-missing");
    textured_cube(&dir);
    let cut = |out: &str| {
        let out = dir.join(out);
        let o = flatcut(&[
            "cut",
            dir.join("cube.obj").to_str().unwrap(),
            "--size",
            "50",
            "--dry-run",
            "-o",
            out.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        let png = image::open(out.join("cube-1.png")).unwrap().to_rgb8();
        let coloured = png.pixels().filter(|p| face_colour(p.0).is_some()).count();
        (stderr(&o), coloured)
    };
    let (err, coloured) = cut("with");
    assert!(!err.contains("tex.png"), "{err}");
    assert!(coloured > 10_000, "{coloured}");

    std::fs::write(dir.join("tex.png"), b"\x89PNG but not really").unwrap();
    let (err, coloured) = cut("broken");
    assert!(
        err.contains("tex.png") && err.contains("print plain"),
        "{err}"
    );
    assert_eq!(coloured, 0);

    std::fs::remove_file(dir.join("tex.png")).unwrap();
    let (err, coloured) = cut("missing");
    assert!(
        err.contains("tex.png") && err.contains("cannot be read"),
        "{err}"
    );
    assert_eq!(coloured, 0);

    std::fs::remove_file(dir.join("cube.mtl")).unwrap();
    let (err, coloured) = cut("no-library");
    assert!(
        err.contains("cube.mtl") && err.contains("cube.obj:1"),
        "{err}"
    );
    assert_eq!(coloured, 0);
}
