//! PNG output: a raster preview of one sheet of a job.
//!
//! Choices:
//! - The canvas is the sheet plus a `BORDER_MM` white border on every side, at `px_per_mm`
//!   ([`DEFAULT_PX_PER_MM`] unless the caller asks otherwise). If the longer side would exceed
//!   `MAX_SIDE_PX`, the scale is reduced so that it fits: a preview of a 10 m roll is still
//!   drawn, just coarser, rather than failing or allocating gigabytes.
//! - A sheet with a zero, negative or non-finite size, a scale that is not a positive finite
//!   number, or a canvas that cannot be allocated gives [`OutputError::Picture`].
//! - White background, sheet outline light grey, the textured faces of a textured model
//!   ([`super::texture`]), then the strokes in `DRAW_ORDER` (labels,
//!   marks, valley folds, mountain folds, cuts on top), colours and dash patterns as in the SVG
//!   (see `role_style` in the module root). Lines are `LINE_MM` wide but at least 1 px,
//!   anti-aliased, round caps and joins. Dash lengths are the mm values times the scale; when a
//!   line had to be widened to 1 px, its dashes grow by the same factor so that the pattern
//!   stays readable.
//! - Geometry is converted to pixels here (x' = (x + border)·s, y' = (height − y + border)·s),
//!   so widths and dashes are plain pixel values. Strokes with fewer than two points or
//!   non-finite coordinates are skipped.
//! - The PNG says its resolution: a `pHYs` chunk (inserted after `IHDR`, as tiny-skia writes
//!   none) with the scale actually drawn at, in px per metre (px/mm × 1000, rounded), so a
//!   picture drawn coarser to fit `MAX_SIDE_PX` does not claim the asked-for resolution.
//! - The bytes depend only on the input: tiny-skia draws deterministically and the PNG carries
//!   no time stamp.

use tiny_skia::{
    Color, LineCap, LineJoin, Paint, PathBuilder, Pixmap, Rect, Stroke, StrokeDash, Transform,
};

use super::{role_style, OutputError, DRAW_ORDER};
use crate::toolpath::SheetJob;

/// Scale used when the caller has no preference: 4 px per mm (about 100 dpi).
pub const DEFAULT_PX_PER_MM: f64 = 4.0;

/// Longest side of a picture, px; larger pictures are drawn at a reduced scale.
pub const MAX_SIDE_PX: u32 = 6000;

/// White border around the sheet, mm.
pub(crate) const BORDER_MM: f64 = 2.0;

/// Width of the stroke lines, mm (at least 1 px).
pub(crate) const LINE_MM: f64 = 0.3;

/// Width of the sheet outline, mm (at least 1 px).
const SHEET_OUTLINE_MM: f64 = 0.2;

/// Sheet outline colour, light grey.
const SHEET_GREY: u8 = 0xc0;

/// The scale (px per mm) a sheet is drawn at when `px_per_mm` is asked for: that, or less so
/// that the picture (the sheet and its border) fits [`MAX_SIDE_PX`] on its longer side.
pub fn drawn_px_per_mm(sheet: &SheetJob, px_per_mm: f64) -> f64 {
    let longer = (sheet.width + 2.0 * BORDER_MM).max(sheet.height + 2.0 * BORDER_MM);
    let max_side = f64::from(MAX_SIDE_PX);
    if longer * px_per_mm > max_side {
        max_side / longer
    } else {
        px_per_mm
    }
}

/// Renders sheet `index` of a job (the index is only used in errors) as PNG bytes at
/// `px_per_mm`, reduced if needed so that neither side exceeds `MAX_SIDE_PX`.
pub fn render(sheet: &SheetJob, index: usize, px_per_mm: f64) -> Result<Vec<u8>, OutputError> {
    render_painted(sheet, index, px_per_mm, &[], &[])
}

