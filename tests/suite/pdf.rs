//! The PDF of a run (issue 25): read by poppler (`pdfinfo`, `pdftoppm`), a page per sheet of the
//! sheet's size, the 50 mm test square measured in a 300 dpi raster, the cut outlines equal to
//! the job's and the HP-GL's, one optional content group per stroke kind, byte-identical
//! output; and the PNGs' `pHYs` with `--dpi`.
//!
//! poppler-utils is a Debian package (`.ci/run` installs it): without it the tests that need it
//! skip with a line on stderr, and fail when `CI` is set.

use crate::common::{flatcut, manifest, scratch, stderr};
use std::path::Path;
use std::process::Command;

/// Whether `pdfinfo` and `pdftoppm` are there; panics under CI when they are not.
pub(crate) fn poppler() -> bool {
    let have = |tool: &str| Command::new(tool).arg("-v").output().is_ok();
    if have("pdfinfo") && have("pdftoppm") {
        return true;
    }
    assert!(
        std::env::var_os("CI").is_none(),
        "CI: the PDF tests need pdfinfo and pdftoppm (Debian's poppler-utils; .ci/run installs it)"
    );
    eprintln!("skipped: no pdfinfo or pdftoppm (apt-get install poppler-utils)");
    false
}

/// `flatcut cut ARGS --dry-run -q -o DIR`, which must succeed.
pub(crate) fn cut(dir: &Path, args: &[&str]) {
    let mut all = vec!["cut"];
    all.extend_from_slice(args);
    all.extend(["--dry-run", "-q", "-o", dir.to_str().unwrap()]);
    let o = flatcut(&all);
    assert!(o.status.success(), "{all:?}: {}", stderr(&o));
}

/// (width, height) in mm of every sheet in a run's report.json.
fn report_sheets(dir: &Path) -> Vec<(f64, f64)> {
    let text = std::fs::read_to_string(dir.join("report.json")).unwrap();
    let rep: serde_json::Value = serde_json::from_str(&text).unwrap();
    rep["sheets"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| {
            (
                s["width_mm"].as_f64().unwrap(),
                s["height_mm"].as_f64().unwrap(),
            )
        })
        .collect()
}

/// `pdfinfo -f 1 -l N FILE`: the page sizes in mm, page by page.
pub(crate) fn pdfinfo_pages(pdf: &Path) -> Vec<(f64, f64)> {
    let o = Command::new("pdfinfo").arg(pdf).output().unwrap();
    assert!(o.status.success(), "pdfinfo: {}", stderr(&o));
    let text = String::from_utf8_lossy(&o.stdout).into_owned();
    let pages: i32 = field(&text, "Pages:").parse().unwrap();
    let o = Command::new("pdfinfo")
        .args(["-f", "1", "-l", &pages.to_string()])
        .arg(pdf)
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&o.stdout).into_owned();
    let sizes: Vec<(f64, f64)> = text
        .lines()
        .filter(|l| l.starts_with("Page") && l.contains(" size:"))
        .map(|l| {
            // "Page    1 size: 595.276 x 841.89 pts (A4)"
            let v: Vec<f64> = l
                .split(':')
                .nth(1)
                .unwrap()
                .split_whitespace()
                .filter_map(|t| t.parse().ok())
                .collect();
            (v[0] * 25.4 / 72.0, v[1] * 25.4 / 72.0)
        })
        .collect();
    assert_eq!(sizes.len() as i32, pages, "{text}");
    sizes
}

fn field<'a>(text: &'a str, name: &str) -> &'a str {
    text.lines()
        .find_map(|l| l.strip_prefix(name))
        .map(str::trim)
        .unwrap_or_else(|| panic!("no {name} in {text}"))
}

