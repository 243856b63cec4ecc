//! Textured papercraft (issue 25 item 3): each flat face of a textured model printed with its
//! triangle of the texture image, in the PDFs (1:1 and tiled) and the PNGs.
//!
//! [`paint`] takes the layout and the flats and gives, per sheet, every textured face in sheet
//! millimetres with its texture coordinates ([`TexturedFace`]); [`triangles`] cuts them into
//! the patches that `pdf` and [`png_faces`] draw under the strokes.
//!
//! Choices:
//! - A face is drawn whole, as the affine image of its texture coordinates, when one affine
//!   map carries all its corners (every triangle, and the quads of most exporters); else as a
//!   fan of triangles from its first corner, each the affine image of its own, which keeps
//!   every corner where the model put it. Drawn whole, a face shows no seam inside it.
//! - Each triangle is clipped to itself grown outwards: by [`BLEED_MM`] past a cut edge of the
//!   piece, so that a cut a little off the line shows no white edge, and by [`JOIN_MM`] past
//!   a fold, a glue tab's fold or a fan diagonal, so that neighbouring triangles meet without
//!   a hairline while no face's colour reaches into its neighbour or onto a tab. A grown
//!   corner sharper than the miter limit is bevelled ([`MITER`]).
//! - A triangle whose texture coordinates enclose no area is filled with the image's colour
//!   at their centre. Coordinates outside [0, 1] are moved by whole units into it (repeat).
//! - Transparent texture pixels are printed as if over white paper (alpha blended onto white).
//! - Glue tabs, seam allowances and the rest of the sheet stay unprinted.

use crate::flatten::Flat;
use crate::nest::Layout;
use crate::surface::texture::{Image, Texture};
use glam::DVec2;
use std::collections::HashSet;
use std::sync::Arc;

/// How far a face's texture reaches past a cut edge, mm.
pub const BLEED_MM: f64 = 1.0;

/// How far a face's texture reaches past a fold, a tab's fold or a fan diagonal, mm.
pub const JOIN_MM: f64 = 0.05;

/// A grown corner reaches at most this many times its edges' growth from the corner.
const MITER: f64 = 3.0;

/// One face to print: its corners on the sheet (mm), their texture coordinates, and how far
/// to grow each edge (`grow[i]`: the edge from corner `i` to `i + 1`).
#[derive(Debug, Clone, PartialEq)]
pub struct TexturedFace {
    /// Index into [`Paint::images`].
    pub image: usize,
    pub pts: Vec<DVec2>,
    pub uv: Vec<DVec2>,
    pub grow: Vec<f64>,
}

/// Everything printed with a texture: the images and, per sheet, the faces.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Paint {
    images: Vec<(Arc<Texture>, usize)>,
    pub sheets: Vec<Vec<TexturedFace>>,
}

impl Paint {
    /// The images the faces refer to.
    pub fn images(&self) -> impl Iterator<Item = &Image> {
        self.images.iter().map(|(t, i)| &t.images[*i])
    }

    /// The faces of sheet `k` (0-based).
    pub fn sheet(&self, k: usize) -> &[TexturedFace] {
        self.sheets.get(k).map_or(&[], |v| v.as_slice())
    }

    pub fn is_empty(&self) -> bool {
        self.sheets.iter().all(|s| s.is_empty())
    }
}

