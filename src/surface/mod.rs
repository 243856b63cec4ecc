//! Surface stage: where developables come from. Each way of making a developable lives in its
//! own file or folder (the papers are in shared/seeds/, see its README); all of them produce a
//! [`Surface`]: a polygon mesh in millimetres whose faces are flat panels, with its name and
//! the file it came from.
//!
//! - [`obj`]: a polyhedral mesh read from a Wavefront OBJ file, checked and repaired; beside
//!   it [`stl`], [`ply`] and [`off`] read the other mesh formats into the same raw mesh
//!   (`weld.rs` welds their points), and [`import`] picks the reader by extension or content.
//! - [`size`]: a model's extent, scaling a surface to a size, and the refusal of implausible
//!   sizes (issue 21).
//! - [`solids`]: small polyhedra for the example patterns and tests (cube, tetrahedron,
//!   lampshade, house).
//! - [`strip`]/: Wang & Tang, *Developable Triangulations of a Strip*: the developable
//!   triangulation between two boundary curves.
//! - [`fittings`]: sheet-metal fittings (cone, square-to-round, pipe miter …) built on strips.
//! - [`boundary`]/: Rose et al. 2007, *Developable Surfaces from Arbitrary Sketched
//!   Boundaries*: a boundary triangulation of closed 3D loops, with darts and rulings.
//! - [`geodesic`]/: Bo & Wang 2007, *Geodesic-Controlled Developable Surfaces*: a flat sheet
//!   bent along control curves (bent sheets).
//! - [`dcharts`]/: Julius 2006, D-Charts: a smooth mesh segmented into nearly developable charts.
//! - [`spline`]/: Tang, Bo, Wallner, Pottmann 2016: spline developables between B-spline
//!   curves, made developable by guided projection.
//! - [`dcs`]: Julius 2006, §6 DCS approximation: a mesh moved towards a developable one.
//! - [`source`], [`material`], [`segment`]: what a surface is built from (the spec's
//!   reader fills them): the surface description, the material, the D-Charts options.

pub mod boundary;
pub mod dcharts;
pub mod dcs;
pub mod fittings;
pub mod geodesic;
pub mod import;
pub mod material;
pub mod obj;
pub mod off;
pub mod ply;
pub mod segment;
pub mod size;
pub mod solids;
pub mod source;
pub mod spline;
pub mod stl;
pub mod strip;
pub mod texture;
mod weld;

use crate::geom::mesh::Mesh;
pub use material::{Material, MaterialKind};
pub use segment::{ApproximateSpec, Fixed, Segment, SegmentSpec};
pub use source::{BoundarySpec, SheetSide, StripSpec, SurfaceKind, SurfaceSpec, Units};
use std::path::PathBuf;

