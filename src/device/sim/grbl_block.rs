//! Reading one G-code block as GRBL 1.1h's `gc_execute_line` does (steps 1 and 2: words, then
//! the checks before anything is executed), with its error numbers in its order: a word
//! without a letter `error:1`, a bad number `2`, an unsupported code or letter `20`, two
//! commands of one modal group `21`, a decimal where an integer belongs `23`, two commands
//! that both use the axis words `24`, a repeated word `25`, a negative F, N, P, S or T `4`.
//! The semantic checks that need the machine's state (feed defined, arc geometry, G53's
//! motion mode…) are the interpreter's ([`super::grbl`]).

/// What the axis words are for in this block (GRBL's `axis_command`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub(crate) enum AxisCommand {
    #[default]
    None,
    /// `G10`, `G28`, `G30`, `G92`.
    NonModal,
    Motion,
    /// `G43.1`.
    ToolLength,
}

/// Motion modes (modal group 1).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Motion {
    Seek,
    Linear,
    Cw,
    Ccw,
    None,
    /// `G38.3`: probe toward the target, stop at contact, no alarm without one.
    Probe,
}

/// Non-modal commands (group 0).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum NonModal {
    Dwell,
    SetCoord,
    GoHome0,
    SetHome0,
    GoHome1,
    SetHome1,
    Absolute,
    SetOffset,
    ResetOffset,
}

/// The words of one block by modal group: `None` where the block does not set it.
#[derive(Debug, Default, Clone)]
pub(crate) struct Block {
    pub motion: Option<Motion>,
    pub non_modal: Option<NonModal>,
    pub axis_command: AxisCommand,
    /// 0 XY, 1 ZX, 2 YZ.
    pub plane: Option<u8>,
    /// true: inches.
    pub units: Option<bool>,
    /// true: relative.
    pub relative: Option<bool>,
    /// true: inverse time (G93).
    pub inverse_time: Option<bool>,
    /// 0..=5: G54..G59.
    pub coord: Option<usize>,
    /// G43.1 (Some(true)) or G49 (Some(false)).
    pub tool_length: Option<bool>,
    /// M3 (Some(1)), M4 (Some(2)), M5 (Some(0)).
    pub spindle: Option<u8>,
    /// M8 (true), M9 (false).
    pub coolant: Option<bool>,
    /// M0 (0), M1 (1), M2 (2), M30 (30).
    pub flow: Option<u8>,
    /// Value words by letter (`A` = 0).
    pub words: [Option<f64>; 26],
}

impl Block {
    pub(crate) fn get(&self, l: u8) -> Option<f64> {
        self.words[(l - b'A') as usize]
    }

    pub(crate) fn axes(&self) -> [Option<f64>; 3] {
        [self.get(b'X'), self.get(b'Y'), self.get(b'Z')]
    }

    pub(crate) fn has_axes(&self) -> bool {
        self.axes().iter().any(Option::is_some)
    }
}

/// A line without its comments and blanks, upper-cased (what GRBL's line reader keeps).
pub(crate) fn strip(line: &str) -> String {
    let mut text = String::new();
    let (mut paren, mut semi) = (false, false);
    for c in line.chars() {
        if paren || semi {
            if c == ')' {
                paren = false;
            }
            continue;
        }
        match c {
            '(' => paren = true,
            ';' => semi = true,
            c if (c as u32) <= 32 || c == '/' => {}
            c => text.push(c.to_ascii_uppercase()),
        }
    }
    text
}

/// GRBL's `read_float`: an optional sign, digits with at most one point; `None` when no
/// digit. Returns the value and the bytes read.
fn read_float(b: &[u8]) -> Option<(f64, usize)> {
    let mut i = 0;
    if i < b.len() && (b[i] == b'-' || b[i] == b'+') {
        i += 1;
    }
    let (mut digits, mut point) = (0, false);
    while i < b.len() {
        match b[i] {
            b'0'..=b'9' => digits += 1,
            b'.' if !point => point = true,
            _ => break,
        }
        i += 1;
    }
    if digits == 0 {
        return None;
    }
    let text = std::str::from_utf8(&b[..i]).ok()?;
    Some((text.parse().ok()?, i))
}

/// Parse a stripped line into a block (see the module documentation for the errors).
pub(crate) fn parse(text: &str) -> Result<Block, u32> {
    let b = text.as_bytes();
    let mut blk = Block::default();
    let mut groups = 0u32;
    let mut i = 0;
    while i < b.len() {
        let letter = b[i];
        if !letter.is_ascii_uppercase() {
            return Err(1);
        }
        let Some((v, n)) = read_float(&b[i + 1..]) else {
            return Err(2);
        };
        i += 1 + n;
        match letter {
            b'G' => g_word(&mut blk, v, &mut groups)?,
            b'M' => m_word(&mut blk, v, &mut groups)?,
            b'F' | b'I' | b'J' | b'K' | b'L' | b'N' | b'P' | b'R' | b'S' | b'T' | b'X' | b'Y'
            | b'Z' => {
                let k = (letter - b'A') as usize;
                if blk.words[k].is_some() {
                    return Err(25);
                }
                if matches!(letter, b'F' | b'N' | b'P' | b'T' | b'S') && v < 0.0 {
                    return Err(4);
                }
                blk.words[k] = Some(v);
            }
            _ => return Err(20),
        }
    }
    if blk.has_axes() && blk.axis_command == AxisCommand::None {
        blk.axis_command = AxisCommand::Motion;
    }
    Ok(blk)
}

