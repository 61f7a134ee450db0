//! Objects given as URDF (`mesh::urdf`): the links' meshes and shapes, placed by their origins
//! and joints, in metres.

use grasp_sim::mesh::surface_mass_properties;
use nalgebra::{Rotation3, Vector3};
use std::path::Path;
use std::process::Output;

fn json(out: &Output) -> serde_json::Value {
    crate::assert_success(out);
    serde_json::from_slice(&out.stdout).unwrap()
}

fn write(dir: &Path, name: &str, bytes: impl AsRef<[u8]>) -> std::path::PathBuf {
    let p = dir.join(name);
    std::fs::create_dir_all(p.parent().unwrap()).unwrap();
    std::fs::write(&p, bytes).unwrap();
    p
}

/// A URDF of one link whose `<visual>` holds `visual`.
fn one_link(visual: &str) -> String {
    format!("<robot name=\"r\"><link name=\"a\"><visual>{visual}</visual></link></robot>")
}

/// A URDF of one link with the mesh `file` at scale 0.001 (a mesh in millimetres).
fn mm_mesh_link(file: &str) -> String {
    one_link(&format!(
        "<geometry><mesh filename=\"{file}\" scale=\"0.001 0.001 0.001\"/></geometry>"
    ))
}

fn run(args: &[&str], file: &Path) -> Output {
    crate::grasp_sim().args(args).arg(file).output().unwrap()
}

/// The cup of thesis 5.3, in millimetres in its STL, given by a URDF that scales it to metres
/// and turns and moves it (roll 0.3, pitch −0.2, yaw 1.0 rad), its mesh named by a `package://`
/// URI: the same object, planned as the cup's scenario plans it, and held; its mass is the
/// URDF's.
#[test]
fn a_urdf_cup_plans_as_the_inverted_cup_scenario() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir_all(dir.path().join("meshes")).unwrap();
    std::fs::copy(
        crate::root().join("assets/objects/cup.stl"),
        dir.path().join("meshes/cup.stl"),
    )
    .unwrap();
    let urdf = write(
        dir.path(),
        "cup.urdf",
        r#"<?xml version="1.0"?>
<robot name="cup">
  <link name="base">
    <inertial><mass value="0.1"/></inertial>
    <visual>
      <origin xyz="0.1 -0.2 0.05" rpy="0.3 -0.2 1.0"/>
      <geometry><mesh filename="package://cups/meshes/cup.stl" scale="0.001 0.001 0.001"/></geometry>
    </visual>
  </link>
</robot>
"#,
    );
    let u = json(&run(&["--json"], &urdf));
    // A bare URDF takes its frame from the geometry (docs/FRAMES.md), which stands a cup wider
    // at its top on its rim: the thesis's inverted cup, whose scenario keeps its file's frame.
    let s = json(&crate::succeed(
        crate::grasp_sim().args(["--json", "scenarios/cup_inverted.toml"]),
    ));
    let num = |v: &serde_json::Value| v.as_f64().unwrap();
    let (vu, vs) = (
        num(&u["object"]["volume_mm3"]),
        num(&s["object"]["volume_mm3"]),
    );
    assert!((vu / vs - 1.0).abs() < 1e-6, "{vu} against {vs}");
    assert!((num(&u["object"]["height_mm"]) - 110.0).abs() < 1e-3);
    // The URDF's inertial mass, not the default density's 0.2 kg.
    assert_eq!(num(&u["object"]["mass_kg"]), 0.1);
    assert!((num(&s["object"]["mass_kg"]) - 500.0 * vs * 1e-9).abs() < 1e-12);
    // The principal axis is the cup's Z turned by R = Rz(yaw)·Ry(pitch)·Rx(roll).
    let axis = Rotation3::from_euler_angles(0.3, -0.2, 1.0) * Vector3::z();
    let a = &u["object"]["principal_axis"];
    let got = Vector3::new(num(&a[0]), num(&a[1]), num(&a[2]));
    assert!(got.dot(&axis).abs() > 1.0 - 1e-9, "{got} against {axis}");
    assert_eq!(u["warnings"], serde_json::json!([]));
    let (gu, gs) = (&u["plan"]["grasp"], &s["plan"]["grasp"]);
    assert_eq!(gu["elevation_index"], gs["elevation_index"]);
    for (fu, fs) in gu["fingers"]
        .as_array()
        .unwrap()
        .iter()
        .zip(gs["fingers"].as_array().unwrap())
    {
        for k in ["theta1_deg", "theta2_deg"] {
            assert!(
                (num(&fu[k]) - num(&fs[k])).abs() < 0.01,
                "{fu} against {fs}"
            );
        }
    }
    assert_eq!(u["sim"]["verdict"], "hold");
}

