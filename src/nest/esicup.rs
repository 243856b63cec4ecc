//! ESICUP strip-packing instances in the JSON form used by jagua-rs and sparrow (see
//! `../shared/data/README.md`): `items` (id, demand, `allowed_orientations` in degrees — absent
//! means free rotation —, `shape` as a `simple_polygon` point list, the first point possibly
//! repeated at the end) and `strip_height`. [`solve`] nests one with the strip optimiser of this
//! stage; [`solution_json`] writes the result in sparrow's solution form (`strip_width`,
//! `layout.placed_items[].transformation` = mirror in x if `reflected`, rotate about the origin
//! by `rotation` degrees, translate) and [`svg`] draws it.

use super::problem::{self, Container, Item, Orient, Orients, Problem, Solution};
use glam::DVec2;
use serde::Deserialize;
use serde_json::json;
use std::path::{Path, PathBuf};

/// Most items an instance may have, counting each unit of demand (the largest ESICUP instances
/// have a few hundred): a bound on memory and time that a typo in `demand` cannot lift.
pub const MAX_ITEMS: usize = 10_000;

/// Errors reading or solving an instance; each names the file and, where it applies, the item.
#[derive(Debug, thiserror::Error)]
pub enum EsicupError {
    #[error("{}: cannot read: {source}", path.display())]
    Read {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{}: not an ESICUP instance: {msg}", path.display())]
    Json { path: PathBuf, msg: String },
    #[error("{}: item {item}: {msg}", path.display())]
    Item {
        path: PathBuf,
        item: i64,
        msg: String,
    },
}

#[derive(Debug, Deserialize)]
struct RawInstance {
    name: Option<String>,
    items: Vec<RawItem>,
    strip_height: f64,
}

#[derive(Debug, Deserialize)]
struct RawItem {
    id: i64,
    #[serde(default = "one")]
    demand: usize,
    allowed_orientations: Option<Vec<f64>>,
    shape: RawShape,
}

fn one() -> usize {
    1
}

#[derive(Debug, Deserialize)]
struct RawShape {
    #[serde(rename = "type")]
    kind: String,
    data: Vec<[f64; 2]>,
}

/// A parsed instance: one problem item per unit of demand.
#[derive(Debug, Clone)]
pub struct Instance {
    pub name: String,
    pub height: f64,
    /// Instance item id of each problem item.
    pub ids: Vec<i64>,
    /// Shapes as given (no repeated closing point), per problem item.
    pub shapes: Vec<Vec<DVec2>>,
    pub problem: Problem,
}

impl Instance {
    /// Total item area.
    pub fn area(&self) -> f64 {
        self.problem.items.iter().map(|i| i.area).sum()
    }
}

/// Read and check an instance file.
pub fn load(path: &Path) -> Result<Instance, EsicupError> {
    let text =
        crate::geom::input::read_text(path, crate::geom::input::TEXT_LIMIT).map_err(|source| {
            EsicupError::Read {
                path: path.to_path_buf(),
                source,
            }
        })?;
    parse(&text, path)
}

/// Parse and check an instance.
pub fn parse(text: &str, path: &Path) -> Result<Instance, EsicupError> {
    let raw: RawInstance = serde_json::from_str(text).map_err(|e| EsicupError::Json {
        path: path.to_path_buf(),
        msg: e.to_string(),
    })?;
    let height = raw.strip_height;
    if !(height.is_finite() && height > 0.0) {
        return Err(EsicupError::Json {
            path: path.to_path_buf(),
            msg: format!("strip_height must be a positive number, got {height}"),
        });
    }
    let mut ids = Vec::new();
    let mut shapes = Vec::new();
    let mut items = Vec::new();
    for it in &raw.items {
        let bad = |msg: String| EsicupError::Item {
            path: path.to_path_buf(),
            item: it.id,
            msg,
        };
        if it.shape.kind != "simple_polygon" {
            return Err(bad(format!(
                "shape type `{}` is not supported (simple_polygon only)",
                it.shape.kind
            )));
        }
        let mut pts: Vec<DVec2> = it
            .shape
            .data
            .iter()
            .map(|p| DVec2::new(p[0], p[1]))
            .collect();
        if pts.len() > 1 && pts.first() == pts.last() {
            pts.pop();
        }
        pts.dedup();
        if pts.len() < 3 {
            return Err(bad(format!(
                "its polygon has {} distinct points, at least 3 are needed",
                pts.len()
            )));
        }
        if pts.iter().any(|p| !p.is_finite()) {
            return Err(bad(
                "its polygon has a coordinate that is not a number".into()
            ));
        }
        if crate::geom::polygon::signed_area(&pts).abs() <= 0.0 {
            return Err(bad("its polygon has no area".into()));
        }
        let orients = match &it.allowed_orientations {
            Some(v) if !v.is_empty() => Orients::Set(
                v.iter()
                    .map(|d| Orient {
                        angle_deg: *d,
                        mirror: false,
                    })
                    .collect(),
            ),
            Some(_) => Orients::Set(vec![Orient {
                angle_deg: 0.0,
                mirror: false,
            }]),
            None => Orients::Free { mirror: false },
        };
        let item = Item::new(vec![pts.clone()], orients);
        if item.min_length(height).is_none() && matches!(item.orients, Orients::Set(_)) {
            let h = item
                .shapes
                .iter()
                .map(|s| s.size.y)
                .fold(f64::INFINITY, f64::min);
            return Err(bad(format!(
                "it is {h} high in every allowed orientation, wider than the strip ({height})"
            )));
        }
        if it.demand > MAX_ITEMS - items.len() {
            return Err(bad(format!(
                "its demand of {} makes more than {MAX_ITEMS} items in all; the nest is not \
                 made for more",
                it.demand
            )));
        }
        for _ in 0..it.demand {
            ids.push(it.id);
            shapes.push(pts.clone());
            items.push(item.clone());
        }
    }
    if items.is_empty() {
        return Err(EsicupError::Json {
            path: path.to_path_buf(),
            msg: "no items".into(),
        });
    }
    let problem = Problem {
        items,
        container: Container::Strip { height },
        spacing: 0.0,
    };
    if let Err(u) = problem::check_fit(&problem) {
        return Err(EsicupError::Item {
            path: path.to_path_buf(),
            item: ids[u.item],
            msg: format!("it does not fit in a strip {height} high in any orientation"),
        });
    }
    Ok(Instance {
        name: raw.name.unwrap_or_else(|| {
            path.file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_default()
        }),
        height,
        ids,
        shapes,
        problem,
    })
}

/// Nest an instance.
pub fn solve(inst: &Instance, cfg: &problem::Config) -> Result<Solution, EsicupError> {
    super::solve::solve(&inst.problem, cfg).map_err(|u| EsicupError::Item {
        path: PathBuf::from(&inst.name),
        item: inst.ids.get(u.item).copied().unwrap_or(-1),
        msg: "it does not fit in the strip".into(),
    })
}

/// Density: item area over the strip area used.
pub fn density(inst: &Instance, sol: &Solution) -> f64 {
    inst.area() / (sol.length * inst.height)
}

/// Round to 1e-9 so that the file does not depend on the last bits of a platform's `sin`.
fn r9(v: f64) -> f64 {
    let r = (v * 1e9).round() / 1e9;
    if r == 0.0 {
        0.0
    } else {
        r
    }
}

/// The solution in sparrow's JSON form.
pub fn solution_json(inst: &Instance, sol: &Solution) -> serde_json::Value {
    let items: Vec<serde_json::Value> = sol
        .placements
        .iter()
        .enumerate()
        .map(|(k, p)| {
            json!({
                "item_id": inst.ids[k],
                "transformation": {
                    "rotation": p.orient.angle_deg,
                    "translation": [p.translation.x, p.translation.y],
                    "reflected": p.orient.mirror,
                }
            })
        })
        .collect();
    json!({
        "name": inst.name,
        "strip_width": sol.length,
        "strip_height": inst.height,
        "layout": { "placed_items": items },
        "density": r9(density(inst, sol)),
    })
}

/// Transformed shape of problem item `k`.
pub fn placed_shape(inst: &Instance, sol: &Solution, k: usize) -> Vec<DVec2> {
    let p = sol.placements[k];
    inst.shapes[k]
        .iter()
        .map(|q| p.orient.apply(*q) + p.translation)
        .collect()
}

/// A picture of the layout (y up, as in the instance).
pub fn svg(inst: &Instance, sol: &Solution) -> String {
    let (w, h) = (sol.length, inst.height);
    let scale = 1000.0 / w.max(h);
    let mut s = format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{:.1}\" height=\"{:.1}\" viewBox=\"0 0 {:.1} {:.1}\">\n",
        w * scale + 20.0,
        h * scale + 20.0,
        w * scale + 20.0,
        h * scale + 20.0
    );
    s += &format!(
        "<rect x=\"10\" y=\"10\" width=\"{:.3}\" height=\"{:.3}\" fill=\"#f4f4f4\" stroke=\"#000\" stroke-width=\"1\"/>\n",
        w * scale,
        h * scale
    );
    for k in 0..sol.placements.len() {
        let pts: Vec<String> = placed_shape(inst, sol, k)
            .iter()
            .map(|p| format!("{:.3},{:.3}", 10.0 + p.x * scale, 10.0 + (h - p.y) * scale))
            .collect();
        let hue = (inst.ids[k].rem_euclid(12) * 30) as u32;
        s += &format!(
            "<polygon points=\"{}\" fill=\"hsl({hue},60%,70%)\" stroke=\"#333\" stroke-width=\"0.5\"/>\n",
            pts.join(" ")
        );
    }
    s += &format!(
        "<text x=\"12\" y=\"{:.1}\" font-size=\"14\" font-family=\"sans-serif\">{}: {:.2} %</text>\n</svg>\n",
        h * scale + 8.0,
        inst.name,
        100.0 * density(inst, sol)
    );
    s
}
