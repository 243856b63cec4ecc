//! Textures of an OBJ model (issue 25 item 3, textured papercraft): the `mtllib` material
//! libraries, each material's diffuse map (`map_Kd`), the `usemtl` in force at each face and
//! the face corners' texture coordinates (`vt`), so that the output stage can print each
//! face's part of the image onto its flat face.
//!
//! Choices (the OBJ/MTL specification leaves these to the reader):
//! - A face is keyed by the line of its `f` in the file ([`crate::geom::mesh::Face::line`],
//!   which validation keeps on the faces it repairs or splits) and each of its corners by the
//!   welded vertex (vertices are welded by bit-identical coordinates, so the file's vertex is
//!   found again by its coordinates). A face whose corners have no `vt`, or whose material has
//!   no readable map, prints plain.
//! - `map_Kd`'s options (`-s`, `-o`, `-clamp`, `-bm`, …) are skipped; the rest of the line is
//!   the file, relative to the MTL file's folder. `mtllib` files are relative to the OBJ's.
//! - A missing or unreadable MTL file or image is a warning naming the file and what is wrong,
//!   never an error: the pieces print plain. PNG and JPEG are read (the `image` crate); an
//!   image over [`MAX_SIDE_PX`] on a side or [`MAX_PIXELS`] in all is refused the same way.
//!   Images are kept at most [`KEEP_SIDE_PX`] on their longer side (resampled by averaging),
//!   more than a print at 300 dpi of a face of 300 mm needs.
//! - Texture coordinates keep OBJ's convention: u to the right, v up, (0, 0) the image's
//!   lower-left corner; a face's coordinates may lie in any unit square (repeat), the output
//!   stage moves them into [0, 1].

use crate::geom::mesh::{Face, Mesh};
use glam::DVec2;
use std::collections::{BTreeMap, HashMap};
use std::path::{Path, PathBuf};

/// Largest side of a texture image read, px.
pub const MAX_SIDE_PX: u32 = 16384;

/// Most pixels of a texture image read.
pub const MAX_PIXELS: u64 = 64 << 20;

/// Longest side a texture is kept at, px.
pub const KEEP_SIDE_PX: u32 = 4096;

/// Most `vt` lines and materials read (beyond: plain faces, with a warning).
const MAX_ITEMS: usize = 50_000_000;

/// A decoded texture image: RGBA, 8 bits, straight alpha, rows from the top.
#[derive(Clone, PartialEq)]
pub struct Image {
    /// The file it came from.
    pub file: PathBuf,
    pub width: u32,
    pub height: u32,
    pub rgba: Vec<u8>,
}

impl std::fmt::Debug for Image {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "Image({}, {}x{})",
            self.file.display(),
            self.width,
            self.height
        )
    }
}

/// One face's texture: its image and the texture coordinates of its corners, by vertex.
#[derive(Debug, Clone, PartialEq)]
struct FaceUv {
    image: usize,
    corners: Vec<(usize, DVec2)>,
}

/// The textures of a model.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Texture {
    pub images: Vec<Image>,
    /// By the line of the face's `f`.
    faces: BTreeMap<usize, FaceUv>,
}

impl Texture {
    /// The image and the texture coordinates of each corner of `face` (in its order), when the
    /// face has them.
    pub fn face(&self, face: &Face) -> Option<(usize, Vec<DVec2>)> {
        let uv = self.faces.get(&face.line?)?;
        let corners = face
            .verts
            .iter()
            .map(|v| uv.corners.iter().find(|(w, _)| w == v).map(|(_, t)| *t))
            .collect::<Option<Vec<_>>>()?;
        Some((uv.image, corners))
    }

    /// Number of faces with texture coordinates.
    pub fn faces(&self) -> usize {
        self.faces.len()
    }
}

/// An OBJ index (1-based, or negative from the end) into a list of `len`.
fn index(t: &str, len: usize) -> Option<usize> {
    let i: i64 = t.parse().ok()?;
    if i > 0 && (i as usize) <= len {
        Some(i as usize - 1)
    } else if i < 0 && i.unsigned_abs() as usize <= len {
        Some(len - i.unsigned_abs() as usize)
    } else {
        None
    }
}

/// The file of a `map_Kd` line's arguments, its options skipped.
fn map_file(args: &str) -> Option<String> {
    let words: Vec<&str> = args.split_whitespace().collect();
    let mut k = 0;
    while k < words.len() && words[k].starts_with('-') {
        k += 1;
        // An option's values: numbers, on/off.
        while k < words.len()
            && (words[k].parse::<f64>().is_ok() || matches!(words[k], "on" | "off"))
            && k + 1 < words.len()
        {
            k += 1;
        }
    }
    let rest = words.get(k..)?.join(" ");
    (!rest.is_empty()).then_some(rest)
}