#[test]
fn pdfinfo_reads_a_page_per_sheet_of_the_sheets_size() {
    if !poppler() {
        return;
    }
    let runs: [(&str, &[&str]); 3] = [
        ("pdf-house", &["patterns/house.toml"]),
        // Three A4 sheets.
        ("pdf-cube-a4", &["patterns/cube.toml", "--sheet", "a4"]),
        // A roll: the page is as long as the roll used.
        ("pdf-cube-roll", &["patterns/cube.toml"]),
    ];
    for (name, args) in runs {
        let dir = scratch(name);
        cut(&dir, args);
        let sheets = report_sheets(&dir);
        let stem = Path::new(args[0]).file_stem().unwrap().to_str().unwrap();
        let pages = pdfinfo_pages(&dir.join(format!("{stem}.pdf")));
        assert_eq!(pages.len(), sheets.len(), "{name}: pages");
        if name == "pdf-cube-a4" {
            assert_eq!(pages.len(), 3, "{name}");
        }
        for (k, (page, sheet)) in pages.iter().zip(&sheets).enumerate() {
            let dw = (page.0 - sheet.0).abs();
            let dh = (page.1 - sheet.1).abs();
            eprintln!("{name} page {}: {page:?} mm, sheet {sheet:?}", k + 1);
            assert!(
                dw < 0.1 && dh < 0.1,
                "{name} page {}: {page:?} vs {sheet:?}",
                k + 1
            );
        }
        // Listed like the SVG.
        let rep = std::fs::read_to_string(dir.join("report.json")).unwrap();
        assert!(
            rep.contains(&format!("\"{stem}.pdf\"")),
            "{name}: report.json"
        );
    }
}

/// One page of a PDF written by flatcut, read back from its uncompressed content stream:
/// per layer name, the subpaths (points in mm, closed or not) and rectangles (x, y, w, h).
#[derive(Debug, Default)]
struct Page {
    paths: Vec<(String, Vec<[f64; 2]>, bool)>,
    rects: Vec<(String, [f64; 4])>,
}

/// The layer (OCG) names of a flatcut PDF, by their resource name (`oc1`…), and its pages.
fn read_pdf(bytes: &[u8]) -> (Vec<(String, String)>, Vec<Page>) {
    let text = String::from_utf8_lossy(bytes).into_owned();
    // OCG objects: "N 0 obj\n<<\n  /Type /OCG\n  /Name (Cut)\n>>".
    let mut ocgs = Vec::new();
    for (at, _) in text.match_indices("/Type /OCG") {
        let head = &text[..at];
        let obj_at = head.rfind(" 0 obj").unwrap();
        let num = head[..obj_at]
            .rsplit('\n')
            .next()
            .unwrap()
            .trim()
            .to_string();
        let name_at = at + text[at..].find("/Name (").unwrap() + 7;
        let name = &text[name_at..name_at + text[name_at..].find(')').unwrap()];
        ocgs.push((num, name.to_string()));
    }
    let props_at = text
        .find("/Properties <<")
        .expect("page resources name the layers");
    let props = &text[props_at + 14..props_at + text[props_at..].find(">>").unwrap()];
    let toks: Vec<&str> = props.split_whitespace().collect();
    let mut layers = Vec::new();
    for t in toks.chunks(4) {
        let res = t[0].trim_start_matches('/').to_string();
        let name = ocgs.iter().find(|(n, _)| n == t[1]).unwrap().1.clone();
        layers.push((res, name));
    }
    let mut pages = Vec::new();
    let mut rest = text.as_str();
    while let Some(s) = rest.find("stream\n") {
        let body = &rest[s + 7..];
        let e = body.find("endstream").unwrap();
        pages.push(read_content(&body[..e], &layers));
        rest = &body[e + 9..];
    }
    (layers, pages)
}

