//! Tests of the spec reader: the whole format on small texts (`patterns/lamp.toml` as the
//! file name), with the line, key and message of each mistake.

use super::*;

const FULL: &str = r#"name = "cube"            # optional; default: the spec file's stem
device = "hpgl-pens"     # optional device profile name

[[surface]]              # one or more
kind = "mesh"
path = "cube.obj"
scale = 1.0
units = "mm"
name = "box"

[material]
kind = "paper"
thickness = 0.25

[sheet]
width = 210
height = 297
roll = false
margin = 5
spacing = 3

[pattern]
fold_threshold = 1.0
"#;

const MINIMAL: &str = "[[surface]]\nkind = \"mesh\"\npath = \"lamp.obj\"\n";

fn p(text: &str) -> Result<Spec, SpecError> {
    parse(text, Path::new("patterns/lamp.toml"))
}

/// Parses `text`, which must fail; returns (line, key or "", message, Display).
fn fail(text: &str) -> (SpecError, String) {
    match p(text) {
        Ok(spec) => panic!("expected an error, got {spec:?}"),
        Err(e) => {
            let shown = e.to_string();
            (e, shown)
        }
    }
}

fn invalid(text: &str) -> (usize, String, String) {
    match fail(text) {
        (
            SpecError::Invalid {
                line, key, message, ..
            },
            shown,
        ) => {
            assert_single_line(&shown);
            assert!(shown.starts_with("patterns/lamp.toml:"), "{shown}");
            (line, key, message)
        }
        (other, _) => panic!("expected Invalid, got {other:?}"),
    }
}

fn syntax(text: &str) -> (usize, String) {
    match fail(text) {
        (SpecError::Syntax { line, message, .. }, shown) => {
            assert_single_line(&shown);
            assert!(shown.starts_with("patterns/lamp.toml:"), "{shown}");
            (line, message)
        }
        (other, _) => panic!("expected Syntax, got {other:?}"),
    }
}

fn assert_single_line(s: &str) {
    assert!(!s.contains('\n') && !s.contains('\r'), "multi-line: {s:?}");
}

#[test]
fn full_example_parses_exactly() {
    let spec = p(FULL).unwrap();
    assert_eq!(
        spec,
        Spec {
            name: "cube".into(),
            path: PathBuf::from("patterns/lamp.toml"),
            device: Some("hpgl-pens".into()),
            size: None,
            sheet_given: true,
            surfaces: vec![SurfaceSpec {
                kind: SurfaceKind::Mesh,
                path: PathBuf::from("patterns/cube.obj"),
                scale: 1.0,
                units: Units::Mm,
                size: None,
                name: "box".into(),
                line: 6,
                strip: None,
                bent: None,
                boundary: None,
                spline: None,
                segment: SegmentSpec::default(),
            }],
            material: Material {
                kind: MaterialKind::Paper,
                thickness: 0.25,
                thickness_given: true,
                ..Material::default()
            },
            sheet: SheetSpec {
                width: 210.0,
                height: Some(297.0),
                margin: 5.0,
                spacing: 3.0
            },
            pattern: PatternSpec::default(),
        }
    );
    assert!(!spec.sheet.is_roll());
}

