//! Hands read from their URDF or MJCF (issue 37): `[hand] urdf` / `[hand] mjcf`, the mapping
//! found from the tree, `grasp-sim hand show`, and the one-line refusals of files that are not
//! a three-finger, two-flexion hand.

use std::path::{Path, PathBuf};
use std::process::Output;

fn asset(rel: &str) -> PathBuf {
    crate::root().join(rel)
}

/// A scenario for the thesis cup (thesis 5.3) with the `[hand]` section `hand`.
fn cup_scenario(dir: &Path, name: &str, hand: &str) -> PathBuf {
    let p = dir.join(format!("{name}.toml"));
    let text = format!(
        "name = \"{name}\"\n[object]\nframe = \"file\"\nmesh = \"{}\"\nunits = \"mm\"\n\
         density_kg_m3 = 500.0\nfriction = 0.3\n[hand]\n{hand}\n",
        asset("assets/objects/cup.stl").display()
    );
    std::fs::write(&p, text).unwrap();
    p
}

fn run_json(args: &[&str], scenario: &Path) -> serde_json::Value {
    let out = crate::grasp_sim()
        .arg("--json")
        .args(args)
        .arg(scenario)
        .output()
        .unwrap();
    crate::assert_success(&out);
    serde_json::from_slice(&out.stdout).unwrap()
}

/// The planned grasp's palm position, quaternion and joint angles, as numbers.
fn grasp_numbers(v: &serde_json::Value) -> Vec<f64> {
    let g = &v["plan"]["grasp"];
    let mut out: Vec<f64> = Vec::new();
    for key in ["position_mm", "quaternion_wxyz"] {
        out.extend(
            g["palm_pose"][key]
                .as_array()
                .unwrap()
                .iter()
                .map(|x| x.as_f64().unwrap()),
        );
    }
    for f in g["fingers"].as_array().unwrap() {
        out.push(f["theta1_deg"].as_f64().unwrap());
        out.push(f["theta2_deg"].as_f64().unwrap());
    }
    out.push(g["elevation_index"].as_f64().unwrap());
    out
}

fn assert_same_grasp(a: &[f64], b: &[f64], what: &str) {
    assert_eq!(a.len(), b.len(), "{what}");
    for (x, y) in a.iter().zip(b) {
        assert!((x - y).abs() < 1e-6, "{what}: {a:?}\nagainst {b:?}");
    }
}

/// The BarrettHand BH8 written from its manual, as URDF and as MJCF: both derive bh8.toml's
/// model (the same grasp of the cup, to round-off), hold the cup, and report the TorqueSwitch
/// coupling the plan breaks (checked, not refused).
#[test]
fn the_bh8_urdf_and_mjcf_plan_the_bh8_grasp_and_hold_the_cup() {
    let dir = tempfile::tempdir().unwrap();
    let toml = cup_scenario(dir.path(), "toml", "file = \"bh8\"");
    let reference = grasp_numbers(&run_json(&["--no-sim"], &toml));
    for (key, file) in [("urdf", "bh8.urdf"), ("mjcf", "bh8.xml")] {
        let hand = format!("{key} = \"{}\"", asset("assets/hands").join(file).display());
        let s = cup_scenario(dir.path(), key, &hand);
        let v = run_json(&[], &s);
        assert_same_grasp(&grasp_numbers(&v), &reference, file);
        assert_eq!(v["sim"]["verdict"], "hold", "{file}: {}", v["sim"]);
        let warnings: Vec<&str> = v["warnings"]
            .as_array()
            .unwrap()
            .iter()
            .filter_map(|w| w.as_str())
            .filter(|w| w.contains("coupling"))
            .collect();
        assert_eq!(warnings.len(), 3, "{file}: {warnings:?}");
        assert!(
            warnings
                .iter()
                .all(|w| w.contains("breaks it by") && w.contains("checked, not refused")),
            "{warnings:?}"
        );
    }
}

