//! stub until the spec module lands
use std::path::PathBuf;
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SurfaceKind { Mesh }
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Units { Mm }
impl Units { pub fn mm(self) -> f64 { 1.0 } }
pub struct SurfaceSpec { pub kind: SurfaceKind, pub path: PathBuf, pub scale: f64, pub units: Units, pub name: String, pub line: usize }
