//! The integration tests, one binary: each module is one area (the whole pipeline, the
//! device over a pseudo-terminal, the CLI, the mesh corpus…), built and linked once.
//! Tests that read `../shared/data` start with [`require_shared!`]: they skip on a developer's
//! clone without it and fail when `CI` is set.

#[macro_use]
mod common;

mod bends;
mod bent;
mod boundary;
mod cli;
mod corpus;
mod dcharts;
mod device;
mod fandisk;
mod fuzz;
mod gpgl;
mod grbl_firmware;
mod house;
mod knife;
mod legible;
mod nest;
mod param;
mod pattern;
mod pdf;
mod print;
mod printcut;
mod resume;
mod robust;
mod simplify;
mod sizing;
mod spline;
mod split;
mod strip;
mod texture;
mod toolchange;
mod toolpath;
