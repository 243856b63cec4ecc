//! Shared math for every stage, one kernel per file; it imports no other module of the crate.
//! Millimetres and `f64` throughout (glam `DVec2`/`DVec3`).
//!
//! - [`mesh`]: polygon meshes, edge adjacency, Newell normals, signed dihedral angles.
//! - [`obj`]: the Wavefront OBJ writer.
//! - [`curve`]: boundary curves sampled to a tolerance, B-spline knots and derivatives.
//! - [`bspline`]: B-spline curves (clamped or periodic) as sparse linear rows of their control
//!   points, for the spline developables' solver.
//! - [`polygon`], [`boolean`], [`segment`]: 2D polygons (area, triangulation, overlap, poles,
//!   line crossings), their booleans and offsets, point and segment distances (2D and 3D).
//! - [`bend`]: sheet-metal bend arithmetic: neutral surface depth, bend allowance, setback and
//!   deduction (shared by the fittings and the development of metal meshes).
//! - [`hull`]: 3D convex hulls and the local-convexity test of an edge.
//! - [`cut`], [`proxy`]: cutting a mesh chart open into a disk, and the developable proxy fit
//!   (D-Charts), shared by the surface and flatten stages.
//! - [`similarity`]: the least-squares similarity (scale, rotation, translation) between two
//!   point sets and its residuals (print-and-cut registration).
//! - [`sparse`]: compressed-column matrices assembled from triplets, for faer's Cholesky.
//! - [`unionfind`], [`heap`]: disjoint sets and a smallest-first heap entry.
//! - [`rng`]: the crate's one seeded random number generator.
//! - [`par`]: fork–join over the machine's cores (a join, a map over independent jobs) whose
//!   results do not depend on the number of threads.
//! - [`grid`]: a uniform grid of boxes and segments over a box, for box and ray queries
//!   (text placement, the PDF's free spots).
//! - [`font`]: the single-stroke font for labels a pen or knife can draw.
//! - [`input`]: reading a user's input file: a regular file under a size limit, UTF-8 with a
//!   position.

pub mod bend;
pub mod boolean;
pub mod bspline;
pub mod curve;
pub mod cut;
pub mod font;
pub mod grid;
pub mod heap;
pub mod hull;
pub mod input;
pub mod mesh;
pub mod obj;
pub mod par;
pub mod polygon;
pub mod proxy;
pub mod rng;
pub mod segment;
pub mod similarity;
pub mod sparse;
pub mod unionfind;