/// [`render`] with textured faces (of the images `images`) under the strokes.
pub fn render_painted(
    sheet: &SheetJob,
    index: usize,
    px_per_mm: f64,
    faces: &[super::texture::TexturedFace],
    images: &[&crate::surface::texture::Image],
) -> Result<Vec<u8>, OutputError> {
    let picture_error = |w: f64, h: f64| OutputError::Picture {
        sheet: index,
        width_px: to_px(w),
        height_px: to_px(h),
    };
    let valid = |v: f64| v.is_finite() && v > 0.0;
    if !valid(sheet.width) || !valid(sheet.height) || !valid(px_per_mm) {
        return Err(picture_error(
            sheet.width * px_per_mm,
            sheet.height * px_per_mm,
        ));
    }

    let w_mm = sheet.width + 2.0 * BORDER_MM;
    let h_mm = sheet.height + 2.0 * BORDER_MM;
    let max_side = f64::from(MAX_SIDE_PX);
    let scale = drawn_px_per_mm(sheet, px_per_mm);
    let w_px = (w_mm * scale).ceil().min(max_side);
    let h_px = (h_mm * scale).ceil().min(max_side);
    let mut pixmap = Pixmap::new(to_px(w_px), to_px(h_px)).ok_or(picture_error(w_px, h_px))?;
    pixmap.fill(Color::WHITE);

    let to_canvas = |x: f64, y: f64| {
        (
            ((x + BORDER_MM) * scale) as f32,
            ((sheet.height - y + BORDER_MM) * scale) as f32,
        )
    };

    // Sheet outline.
    let (left, top) = to_canvas(0.0, sheet.height);
    let (right, bottom) = to_canvas(sheet.width, 0.0);
    if let Some(rect) = Rect::from_ltrb(left, top, right, bottom) {
        let path = PathBuilder::from_rect(rect);
        let stroke = Stroke {
            width: px_width(SHEET_OUTLINE_MM, scale),
            ..Stroke::default()
        };
        let paint = solid([SHEET_GREY; 3]);
        pixmap.stroke_path(&path, &paint, &stroke, Transform::identity(), None);
    }

    if !faces.is_empty() {
        let pictures = super::texture::pictures(images);
        let to_px = (scale, BORDER_MM * scale, (sheet.height + BORDER_MM) * scale);
        super::texture::png_faces(&mut pixmap, faces, images, &pictures, to_px);
    }

    let line_px = px_width(LINE_MM, scale);
    // How much the line was widened to reach 1 px; dashes grow with it.
    let widen = f64::from(line_px) / (LINE_MM * scale);
    for role in DRAW_ORDER {
        let mut pb = PathBuilder::new();
        for s in sheet.strokes.iter().filter(|s| s.role == role) {
            let mut pts: Vec<(f32, f32)> = s.points.iter().map(|p| to_canvas(p.x, p.y)).collect();
            // Non-finite here (NaN, or too large for f32) would make tiny-skia drop the whole
            // path of this role, so the stroke alone is skipped.
            if pts.iter().any(|&(x, y)| !x.is_finite() || !y.is_finite()) {
                continue;
            }
            if s.closed && pts.len() > 2 && pts.first() == pts.last() {
                pts.pop();
            }
            if pts.len() < 2 {
                continue;
            }
            for (k, &(x, y)) in pts.iter().enumerate() {
                if k == 0 {
                    pb.move_to(x, y);
                } else {
                    pb.line_to(x, y);
                }
            }
            if s.closed {
                pb.close();
            }
        }
        // `finish` is None for an empty path (no strokes of this role).
        let Some(path) = pb.finish() else {
            continue;
        };
        let style = role_style(role);
        let dash = if style.dash_mm.is_empty() {
            None
        } else {
            let array = style
                .dash_mm
                .iter()
                .map(|&d| (d * scale * widen) as f32)
                .collect();
            StrokeDash::new(array, 0.0)
        };
        let stroke = Stroke {
            width: match role {
                // Registration marks are filled by strokes of their own width.
                crate::toolpath::StrokeRole::Register => {
                    px_width(crate::toolpath::registration::SIZE_STROKE_MM, scale)
                }
                _ => line_px,
            },
            line_cap: LineCap::Round,
            line_join: LineJoin::Round,
            dash,
            ..Stroke::default()
        };
        pixmap.stroke_path(
            &path,
            &solid(style.rgb),
            &stroke,
            Transform::identity(),
            None,
        );
    }

    let png = pixmap.encode_png().map_err(|e| OutputError::Encode {
        sheet: index,
        message: e.to_string(),
    })?;
    Ok(with_phys(png, px_per_metre(scale)))
}