/// Three links on fixed joints, each placed by its joint: a cylinder (Ø40 × 100 mm) from Z = 0,
/// a 30 × 30 × 20 mm box on it, and a knob whose visual mesh is a `.dae` grasp-sim does not read,
/// so its collision sphere (Ø20 mm) stands in, with a warning naming the link. The object is
/// 140 mm high and its volume is the three solids'.
#[test]
fn links_joints_and_shapes_are_placed_and_joined() {
    let dir = tempfile::tempdir().unwrap();
    let urdf = write(
        dir.path(),
        "stack.urdf",
        r#"<robot name="stack">
  <link name="body">
    <visual><origin xyz="0 0 0.05"/><geometry><cylinder radius="0.02" length="0.1"/></geometry></visual>
  </link>
  <joint name="lid_joint" type="fixed">
    <parent link="body"/><child link="lid"/><origin xyz="0 0 0.1"/>
  </joint>
  <link name="lid">
    <visual><origin xyz="0 0 0.01"/><geometry><box size="0.03 0.03 0.02"/></geometry></visual>
  </link>
  <joint name="knob_joint" type="revolute">
    <parent link="lid"/><child link="knob"/><origin xyz="0 0 0.03"/>
    <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/>
  </joint>
  <link name="knob">
    <visual><geometry><mesh filename="knob.dae"/></geometry></visual>
    <collision><geometry><sphere radius="0.01"/></geometry></collision>
  </link>
</robot>
"#,
    );
    let u = json(&run(&["--json", "--no-sim"], &urdf));
    let num = |v: &serde_json::Value| v.as_f64().unwrap();
    assert!(
        (num(&u["object"]["height_mm"]) - 140.0).abs() < 1e-3,
        "{}",
        u["object"]
    );
    let volume = surface_mass_properties(&grasp_sim::objects::cylinder(40.0, 100.0)).volume_mm3
        + 30.0 * 30.0 * 20.0
        + surface_mass_properties(&grasp_sim::objects::uv_sphere(10.0, 48)).volume_mm3;
    let v = num(&u["object"]["volume_mm3"]);
    assert!((v / volume - 1.0).abs() < 0.005, "{v} against {volume}");
    // No inertial mass: the default density's.
    assert!((num(&u["object"]["mass_kg"]) - 500.0 * v * 1e-9).abs() < 1e-12);
    let w = u["warnings"].to_string();
    assert!(
        w.contains("link `knob`: its visual mesh knob.dae is not a format grasp-sim reads")
            && w.contains("its collision geometry is used"),
        "{w}"
    );
}

