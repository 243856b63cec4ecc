//! The mesh corpus (issue 20): every mesh in `../shared/data/meshes/`, made by nobody here,
//! scaled to 300 mm and cut from paper, fabric and metal on the default A4 sheet. Each run
//! goes through the library as `flatcut cut MESH --size 300 --material M` does (surfaces →
//! flats → pieces → nest) and is checked for what a person assembling the parts relies on:
//! - it runs (no error, exit 0);
//! - no two flat triangles of one piece overlap (the exact triangle test,
//!   `flatten::unfold::find_overlap`), and the nest keeps the pieces apart and on their sheets
//!   (`nest::verify`);
//! - every seam's two sides are as long as each other and as the 3D seam, within the
//!   material's tolerance (`pattern::marks::seam_mismatches`: paper 0.2 %, metal 0.1 %,
//!   fabric 1 %), and report.json says the 3D length;
//! - no text (seam id, bend note, label) overlaps another text or a line of another kind, as
//!   in the bundled patterns (`legible::collisions`).
//!
//! CI runs each mesh in one material (the three in turn, so every material meets several
//! meshes); `corpus_every_mesh_in_every_material` (ignored, `cargo test --release -- --ignored
//! corpus`) runs all three and prints the table of the issue note (pieces, L2, worst piece,
//! worst seam, pieces under 1 % of the area, seconds).

use crate::common::*;
use flatcut::flatten::{charts, unfold, Flat};
use flatcut::pattern::{marks, Piece};
use flatcut::spec::{Material, MaterialKind, Spec};
use std::path::PathBuf;
use std::time::Instant;

/// The corpus meshes, sorted by name.
fn meshes() -> Vec<PathBuf> {
    let dir = shared_data("meshes");
    let mut v: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "obj"))
        .collect();
    v.sort();
    assert!(v.len() >= 10, "{} meshes in {}", v.len(), dir.display());
    v
}

/// `flatcut cut MESH --size 300 --material KIND`'s spec: the mesh at 300 mm, the material's
/// default thickness.
fn spec_at_300(mesh: &std::path::Path, kind: MaterialKind) -> Spec {
    let mut spec = Spec::from_mesh(mesh);
    spec.size = Some(300.0);
    spec.material = Material {
        kind,
        thickness: kind.default_thickness(),
        ..Material::default()
    };
    spec
}

/// What one run measured.
struct Row {
    pieces: usize,
    l2: f64,
    worst_piece: f64,
    worst_seam: f64,
    seams: usize,
    small: usize,
    /// D-Charts segmentations the flatten stage tried (`dcharts_segmentations`; 1 where the
    /// first left no small piece or the mesh was not segmented).
    segmentations: usize,
    seconds: f64,
}

/// `flatcut cut MESH --size 300 --material KIND` through the library, checked (see the
/// module doc); panics naming the mesh and material on a failed check.
fn run(mesh: &std::path::Path, kind: MaterialKind) -> Row {
    let what = format!("{} in {kind}", mesh.display());
    let start = Instant::now();
    let spec = spec_at_300(mesh, kind);
    let (flats, pieces) =
        flatcut::pipeline::pieces(&spec, true).unwrap_or_else(|e| panic!("{what}: {e}"));
    for flat in &flats {
        if let Some((f, g)) = unfold::find_overlap(flat) {
            panic!("{what}: faces {f} and {g} of one piece overlap");
        }
    }
    let mismatches = marks::seam_mismatches(&pieces, kind);
    assert!(
        mismatches.is_empty(),
        "{what}: {} seams over the tolerance, e.g. {}",
        mismatches.len(),
        mismatches[0].1
    );
    for p in &pieces {
        let hit = crate::legible::collisions(p);
        assert!(
            hit.is_empty(),
            "{what}: piece {}: {:?}",
            p.name,
            &hit[..hit.len().min(3)]
        );
    }
    let row = measure(&flats, &pieces);
    let opts = flatcut::nest::NestOptions {
        width: spec.sheet.width,
        height: spec.sheet.height,
        margin: spec.sheet.margin,
        spacing: spec.sheet.spacing,
        seconds: 0.1,
        ..Default::default()
    };
    let layout = flatcut::nest::nest(pieces, &opts).unwrap_or_else(|e| panic!("{what}: {e}"));
    flatcut::nest::verify(&layout).unwrap_or_else(|e| panic!("{what}: {e}"));
    Row {
        seconds: start.elapsed().as_secs_f64(),
        ..row
    }
}