/// Reads the textures of OBJ `text` (read from `path`) for `mesh`, the welded mesh read from
/// it (in file units). Returns `None` when the file names no material with a map or has no
/// `vt`, and the warnings.
pub fn read(text: &str, path: &Path, mesh: &Mesh) -> (Option<Texture>, Vec<String>) {
    let mut warnings = Vec::new();
    if !text.contains("mtllib") || !text.contains("\nvt") {
        return (None, warnings);
    }
    let dir = path.parent().unwrap_or(Path::new(""));
    // Welded vertex of each coordinate triple.
    let by_coords: HashMap<[u64; 3], usize> = mesh
        .vertices
        .iter()
        .enumerate()
        .map(|(i, v)| ([v.x.to_bits(), v.y.to_bits(), v.z.to_bits()], i))
        .collect();
    let mut positions: Vec<Option<usize>> = Vec::new();
    let mut uvs: Vec<DVec2> = Vec::new();
    // Material name → its map file (resolved), from every library.
    let mut maps: BTreeMap<String, PathBuf> = BTreeMap::new();
    let mut images: Vec<Image> = Vec::new();
    // Map file → image index, or None when it could not be read.
    let mut loaded: BTreeMap<PathBuf, Option<usize>> = BTreeMap::new();
    let mut current: Option<usize> = None;
    let mut faces = BTreeMap::new();
    for (k, raw) in text.lines().enumerate() {
        let line = raw.trim();
        let (word, rest) = line.split_once(char::is_whitespace).unwrap_or((line, ""));
        match word {
            "v" => {
                let c: Vec<f64> = rest
                    .split_whitespace()
                    .take(3)
                    .filter_map(|t| t.parse().ok())
                    .collect();
                let v = (c.len() == 3)
                    .then(|| by_coords.get(&[c[0].to_bits(), c[1].to_bits(), c[2].to_bits()]))
                    .flatten()
                    .copied();
                positions.push(v);
            }
            "vt" if uvs.len() < MAX_ITEMS => {
                let c: Vec<f64> = rest
                    .split_whitespace()
                    .take(2)
                    .filter_map(|t| t.parse().ok())
                    .collect();
                let u = c.first().copied().unwrap_or(f64::NAN);
                let v = c.get(1).copied().unwrap_or(0.0);
                uvs.push(DVec2::new(u, v));
            }
            "mtllib" => {
                for lib in rest.split_whitespace() {
                    read_mtl(&dir.join(lib), path, k + 1, &mut maps, &mut warnings);
                }
            }
            "usemtl" => {
                current = maps.get(rest.trim()).and_then(|file| {
                    *loaded.entry(file.clone()).or_insert_with(|| {
                        match load_image(file) {
                            Ok(img) => {
                                images.push(img);
                                Some(images.len() - 1)
                            }
                            Err(e) => {
                                warnings.push(format!(
                                    "{}: texture of material `{}` (line {}): {e}; its faces print plain",
                                    file.display(),
                                    rest.trim(),
                                    k + 1
                                ));
                                None
                            }
                        }
                    })
                });
            }
            "f" => {
                let Some(image) = current else { continue };
                let mut corners = Vec::new();
                for t in rest.split_whitespace() {
                    let mut parts = t.split('/');
                    let v = parts.next().and_then(|p| index(p, positions.len()));
                    let vt = parts.next().and_then(|p| index(p, uvs.len()));
                    match (v.and_then(|v| positions[v]), vt.map(|t| uvs[t])) {
                        (Some(v), Some(uv)) if uv.is_finite() => corners.push((v, uv)),
                        _ => {
                            corners.clear();
                            break;
                        }
                    }
                }
                if corners.len() >= 3 {
                    faces.insert(k + 1, FaceUv { image, corners });
                }
            }
            _ => {}
        }
    }
    if faces.is_empty() {
        return (None, warnings);
    }
    (Some(Texture { images, faces }), warnings)
}

/// The materials of an MTL file with a `map_Kd`, into `maps`; a file that cannot be read is a
/// warning naming it and the OBJ line that asked for it.
fn read_mtl(
    file: &Path,
    obj: &Path,
    line: usize,
    maps: &mut BTreeMap<String, PathBuf>,
    warnings: &mut Vec<String>,
) {
    let text = match crate::geom::input::read_bytes(file, crate::geom::input::DATA_LIMIT) {
        Ok(b) => String::from_utf8_lossy(&b).into_owned(),
        Err(e) => {
            warnings.push(format!(
                "{}: material library named at {}:{line} cannot be read ({e}); the pieces print plain",
                file.display(),
                obj.display()
            ));
            return;
        }
    };
    let dir = file.parent().unwrap_or(Path::new(""));
    let mut name: Option<String> = None;
    for raw in text.lines() {
        let line = raw.trim();
        let (word, rest) = line.split_once(char::is_whitespace).unwrap_or((line, ""));
        match word {
            "newmtl" => name = Some(rest.trim().to_string()),
            "map_Kd" => {
                if let (Some(n), Some(f)) = (&name, map_file(rest)) {
                    if maps.len() < MAX_ITEMS {
                        maps.insert(n.clone(), dir.join(f.replace('\\', "/")));
                    }
                }
            }
            _ => {}
        }
    }
}