#[test]
fn full_example_with_other_values() {
    let text = r#"
[[surface]]
kind = "MESH"
path = "a/b.obj"
scale = 2.5
units = "in"

[[surface]]
kind = "mesh"
path = "/abs/c.obj"
units = "cm"

[material]
kind = "metal"

[sheet]
width = 600.5
roll = true
margin = 0
spacing = 1.5

[pattern]
fold_threshold = 179.5
"#;
    let spec = p(text).unwrap();
    assert_eq!(spec.name, "lamp");
    assert_eq!(spec.device, None);
    assert_eq!(spec.surfaces.len(), 2);
    let a = &spec.surfaces[0];
    assert_eq!(a.path, PathBuf::from("patterns/a/b.obj"));
    assert_eq!(
        (a.scale, a.units, a.name.as_str(), a.line),
        (2.5, Units::In, "b", 4)
    );
    let c = &spec.surfaces[1];
    assert_eq!(c.path, PathBuf::from("/abs/c.obj"));
    assert_eq!(
        (c.scale, c.units, c.name.as_str(), c.line),
        (1.0, Units::Cm, "c", 10)
    );
    assert_eq!(
        spec.material,
        Material {
            kind: MaterialKind::Metal,
            thickness: 1.0,
            ..Material::default()
        }
    );
    assert_eq!(
        spec.sheet,
        SheetSpec {
            width: 600.5,
            height: None,
            margin: 0.0,
            spacing: 1.5
        }
    );
    assert!(spec.sheet.is_roll());
    assert_eq!(spec.pattern.fold_threshold_deg, 179.5);
}

#[test]
fn minimal_spec_gets_all_defaults() {
    let spec = p(MINIMAL).unwrap();
    assert_eq!(spec.name, "lamp");
    assert_eq!(spec.path, PathBuf::from("patterns/lamp.toml"));
    assert_eq!(spec.device, None);
    assert_eq!(
        spec.surfaces,
        vec![SurfaceSpec {
            kind: SurfaceKind::Mesh,
            path: PathBuf::from("patterns/lamp.obj"),
            scale: 1.0,
            units: Units::Mm,
            size: None,
            name: "lamp".into(),
            line: 3,
            strip: None,
            bent: None,
            boundary: None,
            spline: None,
            segment: SegmentSpec::default(),
        }]
    );
    assert_eq!(
        spec.material,
        Material {
            kind: MaterialKind::Paper,
            thickness: 0.25,
            ..Material::default()
        }
    );
    assert_eq!(
        spec.sheet,
        SheetSpec {
            width: 210.0,
            height: Some(297.0),
            margin: 5.0,
            spacing: 3.0
        }
    );
    assert_eq!(spec.pattern.fold_threshold_deg, 1.0);
    assert_eq!(spec.material, Material::default());
    assert_eq!(spec.sheet, SheetSpec::default());
    assert_eq!(spec.pattern, PatternSpec::default());
}

#[test]
fn material_thickness_defaults_by_kind() {
    for (kind, t) in [("paper", 0.25), ("fabric", 0.5), ("metal", 1.0)] {
        let text = format!("{MINIMAL}[material]\nkind = \"{kind}\"\n");
        let spec = p(&text).unwrap();
        assert_eq!(spec.material.thickness, t, "{kind}");
        assert_eq!(spec.material.kind.to_string(), kind);
        assert_eq!(spec.material.kind.default_thickness(), t);
    }
    let spec = p(&format!(
        "{MINIMAL}[material]\nkind = \"fabric\"\nthickness = 2\n"
    ))
    .unwrap();
    assert_eq!(spec.material.thickness, 2.0);
}

#[test]
fn material_bend_keys_default_to_k_04_and_the_thickness_and_are_checked() {
    let spec = p(&format!(
        "{MINIMAL}[material]\nkind = \"metal\"\nthickness = 2\n"
    ))
    .unwrap();
    let bend = spec.material.sheet_bend();
    assert_eq!(
        (bend.thickness, bend.k_factor, bend.inside_radius),
        (2.0, 0.4, 2.0)
    );
    // Metal mesh surfaces are developed with it; paper ones are not.
    let o = spec.pattern_options();
    assert_eq!(o.develop, vec![("lamp".to_string(), bend)]);
    let paper = p(MINIMAL).unwrap().pattern_options();
    assert!(paper.develop.is_empty());

    let spec = p(&format!(
        "{MINIMAL}[material]\nkind = \"metal\"\nthickness = 1.5\nk_factor = 0.33\nbend_radius = 0\n"
    ))
    .unwrap();
    let bend = spec.material.sheet_bend();
    assert_eq!(
        (bend.thickness, bend.k_factor, bend.inside_radius),
        (1.5, 0.33, 0.0)
    );

    let (line, key, message) = invalid(&format!("{MINIMAL}[material]\nk_factor = 1.2\n"));
    assert_eq!((line, key.as_str()), (5, "material.k_factor"));
    assert_eq!(message, "must be a number from 0 to 1, got 1.2");
    let (line, key, message) = invalid(&format!("{MINIMAL}[material]\n\nbend_radius = -2\n"));
    assert_eq!((line, key.as_str()), (6, "material.bend_radius"));
    assert_eq!(
        message,
        "must be a number of millimetres, zero or more, got -2"
    );
    let (_, key, message) = invalid(&format!("{MINIMAL}[material]\nk_factor = nan\n"));
    assert_eq!(key, "material.k_factor");
    assert!(message.contains("not a finite number"), "{message}");
}