/// A developable surface made of flat polygon panels.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Surface {
    /// Name shown in labels and reports.
    pub name: String,
    /// File it was read from.
    pub source: PathBuf,
    /// Panels in millimetres, consistently oriented (counter-clockwise seen from the printed
    /// side, which is the outside of a closed mesh).
    pub mesh: Mesh,
    /// Repairs made on import, one line each, for the user to read.
    pub warnings: Vec<String>,
    /// Which edges are bend (or score) lines, when the source decides it (strips: the chosen
    /// rulings, with their angles); `None` leaves it to the pattern stage's angle threshold.
    pub bends: Option<Vec<Bend>>,
    /// Chart of each face, when the source segmented a smooth mesh into nearly developable
    /// charts that the flatten stage parameterises one by one; `None`: the faces are exact flat
    /// panels, unfolded as they are.
    pub charts: Option<Vec<usize>>,
    /// Edges (their two mesh vertices, smaller first, sorted) cut open even where both faces are
    /// in one chart: the seams that make a tube or a closed shell a disk, and darts (issue 7,
    /// thesis §5.2.3). The flatten stage splits the vertices along them before parameterising
    /// and the pattern stage draws them as cut lines with seam marks on both sides. Empty for
    /// none. Without `charts` the exact unfolder never joins them (the seam ruling where a
    /// closed spline surface is opened).
    pub cuts: Vec<[usize; 2]>,
    /// Figures the source measured, written under the surface in `report.json` (strips: points
    /// on each curve, interior and locally convex bridges, bending energy; boundary surfaces:
    /// interior triangles, locally convex fraction, …); empty for none.
    pub figures: Vec<(&'static str, f64)>,
    /// Other meshes the source found for the same boundary, best first (boundary surfaces,
    /// `--alternatives`); they share the vertices of `mesh`.
    pub alternatives: Vec<Mesh>,
    /// The solved design of a spline surface (curves, creases; `--spline-json`), in the
    /// surface's millimetres; `None` for other kinds.
    pub spline: Option<Box<spline::Design>>,
    /// The textures of a mesh read from an OBJ with materials and `vt` (printed onto the
    /// flat faces by the output stage); `None` for none.
    pub texture: Option<std::sync::Arc<texture::Texture>>,
    /// A mesh's shape at [`size::SHAPE_MM`] across, as its segmentation saw it: the flatten
    /// stage decides on these vertices and scales what it lays out to the millimetres of
    /// `mesh`, so that the same model at any size gives the same pieces (issue 20, item 5).
    /// `None` for surfaces not read from a mesh (their sizes are part of their design).
    pub shape: Option<size::Shape>,
}

/// A bend line chosen by the surface source: a mesh edge (its two vertices) and the signed
/// bend angle it stands for, in degrees, positive for a mountain (convex seen from the printed
/// side). With rulings picked at a spacing, the angle is the sum over the rulings it replaces.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bend {
    pub verts: [usize; 2],
    pub angle_deg: f64,
}

/// Everything that can be wrong with a surface source. Each message is one line that names the
/// file and, where known, the line.
#[derive(Debug, thiserror::Error)]
pub enum SurfaceError {
    #[error("{}: cannot read mesh: {source}", path.display())]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{}{}: {message}", path.display(), line.map(|l| format!(":{l}")).unwrap_or_default())]
    Parse {
        path: PathBuf,
        line: Option<usize>,
        message: String,
    },
    #[error("{}:{line}: vertex {} has a coordinate that is not a finite number ({text}); fix or remove it", path.display(), index + 1)]
    NonFinite {
        path: PathBuf,
        line: usize,
        /// The vertex, 0-based (1-based in the message, as OBJ counts).
        index: usize,
        text: String,
    },
    #[error("{}: {message}", path.display())]
    Invalid { path: PathBuf, message: String },
    #[error("{}{}: edge from {a} to {b} is shared by {count} faces (lines {lines}); each edge may join at most two faces", path.display(), first_line.map(|l| format!(":{l}")).unwrap_or_default())]
    NonManifold {
        path: PathBuf,
        first_line: Option<usize>,
        a: String,
        b: String,
        count: usize,
        lines: String,
    },
    #[error("surface `{surface}`: {message}")]
    Strip { surface: String, message: String },
    #[error("surface `{surface}`: {source}")]
    Bent {
        surface: String,
        source: geodesic::GeodesicError,
    },
    #[error("surface `{surface}`: {message}")]
    Boundary { surface: String, message: String },
    #[error("surface `{surface}`: {}{source}", source.key_prefix())]
    Spline {
        surface: String,
        source: spline::SplineError,
    },
    #[error("{}{}: the mesh is not orientable (a Möbius-like band): its faces cannot all be wound the same way", path.display(), line.map(|l| format!(":{l}")).unwrap_or_default())]
    NonOrientable { path: PathBuf, line: Option<usize> },
}

/// Build the surface a spec entry describes, at its size (`size`, else `scale` × `units`).
pub fn build(spec: &SurfaceSpec) -> Result<Surface, SurfaceError> {
    let mut surface = build_as_given(spec)?;
    if spec.kind != SurfaceKind::Mesh {
        let f = match spec.size {
            Some(s) => size::factor_for(size::extent(&surface.mesh), s),
            None => spec.scale * spec.units.mm(),
        };
        if f != 1.0 {
            surface.scale(f);
        }
    }
    Ok(surface)
}