/// Pieces, stretch and seams of a run.
fn measure(flats: &[Flat], pieces: &[Piece]) -> Row {
    let (mut l2, mut worst_piece, mut area_w) = (0.0, 1.0f64, 0.0);
    for flat in flats.iter().filter(|f| f.surface.charts.is_some()) {
        let (per, whole) = charts::stretch(flat);
        for s in &per {
            worst_piece = worst_piece.max(s.l2);
        }
        l2 += whole.l2 * whole.area_3d;
        area_w += whole.area_3d;
    }
    let total: f64 = pieces.iter().map(|p| p.area).sum();
    let mut worst_seam = 0.0f64;
    let mut seams = 0;
    for p in pieces {
        for s in p.seams.iter().filter(|s| s.is_a && s.length_3d > 0.0) {
            let other = pieces
                .iter()
                .flat_map(|q| &q.seams)
                .find(|t| t.id == s.id && !t.is_a);
            if let Some(t) = other {
                worst_seam = worst_seam.max((s.length - t.length).abs() / s.length_3d);
                seams += 1;
            }
        }
    }
    Row {
        pieces: pieces.len(),
        l2: if area_w > 0.0 { l2 / area_w } else { 1.0 },
        worst_piece,
        worst_seam,
        seams,
        small: pieces.iter().filter(|p| p.area < 0.01 * total).count(),
        segmentations: flats
            .iter()
            .flat_map(|f| &f.surface.figures)
            .filter(|(k, _)| *k == "dcharts_segmentations")
            .map(|&(_, v)| v as usize)
            .max()
            .unwrap_or(1),
        seconds: 0.0,
    }
}

fn print_row(mesh: &std::path::Path, kind: MaterialKind, r: &Row) {
    println!(
        "| {} | {kind} | {} | {:.5} | {:.5} | {:.3} % of {} | {} | {:.1} |",
        mesh.file_stem().unwrap_or_default().to_string_lossy(),
        r.pieces,
        r.l2,
        r.worst_piece,
        100.0 * r.worst_seam,
        r.seams,
        r.small,
        r.seconds
    );
}

const KINDS: [MaterialKind; 3] = [
    MaterialKind::Paper,
    MaterialKind::Fabric,
    MaterialKind::Metal,
];

#[test]
fn corpus_each_mesh_runs_without_overlap_and_with_matching_seams() {
    require_shared!();
    for (i, mesh) in meshes().iter().enumerate() {
        let kind = KINDS[i % 3];
        let r = run(mesh, kind);
        print_row(mesh, kind, &r);
    }
}

#[test]
#[ignore = "the whole corpus in three materials: minutes; run with --release -- --ignored"]
fn corpus_every_mesh_in_every_material() {
    require_shared!();
    println!("| mesh | material | pieces | L2 | worst piece L2 | worst seam | pieces < 1 % | s |");
    println!("|---|---|---|---|---|---|---|---|");
    for mesh in meshes() {
        for kind in KINDS {
            let r = run(&mesh, kind);
            print_row(&mesh, kind, &r);
        }
    }
}

