//! Reading mesh files into a validated [`Mesh`] in millimetres: STL (binary or ASCII, through
//! `stl_io`), Wavefront OBJ (through `tobj`: every object and group in the file is one mesh,
//! polygons are fan-triangulated) and PLY (ASCII or binary, through `ply-rs-bw`: the `vertex`
//! element's `x`, `y`, `z` and the `face` element's `vertex_indices` list, polygons
//! fan-triangulated). The format is chosen by the file name's extension and checked against the
//! content; every format goes through the same validation.
//!
//! Format detection does not trust the first five bytes: a binary file whose 80-byte header
//! happens to begin with "solid" is common (several CAD exporters write one), so a file whose size
//! is exactly `84 + 50 × count` is read as binary whatever its header says.

use super::{Mesh, MeshError, Topology};
use nalgebra::Point3;
use serde::Deserialize;
use std::path::Path;

/// Coordinates beyond this magnitude are rejected: 1000 km is no graspable object, and cubing
/// such values in the mass properties would lose all precision.
const COORDINATE_LIMIT_MM: f64 = 1e9;

/// The length unit of a mesh file's coordinates.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum LengthUnit {
    /// Millimetres (the default, and the planner's unit).
    #[default]
    Mm,
    /// Metres.
    M,
    /// Centimetres.
    Cm,
    /// Inches (25.4 mm).
    Inch,
}

impl LengthUnit {
    /// Every unit, smallest first.
    pub const ALL: [LengthUnit; 4] = [
        LengthUnit::Mm,
        LengthUnit::Cm,
        LengthUnit::Inch,
        LengthUnit::M,
    ];

    /// The unit named `name` as scenarios and `--units` name it.
    pub fn from_name(name: &str) -> Option<LengthUnit> {
        LengthUnit::ALL.into_iter().find(|u| u.name() == name)
    }

    /// The unit as scenarios and `--units` name it.
    pub fn name(self) -> &'static str {
        match self {
            LengthUnit::Mm => "mm",
            LengthUnit::Cm => "cm",
            LengthUnit::M => "m",
            LengthUnit::Inch => "inch",
        }
    }

    /// Millimetres per unit.
    pub fn to_mm(self) -> f64 {
        match self {
            LengthUnit::Mm => 1.0,
            LengthUnit::M => 1000.0,
            LengthUnit::Cm => 10.0,
            LengthUnit::Inch => 25.4,
        }
    }
}

/// A mesh as loaded, with what validation found that is worth a warning.
#[derive(Debug, Clone)]
pub struct LoadedMesh {
    /// The welded mesh in millimetres, outward-wound.
    pub mesh: Mesh,
    /// Triangles in the file.
    pub triangles_read: usize,
    /// Zero-area triangles dropped.
    pub degenerate_dropped: usize,
    /// Triangles dropped because the file has the same face (the same three corners, wound the
    /// same way) earlier: kept, they would count its volume and mass twice.
    pub duplicates_dropped: usize,
    /// Edge statistics of what was kept, as the file has it (before small holes are closed).
    pub topology: Topology,
    /// Holes closed because their boundary spans at most `SMALL_HOLE_MM`: a missing triangle,
    /// a perforation, a scan's pinhole.
    pub holes_filled: usize,
    /// True if and only if the file was wound inside-out and grasp-sim flipped it.
    pub was_inverted: bool,
    /// True if and only if the file was binary (STL or PLY).
    pub is_binary: bool,
    /// The file's format.
    pub format: MeshFormat,
    /// The unit the file was read in.
    pub unit: LengthUnit,
    /// What reading the file chose that a user should know (a URDF link whose collision
    /// geometry stood in for its visual one), as warnings.
    pub notes: Vec<String>,
    /// The mass the file gives `[kg]` (a URDF's links' `<inertial>` masses, summed), if any.
    pub mass_kg: Option<f64>,
}

/// A hole in the surface whose boundary spans at most this is closed at load time `[mm]`: the
/// thesis hand's finger is 14 mm wide, so no finger enters it, and the slices then close (a
/// larger opening, such as a cup's rim, stays open).
pub const SMALL_HOLE_MM: f64 = 14.0;

/// Objects smaller than this along their largest extent are implausible for a hand `[mm]`.
const PLAUSIBLE_MIN_MM: f64 = 5.0;
/// Objects larger than this along their largest extent are implausible for a hand `[mm]`.
const PLAUSIBLE_MAX_MM: f64 = 2000.0;

/// A mesh file format grasp-sim reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MeshFormat {
    /// STL, binary or ASCII.
    Stl,
    /// Wavefront OBJ.
    Obj,
    /// PLY (Stanford polygon format), ASCII or binary.
    Ply,
    /// URDF: the meshes and shapes of its links, placed (`mesh::urdf`).
    Urdf,
}

impl MeshFormat {
    /// The format named by `path`'s extension (case-insensitive), if grasp-sim reads it.
    pub fn from_path(path: &Path) -> Option<MeshFormat> {
        match path.extension()?.to_str()?.to_ascii_lowercase().as_str() {
            "stl" => Some(MeshFormat::Stl),
            "obj" => Some(MeshFormat::Obj),
            "ply" => Some(MeshFormat::Ply),
            "urdf" => Some(MeshFormat::Urdf),
            _ => None,
        }
    }

    /// The lower-case extension.
    pub fn as_str(self) -> &'static str {
        match self {
            MeshFormat::Stl => "stl",
            MeshFormat::Obj => "obj",
            MeshFormat::Ply => "ply",
            MeshFormat::Urdf => "urdf",
        }
    }
}

/// Reads and validates a mesh file (STL, OBJ or PLY, by extension), scaling its coordinates to
/// millimetres; or the object a URDF describes (its lengths in metres, whatever `unit` says).
///
/// # Errors
/// Every [`MeshError`] names `path`: an unknown extension, content of another format, and the
/// errors of [`load_stl`] and [`parse_mesh`].
pub fn load_mesh(path: &Path, unit: LengthUnit) -> Result<LoadedMesh, MeshError> {
    let format = file_format(path)?;
    if format == MeshFormat::Urdf {
        let mut loaded = super::urdf::load_urdf(path)?;
        // Millimetres is the default, so only another unit was asked for (`--units`).
        if unit != LengthUnit::Mm && unit != LengthUnit::M {
            loaded.notes.push(format!(
                "units \"{}\" do not apply to a URDF: its lengths are metres (its meshes' \
                 `scale` gives their unit)",
                unit.name()
            ));
        }
        return Ok(loaded);
    }
    parse_mesh(&read_bytes(path)?, path, format, unit)
}

