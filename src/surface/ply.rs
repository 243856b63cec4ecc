//! PLY files (Greg Turk's polygon file format, Stanford 1994), ASCII and binary (little and
//! big endian): a header (`ply`, `format …`, `element NAME COUNT` each followed by its
//! `property TYPE NAME` or `property list COUNT_TYPE ITEM_TYPE NAME` lines, `end_header`), then
//! the elements' values in header order.
//!
//! flatcut reads the `vertex` element's `x`, `y`, `z` and the `face` element's
//! `vertex_indices` (or `vertex_index`) list; every other element and property is read past.
//! Types: `char`/`int8`, `uchar`/`uint8`, `short`/`int16`, `ushort`/`uint16`, `int`/`int32`,
//! `uint`/`uint32`, `float`/`float32`, `double`/`float64`.
//!
//! Choices: an ASCII file has one element per line (as every writer does); errors name the
//! line (ASCII, and the header) or the vertex or face, counted from 1 (binary); counts are
//! bounded (100 million) so that a broken header cannot ask for unbounded memory.

use super::obj::RawMesh;
use super::weld::{err, indexed, non_finite};
use super::SurfaceError;
use glam::DVec3;
use std::path::Path;

#[derive(Debug, Clone, Copy, PartialEq)]
enum Ty {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Ty {
    fn parse(s: &str) -> Option<Ty> {
        Some(match s {
            "char" | "int8" => Ty::I8,
            "uchar" | "uint8" => Ty::U8,
            "short" | "int16" => Ty::I16,
            "ushort" | "uint16" => Ty::U16,
            "int" | "int32" => Ty::I32,
            "uint" | "uint32" => Ty::U32,
            "float" | "float32" => Ty::F32,
            "double" | "float64" => Ty::F64,
            _ => return None,
        })
    }
    fn size(self) -> usize {
        match self {
            Ty::I8 | Ty::U8 => 1,
            Ty::I16 | Ty::U16 => 2,
            Ty::I32 | Ty::U32 | Ty::F32 => 4,
            Ty::F64 => 8,
        }
    }
}

#[derive(Debug, Clone)]
enum Prop {
    Scalar(Ty, String),
    List(Ty, Ty, String),
}

#[derive(Debug, Clone)]
struct Element {
    name: String,
    count: usize,
    props: Vec<Prop>,
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Encoding {
    Ascii,
    Little,
    Big,
}

const LIMIT: usize = 100_000_000;

/// Parse a PLY file; `path` is used in messages.
pub fn parse(bytes: &[u8], path: &Path) -> Result<RawMesh, SurfaceError> {
    let (enc, elements, body, body_line) = header(bytes, path)?;
    let mut points = Vec::new();
    let mut faces = Vec::new();
    let mut reader = Body {
        bytes: &bytes[body..],
        at: 0,
        enc,
        line: body_line,
        words: Vec::new(),
        word: 0,
    };
    for el in &elements {
        let xyz: Vec<Option<usize>> = ["x", "y", "z"]
            .iter()
            .map(|n| {
                el.props
                    .iter()
                    .position(|p| matches!(p, Prop::Scalar(_, m) if m == n))
            })
            .collect();
        let list = el.props.iter().position(
            |p| matches!(p, Prop::List(_, _, m) if m == "vertex_indices" || m == "vertex_index"),
        );
        let is_vertex = el.name == "vertex";
        let is_face = el.name == "face";
        if is_vertex && xyz.iter().any(|i| i.is_none()) {
            return Err(err(
                path,
                None,
                "the `vertex` element has no `x`, `y` and `z` properties",
            ));
        }
        if is_face && list.is_none() {
            return Err(err(
                path,
                None,
                "the `face` element has no `vertex_indices` list",
            ));
        }
        for k in 0..el.count {
            reader.start_record(path, &el.name, k)?;
            let mut p = [0.0; 3];
            let mut refs = Vec::new();
            for (i, prop) in el.props.iter().enumerate() {
                match prop {
                    Prop::Scalar(t, _) => {
                        let v = reader.value(*t, path, &el.name, k)?;
                        if is_vertex {
                            if let Some(c) = xyz.iter().position(|&j| j == Some(i)) {
                                if !v.is_finite() {
                                    return Err(non_finite(
                                        path,
                                        reader.text_line(),
                                        k,
                                        &v.to_string(),
                                    ));
                                }
                                p[c] = v;
                            }
                        }
                    }
                    Prop::List(ct, it, _) => {
                        let n = reader.value(*ct, path, &el.name, k)?;
                        if !(n >= 0.0 && n.fract() == 0.0 && n <= 1e6) {
                            return Err(reader.bad(
                                path,
                                &el.name,
                                k,
                                format!("list length {n} is not a count"),
                            ));
                        }
                        for _ in 0..n as usize {
                            let v = reader.value(*it, path, &el.name, k)?;
                            if is_face && Some(i) == list {
                                if v.fract() != 0.0 {
                                    return Err(reader.bad(
                                        path,
                                        &el.name,
                                        k,
                                        format!("vertex index {v} is not a whole number"),
                                    ));
                                }
                                refs.push(v as i64);
                            }
                        }
                    }
                }
            }
            if is_vertex {
                points.push(DVec3::from_array(p));
            }
            if is_face {
                faces.push((refs, reader.text_line(), k));
            }
            reader.end_record(path, &el.name, k)?;
        }
    }
    indexed(path, &points, faces)
}

/// The header: encoding, elements, where the body starts (byte offset) and its first line.
fn header(
    bytes: &[u8],
    path: &Path,
) -> Result<(Encoding, Vec<Element>, usize, usize), SurfaceError> {
    let mut at = 0usize;
    let mut line = 0usize;
    let mut enc = None;
    let mut elements: Vec<Element> = Vec::new();
    loop {
        let end = bytes[at..]
            .iter()
            .position(|&b| b == b'\n')
            .ok_or_else(|| err(path, None, "the PLY header has no `end_header` line"))?;
        let text = std::str::from_utf8(&bytes[at..at + end])
            .map_err(|_| err(path, Some(line + 1), "the PLY header is not text"))?
            .trim_end_matches('\r');
        at += end + 1;
        line += 1;
        let w: Vec<&str> = text.split_whitespace().collect();
        let bad = |m: String| err(path, Some(line), m);
        if line == 1 {
            if w != ["ply"] {
                return Err(bad("not a PLY file: the first line must be `ply`".into()));
            }
            continue;
        }
        match w.first().copied() {
            None | Some("comment") | Some("obj_info") => {}
            Some("format") => {
                enc = Some(match w.get(1).copied() {
                    Some("ascii") => Encoding::Ascii,
                    Some("binary_little_endian") => Encoding::Little,
                    Some("binary_big_endian") => Encoding::Big,
                    other => {
                        return Err(bad(format!("unknown PLY format `{}`", other.unwrap_or(""))))
                    }
                });
            }
            Some("element") => {
                let count = w
                    .get(2)
                    .and_then(|c| c.parse::<usize>().ok())
                    .filter(|&c| c <= LIMIT);
                match (w.get(1), count) {
                    (Some(name), Some(count)) => elements.push(Element {
                        name: name.to_string(),
                        count,
                        props: Vec::new(),
                    }),
                    _ => {
                        return Err(bad(format!(
                            "`{text}`: expected `element NAME COUNT` (count at most {LIMIT})"
                        )))
                    }
                }
            }
            Some("property") => {
                let el = elements
                    .last_mut()
                    .ok_or_else(|| bad("`property` before any `element`".into()))?;
                let prop = match w.as_slice() {
                    [_, "list", c, i, name] => match (Ty::parse(c), Ty::parse(i)) {
                        (Some(c), Some(i)) => Prop::List(c, i, name.to_string()),
                        _ => return Err(bad(format!("`{text}`: unknown type"))),
                    },
                    [_, t, name] => match Ty::parse(t) {
                        Some(t) => Prop::Scalar(t, name.to_string()),
                        None => return Err(bad(format!("`{text}`: unknown type `{t}`"))),
                    },
                    _ => return Err(bad(format!("`{text}`: expected `property TYPE NAME` or `property list COUNT_TYPE ITEM_TYPE NAME`"))),
                };
                el.props.push(prop);
            }
            Some("end_header") => break,
            Some(other) => return Err(bad(format!("unknown PLY header line `{other}`"))),
        }
    }
    let enc = enc.ok_or_else(|| err(path, None, "the PLY header has no `format` line"))?;
    Ok((enc, elements, at, line + 1))
}

/// The body being read: bytes (binary) or lines of words (ASCII, one record per line).
struct Body<'a> {
    bytes: &'a [u8],
    at: usize,
    enc: Encoding,
    /// ASCII: the line of the current record.
    line: usize,
    words: Vec<String>,
    word: usize,
}

impl Body<'_> {
    fn text_line(&self) -> Option<usize> {
        (self.enc == Encoding::Ascii).then_some(self.line)
    }