/// The bundled thesis hand exported by `--export-urdf` and read back by `[hand] urdf` plans the
/// cup as its TOML does (palm pose, joint angles), and so it does mounted behind an extra link
/// turned and moved (with geometry of its own, which is not the palm's).
#[test]
fn the_thesis_hand_round_trips_through_its_urdf_also_mounted() {
    let dir = tempfile::tempdir().unwrap();
    let toml = cup_scenario(dir.path(), "cup", "file = \"thesis\"");
    let export = dir.path().join("export");
    let v = run_json(
        &["--no-sim", "--export-urdf", export.to_str().unwrap()],
        &toml,
    );
    let reference = grasp_numbers(&v);
    let urdf = export.join("cup").join("hand.urdf");
    let s = cup_scenario(
        dir.path(),
        "back",
        &format!("urdf = \"{}\"", urdf.display()),
    );
    assert_same_grasp(
        &grasp_numbers(&run_json(&["--no-sim"], &s)),
        &reference,
        "read back",
    );
    let text = std::fs::read_to_string(&urdf).unwrap();
    let mounted = text.replacen(
        "<link name=\"palm\">",
        "<link name=\"flange\"><collision><geometry><box size=\"0.3 0.3 0.05\"/></geometry>\
         </collision></link>\n  <joint name=\"mount\" type=\"fixed\"><parent link=\"flange\"/>\
         <child link=\"palm\"/><origin xyz=\"0.1 -0.2 0.4\" rpy=\"0.7 -1.1 2.3\"/></joint>\n  \
         <link name=\"palm\">",
        1,
    );
    assert_ne!(mounted, text);
    let m = dir.path().join("mounted.urdf");
    std::fs::write(&m, mounted).unwrap();
    let s = cup_scenario(
        dir.path(),
        "mounted",
        &format!("urdf = \"{}\"", m.display()),
    );
    assert_same_grasp(
        &grasp_numbers(&run_json(&["--no-sim"], &s)),
        &reference,
        "mounted",
    );
}

/// The Schunk SDH-2 written from SCHUNK's published numbers, as URDF and as MJCF: its distal
/// joint closes at most 90°, so resting on its palm it wraps nothing under 89 mm and the cup
/// (56-80 mm) is ungraspable; with the palm stand-off the importer gives it, both files plan the
/// same grasp of the cup with the palm held off it, between the phalanges, and the grasp holds.
#[test]
fn the_sdh2_urdf_and_mjcf_hold_the_cup_between_the_phalanges() {
    let dir = tempfile::tempdir().unwrap();
    // 3 mm divides the SDH-2's 33 mm finger gap; a 10° open margin (docs/SCENARIO.md, palm
    // stand-off).
    let rest = "[planner]\nheight_step_mm = 3.0\n[sim]\nopen_margin_deg = 10.0";
    let mut grasps = Vec::new();
    for (key, file) in [("urdf", "sdh2.urdf"), ("mjcf", "sdh2.xml")] {
        let path = asset("assets/hands").join(file);
        let hand = format!("{key} = \"{}\"\n{rest}", path.display());
        let v = run_json(&[], &cup_scenario(dir.path(), key, &hand));
        let g = &v["plan"]["grasp"];
        let standoff = g["palm_standoff_mm"].as_f64().unwrap();
        assert!(
            (2.0..=43.0).contains(&standoff),
            "{file}: stand-off {standoff}"
        );
        // Every distal joint within its 90° of closing.
        for f in g["fingers"].as_array().unwrap() {
            assert!(f["theta2_deg"].as_f64().unwrap() >= 90.0, "{file}: {f}");
        }
        assert_eq!(v["sim"]["verdict"], "hold", "{file}: {}", v["sim"]);
        assert!(v["sim"]["closing"]["shift_mm"].as_f64().unwrap() < 5.0);
        grasps.push(grasp_numbers(&v));
        assert_eq!(g["rules"], "thesis", "{file}");
        // Without the stand-off (the thesis's model), the thesis's rules find the cup too thin
        // for the hand, and only the extended rules' fingertip pinch is left.
        let hand = format!(
            "{key} = \"{}\"\noverrides = {{ \"palm.standoff_max_mm\" = 0.0 }}\n{rest}",
            path.display()
        );
        let v = run_json(&["--no-sim"], &cup_scenario(dir.path(), "off", &hand));
        let reason = v["plan"]["axes"][0]["reason"].as_str().unwrap();
        assert!(
            reason.contains("below the smallest graspable diameter 89."),
            "{file}: {reason}"
        );
        let g = &v["plan"]["grasp"];
        assert!(g["palm_standoff_mm"].is_null(), "{file}: {g}");
        assert_eq!(g["rules"], "extended", "{file}: {g}");
    }
    assert_same_grasp(&grasps[0], &grasps[1], "sdh2.xml against sdh2.urdf");
    let out = crate::succeed(crate::grasp_sim().args([
        "hand",
        "show",
        asset("assets/hands/sdh2.urdf").to_str().unwrap(),
        "--svg",
        dir.path().join("sdh2.svg").to_str().unwrap(),
    ]));
    let table = String::from_utf8_lossy(&out.stdout);
    for row in [
        "phalanx_1.length_mm                86.500",
        "phalanx_2.length_mm                68.500",
        "joints.lateral_mm                  28.580",
        "joints.setback_mm                  14.000",
        "palm.standoff_max_mm               43.000",
        "joints.theta2_range_deg         [90.00, 180.00]",
        "wrap no object under 89.",
    ] {
        assert!(table.contains(row), "`{row}` not in\n{table}");
    }
}