/// The format of the mesh file at `path`, by its extension; an error for a folder or an
/// extension grasp-sim does not read.
fn file_format(path: &Path) -> Result<MeshFormat, MeshError> {
    if path.is_dir() {
        return Err(MeshError::IsDirectory {
            path: path.to_path_buf(),
        });
    }
    MeshFormat::from_path(path).ok_or_else(|| MeshError::UnknownFormat {
        path: path.to_path_buf(),
    })
}

fn read_bytes(path: &Path) -> Result<Vec<u8>, MeshError> {
    crate::files::read_regular(path, crate::files::MAX_MESH_BYTES).map_err(|e| MeshError::Io {
        path: path.to_path_buf(),
        error: e,
    })
}

/// Parses mesh bytes of the given format; `path` is only used in messages.
///
/// # Errors
/// As [`load_mesh`]: the content must match `format`, and pass the same validation as STL.
pub fn parse_mesh(
    bytes: &[u8],
    path: &Path,
    format: MeshFormat,
    unit: LengthUnit,
) -> Result<LoadedMesh, MeshError> {
    let (raw, is_binary) = parse_raw(bytes, path, format)?;
    build(raw, path, unit, is_binary, format)
}

/// A mesh file's triangles as it has them (no unit, welding or repair), its format chosen by
/// the extension and checked against the content: what a URDF's meshes are read with before
/// they are scaled and placed.
///
/// # Errors
/// As [`load_mesh`], but for the validation of the mesh as a whole.
pub(super) fn load_raw(path: &Path) -> Result<Raw, MeshError> {
    let format = file_format(path)?;
    let (raw, is_binary) = parse_raw(&read_bytes(path)?, path, format)?;
    if let Some(i) = raw
        .iter()
        .position(|t| t.iter().flatten().any(|c| !c.is_finite()))
    {
        return Err(MeshError::NonFinite {
            path: path.to_path_buf(),
            triangle: i,
        });
    }
    if raw.is_empty() {
        return Err(MeshError::NoTriangles {
            path: path.to_path_buf(),
        });
    }
    Ok((raw, is_binary))
}

/// The bytes after a UTF-8 byte-order mark, which some editors write at the start of a text
/// file (OBJ, ASCII STL, PLY's header): left in, it hides the first line from the parsers (an
/// OBJ's first vertex, shifting every index) or makes an ASCII STL look binary. A binary STL
/// whose header happens to begin with those bytes keeps them: its size says it is binary.
fn without_bom(bytes: &[u8]) -> &[u8] {
    let binary_stl_size = bytes.len() >= 84
        && 84
            + 50 * u64::from(u32::from_le_bytes([
                bytes[80], bytes[81], bytes[82], bytes[83],
            ]))
            == bytes.len() as u64;
    match bytes.strip_prefix(b"\xEF\xBB\xBF") {
        Some(rest) if !binary_stl_size => rest,
        _ => bytes,
    }
}

fn parse_raw(bytes: &[u8], path: &Path, format: MeshFormat) -> Result<Raw, MeshError> {
    let bytes = without_bom(bytes);
    if bytes.is_empty() {
        return Err(MeshError::Empty {
            path: path.to_path_buf(),
        });
    }
    let looks = looks_like(bytes);
    let mismatch = |found: &str| MeshError::FormatMismatch {
        path: path.to_path_buf(),
        named: format.as_str().to_string(),
        found: found.to_string(),
    };
    match (format, looks) {
        (MeshFormat::Stl, Some(MeshFormat::Stl) | None) => stl_raw(bytes, path),
        (MeshFormat::Obj, Some(MeshFormat::Obj) | None) => obj_raw(bytes, path),
        (MeshFormat::Ply, Some(MeshFormat::Ply)) => ply_raw(bytes, path),
        (MeshFormat::Urdf, _) => Err(MeshError::Urdf {
            path: path.to_path_buf(),
            detail: "a URDF is read from its file, beside the meshes it names".to_string(),
        }),
        (MeshFormat::Ply, _) => Err(MeshError::Ply {
            path: path.to_path_buf(),
            detail: "does not begin with the `ply` line every PLY file starts with".to_string(),
        }),
        (_, Some(found)) => Err(mismatch(match found {
            MeshFormat::Stl => "STL",
            MeshFormat::Obj => "OBJ",
            MeshFormat::Ply => "PLY",
            MeshFormat::Urdf => "URDF",
        })),
    }
}

/// What the content looks like, when it is clear: PLY by its magic line, binary STL by its size,
/// ASCII STL by "solid ... facet", OBJ by vertex and face lines.
fn looks_like(bytes: &[u8]) -> Option<MeshFormat> {
    let head = String::from_utf8_lossy(&bytes[..bytes.len().min(4096)]);
    let first = head.lines().next().unwrap_or("").trim();
    if first == "ply" {
        return Some(MeshFormat::Ply);
    }
    if bytes.len() >= 84 {
        let n = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]);
        if bytes.len() as u64 == 84 + 50 * u64::from(n) {
            return Some(MeshFormat::Stl);
        }
    }
    if head.trim_start().starts_with("solid") && head.contains("facet") {
        return Some(MeshFormat::Stl);
    }
    let mut tokens = head.lines().filter_map(|l| l.split_whitespace().next());
    if tokens.clone().any(|t| t == "v") && tokens.any(|t| t == "f") {
        return Some(MeshFormat::Obj);
    }
    None
}

/// Checks OBJ text for what tobj reports without a line (a coordinate that is not a finite
/// number, a face with an index past the vertex list or of 0), so the error can name the line.
fn check_obj_lines(text: &str, path: &Path) -> Result<(), MeshError> {
    let err = |line: usize, detail: String| MeshError::Obj {
        path: path.to_path_buf(),
        line: Some(line),
        detail,
    };
    let total = text
        .lines()
        .filter(|l| l.split_whitespace().next() == Some("v"))
        .count();
    let mut seen = 0usize;
    for (i, line) in text.lines().enumerate() {
        let n = i + 1;
        let mut t = line.split_whitespace();
        match t.next() {
            Some("v") => {
                seen += 1;
                let coords: Vec<&str> = t.take(3).collect();
                if coords.len() < 3 {
                    return Err(err(n, "a vertex needs three coordinates".to_string()));
                }
                for c in coords {
                    match c.parse::<f64>() {
                        Ok(v) if v.is_finite() => {}
                        Ok(_) => {
                            return Err(err(n, format!("vertex coordinate `{c}` is not finite")))
                        }
                        Err(_) => {
                            return Err(err(n, format!("vertex coordinate `{c}` is not a number")))
                        }
                    }
                }
            }
            Some("f") => {
                let corners: Vec<&str> = t.collect();
                if corners.len() < 3 {
                    return Err(err(n, "a face needs at least three vertices".to_string()));
                }
                if corners.len() > MAX_POLYGON_VERTICES {
                    return Err(err(n, polygon_too_large(corners.len())));
                }
                for c in corners {
                    let v = c.split('/').next().unwrap_or("");
                    let k: i64 = v
                        .parse()
                        .map_err(|_| err(n, format!("face vertex `{c}` is not an index")))?;
                    let ok = match k {
                        0 => false,
                        k if k > 0 => (k as u64) <= total as u64,
                        k => k.unsigned_abs() <= seen as u64,
                    };
                    if !ok {
                        return Err(err(
                            n,
                            format!(
                                "face refers to vertex {k}, but the file has {total} vertices \
                                 (OBJ indices start at 1; negative ones count back from the \
                                 last vertex so far)"
                            ),
                        ));
                    }
                }
            }
            _ => {}
        }
    }
    Ok(())
}

