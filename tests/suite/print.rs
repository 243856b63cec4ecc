//! Tiled printing (`--print`, issue 25 item 2): a 610 × 900 mm sheet on A4 pages, read back by
//! poppler. Every cut drawn on a page, the overlap strips of neighbouring pages equal pixel
//! for pixel at 300 dpi, the assembly map naming every page, no page without a stroke, and
//! the bad papers refused naming the flag.

use crate::common::{flatcut, scratch, stderr};
use crate::pdf::{cut, hpgl_cuts, hpgl_strokes, measure, pdfinfo_pages, poppler, raster};
use std::process::Command;

/// Points every `step` mm along the strokes.
fn samples(strokes: &[Vec<[f64; 2]>], step: f64) -> Vec<[f64; 2]> {
    let mut out = Vec::new();
    for s in strokes {
        for w in s.windows(2) {
            let d = (w[1][0] - w[0][0]).hypot(w[1][1] - w[0][1]);
            let n = (d / step).ceil().max(1.0) as usize;
            for k in 0..=n {
                let t = k as f64 / n as f64;
                out.push([
                    w[0][0] + (w[1][0] - w[0][0]) * t,
                    w[0][1] + (w[1][1] - w[0][1]) * t,
                ]);
            }
        }
    }
    out
}

struct Tile {
    page: usize,
    label: String,
    row: usize,
    col: usize,
    window: [f64; 4],
    at: [f64; 2],
}

fn tiles(rep: &serde_json::Value) -> Vec<Tile> {
    rep["print"]["sheets"][0]["tiles"]
        .as_array()
        .unwrap()
        .iter()
        .map(|t| {
            let f = |v: &serde_json::Value| v.as_f64().unwrap();
            let w: Vec<f64> = t["window_mm"].as_array().unwrap().iter().map(f).collect();
            let a: Vec<f64> = t["at_mm"].as_array().unwrap().iter().map(f).collect();
            Tile {
                page: t["page"].as_u64().unwrap() as usize,
                label: t["label"].as_str().unwrap().to_string(),
                row: t["row"].as_u64().unwrap() as usize,
                col: t["col"].as_u64().unwrap() as usize,
                window: [w[0], w[1], w[2], w[3]],
                at: [a[0], a[1]],
            }
        })
        .collect()
}

const DPI: f64 = 300.0;

/// Pixel (column, row) of sheet point `p` on the page of `t`, `page_h` mm high.
fn px(t: &Tile, page_h: f64, p: [f64; 2]) -> (f64, f64) {
    let x = t.at[0] + p[0] - t.window[0];
    let y = t.at[1] + p[1] - t.window[1];
    (x * DPI / 25.4, (page_h - y) * DPI / 25.4)
}

