//! Device stage: how a program reaches a machine ([`check`] of a program before it is sent,
//! [`serial`] transport, [`stream`] protocols (GRBL streaming in `stream::grbl`)
//! with flow control and GRBL character counting, [`grbl`] protocol knowledge), and the
//! simulated cutter on a pseudo-terminal ([`sim`]) that stands in for a machine, and
//! [`register`]: finding a printed sheet's registration marks with the machine's sensor. What flatcut
//! knows about each machine (language, units, serial settings, tool table) is
//! [`crate::profile`].

pub mod check;
pub mod grbl;
pub mod journal;
pub(crate) mod motion;
pub mod register;
pub mod serial;
pub mod sim;
pub mod stream;