/// The sum of the absolute volumes of the tetrahedra of `mesh`'s triangles about its bounding
/// box's centre `[mm³]`: the scale of the rounding in its signed volume.
fn volume_terms(mesh: &Mesh) -> f64 {
    let (lo, hi) = mesh.bounds();
    let c = nalgebra::center(&lo, &hi);
    (0..mesh.triangles.len())
        .map(|t| {
            let [a, b, d] = mesh.corners(t).map(|p| p - c);
            a.dot(&b.cross(&d)).abs() / 6.0
        })
        .sum()
}

/// The most vertices one polygon of an OBJ or PLY face may have. A polygon is fanned into
/// triangles from its first vertex, so a cap of n vertices becomes n − 2 slivers meeting at one
/// point; a 100,000-vertex cap (issue 56) took the physics check's collider past 4 GB. 1024
/// is far above any polygon a modeller writes (a cylinder's cap of 256 segments is common).
pub const MAX_POLYGON_VERTICES: usize = 1024;

/// The message for a face of `n` vertices, past [`MAX_POLYGON_VERTICES`].
fn polygon_too_large(n: usize) -> String {
    format!(
        "a face of {n} vertices, more than the {MAX_POLYGON_VERTICES} a polygon may have \
         (it is fanned into {} sliver triangles); triangulate it first",
        n - 2
    )
}

/// Triangles as a file has them, and whether it was binary.
pub(super) type Raw = (Vec<[[f32; 3]; 3]>, bool);

fn obj_raw(bytes: &[u8], path: &Path) -> Result<Raw, MeshError> {
    let text = std::str::from_utf8(bytes).map_err(|e| MeshError::Obj {
        path: path.to_path_buf(),
        line: Some(
            bytes[..e.valid_up_to()]
                .iter()
                .filter(|&&b| b == b'\n')
                .count()
                + 1,
        ),
        detail: "not UTF-8 text".to_string(),
    })?;
    check_obj_lines(text, path)?;
    let options = tobj::LoadOptions {
        single_index: true,
        triangulate: true,
        ignore_points: true,
        ignore_lines: true,
    };
    // Materials are not needed: a `mtllib` line is ignored rather than read from disk.
    let (models, _) = tobj::load_obj_buf(&mut std::io::Cursor::new(text), &options, |_| {
        Err(tobj::LoadError::OpenFileFailed)
    })
    .map_err(|e| MeshError::Obj {
        path: path.to_path_buf(),
        line: None,
        detail: e.to_string(),
    })?;
    let mut raw = Vec::new();
    for m in &models {
        let pos = &m.mesh.positions;
        for tri in m.mesh.indices.chunks_exact(3) {
            let mut corners = [[0f32; 3]; 3];
            for (k, &i) in tri.iter().enumerate() {
                let i = i as usize * 3;
                let p = pos.get(i..i + 3).ok_or_else(|| MeshError::Obj {
                    path: path.to_path_buf(),
                    line: None,
                    detail: "a face refers to a vertex the file does not have".to_string(),
                })?;
                corners[k] = [p[0], p[1], p[2]];
            }
            raw.push(corners);
        }
    }
    Ok((raw, false))
}

/// Reads a PLY file (ASCII or binary) as triangles, its polygons fanned; whether it is binary.
fn ply_raw(bytes: &[u8], path: &Path) -> Result<Raw, MeshError> {
    use ply_rs_bw::parser::Parser;
    use ply_rs_bw::ply::{DefaultElement, Encoding};
    let err = |detail: String| ply_err(path, detail);
    let parser = Parser::<DefaultElement>::new();
    let mut reader = std::io::BufReader::new(std::io::Cursor::new(bytes));
    let header = parser
        .read_header(&mut reader)
        .map_err(|e| err(ply_header_message(&e.to_string())))?;
    // A count larger than the file cannot be real: refuse it before anything is allocated for it.
    for (name, def) in &header.elements {
        if def.count > bytes.len() {
            return Err(err(format!(
                "header declares {} `{name}` elements in a file of {} bytes",
                def.count,
                bytes.len()
            )));
        }
    }
    let payload = parser
        .read_payload(&mut reader, &header)
        .map_err(|e| ply_payload_err(path, &e))?;
    let is_binary = header.encoding != Encoding::Ascii;
    let vertices = payload
        .get("vertex")
        .ok_or_else(|| err("no `vertex` element".to_string()))?;
    let points = ply_points(vertices, path)?;
    let faces = payload
        .get("face")
        .ok_or_else(|| err("no `face` element: a point cloud is not a surface".to_string()))?;
    let raw = ply_triangles(faces, &points, path)?;
    Ok((raw, is_binary))
}

/// The PLY parser's header error as a plain line: `header line 2 `format weird 1.0` is not a
/// PLY header line`, without the parser's own Debug dump of what it expected (issue 32).
fn ply_header_message(e: &str) -> String {
    let e = e.split_whitespace().collect::<Vec<_>>().join(" ");
    let plain = e.split(" Error: ").next().unwrap_or(&e);
    let line = plain
        .strip_prefix("Line ")
        .and_then(|r| r.split(':').next())
        .filter(|n| n.chars().all(|c| c.is_ascii_digit()));
    let text = plain
        .split_once("String: '")
        .map(|(_, t)| t.trim_end_matches('\'').trim());
    let short = |t: &str| -> String {
        let t: String = t.chars().take(80).collect();
        t
    };
    match (line, text) {
        (Some(n), Some(t)) => format!(
            "header line {n} `{}` is not a PLY header line (format ascii 1.0, format binary_little_endian 1.0, element, property, comment, end_header)",
            short(t)
        ),
        _ => format!("header: {}", short(plain)),
    }
}