    fn bad(&self, path: &Path, el: &str, k: usize, m: String) -> SurfaceError {
        match self.text_line() {
            Some(l) => err(path, Some(l), m),
            None => err(path, None, format!("{el} {}: {m}", k + 1)),
        }
    }

    fn start_record(&mut self, path: &Path, el: &str, k: usize) -> Result<(), SurfaceError> {
        if self.enc != Encoding::Ascii {
            return Ok(());
        }
        loop {
            if self.at >= self.bytes.len() {
                return Err(err(
                    path,
                    None,
                    format!("the file ends before {el} {}", k + 1),
                ));
            }
            let end = self.bytes[self.at..]
                .iter()
                .position(|&b| b == b'\n')
                .map_or(self.bytes.len(), |e| self.at + e);
            let text = std::str::from_utf8(&self.bytes[self.at..end])
                .map_err(|_| err(path, Some(self.line), "not text in an ASCII PLY file"))?;
            self.at = end + 1;
            self.words = text.split_whitespace().map(str::to_string).collect();
            self.word = 0;
            if !self.words.is_empty() {
                return Ok(());
            }
            self.line += 1;
        }
    }

    fn end_record(&mut self, path: &Path, el: &str, k: usize) -> Result<(), SurfaceError> {
        if self.enc == Encoding::Ascii {
            if self.word < self.words.len() {
                return Err(self.bad(
                    path,
                    el,
                    k,
                    format!("{el} {} has more values than its properties", k + 1),
                ));
            }
            self.line += 1;
        }
        Ok(())
    }

