//! `flatcut check OBJ`: faces, edges, boundary loops, non-manifold edges and the largest angle
//! defect (0 at every interior vertex of a developable mesh), read without repairs so that it
//! shows the mesh as it is.

use crate::Error;
use clap::Args;
use std::path::PathBuf;

#[derive(Debug, Args)]
pub struct CheckArgs {
    /// The mesh to check (Wavefront OBJ).
    pub obj: PathBuf,
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