/// [`MeshError::Ply`] for `path` with `detail` on one line.
fn ply_err(path: &Path, detail: String) -> MeshError {
    MeshError::Ply {
        path: path.to_path_buf(),
        detail: detail.split_whitespace().collect::<Vec<_>>().join(" "),
    }
}

/// The error for a PLY payload that does not read: a truncated file, or the element line that
/// does not fit the header's types.
fn ply_payload_err(path: &Path, e: &std::io::Error) -> MeshError {
    let err = |detail: String| ply_err(path, detail);
    // ply-rs-bw's messages carry the offending line and a nested parser dump; keep the line.
    let m = e
        .to_string()
        .split_whitespace()
        .collect::<Vec<_>>()
        .join(" ");
    let eof = e.kind() == std::io::ErrorKind::UnexpectedEof || m.contains("UnexpectedEof");
    if eof {
        return err(format!(
            "unexpected end of file (truncated?): {}",
            m.split(" Error: ").next().unwrap_or(&m)
        ));
    }
    match m
        .split_once("String: '")
        .and_then(|(_, r)| r.split_once('\''))
    {
        Some((line, _)) => err(format!(
            "cannot read the element line `{}`: not numbers of the types the header declares",
            line.trim()
        )),
        None => err(m.split(" Error: ").next().unwrap_or(&m).to_string()),
    }
}

/// A PLY scalar property as a number (`None` for a list or a missing property).
fn ply_scalar(p: Option<&ply_rs_bw::ply::Property>) -> Option<f64> {
    use ply_rs_bw::ply::Property;
    Some(match p? {
        Property::Float(v) => f64::from(*v),
        Property::Double(v) => *v,
        Property::Char(v) => f64::from(*v),
        Property::UChar(v) => f64::from(*v),
        Property::Short(v) => f64::from(*v),
        Property::UShort(v) => f64::from(*v),
        Property::Int(v) => f64::from(*v),
        Property::UInt(v) => f64::from(*v),
        _ => return None,
    })
}

/// The PLY `vertex` elements' `x, y, z`.
fn ply_points(
    vertices: &[ply_rs_bw::ply::DefaultElement],
    path: &Path,
) -> Result<Vec<[f32; 3]>, MeshError> {
    let mut points = Vec::with_capacity(vertices.len());
    for (i, v) in vertices.iter().enumerate() {
        let mut p = [0f32; 3];
        for (k, key) in ["x", "y", "z"].iter().enumerate() {
            let c = ply_scalar(v.get(*key))
                .ok_or_else(|| ply_err(path, format!("vertex {i} has no numeric `{key}`")))?;
            p[k] = c as f32;
        }
        points.push(p);
    }
    Ok(points)
}

/// The PLY `face` elements as triangles of `points`, each polygon fanned.
fn ply_triangles(
    faces: &[ply_rs_bw::ply::DefaultElement],
    points: &[[f32; 3]],
    path: &Path,
) -> Result<Vec<[[f32; 3]; 3]>, MeshError> {
    use ply_rs_bw::ply::Property;
    let err = |detail: String| ply_err(path, detail);
    let mut raw = Vec::new();
    for (f, face) in faces.iter().enumerate() {
        let list = face
            .get("vertex_indices")
            .or_else(|| face.get("vertex_index"));
        let idx: Vec<i64> = match list {
            Some(Property::ListInt(v)) => v.iter().map(|&i| i64::from(i)).collect(),
            Some(Property::ListUInt(v)) => v.iter().map(|&i| i64::from(i)).collect(),
            Some(Property::ListShort(v)) => v.iter().map(|&i| i64::from(i)).collect(),
            Some(Property::ListUShort(v)) => v.iter().map(|&i| i64::from(i)).collect(),
            Some(Property::ListChar(v)) => v.iter().map(|&i| i64::from(i)).collect(),
            Some(Property::ListUChar(v)) => v.iter().map(|&i| i64::from(i)).collect(),
            _ => {
                return Err(err(format!(
                    "face {} has no integer list `vertex_indices`",
                    f + 1
                )))
            }
        };
        if idx.len() < 3 {
            return Err(err(format!(
                "face {} has {} vertices; a face needs at least three",
                f + 1,
                idx.len()
            )));
        }
        if idx.len() > MAX_POLYGON_VERTICES {
            return Err(err(format!(
                "face {}: {}",
                f + 1,
                polygon_too_large(idx.len())
            )));
        }
        if let Some(&bad) = idx
            .iter()
            .find(|&&i| i < 0 || i as u64 >= points.len() as u64)
        {
            return Err(MeshError::FaceIndex {
                path: path.to_path_buf(),
                face: f + 1,
                index: bad,
                vertices: points.len(),
            });
        }
        // Fan triangulation, as tobj does for OBJ polygons.
        for k in 1..idx.len() - 1 {
            raw.push([
                points[idx[0] as usize],
                points[idx[k] as usize],
                points[idx[k + 1] as usize],
            ]);
        }
    }
    Ok(raw)
}

impl LoadedMesh {
    /// One-line warnings (without the file name) about what was repaired or is suspect.
    pub fn warnings(&self) -> Vec<String> {
        let mut w = self.notes.clone();
        if self.degenerate_dropped > 0 {
            w.push(format!(
                "dropped {} degenerate (zero-area) triangles of {}",
                self.degenerate_dropped, self.triangles_read
            ));
        }
        let t = self.topology;
        if self.duplicates_dropped > 0 {
            w.push(format!(
                "dropped {} duplicated faces of {} (each face counted once in the volume and mass)",
                self.duplicates_dropped, self.triangles_read
            ));
        }
        if t.boundary_edges > 0 || t.non_manifold_edges > 0 {
            w.push(format!(
                "surface is not a closed 2-manifold ({} boundary edges, {} non-manifold edges): \
                 the thesis method assumes a closed shell, slices may be open{}",
                t.boundary_edges,
                t.non_manifold_edges,
                if self.holes_filled > 0 {
                    format!(
                        "; {} holes under {SMALL_HOLE_MM} mm closed",
                        self.holes_filled
                    )
                } else {
                    String::new()
                }
            ));
        }
        if t.misoriented_edges > 0 {
            w.push(format!(
                "{} edges join triangles wound in opposite directions: outward normals may be wrong there",
                t.misoriented_edges
            ));
        }
        if self.was_inverted {
            w.push("triangles were wound inside-out (negative volume); flipped".to_string());
        }
        if let Some(u) = self.units_warning() {
            w.push(u);
        }
        w
    }

