//! Which joined edges of a flat become fold (score) or bend lines, and at which angle.
//!
//! By default (a surface that does not say) an edge folds where its dihedral angle exceeds the
//! pattern's threshold. A surface may instead name its bend lines ([`Surface::bends`]): a
//! strip's rulings (issue 4), which on a finely sampled cone each bend by far less than any
//! threshold, or a few rulings at a spacing, each standing for the angle accumulated since the
//! previous one. Then exactly those edges fold, with the angle the surface gives.
//!
//! [`Surface::bends`]: crate::surface::Surface::bends

use crate::flatten::Flat;
use std::collections::HashMap;

/// For each mesh edge of the flat: its signed fold angle in radians (positive for a mountain)
/// if it is a fold line, else `None`. Only joined edges can fold; the caller checks that.
pub fn fold_angles(flat: &Flat, threshold_rad: f64) -> Vec<Option<f64>> {
    match &flat.surface.bends {
        None => flat
            .dihedral
            .iter()
            .map(|&d| (d.abs() > threshold_rad).then_some(d))
            .collect(),
        Some(bends) => {
            let by_verts: HashMap<(usize, usize), f64> = bends
                .iter()
                .map(|b| {
                    let [a, c] = b.verts;
                    ((a.min(c), a.max(c)), b.angle_deg.to_radians())
                })
                .collect();
            flat.topology
                .edges
                .iter()
                .map(|e| by_verts.get(&(e.verts[0], e.verts[1])).copied())
                .collect()
        }
    }
}