/// The textured faces of a layout, per sheet; `None` when no piece has a texture.
pub fn paint(flats: &[Flat], layout: &Layout) -> Option<Paint> {
    let mut out = Paint {
        images: Vec::new(),
        sheets: vec![Vec::new(); layout.sheets.len()],
    };
    // Per flat with a texture, where its images start in `out.images`.
    let mut first_image = Vec::new();
    for f in flats {
        first_image.push(out.images.len());
        if let Some(t) = &f.surface.texture {
            out.images
                .extend((0..t.images.len()).map(|i| (Arc::clone(t), i)));
        }
    }
    for (piece, at) in layout.pieces.iter().zip(&layout.placements) {
        let Some((k, flat)) = flats
            .iter()
            .enumerate()
            .find(|(_, f)| f.surface.name == piece.surface)
        else {
            continue;
        };
        let Some(tex) = &flat.surface.texture else {
            continue;
        };
        let Some(sheet) = out.sheets.get_mut(at.sheet) else {
            continue;
        };
        let border: HashSet<usize> = piece.border_edges.iter().flatten().copied().collect();
        let mut tabs = HashSet::new();
        for s in piece.seams.iter().filter(|s| s.tab) {
            if let Some(ring) = piece.border_edges.get(s.ring).filter(|r| !r.is_empty()) {
                tabs.extend((0..s.count).map(|j| ring[(s.first + j) % ring.len()]));
            }
        }
        for &f in &piece.faces {
            let (Some(face), Some(flat_pts), Some(edges)) = (
                flat.surface.mesh.faces.get(f),
                flat.face_2d.get(f),
                flat.topology.face_edges.get(f),
            ) else {
                continue;
            };
            let Some((image, uv)) = tex.face(face) else {
                continue;
            };
            if uv.len() != flat_pts.len() || edges.len() != flat_pts.len() {
                continue;
            }
            let grow = edges
                .iter()
                .map(|e| {
                    if border.contains(e) && !tabs.contains(e) {
                        BLEED_MM
                    } else {
                        JOIN_MM
                    }
                })
                .collect();
            // Whole units off, so the coordinates lie in [0, 1] where the face allows.
            let lo = uv
                .iter()
                .fold(DVec2::splat(f64::INFINITY), |a, b| a.min(*b));
            let uv = uv.iter().map(|t| *t - lo.floor()).collect();
            sheet.push(TexturedFace {
                image: first_image[k] + image,
                pts: flat_pts.iter().map(|p| at.apply(*p)).collect(),
                uv,
                grow,
            });
        }
    }
    (!out.is_empty()).then_some(out)
}

/// One patch to draw (a face, or a triangle of one): the clip polygon (sheet mm) and the
/// affine map from texture coordinates to the sheet (`[a, b, c, d, e, f]`: x = a·u + c·v + e,
/// y = b·u + d·v + f), or the colour to fill it with when its texture coordinates enclose no
/// area.
#[derive(Debug, Clone, PartialEq)]
pub struct Patch {
    pub image: usize,
    pub clip: Vec<DVec2>,
    pub fill: Fill,
}

#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Fill {
    Map([f64; 6]),
    Colour([u8; 3]),
}

/// How a face's corners `idx` map from texture coordinates to the sheet: the affine map of its
/// first three, or the image's colour at their centre when they enclose no area.
fn fill_of(face: &TexturedFace, idx: [usize; 3], images: &[&Image]) -> Fill {
    let p = idx.map(|i| face.pts[i]);
    let t = idx.map(|i| face.uv[i]);
    let (du, dv) = (t[1] - t[0], t[2] - t[0]);
    let det = du.perp_dot(dv);
    if det.abs() > 1e-12 && det.is_finite() {
        // M·du = p1 − p0, M·dv = p2 − p0: M = [e1 e2] · inverse([du dv]).
        let (e1, e2) = (p[1] - p[0], p[2] - p[0]);
        let inv = [dv.y / det, -dv.x / det, -du.y / det, du.x / det];
        let m00 = e1.x * inv[0] + e2.x * inv[2];
        let m01 = e1.x * inv[1] + e2.x * inv[3];
        let m10 = e1.y * inv[0] + e2.y * inv[2];
        let m11 = e1.y * inv[1] + e2.y * inv[3];
        let e = p[0].x - (m00 * t[0].x + m01 * t[0].y);
        let f = p[0].y - (m10 * t[0].x + m11 * t[0].y);
        let m = [m00, m10, m01, m11, e, f];
        if m.iter().all(|v| v.is_finite()) {
            return Fill::Map(m);
        }
    }
    let c = (t[0] + t[1] + t[2]) / 3.0;
    Fill::Colour(
        images
            .get(face.image)
            .map_or([255; 3], |img| sample(img, c)),
    )
}

/// How far (mm) a map puts a texture coordinate from where the face has its corner.
fn miss(m: &[f64; 6], uv: DVec2, p: DVec2) -> f64 {
    let q = DVec2::new(
        m[0] * uv.x + m[2] * uv.y + m[4],
        m[1] * uv.x + m[3] * uv.y + m[5],
    );
    q.distance(p)
}

