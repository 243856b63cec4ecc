//! `flatcut send FILE --device D [--port P]`: stream an existing `.plt` or `.gcode` program to a
//! machine (or, with `--simulate` or the `sim` device, to a simulated cutter, whose picture and
//! report go to `-o DIR`, default `out/send`). The file's extension must match the device's
//! language, so that G-code never reaches an HP-GL cutter by mistake.

use super::link::{deliver, LinkArgs};
use crate::Error;
use clap::Args;
use std::path::PathBuf;

#[derive(Debug, Args)]
pub struct SendArgs {
    /// Program to send (`.plt`/`.hpgl` for HP-GL devices, `.gcode`/`.nc` for GRBL).
    pub file: PathBuf,
    /// Device profile (default `sim`).
    #[arg(long, default_value = "sim")]
    pub device: String,
    #[command(flatten)]
    pub link: LinkArgs,
    /// Where the simulated cutter's picture and report go.
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// Print nothing but errors.
    #[arg(short, long)]
    pub quiet: bool,
}

pub fn run(a: &SendArgs) -> Result<(), Error> {
    let profile = crate::profile::find(&a.device)?;
    let bytes = std::fs::read(&a.file)
        .map_err(|e| Error::Usage(format!("{}: cannot read: {e}", a.file.display())))?;
    let ext = a
        .file
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    let expected: &[&str] = match profile.language {
        crate::profile::Language::Hpgl => &["plt", "hpgl", "hpg"],
        crate::profile::Language::Gcode => &["gcode", "nc", "ngc", "gc"],
    };
    if !expected.contains(&ext.as_str()) {
        return Err(Error::Usage(format!(
            "{}: device `{}` speaks {}, which is sent from a .{} file; this file is `.{ext}`",
            a.file.display(),
            profile.name,
            profile.language.label(),
            expected[0]
        )));
    }
    if bytes.is_empty() {
        return Err(Error::Usage(format!(
            "{}: the file is empty",
            a.file.display()
        )));
    }
    let dir = a
        .output
        .clone()
        .unwrap_or_else(|| PathBuf::from("out/send"));
    if super::link::simulated(&profile, &a.link) {
        crate::output::files::create_dir(&dir)?;
    }
    let name = a
        .file
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    for line in deliver(&[(name, bytes)], &profile, &a.link, &dir, a.quiet)? {
        if !a.quiet {
            println!("{line}");
        }
    }
    Ok(())
}