#[test]
fn relative_path_resolved_against_spec_dir() {
    let text = "[[surface]]\nkind = \"mesh\"\npath = \"../meshes/lamp shade.obj\"\n";
    let spec = parse(text, Path::new("/home/u/patterns/lamp.toml")).unwrap();
    assert_eq!(
        spec.surfaces[0].path,
        PathBuf::from("/home/u/patterns/../meshes/lamp shade.obj")
    );
    assert_eq!(spec.surfaces[0].name, "lamp shade");
    // A spec in the current directory leaves the path as written.
    let spec = parse(text, Path::new("lamp.toml")).unwrap();
    assert_eq!(
        spec.surfaces[0].path,
        PathBuf::from("../meshes/lamp shade.obj")
    );
}

#[test]
fn units_conversions() {
    assert_eq!(Units::Mm.mm(), 1.0);
    assert_eq!(Units::Cm.mm(), 10.0);
    assert_eq!(Units::M.mm(), 1000.0);
    assert_eq!(Units::In.mm(), 25.4);
    for (name, u, mm) in [
        ("mm", Units::Mm, 1.0),
        ("cm", Units::Cm, 10.0),
        ("m", Units::M, 1000.0),
        ("in", Units::In, 25.4),
    ] {
        let spec = p(&format!("{MINIMAL}units = \"{name}\"\n")).unwrap();
        assert_eq!(spec.surfaces[0].units, u);
        assert_eq!(spec.surfaces[0].units.mm(), mm);
        assert_eq!(u.to_string(), name);
        assert_eq!(name.parse::<Units>(), Ok(u));
    }
    let (line, key, message) = invalid(&format!("{MINIMAL}units = \"ft\"\n"));
    assert_eq!((line, key.as_str()), (4, "surface[1].units"));
    assert_eq!(message, "must be one of mm, cm, m, in, got \"ft\"");
}

#[test]
fn integer_and_float_numbers() {
    let ints = p(&format!(
        "{MINIMAL}scale = 2\n[sheet]\nwidth = 300\nheight = 400\nmargin = 0\nspacing = 4\n\
         [material]\nthickness = 1\n[pattern]\nfold_threshold = 5\n"
    ))
    .unwrap();
    let floats = p(&format!(
        "{MINIMAL}scale = 2.0\n[sheet]\nwidth = 300.0\nheight = 4e2\nmargin = 0.0\n\
         spacing = 4.0\n[material]\nthickness = 1.0\n[pattern]\nfold_threshold = 5.0\n"
    ))
    .unwrap();
    assert_eq!(ints, floats);
    assert_eq!(ints.surfaces[0].scale, 2.0);
    assert_eq!(
        ints.sheet,
        SheetSpec {
            width: 300.0,
            height: Some(400.0),
            margin: 0.0,
            spacing: 4.0
        }
    );
    assert_eq!(ints.material.thickness, 1.0);
    assert_eq!(ints.pattern.fold_threshold_deg, 5.0);
}