    /// The largest extent of the file's bounding box `[mm]`: within a factor √3 of
    /// [`Self::geometric_size_mm`] whatever the frame (in any frame the box's largest extent
    /// lies between the mesh's diameter over √3 and its diameter), so it decides a size test
    /// alike in every frame where it is that far from the threshold.
    fn box_size_mm(&self) -> f64 {
        let (lo, hi) = self.mesh.bounds();
        (hi - lo).max()
    }

    /// The object's largest extent `[mm]` in its frame from the geometry
    /// ([`super::align::canonical_rotation`]): the same whatever frame the file was written
    /// in, where the file's box is not (a 6 mm rod turned 45° in its box spans 4.6 mm of it).
    /// The file's box where the mesh encloses no volume.
    fn geometric_size_mm(&self) -> f64 {
        let boxed = self.box_size_mm();
        let Some(props) = super::align::covariant_mass_properties(&self.mesh) else {
            return boxed;
        };
        let turn = super::align::canonical_rotation(&self.mesh, &props);
        let mut turned = self.mesh.clone();
        turned.map_vertices(|p| turn * p);
        let (lo, hi) = turned.bounds();
        let size = (hi - lo).max();
        if size.is_finite() {
            size
        } else {
            boxed
        }
    }

    /// For an object the planner found ungraspable: a hint when it is plausibly sized but
    /// smaller than twice the smallest diameter the hand grasps (`smallest_grasp_mm`), and a
    /// larger unit makes it hand-sized, as a file in centimetres read as millimetres does. Of
    /// the larger units, the one that puts its largest extent nearest 100 mm is named. `None`
    /// when [`Self::units_warning`] already speaks of the size.
    pub fn small_object_hint(&self, smallest_grasp_mm: f64) -> Option<String> {
        if self.box_size_mm() >= 2.0 * smallest_grasp_mm * 3f64.sqrt() {
            return None;
        }
        let size = self.geometric_size_mm();
        if !(PLAUSIBLE_MIN_MM..=PLAUSIBLE_MAX_MM).contains(&size)
            || size >= 2.0 * smallest_grasp_mm
            || self.format == MeshFormat::Urdf
        {
            return None;
        }
        let read = self.unit.name();
        let in_unit = size / self.unit.to_mm();
        let (unit, mm) = LengthUnit::ALL
            .into_iter()
            .filter(|&u| u.to_mm() > self.unit.to_mm())
            .map(|u| (u, in_unit * u.to_mm()))
            .filter(|&(_, mm)| mm >= 2.0 * smallest_grasp_mm && mm <= PLAUSIBLE_MAX_MM)
            .min_by(|a, b| {
                (a.1 / 100.0)
                    .ln()
                    .abs()
                    .total_cmp(&(b.1 / 100.0).ln().abs())
            })?;
        let unit = unit.name();
        Some(format!(
            "the object is {} across as read (units = \"{read}\"), small for a hand that grasps \
             {} and more; if the file is in {unit} (the object then {} mm across), set units = \
             \"{unit}\" in [object], or --units {unit} for a bare mesh",
            fmt_mm(size),
            fmt_mm(smallest_grasp_mm),
            fmt_size(mm)
        ))
    }

    /// A warning when the object's size is implausible for a hand (under 5 mm or over 2 m along
    /// its largest extent), naming the unit it was read in and the likely one: of the other
    /// units, the one that makes it plausible and nearest 100 mm (a hand-sized object).
    pub fn units_warning(&self) -> Option<String> {
        let boxed = self.box_size_mm();
        if (PLAUSIBLE_MIN_MM * 3f64.sqrt()..=PLAUSIBLE_MAX_MM / 3f64.sqrt()).contains(&boxed) {
            return None;
        }
        let size = self.geometric_size_mm();
        if (PLAUSIBLE_MIN_MM..=PLAUSIBLE_MAX_MM).contains(&size) {
            return None;
        }
        let read = self.unit.name();
        let in_unit = size / self.unit.to_mm();
        // A URDF's unit is fixed (metres): no other unit to suggest.
        let likely = LengthUnit::ALL
            .into_iter()
            .filter(|&u| u != self.unit && self.format != MeshFormat::Urdf)
            .map(|u| (u, in_unit * u.to_mm()))
            .filter(|(_, mm)| (PLAUSIBLE_MIN_MM..=PLAUSIBLE_MAX_MM).contains(mm))
            .min_by(|a, b| {
                (a.1 / 100.0)
                    .ln()
                    .abs()
                    .total_cmp(&(b.1 / 100.0).ln().abs())
            });
        Some(match likely {
            Some((unit, mm)) => {
                let unit = unit.name();
                format!(
                    "the object is {} {read} across as read (units = \"{read}\"): implausible for \
                     a hand; if the file is in {unit} (the object then {} mm across), set units = \
                     \"{unit}\" in [object], or --units {unit} for a bare mesh",
                    fmt_size(in_unit),
                    fmt_size(mm)
                )
            }
            None => format!(
                "the object is {} across: implausibly {} for a hand",
                fmt_mm(size),
                if size < PLAUSIBLE_MIN_MM {
                    "small"
                } else {
                    "large"
                }
            ),
        })
    }
}

/// Reads and validates an STL file, scaling its coordinates to millimetres.
///
/// # Errors
/// Every [`MeshError`] names `path`: missing or unreadable file, a directory, bytes that are not
/// STL, a truncated or over-long binary file, malformed ASCII, no triangles, NaN or infinite or
/// absurdly large coordinates, only degenerate triangles, or a surface enclosing no volume.
pub fn load_stl(path: &Path, unit: LengthUnit) -> Result<LoadedMesh, MeshError> {
    if path.is_dir() {
        return Err(MeshError::IsDirectory {
            path: path.to_path_buf(),
        });
    }
    let bytes = crate::files::read_regular(path, crate::files::MAX_MESH_BYTES).map_err(|e| {
        MeshError::Io {
            path: path.to_path_buf(),
            error: e,
        }
    })?;
    parse_stl(&bytes, path, unit)
}

/// Parses STL bytes (the file's content) as [`load_stl`] does; `path` is only used in messages.
///
/// # Errors
/// As [`load_stl`].
pub fn parse_stl(bytes: &[u8], path: &Path, unit: LengthUnit) -> Result<LoadedMesh, MeshError> {
    let (raw, is_binary) = stl_raw(bytes, path)?;
    build(raw, path, unit, is_binary, MeshFormat::Stl)
}