/// `hand show` prints the derived table and writes the figure.
#[test]
fn hand_show_prints_the_model_and_writes_its_figure() {
    let dir = tempfile::tempdir().unwrap();
    let svg = dir.path().join("bh8.svg");
    let out = crate::succeed(crate::grasp_sim().args([
        "hand",
        "show",
        asset("assets/hands/bh8.urdf").to_str().unwrap(),
        "--svg",
        svg.to_str().unwrap(),
    ]));
    let table = String::from_utf8_lossy(&out.stdout);
    for row in [
        "phalanx_1.length_mm                70.000",
        "phalanx_2.length_mm                50.000",
        "joints.lateral_mm                  50.000",
        "joints.theta1_range_deg         [40.00, 180.00]",
        "joints.theta2_range_deg         [90.00, 138.00]",
        "finger_2  f3_joint_1",
    ] {
        assert!(table.contains(row), "`{row}` not in\n{table}");
    }
    let figure = std::fs::read_to_string(&svg).unwrap();
    assert!(figure.contains("<svg") && figure.matches("<polygon").count() > 20);
}

/// Runs `grasp-sim --no-sim` on a cup scenario whose hand is the file `name` with `text`;
/// returns the output.
fn refused(dir: &Path, name: &str, text: &str, key: &str) -> Output {
    let f = dir.join(name);
    std::fs::write(&f, text).unwrap();
    let s = cup_scenario(dir, "bad", &format!("{key} = \"{}\"", f.display()));
    crate::grasp_sim().arg("--no-sim").arg(&s).output().unwrap()
}

