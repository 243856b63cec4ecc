//! `flatcut send FILE --device D [--port P]`: stream an existing `.plt` or `.gcode` program to a
//! machine (or, with `--simulate` or the `sim` device, to a simulated cutter, whose picture and
//! report go to `-o DIR`, default `out/send`). The file's extension must match the device's
//! language, so that G-code never reaches an HP-GL cutter by mistake, and an HP-GL or GP-GL
//! program wider than the device's media is refused before the first byte.

use super::link::{deliver_and_print, LinkArgs};
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
    let bytes = crate::pipeline::read_program(&a.file, &profile)?;
    let dir = a
        .output
        .clone()
        .unwrap_or_else(|| PathBuf::from("out/send"));
    // The simulator's picture and report, and the job's journal, go there.
    crate::pipeline::create_dir(&dir)?;
    let name = a
        .file
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    super::link::check_program_media(&profile, &name, &bytes)?;
    deliver_and_print(
        &[(name, bytes)],
        std::slice::from_ref(&a.file),
        &[crate::pipeline::Before::Start],
        &profile,
        &a.link,
        &dir,
        a.quiet,
    )
}