/// The patches of a face, ready to draw: the whole face when one affine map carries all its
/// corners (within 0.001 mm), else a fan of triangles from its first corner.
pub fn triangles(face: &TexturedFace, images: &[&Image]) -> Vec<Patch> {
    let n = face.pts.len();
    let mut out = Vec::new();
    if n < 3 || face.uv.len() != n || face.grow.len() != n {
        return out;
    }
    // The face's winding on the sheet (a mirrored placement turns it).
    let area: f64 = (0..n)
        .map(|i| face.pts[i].perp_dot(face.pts[(i + 1) % n]))
        .sum();
    let sign = if area < 0.0 { -1.0 } else { 1.0 };
    let mut push = |clip: Vec<DVec2>, fill: Fill| {
        if clip.iter().all(|q| q.is_finite()) {
            out.push(Patch {
                image: face.image,
                clip,
                fill,
            });
        }
    };
    let whole = fill_of(face, [0, 1, 2], images);
    let affine = match whole {
        Fill::Map(m) => (3..n).all(|k| miss(&m, face.uv[k], face.pts[k]) <= 1e-3),
        Fill::Colour(_) => n == 3,
    };
    if affine {
        push(grown(&face.pts, &face.grow, sign), whole);
        return out;
    }
    for k in 1..n - 1 {
        let idx = [0, k, k + 1];
        let p = idx.map(|i| face.pts[i]);
        let g = [
            if k == 1 { face.grow[0] } else { JOIN_MM },
            face.grow[k],
            if k + 1 == n - 1 {
                face.grow[n - 1]
            } else {
                JOIN_MM
            },
        ];
        push(grown(&p, &g, sign), fill_of(face, idx, images));
    }
    out
}

/// The polygon `p` with edge `i` (from `p[i]` to `p[i + 1]`) moved outwards by `g[i]`
/// (`sign`: 1 for counter-clockwise); corners past the miter limit bevelled.
fn grown(p: &[DVec2], g: &[f64], sign: f64) -> Vec<DVec2> {
    let n = p.len();
    let normal = |i: usize| {
        let d = (p[(i + 1) % n] - p[i]).normalize_or_zero();
        DVec2::new(d.y, -d.x) * sign
    };
    let mut out = Vec::new();
    for (i, &corner) in p.iter().enumerate() {
        // Corner i between edge i-1 (into it) and edge i (out of it).
        let (a, b) = ((i + n - 1) % n, i);
        let (na, nb) = (normal(a), normal(b));
        let (ga, gb) = (g[a], g[b]);
        // The point q with (q − p)·na = ga and (q − p)·nb = gb.
        let det = na.perp_dot(nb);
        let limit = MITER * ga.max(gb);
        let q = if det.abs() > 1e-9 {
            let d = DVec2::new((ga * nb.y - gb * na.y) / det, (na.x * gb - nb.x * ga) / det);
            Some(corner + d).filter(|_| d.length() <= limit)
        } else {
            None
        };
        match q {
            Some(q) => out.push(q),
            None => {
                out.push(corner + na * ga);
                out.push(corner + nb * gb);
            }
        }
    }
    out
}

/// The colour of `img` at texture coordinates `uv` (nearest pixel, over white).
pub fn sample(img: &Image, uv: DVec2) -> [u8; 3] {
    let (w, h) = (img.width as usize, img.height as usize);
    let x = ((uv.x.fract() + 1.0).fract() * w as f64).floor() as usize;
    let y = ((1.0 - (uv.y.fract() + 1.0).fract()) * h as f64).floor() as usize;
    let (x, y) = (x.min(w.saturating_sub(1)), y.min(h.saturating_sub(1)));
    let at = (y * w + x) * 4;
    match img.rgba.get(at..at + 4) {
        Some(px) => over_white(px),
        None => [255; 3],
    }
}

