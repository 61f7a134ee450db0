//! The built binary: exit codes, JSON Lines and their rounded figures, bad input (exit 2, one
//! line naming the file, a mistyped key's "did you mean"), the summary's lines, and progress on
//! a terminal only.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_grasp-sim"))
}

fn run_in(dir: &Path, args: &[&str]) -> Output {
    bin()
        .current_dir(dir)
        .args(args)
        .output()
        .expect("the binary runs")
}

/// A temp folder with the thesis hand and a scenario pointing at `mesh.stl` beside it.
struct Env {
    dir: tempfile::TempDir,
}

impl Env {
    fn new() -> Env {
        let dir = tempfile::tempdir().unwrap();
        std::fs::copy(
            crate::root().join("assets/hands/thesis.toml"),
            dir.path().join("hand.toml"),
        )
        .unwrap();
        Env { dir }
    }
    fn path(&self, name: &str) -> PathBuf {
        self.dir.path().join(name)
    }
    fn write(&self, name: &str, bytes: impl AsRef<[u8]>) -> PathBuf {
        let p = self.path(name);
        std::fs::write(&p, bytes).unwrap();
        p
    }
    fn scenario(&self, name: &str, body: &str) -> PathBuf {
        self.write(name, body)
    }
    fn basic_scenario(&self, mesh: &str, extra: &str) -> PathBuf {
        self.scenario(
            "s.toml",
            &format!(
                "name = \"t\"\n[object]\nmesh = \"{mesh}\"\n[hand]\nfile = \"hand.toml\"\n{extra}\n[expect]\noutcome = \"hold\"\n"
            ),
        )
    }
    fn run(&self, args: &[&str]) -> Output {
        run_in(self.dir.path(), args)
    }
}

fn good_mesh() -> Vec<u8> {
    grasp_sim::objects::cylinder(40.0, 124.0).to_binary_stl()
}

/// Asserts exit status 2, nothing on stdout, and exactly one stderr line naming `file` and
/// containing `needle`.
fn assert_bad_input(out: &Output, file: &str, needle: &str) {
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "stderr: {err}");
    assert!(
        out.stdout.is_empty(),
        "stdout not empty: {}",
        String::from_utf8_lossy(&out.stdout)
    );
    let lines: Vec<&str> = err.lines().collect();
    assert_eq!(lines.len(), 1, "expected one line, got: {err}");
    assert!(
        lines[0].contains(file),
        "message does not name {file}: {err}"
    );
    assert!(lines[0].contains(needle), "message lacks {needle:?}: {err}");
    assert!(
        !err.contains("panicked") && !err.contains("RUST_BACKTRACE"),
        "{err}"
    );
}

#[test]
fn bad_meshes_get_one_line_and_exit_2() {
    let good = good_mesh();
    let mut truncated = good.clone();
    truncated.truncate(84 + 50 * 10 + 7);
    let mut trailing = good.clone();
    trailing.extend_from_slice(b"junk");
    let mut nan = good.clone();
    nan[84 + 12..84 + 16].copy_from_slice(&f32::NAN.to_le_bytes());
    let mut inf = good.clone();
    inf[84 + 50 * 3 + 20..84 + 50 * 3 + 24].copy_from_slice(&f32::INFINITY.to_le_bytes());
    let mut huge = good.clone();
    huge[84 + 12..84 + 16].copy_from_slice(&1e30f32.to_le_bytes());
    let mut zero = vec![0u8; 84];
    zero[80..84].copy_from_slice(&0u32.to_le_bytes());
    // Only zero-area triangles: every vertex of each triangle the same point.
    let mut flat = vec![0u8; 84 + 50 * 2];
    flat[80..84].copy_from_slice(&2u32.to_le_bytes());
    let single = grasp_sim::mesh::Mesh {
        vertices: vec![
            nalgebra::Point3::new(0.0, 0.0, 0.0),
            nalgebra::Point3::new(10.0, 0.0, 0.0),
            nalgebra::Point3::new(0.0, 10.0, 0.0),
        ],
        triangles: vec![[0, 1, 2]],
    }
    .to_binary_stl();
    let cases: Vec<(&str, Vec<u8>, &str)> = vec![
        ("empty.stl", vec![], "empty file"),
        ("text.stl", b"hello, this is not a mesh at all".to_vec(), "not an STL"),
        ("truncated.stl", truncated, "truncated"),
        ("trailing.stl", trailing, "trailing bytes"),
        ("nan.stl", nan, "NaN or infinite"),
        ("inf.stl", inf, "NaN or infinite"),
        ("huge.stl", huge, "beyond"),
        ("zero.stl", zero, "no triangles"),
        ("flat.stl", flat, "degenerate"),
        ("single.stl", single, "encloses no volume"),
        (
            "ascii_bad_number.stl",
            b"solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 abc\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid x\n".to_vec(),
            "malformed ASCII",
        ),
        (
            "ascii_missing_field.stl",
            b"solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid x\n".to_vec(),
            "malformed ASCII",
        ),
        (
            "ascii_nan.stl",
            b"solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex nan 0 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid x\n".to_vec(),
            "line 5 (`vertex nan 0 0`)",
        ),
        (
            "ascii_overflow.stl",
            b"solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1e999 0\nendloop\nendfacet\nendsolid x\n".to_vec(),
            "line 6 (`vertex 0 1e999 0`)",
        ),
        (
            "ascii_no_endsolid.stl",
            b"solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\n".to_vec(),
            "malformed ASCII",
        ),
    ];
    for (name, bytes, needle) in cases {
        let env = Env::new();
        env.write(name, &bytes);
        let s = env.basic_scenario(name, "");
        let out = env.run(&[s.to_str().unwrap()]);
        assert_bad_input(&out, name, needle);
    }
}

