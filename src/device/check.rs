//! Checking a program before its first byte goes out. GP-GL gets the same final tool-up and
//! terminator as HP-GL below ([`check_gpgl`]). HP-GL: every move within HP-GL's
//! coordinate range (±2^30 plotter units; a device ignores an instruction out of range, so the
//! job would go on from the wrong place), and a final tool-up: a program that ends with the
//! tool down (truncated, or made by hand) gets `;PU;` appended, with a warning, so that no job
//! leaves the knife in the material.
//!
//! The program is run through the simulated cutter's interpreter (`sim::hpgl`), the same one
//! the device simulator and the no-flow-control pacing use, so "tool down at the end" means
//! what a plotter would make of it. An unterminated last instruction counts as the device
//! would execute it once the appended `;` arrives.

use super::sim::hpgl::{Hpgl, RANGE};
use crate::output::hpgl::read::{instruction, next_instruction, numbers};
use crate::profile::Profile;

/// A program fault found before sending.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CheckError {
    #[error("instruction {index} (byte {byte}) `{op}` moves outside HP-GL's coordinate range (±{} plotter units); the device would ignore it and cut on from the wrong place", RANGE as u64)]
    OutOfRange {
        /// 1-based.
        index: usize,
        /// 1-based offset of the instruction's first byte.
        byte: usize,
        op: String,
    },
}

/// A program as it will be sent, and what was changed.
#[derive(Debug, Clone, PartialEq)]
pub struct Checked {
    pub bytes: Vec<u8>,
    pub warnings: Vec<String>,
}

/// The program without its trailing white space and NULs.
fn body(program: &[u8]) -> &[u8] {
    program
        .iter()
        .rposition(|b| !b.is_ascii_whitespace() && *b != 0)
        .map_or(&program[..0], |i| &program[..=i])
}

/// Check a GP-GL program as [`check_hpgl`] checks HP-GL: run through the simulated cutter's
/// GP-GL interpreter, an unterminated last instruction gets its ETX, and a program that ends
/// with the tool down gets a tool-up where the tool stands (`M x,y`), each with a warning.
pub fn check_gpgl(program: &[u8], profile: &Profile) -> Checked {
    use crate::output::gpgl;
    let mut m = super::sim::gpgl::Gpgl::new(profile);
    let mut rest = program;
    while !rest.is_empty() {
        let n = gpgl::next_instruction(rest).unwrap_or(rest.len());
        m.execute(&rest[..n]);
        rest = &rest[n..];
    }
    let mut bytes = program.to_vec();
    let mut warnings = Vec::new();
    let body = body(program);
    if body.last().is_some_and(|&b| !gpgl::ends_instruction(b)) {
        bytes.push(0x03);
        warnings.push(
            "the last instruction has no terminator: an ETX was appended so that the device executes it"
                .into(),
        );
    }
    if m.is_down() {
        let tool = m.tool_down().unwrap_or_else(|| "the tool".into());
        let at = m.position();
        bytes.extend_from_slice(format!("M{},{}\x03", at.x.round(), at.y.round()).as_bytes());
        warnings.push(format!(
            "the program ends with the tool down ({tool}): a tool-up where it stands (`M`) was appended"
        ));
    }
    Checked { bytes, warnings }
}