/// [`build`] before a non-mesh surface is scaled (a mesh is scaled as it is read).
fn build_as_given(spec: &SurfaceSpec) -> Result<Surface, SurfaceError> {
    match spec.kind {
        SurfaceKind::Mesh => {
            let mut raw = import::read(&spec.path)?;
            let texture = raw.texture.take().map(std::sync::Arc::new);
            let texture_warnings = std::mem::take(&mut raw.texture_warnings);
            let raw_extent = size::extent(&raw.mesh);
            let scale = match spec.size {
                Some(s) => size::factor_for(raw_extent, s),
                None => spec.scale * spec.units.mm(),
            };
            // Checked, repaired and segmented at one size whatever the size asked for (the
            // checks' thresholds are relative; the segmentation's decisions then are too).
            let canonical = size::factor_for(raw_extent, size::SHAPE_MM);
            let (mesh, mut warnings) = obj::validate(raw, canonical)?;
            warnings.extend(texture_warnings);
            let mut surface = Surface {
                name: spec.name.clone(),
                source: spec.path.clone(),
                mesh,
                warnings,
                bends: None,
                charts: None,
                texture,
                ..Default::default()
            };
            // Smooth meshes (issue 7): DCS approximation and D-Charts segmentation.
            dcharts::apply(&mut surface, &spec.segment)?;
            surface.shape = Some(size::Shape {
                vertices: surface.mesh.vertices.clone(),
                to_mm: 1.0,
            });
            surface.scale(scale / canonical);
            Ok(surface)
        }
        SurfaceKind::Strip => build_strip(spec),
        SurfaceKind::BentSheet => build_bent(spec),
        SurfaceKind::Boundary => build_boundary(spec),
        SurfaceKind::Spline => build_spline(spec),
    }
}

/// A [`strip`] surface: sample both curves, triangulate, move to the neutral surface, pick the
/// bend lines.
fn build_strip(spec: &SurfaceSpec) -> Result<Surface, SurfaceError> {
    let err = |message: String| SurfaceError::Strip {
        surface: spec.name.clone(),
        message,
    };
    let st = spec
        .strip
        .as_ref()
        .ok_or_else(|| err("a strip needs `p` and `q`".into()))?;
    let p =
        st.p.sample(st.tolerance)
            .map_err(|e| err(format!("`p`: {e}")))?;
    let q =
        st.q.sample(st.tolerance)
            .map_err(|e| err(format!("`q`: {e}")))?;
    let mut s = strip::Strip::new(&p, &q).map_err(|e| err(e.to_string()))?;
    // The global triangulations keep one byte per bridge (m·n of them).
    const MAX_BRIDGES: usize = 64_000_000;
    if s.m().saturating_mul(s.n()) > MAX_BRIDGES {
        return Err(err(format!(
            "`p` has {} points and `q` {}: {} candidate bridges is over {MAX_BRIDGES}; raise `tolerance` (now {} mm)",
            s.m(),
            s.n(),
            s.m().saturating_mul(s.n()),
            st.tolerance
        )));
    }
    let steps = s.triangulate(st.method);
    let mut warnings = Vec::new();
    let mt = s.metrics(&steps);
    if mt.convex < mt.interior && st.method != strip::Method::Gmat {
        warnings.push(format!(
            "surface `{}`: {} of {} rulings are not locally convex: the blank will need some stretching there",
            spec.name,
            mt.interior - mt.convex,
            mt.interior
        ));
    }
    if st.neutral_offset != 0.0 {
        let reach = s.inner_reach();
        if st.neutral_offset > 0.0 && st.neutral_offset >= reach {
            return Err(err(format!(
                "the neutral surface lies {:.3} mm inside, more than the curves allow ({reach:.3} mm from their centre): the thickness is larger than a radius",
                st.neutral_offset
            )));
        }
        s = s.offset(&steps, st.neutral_offset);
    }
    let figures = vec![
        ("points_p", s.m() as f64),
        ("points_q", s.n() as f64),
        ("interior_bridges", mt.interior as f64),
        ("locally_convex_bridges", mt.convex as f64),
        ("bending_energy", mt.energy),
    ];
    Ok(Surface {
        name: spec.name.clone(),
        source: spec.path.clone(),
        mesh: s.mesh(&steps),
        warnings,
        bends: Some(s.bends(&steps, st.bend_lines)),
        charts: None,
        figures,
        ..Default::default()
    })
}

