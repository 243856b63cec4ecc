//! Device stage: what flatcut knows about machines ([`profile`]: language, units, tool table)
//! and how a program reaches them. For now a program is written to a file; the serial
//! transport and the simulated cutter come with the device issue.

pub mod profile;

pub use profile::{Language, Profile, ProfileError, Tool};