#[test]
fn unknown_top_level_key() {
    let text = format!("name = \"x\"\n\ncolour = \"red\"\n{MINIMAL}");
    let (line, message) = syntax(&text);
    assert_eq!(line, 3);
    assert!(
        message.starts_with("unknown field `colour`, expected one of"),
        "{message}"
    );
    assert!(message.contains("`surface`"), "{message}");
    let shown = p(&text).unwrap_err().to_string();
    assert!(
        shown.starts_with("patterns/lamp.toml:3: unknown field `colour`"),
        "{shown}"
    );
}

#[test]
fn unknown_key_in_sheet() {
    let (line, message) = syntax(&format!("{MINIMAL}[sheet]\nwidth = 200\nwidht = 300\n"));
    assert_eq!(line, 6);
    assert!(message.starts_with("unknown field `widht`"), "{message}");
    assert!(
        message.contains("`width`") && message.contains("`roll`"),
        "{message}"
    );
}

#[test]
fn unknown_key_in_surface() {
    let text = format!("{MINIMAL}\n[[surface]]\nkind = \"mesh\"\npath = \"b.obj\"\nscal = 2\n");
    let (line, message) = syntax(&text);
    assert_eq!(line, 8);
    assert!(message.starts_with("unknown field `scal`"), "{message}");
    assert!(message.contains("`scale`"), "{message}");
}

#[test]
fn negative_width_is_invalid() {
    let text = format!("{MINIMAL}[sheet]\nheight = 100\nwidth = -3\n");
    let (line, key, message) = invalid(&text);
    assert_eq!((line, key.as_str()), (6, "sheet.width"));
    assert_eq!(message, "must be a positive number of millimetres, got -3");
    assert_eq!(
        p(&text).unwrap_err().to_string(),
        "patterns/lamp.toml:6: `sheet.width`: must be a positive number of millimetres, got -3"
    );
}

#[test]
fn wrong_types_name_the_key() {
    let (line, key, message) = invalid(&format!("{MINIMAL}[sheet]\nwidth = \"wide\"\n"));
    assert_eq!((line, key.as_str()), (5, "sheet.width"));
    assert_eq!(
        message,
        "must be a positive number of millimetres, got \"wide\""
    );

    let (line, key, message) = invalid(&format!("{MINIMAL}[sheet]\nroll = \"yes\"\nheight = 5\n"));
    assert_eq!((line, key.as_str()), (5, "sheet.roll"));
    assert_eq!(message, "must be true or false, got \"yes\"");

    let (line, key, message) = invalid("surface = \"cube.obj\"\n");
    assert_eq!((line, key.as_str()), (1, "surface"));
    assert!(message.ends_with("got \"cube.obj\""), "{message}");

    let (line, key, message) = invalid(&format!("sheet = 5\n{MINIMAL}"));
    assert_eq!((line, key.as_str()), (1, "sheet"));
    assert_eq!(message, "must be a table ([sheet]), got 5");

    let (line, key, message) = invalid(&format!("{MINIMAL}scale = [1, 2]\n"));
    assert_eq!((line, key.as_str()), (4, "surface[1].scale"));
    assert_eq!(message, "must be a positive number, got an array");

    let (line, key, message) = invalid(&format!("name = 1979-05-27\n{MINIMAL}"));
    assert_eq!((line, key.as_str()), (1, "name"));
    assert_eq!(message, "must be a non-empty string, got a date-time");

    let (line, key, _) = invalid(&format!("name = \"\"\n{MINIMAL}"));
    assert_eq!((line, key.as_str()), (1, "name"));
}

#[test]
fn roll_with_height_is_invalid() {
    let (line, key, message) = invalid(&format!("{MINIMAL}[sheet]\nroll = true\nheight = 500\n"));
    assert_eq!((line, key.as_str()), (6, "sheet.height"));
    assert!(message.contains("roll = true"), "{message}");
}