    fn value(&mut self, t: Ty, path: &Path, el: &str, k: usize) -> Result<f64, SurfaceError> {
        if self.enc == Encoding::Ascii {
            let Some(w) = self.words.get(self.word) else {
                return Err(self.bad(
                    path,
                    el,
                    k,
                    format!("{el} {} has fewer values than its properties", k + 1),
                ));
            };
            self.word += 1;
            return w.parse::<f64>().map_err(|_| {
                self.bad(
                    path,
                    el,
                    k,
                    format!("{el} {}: `{w}` is not a number", k + 1),
                )
            });
        }
        let n = t.size();
        let Some(b) = self.bytes.get(self.at..self.at + n) else {
            return Err(err(
                path,
                None,
                format!("the file ends inside {el} {}", k + 1),
            ));
        };
        self.at += n;
        let mut a = [0u8; 8];
        a[..n].copy_from_slice(b);
        if self.enc == Encoding::Big {
            a[..n].reverse();
        }
        Ok(match t {
            Ty::I8 => a[0] as i8 as f64,
            Ty::U8 => a[0] as f64,
            Ty::I16 => i16::from_le_bytes([a[0], a[1]]) as f64,
            Ty::U16 => u16::from_le_bytes([a[0], a[1]]) as f64,
            Ty::I32 => i32::from_le_bytes([a[0], a[1], a[2], a[3]]) as f64,
            Ty::U32 => u32::from_le_bytes([a[0], a[1], a[2], a[3]]) as f64,
            Ty::F32 => f32::from_le_bytes([a[0], a[1], a[2], a[3]]) as f64,
            Ty::F64 => f64::from_le_bytes(a),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const HEAD: &str = "ply\nformat FORMAT 1.0\ncomment square\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nproperty uchar red\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";

    #[test]
    fn ascii_and_binary_read_the_same_square() {
        let a = HEAD.replace("FORMAT", "ascii") + "0 0 0 1\n1 0 0 1\n1 1 0 1\n0 1 0 1\n4 0 1 2 3\n";
        let a = parse(a.as_bytes(), Path::new("s.ply")).unwrap();
        assert_eq!((a.mesh.vertices.len(), a.mesh.faces.len()), (4, 1));
        assert_eq!(a.mesh.faces[0].line, Some(16));
        for (fmt, big) in [("binary_little_endian", false), ("binary_big_endian", true)] {
            let mut b = HEAD.replace("FORMAT", fmt).into_bytes();
            for p in [[0f32, 0., 0.], [1., 0., 0.], [1., 1., 0.], [0., 1., 0.]] {
                for x in p {
                    b.extend_from_slice(&if big {
                        x.to_be_bytes()
                    } else {
                        x.to_le_bytes()
                    });
                }
                b.push(7);
            }
            b.push(4);
            for i in 0i32..4 {
                b.extend_from_slice(&if big {
                    i.to_be_bytes()
                } else {
                    i.to_le_bytes()
                });
            }
            let m = parse(&b, Path::new("s.ply")).unwrap();
            assert_eq!(m.mesh.vertices, a.mesh.vertices);
            assert_eq!(m.mesh.faces[0].verts, a.mesh.faces[0].verts);
            b.truncate(b.len() - 3);
            let e = parse(&b, Path::new("s.ply")).unwrap_err().to_string();
            assert!(e.contains("ends inside face 1"), "{e}");
        }
        let bad =
            HEAD.replace("FORMAT", "ascii") + "0 0 0 1\n1 0 0 1\n1 x 0 1\n0 1 0 1\n4 0 1 2 3\n";
        let e = parse(bad.as_bytes(), Path::new("s.ply"))
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("s.ply:14:"), "{e}");
    }
}
