//! `flatcut resume DIR`: go on with a job that stopped (hang-up, stall, Ctrl-C, a GRBL alarm)
//! from the last stroke the device is known to have finished, as the journal in `DIR` says
//! (`device::journal`).
//!
//! The stopped stream is read again from its files, checked as it was sent, and must be the
//! same bytes (its length and hash are in the journal): a program changed since is refused.
//! The stroke the job stopped in is cut again from its start (`--from-stroke N` chooses
//! another, 1-based); the streams after it follow whole, with their pauses. A real machine
//! first waits for the operator to re-home it or check that its origin is where the job
//! started, since after a hang-up or an alarm its position is not to be trusted. A simulated
//! machine starts afresh at its origin.

use super::link::{self, LinkArgs, Stream};
use crate::device::journal::{self, Journal, State};
use crate::Error;
use clap::Args;
use std::path::{Path, PathBuf};

#[derive(Debug, Args)]
pub struct ResumeArgs {
    /// The job's output folder (where `cut`, `fitting` or `send` wrote journal.json).
    pub dir: PathBuf,
    /// Device profile (default: the one the job was sent to).
    #[arg(long)]
    pub device: Option<String>,
    /// Go on from this stroke (1-based) of the first stream not done, instead of the
    /// journal's.
    #[arg(long, value_name = "N")]
    pub from_stroke: Option<usize>,
    #[command(flatten)]
    pub link: LinkArgs,
    /// Print nothing but errors.
    #[arg(short, long)]
    pub quiet: bool,
}

pub fn run(a: &ResumeArgs) -> Result<(), Error> {
    let mut journal = Journal::load(&a.dir).map_err(|e| Error::Usage(e.to_string()))?;
    let device = a.device.clone().unwrap_or_else(|| journal.device.clone());
    let profile = crate::profile::find(&device)?;
    let opts = link::stream_options(&a.link, a.quiet)?;
    let Some(first) = journal.streams.iter().position(|e| e.state != State::Done) else {
        if !a.quiet {
            println!(
                "{}: every stream of the job is done; nothing to resume",
                a.dir.join(journal::FILE).display()
            );
        }
        return Ok(());
    };
    let mut streams = Vec::with_capacity(journal.streams.len());
    for (j, e) in journal.streams.iter().enumerate() {
        streams.push(if j < first {
            Stream {
                sheet: e.sheet,
                names: Vec::new(),
                files: e.files.clone(),
                bytes: Vec::new(),
            }
        } else {
            read_stream(&a.dir, j, e, &profile)?
        });
    }
    let e = &journal.streams[first];
    let from = match (a.from_stroke, e.state) {
        (Some(0), _) => {
            return Err(Error::Usage(
                "--from-stroke counts from 1 (the first stroke)".into(),
            ))
        }
        (Some(k), _) if k > e.strokes => {
            return Err(Error::Usage(format!(
                "--from-stroke {k}: stream {} has {} strokes",
                first + 1,
                e.strokes
            )))
        }
        (Some(k), _) => k - 1,
        (None, State::Sending) => {
            return Err(Error::Usage(format!(
                "{}: stream {} ({}) was being sent when flatcut stopped, so where the machine got to is not known: look at the work and give --from-stroke N",
                a.dir.join(journal::FILE).display(),
                first + 1,
                streams[first].names.join(" + ")
            )))
        }
        (None, State::Stopped) => e.finished,
        (None, _) => 0,
    };
    let s = &mut streams[first];
    let total = e.strokes;
    if from >= total {
        // Every stroke is known done: only the end of the program (tool up) is left.
        journal.streams[first].state = State::Done;
        journal.streams[first].finished = total;
    } else {
        s.bytes = journal::resume_program(&s.bytes, profile.language, from).ok_or_else(|| {
            Error::Usage(format!(
                "stream {}: it has no stroke {} to go on from",
                first + 1,
                from + 1
            ))
        })?;
    }
    if !link::simulated(&profile, &a.link) {
        link::need_port(&profile, &a.link, false)?;
        let left: Vec<String> = streams[first..]
            .iter()
            .flat_map(|s| s.names.clone())
            .collect();
        link::wait_for_operator(
            &format!(
                "re-home the machine, or check that its origin is where the job started (stroke {} of {} comes next)",
                from + 1,
                total
            ),
            &left,
            &opts,
        )?;
    }
    if !a.quiet {
        println!(
            "resuming {} on {} from stroke {} of {}",
            streams[first].names.join(" + "),
            profile.name,
            from + 1,
            total
        );
    }
    let todo: Vec<(usize, usize)> = (first..streams.len())
        .filter(|&j| !(j == first && from >= total))
        .map(|j| (j, if j == first { from } else { 0 }))
        .collect();
    let n = journal.streams.iter().map(|e| e.sheet).max().unwrap_or(1);
    let said = link::send_streams(
        &streams,
        &todo,
        &mut journal,
        n,
        &profile,
        &a.link,
        &a.dir,
        &opts,
    )?;
    if !a.quiet {
        for l in said {
            println!("{l}");
        }
    }
    Ok(())
}

/// Stream `j` of the journal, read again from its files and checked as it was sent; the same
/// bytes or an error.
fn read_stream(
    dir: &Path,
    j: usize,
    e: &journal::Entry,
    profile: &crate::profile::Profile,
) -> Result<Stream, Error> {
    let mut programs = Vec::new();
    for f in &e.files {
        let path = PathBuf::from(f);
        let bytes = crate::pipeline::read_program(&path, profile)?;
        let name = path
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        programs.push((name, bytes));
    }
    let programs = link::checked(&programs, profile, true)?;
    let bytes: Vec<u8> = programs.iter().flat_map(|p| p.1.clone()).collect();
    if bytes.len() != e.bytes || journal::hash(&bytes) != e.hash {
        return Err(Error::Usage(format!(
            "{}: stream {} ({}) is not the program that was sent ({} bytes now, {} then): it was changed or made again; send it anew",
            dir.join(journal::FILE).display(),
            j + 1,
            e.files.join(" + "),
            bytes.len(),
            e.bytes
        )));
    }
    Ok(Stream {
        sheet: e.sheet,
        names: programs.into_iter().map(|p| p.0).collect(),
        files: e.files.clone(),
        bytes,
    })
}