#[test]
fn a_610_by_900_sheet_tiled_on_a4() {
    if !poppler() {
        return;
    }
    let dir = scratch("print-tiled");
    cut(
        &dir,
        &[
            "patterns/house.toml",
            "--sheet",
            "610x900",
            "--size",
            "300",
            "--print",
            "a4",
        ],
    );
    let rep: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("report.json")).unwrap()).unwrap();
    assert_eq!(rep["sheets"].as_array().unwrap().len(), 1, "one sheet");
    let pdf = dir.join("house-print.pdf");
    let sizes = pdfinfo_pages(&pdf);
    let pages = rep["print"]["pages"].as_u64().unwrap() as usize;
    assert_eq!(sizes.len(), pages);
    let sheet = &rep["print"]["sheets"][0];
    let page_mm = [
        sheet["page_mm"][0].as_f64().unwrap(),
        sheet["page_mm"][1].as_f64().unwrap(),
    ];
    for s in &sizes {
        assert!((s.0 - page_mm[0]).abs() < 0.01 && (s.1 - page_mm[1]).abs() < 0.01);
        // A4, either way round.
        let (a, b) = (s.0.min(s.1), s.0.max(s.1));
        assert!(
            (a - 210.0).abs() < 0.01 && (b - 297.0).abs() < 0.01,
            "{s:?}"
        );
    }
    let tiles = tiles(&rep);
    let blank: Vec<String> = sheet["blank"]
        .as_array()
        .unwrap()
        .iter()
        .map(|b| b.as_str().unwrap().to_string())
        .collect();
    let (rows, cols) = (
        sheet["rows"].as_u64().unwrap() as usize,
        sheet["cols"].as_u64().unwrap() as usize,
    );
    assert_eq!(tiles.len() + blank.len(), rows * cols);
    assert_eq!(pages, 1 + tiles.len(), "the map and the printed pages");
    eprintln!(
        "{rows} x {cols} pages, {} printed, blank: {blank:?}",
        tiles.len()
    );
    assert!(!blank.is_empty(), "this layout leaves pages out");

    // The map names every page, printed or blank.
    let map = sheet["map_page"].as_u64().unwrap().to_string();
    let o = Command::new("pdftotext")
        .args(["-f", &map, "-l", &map, pdf.to_str().unwrap(), "-"])
        .output()
        .unwrap();
    assert!(o.status.success(), "pdftotext: {}", stderr(&o));
    let text = String::from_utf8_lossy(&o.stdout).into_owned();
    for label in tiles.iter().map(|t| &t.label).chain(&blank) {
        assert!(
            text.split_whitespace()
                .any(|w| w.trim_matches(['(', ')']) == label),
            "{label} not on the map: {text}"
        );
    }

    // The map's test squares measure 50 mm and 2 in at 300 dpi (lower left, 4 mm inside the
    // printable area, 4 mm apart).
    let m = rep["print"]["margin_mm"].as_f64().unwrap() + 4.0;
    let r = raster(&pdf, map.parse().unwrap(), 300, &dir);
    for (x, side) in [(m, 50.0), (m + 54.0, 50.8)] {
        let (across, down) = measure(&r, 300.0, page_mm[1], [x, m, side, side]);
        eprintln!("map: {side} mm square measures {across:.4} x {down:.4} mm");
        assert!((across - side).abs() < 0.1 && (down - side).abs() < 0.1);
    }

    // Every page raster at 300 dpi.
    let rasters: Vec<(usize, usize, Vec<u8>)> = tiles
        .iter()
        .map(|t| raster(&pdf, t.page, 300, &dir))
        .collect();
    let dark = |r: &(usize, usize, Vec<u8>), c: f64, row: f64, reach: i64, below: u8| {
        let (w, h, px) = r;
        let (c, row) = (c.round() as i64, row.round() as i64);
        (-reach..=reach).any(|dy| {
            (-reach..=reach).any(|dx| {
                let (x, y) = (c + dx, row + dy);
                x >= 0
                    && y >= 0
                    && (x as usize) < *w
                    && (y as usize) < *h
                    && px[y as usize * w + x as usize] < below
            })
        })
    };

    // Every cut is drawn: each point along the cuts, on a page whose window holds it with
    // 1 mm to spare, lies on a dark pixel.
    let plt = std::fs::read_to_string(dir.join("house.plt")).unwrap();
    let cuts = samples(&hpgl_cuts(&plt), 2.0);
    assert!(cuts.len() > 200);
    let inside = |t: &Tile, p: [f64; 2], m: f64| {
        p[0] >= t.window[0] + m
            && p[0] <= t.window[2] - m
            && p[1] >= t.window[1] + m
            && p[1] <= t.window[3] - m
    };
    let mut checked = 0;
    for p in &cuts {
        let hosts: Vec<usize> = (0..tiles.len())
            .filter(|&k| inside(&tiles[k], *p, 1.0))
            .collect();
        assert!(!hosts.is_empty(), "cut point {p:?} is on no page");
        for k in hosts {
            let (c, r) = px(&tiles[k], page_mm[1], *p);
            assert!(
                dark(&rasters[k], c, r, 2, 96),
                "cut point {p:?} not drawn on page {}",
                tiles[k].label
            );
            checked += 1;
        }
    }
    eprintln!("{} cut points checked on the pages", checked);

    // No page without a stroke: each printed window holds a point of some stroke.
    let all = samples(&hpgl_strokes(&plt, None), 1.0);
    for t in &tiles {
        assert!(
            all.iter().any(|p| inside(t, *p, -1.0)),
            "page {} has nothing on it",
            t.label
        );
    }

    // Overlap strips: neighbours (same row, next column; same column, next row) show the same
    // pixels where their windows overlap, 2 px in from the clip edges.
    let mut pairs = 0;
    let mut inked = 0;
    for (i, a) in tiles.iter().enumerate() {
        for (j, b) in tiles.iter().enumerate() {
            let right = a.row == b.row && b.col == a.col + 1;
            let below = a.col == b.col && b.row == a.row + 1;
            if !(right || below) {
                continue;
            }
            let lo = [a.window[0].max(b.window[0]), a.window[1].max(b.window[1])];
            let hi = [a.window[2].min(b.window[2]), a.window[3].min(b.window[3])];
            assert!(hi[0] > lo[0] && hi[1] > lo[1]);
            let (ax0, ay0) = px(a, page_mm[1], [lo[0], hi[1]]);
            let (ax1, ay1) = px(a, page_mm[1], [hi[0], lo[1]]);
            let (bx0, by0) = px(b, page_mm[1], [lo[0], hi[1]]);
            // The shift between the pages is a whole number of pixels.
            let (sx, sy) = (bx0 - ax0, by0 - ay0);
            assert!(
                (sx - sx.round()).abs() < 1e-6 && (sy - sy.round()).abs() < 1e-6,
                "shift {sx} {sy}"
            );
            let (sx, sy) = (sx.round() as i64, sy.round() as i64);
            let (ra, rb) = (&rasters[i], &rasters[j]);
            let mut differ = 0;
            let mut n = 0;
            let mut ink = 0;
            for y in (ay0.ceil() as i64 + 2)..(ay1.floor() as i64 - 2) {
                for x in (ax0.ceil() as i64 + 2)..(ax1.floor() as i64 - 2) {
                    let pa = ra.2[y as usize * ra.0 + x as usize];
                    let pb = rb.2[(y + sy) as usize * rb.0 + (x + sx) as usize];
                    n += 1;
                    if pa != pb {
                        differ += 1;
                    }
                    if pa < 250 {
                        ink += 1;
                    }
                }
            }
            assert!(n > 10_000, "strip of {n} px");
            assert_eq!(
                differ, 0,
                "pages {} and {}: {differ} of {n} px differ in their overlap",
                a.label, b.label
            );
            pairs += 1;
            inked += usize::from(ink > 100);
        }
    }
    eprintln!("{pairs} overlap strips equal pixel for pixel, {inked} with ink in them");
    assert!(pairs >= 4);
    assert_eq!(inked, pairs, "every strip carries at least its match line");
}