/// Malformed hand files, each refused with one line naming the file, its line where there is
/// one, and what was expected; exit 2.
#[test]
fn malformed_hand_files_are_refused_with_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let toml = cup_scenario(dir.path(), "cup", "file = \"thesis\"");
    let export = dir.path().join("export");
    run_json(
        &["--no-sim", "--export-urdf", export.to_str().unwrap()],
        &toml,
    );
    let good = std::fs::read_to_string(export.join("cup").join("hand.urdf")).unwrap();
    // A fourth finger: finger_1's links and joints again under other names.
    let start = good.find("  <link name=\"finger_1_phalanx_1\">").unwrap();
    let end = good.find("  <link name=\"finger_2_phalanx_1\">").unwrap();
    let extra = good[start..end].replace("finger_1", "finger_4");
    let four = good.replacen("</robot>", &format!("{extra}</robot>"), 1);
    // A loop: finger_1's phalanx 2 given a second parent.
    let looped = good.replacen(
        "</robot>",
        "  <joint name=\"back\" type=\"fixed\"><parent link=\"finger_3_phalanx_2\"/><child \
         link=\"finger_1_phalanx_2\"/></joint>\n</robot>",
        1,
    );
    // A missing joint: finger_2 without its joint 2 (its phalanx 2 a second root).
    let js = good.find("  <joint name=\"finger_2_joint_2\"").unwrap();
    let je = js + good[js..].find("</joint>").unwrap() + "</joint>\n".len();
    let missing = format!("{}{}", &good[..js], &good[je..]);
    // A mesh that is not there, as the palm's collision geometry.
    let no_mesh = good.replacen(
        "<collision><origin xyz=\"0.005000000 0.000000000 0.000000000\"/><geometry><box",
        "<collision><origin xyz=\"0.005000000 0.000000000 0.000000000\"/><geometry><mesh \
         filename=\"meshes/palm.stl\"/><box",
        1,
    );
    assert_ne!(no_mesh, good);
    let mjcf_loop = std::fs::read_to_string(asset("assets/hands/bh8.xml"))
        .unwrap()
        .replacen(
            "<equality>",
            "<equality>\n    <connect body1=\"f1_link_2\" body2=\"f3_link_2\" anchor=\"0 0 0\"/>",
            1,
        );
    let table: [(&str, &str, String, &str); 5] = [
        ("four.urdf", "urdf", four, "carries 4 fingers"),
        ("loop.urdf", "urdf", looped, "has two parent joints"),
        ("missing.urdf", "urdf", missing, "both have no parent"),
        (
            "nomesh.urdf",
            "urdf",
            no_mesh,
            "mesh meshes/palm.stl not found",
        ),
        ("loop.xml", "mjcf", mjcf_loop, "closes a loop"),
    ];
    for (name, key, text, expected) in table {
        let out = refused(dir.path(), name, &text, key);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{name}: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{name}: {err}");
        assert!(
            err.contains(name) && err.contains(expected),
            "{name}: {err}"
        );
        assert!(err.contains(": line "), "{name}: {err}");
        if name != "nomesh.urdf" {
            assert!(err.contains("expected"), "{name}: {err}");
        }
    }
}

/// `[hand.mapping]`: the BarrettHand's own finger names put F1 first (`hand show SCENARIO`
/// shows it, and the plan is the same hand's); a thumb that is not the opposing finger, a
/// joint the file does not have, and a spread held where the fingers no longer flex in
/// parallel planes are refused with one line.
#[test]
fn a_mapping_names_the_fingers_or_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let urdf = asset("assets/hands/bh8.urdf");
    let hand = |mapping: &str| format!("urdf = \"{}\"\n[hand.mapping]\n{mapping}", urdf.display());
    let named = cup_scenario(
        dir.path(),
        "named",
        &hand(
            "finger_1 = [\"f1_joint_1\", \"f1_joint_2\"]\nthumb = [\"f3_joint_1\", \"f3_joint_2\"]\n\
             spread = { f1_spread = 0.0 }",
        ),
    );
    let out = crate::succeed(
        crate::grasp_sim()
            .args(["hand", "show"])
            .arg(&named)
            .args(["--svg", dir.path().join("n.svg").to_str().unwrap()]),
    );
    let table = String::from_utf8_lossy(&out.stdout);
    assert!(
        table.contains("finger_1  f1_joint_1") && table.contains("finger_3  f2_joint_1"),
        "{table}"
    );
    let v = run_json(&["--no-sim"], &named);
    assert_eq!(v["plan"]["status"], "feasible");
    for (name, mapping, expected) in [
        (
            "thumb",
            "thumb = [\"f1_joint_1\", \"f1_joint_2\"]",
            "expected the opposing finger",
        ),
        (
            "missing",
            "finger_1 = [\"f1_joint_1\", \"no_such_joint\"]",
            "which the file does not have",
        ),
        (
            "spread",
            "spread = { f1_spread = 30.0 }",
            "expected every finger to flex in parallel planes",
        ),
    ] {
        let s = cup_scenario(dir.path(), name, &hand(mapping));
        let out = crate::grasp_sim().arg("--no-sim").arg(&s).output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{name}: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{name}: {err}");
        assert!(
            err.contains("bh8.urdf") && err.contains(expected),
            "{name}: {err}"
        );
    }
}

