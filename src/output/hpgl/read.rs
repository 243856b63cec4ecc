//! Reading HP-GL: the one lexer of the crate. An instruction ends with `;` or a line feed
//! (`ends_instruction`, [`next_instruction`]); it is a two-letter mnemonic, or `!` and two
//! letters for Roland's CAMM-GL extensions, upper-cased ([`instruction`]), then numbers
//! separated by commas or whitespace ([`numbers`]). The simulated cutter
//! (`device::sim::hpgl`) executes what this reads as a plotter would; [`parse`] reads back the
//! pen-down paths of a program that `super::emit` made, for tests and reports.
//!
//! Choices where the HP-GL manuals leave room: a parameter that is not a finite number makes
//! the whole instruction unreadable (the simulator skips it and counts it; [`parse`] refuses
//! the program); NUL bytes around an instruction are ignored.

/// Whether `b` ends an HP-GL instruction: `;` or a line feed.
pub(crate) fn ends_instruction(b: u8) -> bool {
    b == b';' || b == b'\n'
}

/// Length of the complete instruction at the front of `buf` (terminator included), if the
/// terminator has arrived.
pub fn next_instruction<'a>(buf: impl IntoIterator<Item = &'a u8>) -> Option<usize> {
    buf.into_iter()
        .position(|&b| ends_instruction(b))
        .map(|i| i + 1)
}

/// One instruction's mnemonic and parameter text. `text` is the instruction with or without
/// its terminator; `;`, whitespace and NULs around it are ignored. `None`: an empty
/// instruction. `Some(Err(()))`: no mnemonic can be cut from it (a character that is not
/// ASCII where the mnemonic ends).
pub fn instruction(text: &str) -> Option<Result<(String, &str), ()>> {
    let text = text.trim_matches(|c: char| c == ';' || c.is_whitespace() || c == '\0');
    if text.is_empty() {
        return None;
    }
    let split = if text.starts_with('!') { 3 } else { 2 };
    let Some(op) = text.get(..split.min(text.len())) else {
        return Some(Err(()));
    };
    Some(Ok((op.to_ascii_uppercase(), &text[op.len()..])))
}

/// The parameters of an instruction: numbers separated by commas or whitespace. `Err`: the
/// first one that is not a finite number.
pub fn numbers(params: &str) -> Result<Vec<f64>, &str> {
    params
        .split(|c: char| c == ',' || c.is_whitespace())
        .filter(|s| !s.is_empty())
        .map(|s| s.parse::<f64>().ok().filter(|v| v.is_finite()).ok_or(s))
        .collect()
}

/// A stroke read back from an HP-GL program: pen number, the velocity and force in effect
/// (as written after `VS` and `FS`/`!FS`; `None` when none was set since `IN`) and the points
/// in plotter units.
#[derive(Debug, Clone, PartialEq)]
pub struct ParsedStroke {
    pub pen: u32,
    pub speed: Option<f64>,
    pub force: Option<f64>,
    pub points: Vec<(i64, i64)>,
}

/// Read back the pen-down paths of a program made by `super::emit`: absolute `PU`/`PD`/`PA`, `SP`,
/// `VS`, `FS` and Roland's `!FS`; `IN` resets pen, velocity and force. Other instructions
/// (a profile's `init` and `end` lines) are skipped, except `PR`, whose relative moves this
/// reader does not follow. For tests and reports; the full interpreter is the simulated
/// cutter's.
pub fn parse(program: &str) -> Result<Vec<ParsedStroke>, String> {
    let mut strokes: Vec<ParsedStroke> = Vec::new();
    let mut pen = 0u32;
    let mut speed: Option<f64> = None;
    let mut force: Option<f64> = None;
    let mut at = (0i64, 0i64);
    let mut down = false;
    let ends = |c: char| c.is_ascii() && ends_instruction(c as u8);
    for (n, cmd) in program.split(ends).enumerate() {
        let cmd = cmd.trim();
        let Some(Ok((op, args))) = instruction(cmd) else {
            continue;
        };
        let understood = matches!(
            op.as_str(),
            "IN" | "SP" | "PU" | "PD" | "PA" | "PR" | "VS" | "FS" | "!FS"
        );
        if !understood {
            continue;
        }
        let nums = numbers(args)
            .map_err(|bad| format!("instruction {} `{cmd}`: `{bad}` is not a number", n + 1))?;
        match op.as_str() {
            "IN" => {
                pen = 0;
                speed = None;
                force = None;
                down = false;
            }
            "SP" => pen = nums.first().copied().unwrap_or(0.0) as u32,
            "VS" => speed = nums.first().copied(),
            "FS" | "!FS" => force = nums.first().copied(),
            "PR" if !nums.is_empty() => {
                return Err(format!(
                    "instruction {} `{cmd}`: relative moves are not read",
                    n + 1
                ))
            }
            "PR" => {}
            _ => {
                // PU, PD, PA: pen state (PA keeps it), then absolute moves.
                let pd = match op.as_str() {
                    "PU" => false,
                    "PD" => true,
                    _ => down,
                };
                if nums.len() % 2 != 0 {
                    return Err(format!("instruction {} `{cmd}`: odd coordinates", n + 1));
                }
                for xy in nums.chunks(2) {
                    let (x, y) = (xy[0].round() as i64, xy[1].round() as i64);
                    if pd {
                        if !down {
                            strokes.push(ParsedStroke {
                                pen,
                                speed,
                                force,
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
        }
    }
    Ok(strokes)
}