#[test]
fn roll_gives_no_height() {
    let spec = p(&format!("{MINIMAL}[sheet]\nwidth = 610\nroll = true\n")).unwrap();
    assert_eq!(spec.sheet.height, None);
    assert_eq!(spec.sheet.width, 610.0);
    assert!(spec.sheet.is_roll());
    let spec = p(&format!("{MINIMAL}[sheet]\nroll = false\n")).unwrap();
    assert_eq!(spec.sheet.height, Some(297.0));
}

#[test]
fn margin_must_leave_room() {
    let (line, key, message) = invalid(&format!("{MINIMAL}[sheet]\nwidth = 100\nmargin = 50\n"));
    assert_eq!((line, key.as_str()), (6, "sheet.margin"));
    assert_eq!(
        message,
        "must be less than half the sheet width (100 mm), got 50"
    );

    let (line, key, message) = invalid(&format!("{MINIMAL}[sheet]\nheight = 8\n"));
    assert_eq!((line, key.as_str()), (5, "sheet.margin"));
    assert_eq!(
        message,
        "must be less than half the sheet height (8 mm), got 5 (the default)"
    );

    // A roll has no height to check against.
    let spec = p(&format!(
        "{MINIMAL}[sheet]\nwidth = 100\nmargin = 49.5\nroll = true\n"
    ))
    .unwrap();
    assert_eq!(spec.sheet.margin, 49.5);
}

#[test]
fn other_range_checks() {
    let (line, key, message) = invalid(&format!("{MINIMAL}[pattern]\nfold_threshold = 180\n"));
    assert_eq!((line, key.as_str()), (5, "pattern.fold_threshold"));
    assert_eq!(
        message,
        "must be a number of degrees, at least 0 and less than 180, got 180"
    );

    let (line, key, _) = invalid(&format!("{MINIMAL}[sheet]\nspacing = -0.5\n"));
    assert_eq!((line, key.as_str()), (5, "sheet.spacing"));

    let (line, key, message) = invalid(&format!("{MINIMAL}[material]\nthickness = 0\n"));
    assert_eq!((line, key.as_str()), (5, "material.thickness"));
    assert_eq!(message, "must be a positive number of millimetres, got 0");

    let (line, key, message) = invalid(&format!("{MINIMAL}[sheet]\nwidth = inf\n"));
    assert_eq!((line, key.as_str()), (5, "sheet.width"));
    assert_eq!(
        message,
        "must be a positive number of millimetres, got inf (not a finite number)"
    );
}

#[test]
fn bad_material_kind_lists_allowed() {
    let (line, key, message) = invalid(&format!("{MINIMAL}[material]\nkind = \"wood\"\n"));
    assert_eq!((line, key.as_str()), (5, "material.kind"));
    assert_eq!(message, "must be one of paper, fabric, metal, got \"wood\"");

    assert_eq!("Fabric".parse::<MaterialKind>(), Ok(MaterialKind::Fabric));
    assert_eq!(
        "wood".parse::<MaterialKind>(),
        Err("expected one of paper, fabric, metal, got \"wood\"".to_string())
    );
    assert_eq!(MaterialKind::Metal.to_string(), "metal");
}

#[test]
fn bad_surface_kind_lists_allowed() {
    let (line, key, message) = invalid("[[surface]]\nkind = \"nurbs\"\npath = \"a.obj\"\n");
    assert_eq!((line, key.as_str()), (2, "surface[1].kind"));
    assert_eq!(
        message,
        "must be one of mesh, strip, bent-sheet, boundary, spline, got \"nurbs\""
    );
}

#[test]
fn missing_surface_keys() {
    let (line, key, message) = invalid(&format!("{MINIMAL}\n[[surface]]\nkind = \"mesh\"\n"));
    assert_eq!((line, key.as_str()), (5, "surface[2].path"));
    assert!(message.starts_with("missing"), "{message}");

    let (line, key, message) = invalid("\n[[surface]]\npath = \"a.obj\"\n");
    assert_eq!((line, key.as_str()), (2, "surface[1].kind"));
    assert!(message.contains("mesh"), "{message}");
}

