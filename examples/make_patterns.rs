//! Writes `patterns/*.obj` from `flatcut::surface::solids` (the example meshes are generated,
//! never hand-edited). Run from the crate root: `cargo run --example make_patterns`.

fn main() -> std::io::Result<()> {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("patterns");
    std::fs::create_dir_all(&dir)?;
    for (name, mesh, what) in flatcut::surface::solids::examples() {
        let text =
            flatcut::surface::solids::to_obj(&mesh, &flatcut::surface::solids::obj_comment(what));
        let path = dir.join(format!("{name}.obj"));
        std::fs::write(&path, text)?;
        println!("wrote {}", path.display());
    }
    Ok(())
}
