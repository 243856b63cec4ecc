//! How a mesh surface is cut into pieces: the options of the D-Charts segmentation
//! ([`super::dcharts::apply`], Julius et al.) and of the DCS approximation before it
//! ([`super::dcs`]), as a spec file's `kind = "mesh"` keys give them (issue 7).
//!
//! Choices: every field is optional; `None` leaves the decision to the mesh (smooth meshes are
//! segmented, polyhedral ones unfolded face by face) or to the material's defaults.

/// How a mesh surface is cut into pieces (a spec's `segment`, `charts`, `f_max`,
/// `approximate` and `simplify`, see `spec::mesh`).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SegmentSpec {
    /// `None`: decided from the mesh (D-Charts when it is smooth, see
    /// `surface::dcharts::is_smooth`).
    pub mode: Option<Segment>,
    /// Initial estimate of the number of charts (at least 1).
    pub charts: Option<usize>,
    /// D-Charts fitting threshold, more than 0 and at most 1.
    pub f_max: Option<f64>,
    pub approximate: Option<ApproximateSpec>,
    /// Largest deviation (mm) of a simplified seam between charts (thesis §5.3,
    /// `pattern::simplify`); 0: off; `None`: the material's default (paper and fabric 0.5,
    /// metal 0.1). Exact unfoldings never change.
    pub simplify: Option<f64>,
}

/// `segment = "faces" | "dcharts"`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Segment {
    /// Every face a rigid panel, unfolded exactly.
    Faces,
    /// D-Charts: nearly developable charts, parameterised.
    Dcharts,
}

impl Segment {
    /// The names a spec file and the command line use.
    pub(crate) const NAMES: [(&'static str, Segment); 2] =
        [("faces", Segment::Faces), ("dcharts", Segment::Dcharts)];
}

/// `approximate = { iterations, fixed }`: DCS approximation before segmenting.
#[derive(Debug, Clone, PartialEq)]
pub struct ApproximateSpec {
    /// Rounds (>= 1; default 1).
    pub iterations: usize,
    /// Vertices that stay in place.
    pub fixed: Vec<Fixed>,
}

/// A fixed vertex (or set) of the DCS approximation.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Fixed {
    /// Every vertex on the mesh boundary.
    Boundary,
    /// A vertex of the (welded) mesh, 0-based (the spec numbers them from 1).
    Vertex(usize),
}
