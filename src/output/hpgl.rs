//! HP-GL programs: `IN;`, then for each stroke a pen select when the tool changes (`SPn;`), a
//! pen-up move to its start (`PU x,y;`) and pen-down moves along it (`PD x,y,…;`), in absolute
//! plotter units; `PU;SP0;` at the end puts the pen away with the tool up.
//!
//! Coordinates are converted from millimetres with the profile's units per mm (40 for HP-GL)
//! and rounded once, from the absolute position, so rounding never accumulates. Long strokes
//! are split into `PD` commands of at most 32 points, one command per line, because some
//! cutters limit the length of an instruction. Strokes whose kind the profile has no pen for
//! are left out; a point repeated after rounding is sent once.

use crate::device::Profile;
use crate::toolpath::SheetJob;
use std::fmt::Write;

/// Points per `PD` instruction.
const PD_POINTS: usize = 32;

/// Encode one sheet's strokes.
pub fn emit(sheet: &SheetJob, profile: &Profile) -> Vec<u8> {
    let k = profile.units_per_mm;
    let to_units = |v: f64| (v * k).round() as i64;
    let mut out = String::from("IN;\n");
    let mut pen: Option<u32> = None;
    for stroke in &sheet.strokes {
        let Some(p) = profile.tool(stroke.role.kind()).and_then(|t| t.pen) else {
            continue;
        };
        let mut pts: Vec<(i64, i64)> = stroke
            .points
            .iter()
            .map(|q| (to_units(q.x), to_units(q.y)))
            .collect();
        pts.dedup();
        let Some(&(x0, y0)) = pts.first() else {
            continue;
        };
        if pen != Some(p) {
            let _ = writeln!(out, "SP{p};");
            pen = Some(p);
        }
        let _ = writeln!(out, "PU{x0},{y0};");
        if pts.len() == 1 {
            // A dot: put the tool down where it is.
            let _ = writeln!(out, "PD{x0},{y0};");
            continue;
        }
        for chunk in pts[1..].chunks(PD_POINTS) {
            out.push_str("PD");
            for (i, (x, y)) in chunk.iter().enumerate() {
                if i > 0 {
                    out.push(',');
                }
                let _ = write!(out, "{x},{y}");
            }
            out.push_str(";\n");
        }
    }
    out.push_str("PU;SP0;\n");
    out.into_bytes()
}

/// A stroke read back from an HP-GL program: pen number and points in plotter units.
#[derive(Debug, Clone, PartialEq)]
pub struct ParsedStroke {
    pub pen: u32,
    pub points: Vec<(i64, i64)>,
}

/// Read back the pen-down paths of a program made by [`emit`] (absolute `PU`/`PD`/`SP` only).
/// For tests and reports; the full interpreter is the simulated cutter's.
pub fn parse(program: &str) -> Result<Vec<ParsedStroke>, String> {
    let mut strokes: Vec<ParsedStroke> = Vec::new();
    let mut pen = 0u32;
    let mut at = (0i64, 0i64);
    let mut down = false;
    for (n, cmd) in program.split(';').enumerate() {
        let cmd = cmd.trim();
        if cmd.len() < 2 {
            continue;
        }
        let (op, args) = cmd.split_at(2);
        let nums: Vec<i64> = if args.is_empty() {
            Vec::new()
        } else {
            args.split(',')
                .map(|v| v.trim().parse::<i64>())
                .collect::<Result<_, _>>()
                .map_err(|e| format!("instruction {} `{cmd}`: {e}", n + 1))?
        };
        match op {
            "IN" => {}
            "SP" => pen = nums.first().copied().unwrap_or(0) as u32,
            "PU" | "PD" => {
                let pd = op == "PD";
                for xy in nums.chunks(2) {
                    let &[x, y] = xy else {
                        return Err(format!("instruction {} `{cmd}`: odd coordinates", n + 1));
                    };
                    if pd {
                        if !down {
                            strokes.push(ParsedStroke {
                                pen,
                                points: vec![at],
                            });
                        }
                        if let Some(s) = strokes.last_mut() {
                            s.points.push((x, y));
                        }
                    }
                    down = pd;
                    at = (x, y);
                }
                down = pd;
            }
            other => return Err(format!("instruction {} `{other}` not understood", n + 1)),
        }
    }
    Ok(strokes)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::toolpath::{Stroke, StrokeRole};
    use glam::DVec2;

    #[test]
    fn pens_units_and_end() {
        let profile = crate::device::profile::find("hpgl-pens").unwrap();
        let job = SheetJob {
            width: 100.0,
            height: 100.0,
            strokes: vec![
                Stroke {
                    role: StrokeRole::Label,
                    points: vec![DVec2::new(1.0, 1.0), DVec2::new(2.0, 1.0)],
                    closed: false,
                    piece: None,
                },
                Stroke {
                    role: StrokeRole::Cut,
                    points: vec![
                        DVec2::new(10.0, 10.0),
                        DVec2::new(20.012, 10.0),
                        DVec2::new(20.0, 20.0),
                        DVec2::new(10.0, 10.0),
                    ],
                    closed: true,
                    piece: None,
                },
            ],
        };
        let text = String::from_utf8(emit(&job, &profile)).unwrap();
        assert_eq!(
            text,
            "IN;\nSP3;\nPU40,40;\nPD80,40;\nSP1;\nPU400,400;\nPD800,400,800,800,400,400;\nPU;SP0;\n"
        );
        let back = parse(&text).unwrap();
        assert_eq!(back.len(), 2);
        assert_eq!(back[1].pen, 1);
        assert_eq!(
            back[1].points,
            vec![(400, 400), (800, 400), (800, 800), (400, 400)]
        );
    }
}
