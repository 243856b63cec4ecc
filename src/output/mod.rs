//! Output stage: turns a [`Job`](crate::toolpath::Job) into bytes — HPGL/G-code programs for
//! the cutter (`hpgl.rs`), an SVG document of all sheets ([`svg`]) and a PNG preview per sheet
//! ([`png`]).
//! Device units (plotter units, pixels) appear only here; everything upstream is millimetres,
//! x right, y up, origin at the sheet's lower-left corner.
//!
//! Choices shared by the encoders and kept in this module so that SVG and PNG agree:
//! the colour and dash pattern of each [`StrokeRole`], and the drawing order
//! ([`DRAW_ORDER`]: labels, marks, valley folds, mountain folds, cuts — cuts end up on top).

use crate::toolpath::StrokeRole;

pub mod hpgl;
pub mod png;
pub mod report;
pub mod svg;

/// Errors of the output stage; each names the sheet (index in the job) it happened on.
#[derive(Debug, thiserror::Error)]
pub enum OutputError {
    /// The picture has a zero or non-finite size, or its pixels cannot be allocated.
    #[error("sheet {sheet}: picture of {width_px}×{height_px} px cannot be drawn")]
    Picture {
        sheet: usize,
        width_px: u32,
        height_px: u32,
    },
    /// The PNG encoder refused the picture.
    #[error("sheet {sheet}: PNG encoding failed: {message}")]
    Encode { sheet: usize, message: String },
}

/// Roles in drawing order, back to front: what is drawn later lies on top.
/// The SVG layers follow this order too, after the sheet layer.
pub const DRAW_ORDER: [StrokeRole; 5] = [
    StrokeRole::Label,
    StrokeRole::Mark,
    StrokeRole::FoldValley,
    StrokeRole::FoldMountain,
    StrokeRole::Cut,
];

/// Colour (sRGB) and dash pattern (mm, on/off pairs; empty = solid) of a role.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct RoleStyle {
    pub rgb: [u8; 3],
    pub dash_mm: &'static [f64],
}

impl RoleStyle {
    /// `#rrggbb`.
    pub fn hex(self) -> String {
        let [r, g, b] = self.rgb;
        format!("#{r:02x}{g:02x}{b:02x}")
    }
}

/// Style of each role: cut black; mountain fold red dash-dot; valley fold blue dashed;
/// marks green; labels dark green.
pub(crate) fn role_style(role: StrokeRole) -> RoleStyle {
    match role {
        StrokeRole::Cut => RoleStyle {
            rgb: [0x00, 0x00, 0x00],
            dash_mm: &[],
        },
        StrokeRole::FoldMountain => RoleStyle {
            rgb: [0xd0, 0x00, 0x00],
            dash_mm: &[3.0, 1.0, 0.5, 1.0],
        },
        StrokeRole::FoldValley => RoleStyle {
            rgb: [0x00, 0x50, 0xd0],
            dash_mm: &[2.0, 1.0],
        },
        StrokeRole::Mark => RoleStyle {
            rgb: [0x00, 0x80, 0x00],
            dash_mm: &[],
        },
        StrokeRole::Label => RoleStyle {
            rgb: [0x00, 0x60, 0x00],
            dash_mm: &[],
        },
    }
}

/// Formats a coordinate in mm with at most 3 decimals, without trailing zeros and without
/// "-0": `12.5`, `0`, `3.142`. Rounding is Rust's `{:.3}` of the `f64`, so the text depends only
/// on the value. A non-finite value prints as `0` so that a document stays well-formed
/// (upstream stages only produce finite coordinates).
pub fn fmt_mm(v: f64) -> String {
    if !v.is_finite() {
        return "0".to_string();
    }
    let mut s = format!("{v:.3}");
    if s.contains('.') {
        let trimmed = s.trim_end_matches('0').trim_end_matches('.').len();
        s.truncate(trimmed);
    }
    if s == "-0" {
        s = "0".to_string();
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fmt_mm_examples() {
        assert_eq!(fmt_mm(12.5), "12.5");
        assert_eq!(fmt_mm(0.0), "0");
        assert_eq!(fmt_mm(-0.0), "0");
        assert_eq!(fmt_mm(-0.0004), "0");
        assert_eq!(fmt_mm(std::f64::consts::PI), "3.142");
        assert_eq!(fmt_mm(100.0), "100");
        assert_eq!(fmt_mm(-7.25), "-7.25");
        assert_eq!(fmt_mm(1.9996), "2");
        assert_eq!(fmt_mm(f64::NAN), "0");
        assert_eq!(fmt_mm(f64::INFINITY), "0");
    }

    #[test]
    fn styles() {
        assert_eq!(role_style(StrokeRole::FoldMountain).hex(), "#d00000");
        assert_eq!(role_style(StrokeRole::FoldValley).hex(), "#0050d0");
        assert_eq!(role_style(StrokeRole::Mark).hex(), "#008000");
        assert_eq!(role_style(StrokeRole::Label).hex(), "#006000");
        assert_eq!(role_style(StrokeRole::Cut).hex(), "#000000");
    }
}
