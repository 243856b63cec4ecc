//! Spec → surfaces → flats → pieces, the first half of the pipeline ([`super`]): each
//! surface built at its size, laid flat (a mesh segmented again while its D-Charts leave
//! pieces under 1 % of its area, [`flatten_segmented`]) and made into pieces, split to fit
//! the spec's sheet unless `split = none`.

use crate::flatten::Flat;
use crate::pattern::Piece;
use crate::spec::Spec;
use crate::Error;

/// Surfaces → flats → pieces for a spec; prints the surfaces' warnings to stderr unless
/// `quiet`.
pub fn pieces(spec: &Spec, quiet: bool) -> Result<(Vec<Flat>, Vec<Piece>), Error> {
    flatten_surfaces(spec, sized_surfaces(spec)?, quiet)
}

/// The spec's surfaces built at their sizes (`size`, else `scale` × `units`), then the whole
/// job at its `size`; without a size given, a model of implausible size is refused
/// (`surface::size`).
pub fn sized_surfaces(spec: &Spec) -> Result<Vec<crate::surface::Surface>, Error> {
    let mut surfaces = Vec::new();
    for s in &spec.surfaces {
        let mut s = s.for_material(&spec.material);
        if spec.surfaces.len() == 1 && spec.size.is_some() {
            s.size = spec.size;
        }
        let surface = crate::surface::build(&s).map_err(|e| {
            if s.line > 0 {
                Error::At {
                    file: spec.path.clone(),
                    line: s.line,
                    source: Box::new(e.into()),
                }
            } else {
                e.into()
            }
        })?;
        surfaces.push(surface);
    }
    // The whole job at `size`; one surface was sized as it was read.
    let extent = crate::surface::size::extent_of(&surfaces);
    if let (Some(size), true) = (spec.size, spec.surfaces.len() > 1) {
        let f = crate::surface::size::factor_for(extent, size);
        surfaces.iter_mut().for_each(|s| s.scale(f));
    } else if spec.size.is_none() && spec.surfaces.iter().any(|s| s.size.is_none()) {
        let units = spec
            .surfaces
            .first()
            .map_or(Default::default(), |s| s.units);
        crate::surface::size::check_plausible(&spec.path, extent, units)?;
    }
    Ok(surfaces)
}

/// The room of the spec's sheet inside its margins.
fn sheet_room(spec: &Spec) -> crate::pattern::split::Room {
    let s = &spec.sheet;
    crate::pattern::split::Room::inside(s.width, s.height, s.margin)
}

/// Surfaces → flats → pieces (after [`sized_surfaces`]).
fn flatten_surfaces(
    spec: &Spec,
    surfaces: Vec<crate::surface::Surface>,
    quiet: bool,
) -> Result<(Vec<Flat>, Vec<Piece>), Error> {
    let mut flats = Vec::new();
    let pattern = spec.pattern_options();
    for (surface, s) in surfaces.into_iter().zip(&spec.surfaces) {
        // Whatever its size came from, a surface lies within the range flatcut works in.
        plausible_surface(&surface).map_err(|e| {
            if s.line > 0 {
                Error::At {
                    file: spec.path.clone(),
                    line: s.line,
                    source: Box::new(e),
                }
            } else {
                Error::In {
                    file: spec.path.clone(),
                    source: Box::new(e),
                }
            }
        })?;
        if !quiet {
            for w in &surface.warnings {
                eprintln!("flatcut: warning: {w}");
            }
        }
        // Charted (smooth) surfaces are parameterised, the rest unfolded exactly; pieces are
        // not merged past what fits the sheet when pieces are split to fit it.
        let (room, sheet) = match spec.pattern.split.unwrap_or_default() {
            crate::pattern::split::Split::Auto => {
                let r = sheet_room(spec);
                (
                    Some(r.for_faces(&pattern)),
                    Some([r.width, r.height.unwrap_or(f64::INFINITY)]),
                )
            }
            crate::pattern::split::Split::None => (None, None),
        };
        let opts = crate::flatten::charts::FlattenOptions {
            unfold: crate::flatten::UnfoldOptions::default(),
            room,
            sheet,
            ..crate::flatten::charts::FlattenOptions::for_material(spec.material.kind)
        };
        let flat = flatten_segmented(surface, &s.segment, &opts)?;
        if !quiet && flat.surface.charts.is_some() {
            for w in flat
                .surface
                .warnings
                .iter()
                .filter(|w| w.contains("stretches by"))
            {
                eprintln!("flatcut: warning: {w}");
            }
        }
        flats.push(flat);
    }
    let opts = pattern;
    let pieces =
        match spec.pattern.split.unwrap_or_default() {
            crate::pattern::split::Split::None => crate::pattern::build(&flats, &opts)?,
            crate::pattern::split::Split::Auto => {
                let room = sheet_room(spec);
                let before: Vec<usize> = flats.iter().map(|f| f.surface.warnings.len()).collect();
                let pieces = crate::pattern::split::build_to_fit(&mut flats, &opts, &room)
                    .map_err(|e| Error::In {
                        file: spec.path.clone(),
                        source: Box::new(e.into()),
                    })?;
                // Parts of a split piece that stretch more than their material allows.
                for (f, n) in flats.iter().zip(before).filter(|_| !quiet) {
                    for w in f.surface.warnings.iter().skip(n) {
                        eprintln!("flatcut: warning: {w}");
                    }
                }
                pieces
            }
        };
    Ok((flats, pieces))
}