#[test]
fn tiled_print_is_deterministic_and_bad_papers_are_refused() {
    let (a, b) = (scratch("print-same-a"), scratch("print-same-b"));
    let args = [
        "patterns/cube.toml",
        "--sheet",
        "a4",
        "--print",
        "letter",
        "--overlap",
        "5",
    ];
    cut(&a, &args);
    cut(&b, &args);
    let (pa, pb) = (
        std::fs::read(a.join("cube-print.pdf")).unwrap(),
        std::fs::read(b.join("cube-print.pdf")).unwrap(),
    );
    assert!(pa == pb, "the tiled PDFs differ");
    let rep: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(a.join("report.json")).unwrap()).unwrap();
    assert_eq!(rep["print"]["paper"], "letter");
    // 5 mm on the 0.254 mm grid.
    assert_eq!(rep["print"]["overlap_mm"].as_f64(), Some(5.08));
    // PNGs at print resolution with --print: 300 dpi is 11811 px/m in pHYs.
    let png = std::fs::read(a.join("cube-1.png")).unwrap();
    let at = png.windows(4).position(|w| w == b"pHYs").unwrap();
    let ppm = u32::from_be_bytes(png[at + 4..at + 8].try_into().unwrap());
    assert_eq!(ppm, 11811);

    let dir = scratch("print-bad");
    let out = dir.join("out");
    let o = flatcut(&[
        "cut",
        "patterns/cube.toml",
        "--print",
        "40x40",
        "--dry-run",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("--print 40x40"), "{}", stderr(&o));
    let written = std::fs::read_dir(&out).map_or(0, |d| d.count());
    assert_eq!(written, 0, "nothing written");
    for bad in [
        ["--print", "b5"],
        ["--print", "0x10"],
        ["--print", "a0"],
        ["--overlap", "-3"],
    ] {
        let mut args = vec!["cut", "patterns/cube.toml", "--dry-run", "-o"];
        args.push(out.to_str().unwrap());
        args.extend(bad);
        if bad[0] == "--overlap" {
            args.extend(["--print", "a4"]);
        }
        let o = flatcut(&args);
        assert_eq!(o.status.code(), Some(1), "{bad:?}: {}", stderr(&o));
        assert!(stderr(&o).contains(bad[0]), "{bad:?}: {}", stderr(&o));
    }
}