fn read_content(stream: &str, layers: &[(String, String)]) -> Page {
    let mut page = Page::default();
    let mut nums: Vec<f64> = Vec::new();
    let mut layer = String::new();
    let mut last_name = String::new();
    let mut path: Vec<[f64; 2]> = Vec::new();
    let flush = |page: &mut Page, path: &mut Vec<[f64; 2]>, layer: &str, closed: bool| {
        if !path.is_empty() {
            page.paths
                .push((layer.to_string(), std::mem::take(path), closed));
        }
    };
    for tok in stream.split_whitespace() {
        if let Ok(v) = tok.parse::<f64>() {
            nums.push(v);
            continue;
        }
        match tok {
            "cm" => {
                let k = 72.0 / 25.4;
                assert_eq!(nums.len(), 6);
                assert!((nums[0] - k).abs() < 1e-5 && (nums[3] - k).abs() < 1e-5);
            }
            "BDC" => {
                layer = layers
                    .iter()
                    .find(|(r, _)| *r == last_name)
                    .map(|(_, n)| n.clone())
                    .unwrap_or_else(|| panic!("unknown layer {last_name}"));
            }
            "EMC" => layer.clear(),
            "m" => {
                flush(&mut page, &mut path, &layer, false);
                path.push([nums[0], nums[1]]);
            }
            "l" => path.push([nums[0], nums[1]]),
            "h" => flush(&mut page, &mut path, &layer, true),
            "S" => flush(&mut page, &mut path, &layer, false),
            "re" => page
                .rects
                .push((layer.clone(), [nums[0], nums[1], nums[2], nums[3]])),
            t if t.starts_with('/') => last_name = t[1..].to_string(),
            _ => {}
        }
        nums.clear();
    }
    page
}

/// 8-bit grey raster of page `page` (1-based) at `dpi`: (width, height, pixels).
pub(crate) fn raster(pdf: &Path, page: usize, dpi: u32, out: &Path) -> (usize, usize, Vec<u8>) {
    let root = out.join(format!("page-{page}"));
    let o = Command::new("pdftoppm")
        .args(["-r", &dpi.to_string(), "-gray", "-singlefile"])
        .args(["-f", &page.to_string(), "-l", &page.to_string()])
        .arg(pdf)
        .arg(&root)
        .output()
        .unwrap();
    assert!(o.status.success(), "pdftoppm: {}", stderr(&o));
    let bytes = std::fs::read(root.with_extension("pgm")).unwrap();
    // P5\n<w> <h>\n255\n<pixels>
    let mut fields = Vec::new();
    let mut at = 0;
    while fields.len() < 4 {
        while bytes[at].is_ascii_whitespace() {
            at += 1;
        }
        let start = at;
        while !bytes[at].is_ascii_whitespace() {
            at += 1;
        }
        fields.push(String::from_utf8_lossy(&bytes[start..at]).into_owned());
    }
    assert_eq!(fields[0], "P5");
    let (w, h): (usize, usize) = (fields[1].parse().unwrap(), fields[2].parse().unwrap());
    let px = bytes[at + 1..].to_vec();
    assert_eq!(px.len(), w * h);
    (w, h, px)
}

/// The centre of the dark line crossing `samples` (positions in px, darkness 0–255): the
/// darkness-weighted mean position.
fn centre(samples: impl Iterator<Item = (f64, u8)>) -> f64 {
    let (mut sum, mut weight) = (0.0, 0.0);
    for (pos, v) in samples {
        let d = f64::from(255 - v);
        sum += pos * d;
        weight += d;
    }
    assert!(
        weight > 0.0,
        "no dark pixels where the square's edge should be"
    );
    sum / weight
}

