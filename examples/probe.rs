use flatcut::*;
use std::path::Path;
fn main() {
    for name in ["fandisk", "cylinder", "mushroom"] {
        let p = format!("../shared/data/meshes/{name}.obj");
        let raw = surface::obj::read(Path::new(&p)).unwrap();
        let (mesh, w) = surface::obj::validate(raw, 100.0).unwrap();
        let t = mesh.topology(); let me: f64 = t.edges.iter().map(|e| mesh.vertices[e.verts[0]].distance(mesh.vertices[e.verts[1]])).sum::<f64>() / t.edges.len() as f64;
        println!("mean edge {me} mm, boundary loops {}", t.boundary_loops(&mesh));
        let s = surface::Surface { name: name.into(), source: p.into(), mesh, warnings: w.clone() };
        let t = std::time::Instant::now();
        let mut best = None;
        for grow in [false, true] { for cw in [0.5, 1.0] { for lw in [0.05, 0.2] {
            let o = flatten::UnfoldOptions { length_weight: lw, convex_weight: cw, concave_weight: 1.0, grow, tolerance: 0.02 };
            let fl = flatten::unfold(s.clone(), &o).unwrap();
            println!("   grow {grow} cw {cw} lw {lw}: {}", fl.islands.len());
            if best.as_ref().map_or(true, |(n, _)| fl.islands.len() < *n) { best = Some((fl.islands.len(), o)); }
        }}}
        let flat = flatten::unfold(s, &best.unwrap().1).unwrap();
        let dt = t.elapsed();
        let ov = flatten::unfold::find_overlap(&flat);
        println!("{name}: {} islands in {:?}, overlap {:?}, warnings {:?}", flat.islands.len(), dt, ov, w);
        let mut sizes: Vec<usize> = flat.islands.iter().map(|i| i.len()).collect(); sizes.sort(); sizes.reverse();
        println!("  sizes {:?}", &sizes);
    }
}
