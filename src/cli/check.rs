//! `flatcut check MESH`: size, faces, edges, boundary loops, non-manifold edges and the largest
//! angle defect (0 at every interior vertex of a developable mesh) of an OBJ, STL, PLY or OFF
//! file, read without repairs so that it shows the mesh as it is. The size is the bounding
//! box in the file's units (`--units`, default mm), with the hint `cut` would give when it is
//! implausible.

use crate::Error;
use clap::Args;
use std::path::PathBuf;

#[derive(Debug, Args)]
pub struct CheckArgs {
    /// The mesh to check (Wavefront OBJ, STL, PLY or OFF).
    pub obj: PathBuf,
    /// Units of the file's coordinates: mm (default), cm, m or in.
    #[arg(long, value_name = "mm|cm|m|in", value_parser = super::args::parse_units)]
    pub units: Option<crate::spec::Units>,
    /// Print the figures as JSON.
    #[arg(long)]
    pub json: bool,
}

pub fn run(a: &CheckArgs) -> Result<(), Error> {
    let s = crate::pipeline::check_mesh(&a.obj)?;
    if a.json {
        println!("{}", serde_json::to_string_pretty(&s).unwrap_or_default());
        return Ok(());
    }
    println!("{}", a.obj.display());
    let units = a.units.unwrap_or_default();
    let e = s.extent;
    println!(
        "  size                {} × {} × {} {units} ({} mm across)",
        fmt(e[0]),
        fmt(e[1]),
        fmt(e[2]),
        fmt(e[0].max(e[1]).max(e[2]) * units.mm())
    );
    let mm = glam::DVec3::from_array(e) * units.mm();
    if let Err(hint) = crate::surface::size::check_plausible(&a.obj, mm, units) {
        let text = hint.to_string();
        let prefix = format!("{}: ", a.obj.display());
        println!("  cut: {}", text.strip_prefix(&prefix).unwrap_or(&text));
    }
    println!("  vertices            {}", s.vertices);
    println!("  faces               {}", s.faces);
    println!("  edges               {}", s.edges);
    println!("  boundary loops      {}", s.boundary_loops);
    println!("  non-manifold edges  {}", s.non_manifold_edges);
    println!("  non-planar faces    {}", s.non_planar_faces);
    println!("  largest angle defect {:.4}°", s.max_angle_defect_deg);
    let verdict = if s.non_manifold_edges > 0 {
        "cannot be unfolded until its non-manifold edges are fixed"
    } else if s.max_angle_defect_deg < 1e-6 {
        "developable: unfolds with folds only where faces bend"
    } else {
        "not developable everywhere: it will be cut at vertices with an angle defect"
    };
    println!("  {verdict}");
    Ok(())
}

/// A figure with at most 4 decimals, no trailing zeros.
fn fmt(v: f64) -> String {
    let s = format!("{v:.4}");
    s.trim_end_matches('0').trim_end_matches('.').to_string()
}
