//! Reading STL (binary or ASCII, through `stl_io`) into a validated [`Mesh`] in millimetres.
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

/// The length unit of an STL file's coordinates.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum LengthUnit {
    /// Millimetres (the default, and the planner's unit).
    #[default]
    Mm,
    /// Metres.
    M,
    /// Inches (25.4 mm).
    Inch,
}

impl LengthUnit {
    /// Millimetres per unit.
    pub fn to_mm(self) -> f64 {
        match self {
            LengthUnit::Mm => 1.0,
            LengthUnit::M => 1000.0,
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
    /// Edge statistics of what was kept.
    pub topology: Topology,
    /// True if and only if the file was wound inside-out and grasp-sim flipped it.
    pub was_inverted: bool,
    /// True if and only if the file was binary STL.
    pub is_binary: bool,
}

impl LoadedMesh {
    /// One-line warnings (without the file name) about what was repaired or is suspect.
    pub fn warnings(&self) -> Vec<String> {
        let mut w = Vec::new();
        if self.degenerate_dropped > 0 {
            w.push(format!(
                "dropped {} degenerate (zero-area) triangles of {}",
                self.degenerate_dropped, self.triangles_read
            ));
        }
        let t = self.topology;
        if t.boundary_edges > 0 || t.non_manifold_edges > 0 {
            w.push(format!(
                "surface is not a closed 2-manifold ({} boundary edges, {} non-manifold edges): \
                 the thesis method assumes a closed shell, slices may be open",
                t.boundary_edges, t.non_manifold_edges
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
        w
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
    let bytes = std::fs::read(path).map_err(|e| MeshError::Io {
        path: path.to_path_buf(),
        message: crate::scenario::io_message(&e),
    })?;
    parse_stl(&bytes, path, unit)
}

/// Parses STL bytes (the file's content) as [`load_stl`] does; `path` is only used in messages.
///
/// # Errors
/// As [`load_stl`].
pub fn parse_stl(bytes: &[u8], path: &Path, unit: LengthUnit) -> Result<LoadedMesh, MeshError> {
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
        let declared = declared.unwrap_or(0);
        let expected = binary_size.unwrap_or(84);
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
        read_triangles(&patched, path, true)?
    } else if starts_solid {
        let text = std::str::from_utf8(bytes).map_err(|e| MeshError::NotStl {
            path: p(),
            detail: format!(
                "starts with \"solid\" but is not UTF-8 text (byte {}), and its size {} is not \
                 that of a binary STL",
                e.valid_up_to(),
                len
            ),
        })?;
        // stl_io wants "solid <name>"; a bare "solid" first line is valid STL too.
        let trimmed = text.trim_start();
        let first_line = trimmed.lines().next().unwrap_or("");
        let text = if first_line.trim() == "solid" {
            format!("solid unnamed{}", &trimmed[first_line.len()..])
        } else {
            trimmed.to_string()
        };
        read_triangles(text.as_bytes(), path, false)?
    } else {
        return Err(MeshError::NotStl {
            path: p(),
            detail: format!("{len} bytes, neither ASCII (\"solid ...\") nor a binary STL header"),
        });
    };

    build(triangles, path, unit, is_binary)
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

fn build(
    raw: Vec<[[f32; 3]; 3]>,
    path: &Path,
    unit: LengthUnit,
    is_binary: bool,
) -> Result<LoadedMesh, MeshError> {
    let p = || path.to_path_buf();
    if raw.is_empty() {
        return Err(MeshError::NoTriangles { path: p() });
    }
    let scale = unit.to_mm();
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
    let (mut mesh, mut degenerate) = Mesh::from_triangles(&soup);
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
    let before = mesh.triangles.len();
    let keep: Vec<bool> = (0..before)
        .map(|t| mesh.area_normal(t).norm() > 1e-14 * diag2)
        .collect();
    let mut it = keep.iter();
    mesh.triangles.retain(|_| *it.next().unwrap_or(&false));
    degenerate += before - mesh.triangles.len();
    if mesh.triangles.is_empty() {
        return Err(MeshError::AllDegenerate {
            path: p(),
            count: raw.len(),
        });
    }

    let volume = super::mass_properties(&mesh).volume_mm3;
    let mut was_inverted = false;
    // A closed surface of any real size encloses a volume well above rounding noise.
    let noise = 1e-9 * diag2.powf(1.5);
    if volume.abs() <= noise {
        return Err(MeshError::NoVolume {
            path: p(),
            volume_mm3: volume,
        });
    }
    if volume < 0.0 {
        mesh.flip();
        was_inverted = true;
    }
    let topology = mesh.topology();
    Ok(LoadedMesh {
        mesh,
        triangles_read: raw.len(),
        degenerate_dropped: degenerate,
        topology,
        was_inverted,
        is_binary,
    })
}