/// The side of the square at `rect` (mm, x y w h, on a page `page_h` mm high) measured in the
/// raster: the distance between the centres of its opposite edges along 21 lines across its
/// middle, in mm, (horizontal, vertical), each the mean over the lines.
pub(crate) fn measure(
    r: &(usize, usize, Vec<u8>),
    dpi: f64,
    page_h: f64,
    rect: [f64; 4],
) -> (f64, f64) {
    let (w, h, px) = r;
    let k = dpi / 25.4;
    let at = |col: i64, row: i64| -> u8 {
        if col < 0 || row < 0 || col as usize >= *w || row as usize >= *h {
            255
        } else {
            px[row as usize * w + col as usize]
        }
    };
    let [x, y, side, _] = rect;
    // Edges in px: left, right, top, bottom; windows ±2 mm around them.
    let (left, right) = (x * k, (x + side) * k);
    let (top, bottom) = ((page_h - y - side) * k, (page_h - y) * k);
    let win = (2.0 * k) as i64;
    let (mut across, mut down) = (0.0, 0.0);
    for i in -10..=10 {
        // Lines through the middle fifth of the square.
        let row = ((top + bottom) / 2.0 + f64::from(i) * side * k / 100.0) as i64;
        let col = ((left + right) / 2.0 + f64::from(i) * side * k / 100.0) as i64;
        let edge_x = |e: f64| {
            centre((e as i64 - win..=e as i64 + win).map(|c| (c as f64 + 0.5, at(c, row))))
        };
        let edge_y = |e: f64| {
            centre((e as i64 - win..=e as i64 + win).map(|r| (r as f64 + 0.5, at(col, r))))
        };
        across += edge_x(right) - edge_x(left);
        down += edge_y(bottom) - edge_y(top);
    }
    (across / 21.0 / k, down / 21.0 / k)
}

#[test]
fn test_squares_measure_50_mm_and_2_in_at_300_dpi() {
    if !poppler() {
        return;
    }
    let mut measured = 0;
    for (name, sheet) in [
        ("pdf-square-house", None),
        // Sheets crowded with pieces: the squares find another free spot, or lie over them.
        ("pdf-square-crowded", Some(200.0)),
    ] {
        let mut spec = flatcut::spec::load(&manifest("patterns/house.toml")).unwrap();
        if let Some(side) = sheet {
            spec.sheet.width = side;
            spec.sheet.height = Some(side);
        }
        let (dir, job) = library_cut(&spec, name);
        let file = dir.join("house.pdf");
        let (_, pages) = read_pdf(&std::fs::read(&file).unwrap());
        let sizes = pdfinfo_pages(&file);
        assert_eq!(pages.len(), job.sheets.len());
        for (k, ((page, size), sheet)) in pages.iter().zip(&sizes).zip(&job.sheets).enumerate() {
            let squares: Vec<_> = page
                .rects
                .iter()
                .filter(|(l, _)| l == "Test squares")
                .collect();
            let (placed, free) = flatcut::output::pdf::test_squares(sheet);
            assert_eq!(squares.len(), 2, "{name} page {}", k + 1);
            for ((_, rect), sq) in squares.iter().zip(&placed) {
                assert!((rect[0] - sq.corner.x).abs() < 1e-3 && (rect[2] - sq.side).abs() < 1e-3);
            }
            if !free {
                eprintln!(
                    "{name} page {}: no free spot, the squares lie over the pieces: not measured",
                    k + 1
                );
                continue;
            }
            let r = raster(&file, k + 1, 300, &dir);
            // 300 dpi: 50 mm is 590.55 px.
            let want_w = size.0 * 300.0 / 25.4;
            assert!((r.0 as f64 - want_w).abs() <= 1.0, "raster {} px wide", r.0);
            for ((_, rect), want) in squares.iter().zip([50.0, 50.8]) {
                let (across, down) = measure(&r, 300.0, size.1, *rect);
                eprintln!(
                    "{name} page {}: {want} mm square at ({}, {}) measures {across:.4} × {down:.4} mm ({:.2} px)",
                    k + 1,
                    rect[0],
                    rect[1],
                    across * 300.0 / 25.4
                );
                assert!(
                    (across - want).abs() < 0.1 && (down - want).abs() < 0.1,
                    "{name} page {}: {want} mm square measures {across} × {down} mm",
                    k + 1
                );
                measured += 1;
            }
        }
    }
    // The house's A3 page and the crowded run's second page at least.
    assert!(measured >= 4, "{measured} squares measured");
}