/// Chart counts a mesh segmented into the default number of charts is segmented into again,
/// in turn, while some of its pieces are small ([`flatten_segmented`]).
const CHART_RETRIES: [usize; 3] = [16, 10, 12];

/// A surface laid flat (`flatten::charts::flatten`). A mesh segmented by D-Charts into its
/// default number of charts (the spec names none) whose pieces include some under 1 % of its
/// area that are not a whole part of it (`flatten::charts::small_islands`: a piece too small
/// to handle, where the merges, share-outs and hinges of the flatten stage found no
/// neighbour to join it to within the material's tolerance) is segmented again into
/// [`CHART_RETRIES`] charts in turn, until one leaves none: which charts are cut up, and so
/// which small pieces are left, turns on the count (issue 20). Twice the default first (the
/// flatten stage joins back what fits), then counts between. The flat with the fewest small
/// pieces is kept, then the one with the fewest pieces, then the first; report.json gives the
/// count it was segmented with and the segmentations tried (`figures`).
fn flatten_segmented(
    surface: crate::surface::Surface,
    seg: &crate::surface::SegmentSpec,
    opts: &crate::flatten::charts::FlattenOptions,
) -> Result<Flat, Error> {
    use crate::flatten::charts::{flatten, small_islands};
    let again = (surface.charts.is_some() && seg.charts.is_none()).then(|| surface.clone());
    let mut best = flatten(surface, opts)?;
    let Some(again) = again else {
        return Ok(best);
    };
    let key = |f: &Flat| (small_islands(f), f.islands.len());
    let (mut best_key, mut charts, mut tried) = (key(&best), None, 1);
    for n in CHART_RETRIES {
        if best_key.0 == 0 {
            break;
        }
        let mut s = again.clone();
        // A retry that fails keeps what the ones before gave.
        if !matches!(crate::surface::dcharts::resegment(&mut s, seg, n), Ok(true)) {
            continue;
        }
        tried += 1;
        if let Ok(f) = flatten(s, opts) {
            let k = key(&f);
            if k < best_key {
                (best, best_key, charts) = (f, k, Some(n));
            }
        }
    }
    let default = crate::surface::dcharts::DChartsOptions::default().charts;
    let figures = &mut best.surface.figures;
    figures.push(("dcharts_charts", charts.unwrap_or(default) as f64));
    figures.push(("dcharts_segmentations", f64::from(tried)));
    Ok(best)
}

/// A surface whose coordinates are beyond [`crate::geom::input::MAX_COORD`] is refused before
/// any stage allocates by them (a pole grid, a picture, a nesting scan).
fn plausible_surface(surface: &crate::surface::Surface) -> Result<(), Error> {
    let max = crate::geom::input::MAX_COORD;
    let far = surface
        .mesh
        .vertices
        .iter()
        .map(|v| v.abs().max_element())
        .fold(0.0, f64::max);
    if far > max || far.is_nan() {
        return Err(Error::Usage(format!(
            "surface `{}`: a coordinate is {far:.3e} mm from the origin, beyond the {max:.0} mm (1 km) flatcut works in; check the units or the dimensions",
            surface.name
        )));
    }
    Ok(())
}