/// An RGBA pixel blended onto white.
pub fn over_white(px: &[u8]) -> [u8; 3] {
    let a = u32::from(px[3]);
    [0, 1, 2].map(|k| ((u32::from(px[k]) * a + 255 * (255 - a) + 127) / 255) as u8)
}

/// The RGB bytes of an image over white, rows from the top (for the PDF).
pub fn rgb_over_white(img: &Image) -> Vec<u8> {
    img.rgba.chunks_exact(4).flat_map(over_white).collect()
}

/// Draws the textured faces of a sheet onto a picture; `to_px` maps sheet mm to pixels by
/// `x' = s·x + ox, y' = −s·y + oy` (given as `(s, ox, oy)`).
pub(crate) fn png_faces(
    pixmap: &mut tiny_skia::Pixmap,
    faces: &[TexturedFace],
    images: &[&Image],
    pictures: &[Option<tiny_skia::Pixmap>],
    (s, ox, oy): (f64, f64, f64),
) {
    use tiny_skia::{
        FillRule, FilterQuality, Paint as Brush, PathBuilder, Pattern, SpreadMode, Transform,
    };
    for face in faces {
        for t in triangles(face, images) {
            let mut pb = PathBuilder::new();
            for (k, q) in t.clip.iter().enumerate() {
                let (x, y) = ((s * q.x + ox) as f32, (-s * q.y + oy) as f32);
                if k == 0 {
                    pb.move_to(x, y);
                } else {
                    pb.line_to(x, y);
                }
            }
            pb.close();
            let Some(path) = pb.finish() else { continue };
            let mut brush = Brush {
                anti_alias: true,
                ..Brush::default()
            };
            match t.fill {
                Fill::Map([a, b, c, d, e, f]) => {
                    let (Some(Some(pic)), Some(img)) = (pictures.get(t.image), images.get(t.image))
                    else {
                        continue;
                    };
                    // Image pixel (px, py) → uv = (px / W, 1 − py / H) → sheet → picture.
                    let (w, h) = (f64::from(img.width), f64::from(img.height));
                    let (su, sv) = (1.0 / w, -1.0 / h);
                    // Sheet = M·uv + (e, f); picture = (s·x + ox, −s·y + oy).
                    let m = [
                        s * a * su,
                        -s * b * su,
                        s * c * sv,
                        -s * d * sv,
                        s * (c + e) + ox,
                        -s * (d + f) + oy,
                    ];
                    let tr = Transform::from_row(
                        m[0] as f32,
                        m[1] as f32,
                        m[2] as f32,
                        m[3] as f32,
                        m[4] as f32,
                        m[5] as f32,
                    );
                    brush.shader = Pattern::new(
                        pic.as_ref(),
                        SpreadMode::Pad,
                        FilterQuality::Bilinear,
                        1.0,
                        tr,
                    );
                }
                Fill::Colour([r, g, b]) => brush.set_color_rgba8(r, g, b, 255),
            }
            pixmap.fill_path(
                &path,
                &brush,
                FillRule::Winding,
                Transform::identity(),
                None,
            );
        }
    }
}