/// Issue 20, item 5: the pieces are decided on the shape, not on its size. The same mesh at
/// 30 mm, 300 mm and 3 m gives the same pieces, face for face, and each layout is the 300 mm
/// one scaled (to rounding); the mushroom is charted, the pig is charted with darts and
/// merges, fandisk goes through D-Charts' creases.
#[test]
fn corpus_pieces_do_not_depend_on_the_size() {
    for name in ["mushroom.obj", "pig.obj", "fandisk.obj"] {
        let mesh = shared_data("meshes").join(name);
        let flat_at = |size: f64| {
            let mut spec = Spec::from_mesh(&mesh);
            spec.size = Some(size);
            let mut surfaces = flatcut::pipeline::sized_surfaces(&spec).unwrap();
            let opts = charts::FlattenOptions::for_material(MaterialKind::Paper);
            charts::flatten(surfaces.remove(0), &opts).unwrap()
        };
        let base = flat_at(300.0);
        assert!(
            base.islands.len() > 1,
            "{name}: {} pieces",
            base.islands.len()
        );
        for size in [30.0, 3000.0] {
            let flat = flat_at(size);
            let what = format!("{name} at {size} mm");
            assert_eq!(
                flat.islands, base.islands,
                "{what}: other pieces than at 300 mm"
            );
            assert_eq!(flat.joined, base.joined, "{what}: other folds and seams");
            let k = size / 300.0;
            let worst = flat
                .face_2d
                .iter()
                .flatten()
                .zip(base.face_2d.iter().flatten())
                .map(|(p, q)| p.distance(*q * k) / size)
                .fold(0.0, f64::max);
            assert!(
                worst < 1e-12,
                "{what}: layout off the 300 mm one by {worst:e} of the size"
            );
            // The layout is in the surface's millimetres: its edges as long as in 3D.
            let m = &flat.surface.mesh;
            let mut sum = (0.0, 0.0);
            for (f, face) in m.faces.iter().enumerate() {
                let n = face.verts.len();
                for i in 0..n {
                    let (a, b) = (face.verts[i], face.verts[(i + 1) % n]);
                    sum.0 += m.vertices[a].distance(m.vertices[b]);
                    sum.1 += flat.face_2d[f][i].distance(flat.face_2d[f][(i + 1) % n]);
                }
            }
            assert!(
                (sum.1 / sum.0 - 1.0).abs() < 0.01,
                "{what}: flat edges {sum:?} vs 3D"
            );
        }
    }
}

/// Split to fit, regression: couplingdown in fabric at 300 mm on A4 left part 3a 0.12 mm too
/// wide after the split's rounds (each new partition landed a part just as far over), and the
/// nest then refused it. Every part now fits the sheet in an orientation the nest tries.
#[test]
fn split_couplingdown_in_fabric_fits_every_part_on_a4() {
    let spec = spec_at_300(
        &shared_data("meshes/couplingdown.obj"),
        MaterialKind::Fabric,
    );
    let (_, pieces) = flatcut::pipeline::pieces(&spec, true).unwrap();
    let s = &spec.sheet;
    let room = flatcut::pattern::split::Room::inside(s.width, s.height, s.margin);
    for p in &pieces {
        let over = flatcut::pattern::split::piece_overflow(p, &room);
        assert!(over <= 0.0, "piece {} is {over} mm over the sheet", p.name);
    }
    assert!(pieces.len() > 20, "{} pieces", pieces.len());
}

/// Issue 20, item 3: small pieces are merged in rounds until none merges, each trying up to
/// eight neighbours. Couplingdown in paper at 300 mm on A4 kept 6 pieces under 1 % of the
/// area (one round of three neighbours left 12, one round of eight 9), and nothing else in
/// [`run`]'s checks gives way. Its strip of 1.2 % too long for A4, which the pattern stage
/// split into two pieces of 0.6 %, is now shared out across with a neighbour
/// (`flatten::charts::merge::share_across`): 1 piece was under 1 % (35 pieces became 33);
/// passed on through one of its six nearest neighbours (`flatten::charts::hinge`'s
/// `pass_on`), none is (32 pieces). Since pieces too large for the sheet are halved and laid
/// again in the flatten stage (`flatten::charts::room`), no part stretches past the tolerance
/// (the pattern stage's part 8a of the piece as it lay had L2 1.00375), with two pieces more
/// (34).
#[test]
fn corpus_small_pieces_of_couplingdown_are_merged_in_rounds() {
    require_shared!();
    let r = run(&shared_data("meshes/couplingdown.obj"), MaterialKind::Paper);
    print_row(
        &shared_data("meshes/couplingdown.obj"),
        MaterialKind::Paper,
        &r,
    );
    assert_eq!(r.small, 0, "pieces under 1 % of the area");
    assert!(r.worst_piece <= 1.003, "worst piece L2 {}", r.worst_piece);
    assert!(r.pieces <= 34, "{} pieces", r.pieces);
}

