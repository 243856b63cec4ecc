//! OFF files (Object File Format, Geomview; the format of the CGAL and Princeton shape
//! benchmark meshes): a header `OFF` (or `COFF`, `NOFF`, `CNOFF`, `STOFF`… with colours,
//! normals or texture coordinates after each vertex), the counts `vertices faces edges`, the
//! vertices `x y z …`, then one face per line: `n i1 … in` (0-based indices) and optional
//! colour values.
//!
//! Choices: `#` starts a comment anywhere on a line; the counts may stand on the header's line;
//! the edge count is ignored; values after a vertex's three coordinates and after a face's
//! indices (colours) are ignored; `4OFF`/`nOFF` (other dimensions) and binary OFF are refused
//! with a message. Errors name the line.

use super::obj::RawMesh;
use super::weld::{coord, err, indexed};
use super::SurfaceError;
use glam::DVec3;
use std::path::Path;

/// Parse an OFF file; `path` is used in messages.
pub fn parse(bytes: &[u8], path: &Path) -> Result<RawMesh, SurfaceError> {
    let text = std::str::from_utf8(bytes)
        .ok()
        .filter(|t| !t.contains('\0'))
        .ok_or_else(|| err(path, None, "not an OFF file: it is not text (binary OFF is not read); export the model as ASCII OFF"))?;
    // Significant lines: (line number, words), comments and blank lines dropped.
    let mut lines = text.lines().enumerate().filter_map(|(k, l)| {
        let l = l.split('#').next().unwrap_or("");
        let words: Vec<&str> = l.split_whitespace().collect();
        (!words.is_empty()).then_some((k + 1, words))
    });
    let (hline, header) = lines
        .next()
        .ok_or_else(|| err(path, None, "not an OFF file: it is empty"))?;
    let kw = header[0];
    let prefix = kw
        .strip_suffix("OFF")
        .filter(|p| p.chars().all(|c| "STCN".contains(c)));
    if prefix.is_none() {
        return Err(err(
            path,
            Some(hline),
            format!("not a 3D OFF file: it begins with `{kw}`, not `OFF` (or COFF, NOFF, STOFF…)"),
        ));
    }
    if header
        .get(1)
        .is_some_and(|w| w.eq_ignore_ascii_case("binary"))
    {
        return Err(err(
            path,
            Some(hline),
            "binary OFF is not read; export the model as ASCII OFF",
        ));
    }
    let (cline, counts) = if header.len() >= 3 {
        (hline, header[1..].to_vec())
    } else {
        lines.next().ok_or_else(|| {
            err(
                path,
                Some(hline),
                "the counts `vertices faces edges` are missing",
            )
        })?
    };
    let count = |i: usize, what: &str| -> Result<usize, SurfaceError> {
        counts
            .get(i)
            .and_then(|w| w.parse::<usize>().ok())
            .ok_or_else(|| {
                err(
                    path,
                    Some(cline),
                    format!("the number of {what} is missing or not a whole number"),
                )
            })
    };
    let nv = count(0, "vertices")?;
    let nf = count(1, "faces")?;
    const LIMIT: usize = 100_000_000;
    if nv > LIMIT || nf > LIMIT {
        return Err(err(
            path,
            Some(cline),
            format!("{nv} vertices and {nf} faces: more than {LIMIT}"),
        ));
    }
    let mut points = Vec::with_capacity(nv.min(1 << 20));
    for v in 0..nv {
        let (line, w) = lines.next().ok_or_else(|| {
            err(
                path,
                None,
                format!("the file ends after {v} of its {nv} vertices"),
            )
        })?;
        if w.len() < 3 {
            return Err(err(
                path,
                Some(line),
                format!(
                    "vertex {} needs three coordinates, found `{}`",
                    v + 1,
                    w.join(" ")
                ),
            ));
        }
        let mut p = [0.0; 3];
        for i in 0..3 {
            p[i] = coord(path, Some(line), v, w[i])?;
        }
        points.push(DVec3::from_array(p));
    }
    let mut faces = Vec::with_capacity(nf.min(1 << 20));
    for f in 0..nf {
        let (line, w) = lines.next().ok_or_else(|| {
            err(
                path,
                None,
                format!("the file ends after {f} of its {nf} faces"),
            )
        })?;
        let n = w[0]
            .parse::<usize>()
            .ok()
            .filter(|&n| n < w.len())
            .ok_or_else(|| {
                err(
                    path,
                    Some(line),
                    format!(
                        "face {} must be `n i1 … in`, found `{}`",
                        f + 1,
                        w.join(" ")
                    ),
                )
            })?;
        let refs = w[1..=n]
            .iter()
            .map(|t| t.parse::<i64>())
            .collect::<Result<Vec<i64>, _>>()
            .map_err(|_| {
                err(
                    path,
                    Some(line),
                    format!(
                        "face {}: vertex indices must be whole numbers, found `{}`",
                        f + 1,
                        w.join(" ")
                    ),
                )
            })?;
        faces.push((refs, Some(line), f));
    }
    indexed(path, &points, faces)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn square_reads_and_errors_name_the_line() {
        let t = "OFF\n# a square\n4 1 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3 255 0 0\n";
        let m = parse(t.as_bytes(), Path::new("s.off")).unwrap();
        assert_eq!((m.mesh.vertices.len(), m.mesh.faces.len()), (4, 1));
        assert_eq!(m.mesh.faces[0].verts, vec![0, 1, 2, 3]);
        assert_eq!(m.mesh.faces[0].line, Some(8));
        let e = parse(
            t.replace("4 0 1 2 3", "4 0 1 2 9").as_bytes(),
            Path::new("s.off"),
        )
        .unwrap_err()
        .to_string();
        assert!(e.starts_with("s.off:8:") && e.contains("vertex 9"), "{e}");
        let e = parse(t.replace("1 1 0", "1 nan 0").as_bytes(), Path::new("s.off"))
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("s.off:6:"), "{e}");
        let e = parse(b"OFF\n4 1 0\n0 0 0\n", Path::new("s.off"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("ends after 1 of its 4 vertices"), "{e}");
    }
}