#[test]
fn no_surfaces_is_an_error() {
    let (line, key, message) = invalid("name = \"x\"\n[sheet]\nwidth = 200\n");
    assert_eq!((line, key.as_str()), (1, "surface"));
    assert!(message.contains("[[surface]]"), "{message}");

    let (line, key, message) = invalid("name = \"x\"\nsurface = []\n");
    assert_eq!((line, key.as_str()), (2, "surface"));
    assert!(message.ends_with("got an empty array"), "{message}");
}

#[test]
fn malformed_toml_is_syntax_error() {
    let (line, message) = syntax(&format!("{MINIMAL}[sheet\nwidth = 1\n"));
    assert_eq!(line, 4);
    assert!(!message.is_empty());

    let (line, message) = syntax(&format!("{MINIMAL}scale = \n"));
    assert_eq!(line, 4);
    assert!(!message.is_empty());

    let (line, message) = syntax(&format!(
        "name = \"a\"\n{MINIMAL}name = \"b\"\nname = \"c\"\n"
    ));
    assert_eq!(line, 6);
    assert_eq!(message, "duplicate key `name`");
}

#[test]
fn nan_is_invalid() {
    let (line, key, message) = invalid(&format!("{MINIMAL}scale = nan\n"));
    assert_eq!((line, key.as_str()), (4, "surface[1].scale"));
    assert_eq!(
        message,
        "must be a positive number, got nan (not a finite number)"
    );
}

#[test]
fn missing_file_is_io() {
    let path = Path::new("/nonexistent/flatcut/spec-test/lamp.toml");
    match load(path) {
        Err(e @ SpecError::Io { .. }) => {
            let shown = e.to_string();
            assert!(
                shown.starts_with("/nonexistent/flatcut/spec-test/lamp.toml: cannot read spec: "),
                "{shown}"
            );
            assert_single_line(&shown);
        }
        other => panic!("expected Io, got {other:?}"),
    }
}