fn stl_raw(bytes: &[u8], path: &Path) -> Result<Raw, MeshError> {
    let bytes = without_bom(bytes);
    let p = || path.to_path_buf();
    if bytes.is_empty() {
        return Err(MeshError::Empty { path: p() });
    }
    let len = bytes.len() as u64;
    let declared = (bytes.len() >= 84)
        .then(|| u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]));
    let binary_size = declared.map(|n| 84 + 50 * u64::from(n));
    let starts_solid = {
        let head = &bytes[..bytes.len().min(512)];
        let text = String::from_utf8_lossy(head);
        text.trim_start().starts_with("solid")
    };

    let is_binary = binary_size == Some(len) || (!starts_solid && declared.is_some());
    let triangles = if is_binary {
        stl_binary(
            bytes,
            path,
            declared.unwrap_or(0),
            binary_size.unwrap_or(84),
        )?
    } else if starts_solid {
        stl_ascii(bytes, path)?
    } else {
        return Err(MeshError::NotStl {
            path: p(),
            detail: format!("{len} bytes, neither ASCII (\"solid ...\") nor a binary STL header"),
        });
    };

    Ok((triangles, is_binary))
}

/// The triangles of a binary STL whose header declares `declared` triangles, `expected` bytes.
fn stl_binary(
    bytes: &[u8],
    path: &Path,
    declared: u32,
    expected: u64,
) -> Result<Vec<[[f32; 3]; 3]>, MeshError> {
    let p = || path.to_path_buf();
    let len = bytes.len() as u64;
    if len < expected {
        return Err(MeshError::Truncated {
            path: p(),
            declared,
            expected,
            actual: len,
        });
    }
    if len > expected {
        return Err(MeshError::TrailingBytes {
            path: p(),
            declared,
            extra: len - expected,
        });
    }
    // The header is free text; blank it so stl_io's ASCII probe cannot misread a binary file
    // whose header begins with "solid ".
    let mut patched = bytes.to_vec();
    patched[..80].fill(0);
    read_triangles(&patched, path, true)
}

/// The triangles of an ASCII STL, every `solid ... endsolid` block of it (CAD tools write an
/// assembly as several; stl_io read the first only, half an object without a word); a grammar
/// error names the first line that breaks it. The grammar: `solid [name]`, then per facet
/// `facet normal x y z`, `outer loop`, three `vertex x y z`, `endloop`, `endfacet`, then
/// `endsolid [name]`, and after it another solid or nothing but blank lines; `x y z` finite
/// numbers (so `nan`, `inf` and `1e999` break it). Words are separated by any white space.
fn stl_ascii(bytes: &[u8], path: &Path) -> Result<Vec<[[f32; 3]; 3]>, MeshError> {
    let p = || path.to_path_buf();
    let len = bytes.len() as u64;
    let text = std::str::from_utf8(bytes).map_err(|e| MeshError::NotStl {
        path: p(),
        detail: format!(
            "starts with \"solid\" but is not UTF-8 text (byte {}), and its size {} is not \
             that of a binary STL",
            e.valid_up_to(),
            len
        ),
    })?;
    parse_ascii_stl(text).map_err(|detail| MeshError::Ascii { path: p(), detail })
}

/// The facet lines of an ASCII STL: keyword words and how many numbers follow them.
const FACET_LINES: [(&str, usize); 7] = [
    ("facet normal", 3),
    ("outer loop", 0),
    ("vertex", 3),
    ("vertex", 3),
    ("vertex", 3),
    ("endloop", 0),
    ("endfacet", 0),
];

/// [`stl_ascii`]'s parser: the triangles of every solid, or the error's detail, `line N
/// (`the line`): expected ...` (or `line N (end of file)`).
fn parse_ascii_stl(text: &str) -> Result<Vec<[[f32; 3]; 3]>, String> {
    let mut out = Vec::new();
    // Where in the grammar: None between solids, Some(step) inside one (step 0: a facet or
    // `endsolid`).
    let mut state: Option<usize> = None;
    let mut solids = 0usize;
    let mut corners = [[0f32; 3]; 3];
    let mut last = 0usize;
    for (i, line) in text.lines().enumerate() {
        let n = i + 1;
        let mut words = line.split_whitespace();
        let Some(first) = words.next() else {
            continue;
        };
        last = n;
        let step = match state {
            None => {
                if first != "solid" {
                    let want = if solids == 0 {
                        "expected `solid`"
                    } else {
                        "expected `solid` or the end of the file after `endsolid`"
                    };
                    return Err(format!("line {n} ({}): {want}", quote_line(line)));
                }
                solids += 1;
                state = Some(0);
                continue;
            }
            Some(step) => step,
        };
        if step == 0 && first == "endsolid" {
            state = None;
            continue;
        }
        let v = facet_line(step, std::iter::once(first).chain(words))
            .map_err(|want| format!("line {n} ({}): {want}", quote_line(line)))?;
        if (2..=4).contains(&step) {
            corners[step - 2] = v;
        }
        if step == FACET_LINES.len() - 1 {
            out.push(corners);
        }
        state = Some((step + 1) % FACET_LINES.len());
    }
    match state {
        None if solids > 0 => Ok(out),
        None => Err(format!("line {} (end of file): expected `solid`", last + 1)),
        Some(step) => {
            let want = if step == 0 {
                "expected `endsolid`".to_string()
            } else {
                format!("expected `{}`", FACET_LINES[step].0)
            };
            Err(format!("line {} (end of file): {want}", last + 1))
        }
    }
}

/// A line of an ASCII STL as an error message quotes it: trimmed, and cut to 80 characters
/// (with `...`) when longer, in backquotes.
fn quote_line(l: &str) -> String {
    let l = l.trim();
    let short: String = l.chars().take(80).collect();
    if short.len() < l.len() {
        format!("`{short}...`")
    } else {
        format!("`{short}`")
    }
}

/// The facet line at `step` of [`FACET_LINES`], given as its `words`: its numbers (zeros for a
/// line without any), or what was expected (`expected ...`, with why a number was refused).
fn facet_line<'a>(step: usize, words: impl Iterator<Item = &'a str>) -> Result<[f32; 3], String> {
    let (keyword, count) = FACET_LINES[step];
    let want = || {
        let nums = if count == 3 { " x y z" } else { "" };
        if step == 0 {
            format!("expected `{keyword}{nums}` or `endsolid`")
        } else {
            format!("expected `{keyword}{nums}`")
        }
    };
    let kw: Vec<&str> = keyword.split(' ').collect();
    let mut all = words;
    if !kw.iter().all(|k| all.next() == Some(*k)) {
        return Err(want());
    }
    let numbers: Vec<&str> = all.collect();
    if numbers.len() != count {
        return Err(want());
    }
    let mut v = [0f32; 3];
    for (k, w) in numbers.iter().enumerate() {
        match w.parse::<f32>() {
            Ok(x) if x.is_finite() => v[k] = x,
            Ok(_) => return Err(format!("{}, with finite numbers", want())),
            Err(e) => return Err(format!("{} ({e})", want())),
        }
    }
    Ok(v)
}