/// Issue 20, item 3: couplingdown in metal at 300 mm on A4 has a strip of 1.2 % of the area,
/// too long for the sheet, that the pattern stage split into two pieces of 0.6 %. It is now
/// hinged in parts onto its neighbours before (`flatten::charts::hinge`): 7 pieces under 1 %
/// of the area became 5 (40 pieces became 38); shared out with a neighbour where the two
/// overlap (`flatten::charts::merge::share_apart`), 3 are. A piece of two faces filling a
/// hole of its neighbour, which no merge took with the seam that opened the hole, is laid
/// out with it without that seam (`flatten::charts::slit::uncut_merge`): 2 are (37 pieces);
/// tried so with the small-piece merges already (where the merge with the cuts failed
/// within the tolerance), none is (33 pieces). Since a small piece shared out with a
/// neighbour is also halved into equal areas where the bisector's halves are not kept
/// (`rebalance`), the small pieces go other ways (one share-out more, which keeps the count
/// where a graft lowers it): 34 pieces, none small. Pieces too large for the sheet halved and
/// laid again in the flatten stage (`flatten::charts::room`) make two more (36), none small.
#[test]
fn corpus_couplingdown_in_metal_hinges_a_strip_too_long_for_the_sheet() {
    require_shared!();
    let mesh = shared_data("meshes/couplingdown.obj");
    let r = run(&mesh, MaterialKind::Metal);
    print_row(&mesh, MaterialKind::Metal, &r);
    assert!(r.worst_piece <= 1.001, "worst piece L2 {}", r.worst_piece);
    assert_eq!(r.small, 0, "pieces under 1 % of the area");
    assert!(r.pieces <= 36, "{} pieces", r.pieces);
}

/// Issue 20, items 2 and 3: cow in metal (L2 1.001) at 300 mm on A4. Charts still over the
/// tolerance once split three times are laid out exactly, and small pieces that cannot be
/// laid out again with a neighbour are grafted onto their neighbours as they lie
/// (`flatten::charts::exact`), else hinged onto one by an edge (`flatten::charts::hinge`),
/// whole or in parts. Before the first two, 11 pieces were over the tolerance (the worst at
/// L2 1.347) and 37 were under 1 % of the area; then none was over and 16 were small (42
/// pieces); hinged whole, 11 were small (37 pieces); in halves and quarters too, 8 (34
/// pieces); merged with a slit where no hinge fits (`flatten::charts::slit`), 7 (33
/// pieces); shared out where a small piece and a neighbour overlap, 6 (33 pieces); merged
/// with darts where the two as one stretch past the tolerance, 5 (32 pieces); passed on
/// through a neighbour to a third piece (`flatten::charts::hinge`'s `pass_on`), 4 are (31
/// pieces); passed through the neighbour that closes round them along a corridor to a third
/// piece (`flatten::charts::merge`'s `pass_through`), 2 are (29 pieces). Those two (0.74 %
/// and 0.58 %) fit beside no neighbour within L2 1.001 in any way; segmented again when small
/// pieces are left (`pipeline`'s `flatten_segmented`: 16 charts, 1 small piece, then 10),
/// none is (27 pieces). With the L-BFGS stretch minimiser (`flatten::param::lbfgs`) and
/// gussets only within their reach (`flatten::charts::darts`), the first segmentation
/// leaves one small piece and 16 charts none: 28 pieces.
#[test]
fn corpus_cow_in_metal_is_within_its_tolerance_and_grafts_small_pieces() {
    require_shared!();
    let mesh = shared_data("meshes/cow.obj");
    let r = run(&mesh, MaterialKind::Metal);
    print_row(&mesh, MaterialKind::Metal, &r);
    assert!(r.worst_piece <= 1.001, "worst piece L2 {}", r.worst_piece);
    assert_eq!(r.small, 0, "pieces under 1 % of the area");
    assert!(r.pieces <= 28, "{} pieces", r.pieces);
    assert!(
        r.segmentations > 1,
        "segmented once: no small piece to retry for"
    );
}