/// Each broken URDF is one line on stderr naming the file and the problem, exit status 2, and
/// the good input run beside it still prints its result.
#[test]
fn a_broken_urdf_is_one_line_naming_it() {
    let dir = tempfile::tempdir().unwrap();
    let link = one_link;
    let cases = [
        (
            "unclosed.urdf",
            "<robot><link name=\"a\">".to_string(),
            "not well-formed XML",
        ),
        (
            "sdf.urdf",
            "<sdf/>".to_string(),
            "the root element is <sdf>, not <robot>",
        ),
        (
            "missing.urdf",
            link("<geometry><mesh filename=\"package://p/gone.stl\"/></geometry>"),
            "mesh package://p/gone.stl not found beside the URDF or above it",
        ),
        (
            "missrel.urdf",
            link("<geometry><mesh filename=\"meshes/gone.stl\"/></geometry>"),
            "mesh meshes/gone.stl not found beside the URDF",
        ),
        (
            "nan.urdf",
            link("<origin xyz=\"0 nan 0\"/><geometry><sphere radius=\"0.1\"/></geometry>"),
            "line 1: <origin xyz=\"0 nan 0\"> needs 3 finite numbers",
        ),
        (
            "empty.urdf",
            "<robot name=\"r\"><link name=\"a\"><inertial/></link></robot>".to_string(),
            "no geometry grasp-sim can read",
        ),
        (
            "mass.urdf",
            "<robot name=\"r\"><link name=\"a\"><inertial><mass value=\"-1\"/></inertial>\
             <visual><geometry><sphere radius=\"0.05\"/></geometry></visual></link></robot>"
                .to_string(),
            "link `a` has a negative mass (-1 kg)",
        ),
        (
            "zero.urdf",
            link("<geometry><box size=\"0.1 0 0.1\"/></geometry>"),
            "<box> needs a size of three positive lengths",
        ),
    ];
    for (name, text, expect) in cases {
        let p = write(dir.path(), name, text);
        let out = crate::grasp_sim()
            .args(["--no-sim"])
            .arg(&p)
            .arg("scenarios/cup.toml")
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{name}: {err}");
        let lines: Vec<&str> = err.lines().filter(|l| l.contains(name)).collect();
        assert_eq!(lines.len(), 1, "{name}: {err}");
        assert!(lines[0].contains(expect), "{name}: {err}");
        assert!(
            String::from_utf8_lossy(&out.stdout).contains("Plan        feasible"),
            "{name}: the cup's result is missing"
        );
    }
    // A mesh the URDF names that is itself broken is named.
    write(dir.path(), "bad.stl", b"solid x\nfacet normal 0 0 1\n");
    let p = write(
        dir.path(),
        "badmesh.urdf",
        link("<geometry><mesh filename=\"bad.stl\"/></geometry>"),
    );
    let out = run(&["--no-sim"], &p);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("bad.stl: malformed ASCII STL"), "{err}");
    assert!(err.contains("badmesh.urdf: URDF: "), "{err}");
}

/// A folder of URDFs and the meshes they name is a folder of URDF objects: the meshes are not
/// objects of their own.
#[test]
fn a_folder_of_urdfs_runs_the_urdfs() {
    let dir = tempfile::tempdir().unwrap();
    write(
        dir.path(),
        "d40.stl",
        grasp_sim::objects::cylinder(40.0, 100.0).to_binary_stl(),
    );
    for name in ["a.urdf", "b.urdf"] {
        write(dir.path(), name, mm_mesh_link("d40.stl"));
    }
    let out = crate::grasp_sim()
        .args(["batch", "--no-sim"])
        .arg(dir.path())
        .output()
        .unwrap();
    crate::assert_success(&out);
    let lines: Vec<serde_json::Value> = String::from_utf8_lossy(&out.stdout)
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(lines.len(), 2, "{lines:?}");
    for (l, name) in lines.iter().zip(["a.urdf", "b.urdf"]) {
        assert!(l["batch"]["input"].as_str().unwrap().ends_with(name), "{l}");
        assert_eq!(l["plan"]["status"], "feasible", "{l}");
        let h = l["object"]["height_mm"].as_f64().unwrap();
        assert!((h - 100.0).abs() < 1e-3, "{h}");
    }
}

/// A URDF's object is its meshes too: `batch --resume` runs it again when a mesh it names is
/// edited, and not when nothing changed.
#[test]
fn resume_sees_an_edited_urdf_mesh() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = |d: f64| grasp_sim::objects::cylinder(d, 100.0).to_binary_stl();
    write(dir.path(), "m.stl", mesh(40.0));
    let urdf = write(dir.path(), "a.urdf", mm_mesh_link("m.stl"));
    let out = dir.path().join("out.jsonl");
    let resume = || {
        let o = crate::grasp_sim()
            .args(["batch", "--no-sim", "--resume", "--out"])
            .arg(&out)
            .arg(&urdf)
            .output()
            .unwrap();
        crate::assert_success(&o);
        String::from_utf8_lossy(&o.stderr).into_owned()
    };
    resume();
    let err = resume();
    assert!(err.contains("1 of 1 object already in"), "{err}");
    write(dir.path(), "m.stl", mesh(50.0));
    let err = resume();
    assert!(err.contains("0 of 1 object already in"), "{err}");
}