fn group(groups: &mut u32, g: u32) -> Result<(), u32> {
    if *groups & (1 << g) != 0 {
        return Err(21);
    }
    *groups |= 1 << g;
    Ok(())
}

fn axis_command(blk: &mut Block, c: AxisCommand) -> Result<(), u32> {
    if blk.axis_command != AxisCommand::None {
        return Err(24);
    }
    blk.axis_command = c;
    Ok(())
}

fn g_word(blk: &mut Block, v: f64, groups: &mut u32) -> Result<(), u32> {
    let int = v.trunc() as i64;
    let mantissa = ((v - v.trunc()) * 100.0).round() as i64;
    let mut used = false;
    let g = match int {
        0..=3 => {
            axis_command(blk, AxisCommand::Motion)?;
            blk.motion =
                Some([Motion::Seek, Motion::Linear, Motion::Cw, Motion::Ccw][int as usize]);
            1
        }
        80 => {
            blk.motion = Some(Motion::None);
            1
        }
        38 if mantissa == 30 => {
            axis_command(blk, AxisCommand::Motion)?;
            blk.motion = Some(Motion::Probe);
            used = true;
            1
        }
        4 | 10 | 28 | 30 | 53 | 92 => {
            let nm = match (int, mantissa) {
                (4, _) => NonModal::Dwell,
                (10, _) => NonModal::SetCoord,
                (28, 10) => NonModal::SetHome0,
                (28, _) => NonModal::GoHome0,
                (30, 10) => NonModal::SetHome1,
                (30, _) => NonModal::GoHome1,
                (53, _) => NonModal::Absolute,
                (92, 10) => NonModal::ResetOffset,
                _ => NonModal::SetOffset,
            };
            if matches!(int, 10 | 28 | 30 | 92) && mantissa == 0 {
                axis_command(blk, AxisCommand::NonModal)?;
            }
            if mantissa == 10 && matches!(int, 28 | 30 | 92) {
                used = true;
            }
            blk.non_modal = Some(nm);
            0
        }
        17..=19 => {
            blk.plane = Some((int - 17) as u8);
            2
        }
        20 | 21 => {
            blk.units = Some(int == 20);
            6
        }
        90 | 91 => {
            blk.relative = Some(int == 91);
            3
        }
        93 | 94 => {
            blk.inverse_time = Some(int == 93);
            5
        }
        40 => 7,
        43 if mantissa == 10 => {
            axis_command(blk, AxisCommand::ToolLength)?;
            blk.tool_length = Some(true);
            used = true;
            8
        }
        49 => {
            blk.tool_length = Some(false);
            8
        }
        54..=59 => {
            blk.coord = Some((int - 54) as usize);
            12
        }
        61 => 13,
        _ => return Err(20),
    };
    if mantissa > 0 && !used {
        return Err(23);
    }
    group(groups, g)
}

fn m_word(blk: &mut Block, v: f64, groups: &mut u32) -> Result<(), u32> {
    if v.fract() != 0.0 {
        return Err(23);
    }
    let g = match v as i64 {
        c @ (0 | 1 | 2 | 30) => {
            blk.flow = Some(c as u8);
            14
        }
        c @ (3..=5) => {
            blk.spindle = Some(match c {
                3 => 1,
                4 => 2,
                _ => 0,
            });
            15
        }
        c @ (8 | 9) => {
            blk.coolant = Some(c == 8);
            16
        }
        _ => return Err(20),
    };
    group(groups, g)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn errors_in_grbl_order() {
        let p = |l: &str| parse(&strip(l)).map(|_| ());
        assert_eq!(p("G1 X1.2.3"), Err(1));
        assert_eq!(p("G0 G1 X1"), Err(24));
        assert_eq!(p("G0 X1 X2"), Err(25));
        assert_eq!(p("G5 X1"), Err(20));
        assert_eq!(p("G59.1"), Err(23));
        assert_eq!(p("M6"), Err(20));
        assert_eq!(p("G17 G18"), Err(21));
        assert_eq!(p("G1 X2 F-5"), Err(4));
        assert_eq!(p("%"), Err(1));
        assert_eq!(p("X"), Err(2));
        assert_eq!(p("g0 x2 (a) ; b"), Ok(()));
        assert_eq!(p("G92.1"), Ok(()));
        assert_eq!(p("G43.1 Z1"), Ok(()));
    }
}