/// Issue 20, items 3 and 5: a mesh segmented again for its small pieces
/// (`surface::dcharts::resegment`) is segmented at the size it was first segmented at, so its
/// charts do not depend on the size either: homer at 30 mm and at 300 mm gets the same 16
/// charts, and segmented again into the default count, the charts it had.
#[test]
fn corpus_a_mesh_segmented_again_gets_the_same_charts_at_any_size() {
    require_shared!();
    let mesh = shared_data("meshes/homer.obj");
    let at = |size: f64| {
        let mut spec = Spec::from_mesh(&mesh);
        spec.size = Some(size);
        let seg = spec.surfaces[0].segment.clone();
        (
            flatcut::pipeline::sized_surfaces(&spec).unwrap().remove(0),
            seg,
        )
    };
    let (small, seg) = at(30.0);
    let (large, _) = at(300.0);
    let first = large.charts.clone().expect("homer is segmented");
    let again = |s: &flatcut::surface::Surface, n: usize| {
        let mut s = s.clone();
        assert!(flatcut::surface::dcharts::resegment(&mut s, &seg, n).unwrap());
        (s.charts.unwrap(), s.cuts)
    };
    let default = flatcut::surface::dcharts::DChartsOptions::default().charts;
    assert_eq!(again(&large, default).0, first, "the default count again");
    let (a, b) = (again(&small, 16), again(&large, 16));
    assert_eq!(a, b, "16 charts at 30 mm and at 300 mm");
    assert_ne!(b.0, first, "16 charts are the default's");
}

/// Issue 20, item 3: a small piece whose neighbour closes round it (a gusset at a saddle:
/// the two as one turn past a full turn round a vertex) fits beside that neighbour in no
/// way. Pig in metal kept one (4 faces, 0.17 %, in a notch of its only neighbour), homer in
/// paper one (79 faces), homer in metal three (35 pieces). Passed through the neighbour along
/// a corridor of its faces to a third piece and joined to that (`flatten::charts::merge`'s
/// `pass_through`), pig in metal and homer in paper keep none and homer in metal one (32
/// pieces), which no neighbour takes within L2 1.001; segmented again for it (16 charts,
/// `pipeline`'s `flatten_segmented`), none (27 pieces).
#[test]
fn corpus_small_pieces_closed_round_by_a_neighbour_are_passed_through_it() {
    require_shared!();
    for (name, kind, tolerance, most) in [
        ("pig.obj", MaterialKind::Metal, 1.001, 0),
        ("homer.obj", MaterialKind::Paper, 1.003, 0),
        ("homer.obj", MaterialKind::Metal, 1.001, 0),
    ] {
        let mesh = shared_data("meshes").join(name);
        let r = run(&mesh, kind);
        print_row(&mesh, kind, &r);
        assert!(
            r.worst_piece <= tolerance,
            "{name} {kind:?}: worst piece L2 {}",
            r.worst_piece
        );
        assert!(
            r.small <= most,
            "{name} {kind:?}: {} pieces under 1 % of the area",
            r.small
        );
    }
}

/// Issue 20, item 3: cow in paper at 300 mm on A4 kept one piece under 1 % of the area (50
/// faces, 0.59 %), which no neighbour took in any way; halved anew with one along the
/// bisector, the halves were not kept. Halved into equal areas when the bisector's halves are
/// not kept (`flatten::charts::merge`'s `rebalance`), the two are: none is left, in 21
/// pieces (22 before). With the L-BFGS stretch minimiser (`flatten::param::lbfgs`) and
/// gussets only within their reach (`flatten::charts::darts`): none, in 24 pieces.
#[test]
fn corpus_cow_in_paper_shares_its_last_small_piece_out_in_halves_of_equal_area() {
    require_shared!();
    let mesh = shared_data("meshes/cow.obj");
    let r = run(&mesh, MaterialKind::Paper);
    print_row(&mesh, MaterialKind::Paper, &r);
    assert!(r.worst_piece <= 1.003, "worst piece L2 {}", r.worst_piece);
    assert_eq!(r.small, 0, "pieces under 1 % of the area");
    assert!(r.pieces <= 24, "{} pieces", r.pieces);
}

/// Issue 20, item 3: elephant at 300 mm on A4 kept one piece under 1 % of the area in paper
/// (5 faces) and one in metal (0.28 %), each joined to no neighbour in any way. Passed on
/// through a neighbour (`flatten::charts::hinge`'s `pass_on`: the two split where they
/// overlap, the small part joined to a piece next to it), none is left in either.
#[test]
fn corpus_elephant_passes_its_small_pieces_on_through_a_neighbour() {
    require_shared!();
    let mesh = shared_data("meshes/elephant.obj");
    for (kind, tolerance) in [(MaterialKind::Paper, 1.003), (MaterialKind::Metal, 1.001)] {
        let r = run(&mesh, kind);
        print_row(&mesh, kind, &r);
        assert!(
            r.worst_piece <= tolerance,
            "worst piece L2 {}",
            r.worst_piece
        );
        assert_eq!(r.small, 0, "{kind:?}: pieces under 1 % of the area");
    }
}

