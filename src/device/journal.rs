//! The resume journal: what a job sent, and from which stroke a stopped job goes on.
//!
//! A job that streams writes `journal.json` in its output folder (atomically, before each
//! stream and when it ends): one entry per stream (a sheet's program, or the passes of a sheet
//! with a tool change, sent as one), with its files, its length and a hash of its bytes, and its
//! state: `pending`, `sending`, `done`, or `stopped` with the number of strokes the device is
//! known to have finished and the reason. `flatcut resume DIR` reads it back.
//!
//! Choices (no paper covers this):
//! - **Known finished.** A stroke is finished when every byte of it (up to the next stroke's
//!   start) is known executed. HP-GL and GP-GL: the bytes the device confirmed (the simulator's
//!   count, an `ESC.B` answer, or what was written less the buffer). GRBL: an `ok` means a line
//!   was planned, not run, so the last [`GRBL_PLANNED`] motion lines before the last `ok` count
//!   as not run. Nothing known: nothing finished.
//! - **The resumed program** is the original's preamble (everything before its first stroke:
//!   units, `IN`, the first tool, the G-code header with its first lift), then the settings
//!   that were in effect at the stroke (HP-GL/GP-GL: every instruction before it that does not
//!   move; G-code: the last feed `F`, and the laser's `M4 S` when it was on), then the program
//!   from that stroke on. Every stroke starts with the tool up and a move to its start
//!   (HP-GL `PU x,y`, GP-GL `M x,y`, G-code a lift then `G0 X Y`), so the stroke the job stopped
//!   in is cut again whole, from its start, and no other stroke is cut twice.
//! - A `sending` entry is a flatcut that died while streaming: where the device got to is not
//!   known, and resume needs the stroke from the operator (`--from-stroke`).

use super::stream::{stroke_starts, Position};
use crate::profile::Language;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// The journal's file name in a job's output folder.
pub const FILE: &str = "journal.json";

/// Motion lines GRBL may hold answered but not run: its planner (16 blocks in 1.1h, 18 in
/// 0.9) and the lines waiting in its 128-byte receive buffer are already counted by the
/// sender's `ok`s.
pub const GRBL_PLANNED: usize = 18;

/// A job's journal.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Journal {
    /// The device profile the job was sent to.
    pub device: String,
    pub streams: Vec<Entry>,
}

/// One stream of a job.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Entry {
    /// Sheet (1-based).
    pub sheet: usize,
    /// The program files sent one after the other as this stream.
    pub files: Vec<String>,
    /// Length of the stream as sent (after the device check), bytes.
    pub bytes: usize,
    /// FNV-1a hash of the stream as sent, hex.
    pub hash: String,
    pub strokes: usize,
    pub state: State,
    /// Strokes the device is known to have finished (the resume point, 0-based).
    #[serde(default)]
    pub finished: usize,
    /// Why it stopped.
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub why: String,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum State {
    Pending,
    Sending,
    Done,
    Stopped,
}

#[derive(Debug, thiserror::Error)]
pub enum JournalError {
    #[error("{path}: cannot read the journal: {err} (was the job sent from this folder?)")]
    Read { path: String, err: std::io::Error },
    #[error("{path}: not a flatcut journal: {err}")]
    Parse { path: String, err: String },
    #[error("{path}: cannot write the journal: {err}")]
    Write { path: String, err: String },
}