/// Check an HP-GL program (see the module doc); G-code is returned as it is (its checks are
/// the GRBL streamer's).
pub fn check_hpgl(program: &[u8], profile: &Profile) -> Result<Checked, CheckError> {
    let mut m = Hpgl::new(profile);
    let mut rest = program;
    let mut at = 0usize;
    let mut index = 0usize;
    loop {
        let n = next_instruction(rest).unwrap_or(rest.len());
        if n == 0 {
            break;
        }
        let raw = &rest[..n];
        let text = String::from_utf8_lossy(raw);
        if let Some(Ok((op, args))) = instruction(&text) {
            index += 1;
            let before = m.ignored.get(&format!("{op} (out of range)")).copied();
            m.execute(raw);
            let after = m.ignored.get(&format!("{op} (out of range)")).copied();
            if after != before && numbers(args).is_ok() {
                return Err(CheckError::OutOfRange {
                    index,
                    byte: at + 1,
                    op,
                });
            }
        }
        at += n;
        rest = &rest[n..];
    }
    let mut bytes = program.to_vec();
    let mut warnings = Vec::new();
    let body = body(program);
    let open = body.last().is_some_and(|&b| b != b';' && b != b'\n');
    if open {
        bytes.push(b';');
        warnings.push(
            "the last instruction has no terminator: a `;` was appended so that the device executes it"
                .into(),
        );
    }
    if m.pen_down() {
        let tool = m.tool_down().unwrap_or_else(|| "the pen".into());
        bytes.extend_from_slice(b"PU;");
        warnings.push(format!(
            "the program ends with the tool down ({tool}): a tool-up (`PU;`) was appended"
        ));
    }
    Ok(Checked { bytes, warnings })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn profile() -> Profile {
        crate::profile::find("sim").unwrap()
    }

    #[test]
    fn a_gpgl_program_ending_tool_down_gets_a_tool_up() {
        let p = crate::profile::find("graphtec-ce6000-gpgl").unwrap();
        let c = check_gpgl(b"J1\x03M100,100\x03D400,400\x03", &p);
        assert!(
            c.bytes.ends_with(b"D400,400\x03M400,400\x03"),
            "{:?}",
            String::from_utf8_lossy(&c.bytes)
        );
        assert_eq!(c.warnings.len(), 1, "{:?}", c.warnings);
        let c = check_gpgl(b"J1\x03M100,100\x03D400,400", &p);
        assert!(c.bytes.ends_with(b"D400,400\x03M400,400\x03"));
        assert_eq!(c.warnings.len(), 2, "{:?}", c.warnings);
        // Ending tool up: as it is.
        let ok = b"J1\x03M100,100\x03D400,400\x03M0,0\x03H\x03";
        let c = check_gpgl(ok, &p);
        assert_eq!(c.bytes, ok.to_vec());
        assert!(c.warnings.is_empty());
    }

    #[test]
    fn a_program_ending_tool_down_gets_a_tool_up() {
        let c = check_hpgl(b"IN;SP1;PU0,0;PD400,400;", &profile()).unwrap();
        assert!(c.bytes.ends_with(b"PD400,400;PU;"));
        assert_eq!(c.warnings.len(), 1, "{:?}", c.warnings);
        let c = check_hpgl(b"IN;SP1;PU0,0;PD400,400", &profile()).unwrap();
        assert!(c.bytes.ends_with(b"PD400,400;PU;"));
        assert_eq!(c.warnings.len(), 2, "{:?}", c.warnings);
        let c = check_hpgl(b"IN;SP1;PD400,400;PU", &profile()).unwrap();
        assert!(
            c.bytes.ends_with(b";PU;"),
            "{:?}",
            String::from_utf8_lossy(&c.bytes)
        );
        let ok = b"IN;SP1;PU0,0;PD400,400;PU;SP0;";
        let c = check_hpgl(ok, &profile()).unwrap();
        assert_eq!(c.bytes, ok.to_vec());
        assert!(c.warnings.is_empty());
    }

    #[test]
    fn out_of_range_moves_are_refused_before_sending() {
        let e = check_hpgl(b"SP2;PD;PA1e300,0;PU1,1;", &profile()).unwrap_err();
        assert_eq!(
            e,
            CheckError::OutOfRange {
                index: 3,
                byte: 8,
                op: "PA".into()
            }
        );
        let e = check_hpgl(b"PR;PU1000000000,0;PU1000000000,0;", &profile()).unwrap_err();
        assert!(matches!(e, CheckError::OutOfRange { index: 3, .. }), "{e}");
    }
}
