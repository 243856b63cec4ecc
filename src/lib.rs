//! flatcut: developable surfaces to nested flat patterns for cutter plotters.
//!
//! The pipeline runs one way, one stage per module, plain data between them:
//! a [`spec::Spec`] names the surfaces; [`surface`] makes each a [`surface::Surface`] (3D flat
//! panels: imported meshes, Wang–Tang strips between two curves, sheet-metal fittings); [`flatten`] lays it into the plane as a [`flatten::Flat`] (islands of faces moved by
//! rigid motions); [`pattern`] turns islands into [`pattern::Piece`]s (cut outline, fold lines,
//! edge ids, labels); [`nest`] places pieces on sheets as a [`nest::Layout`]; [`toolpath`]
//! orders the strokes of each sheet into a [`toolpath::Job`]; [`output`] encodes a job as HPGL,
//! SVG or PNG; [`device`] knows the machines (profiles) and carries the program to them.
//!
//! Millimetres and `f64` inside; device units appear only in [`output`].

pub mod cli;
pub mod device;
pub mod flatten;
pub mod geom;
pub mod nest;
pub mod output;
pub mod pattern;
pub mod pipeline;
pub mod profile;
pub mod spec;
pub mod surface;
pub mod toolpath;

/// Any error of a run, by stage. Each message is one line that names the file, piece or line
/// concerned.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    #[error(transparent)]
    Spec(#[from] spec::SpecError),
    #[error(transparent)]
    Surface(#[from] surface::SurfaceError),
    #[error(transparent)]
    Flatten(#[from] flatten::FlattenError),
    #[error(transparent)]
    Pattern(#[from] pattern::PatternError),
    #[error(transparent)]
    Nest(#[from] nest::NestError),
    #[error(transparent)]
    Esicup(#[from] nest::esicup::EsicupError),
    #[error(transparent)]
    Output(#[from] output::OutputError),
    #[error(transparent)]
    Profile(#[from] profile::ProfileError),
    #[error(transparent)]
    Serial(#[from] device::serial::SerialError),
    /// Boxed: it carries the job position and is much larger than the other variants.
    #[error(transparent)]
    Stream(Box<device::stream::StreamError>),
    #[error(transparent)]
    Sim(#[from] device::sim::SimError),
    #[error("{}: {source}", file.display())]
    In {
        file: std::path::PathBuf,
        source: Box<Error>,
    },
    #[error("{}:{line}: {source}", file.display())]
    At {
        file: std::path::PathBuf,
        line: usize,
        source: Box<Error>,
    },
    #[error("{0}")]
    Usage(String),
}

impl From<device::stream::StreamError> for Error {
    fn from(e: device::stream::StreamError) -> Self {
        Error::Stream(Box::new(e))
    }
}

impl Error {
    /// 2 for a bug in flatcut, 1 for everything the user or the environment can fix.
    pub fn exit_code(&self) -> i32 {
        match self {
            Error::Pattern(_) | Error::Nest(nest::NestError::Infeasible(_)) => 2,
            Error::In { source, .. } | Error::At { source, .. } => source.exit_code(),
            _ => 1,
        }
    }
}
