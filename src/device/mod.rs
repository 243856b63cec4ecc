//! Device stage: what flatcut knows about machines ([`profile`]: language, units, serial
//! settings, tool table), how a program reaches them ([`serial`] transport, [`stream`]
//! protocols with flow control and GRBL character counting, [`grbl`] protocol knowledge), and
//! the simulated cutter on a pseudo-terminal ([`sim`]) that stands in for a machine.

pub mod grbl;
pub mod profile;
pub mod serial;
pub mod sim;
pub mod stream;

pub use profile::{Language, Profile, ProfileError, Tool};