/// `pipeline::cut` of `spec` on `sim` into a scratch directory `name`: the directory and the
/// job as designed (what the PDF draws).
fn library_cut(
    spec: &flatcut::spec::Spec,
    name: &str,
) -> (std::path::PathBuf, flatcut::toolpath::Job) {
    let profile = flatcut::pipeline::device("sim", None, None).unwrap();
    let dir = scratch(name);
    let extras = flatcut::pipeline::Extras {
        output: Some(dir.clone()),
        quiet: true,
        ..Default::default()
    };
    let run = flatcut::pipeline::cut(
        spec,
        &profile,
        &flatcut::pipeline::Search::default(),
        &flatcut::pipeline::Toolpath::default(),
        &extras,
    )
    .unwrap();
    (dir, run.job)
}

/// The HP-GL's pen-down strokes with pen 1 (the cut pen of `sim`), in mm (40 units per mm).
pub(crate) fn hpgl_cuts(plt: &str) -> Vec<Vec<[f64; 2]>> {
    hpgl_strokes(plt, Some(1))
}

/// The HP-GL's pen-down strokes with `pen` (any pen: `None`), in mm (40 units per mm).
pub(crate) fn hpgl_strokes(plt: &str, only: Option<i32>) -> Vec<Vec<[f64; 2]>> {
    let mut strokes: Vec<Vec<[f64; 2]>> = Vec::new();
    let (mut pen, mut at) = (0, [0.0, 0.0]);
    for cmd in plt.split(';').map(str::trim) {
        let (op, args) = cmd.split_at(cmd.len().min(2));
        let nums: Vec<f64> = args
            .split(',')
            .filter_map(|t| t.trim().parse::<f64>().ok())
            .map(|v| v / 40.0)
            .collect();
        match op {
            "SP" => pen = nums.first().map_or(0, |v| (v * 40.0).round() as i32),
            "PU" => {
                if let Some(c) = nums.chunks(2).last() {
                    at = [c[0], c[1]];
                }
            }
            "PD" if only.is_none_or(|p| p == pen) => {
                let mut s = vec![at];
                s.extend(nums.chunks(2).map(|c| [c[0], c[1]]));
                at = *s.last().unwrap();
                strokes.push(s);
            }
            "PD" => {
                if let Some(c) = nums.chunks(2).last() {
                    at = [c[0], c[1]];
                }
            }
            _ => {}
        }
    }
    strokes
}