fn read_triangles(
    bytes: &[u8],
    path: &Path,
    binary: bool,
) -> Result<Vec<[[f32; 3]; 3]>, MeshError> {
    let mut cursor = std::io::Cursor::new(bytes);
    let err = |e: std::io::Error| {
        if binary {
            MeshError::NotStl {
                path: path.to_path_buf(),
                detail: e.to_string(),
            }
        } else {
            MeshError::Ascii {
                path: path.to_path_buf(),
                detail: e.to_string().replace('\n', " "),
            }
        }
    };
    let reader = stl_io::create_stl_reader(&mut cursor).map_err(err)?;
    let mut out = Vec::new();
    for tri in reader {
        let tri = tri.map_err(err)?;
        out.push([tri.vertices[0].0, tri.vertices[1].0, tri.vertices[2].0]);
    }
    Ok(out)
}

/// The file's triangles in millimetres (`scale` per file unit), each coordinate checked to be
/// finite and within [`COORDINATE_LIMIT_MM`].
fn scaled_soup(
    raw: &[[[f32; 3]; 3]],
    path: &Path,
    scale: f64,
) -> Result<Vec<[Point3<f64>; 3]>, MeshError> {
    let p = || path.to_path_buf();
    let mut soup = Vec::with_capacity(raw.len());
    for (i, tri) in raw.iter().enumerate() {
        let mut corners = [Point3::origin(); 3];
        for (k, v) in tri.iter().enumerate() {
            if v.iter().any(|c| !c.is_finite()) {
                return Err(MeshError::NonFinite {
                    path: p(),
                    triangle: i,
                });
            }
            let q = Point3::new(
                f64::from(v[0]) * scale,
                f64::from(v[1]) * scale,
                f64::from(v[2]) * scale,
            );
            if let Some(&c) = q.iter().find(|c| c.abs() > COORDINATE_LIMIT_MM) {
                return Err(MeshError::OutOfRange {
                    path: p(),
                    triangle: i,
                    value: c,
                    limit: COORDINATE_LIMIT_MM,
                });
            }
            corners[k] = q;
        }
        soup.push(corners);
    }
    Ok(soup)
}

/// Drops the triangles without area relative to the mesh's squared diagonal `diag2`; how many.
fn drop_collinear(mesh: &mut Mesh, diag2: f64) -> usize {
    let before = mesh.triangles.len();
    let keep: Vec<bool> = (0..before)
        .map(|t| mesh.area_normal(t).norm() > 1e-14 * diag2)
        .collect();
    let mut it = keep.iter();
    mesh.triangles.retain(|_| *it.next().unwrap_or(&false));
    before - mesh.triangles.len()
}

/// Drops the triangles that repeat an earlier one's corners in the same cyclic order; how many.
fn drop_duplicates(mesh: &mut Mesh) -> usize {
    let before = mesh.triangles.len();
    let mut seen: std::collections::HashSet<[u32; 3], super::FastHash> =
        std::collections::HashSet::with_capacity_and_hasher(before, super::FastHash::default());
    mesh.triangles.retain(|t| {
        // The rotation that puts the smallest index first keeps the winding.
        let k = (0..3).min_by_key(|&i| t[i]).unwrap_or(0);
        seen.insert([t[k], t[(k + 1) % 3], t[(k + 2) % 3]])
    });
    before - mesh.triangles.len()
}

pub(super) fn build(
    raw: Vec<[[f32; 3]; 3]>,
    path: &Path,
    unit: LengthUnit,
    is_binary: bool,
    format: MeshFormat,
) -> Result<LoadedMesh, MeshError> {
    let p = || path.to_path_buf();
    if raw.is_empty() {
        return Err(MeshError::NoTriangles { path: p() });
    }
    let soup = scaled_soup(&raw, path, unit.to_mm())?;
    let (mut mesh, mut degenerate) = Mesh::from_triangles_welded(&soup);
    if mesh.triangles.is_empty() {
        return Err(MeshError::AllDegenerate {
            path: p(),
            count: raw.len(),
        });
    }
    // Collinear triangles with distinct vertices have no area either: drop them, relative to the
    // mesh size so that the rule does not depend on the unit.
    let (lo, hi) = mesh.bounds();
    let diag2 = (hi - lo).norm_squared();
    degenerate += drop_collinear(&mut mesh, diag2);
    let duplicates = drop_duplicates(&mut mesh);
    if mesh.triangles.is_empty() {
        return Err(MeshError::AllDegenerate {
            path: p(),
            count: raw.len(),
        });
    }

    let mut notes = Vec::new();
    let topology = oriented(&mut mesh, &mut notes);
    let holes_filled = if topology.boundary_edges > 0 {
        mesh.fill_small_holes(SMALL_HOLE_MM)
    } else {
        0
    };
    let volume = enclosed_volume(&mesh, topology.boundary_edges > 0, diag2, path)?;
    let mut was_inverted = false;
    if volume < 0.0 {
        mesh.flip();
        was_inverted = true;
    }
    Ok(LoadedMesh {
        mesh,
        triangles_read: raw.len(),
        degenerate_dropped: degenerate,
        duplicates_dropped: duplicates,
        topology,
        holes_filled,
        was_inverted,
        is_binary,
        format,
        unit,
        notes,
        mass_kg: None,
    })
}

/// The topology of `mesh` after the faces written the wrong way round on a shell are turned
/// to agree with their neighbours, with a note in `notes` when any were. Such faces would each
/// subtract their share of the volume (a 40 mm cube with one of its 12 triangles turned read as
/// 32 cm³ and was then flipped whole).
fn oriented(mesh: &mut Mesh, notes: &mut Vec<String>) -> Topology {
    let mut topology = mesh.topology();
    if topology.misoriented_edges > 0 {
        let turned = mesh.orient_consistently();
        let before = topology.misoriented_edges;
        topology = mesh.topology();
        notes.push(format!(
            "{turned} of {} triangles were wound against their neighbours ({before} edges walked \
             the same way by both triangles); turned to agree with them",
            mesh.triangles.len()
        ));
    }
    topology
}