/// The SDH-2 with its proximal links as meshes (an octagonal prism, the box's extents with its
/// four long edges chamfered 5 mm): the model is the box file's (the same extents), but the
/// physics check and `--export-mjcf` use the meshes' hulls: each proximal link's collider is the
/// prism (its volume, its place about its joint), the exported scene carries the meshes, and the
/// check's closing differs from the boxes' while the cup is still held.
#[test]
fn link_meshes_are_the_colliders_of_their_bodies() {
    use grasp_sim::hand::import::{load, Mapping};
    let dir = tempfile::tempdir().unwrap();
    let (hx, hy, l, c) = (0.01465, 0.0139, 0.0865, 0.005);
    let ring = [
        (hx - c, hy),
        (hx, hy - c),
        (hx, -(hy - c)),
        (hx - c, -hy),
        (-(hx - c), -hy),
        (-hx, -(hy - c)),
        (-hx, hy - c),
        (-(hx - c), hy),
    ];
    let mut obj = String::new();
    for z in [0.0, l] {
        for (x, y) in ring {
            obj.push_str(&format!("v {x} {y} {z}\n"));
        }
    }
    for k in 0..8 {
        let (a, b) = (k + 1, (k + 1) % 8 + 1);
        obj.push_str(&format!("f {a} {b} {}\nf {a} {} {}\n", b + 8, b + 8, a + 8));
    }
    obj.push_str("f 1 2 3 4 5 6 7 8\nf 16 15 14 13 12 11 10 9\n");
    std::fs::write(dir.path().join("proximal.obj"), obj).unwrap();
    let boxes = std::fs::read_to_string(asset("assets/hands/sdh2.urdf")).unwrap();
    let box_geom =
        "<origin xyz=\"0.000000 0.0 0.043250\"/><geometry><box size=\"0.029300 0.0278 0.0865\"/>";
    assert_eq!(boxes.matches(box_geom).count(), 3);
    let meshes = boxes.replace(box_geom, "<geometry><mesh filename=\"proximal.obj\"/>");
    let file = dir.path().join("sdh2_mesh.urdf");
    std::fs::write(&file, meshes).unwrap();
    let d = load(&file, &Mapping::default(), &[]).unwrap();
    let reference = load(&asset("assets/hands/sdh2.urdf"), &Mapping::default(), &[]).unwrap();
    assert!(reference.hand.link_geometry.is_none());
    assert!(
        d.notes.iter().any(|n| n.contains("links with meshes")),
        "{:?}",
        d.notes
    );
    let area = 4.0 * hx * hy - 2.0 * c * c;
    for (k, f) in d.hand.finger_list.iter().enumerate() {
        let shapes = grasp_sim::sim::hand_shapes::link_shapes(&d.hand, 1 + 2 * k).unwrap();
        assert_eq!(shapes.len(), 1);
        let hull = shapes[0].as_convex_polyhedron().unwrap();
        assert_eq!(hull.points().len(), 16, "{}", f.name);
        let volume = f64::from(shapes[0].mass_properties(1.0).mass());
        assert!(
            (volume - area * l).abs() < 1e-3 * area * l,
            "{volume} vs {}",
            area * l
        );
        // Along the phalanx (the body's y on its side, from its joint) and across it.
        let aabb = shapes[0].compute_local_aabb();
        let s = f.side.sign();
        let (lo, hi) = (aabb.mins, aabb.maxs);
        let (from, to) = if s > 0.0 {
            (lo.y, hi.y)
        } else {
            (-hi.y, -lo.y)
        };
        let near = |a: f32, b: f64| (f64::from(a) - b).abs() < 1e-5;
        assert!(
            near(from, 0.0) && near(to, l) && near(hi.x, hx) && near(lo.x, -hx),
            "{}: {lo:?} {hi:?}",
            f.name
        );
        assert!(
            near(hi.z, hy) && near(lo.z, -hy),
            "{}: {lo:?} {hi:?}",
            f.name
        );
        // The distal links stay the model's boxes.
        assert!(grasp_sim::sim::hand_shapes::link_shapes(&d.hand, 2 + 2 * k).is_none());
    }
    assert!(grasp_sim::sim::hand_shapes::link_shapes(&d.hand, 0).is_none());
    // Planned as the box file (the same model); checked with the prisms.
    let rest = "[planner]\nheight_step_mm = 3.0\n[sim]\nopen_margin_deg = 10.0";
    let run = |f: &Path, name: &str| {
        let hand = format!("urdf = \"{}\"\n{rest}", f.display());
        let export = dir.path().join(format!("x_{name}"));
        let v = run_json(
            &["--export-mjcf", export.to_str().unwrap()],
            &cup_scenario(dir.path(), name, &hand),
        );
        let scene = std::fs::read_to_string(export.join(name).join("scene.xml")).unwrap();
        (v, scene)
    };
    let (vb, sb) = run(&asset("assets/hands/sdh2.urdf"), "boxes");
    let (vm, sm) = run(&file, "meshes");
    assert_same_grasp(
        &grasp_numbers(&vm),
        &grasp_numbers(&vb),
        "meshes against boxes",
    );
    assert_eq!(vm["sim"]["verdict"], "hold", "{}", vm["sim"]);
    assert!(!sb.contains("type=\"mesh\" mesh=\"hand_"));
    for f in ["finger_1", "finger_2", "finger_3"] {
        let name = format!("hand_{f}_phalanx_1_0");
        assert!(
            sm.contains(&format!("<mesh name=\"{name}\" vertex=\"")),
            "{name}"
        );
        assert!(sm.contains(&format!(
            "<geom name=\"{name}\" type=\"mesh\" mesh=\"{name}\""
        )));
    }
    let finals = |v: &serde_json::Value| v["sim"]["closing"]["fingers"].to_string();
    assert_ne!(finals(&vm), finals(&vb));
}