#[test]
fn missing_mesh_and_directory_get_exit_2() {
    let env = Env::new();
    let s = env.basic_scenario("nowhere.stl", "");
    let out = env.run(&[s.to_str().unwrap()]);
    assert_bad_input(&out, "nowhere.stl", "no such file");
    // The scenario that asked for the mesh is named too, first.
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.starts_with(&format!("grasp-sim: error: {}: ", s.display())),
        "{err}"
    );
    std::fs::create_dir(env.path("adir.stl")).unwrap();
    let s = env.basic_scenario("adir.stl", "");
    assert_bad_input(&env.run(&[s.to_str().unwrap()]), "adir.stl", "directory");
    assert_bad_input(&env.run(&["missing.toml"]), "missing.toml", "no such file");
}

#[test]
fn bad_scenarios_name_the_file_and_key() {
    let cases: Vec<(&str, &str)> = vec![
        ("name = \"t\"\ncolour = \"red\"\n[object]\nmesh = \"m.stl\"\n[hand]\nfile = \"hand.toml\"\n[expect]\noutcome = \"hold\"\n", "colour"),
        ("[object]\nmesh = \"m.stl\"\nfriction = \"high\"\n[hand]\nfile = \"hand.toml\"\n[expect]\noutcome = \"hold\"\n", "friction"),
        ("[object]\nmesh = \"m.stl\"\n[hand]\nfile = \"hand.toml\"\n[planner]\nsf_c = true\n[expect]\noutcome = \"hold\"\n", "sf_c"),
        ("[object]\nmesh = \"m.stl\"\nmass_kg = -1.0\n[hand]\nfile = \"hand.toml\"\n[expect]\noutcome = \"hold\"\n", "mass_kg"),
        ("[object]\nmesh = \"m.stl\"\ndensity_kg_m3 = 0.0\n[hand]\nfile = \"hand.toml\"\n[expect]\noutcome = \"hold\"\n", "density_kg_m3"),
        ("[object]\nmesh = \"m.stl\"\nfriction = 5.0\n[hand]\nfile = \"hand.toml\"\n[expect]\noutcome = \"hold\"\n", "friction"),
        ("[object]\nmesh = \"m.stl\"\n[hand]\nfile = \"hand.toml\"\n[planner]\nheight_step_mm = 3.0\n[expect]\noutcome = \"hold\"\n", "finger gap"),
        ("[object]\nmesh = \"m.stl\"\n[hand]\nfile = \"hand.toml\"\n[planner]\nangular_step_deg = 7.0\n[expect]\noutcome = \"hold\"\n", "divide 360"),
        ("[object]\nmesh = \"m.stl\"\n[hand]\nfile = \"hand.toml\"\n[expect]\noutcome = \"wobble\"\n", "wobble"),
        ("[object]\nmesh = \"m.stl\"\n[hand]\nfile = \"hand.toml\"\n[sim]\nprotocol = \"full\"\nclosing_decides = true\n", "sim.closing_decides"),
        ("[object]\nmesh = \"m.stl\"\n[hand]\nfile = \"nohand.toml\"\n[expect]\noutcome = \"hold\"\n", "nohand.toml"),
        ("[object]\nmesh = \"m.stl\"\n[hand]\nfile = \"hand.toml\"\noverrides = { \"phalanx_9.length_mm\" = 3.0 }\n[expect]\noutcome = \"hold\"\n", "hand.overrides.\"phalanx_9.length_mm\""),
        ("[object\nmesh = \"m.stl\"\n", "line 1"),
        ("name = \"t\"\n[hand]\nfile = \"hand.toml\"\n", "missing section `[object]`"),
        ("[object]\nunits = \"mm\"\n", "`mesh`"),
        ("[object]\nmesh = \"\"\n", "`object.mesh` is empty"),
        ("[object]\nmesh = \"m.stl\"\n[hand]\nfile = \"bh9\"\n", "bh9"),
    ];
    for (body, needle) in cases {
        let env = Env::new();
        env.write("m.stl", good_mesh());
        let s = env.scenario("bad.toml", body);
        let out = env.run(&[s.to_str().unwrap()]);
        let file = if needle == "nohand.toml" || needle == "bh9" {
            needle
        } else {
            "bad.toml"
        };
        assert_bad_input(&out, file, needle);
    }
}

#[test]
fn a_file_that_is_neither_scenario_nor_mesh_says_what_is_read() {
    // A `.dae` (a mesh format grasp-sim does not read) or a `.txt` is read as a scenario; the
    // error says so, and which formats are read. A `.toml` gets no such hint.
    let env = Env::new();
    for (name, body) in [("part.dae", "<COLLADA/>\n"), ("notes.txt", "hello world\n")] {
        let p = env.scenario(name, body);
        let out = env.run(&[p.to_str().unwrap()]);
        assert_bad_input(&out, name, "meshes from .stl, .obj, .ply and .urdf");
    }
    let p = env.scenario("bad.toml", "hello world\n");
    let out = env.run(&[p.to_str().unwrap()]);
    assert!(!String::from_utf8_lossy(&out.stderr).contains("meshes from"));
}