/// Pixels per metre of a scale in px/mm, rounded, for `pHYs`.
pub fn px_per_metre(px_per_mm: f64) -> u32 {
    let v = (px_per_mm * 1000.0).round();
    if v.is_finite() && v >= 1.0 {
        v.min(f64::from(u32::MAX >> 1)) as u32
    } else {
        1
    }
}

/// `png` with a `pHYs` chunk (`px_per_m` in x and in y, unit: metre) right after its `IHDR`
/// (tiny-skia writes none); unchanged if it does not start with a PNG signature and `IHDR`.
fn with_phys(png: Vec<u8>, px_per_m: u32) -> Vec<u8> {
    // Signature (8), then IHDR: length (4), type (4), 13 bytes of data, CRC (4).
    const IHDR_END: usize = 8 + 4 + 4 + 13 + 4;
    if png.len() < IHDR_END || &png[1..4] != b"PNG" || &png[12..16] != b"IHDR" {
        return png;
    }
    let mut body = Vec::with_capacity(13);
    body.extend_from_slice(b"pHYs");
    body.extend_from_slice(&px_per_m.to_be_bytes());
    body.extend_from_slice(&px_per_m.to_be_bytes());
    body.push(1);
    let mut out = Vec::with_capacity(png.len() + 21);
    out.extend_from_slice(&png[..IHDR_END]);
    out.extend_from_slice(&9u32.to_be_bytes());
    out.extend_from_slice(&body);
    out.extend_from_slice(&crc32fast::hash(&body).to_be_bytes());
    out.extend_from_slice(&png[IHDR_END..]);
    out
}

/// Width in px of a `mm` wide line at `scale`, at least 1 px.
fn px_width(mm: f64, scale: f64) -> f32 {
    (mm * scale).max(1.0) as f32
}

/// Anti-aliased opaque paint.
fn solid([r, g, b]: [u8; 3]) -> Paint<'static> {
    let mut paint = Paint::default();
    paint.set_color_rgba8(r, g, b, 255);
    paint.anti_alias = true;
    paint
}