/// A hand file of many elements, each on a line of its own: the readers name the right line
/// deep in it, and a hand of more links than any hand has is refused as its elements are
/// counted, before any is read (80,000 fixed links, 8.8 MB, were read for minutes before:
/// every line named was counted from the start of the file).
#[test]
fn lines_deep_in_a_large_hand_file_are_named_and_a_huge_one_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let src = std::fs::read_to_string(asset("assets/hands/bh8.urdf")).unwrap();
    let at = src.find("<robot").unwrap();
    let at = at + src[at..].find('>').unwrap() + 1;
    let chain = |n: usize| -> String {
        (0..n)
            .map(|k| {
                let child = if k + 1 < n {
                    format!("c{}", k + 1)
                } else {
                    "palm".to_string()
                };
                format!(
                    "\n<link name=\"c{k}\"/>\n<joint name=\"cj{k}\" type=\"fixed\"><parent \
                     link=\"c{k}\"/><child link=\"{child}\"/></joint>"
                )
            })
            .collect()
    };
    // 1500 links above the palm, then a second parent for finger 1's phalanx 2 on a known line.
    let text = format!(
        "{}{}{}",
        &src[..at],
        chain(1500),
        src[at..].replacen(
            "</robot>",
            "<joint name=\"back\" type=\"fixed\"><parent link=\"c0\"/><child \
             link=\"c1\"/></joint>\n</robot>",
            1
        )
    );
    let line = 1 + text[..text.find("<joint name=\"back\"").unwrap()]
        .matches('\n')
        .count();
    assert!(line > 3000, "{line}");
    let out = refused(dir.path(), "deep.urdf", &text, "urdf");
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("deep.urdf") && err.contains(&format!("line {line}")),
        "line {line} not named: {err}"
    );
    let huge = format!("{}{}{}", &src[..at], chain(80_000), &src[at..]);
    assert!(huge.len() > 8_000_000);
    let out = refused(dir.path(), "huge.urdf", &huge, "urdf");
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    let links = 80_000 + src.matches("<link ").count();
    assert!(
        err.contains("huge.urdf") && err.contains(&format!("{links} links, more than the 2000")),
        "{err}"
    );
}