/// Issue 16 item 3: one bad input does not sink the others; the worst status wins.
#[test]
fn a_bad_input_among_good_ones_is_reported_and_the_rest_run() {
    let env = Env::new();
    env.write("m.stl", good_mesh());
    let good = env.basic_scenario("m.stl", "");
    let bad = env.scenario("bad.toml", "[object]\nmesh = \"gone.stl\"\n");
    let out = env.run(&[
        "--json",
        "--no-sim",
        good.to_str().unwrap(),
        "missing.toml",
        bad.to_str().unwrap(),
        "m.stl",
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    let text = String::from_utf8(out.stdout).unwrap();
    let names: Vec<String> = text
        .lines()
        .map(|l| serde_json::from_str::<serde_json::Value>(l).unwrap()["scenario"].to_string())
        .collect();
    assert_eq!(names, ["\"t\"", "\"m\""]);
    let errors: Vec<&str> = err.lines().filter(|l| l.contains("error")).collect();
    assert_eq!(errors.len(), 2, "{err}");
    assert!(
        errors[0].contains("missing.toml") && errors[1].contains("gone.stl"),
        "{err}"
    );
}

/// Issue 16 item 3: an output folder that cannot be written is refused before any work.
#[test]
fn an_unwritable_report_folder_fails_before_the_run() {
    let env = Env::new();
    env.write("m.stl", good_mesh());
    env.write("afile", "x");
    let s = env.basic_scenario("m.stl", "");
    let out = env.run(&["--report", "afile/sub", s.to_str().unwrap()]);
    assert_bad_input(&out, "afile/sub", "--report");
}

#[test]
fn json_lines_report_the_object_contract() {
    let root = crate::root();
    let out = run_in(
        &root,
        &[
            "--json",
            "--no-sim",
            "scenarios/cylinder_d40.toml",
            "scenarios/cup.toml",
        ],
    );
    crate::assert_success(&out);
    let text = String::from_utf8(out.stdout).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), 2);
    let v: serde_json::Value = serde_json::from_str(lines[0]).unwrap();
    assert_eq!(v["scenario"], "cylinder_d40");
    let o = &v["object"];
    assert_eq!(o["triangles"], 576);
    let vol = o["volume_mm3"].as_f64().unwrap();
    let expected = std::f64::consts::PI * 400.0 * 124.0;
    assert!(((vol - expected) / expected).abs() < 0.005, "volume {vol}");
    assert!((o["height_mm"].as_f64().unwrap() - 124.0).abs() < 1e-9);
    let axis: Vec<f64> = o["principal_axis"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect();
    assert!((axis[2] - 1.0).abs() < 1e-12, "{axis:?}");
    // The plan contract; the physics check is reported as not run, not invented.
    let p = &v["plan"];
    assert_eq!(p["status"], "feasible");
    assert_eq!(p["indexed_elevations"], 45);
    assert_eq!(p["effective_elevation_mm"][0], 7.0);
    assert!(p["candidates_tried"].as_u64().unwrap() >= 1);
    assert_eq!(p["sorted_indices"][0], 43);
    let g = &p["grasp"];
    assert_eq!(g["elevation_index"], 43);
    assert_eq!(g["approach_angle_deg"], 0.0);
    assert_eq!(g["fingers"].as_array().unwrap().len(), 3);
    for key in ["theta1_deg", "theta2_deg"] {
        assert!(g["fingers"][0][key].is_number());
    }
    assert_eq!(g["fingers"][0]["als"]["top"].as_array().unwrap().len(), 2);
    assert_eq!(
        g["palm_pose"]["quaternion_wxyz"].as_array().unwrap().len(),
        4
    );
    assert_eq!(v["sim"]["verdict"], "not_run");
    assert_eq!(v["expect"]["met"], true);
    let w: serde_json::Value = serde_json::from_str(lines[1]).unwrap();
    assert_eq!(w["scenario"], "cup");
}

#[test]
fn the_same_scenario_gives_the_same_json() {
    let root = crate::root();
    let strip = |o: Output| {
        let mut v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        v["plan"]["timings_ms"] = serde_json::Value::Null;
        v["sim"]["wall_ms"] = serde_json::Value::Null;
        v
    };
    let a = strip(run_in(&root, &["--json", "scenarios/chapter4.toml"]));
    let b = strip(run_in(&root, &["--json", "scenarios/chapter4.toml"]));
    assert_eq!(a, b);
}

#[test]
fn every_bundled_scenario_runs() {
    let root = crate::root();
    let mut args = vec!["--no-sim".to_string()];
    for e in std::fs::read_dir(root.join("scenarios")).unwrap() {
        let p = e.unwrap().path();
        // scenarios/hands/ holds the scenarios of the other bundled hands.
        if p.is_file() {
            args.push(p.to_string_lossy().into_owned());
        }
    }
    assert!(args.len() >= 9, "eight thesis scenarios expected");
    let out = bin().current_dir(&root).args(&args).output().unwrap();
    crate::assert_success(&out);
}

#[test]
fn an_open_mesh_warns_with_the_boundary_edge_count() {
    // A cylinder with its top cap removed: 144 boundary edges, still encloses volume.
    let mut mesh = grasp_sim::objects::cylinder(40.0, 124.0);
    let top = mesh
        .vertices
        .iter()
        .position(|p| p.x == 0.0 && p.y == 0.0 && p.z == 124.0)
        .unwrap() as u32;
    mesh.triangles.retain(|t| !t.contains(&top));
    let env = Env::new();
    env.write("open.stl", mesh.to_binary_stl());
    let s = env.basic_scenario("open.stl", "");
    let out = env.run(&[s.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{err}");
    assert!(
        err.contains("open.stl") && err.contains("144 boundary edges"),
        "{err}"
    );
}

#[test]
fn a_binary_file_whose_header_says_solid_is_read_as_binary() {
    let mut bytes = good_mesh();
    bytes[..80].fill(b' ');
    bytes[..11].copy_from_slice(b"solid cad x");
    let env = Env::new();
    env.write("solid_header.stl", &bytes);
    let s = env.basic_scenario("solid_header.stl", "");
    let out = env.run(&["--json", s.to_str().unwrap()]);
    crate::assert_success(&out);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["object"]["triangles"], 576);
}

/// A scenario without `[expect]` and without `[hand]` (the bundled thesis hand) runs outside the
/// repository, reports, judges nothing and exits 0 (issue 13 item 2, issue 16 item 5).
#[test]
fn a_minimal_scenario_needs_no_expect_and_no_hand() {
    let env = Env::new();
    env.write("m.stl", good_mesh());
    let bare = env.scenario("min.toml", "[object]\nmesh = \"m.stl\"\n");
    let named = env.scenario(
        "named.toml",
        "[object]\nmesh = \"m.stl\"\n[hand]\nfile = \"thesis\"\n",
    );
    let out = env.run(&[
        "--json",
        "--no-sim",
        bare.to_str().unwrap(),
        named.to_str().unwrap(),
    ]);
    crate::assert_success(&out);
    let text = String::from_utf8(out.stdout).unwrap();
    let lines: Vec<serde_json::Value> = text
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(lines.len(), 2);
    for v in &lines {
        assert_eq!(v["plan"]["status"], "feasible", "{v}");
        assert_eq!(v["expect"]["outcome"], "none");
        assert!(v["expect"]["met"].is_null());
        assert!(v["expect"]["details"]
            .as_str()
            .unwrap()
            .contains("no expectation"));
    }
    let out = env.run(&["--no-sim", bare.to_str().unwrap()]);
    crate::assert_success(&out);
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(
        text.contains("Result      grasp at approach 0 deg"),
        "{text}"
    );
    assert!(text.contains("Expect      none given"), "{text}");
    // Issue 16 item 10: "1 candidate" but "2 candidates", and no "-0.0" for a pitch that
    // rounds to zero.
    let plan = text
        .lines()
        .find(|l| l.trim_start().starts_with("Plan "))
        .unwrap();
    let tried = plan.split("; ").nth(1).unwrap().split(' ').next().unwrap();
    let n: usize = tried.parse().unwrap();
    let word = if n == 1 { "candidate" } else { "candidates" };
    assert!(text.contains(&format!("; {n} {word} tried")), "{text}");
    assert!(text.contains("Palm_Pitch_Angle = 0.0 deg"), "{text}");
}

/// Bare meshes on the command line (and mixed with scenarios) run with the bundled hand and the
/// defaults; `--units` scales them.
#[test]
fn bare_meshes_run_with_the_defaults() {
    let env = Env::new();
    env.write("cyl.stl", good_mesh());
    env.write("box.obj", crate::formats::BOX_OBJ);
    env.write("box.ply", crate::formats::BOX_PLY);
    let s = env.basic_scenario("cyl.stl", "");
    let out = env.run(&[
        "--json",
        "--no-sim",
        "cyl.stl",
        "box.obj",
        s.to_str().unwrap(),
        "box.ply",
    ]);
    crate::assert_success(&out);
    let text = String::from_utf8(out.stdout).unwrap();
    let lines: Vec<serde_json::Value> = text
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    let names: Vec<&str> = lines
        .iter()
        .map(|v| v["scenario"].as_str().unwrap())
        .collect();
    assert_eq!(names, ["cyl", "box", "t", "box"]);
    assert_eq!(lines[0]["plan"]["status"], "feasible");
    assert_eq!(lines[0]["expect"]["outcome"], "none");
    assert_eq!(lines[2]["expect"]["outcome"], "hold");
    for i in [1, 3] {
        assert!((lines[i]["object"]["volume_mm3"].as_f64().unwrap() - 48000.0).abs() < 1e-6);
    }
    // The cylinder written in metres and read as such is the same cylinder.
    let mut m = grasp_sim::objects::cylinder(40.0, 124.0);
    m.map_vertices(|p| p / 1000.0);
    env.write("cyl_m.stl", m.to_binary_stl());
    let out = env.run(&["--json", "--no-sim", "--units", "m", "cyl_m.stl"]);
    crate::assert_success(&out);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert!(
        (v["object"]["height_mm"].as_f64().unwrap() - 124.0).abs() < 1e-3,
        "{v}"
    );
    assert_eq!(v["plan"]["status"], "feasible");
}

/// The human summary says plainly which grasp, whether it held, and why not.
#[test]
fn the_summary_says_whether_the_grasp_held_and_why_not() {
    let root = crate::root();
    let out = run_in(
        &root,
        &[
            "scenarios/sim_open_fingers.toml",
            "scenarios/cylinder_d10.toml",
        ],
    );
    crate::assert_success(&out);
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(
        text.contains("NOT held: the object fell out of the hand"),
        "{text}"
    );
    assert!(
        text.contains("Result      no grasp found: too thin"),
        "{text}"
    );
}

/// Issue 16 item 4: a size implausible for a hand is said, with the likely unit.
#[test]
fn implausible_sizes_warn_with_the_likely_unit() {
    let env = Env::new();
    let mut m = grasp_sim::objects::cylinder(40.0, 124.0);
    m.map_vertices(|p| p / 1000.0);
    env.write("in_m.stl", m.to_binary_stl());
    let out = env.run(&["--no-sim", "in_m.stl"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("in_m.stl") && err.contains("0.124 mm across") && err.contains("--units m"),
        "{err}"
    );
    env.write("cyl.stl", good_mesh());
    let s = env.basic_scenario("cyl.stl", "");
    let text = std::fs::read_to_string(&s)
        .unwrap()
        .replace("[object]\n", "[object]\nunits = \"m\"\n");
    std::fs::write(&s, text).unwrap();
    let out = env.run(&["--no-sim", s.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("124 m across as read") && err.contains("units = \"mm\""),
        "{err}"
    );
    // A plausible object says nothing of units.
    let out = env.run(&["--no-sim", "cyl.stl"]);
    assert!(!String::from_utf8_lossy(&out.stderr).contains("implausible"));
    // A file in centimetres read as metres: centimetres is the unit that makes it hand-sized
    // (12.4 cm; millimetres would make it 12.4 mm), and `--units cm` reads it so.
    let mut m = grasp_sim::objects::cylinder(40.0, 124.0);
    m.map_vertices(|p| p / 10.0);
    env.write("in_cm.stl", m.to_binary_stl());
    let out = env.run(&["--no-sim", "--units", "m", "in_cm.stl"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("12.4 m across as read") && err.contains("--units cm"),
        "{err}"
    );
    let out = env.run(&["--json", "--no-sim", "--units", "cm", "in_cm.stl"]);
    crate::assert_success(&out);
    let r: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let height = r["object"]["height_mm"].as_f64().unwrap();
    assert!((height - 124.0).abs() < 1e-3, "{height}"); // STL keeps f32
    assert!(!String::from_utf8_lossy(&out.stderr).contains("implausible"));
    // The same file read as millimetres is 12.4 mm: plausible in size, but smaller than twice
    // the thesis hand's smallest grasp (17.4 mm) and ungraspable, so the hint names
    // centimetres (124 mm; inches would give 315 mm). Planned, it says nothing.
    let out = env.run(&["--json", "--no-sim", "in_cm.stl"]);
    let r: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(r["plan"]["status"], "ungraspable");
    let hint = "in_cm.stl: the object is 12.4 mm across as read (units = \"mm\"), small for a \
                hand that grasps 17.4 mm and more; if the file is in cm (the object then 124 mm \
                across), set units = \"cm\" in [object], or --units cm for a bare mesh";
    assert_eq!(
        r["warnings"],
        serde_json::json!([hint]),
        "{}",
        r["warnings"]
    );
    let out = env.run(&["--json", "--no-sim", "cyl.stl"]);
    let r: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(r["warnings"], serde_json::json!([]), "{}", r["warnings"]);
}

/// The size messages judge the object's own extent, not the file's box: a 6 mm rod turned 45°
/// spans 4.8 mm of its box, which read as implausible (under 5 mm) where the same rod written
/// square did not; a 4 mm rod is implausible in both frames, with the same message.
#[test]
fn the_size_messages_do_not_depend_on_the_file_frame() {
    let env = Env::new();
    let turn =
        nalgebra::Rotation3::from_axis_angle(&nalgebra::Vector3::y_axis(), 45f64.to_radians());
    let stderr_of = |name: &str, length: f64, turned: bool| {
        let mut m = grasp_sim::objects::cylinder(0.8, length);
        if turned {
            m.map_vertices(|p| turn * p);
        }
        env.write(name, m.to_binary_stl());
        let out = env.run(&["--no-sim", name]);
        String::from_utf8_lossy(&out.stderr).replace(name, "ROD")
    };
    let (square, turned) = (
        stderr_of("a.stl", 6.0, false),
        stderr_of("b.stl", 6.0, true),
    );
    assert!(!square.contains("implausible"), "{square}");
    assert!(!turned.contains("implausible"), "{turned}");
    let (square, turned) = (
        stderr_of("c.stl", 4.0, false),
        stderr_of("d.stl", 4.0, true),
    );
    assert!(
        square.contains("the object is 4.00 mm across as read"),
        "{square}"
    );
    assert_eq!(square, turned);
}

/// Issue 16 item 10: `gen-assets` outside the repository writes scenarios that run there (they
/// name the bundled hand, not a path into the repository).
#[test]
fn gen_assets_elsewhere_gives_runnable_scenarios() {
    let env = Env::new();
    let out = env.run(&["gen-assets", "--out", "objs"]);
    crate::assert_success(&out);
    let s = env.path("objs/train/thin_rod.toml");
    crate::assert_success(&env.run(&["--no-sim", s.to_str().unwrap()]));
}

/// Issue 16 item 7: a hand-file error names its line.
#[test]
fn hand_file_errors_name_the_line() {
    let env = Env::new();
    env.write("m.stl", good_mesh());
    let hand = std::fs::read_to_string(env.path("hand.toml")).unwrap();
    env.write("hand.toml", hand.replace("gap_mm = 25.0", "gap_mn = 25.0"));
    let s = env.basic_scenario("m.stl", "");
    let out = env.run(&[s.to_str().unwrap()]);
    assert_bad_input(&out, "hand.toml", "gap_mn");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("line ") && err.contains("gap_mm"), "{err}");
}

#[test]
fn a_reader_that_goes_away_is_not_bad_input() {
    // `grasp-sim --json ... | head -c 10`: the pipe closes before the output is written. The
    // run stops quietly with status 0 (it used to print "Broken pipe" and exit 2, the status of
    // bad input).
    let mut child = crate::grasp_sim()
        .args([
            "--json",
            "--no-sim",
            "scenarios/cup.toml",
            "scenarios/prism.toml",
        ])
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdout.take());
    let out = child.wait_with_output().unwrap();
    assert_eq!(out.status.code(), Some(0), "{out:?}");
    assert!(
        out.stderr.is_empty(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

#[test]
fn the_summary_names_the_elevation_range_it_searched() {
    // The thesis's Effective Elevation lies inside the object; under the extended rules the
    // range searched overhangs its ends, and the summary says so rather than calling it the
    // Effective Elevation. An object shorter than the fingers has none (not an inverted range).
    let env = Env::new();
    let cup = crate::root().join("scenarios/cup.toml");
    let out = run_in(env.dir.path(), &["--no-sim", cup.to_str().unwrap()]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("Effective elevation 7.0..103.0 mm"), "{text}");
    let ball = crate::root().join("assets/real/scenarios/adroit_ball.toml");
    let out = run_in(env.dir.path(), &["--no-sim", ball.to_str().unwrap()]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains(
            "Search elevation (extended rules: outer fingers may overhang the ends) -5.0.."
        ),
        "{text}"
    );
    env.write(
        "tiny.stl",
        grasp_sim::objects::cylinder(0.04, 0.124).to_binary_stl(),
    );
    let out = env.run(&["--no-sim", "tiny.stl"]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("Effective elevation none"), "{text}");
}

#[test]
fn gravity_on_the_command_line_overrides_the_scenario() {
    // `--gravity six` checks a bare mesh in the six directions a scenario's `[sim] gravity`
    // would; `--gravity down` takes a `six` scenario back to the one direction. The grasp is
    // the same either way, and the first direction of `six` (+X) differs from `down` (−Z).
    let dir = tempfile::tempdir().unwrap();
    let root = crate::root();
    let mesh = root.join("assets/objects/cylinder_d40.stl");
    let scenario = dir.path().join("d40_six.toml");
    std::fs::write(
        &scenario,
        format!(
            "[object]\nmesh = {:?}\ndensity_kg_m3 = 500.0\nfriction = 0.3\n[sim]\ngravity = \"six\"\n",
            mesh.to_str().unwrap()
        ),
    )
    .unwrap();
    let directions = |args: &[&str]| -> (Vec<Vec<f64>>, serde_json::Value) {
        let out = run_in(dir.path(), args);
        assert_eq!(
            out.status.code(),
            Some(0),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        let dirs = v["sim"]["directions"]
            .as_array()
            .unwrap()
            .iter()
            .map(|d| serde_json::from_value(d["gravity"].clone()).unwrap())
            .collect();
        // The grasp as planned (its `check` is the physics check's, which gravity changes).
        let mut grasp = v["plan"]["grasp"].clone();
        grasp.as_object_mut().unwrap().remove("check");
        (dirs, grasp)
    };
    let m = mesh.to_str().unwrap();
    let s = scenario.to_str().unwrap();
    let (bare, grasp) = directions(&["--json", m]);
    assert_eq!(bare, vec![vec![0.0, 0.0, -1.0]]);
    let (bare_six, grasp_six) = directions(&["--json", "--gravity", "six", m]);
    assert_eq!(bare_six.len(), 6, "{bare_six:?}");
    assert_eq!(bare_six[0], vec![1.0, 0.0, 0.0]);
    assert!(bare_six.contains(&vec![0.0, 0.0, -1.0]), "{bare_six:?}");
    assert_eq!(grasp, grasp_six);
    let (scenario_six, _) = directions(&["--json", s]);
    assert_eq!(scenario_six, bare_six);
    let (scenario_down, _) = directions(&["--json", "--gravity", "down", s]);
    assert_eq!(scenario_down, bare);
    // Anything else is a usage error, exit 2, that lists the two.
    let out = run_in(dir.path(), &["--gravity", "sideways", m]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("possible values: down, six"), "{err}");
}

/// Runs `args` under `script`, so that stderr is a terminal; `None` where `script` is missing.
fn on_a_terminal(args: &str) -> Option<String> {
    let bin = env!("CARGO_BIN_EXE_grasp-sim");
    let out = std::process::Command::new("script")
        .args(["-qec", &format!("{bin} {args} >/dev/null"), "/dev/null"])
        .current_dir(crate::root())
        .output()
        .ok()?;
    out.status
        .success()
        .then(|| String::from_utf8_lossy(&out.stdout).into_owned())
}

#[test]
fn long_runs_show_progress_on_a_terminal_only() {
    let Some(tty) = on_a_terminal("scenarios/cylinder_d40.toml") else {
        eprintln!("no `script` here: the terminal half is not checked");
        return;
    };
    assert!(
        tty.contains("cylinder_d40: planning, physics check"),
        "{tty}"
    );
    let piped = crate::succeed(crate::grasp_sim().args(["scenarios/cylinder_d40.toml"]));
    let err = String::from_utf8_lossy(&piped.stderr);
    assert!(!err.contains("physics check"), "{err}");

    let out = tempfile::tempdir().unwrap();
    let args = format!(
        "tune scenarios/cylinder_d40.toml --param sf_c=0:1:1 --out {}",
        out.path().display()
    );
    let tty = on_a_terminal(&args).expect("tune runs");
    assert!(tty.contains("/2") && tty.contains("tune: "), "{tty}");
    let piped = crate::succeed(crate::grasp_sim().args(args.split(' ')));
    let err = String::from_utf8_lossy(&piped.stderr);
    assert!(!err.contains("done at one setting"), "{err}");
}

#[test]
fn the_summary_lists_every_candidate_collected_or_checked() {
    let out = crate::succeed(crate::grasp_sim().args([
        "scenarios/cup.toml",
        "--no-sim",
        "--candidates",
        "3",
    ]));
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("3 candidates tried"), "{text}");
    assert!(text.contains("Candidates  3 collected"), "{text}");
    for (k, approach) in [(1, 0), (2, 10), (3, 20)] {
        assert!(
            text.contains(&format!(
                "{k}. axis least (thesis), approach {approach} deg"
            )),
            "{text}"
        );
    }
    assert!(
        text.contains("* 1. "),
        "the reported grasp is marked: {text}"
    );
    // Checked by the physics check: each candidate's verdict, and how many were checked.
    let summary = |scenario: &str| {
        let out = crate::grasp_sim().arg(scenario).output().unwrap();
        String::from_utf8_lossy(&out.stdout).into_owned()
    };
    let text = summary("scenarios/sim_d40_slippery_heavy.toml");
    // Its first candidate closes as planned and drops, so the search closes 16 picks and
    // checks them in the order their closings gave after it (`[sim] order_by_closing`): 8
    // checked, the first first (reported: every one a drop), each with its closing.
    assert!(text.contains("667 candidates tried, 8 checked"), "{text}");
    assert!(
        text.contains("* 1. axis least (thesis), approach 0 deg, index 43 "),
        "{text}"
    );
    assert!(
        text.contains("16 collected, the closed ones first, in the order their closings gave"),
        "{text}"
    );
    assert_eq!(text.matches("; check: drop (").count(), 8, "{text}");
    assert_eq!(text.matches("; closed as planned, ").count(), 16, "{text}");
    // With one check allowed (`max_checked = 1`), a first that closed as planned and dropped
    // is the answer: its check counted, nothing else planned or closed.
    let text = summary("scenarios/sim_cup_weak_motors.toml");
    assert!(text.contains("1 candidate tried, 1 checked"), "{text}");
    // A single grasp is not listed twice.
    let out = crate::succeed(crate::grasp_sim().args(["scenarios/cup.toml", "--no-sim"]));
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(!text.contains("Candidates  "), "{text}");
}

#[test]
fn the_summary_names_the_grasp_axis_and_the_rules_beyond_the_thesis() {
    // A 50 x 70 x 150 mm box: the thesis's rules find nothing (the palm meets the object in
    // its plane), the extended rules back the palm off. The Plan line says so.
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("box.stl");
    std::fs::write(
        &p,
        grasp_sim::objects::prism(50.0, 70.0, 150.0).to_binary_stl(),
    )
    .unwrap();
    let out = crate::succeed(crate::grasp_sim().arg("--no-sim").arg(&p));
    let text = String::from_utf8_lossy(&out.stdout);
    let plan = text
        .lines()
        .find(|l| l.trim_start().starts_with("Plan "))
        .unwrap();
    let json = crate::succeed(crate::grasp_sim().args(["--no-sim", "--json"]).arg(&p));
    let v: serde_json::Value = serde_json::from_slice(&json.stdout).unwrap();
    let g = &v["plan"]["grasp"];
    assert_eq!(g["rules"], "extended", "{g}");
    assert_eq!(g["relaxations"][0], "palm_backed_off", "{g}");
    assert!(
        plan.contains("feasible under rules beyond the thesis (extended: palm_backed_off)"),
        "{plan}"
    );
    // About its least axis, as the Object line: no Grasp axis line.
    assert_eq!(g["axis_name"], "least");
    assert!(!text.contains("Grasp axis"), "{text}");
    // The thesis's cup plans under the thesis's rules: the Plan line says nothing more.
    let cup = crate::succeed(crate::grasp_sim().args(["--no-sim", "scenarios/cup.toml"]));
    let cup = String::from_utf8_lossy(&cup.stdout);
    assert!(cup.contains("  Plan        feasible; "), "{cup}");
    // An open tube (no caps) is grasped about its own axis. The mass properties of its open
    // surface make that axis the largest; the object's own frame (docs/FRAMES.md, issue 30)
    // takes its moments from a fan of tetrahedra from the surface's centroid, which encloses
    // the tube's solid, so its own axis is the least: the Object line's height is along it,
    // and there is no Grasp axis line.
    let tube = dir.path().join("tube.stl");
    std::fs::write(&tube, open_tube(30.0, 120.0, 64)).unwrap();
    let out = crate::succeed(crate::grasp_sim().args(["--no-sim", "--json"]).arg(&tube));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(
        v["plan"]["grasp"]["axis_name"], "least",
        "{}",
        v["plan"]["grasp"]
    );
    let out = crate::succeed(crate::grasp_sim().arg("--no-sim").arg(&tube));
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("height 120.0 mm") && !text.contains("Grasp axis"),
        "{text}"
    );
}

/// An open tube of radius `r` and height `h` on `n` facets (no caps), as ASCII STL.
fn open_tube(r: f64, h: f64, n: usize) -> String {
    use std::f64::consts::TAU;
    let p = |k: usize, z: f64| {
        let a = TAU * k as f64 / n as f64;
        format!("vertex {} {} {z}\n", r * a.cos(), r * a.sin())
    };
    let mut s = String::from("solid tube\n");
    for k in 0..n {
        for tri in [
            [p(k, 0.0), p(k + 1, 0.0), p(k + 1, h)],
            [p(k, 0.0), p(k + 1, h), p(k, h)],
        ] {
            s.push_str("facet normal 0 0 0\nouter loop\n");
            s.extend(tri);
            s.push_str("endloop\nendfacet\n");
        }
    }
    s.push_str("endsolid tube\n");
    s
}

#[test]
fn a_mistyped_key_gets_a_did_you_mean() {
    let dir = tempfile::tempdir().unwrap();
    let cup = crate::root().join("assets/objects/cup.stl");
    let write = |name: &str, text: String| {
        let p = dir.path().join(name);
        std::fs::write(&p, text).unwrap();
        p
    };
    let err = |p: &std::path::Path| {
        let out = crate::grasp_sim().arg(p).output().unwrap();
        assert_eq!(out.status.code(), Some(2));
        String::from_utf8_lossy(&out.stderr).into_owned()
    };
    let mesh = cup.display();
    // A scenario key, a section name, a hand-file key and an override key.
    let p = write(
        "a.toml",
        format!("[object]\nmesh = \"{mesh}\"\ndensty_kg_m3 = 3\n"),
    );
    assert!(
        err(&p).contains("did you mean `density_kg_m3`?"),
        "{}",
        err(&p)
    );
    let p = write("b.toml", format!("[object]\nmesh = \"{mesh}\"\n[planer]\n"));
    assert!(
        err(&p).contains("unknown section `[planer]`")
            && err(&p).contains("did you mean `[planner]`?"),
        "{}",
        err(&p)
    );
    // A key of another section is sent there: `friction` is the object's, not the check's.
    let p = write(
        "f.toml",
        format!("[object]\nmesh = \"{mesh}\"\n[sim]\nfriction = 0.5\n"),
    );
    assert!(
        err(&p).contains("unknown field `friction`")
            && err(&p).contains("; `friction` is a key of `[object]`"),
        "{}",
        err(&p)
    );
    // A value of the wrong type is named in the file's words, not Rust's.
    let p = write(
        "t.toml",
        format!("[object]\nmesh = \"{mesh}\"\n[sim]\nduration_s = \"2\"\n"),
    );
    assert!(err(&p).contains("expected a number"), "{}", err(&p));
    let p = write(
        "g.toml",
        format!("[object]\nmesh = \"{mesh}\"\n[sim]\ngravity = 6\n"),
    );
    assert!(err(&p).contains("expected a name in quotes"), "{}", err(&p));
    let hand = std::fs::read_to_string(crate::root().join("assets/hands/thesis.toml")).unwrap();
    write(
        "h.toml",
        hand.replacen("\nmargin_mm = ", "\nmargn_mm = ", 1),
    );
    let p = write(
        "c.toml",
        format!("[object]\nmesh = \"{mesh}\"\n[hand]\nfile = \"h.toml\"\n"),
    );
    let e = err(&p);
    assert!(
        e.contains("h.toml: line ") && e.contains("did you mean `margin_mm`?"),
        "{e}"
    );
    let p = write(
        "d.toml",
        format!(
            "[object]\nmesh = \"{mesh}\"\n[hand]\noverrides = {{ \"phalanx_2.lenght_mm\" = 18.0 }}\n"
        ),
    );
    assert!(
        err(&p).contains("did you mean `phalanx_2.length_mm`?"),
        "{}",
        err(&p)
    );
    // Nothing near: no guess.
    let p = write(
        "e.toml",
        format!("[object]\nmesh = \"{mesh}\"\ncolour = 3\n"),
    );
    assert!(!err(&p).contains("did you mean"), "{}", err(&p));
}

#[test]
fn payload_without_the_physics_check_says_it_is_ignored() {
    let out =
        crate::succeed(crate::grasp_sim().args(["scenarios/cup.toml", "--no-sim", "--payload"]));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("--payload is ignored with --no-sim"), "{err}");
    let out = crate::succeed(crate::grasp_sim().args(["scenarios/cup.toml", "--no-sim"]));
    assert!(!String::from_utf8_lossy(&out.stderr).contains("--payload"));
}

#[test]
fn json_figures_carry_no_float_noise() {
    let out =
        crate::succeed(crate::grasp_sim().args(["--json", "--no-sim", "scenarios/chapter4.toml"]));
    let text = String::from_utf8_lossy(&out.stdout);
    // Every number outside strings has at most 12 significant digits and none is a tiny
    // leftover of a cancellation (3.6e-16 mm) or a negative zero.
    let v: serde_json::Value = serde_json::from_str(&text).unwrap();
    fn walk(v: &serde_json::Value, bad: &mut Vec<String>) {
        match v {
            serde_json::Value::Number(n) => {
                if let Some(x) = n.as_f64().filter(|_| n.is_f64()) {
                    let rounded = grasp_sim::report::round_significant(x, 12);
                    if rounded != x || (x != 0.0 && x.abs() < 1e-10) || n.to_string() == "-0.0" {
                        bad.push(n.to_string());
                    }
                }
            }
            serde_json::Value::Array(a) => a.iter().for_each(|x| walk(x, bad)),
            serde_json::Value::Object(o) => o.values().for_each(|x| walk(x, bad)),
            _ => {}
        }
    }
    let mut bad = Vec::new();
    walk(&v, &mut bad);
    assert!(bad.is_empty(), "{bad:?}");
    // Field order is the contract's (scenario first), not alphabetical.
    assert!(text.starts_with("{\"scenario\":"), "{}", &text[..40]);
}

/// The newcomer's path of 2026-12-01: one bad input does not sink a `tune`, an output file
/// that is a folder and a folder with nothing to run are refused before any work, two inputs
/// of one name write two output folders, and `--units` on a scenario says it does not apply.
#[test]
fn tune_batch_and_outputs_keep_the_good_inputs_and_refuse_bad_paths_first() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let good = crate::root().join("assets/objects/cylinder_d40.stl");
    let bad = d.join("nan.stl");
    std::fs::write(&bad, "solid t\nfacet normal 0 0 1\nouter loop\nvertex nan 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid\n").unwrap();
    // tune: the bad mesh is named and left out, the good one tuned on, the results written,
    // exit 2.
    let out_dir = d.join("tune");
    let out = crate::grasp_sim()
        .args(["tune", "--param", "sf_c=0:1:1", "--out"])
        .arg(&out_dir)
        .arg(&good)
        .arg(&bad)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("nan.stl: malformed ASCII STL: line 4"),
        "{err}"
    );
    assert!(String::from_utf8_lossy(&out.stdout).contains("over 1 object"));
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out_dir.join("tune.json")).unwrap()).unwrap();
    assert_eq!(json["skipped"][0][0], bad.display().to_string());
    assert_eq!(json["counters"]["objects_loaded"], 1);
    // tune on the bad mesh alone: its error, nothing written.
    let alone = d.join("tune_alone");
    let out = crate::grasp_sim()
        .args(["tune", "--param", "sf_c=0:1:1", "--out"])
        .arg(&alone)
        .arg(&bad)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(!alone.join("tune.json").exists());
    // A folder with nothing to run, for tune and batch: an error naming it, no work done.
    let empty = d.join("only_dae");
    std::fs::create_dir(&empty).unwrap();
    std::fs::write(empty.join("mug.dae"), "<COLLADA/>").unwrap();
    for args in [
        vec!["batch".to_string()],
        vec![
            "tune".into(),
            "--param".into(),
            "sf_c=0:1:1".into(),
            "--out".into(),
            d.join("t2").display().to_string(),
        ],
    ] {
        let out = crate::grasp_sim().args(&args).arg(&empty).output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert!(
            err.contains("no scenario (.toml) or mesh (.stl, .obj, .ply, .urdf) in this folder"),
            "{err}"
        );
    }
    // batch --out naming a folder: refused before the object runs.
    let out = crate::grasp_sim()
        .arg("batch")
        .arg(&good)
        .arg("--out")
        .arg(d)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("is a folder; give a file to write the results to"),
        "{err}"
    );
    assert!(!err.contains("[1/1]") && !err.contains("hold"), "{err}");
    // Two inputs of one name: two report folders, the second told.
    for sub in ["a", "b"] {
        std::fs::create_dir(d.join(sub)).unwrap();
        std::fs::copy(&good, d.join(sub).join("obj.stl")).unwrap();
    }
    let reports = d.join("reports");
    let out = crate::grasp_sim()
        .args(["--no-sim", "--report"])
        .arg(&reports)
        .arg(d.join("a/obj.stl"))
        .arg(d.join("b/obj.stl"))
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{err}");
    assert!(reports.join("obj/report.html").is_file());
    assert!(reports.join("obj-2/report.html").is_file());
    assert!(
        err.contains("an earlier input has the name `obj`; its output folders are `obj-2`"),
        "{err}"
    );
    // --units on a scenario: it does not apply, and the run says so.
    let out =
        crate::succeed(crate::grasp_sim().args(["--no-sim", "--units", "m", "scenarios/cup.toml"]));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("--units m applies to bare meshes"), "{err}");
}