#[test]
fn load_reads_toml_file() {
    let dir = std::env::temp_dir().join(format!("flatcut-spec-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("job.spec");
    std::fs::write(&file, MINIMAL).unwrap();
    let spec = load(&file);
    let _ = std::fs::remove_dir_all(&dir);
    let spec = spec.unwrap();
    assert_eq!(spec.name, "job");
    assert_eq!(spec.surfaces[0].path, dir.join("lamp.obj"));
}

#[test]
fn obj_path_gives_mesh_defaults() {
    for name in ["models/Cube.obj", "models/Cube.OBJ"] {
        let path = Path::new(name);
        let spec = load(path).unwrap();
        assert_eq!(spec, Spec::from_mesh(path));
        assert_eq!(spec.name, "Cube");
        assert_eq!(spec.path, PathBuf::from(name));
        assert_eq!(spec.device, None);
        assert_eq!(
            spec.surfaces,
            vec![SurfaceSpec {
                kind: SurfaceKind::Mesh,
                path: PathBuf::from(name),
                scale: 1.0,
                units: Units::Mm,
                size: None,
                name: "Cube".into(),
                line: 0,
                strip: None,
                bent: None,
                boundary: None,
                spline: None,
                segment: SegmentSpec::default(),
            }]
        );
        assert_eq!(
            spec.material,
            Material {
                kind: MaterialKind::Paper,
                thickness: 0.25,
                ..Material::default()
            }
        );
        assert_eq!(
            spec.sheet,
            SheetSpec {
                width: 210.0,
                height: Some(297.0),
                margin: 5.0,
                spacing: 3.0
            }
        );
        assert_eq!(spec.pattern.fold_threshold_deg, 1.0);
    }
}

#[test]
fn error_display_is_one_line_with_path() {
    let cases = [
        format!("{MINIMAL}colour = 1\n"),
        format!("{MINIMAL}[sheet]\nwidth = -1\n"),
        "[[surface]]\nkind = \"mesh\"\npath = \"a\nb\"\n".to_string(),
        "x = [\n1,\n".to_string(),
        "a = \"\"\"\nmulti\nline\n".to_string(),
        String::new(),
    ];
    for text in cases {
        let shown = p(&text).unwrap_err().to_string();
        assert!(shown.starts_with("patterns/lamp.toml:"), "{shown}");
        assert_single_line(&shown);
    }
}

#[test]
fn boundary_spec_parses_loops_darts_rulings_and_settings() {
    let spec = p(r#"
[[surface]]
kind = "boundary"
name = "panel"
loop = [[0, 0, 0], [100, 0, 0], [100, 80, 10], [50, 100, 5], [0, 80, 10], [0, 0, 0]]
darts = [{ at = 1, points = [[20, 30, 2]], width = 4 }]
rulings = [[2, 5]]
max_dihedral = 45
min_chart_area = 3
max_iterations = 200
good_interior = 2
good_fairness = 0.5
"#)
    .unwrap();
    let s = &spec.surfaces[0];
    assert_eq!(s.kind, SurfaceKind::Boundary);
    assert_eq!(s.name, "panel");
    assert_eq!(s.line, 5);
    let b = s.boundary.as_ref().unwrap();
    assert_eq!(b.input.loops.len(), 1);
    assert_eq!(
        b.input.loops[0].len(),
        5,
        "the repeated closing point is dropped"
    );
    assert_eq!(b.input.darts[0].at, 0);
    assert_eq!(b.input.darts[0].width, Some(4.0));
    assert_eq!(b.input.rulings, vec![[(0, 1), (0, 4)]]);
    assert_eq!(b.options.max_dihedral_deg, 45.0);
    assert!((b.options.min_chart_area - 0.03).abs() < 1e-15);
    assert_eq!(b.options.max_iterations, 200);
    assert_eq!(b.options.good_interior, 2);
    assert_eq!(b.options.good_fairness, 0.5);
    // A closed curve table is sampled; two loops.
    let spec = p(r#"
[[surface]]
kind = "boundary"
loops = [{ kind = "ellipse", center = [0, 0, 0], rx = 100, ry = 60 }, [[-10, -10, 0], [10, -10, 0], [0, 10, 0]]]
darts = [{ loop = 2, at = 3, points = [[0, 0, 0]] }]
rulings = [[[1, 1], [2, 1]]]
"#)
    .unwrap();
    let b = spec.surfaces[0].boundary.as_ref().unwrap();
    assert_eq!(b.input.loops.len(), 2);
    assert_eq!((b.input.darts[0].looop, b.input.darts[0].at), (1, 2));
    assert_eq!(b.input.rulings, vec![[(0, 0), (1, 0)]]);
    assert!(b.input.loops[0].len() > 8);
}

#[test]
fn size_top_level_and_per_surface() {
    let s = p(&format!("size = 200\n{MINIMAL}size = 150\n")).unwrap();
    assert_eq!(s.size, Some(200.0));
    assert_eq!(s.surfaces[0].size, Some(150.0));
    assert!(!s.sheet_given);
    assert!(
        p(&format!("{MINIMAL}[sheet]\nwidth = 300\n"))
            .unwrap()
            .sheet_given
    );
    let (line, key, msg) = invalid(&format!("size = -1\n{MINIMAL}"));
    assert_eq!((line, key.as_str()), (1, "size"));
    assert!(msg.contains("-1"), "{msg}");
    let (line, key, _) = invalid(&format!("{MINIMAL}size = 0\n"));
    assert_eq!((line, key.as_str()), (4, "surface[1].size"));
}
