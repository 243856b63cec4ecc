//! flatcut