/// Issue 20: a piece split to fit the sheet keeps its layout, and a part of it can stretch
/// more than the whole. The split now prefers, among partitions with the fewest parts, the one
/// with fewest parts over the material's tolerance, and a part still over it is named in a
/// warning of its surface (report.json) saying why. Knot1 in metal at 300 mm on A4 had three
/// parts over L2 1.001 (1a, 8b, 11a); now one, with its warning. And its small pieces are
/// merged, shared out or grafted: none is left under 1 % of the area.
#[test]
fn corpus_knot_in_metal_split_parts_stay_within_the_tolerance_or_say_why() {
    require_shared!();
    let spec = spec_at_300(&shared_data("meshes/knot1.obj"), MaterialKind::Metal);
    let (flats, pieces) = flatcut::pipeline::pieces(&spec, true).unwrap();
    let flat = &flats[0];
    let mut over = Vec::new();
    for p in &pieces {
        let uv: Vec<_> = p.faces.iter().map(|&f| flat.face_2d[f].clone()).collect();
        let s = flatcut::flatten::distortion::stretch(&flat.surface.mesh, &p.faces, &uv);
        if s.l2 > 1.001 {
            over.push((p.name.clone(), s.l2));
        }
    }
    let small = measure(&flats, &pieces).small;
    println!(
        "knot1 metal: {} pieces, {small} under 1 % of the area, over L2 1.001: {over:?}",
        pieces.len()
    );
    assert!(over.len() <= 1, "{over:?}");
    // A small piece that fits no neighbour laid out as one is shared out with one
    // (`merge::rebalance`: 277 + 16 faces become 96 + 197): 3 small pieces before, then 2;
    // the last is shared out where it and a neighbour overlap (`merge::share_apart`).
    assert!(small == 0, "{small} pieces under 1 % of the area");
    for (name, _) in &over {
        assert!(
            flat.surface
                .warnings
                .iter()
                .any(|w| w.contains(&format!("part {name} stretches by"))),
            "{name}: {:?}",
            flat.surface.warnings
        );
    }
}

/// Issue 20, item 2: homer in fabric at 300 mm. Laid with lower stretch, its largest chart's
/// seam matching pulled a border edge across its neighbours (a flip), was refused, and the
/// chart went out unmatched: seams 30 % apart between its parts and their neighbours. Now
/// matching goes partway where it would flip and tries again from there, and a chart still
/// off its 3D border lengths at the end is matched again or halved: every seam is within
/// fabric's 1 % (the corpus check), measured 0.045 %.
#[test]
fn corpus_homer_in_fabric_matches_every_seam_of_its_largest_charts() {
    require_shared!();
    let mesh = shared_data("meshes/homer.obj");
    let r = run(&mesh, MaterialKind::Fabric);
    print_row(&mesh, MaterialKind::Fabric, &r);
    assert!(
        r.worst_seam < 0.002,
        "worst seam {:.3} %",
        100.0 * r.worst_seam
    );
}

/// Issue 20, few pieces: pieces of any size are joined where they lie flat as one
/// (`merge_laid`), but not into a piece larger than the sheet while pieces are split to fit
/// it. The torus knot in fabric on A4 went from 7 pieces to 2 that way, each then split into
/// parts: 33 parts, 6 of them under 1 % of the area, against 21 without the join.
#[test]
fn corpus_knot_in_fabric_is_not_joined_past_the_sheet() {
    require_shared!();
    let spec = spec_at_300(&shared_data("meshes/knot1.obj"), MaterialKind::Fabric);
    let (flats, pieces) = flatcut::pipeline::pieces(&spec, true).unwrap();
    let r = measure(&flats, &pieces);
    println!(
        "knot1 fabric on A4: {} parts, {} under 1 % of the area",
        r.pieces, r.small
    );
    assert!(r.pieces <= 24, "{} parts", r.pieces);
    assert!(r.small <= 2, "{} parts under 1 % of the area", r.small);
}