/// A URDF's lengths are metres: a scenario giving it another `units` is an error naming the
/// key, and `--units` on a bare URDF is a warning that it does not apply.
#[test]
fn a_urdf_is_in_metres_whatever_units_say() {
    let dir = tempfile::tempdir().unwrap();
    write(
        dir.path(),
        "ball.urdf",
        one_link("<geometry><sphere radius=\"0.03\"/></geometry>"),
    );
    let scenario = |units: &str| {
        write(
            dir.path(),
            "s.toml",
            format!("[object]\nmesh = \"ball.urdf\"\n{units}"),
        )
    };
    let out = run(&["--no-sim"], &scenario("units = \"cm\"\n"));
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("s.toml")
            && err.contains("object.units")
            && err.contains("a URDF's lengths are metres"),
        "{err}"
    );
    for units in ["", "units = \"m\"\n"] {
        let u = json(&run(&["--json", "--no-sim"], &scenario(units)));
        let h = u["object"]["height_mm"].as_f64().unwrap();
        assert!((h - 60.0).abs() < 1e-3, "{h}");
    }
    let u = json(&run(
        &["--json", "--no-sim", "--units", "cm"],
        &dir.path().join("ball.urdf"),
    ));
    assert!((u["object"]["height_mm"].as_f64().unwrap() - 60.0).abs() < 1e-3);
    assert!(
        u["warnings"]
            .to_string()
            .contains("units \\\"cm\\\" do not apply to a URDF"),
        "{}",
        u["warnings"]
    );
}

/// Open shells in a turned frame: Meta-World's soccer ball (panels that do not close) and
/// basketball, given by URDFs upright and turned by (roll 1.1, pitch −0.7, yaw 2.3), enclose the
/// same volume: the union is sliced along the surface's own long axis, open ends joined, not
/// along the file's Z (where the turned soccer ball kept 1,158 of 20,132 mm³).
#[test]
fn open_shells_enclose_the_same_volume_in_a_turned_frame() {
    let dir = tempfile::tempdir().unwrap();
    for name in ["mw_soccer_ball", "mw_basketball"] {
        let mesh = crate::root().join(format!("assets/real/meshes/{name}.stl"));
        let volume = |rpy: &str| {
            let urdf = write(
                dir.path(),
                &format!("{name}.urdf"),
                mm_mesh_link(&mesh.display().to_string())
                    .replace("<visual>", &format!("<visual><origin rpy=\"{rpy}\"/>")),
            );
            json(&run(&["--json", "--no-sim"], &urdf))["object"]["volume_mm3"]
                .as_f64()
                .unwrap()
        };
        let (upright, turned) = (volume("0 0 0"), volume("1.1 -0.7 2.3"));
        assert!(
            (turned / upright - 1.0).abs() < 1e-4,
            "{name}: {upright} mm^3 upright, {turned} mm^3 turned"
        );
    }
}

/// A URDF names its links' geometry in a few bytes each, and each box is 576 triangles: 4,000
/// boxes (0.7 MB of URDF) would make 2.3 million triangles, past the bound of
/// `MAX_URDF_TRIANGLES`, and is refused with one line naming the file and how far it got, before
/// the mesh is made (60,000 boxes took more than 10 GB before the bound). 1,000 boxes stay under
/// it and load.
#[test]
fn a_urdf_of_too_many_primitives_is_refused_before_its_mesh_is_made() {
    let dir = tempfile::tempdir().unwrap();
    let boxes = |n: usize| -> String {
        let links: String = (0..n)
            .map(|k| {
                format!(
                    "<link name=\"l{k}\"><collision><geometry><box size=\"0.01 0.01 0.01\"/>\
                     </geometry></collision></link>\n"
                )
            })
            .collect();
        let joints: String = (1..n)
            .map(|k| {
                format!(
                    "<joint name=\"j{k}\" type=\"fixed\"><parent link=\"l0\"/><child \
                     link=\"l{k}\"/><origin xyz=\"{} {} 0\"/></joint>\n",
                    0.011 * (k % 100) as f64,
                    0.011 * (k / 100) as f64
                )
            })
            .collect();
        format!("<robot name=\"r\">\n{links}{joints}</robot>\n")
    };
    let limit = grasp_sim::mesh::urdf::MAX_URDF_TRIANGLES;
    assert_eq!(limit, 2_000_000);
    let many = write(dir.path(), "many.urdf", boxes(4000));
    let out = run(&["--no-sim"], &many);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    assert!(
        err.contains("many.urdf")
            && err.contains("more than 2000000 triangles")
            && err.contains("the first 3473 of its 4000 pieces of geometry make 2000448"),
        "{err}"
    );
    let fewer = write(dir.path(), "fewer.urdf", boxes(1000));
    let loaded = grasp_sim::mesh::load_mesh(&fewer, grasp_sim::mesh::LengthUnit::M).unwrap();
    assert_eq!(loaded.mesh.triangles.len(), 1000 * 576);
}
