//! Shared math for every stage: boundary curves sampled to a tolerance ([`curve`]), polygon meshes with edge adjacency ([`mesh`]), 2D polygons and
//! their tests ([`polygon`]), and a single-stroke font for labels a pen or knife can draw
//! ([`font`]). Millimetres and `f64` throughout (glam `DVec2`/`DVec3`).
//! 3D convex hulls and the local-convexity test of an edge: [`hull`].

pub mod boolean;
pub mod curve;
pub mod cut;
pub mod font;
pub mod heap;
pub mod hull;
pub mod mesh;
pub mod obj;
pub mod polygon;
pub mod proxy;
pub mod rng;
pub mod segment;
pub mod unionfind;