/// A [`boundary`] surface (Rose et al.): the boundary triangulation of the spec's loops.
fn build_boundary(spec: &SurfaceSpec) -> Result<Surface, SurfaceError> {
    let err = |message: String| SurfaceError::Boundary {
        surface: spec.name.clone(),
        message,
    };
    let b = spec
        .boundary
        .as_ref()
        .ok_or_else(|| err("a boundary surface needs `loop`".into()))?;
    let out = boundary::triangulate(&b.input, &b.options).map_err(|e| err(e.to_string()))?;
    let f = &out.figures;
    Ok(Surface {
        name: spec.name.clone(),
        source: spec.path.clone(),
        mesh: out.mesh,
        warnings: out
            .warnings
            .into_iter()
            .map(|w| format!("surface `{}`: {w}", spec.name))
            .collect(),
        figures: vec![
            ("triangles", f.triangles as f64),
            ("interior_triangles", f.interior_triangles as f64),
            ("interior_edges", f.interior_edges as f64),
            ("locally_convex_fraction", f.convex_fraction()),
            ("largest_dihedral_deg", f.largest_dihedral_deg),
            ("fairness_rad2", f.fairness),
            ("iterations", f.iterations as f64),
        ],
        alternatives: out.alternatives,
        ..Default::default()
    })
}

/// A [`geodesic`] bent sheet: the outline folded along the rulings of its control curves.
fn build_bent(spec: &SurfaceSpec) -> Result<Surface, SurfaceError> {
    let err = |source| SurfaceError::Bent {
        surface: spec.name.clone(),
        source,
    };
    let b = spec.bent.as_ref().ok_or_else(|| {
        err(geodesic::GeodesicError::Mesh(
            "a bent sheet needs `outline`, `line` and a control curve".into(),
        ))
    })?;
    let bent = geodesic::bend(b).map_err(err)?;
    Ok(Surface {
        name: spec.name.clone(),
        source: spec.path.clone(),
        mesh: bent.mesh,
        warnings: bent
            .warnings
            .into_iter()
            .map(|w| format!("surface `{}`: {w}", spec.name))
            .collect(),
        bends: Some(bent.bends),
        ..Default::default()
    })
}

/// A [`spline`] surface (Tang et al.): solved by guided projection, sampled with its rulings
/// as edges and its creases as fold lines.
fn build_spline(spec: &SurfaceSpec) -> Result<Surface, SurfaceError> {
    let err = |source| SurfaceError::Spline {
        surface: spec.name.clone(),
        source,
    };
    let sp = spec.spline.as_ref().ok_or_else(|| {
        err(spline::SplineError::Shape {
            key: "curves".into(),
            message: "missing: a spline surface needs `curves`".into(),
        })
    })?;
    let solved = spline::build(sp).map_err(err)?;
    Ok(Surface {
        name: spec.name.clone(),
        source: spec.path.clone(),
        mesh: solved.mesh,
        warnings: solved
            .warnings
            .into_iter()
            .map(|w| format!("surface `{}`: {w}", spec.name))
            .collect(),
        bends: Some(solved.bends),
        cuts: solved.seam,
        figures: solved.figures,
        spline: Some(Box::new(spline::Design {
            model: solved.model,
            params: solved.params,
            curve_verts: solved.curve_verts,
        })),
        ..Default::default()
    })
}
