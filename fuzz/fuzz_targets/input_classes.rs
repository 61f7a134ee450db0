//! The input classes of issue 56's hostile probe, each built from fuzz bytes so that most
//! inputs reach the code they aim at: OBJ files of polygon faces (a face of any size, indices
//! out of range, negative and relative), ASCII STL files of several solids, a scenario's
//! `name`, and a hand's URDF or MJCF tree changed line by line (links reparented into forks
//! and loops, chains of fixed links, joints deleted or duplicated, limits reversed, numbers
//! made huge or not numbers). Each function is the whole check of one target: an error of one
//! line naming the file, or a result that keeps the readers' promises; never a panic.
//!
//! Shared by the cargo-fuzz targets (`obj_polygons`, `stl_solids`, `scenario_name`,
//! `hand_tree`) and the stable-toolchain driver `tests/it/fuzz_drive.rs`, which runs each to
//! 10⁶ mutated inputs without nightly.

use std::path::Path;

/// Bytes read one at a time, zero once they run out.
pub struct Bytes<'a>(&'a [u8]);

impl<'a> Bytes<'a> {
    /// The bytes to read from.
    pub fn new(data: &'a [u8]) -> Self {
        Bytes(data)
    }

    /// The next byte (zero past the end).
    pub fn u8(&mut self) -> u8 {
        match self.0.split_first() {
            Some((&b, rest)) => {
                self.0 = rest;
                b
            }
            None => 0,
        }
    }

    /// The next two bytes, little-endian.
    pub fn u16(&mut self) -> u16 {
        u16::from(self.u8()) | (u16::from(self.u8()) << 8)
    }

    /// Whether bytes remain.
    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }

    /// A coordinate: mostly small integers and halves, sometimes a value a careless file has.
    pub fn number(&mut self) -> String {
        match self.u8() {
            0 => "nan".into(),
            1 => "inf".into(),
            2 => "1e300".into(),
            3 => "-0".into(),
            4 => "5e-324".into(),
            5 => "1e-9".into(),
            b => format!("{}", (i32::from(b) - 128) as f64 / 4.0),
        }
    }
}

/// Asserts that an error is one line and names the file.
fn one_line_naming(message: &str, file: &str) {
    assert!(!message.contains('\n'), "not one line: {message}");
    assert!(message.contains(file), "does not name {file}: {message}");
}

/// An OBJ of up to 64 vertices and faces of 0 to 2999 corners, each corner an index that may
/// be relative, zero or past the end, with `vt`/`vn` parts: read, the error naming the file,
/// or a mesh with finite vertices and no more triangles than the faces' corners allow.
pub fn obj_polygons(data: &[u8]) {
    let mut b = Bytes::new(data);
    let vertices = 3 + usize::from(b.u8() % 62);
    let mut obj = String::new();
    for _ in 0..vertices {
        obj += &format!("v {} {} {}\n", b.number(), b.number(), b.number());
    }
    let mut corners_total = 0usize;
    while !b.is_empty() {
        let size = match b.u8() {
            0 => usize::from(b.u16() % 3000),
            s => usize::from(s % 12),
        };
        corners_total += size;
        obj.push('f');
        for _ in 0..size {
            let c = b.u8();
            let index = match c % 8 {
                0 => -(i64::from(c / 8) + 1),
                1 => 0,
                2 => vertices as i64 + i64::from(c / 8) + 1,
                _ => i64::from(c) % vertices as i64 + 1,
            };
            obj += &match c % 5 {
                0 => format!(" {index}/1"),
                1 => format!(" {index}//1"),
                _ => format!(" {index}"),
            };
        }
        obj.push('\n');
    }
    match grasp_sim::mesh::parse_mesh(
        obj.as_bytes(),
        Path::new("fuzz.obj"),
        grasp_sim::mesh::MeshFormat::Obj,
        grasp_sim::mesh::LengthUnit::Mm,
    ) {
        Ok(loaded) => {
            assert!(loaded
                .mesh
                .vertices
                .iter()
                .all(|p| p.iter().all(|c| c.is_finite())));
            assert!(loaded.mesh.triangles.len() <= corners_total);
        }
        Err(e) => one_line_naming(&e.to_string(), "fuzz.obj"),
    }
}

/// An ASCII STL of one to four solids of up to 16 facets each, names with spaces or none, and
/// sometimes text between the solids or an `endsolid` left out: read, the error naming the
/// file, or, for a well-formed file, every facet of every solid counted.
pub fn stl_solids(data: &[u8]) {
    let mut b = Bytes::new(data);
    let solids = 1 + usize::from(b.u8() % 4);
    let flags = b.u8();
    let mut text = String::new();
    let mut facets = 0usize;
    for s in 0..solids {
        let name = match b.u8() % 4 {
            0 => String::new(),
            1 => format!(" part {s}"),
            2 => " solid".into(),
            _ => format!(" p{s}"),
        };
        text += &format!("solid{name}\n");
        let n = usize::from(b.u8() % 17);
        for _ in 0..n {
            text += "facet normal 0 0 0\n outer loop\n";
            for _ in 0..3 {
                text += &format!("  vertex {} {} {}\n", b.number(), b.number(), b.number());
            }
            text += " endloop\nendfacet\n";
        }
        facets += n;
        if flags & 1 != 0 && s + 1 == solids / 2 + 1 {
            text += "garbage between solids\n";
        }
        if flags & 2 == 0 || s + 1 < solids {
            text += &format!("endsolid{name}\n");
        }
    }
    let well_formed = flags & 3 == 0;
    match grasp_sim::mesh::parse_mesh(
        text.as_bytes(),
        Path::new("fuzz.stl"),
        grasp_sim::mesh::MeshFormat::Stl,
        grasp_sim::mesh::LengthUnit::Mm,
    ) {
        Ok(loaded) => {
            if well_formed {
                assert_eq!(loaded.triangles_read, facets, "{text}");
            }
            assert!(loaded
                .mesh
                .vertices
                .iter()
                .all(|p| p.iter().all(|c| c.is_finite())));
        }
        Err(e) => one_line_naming(&e.to_string(), "fuzz.stl"),
    }
}

