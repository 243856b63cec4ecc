//! flatcut: developable surfaces to nested flat patterns for cutter plotters.
//!
//! # The pipeline
//!
//! One direction, one stage per module, plain data between them, composed in one place,
//! [`pipeline`]:
//!
//! 1. [`spec`] reads a job (a TOML spec, or a bare mesh with defaults) into the stages' own
//!    option types, with messages that name `FILE:LINE` and the key.
//! 2. [`surface`] makes each surface a [`surface::Surface`]: a 3D mesh of flat panels (imported
//!    OBJ meshes, D-Charts of smooth meshes, Wang–Tang strips between two curves, Bo–Wang bent
//!    sheets, Rose et al. boundary triangulations, sheet-metal fittings).
//! 3. [`flatten`] lays it into the plane as a [`flatten::Flat`]: exact unfolding into islands
//!    of faces moved by rigid motions, or LSCM / ABF++ charts of nearly developable meshes.
//! 4. [`pattern`] turns islands into [`pattern::Piece`]s: cut outline, fold and bend lines,
//!    seam ids, notches, labels, glue tabs, allowance and kerf; pieces too large for the sheet
//!    are split along their own lines first.
//! 5. [`nest`] places pieces on sheets or a roll as a [`nest::Layout`].
//! 6. [`toolpath`] orders each sheet's strokes into a [`toolpath::Job`] and prepares it for the
//!    machine (perforation, overcut, drag-knife offset).
//! 7. [`output`] encodes a job as HP-GL / CAMM-GL or GRBL G-code, and draws it as SVG, PNG and
//!    DXF, with report.json and the run's files written atomically.
//! 8. [`device`] carries a program to the machine: serial transport, buffered HP-GL and GRBL
//!    streaming, and the simulated cutter on a pseudo-terminal.
//!
//! Two leaves serve every stage: [`profile`] (device profiles and the stroke kinds their tools
//! make) and [`geom`] (shared math: meshes, curves, polygons, hulls, chart cutting, one seeded
//! RNG). [`cli`] parses the command line and calls [`pipeline`]. Imports run down the list
//! `cli → pipeline → spec → surface → … → device → profile, geom` and never up it; a stage uses
//! an earlier stage's public types, never its internals (`tests/suite/house.rs` checks it).
//!
//! Millimetres and `f64` inside, angles in radians (a field in another unit says so:
//! `angle_deg`); device units appear only in [`output`]. Indices are 0-based inside and
//! 1-based only in messages.
//!
//! # Using the crate
//!
//! [`pipeline::pieces`], [`pipeline::plan`] and [`pipeline::cut`] run the stages on a
//! [`spec::Spec`] ([`spec::load`]) for a [`profile::Profile`] ([`profile::find`]); each stage's
//! entry point (`surface::build`, `flatten::charts::flatten`, `pattern::build`, `nest::nest`,
//! `toolpath::plan`, `output::program`, `device::stream::send`) takes the previous stage's value
//! and its own options.
//!
//! # Layout
//!
//! ```text
//! lib.rs                       flatcut
//! main.rs                      The `flatcut` binary
//! pipeline.rs                  The one composer of the pipeline
//! pipeline/
//!   printcut.rs                Print-and-cut as the pipeline composes it (issue 25 item 4)
//!   surfaces.rs                Spec → surfaces → flats → pieces, a mesh segmented again for small pieces
//! cli/
//!   mod.rs                     Command line
//!   args.rs                    Flag groups shared by several subcommands (`cut`, `flatten`, `fitting`, `nest`)
//!   check.rs                   `flatcut check OBJ`
//!   cut.rs                     `flatcut cut SPEC|OBJ`
//!   fitting.rs                 `flatcut fitting KIND`
//!   flatten.rs                 `flatcut flatten SPEC|OBJ`
//!   link.rs                    What the subcommands that talk to a machine share
//!   nest.rs                    `flatcut nest INSTANCE.json [--nest-time S] [--seed N] [--threads T] -o DIR`
//!   ports.rs                   `flatcut ports` lists serial ports
//!   printcut.rs                Print-and-cut on the command line: flags, measuring the marks, the registered send
//!   send.rs                    `flatcut send FILE --device D [--port P]`
//!   sim.rs                     `flatcut sim --device D -o DIR`
//! device/
//!   mod.rs                     Device stage
//!   check.rs                   Checking an HP-GL program before its first byte goes out
//!   grbl.rs                    What GRBL 1.1 says on the wire, shared by the streaming host (`super::stream`) and the simulate…
//!   register.rs                Finding a printed sheet's registration marks with the machine's own sensor
//!   motion.rs                  How long a GRBL machine takes for its moves (trapezoidal speed profiles)
//!   serial.rs                  The serial transport
//!   stream/
//!     mod.rs                   Streaming a program into a device without ever overrunning it
//!     grbl.rs                  GRBL streaming: character counting and send-response, status polling
//!   sim/
//!     mod.rs                   The simulated cutter
//!     gpgl.rs                  The simulated cutter's GP-GL interpreter (Graphtec cutters in native mode)
//!     grbl/
//!       mod.rs                 The simulated cutter's GRBL interpreter, as GRBL 1.1h answers
//!       system.rs              The simulated GRBL's `$` commands and settings
//!     grbl_block.rs            Reading one G-code block as GRBL 1.1h's `gc_execute_line` does
//!     machine.rs               The simulated cutter's machine thread: line rate, buffer, flow control, answers
//!     hpgl.rs                  The simulated cutter's HP-GL interpreter
//!     record.rs                What the simulated cutter remembers of a job
//!     sensor.rs                The simulated cutter's printed sheet and its optical registration-mark sensor
//! flatten/
//!   mod.rs                     Flatten stage
//!   distortion.rs              Distortion of a flat layout against its 3D surface
//!   unfold.rs                  Exact unfolding of polyhedral meshes
//!   charts/
//!     mod.rs                   Flattening of a segmented smooth surface
//!     assemble.rs              The charts once laid, as one `Flat`
//!     darts.rs                 Darts and gussets
//!     hinge.rs                 Small pieces hinged onto a neighbour by one edge, the rest of their common boundary a slit
//!     overlap.rs               Overlap inside one chart's layout, and what is done about it (Julius 2006, thesis §5.3 "fixing …
//!   param/
//!     mod.rs                   Parameterisation of nearly developable disk-topology charts
//!     abf.rs                   ABF++ angles (Sheffer, Lévy, Mogilnitsky, Bogomyakov 2005)
//! geom/
//!   mod.rs                     Shared math for every stage, one kernel per file
//!   bend.rs                    Sheet-metal bend arithmetic, one place for every stage that develops a sheet: where the neutral…
//!   boolean.rs                 Polygon booleans and offsets on `DVec2` rings, through the `i_overlay` crate (pure Rust, MIT)
//!   curve.rs                   Boundary curves for strips (issue 4, item 2)
//!   cut.rs                     Cutting a chart of a mesh open into a topological disk (Julius 2006, thesis §5.2.3, "cuts conne…
//!   font.rs                    Single-stroke vector font for piece labels and edge id numbers
//!   heap.rs                    A binary-heap entry that pops the smallest key first, ties broken on the smaller id
//!   hull.rs                    3D convex hulls with facet adjacency and orientation, and the local-convexity test of an edge (…
//!   input.rs                   Reading a user's input file with bounds (a regular file under a size limit, UTF-8)
//!   mesh.rs                    Polygon meshes and their edge adjacency, Newell normals (`newell`) and signed dihedral angles (…
//!   obj.rs                     Wavefront OBJ text of a mesh, optionally with texture coordinates
//!   polygon.rs                 2D polygons
//!   proxy.rs                   The DCS proxy and its fit (Julius 2006, thesis §4.3, eq. 4.1 and eq. 5.4; §6.2.1, eq. 6.1)
//!   rng.rs                     The crate's one seeded random number generator
//!   segment.rs                 Distances between points and segments, in 2D and 3D
//!   similarity.rs              Least-squares similarity fit in the plane (Umeyama 1991)
//!   sparse.rs                  Sparse matrices for faer's Cholesky, assembled from triplets by column
//!   unionfind.rs               Union-find (disjoint sets) over `0..n` with path halving
//! nest/
//!   mod.rs                     Nest stage
//!   bench.rs                   The few solver steps that the benchmarks in `benches/nest.rs` time, behind a narrow public entr…
//!   esicup.rs                  ESICUP strip-packing instances in the JSON form used by jagua-rs and sparrow (see `../shared/da…
//!   problem.rs                 The nesting problem as data, independent of flatcut's pieces and of the ESICUP files
//!   collision/
//!     mod.rs                   Collision detection of the nest stage, in exact `f64` geometry, and the overlap measure the sep…
//!     overlap.rs               The overlap proxy between two colliding shapes, after sparrow (Gardeyn, Vanden Berghe, Wauters,…
//!     poles.rs                 Poles of inaccessibility of an item, after sparrow (Gardeyn, Vanden Berghe, Wauters, "An open-s…
//!     shape.rs                 Shapes of the nest stage
//!   solve/
//!     mod.rs                   The solver
//!     construct.rs             Constructive start
//!     improve.rs               Improvement of a constructed layout by overlap minimisation, after sparrow (Gardeyn, Vanden Ber…
//!     separate.rs              The separator of sparrow (Gardeyn, Vanden Berghe, Wauters, "An open-source heuristic to reboot …
//!     state.rs                 The state of one search
//! output/
//!   mod.rs                     Output stage
//!   design.rs                  `--spline-json`: the solved spline designs as JSON
//!   dxf.rs                     DXF output for sheet-metal shops (issue 4, item 6)
//!   files.rs                   Writing a run's files
//!   gpgl.rs                    GP-GL programs for Graphtec cutting plotters (CE6000 / CE7000 / FC series) in their native …
//!   gcode.rs                   GRBL 1.1 G-code programs (dialect `grbl`) for a drag knife on Z, a servo-lifted pen or a laser,…
//!   obj.rs                     Wavefront OBJ writer
//!   pdf.rs                     PDF output: 1:1, a page per sheet, stroke kinds as switchable layers, test squares
//!   print.rs                   tiled printing (--print): sheets onto printer pages with overlaps, match lines, assembly maps
//!   png.rs                     PNG output
//!   report.rs                  `report.json`
//!   svg.rs                     SVG output
//!   hpgl/
//!     mod.rs                   HP-GL programs, plain (dialect `hp-gl`) and Roland CAMM-GL mode 2 (dialect `camm-gl2`), one ins…
//!     read.rs                  Reading HP-GL
//! pattern/
//!   mod.rs                     Pattern stage
//!   allowance.rs               What a material adds to the border of a piece before it is cut (issue 8, item 2)
//!   bends.rs                   Which joined edges of a flat become fold (score) or bend lines, and at which angle
//!   develop.rs                 Sheet-metal development of mesh pieces (issue 20, item 9): each fold of a metal piece unfolded …
//!   legible.rs                 Legible finishing (issue 20, item 10): every text on a piece clear of the others and of every l…
//!   marks.rs                   Marks that tell a person which edge goes where and which way up a piece goes
//!   simplify.rs                Simplified seams for pieces laid out from D-Charts (issue 7, thesis §5.3 "Simplifying boundarie…
//!   split/
//!     mod.rs                   Splitting pieces that do not fit the sheet (issue 21, items 4 and 5): a piece larger than the s…
//!     partition.rs             Partitioning an island that does not fit the sheet into parts that do
//! profile/
//!   mod.rs                     Device profiles, the configuration several stages read (toolpath, output, device)
//!   read.rs                    Reading a profile
//!   registration.rs            The `[registration]` table: sensor, marks, tolerances (print-and-cut)
//!   serial.rs                  Serial line settings and the protocol that paces a program into the device
//!   tools.rs                   The tool table
//! spec/
//!   mod.rs                     The job spec
//!   bent.rs                    The reader of `kind = "bent-sheet"` surfaces
//!   boundary.rs                The reader of `kind = "boundary"` surfaces
//!   context.rs                 The `FILE:LINE` and dotted-key context of the spec reader's messages
//!   curves.rs                  Readers shared by several kinds of surface
//!   mesh.rs                    The reader of `kind = "mesh"` surfaces
//!   names.rs                   The names a user writes for the stages' enums
//!   spanned.rs                 The spanned-value machinery of the spec reader
//!   spline.rs                  The reader of `kind = "spline"` surfaces (Tang et al. 2016)
//!   strip.rs                   The reader of `kind = "strip"` surfaces
//!   tests.rs                   Tests of the spec reader
//! surface/
//!   mod.rs                     Surface stage
//!   dcs.rs                     The DCS approximation (Julius 2006, thesis chapter 6, eq. 6.1–6.3)
//!   fittings.rs                Sheet-metal fittings a shop makes every day (issue 4, item 3), each built as a developable stri…
//!   import.rs                  Mesh files of every format flatcut reads, chosen by extension and, for a file with another…
//!   material.rs                The material a pattern is cut from
//!   obj.rs                     Polyhedral meshes from Wavefront OBJ files, read through `tobj`, keeping polygon faces (a plana…
//!   off.rs                     OFF files (Object File Format, Geomview; the format of the CGAL and Princeton shape benchm…
//!   ply.rs                     PLY files (Greg Turk's polygon file format, Stanford 1994), ASCII and binary (little and b…
//!   segment.rs                 How a mesh surface is cut into pieces
//!   size.rs                    The size of a model
//!   solids.rs                  Small polyhedra for the example patterns in `patterns/` and for tests
//!   source.rs                  The description of one surface to build, the input of `crate::surface::build`
//!   stl.rs                     STL files (binary and ASCII), the triangle soups of 3D printing, welded into an indexed me…
//!   weld.rs                    What the mesh readers of STL, PLY and OFF share (see `import.rs`)
//!   boundary/
//!     mod.rs                   Developable surfaces from a closed 3D boundary (Rose, Sheffer, Wither, Cani, Thibert 2007, seed…
//!     bnb.rs                   §5 branch-and-bound on one simple loop (local vertex indices 0..m, in loop order), Fig. 9
//!     bounds.rs                §5.1.1 cover quality
//!     charts.rs                §3 charts of a subloop's convex hull, its envelopes, and the subloops a cover leaves
//!     checks.rs                Checks of the input boundary
//!     darts.rs                 §6.1 darts
//!     figures.rs               §4 metrics of a finished triangulation, for the report
//!     loops.rs                 §6 several loops and §6.1 rulings
//!     planar.rs                A planar loop needs no search: its developable is the flat polygon it bounds
//!     search.rs                The search of every region (§5), with the §7 radial offset and what happens when it finds nothi…
//!   dcharts/
//!     mod.rs                   D-Charts
//!     creases.rs               Which meshes are segmented, and what a pattern scores inside a chart
//!     disks.rs                 Charts made disks (Julius 2006, thesis §5.2.3, "cuts connecting the chart boundary loops")
//!     grow.rs                  Chart growing (Julius 2006, thesis §5.2.1, eq. 5.1–5.3)
//!     holes.rs                 Hole filling (Julius 2006, thesis §5.2.2)
//!     merge.rs                 Merging (Julius 2006, thesis §5.2.3)
//!     straighten.rs            Boundary straightening (Julius 2006, thesis §5.2.3, first post-processing step)
//!   geodesic/
//!     mod.rs                   Bent sheets
//!     admissible.rs            Admissibility (§3.2, §3.3, §4.3)
//!     bends.rs                 Bend lines from the rulings
//!     control.rs               A piece's control curve (§4.1)
//!     folds.rs                 The folds of one piece
//!     mesh.rs                  The folded sheet as a mesh (§3.3 step 4, §3.4, §4.2)
//!     path.rs                  The curve drawn on the flat sheet (§5: a line for a geodesic, else a planar curve whose signed …
//!     sheet.rs                 The flat sheet (§3.3)
//!     spline.rs                Control curves as something to evaluate
//!   spline/
//!     mod.rs                   Spline developables (Tang, Bo, Wallner, Pottmann 2016, *Interactive design of developable surf…
//!     develop.rs               Isometry to a prescribed flat domain (Tang et al. 2016, §5, eq. 12)
//!     solve/
//!       mod.rs                 Guided projection (Tang et al. 2016, §3.2 eq. 6) for spline developables
//!       goals.rs               The goals of a spline solve besides its constraints (Tang et al. 2016)
//!     system.rs                The linear algebra of guided projection (Tang et al. 2016, eq. 6)
//!     target.rs                Approximation of a target shape (Tang et al. 2016, §4.2, eq. 9–11)
//!     tests.rs                 Spline developables with exact answers (issue 24's acceptance shapes, at the library level)
//!   strip/
//!     mod.rs                   Developable triangulations of a strip (Wang & Tang, seed 003)
//!     global.rs                The global searches (§5)
//!     lanes.rs                 The data the cost rows of `super::global` run on
//!     local.rs                 LODT + LMBT (§4), kept for comparison
//!     offset.rs                A strip moved by a distance along its surface normals
//!     shop.rs                  Bend lines as a sheet-metal shop marks them (`bend_lines = "shop"`, the default of `flatcut fit…
//! toolpath/
//!   mod.rs                     Toolpath stage
//!   collect.rs                 The strokes of one sheet, unordered
//!   cuttable.rs                Features a device cannot make, found before anything is cut (issue 21)
//!   knife.rs                   What a machine's tools need beyond the ordered design
//!   order.rs                   Travel optimisation inside one group of strokes
//!   passes.rs                  Machines with one tool (issue 23)
//!   registration.rs            Registration marks of a print-and-cut sheet (issue 25 item 4)
//!   weed.rs                    Weed lines for vinyl (and any material whose waste is peeled off the carrier)
//! ```

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
    #[error(transparent)]
    Register(#[from] device::register::RegisterError),
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
            Error::Pattern(e) if e.is_bug() => 2,
            Error::Flatten(flatten::FlattenError::Overlap { .. }) => 2,
            Error::Nest(nest::NestError::Infeasible(_)) => 2,
            Error::In { source, .. } | Error::At { source, .. } => source.exit_code(),
            _ => 1,
        }
    }
}
