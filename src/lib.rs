//! flatcut: developable surfaces to nested flat patterns for cutter plotters.
//!
//! The pipeline runs one way, one stage per module, plain data between them:
//! a [`spec::Spec`] names the surfaces; [`surface`] makes each a [`surface::Surface`] (3D flat
//! panels); [`flatten`] lays it into the plane as a [`flatten::Flat`] (islands of faces moved by
//! rigid motions); [`pattern`] turns islands into [`pattern::Piece`]s (cut outline, fold lines,
//! edge ids, labels); [`nest`] places pieces on sheets as a [`nest::Layout`]; [`toolpath`]
//! orders the strokes of each sheet into a [`toolpath::Job`]; [`output`] encodes a job as HPGL,
//! SVG or PNG; [`device`] knows the machines (profiles) and carries the program to them.
//!
//! Millimetres and `f64` inside; device units appear only in [`output`].

pub mod geom;
pub mod spec;
pub mod surface;
pub mod flatten;
pub mod pattern;
pub mod nest;
pub mod toolpath;