/// Any bytes as a scenario's `name` (control characters, `/`, `..`, long names, escaped as
/// TOML needs), the scenario in `scenarios` beside the bundled ones: refused naming `name`,
/// or a name that joined onto a folder stays one name inside it.
pub fn scenario_name(data: &[u8], scenarios: &Path) {
    let raw = String::from_utf8_lossy(data);
    let mut name = String::new();
    for c in raw.chars() {
        match c {
            '"' => name += "\\\"",
            '\\' => name += "\\\\",
            c if c.is_control() => name += &format!("\\u{:04X}", u32::from(c)),
            c => name.push(c),
        }
    }
    let text =
        format!("name = \"{name}\"\n[object]\nmesh = \"../assets/objects/cylinder_d40.stl\"\n");
    let path = scenarios.join("fuzz.toml");
    match grasp_sim::scenario::Scenario::parse(&text, &path) {
        Ok(s) => {
            assert!(grasp_sim::files::folder_name_problem(&s.name).is_none());
            let joined = Path::new("rep").join(&s.name);
            assert_eq!(joined.parent(), Some(Path::new("rep")), "{:?}", s.name);
            assert_eq!(joined.components().count(), 2, "{:?}", s.name);
        }
        Err(e) => {
            let m = e.to_string();
            one_line_naming(&m, "fuzz.toml");
        }
    }
}

/// A hand's URDF or MJCF (`seed`, one element a line) changed line by line as the bytes say,
/// written to `file`: imported, the error naming the file, or a hand model.
pub fn hand_tree(data: &[u8], seed: &str, file: &Path) {
    let mut b = Bytes::new(data);
    let mut lines: Vec<String> = seed.lines().map(str::to_string).collect();
    let names: Vec<String> = lines
        .iter()
        .filter_map(|l| {
            let at = l.find("name=\"")? + 6;
            let end = l[at..].find('"')?;
            Some(l[at..at + end].to_string())
        })
        .collect();
    let is_urdf = seed.contains("<robot");
    let edits = 1 + b.u8() % 6;
    for _ in 0..edits {
        if lines.len() < 3 {
            break;
        }
        let k = 1 + usize::from(b.u8()) % (lines.len() - 2);
        match b.u8() % 8 {
            0 => {
                lines.remove(k);
            }
            1 => {
                let l = lines[k].clone();
                lines.insert(k, l);
            }
            2 => {
                // A name replaced by another's: forks, loops, a link its own parent.
                let other = &names[usize::from(b.u8()) % names.len().max(1)];
                if let Some(at) = lines[k]
                    .rfind("link=\"")
                    .or_else(|| lines[k].find("name=\""))
                {
                    let start = at + lines[k][at..].find('"').unwrap_or(0) + 1;
                    if let Some(end) = lines[k][start..].find('"') {
                        lines[k].replace_range(start..start + end, other);
                    }
                }
            }
            3 => {
                // A number made another: reversed limits, huge, not a number.
                let n = b.number();
                if let Some(at) = lines[k].find(|c: char| c.is_ascii_digit()) {
                    let end = lines[k][at..]
                        .find(|c: char| !(c.is_ascii_digit() || c == '.'))
                        .map_or(lines[k].len(), |e| at + e);
                    lines[k].replace_range(at..end, &n);
                }
            }
            4 => {
                let j = 1 + usize::from(b.u8()) % (lines.len() - 2);
                lines.swap(k, j);
            }
            5 => {
                for (from, to) in [("lower=", "upper="), ("revolute", "fixed")] {
                    if lines[k].contains(from) {
                        lines[k] = lines[k].replacen(from, to, 1);
                    }
                }
            }
            _ => {
                // A chain of fixed links (URDF) or nested bodies (MJCF) above the palm.
                let n = match b.u8() {
                    0 => 2100,
                    c => usize::from(c % 64),
                };
                let mut chain = String::new();
                if is_urdf {
                    for i in 0..n {
                        chain += &format!("<link name=\"c{i}\"/>");
                        let child = if i + 1 < n {
                            format!("c{}", i + 1)
                        } else {
                            "palm".into()
                        };
                        chain += &format!(
                            "<joint name=\"cj{i}\" type=\"fixed\"><parent link=\"c{i}\"/><child link=\"{child}\"/></joint>"
                        );
                    }
                } else {
                    for i in 0..n {
                        chain += &format!("<body name=\"c{i}\">");
                    }
                    chain += &"</body>".repeat(n);
                }
                lines.insert(k, chain);
            }
        }
    }
    let text = lines.join("\n");
    if std::fs::write(file, text).is_err() {
        return;
    }
    let shown = file.file_name().unwrap_or_default().to_string_lossy();
    match grasp_sim::hand::import::load(file, &Default::default(), &[]) {
        Ok(_) => {}
        Err(e) => one_line_naming(&e.to_string(), &shown),
    }
}