/// The signed volume `mesh` encloses `[mm³]` (`is_open`: it has boundary edges; `diag2`: its
/// bounding box's diagonal squared).
///
/// Of an open surface, the volume about the bounding box's centre depends on the frame the
/// file was written in, and so would whether it is turned inside-out: its sign is taken from
/// the fan about the surface's own centroid, which moves with it (issue 30).
///
/// # Errors
/// [`MeshError::NoVolume`] naming `path`, for a volume within rounding noise.
fn enclosed_volume(mesh: &Mesh, is_open: bool, diag2: f64, path: &Path) -> Result<f64, MeshError> {
    let volume = if is_open {
        super::align::covariant_signed_volume(mesh)
    } else {
        super::mass_properties(mesh).volume_mm3
    };
    // A closed surface of any real size encloses a volume well above rounding noise. The
    // noise was taken from the bounding box alone (1e-9 of its diagonal cubed), which called a
    // closed 10 km rod of 20 mm and a 0.001 × 1000 mm needle surfaces enclosing nothing
    // (issue 56): a volume is kept as well when it stands above the rounding of its own
    // terms, the triangles' tetrahedra about the box's centre (each good to the f32
    // coordinates, some 1e-7 of itself), so that each reaches the check of what is wrong with
    // it (too large for the planner's steps, too thin for the hand).
    let noise = 1e-9 * diag2.powf(1.5);
    if volume.abs() <= noise && volume.abs() <= 1e-5 * volume_terms(mesh) {
        return Err(MeshError::NoVolume {
            path: path.to_path_buf(),
            volume_mm3: volume,
        });
    }
    Ok(volume)
}

/// The most elevation-angle cells [`check_planner_work`] lets the planner hold: 400,000 (a
/// 10 m cube at `height_step_mm = 0.1` is 1.8 million, and took 3.5 GB; a 2 m object at the
/// defaults is 25,000).
pub const MAX_PLANNER_CELLS: u64 = 400_000;

/// Checks that the planner's work on `mesh` is bounded: at most [`MAX_PLANNER_CELLS`] indexed
/// elevations (the diameter of the sphere about `centre` that holds the mesh, over
/// `height_step_mm`: a bound for every axis the planner tries) times approach angles (180° over
/// `angular_step_deg`). About the centroid, the bound does not depend on the frame the file was
/// written in (the file's bounding box does: a cube written turned is a third wider in it).
///
/// # Errors
/// [`MeshError::TooLarge`] naming `path`, the cells and the limit.
pub fn check_planner_work(
    mesh: &Mesh,
    centre: Point3<f64>,
    path: &Path,
    height_step_mm: f64,
    angular_step_deg: f64,
) -> Result<(), MeshError> {
    let (lo, hi) = mesh.bounds();
    let centre = if centre.coords.iter().all(|c| c.is_finite()) {
        centre
    } else {
        nalgebra::center(&lo, &hi)
    };
    let extent_mm = 2.0
        * mesh
            .vertices
            .iter()
            .map(|p| (p - centre).norm())
            .fold(0.0, f64::max);
    let elevations = (extent_mm / height_step_mm).floor() + 1.0;
    let angles = (180.0 / angular_step_deg).round().max(1.0);
    let cells = elevations * angles;
    if cells.is_finite() && cells <= MAX_PLANNER_CELLS as f64 {
        return Ok(());
    }
    Err(MeshError::TooLarge {
        path: path.to_path_buf(),
        extent_mm,
        height_step_mm,
        angular_step_deg,
        cells: if cells.is_finite() {
            cells as u64
        } else {
            u64::MAX
        },
        limit: MAX_PLANNER_CELLS,
        hint: String::new(),
    })
}

/// A length with three significant figures.
fn fmt_size(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    let digits = (2 - v.abs().log10().floor() as i32).max(0) as usize;
    format!("{v:.digits$}")
}

/// A length in millimetres, or metres when over 10 m.
fn fmt_mm(mm: f64) -> String {
    if mm >= 10_000.0 {
        format!("{} m", fmt_size(mm / 1000.0))
    } else {
        format!("{} mm", fmt_size(mm))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `solid name`, one facet per triangle, `endsolid name`.
    fn solid(name: &str, tris: &[[[f32; 3]; 3]]) -> String {
        let mut s = format!("solid {name}\n");
        for t in tris {
            s += "  facet normal 0 0 0\n    outer loop\n";
            for v in t {
                s += &format!("      vertex {} {} {}\n", v[0], v[1], v[2]);
            }
            s += "    endloop\n  endfacet\n";
        }
        s + &format!("endsolid {name}\n")
    }

    /// Issue 56: an ASCII STL of two solids (an assembly) was read up to its first
    /// `endsolid`; every solid is read, and what follows an `endsolid` must be another.
    #[test]
    fn every_solid_of_an_ascii_stl_is_read() {
        let a = [[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]];
        let b = [
            [[0.0, 0.0, 5.0], [1.0, 0.0, 5.0], [0.0, 1.0, 5.0]],
            [[0.0, 0.0, 6.0], [1.0, 0.0, 6.0], [0.0, 1.5, 6.0]],
        ];
        let text = format!("{}\n{}", solid("a", &a), solid("b", &b));
        let tris = parse_ascii_stl(&text).unwrap();
        assert_eq!(tris.len(), 3);
        assert_eq!(tris[0], a[0]);
        assert_eq!(tris[2], b[1]);
        // A bare `solid` and `endsolid`, tabs and CRLF line ends read too.
        let crlf = "solid\r\n\tfacet normal 0 0 1\r\nouter loop\r\nvertex 0 0 0\r\nvertex 1 0 0\r\nvertex 0 1 0\r\nendloop\r\nendfacet\r\nendsolid\r\n";
        assert_eq!(parse_ascii_stl(crlf).unwrap().len(), 1);
        // Anything else after an `endsolid` is refused with its line.
        let junk = format!("{}garbage here\n", solid("a", &a));
        assert_eq!(
            parse_ascii_stl(&junk).unwrap_err(),
            "line 10 (`garbage here`): expected `solid` or the end of the file after `endsolid`"
        );
        // A second solid cut short names where.
        let cut = format!("{}solid b\n  facet normal 0 0 1\n", solid("a", &a));
        assert_eq!(
            parse_ascii_stl(&cut).unwrap_err(),
            "line 12 (end of file): expected `outer loop`"
        );
        assert_eq!(
            parse_ascii_stl("solid a\nfacet normal 0 0 1\nouter loop\nvertex 0 0 inf\n")
                .unwrap_err(),
            "line 4 (`vertex 0 0 inf`): expected `vertex x y z`, with finite numbers"
        );
    }
}