/// FNV-1a, 64 bit, as 16 hex digits.
pub fn hash(bytes: &[u8]) -> String {
    let h = bytes.iter().fold(0xcbf2_9ce4_8422_2325_u64, |h, &b| {
        (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
    });
    format!("{h:016x}")
}

impl Journal {
    /// Read `DIR/journal.json` (at most 1 MB).
    pub fn load(dir: &Path) -> Result<Journal, JournalError> {
        let path = dir.join(FILE);
        let p = path.display().to_string();
        let meta = std::fs::metadata(&path).map_err(|err| JournalError::Read {
            path: p.clone(),
            err,
        })?;
        if !meta.is_file() || meta.len() > 1 << 20 {
            return Err(JournalError::Parse {
                path: p,
                err: "not a regular file under 1 MB".into(),
            });
        }
        let text = std::fs::read_to_string(&path).map_err(|err| JournalError::Read {
            path: p.clone(),
            err,
        })?;
        serde_json::from_str(&text).map_err(|e| JournalError::Parse {
            path: p,
            err: format!("line {}, column {}: {}", e.line(), e.column(), e),
        })
    }

    /// Write it into `dir`, atomically, as one of the folder's run files.
    pub fn save(&self, dir: &Path) -> Result<(), JournalError> {
        let text = serde_json::to_string_pretty(self).map_err(|e| JournalError::Write {
            path: dir.join(FILE).display().to_string(),
            err: e.to_string(),
        })?;
        crate::output::files::write_in_run(dir, FILE, text.as_bytes()).map_err(|e| {
            JournalError::Write {
                path: dir.join(FILE).display().to_string(),
                err: e.to_string(),
            }
        })
    }
}

/// The strokes of `program` that the device is known to have finished when it stopped at `at`.
pub fn finished_strokes(program: &[u8], language: Language, at: &Position) -> usize {
    let starts = stroke_starts(program, language);
    let executed = match language {
        Language::Hpgl | Language::Gpgl => at.confirmed.unwrap_or(0),
        Language::Gcode => grbl_run_bytes(program, at.line.unwrap_or(0)),
    };
    // Stroke j ends where stroke j + 1 starts; the last one at the end of the program.
    let ends = starts.iter().skip(1).copied().chain([program.len()]);
    ends.take_while(|&e| e <= executed)
        .count()
        .min(starts.len())
}

/// Bytes of a G-code program known run when line `ok_line` (1-based) was the last answered:
/// up to the line [`GRBL_PLANNED`] motion lines before it.
fn grbl_run_bytes(program: &[u8], ok_line: usize) -> usize {
    let lines: Vec<&[u8]> = program.split(|&b| b == b'\n').collect();
    let mut at = 0;
    let mut offsets = Vec::with_capacity(lines.len());
    for l in &lines {
        offsets.push(at);
        at += l.len() + 1;
    }
    let mut left = GRBL_PLANNED;
    let mut k = ok_line.min(lines.len());
    while k > 0 && left > 0 {
        k -= 1;
        let t = String::from_utf8_lossy(lines[k]);
        let t = t.trim_start();
        if ["G0", "G1", "G2", "G3"].iter().any(|g| t.starts_with(g)) {
            left -= 1;
        }
    }
    if left > 0 {
        return 0;
    }
    offsets.get(k).copied().unwrap_or(0)
}

/// The program that goes on from stroke `from` (0-based) of `program`: its preamble, the
/// settings in effect at that stroke, and the rest (see the module documentation). `None`
/// when `from` is past the last stroke.
pub fn resume_program(program: &[u8], language: Language, from: usize) -> Option<Vec<u8>> {
    let starts = stroke_starts(program, language);
    let (&first, &at) = (starts.first()?, starts.get(from)?);
    let mut out = program[..first].to_vec();
    match language {
        Language::Hpgl | Language::Gpgl => {
            let mut rest = &program[first..at];
            while !rest.is_empty() {
                let n = match language {
                    Language::Hpgl => crate::output::hpgl::read::next_instruction(rest),
                    _ => crate::output::gpgl::next_instruction(rest),
                }
                .unwrap_or(rest.len());
                let ins = &rest[..n];
                if !moves(ins, language) {
                    out.extend_from_slice(ins);
                }
                rest = &rest[n..];
            }
        }
        Language::Gcode => {
            let before = String::from_utf8_lossy(&program[first..at]);
            let word = |w: char| {
                before
                    .lines()
                    .flat_map(|l| l.split_whitespace())
                    .rfind(|t| t.starts_with(w) && t.len() > 1)
                    .map(str::to_string)
            };
            if let Some(f) = word('F') {
                out.extend_from_slice(format!("{f}\n").as_bytes());
            }
            // The last M4/M5 before the resume point says whether the laser was on (M3 S is
            // a servo pen's position, which each stroke sets itself).
            let laser_on = before
                .lines()
                .map(str::trim_start)
                .rfind(|l| l.starts_with("M4") || l.starts_with("M5"))
                .is_some_and(|l| l.starts_with("M4"));
            if let (true, Some(s)) = (laser_on, word('S')) {
                out.extend_from_slice(format!("M4 {s}\n").as_bytes());
            }
        }
    }
    out.extend_from_slice(&program[at..]);
    Some(out)
}

/// Whether an HP-GL or GP-GL instruction moves the tool.
fn moves(ins: &[u8], language: Language) -> bool {
    let t = String::from_utf8_lossy(ins);
    let t = t.trim_start_matches(|c: char| c == ';' || c.is_whitespace() || c == '\0');
    let up = t.to_ascii_uppercase();
    match language {
        Language::Hpgl => ["PU", "PD", "PA", "PR"].iter().any(|m| up.starts_with(m)),
        _ => {
            // GP-GL: M and D (absolute), O and E (relative) move.
            matches!(up.as_bytes().first(), Some(b'M' | b'D' | b'O' | b'E'))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const HPGL: &[u8] =
        b"IN;SP1;VS10;PU0,0;PD100,0;PU100,100;SP2;PD200,100;PU300,0;PD300,50;PU;SP0;";

    #[test]
    fn an_hpgl_resume_keeps_the_tool_and_speed_in_effect() {
        let r = resume_program(HPGL, Language::Hpgl, 2).unwrap();
        assert_eq!(
            String::from_utf8(r).unwrap(),
            "IN;SP1;VS10;SP2;PU300,0;PD300,50;PU;SP0;"
        );
        assert!(resume_program(HPGL, Language::Hpgl, 3).is_none());
    }

    #[test]
    fn finished_strokes_count_only_whole_strokes() {
        let at = |c| Position {
            confirmed: Some(c),
            ..Position::default()
        };
        let second = HPGL.windows(9).position(|w| w == b"PU100,100").unwrap();
        assert_eq!(finished_strokes(HPGL, Language::Hpgl, &at(0)), 0);
        assert_eq!(finished_strokes(HPGL, Language::Hpgl, &at(second - 1)), 0);
        assert_eq!(finished_strokes(HPGL, Language::Hpgl, &at(second)), 1);
        assert_eq!(finished_strokes(HPGL, Language::Hpgl, &at(HPGL.len())), 3);
    }

    #[test]
    fn a_gcode_resume_sets_the_feed_and_the_beam_again() {
        let p = b"G21\nG90\nG0 X0 Y0\nM4 S800\nG1 X10 Y0 F300\nG0 X20 Y0\nG1 X30 Y0\nM5\nM2\n";
        let r = String::from_utf8(resume_program(p, Language::Gcode, 1).unwrap()).unwrap();
        assert_eq!(r, "G21\nG90\nF300\nM4 S800\nG0 X20 Y0\nG1 X30 Y0\nM5\nM2\n");
    }

    #[test]
    fn an_ok_from_grbl_is_not_a_finished_stroke() {
        let mut p = String::from("G21\n");
        for k in 0..10 {
            p.push_str(&format!("G0 X{k} Y0\nG1 Z-1 F100\nG1 X{k} Y5\nG0 Z2\n"));
        }
        let at = |l| Position {
            line: Some(l),
            ..Position::default()
        };
        // 41 lines answered: 40 motion lines, of which the last 18 may still be planned.
        assert_eq!(finished_strokes(p.as_bytes(), Language::Gcode, &at(41)), 5);
        assert_eq!(finished_strokes(p.as_bytes(), Language::Gcode, &at(10)), 0);
    }
}