/// The images as opaque pictures (over white) for [`png_faces`]; `None` for one tiny-skia
/// cannot hold.
pub(crate) fn pictures(images: &[&Image]) -> Vec<Option<tiny_skia::Pixmap>> {
    images
        .iter()
        .map(|img| {
            let data: Vec<u8> = img
                .rgba
                .chunks_exact(4)
                .flat_map(|px| {
                    let [r, g, b] = over_white(px);
                    [r, g, b, 255]
                })
                .collect();
            let size = tiny_skia::IntSize::from_wh(img.width, img.height)?;
            tiny_skia::Pixmap::from_vec(data, size)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn img() -> Image {
        // 2 x 2: top row red, green; bottom row blue, half-transparent black.
        Image {
            file: "t.png".into(),
            width: 2,
            height: 2,
            rgba: vec![255, 0, 0, 255, 0, 255, 0, 255, 0, 0, 255, 255, 0, 0, 0, 128],
        }
    }

    #[test]
    fn samples_follow_obj_orientation() {
        let i = img();
        assert_eq!(sample(&i, DVec2::new(0.25, 0.75)), [255, 0, 0]);
        assert_eq!(sample(&i, DVec2::new(0.75, 0.75)), [0, 255, 0]);
        assert_eq!(sample(&i, DVec2::new(0.25, 0.25)), [0, 0, 255]);
        assert_eq!(sample(&i, DVec2::new(0.75, 0.25)), [127, 127, 127]);
        // Repeat.
        assert_eq!(sample(&i, DVec2::new(1.25, -0.25)), [255, 0, 0]);
    }

    #[test]
    fn triangles_map_texture_corners_onto_their_points() {
        let face = TexturedFace {
            image: 0,
            pts: vec![
                DVec2::new(10.0, 10.0),
                DVec2::new(40.0, 10.0),
                DVec2::new(40.0, 30.0),
                DVec2::new(10.0, 30.0),
            ],
            uv: vec![
                DVec2::new(0.0, 0.0),
                DVec2::new(1.0, 0.0),
                DVec2::new(1.0, 1.0),
                DVec2::new(0.0, 1.0),
            ],
            grow: vec![BLEED_MM, JOIN_MM, JOIN_MM, JOIN_MM],
        };
        let i = img();
        let t = triangles(&face, &[&i]);
        assert_eq!(t.len(), 1, "one affine map: the face whole");
        let check = |t: &[Patch], far: DVec2| {
            for tri in t {
                let Fill::Map([a, b, c, d, e, f]) = tri.fill else {
                    panic!("a map")
                };
                let at = |u: f64, v: f64| DVec2::new(a * u + c * v + e, b * u + d * v + f);
                assert!(at(0.0, 0.0).distance(DVec2::new(10.0, 10.0)) < 1e-12);
                assert!(at(1.0, 1.0).distance(far) < 1e-12);
            }
        };
        check(&t, DVec2::new(40.0, 30.0));
        // The bottom edge grows by the bleed, the others by the join.
        let (lo, hi) = t[0]
            .clip
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), p| {
                (l.min(p.y), h.max(p.y))
            });
        assert!((lo - (10.0 - BLEED_MM)).abs() < 1e-9, "{:?}", t[0].clip);
        assert!((hi - (30.0 + JOIN_MM)).abs() < 1e-9, "{:?}", t[0].clip);
        // Mirrored (clockwise) the growth still goes outwards.
        let mut m = face.clone();
        m.pts.iter_mut().for_each(|p| p.x = -p.x);
        let t = triangles(&m, &[&i]);
        let lo = t[0].clip.iter().map(|p| p.y).fold(f64::INFINITY, f64::min);
        assert!((lo - (10.0 - BLEED_MM)).abs() < 1e-9);
        // A corner off the affine map: two triangles, each through its own corners.
        let mut k = face.clone();
        k.pts[2] = DVec2::new(45.0, 32.0);
        let t = triangles(&k, &[&i]);
        assert_eq!(t.len(), 2);
        check(&t[..1], DVec2::new(45.0, 32.0));
        // Degenerate texture coordinates: a plain fill of the colour there.
        let mut d = face;
        d.uv = vec![DVec2::new(0.25, 0.75); 4];
        let t = triangles(&d, &[&i]);
        assert_eq!(t[0].fill, Fill::Colour([255, 0, 0]));
    }

    #[test]
    fn sharp_corners_are_bevelled() {
        let p = [DVec2::ZERO, DVec2::new(100.0, 0.0), DVec2::new(100.0, 1.0)];
        let g = grown(&p, &[1.0, 1.0, 1.0], 1.0);
        // A square grown by 1: its corners move by (1, 1).
        let sq = [DVec2::ZERO, DVec2::X, DVec2::ONE, DVec2::Y];
        let gs = grown(&sq, &[1.0; 4], 1.0);
        assert!(gs[0].distance(DVec2::splat(-1.0)) < 1e-12, "{gs:?}");
        assert!(gs[2].distance(DVec2::splat(2.0)) < 1e-12, "{gs:?}");
        assert!(g.len() > 3);
        assert!(g
            .iter()
            .all(|q| q.distance(DVec2::ZERO) < 100.0 + MITER + 1.0));
        assert!(g.iter().all(|q| q.x > -MITER - 1e-9));
    }
}