/// Reads and decodes an image, within the limits, kept at most [`KEEP_SIDE_PX`].
fn load_image(file: &Path) -> Result<Image, String> {
    let bytes = crate::geom::input::read_bytes(file, crate::geom::input::DATA_LIMIT)
        .map_err(|e| format!("cannot be read ({e})"))?;
    let mut reader = image::ImageReader::new(std::io::Cursor::new(bytes))
        .with_guessed_format()
        .map_err(|e| format!("cannot be read ({e})"))?;
    let mut limits = image::Limits::default();
    limits.max_image_width = Some(MAX_SIDE_PX);
    limits.max_image_height = Some(MAX_SIDE_PX);
    limits.max_alloc = Some(MAX_PIXELS * 4);
    reader.limits(limits);
    let decoded = reader
        .decode()
        .map_err(|e| format!("is not an image flatcut can read (PNG or JPEG): {e}"))?;
    let rgba = decoded.to_rgba8();
    let (w, h) = rgba.dimensions();
    if w == 0 || h == 0 {
        return Err("is an empty image".into());
    }
    let longer = w.max(h);
    let rgba = if longer > KEEP_SIDE_PX {
        let k = f64::from(KEEP_SIDE_PX) / f64::from(longer);
        let (nw, nh) = (
            ((f64::from(w) * k).round() as u32).max(1),
            ((f64::from(h) * k).round() as u32).max(1),
        );
        image::imageops::resize(&rgba, nw, nh, image::imageops::FilterType::Triangle)
    } else {
        rgba
    };
    let (width, height) = rgba.dimensions();
    Ok(Image {
        file: file.to_path_buf(),
        width,
        height,
        rgba: rgba.into_raw(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn indices_and_map_options() {
        assert_eq!(index("1", 3), Some(0));
        assert_eq!(index("-1", 3), Some(2));
        assert_eq!(index("4", 3), None);
        assert_eq!(index("0", 3), None);
        assert_eq!(index("x", 3), None);
        assert_eq!(map_file("tex.png").as_deref(), Some("tex.png"));
        assert_eq!(
            map_file("-s 1 1 1 -clamp on my tex.png").as_deref(),
            Some("my tex.png")
        );
        assert_eq!(map_file("-bm 0.5 a.jpg").as_deref(), Some("a.jpg"));
        assert_eq!(map_file(""), None);
    }

    #[test]
    fn a_missing_library_or_image_is_a_warning() {
        let dir = std::env::temp_dir().join(format!("flatcut-tex-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let obj = dir.join("m.obj");
        let text = "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nusemtl a\nf 1/1 2/2 3/3\n";
        let mesh = Mesh {
            vertices: vec![glam::DVec3::ZERO, glam::DVec3::X, glam::DVec3::Y],
            faces: vec![Face {
                verts: vec![0, 1, 2],
                line: Some(9),
            }],
        };
        let (t, w) = read(text, &obj, &mesh);
        assert!(t.is_none());
        assert!(w[0].contains("m.mtl") && w[0].contains(":1"), "{w:?}");
        std::fs::write(dir.join("m.mtl"), "newmtl a\nmap_Kd gone.png\n").unwrap();
        let (t, w) = read(text, &obj, &mesh);
        assert!(t.is_none());
        assert!(w[0].contains("gone.png") && w[0].contains("`a`"), "{w:?}");
        std::fs::write(dir.join("gone.png"), b"not a png").unwrap();
        let (_, w) = read(text, &obj, &mesh);
        assert!(w[0].contains("not an image"), "{w:?}");
        // A real 2 x 1 image.
        let img = image::RgbaImage::from_raw(2, 1, vec![255, 0, 0, 255, 0, 0, 255, 255]).unwrap();
        img.save(dir.join("gone.png")).unwrap();
        let (t, w) = read(text, &obj, &mesh);
        assert!(w.is_empty(), "{w:?}");
        let t = t.unwrap();
        assert_eq!((t.images[0].width, t.images[0].height), (2, 1));
        let (i, uv) = t.face(&mesh.faces[0]).unwrap();
        assert_eq!(i, 0);
        assert_eq!(uv, vec![DVec2::ZERO, DVec2::X, DVec2::Y]);
        let _ = std::fs::remove_dir_all(&dir);
    }
}