fn dist(a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

/// Distance from `p` to the nearest segment of any of `strokes`.
fn to_strokes(p: [f64; 2], strokes: &[Vec<[f64; 2]>]) -> f64 {
    let seg = |a: [f64; 2], b: [f64; 2]| {
        let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
        let len2 = dx * dx + dy * dy;
        let t = if len2 > 0.0 {
            (((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / len2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        dist(p, [a[0] + t * dx, a[1] + t * dy])
    };
    strokes
        .iter()
        .flat_map(|s| {
            s.windows(2)
                .map(|w| seg(w[0], w[1]))
                .chain([seg(s[0], s[0])])
        })
        .fold(f64::INFINITY, f64::min)
}

#[test]
fn cut_outlines_equal_the_jobs_and_the_hpgls() {
    use flatcut::toolpath::StrokeRole;
    let spec = flatcut::spec::load(&manifest("patterns/house.toml")).unwrap();
    let (dir, job) = library_cut(&spec, "pdf-outlines");
    let (_, pages) = read_pdf(&std::fs::read(dir.join("house.pdf")).unwrap());
    assert_eq!(pages.len(), job.sheets.len());
    let sheet = &job.sheets[0];
    // The job's cuts and notches, in its order, closed ones without their repeated end.
    let want: Vec<(Vec<[f64; 2]>, bool)> = sheet
        .strokes
        .iter()
        .filter(|s| matches!(s.role, StrokeRole::Cut | StrokeRole::Notch))
        .map(|s| {
            let mut p: Vec<[f64; 2]> = s.points.iter().map(|q| [q.x, q.y]).collect();
            if s.closed && p.len() > 2 && dist(p[0], p[p.len() - 1]) < 1e-9 {
                p.pop();
            }
            (p, s.closed)
        })
        .collect();
    let got: Vec<_> = pages[0]
        .paths
        .iter()
        .filter(|(l, _, _)| l == "Cut")
        .collect();
    assert_eq!(got.len(), want.len(), "cut subpaths");
    assert!(!want.is_empty());
    let mut worst: f64 = 0.0;
    for ((_, g, gc), (w, wc)) in got.iter().zip(&want) {
        assert_eq!(gc, wc, "closed");
        assert_eq!(g.len(), w.len(), "points of a cut");
        for (a, b) in g.iter().zip(w) {
            worst = worst.max(dist(*a, *b));
        }
    }
    eprintln!("PDF cut points vs the job: {worst:.5} mm at worst");
    assert!(worst <= 0.05, "{worst} mm");

    // Against the HP-GL (sim: no knife offset, no overcut, sheet frame as is): every PDF cut
    // point lies on an HP-GL cut and every HP-GL cut point on a PDF cut.
    let plt = std::fs::read_to_string(dir.join("house.plt")).unwrap();
    let hp = hpgl_cuts(&plt);
    assert!(!hp.is_empty());
    let pdf_cuts: Vec<Vec<[f64; 2]>> = got
        .iter()
        .map(|(_, p, closed)| {
            let mut p = p.clone();
            if *closed {
                p.push(p[0]);
            }
            p
        })
        .collect();
    let a = pdf_cuts
        .iter()
        .flatten()
        .map(|p| to_strokes(*p, &hp))
        .fold(0.0, f64::max);
    let b = hp
        .iter()
        .flatten()
        .map(|p| to_strokes(*p, &pdf_cuts))
        .fold(0.0, f64::max);
    eprintln!("PDF cuts vs HP-GL cuts: {a:.4} mm, HP-GL vs PDF: {b:.4} mm at worst");
    assert!(a <= 0.05 && b <= 0.05, "{a} {b}");
}

#[test]
fn a_layer_per_stroke_kind() {
    use flatcut::output::pdf::Layer;
    let dir = scratch("pdf-layers");
    cut(&dir, &["patterns/cube.toml", "--sheet", "a4"]);
    let bytes = std::fs::read(dir.join("cube.pdf")).unwrap();
    let text = String::from_utf8_lossy(&bytes).into_owned();
    assert!(text.contains("/OCProperties"));
    let (layers, pages) = read_pdf(&bytes);
    let names: Vec<&str> = layers.iter().map(|(_, n)| n.as_str()).collect();
    eprintln!("layers: {names:?}");
    for want in ["Cut", "Folds", "Marks", "Labels", "Test squares"] {
        assert!(names.contains(&want), "{want} in {names:?}");
    }
    // Each drawn thing is in a layer, and every layer has something in it.
    for page in &pages {
        assert!(page.paths.iter().all(|(l, _, _)| !l.is_empty()));
    }
    for name in &names {
        assert!(
            pages
                .iter()
                .any(|p| p.paths.iter().any(|(l, _, _)| l == name)),
            "{name} is empty"
        );
    }
    assert_eq!(
        Layer::of(flatcut::toolpath::StrokeRole::FoldValley).name(),
        "Folds"
    );
}

#[test]
fn two_runs_give_the_same_pdf() {
    let (a, b) = (scratch("pdf-same-a"), scratch("pdf-same-b"));
    cut(&a, &["patterns/cube.toml", "--sheet", "a4"]);
    cut(&b, &["patterns/cube.toml", "--sheet", "a4"]);
    let (pa, pb) = (
        std::fs::read(a.join("cube.pdf")).unwrap(),
        std::fs::read(b.join("cube.pdf")).unwrap(),
    );
    assert!(pa.len() > 1000);
    assert!(pa == pb, "the PDFs differ");
}

/// The `pHYs` chunk of a PNG: (x px/m, y px/m, unit), and its width.
fn png_phys(png: &[u8]) -> (Option<(u32, u32, u8)>, u32) {
    let be = |b: &[u8]| u32::from_be_bytes(b.try_into().unwrap());
    let width = be(&png[16..20]);
    let mut at = 8;
    while at + 12 <= png.len() {
        let len = be(&png[at..at + 4]) as usize;
        if &png[at + 4..at + 8] == b"pHYs" {
            let d = &png[at + 8..at + 17];
            return (Some((be(&d[0..4]), be(&d[4..8]), d[8])), width);
        }
        at += 12 + len;
    }
    (None, width)
}

#[test]
fn png_dpi_sets_phys_and_size() {
    let dir = scratch("pdf-png-dpi");
    cut(&dir, &["patterns/house.toml", "--dpi", "300"]);
    let (phys, width) = png_phys(&std::fs::read(dir.join("house-1.png")).unwrap());
    assert_eq!(phys, Some((11811, 11811, 1)));
    // The picture is the 297 mm sheet and a 2 mm border each side.
    let border = 2.0;
    let want = (297.0 + 2.0 * border) * 300.0 / 25.4;
    eprintln!("house-1.png at 300 dpi: {width} px wide, {want:.2} px expected");
    assert!((f64::from(width) - want).abs() <= 1.0, "{width} px");

    // Without --dpi: the preview's 4 px/mm, said in pHYs.
    let dir = scratch("pdf-png-default");
    cut(&dir, &["patterns/house.toml"]);
    let (phys, _) = png_phys(&std::fs::read(dir.join("house-1.png")).unwrap());
    assert_eq!(phys, Some((4000, 4000, 1)));

    // flatten takes it too.
    let dir = scratch("pdf-png-flatten");
    let o = flatcut(&[
        "flatten",
        "patterns/house.toml",
        "--dpi",
        "150",
        "-q",
        "-o",
        dir.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let (phys, _) = png_phys(&std::fs::read(dir.join("house-1.png")).unwrap());
    assert_eq!(phys, Some((5906, 5906, 1)));
    assert!(dir.join("house.pdf").is_file());

    // 1200 dpi of the 424 mm tall picture (the A3 sheet and its borders) is over 6000 px:
    // drawn coarser, said on stderr, and pHYs says the scale drawn at.
    let dir = scratch("pdf-png-capped");
    let o = flatcut(&[
        "cut",
        "patterns/house.toml",
        "--dry-run",
        "--dpi",
        "1200",
        "-o",
        dir.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let e = stderr(&o);
    assert!(
        e.contains("warning: --dpi 1200: house-1.png") && e.contains("house.pdf"),
        "{e}"
    );
    let (phys, width) = png_phys(&std::fs::read(dir.join("house-1.png")).unwrap());
    assert!(width <= 6000, "{width}");
    let want = (6000.0 / (420.0 + 2.0 * border) * 1000.0).round() as u32;
    assert_eq!(phys, Some((want, want, 1)), "{e}");

    for bad in ["0", "abc", "-3", "1201", "nan"] {
        let dir = scratch("pdf-png-bad");
        let o = flatcut(&[
            "cut",
            "patterns/house.toml",
            "--dry-run",
            "-q",
            "--dpi",
            bad,
            "-o",
            dir.to_str().unwrap(),
        ]);
        assert_eq!(o.status.code(), Some(1), "--dpi {bad}");
        assert!(stderr(&o).contains("--dpi"), "--dpi {bad}: {}", stderr(&o));
        assert!(!dir.join("house.pdf").exists());
    }
}