/// Pixel count for error reports and allocation: non-finite or negative → 0, saturating.
fn to_px(v: f64) -> u32 {
    if v.is_finite() && v > 0.0 {
        v as u32
    } else {
        0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::toolpath::{Stroke as TStroke, StrokeRole};
    use glam::DVec2;

    fn stroke(role: StrokeRole, pts: &[(f64, f64)], closed: bool) -> TStroke {
        TStroke {
            role,
            points: pts.iter().map(|&(x, y)| DVec2::new(x, y)).collect(),
            closed,
            piece: Some(0),
            outer: false,
        }
    }

    /// 100 × 60 mm sheet: a closed cut square, a mountain fold, a valley fold, a mark.
    fn sheet() -> SheetJob {
        SheetJob {
            width: 100.0,
            height: 60.0,
            strokes: vec![
                stroke(StrokeRole::Mark, &[(5.0, 5.0), (15.0, 5.0)], false),
                stroke(StrokeRole::FoldValley, &[(20.0, 40.0), (80.0, 40.0)], false),
                stroke(
                    StrokeRole::FoldMountain,
                    &[(20.0, 30.0), (80.0, 30.0)],
                    false,
                ),
                stroke(
                    StrokeRole::Cut,
                    &[
                        (10.0, 10.0),
                        (90.0, 10.0),
                        (90.0, 50.0),
                        (10.0, 50.0),
                        (10.0, 10.0),
                    ],
                    true,
                ),
            ],
        }
    }

    fn rgb(p: &Pixmap, x_mm: f64, y_mm: f64, sheet_h: f64, s: f64) -> (u8, u8, u8) {
        let x = ((x_mm + BORDER_MM) * s) as u32;
        let y = ((sheet_h - y_mm + BORDER_MM) * s) as u32;
        let c = p.pixel(x, y).expect("pixel inside").demultiply();
        (c.red(), c.green(), c.blue())
    }

    #[test]
    fn size_colours_background() {
        let s = 10.0;
        let bytes = render(&sheet(), 0, s).expect("renders");
        let p = Pixmap::decode_png(&bytes).expect("decodes");
        assert_eq!((p.width(), p.height()), (1040, 640));

        // Background, inside the sheet and in the border.
        assert_eq!(rgb(&p, 50.0, 20.0, 60.0, s), (255, 255, 255));
        assert_eq!(p.pixel(0, 0).map(|c| c.demultiply().red()), Some(255));
        assert_eq!(p.pixel(5, 5).map(|c| c.demultiply().blue()), Some(255));

        // On a cut line: dark.
        let (r, g, b) = rgb(&p, 50.0, 10.0, 60.0, s);
        assert!(r < 64 && g < 64 && b < 64, "cut pixel {r} {g} {b}");
        let (r, g, b) = rgb(&p, 90.0, 30.0, 60.0, s);
        assert!(r < 64 && g < 64 && b < 64, "cut pixel {r} {g} {b}");

        // On a mountain fold, 1 mm into the first 3 mm dash: reddish.
        let (r, g, b) = rgb(&p, 21.0, 30.0, 60.0, s);
        assert!(r > 150 && g < 80 && b < 80, "mountain pixel {r} {g} {b}");
        // In the first 1 mm gap (3..4 mm, away from the round caps): background.
        assert_eq!(rgb(&p, 23.5, 30.0, 60.0, s), (255, 255, 255));

        // On a valley fold: bluish.
        let (r, g, b) = rgb(&p, 21.0, 40.0, 60.0, s);
        assert!(b > 150 && r < 80, "valley pixel {r} {g} {b}");

        // On a mark: green.
        let (r, g, b) = rgb(&p, 10.0, 5.0, 60.0, s);
        assert!(g > 100 && r < 60 && b < 60, "mark pixel {r} {g} {b}");
    }

    #[test]
    fn default_scale_size() {
        let bytes = render(&sheet(), 0, DEFAULT_PX_PER_MM).expect("renders");
        let p = Pixmap::decode_png(&bytes).expect("decodes");
        assert_eq!((p.width(), p.height()), (416, 256));
    }

    #[test]
    fn huge_sheet_is_scaled_down() {
        let mut big = sheet();
        big.width = 10_000.0;
        big.height = 10_000.0;
        let bytes = render(&big, 3, DEFAULT_PX_PER_MM).expect("renders");
        let p = Pixmap::decode_png(&bytes).expect("decodes");
        assert!(p.width() <= MAX_SIDE_PX && p.height() <= MAX_SIDE_PX);
        assert!(p.width() >= MAX_SIDE_PX - 1);
        // Long thin roll: long side capped, short side proportional.
        let mut roll = sheet();
        roll.width = 600.0;
        roll.height = 20_000.0;
        let p = Pixmap::decode_png(&render(&roll, 0, 4.0).expect("renders")).expect("decodes");
        assert_eq!(p.height(), MAX_SIDE_PX);
        assert!(p.width() > 150 && p.width() < 200, "width {}", p.width());
    }

    #[test]
    fn bad_sizes_are_errors() {
        let mut zero = sheet();
        zero.width = 0.0;
        zero.height = 0.0;
        match render(&zero, 7, DEFAULT_PX_PER_MM) {
            Err(OutputError::Picture { sheet: 7, .. }) => {}
            other => panic!("expected picture error, got {other:?}"),
        }
        let mut nan = sheet();
        nan.height = f64::NAN;
        assert!(matches!(
            render(&nan, 1, 4.0),
            Err(OutputError::Picture { sheet: 1, .. })
        ));
        assert!(render(&sheet(), 0, 0.0).is_err());
        assert!(render(&sheet(), 0, -1.0).is_err());
        assert!(render(&sheet(), 0, f64::INFINITY).is_err());
        // Absurdly small but valid scale: a 1 × 1 px picture, not a panic.
        let p = Pixmap::decode_png(&render(&sheet(), 0, 1e-320).expect("renders")).expect("png");
        assert_eq!((p.width(), p.height()), (1, 1));
        let msg = render(&zero, 2, 4.0).map(|_| ()).unwrap_err().to_string();
        assert_eq!(msg, "sheet 2: picture of 0×0 px cannot be drawn");
    }

    #[test]
    fn degenerate_strokes_are_skipped() {
        let mut s = sheet();
        s.strokes.push(stroke(StrokeRole::Cut, &[], false));
        s.strokes.push(stroke(StrokeRole::Cut, &[(1.0, 1.0)], true));
        s.strokes.push(stroke(
            StrokeRole::Label,
            &[(1.0, f64::NAN), (2.0, 2.0)],
            false,
        ));
        s.strokes.push(stroke(
            StrokeRole::Label,
            &[(1e300, 1.0), (2.0, 2.0)],
            false,
        ));
        // A good label: x = 1 mm, y 57 → 40 mm; at 10 px/mm the column x = 30 px, y 50..220 px.
        s.strokes.push(stroke(
            StrokeRole::Label,
            &[(1.0, 57.0), (1.0, 40.0)],
            false,
        ));
        let p = Pixmap::decode_png(&render(&s, 0, 10.0).expect("renders")).expect("png");
        // The bad label strokes do not take the good ones with them.
        let c = p.pixel(30, 100).map(|c| c.demultiply());
        assert!(c.is_some_and(|c| c.red() < 100 && c.green() > 50), "{c:?}");
        // Tiny scale: lines widened to 1 px, still draws.
        assert!(render(&s, 0, 0.05).is_ok());
    }

    /// The `pHYs` chunk of a PNG: (x px/m, y px/m, unit), after checking its CRC.
    fn phys(png: &[u8]) -> Option<(u32, u32, u8)> {
        let mut at = 8;
        while at + 12 <= png.len() {
            let len = u32::from_be_bytes(png[at..at + 4].try_into().ok()?) as usize;
            let kind = &png[at + 4..at + 8];
            let data = png.get(at + 8..at + 8 + len)?;
            let crc = u32::from_be_bytes(png.get(at + 8 + len..at + 12 + len)?.try_into().ok()?);
            assert_eq!(
                crc,
                crc32fast::hash(&png[at + 4..at + 8 + len]),
                "CRC of {kind:?}"
            );
            if kind == b"pHYs" {
                let x = u32::from_be_bytes(data[0..4].try_into().ok()?);
                let y = u32::from_be_bytes(data[4..8].try_into().ok()?);
                return Some((x, y, data[8]));
            }
            at += 12 + len;
        }
        None
    }

    #[test]
    fn phys_says_the_resolution() {
        let bytes = render(&sheet(), 0, 300.0 / 25.4).expect("renders");
        assert_eq!(phys(&bytes), Some((11811, 11811, 1)));
        let p = Pixmap::decode_png(&bytes).expect("decodes with the extra chunk");
        assert_eq!(p.width(), (104.0 * 300.0 / 25.4_f64).ceil() as u32);
        assert_eq!(
            phys(&render(&sheet(), 0, 4.0).expect("renders")),
            Some((4000, 4000, 1))
        );
        // Drawn coarser to fit: the real scale, 6000 px over 10004 mm.
        let mut big = sheet();
        big.width = 10_000.0;
        let bytes = render(&big, 0, 4.0).expect("renders");
        let expect = (6000.0 / 10_004.0 * 1000.0_f64).round() as u32;
        assert_eq!(phys(&bytes), Some((expect, expect, 1)));
        assert_eq!(px_per_metre(f64::NAN), 1);
        assert_eq!(with_phys(b"not a png".to_vec(), 1), b"not a png");
    }

    #[test]
    fn deterministic() {
        let a = render(&sheet(), 0, 4.0).expect("renders");
        let b = render(&sheet(), 0, 4.0).expect("renders");
        assert_eq!(a, b);
    }
}
