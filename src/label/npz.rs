//! `label --npz DIR`: one numpy `.npz` per object, the arrays of its labelled grasps' fields, for
//! learning pipelines (`numpy.load("DIR/cup.npz")`).
//!
//! An `.npz` is a zip archive of `.npy` files (numpy's format 1.0: a magic string, a header
//! giving the dtype, the order and the shape, then the data, little-endian, C order). Entries
//! are stored uncompressed with a fixed timestamp, so the same lines give the same bytes.
//!
//! Arrays, one row per labelled grasp in grasp-index order: `grasp_index` (int64), `palm_pose`
//! (float64, K × 4 × 4, mm), `joint_angles_deg` and `closed_joint_angles_deg` (float64, K × F ×
//! 2), `axis_name`, `rules` and `verdict` (unicode), `as_planned` (bool, the nominal check's),
//! `samples` (int64), `hold_probability`, `as_planned_probability` (float64), `interval` and
//! `as_planned_interval` (float64, K × 2), `grade_palm` (float64, NaN where ungraded), and per
//! direction `direction_gravity` (D × 3) and `direction_hold_probability` (K × D).

use std::io::Write;

/// One array: its dtype, shape and little-endian bytes.
struct Array {
    name: &'static str,
    descr: String,
    shape: Vec<usize>,
    data: Vec<u8>,
}

impl Array {
    fn f64s(name: &'static str, shape: Vec<usize>, values: impl IntoIterator<Item = f64>) -> Array {
        Array {
            name,
            descr: "<f8".to_string(),
            shape,
            data: values.into_iter().flat_map(f64::to_le_bytes).collect(),
        }
    }

    fn i64s(name: &'static str, values: &[i64]) -> Array {
        Array {
            name,
            descr: "<i8".to_string(),
            shape: vec![values.len()],
            data: values.iter().flat_map(|v| v.to_le_bytes()).collect(),
        }
    }

    fn bools(name: &'static str, values: &[bool]) -> Array {
        Array {
            name,
            descr: "|b1".to_string(),
            shape: vec![values.len()],
            data: values.iter().map(|&b| u8::from(b)).collect(),
        }
    }

    /// Fixed-width unicode (`<U{n}`: UTF-32LE code points, padded with zeros).
    fn strings(name: &'static str, values: &[String]) -> Array {
        let n = values
            .iter()
            .map(|s| s.chars().count())
            .max()
            .unwrap_or(0)
            .max(1);
        let mut data = Vec::with_capacity(values.len() * n * 4);
        for s in values {
            let mut k = 0;
            for c in s.chars() {
                data.extend_from_slice(&u32::from(c).to_le_bytes());
                k += 1;
            }
            data.extend(std::iter::repeat_n(0u8, (n - k) * 4));
        }
        Array {
            name,
            descr: format!("<U{n}"),
            shape: vec![values.len()],
            data,
        }
    }

    /// The `.npy` file (format 1.0).
    fn npy(&self) -> Vec<u8> {
        let shape = match self.shape.as_slice() {
            [n] => format!("({n},)"),
            s => format!(
                "({})",
                s.iter()
                    .map(|d| d.to_string())
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        };
        let mut header = format!(
            "{{'descr': '{}', 'fortran_order': False, 'shape': {shape}, }}",
            self.descr
        );
        // The magic (6), the version (2) and the length (2), then the header padded with
        // spaces to a multiple of 64 bytes in all, ending in a newline.
        let total = 10 + header.len() + 1;
        header.push_str(&" ".repeat((64 - total % 64) % 64));
        header.push('\n');
        let mut out = Vec::with_capacity(10 + header.len() + self.data.len());
        out.extend_from_slice(b"\x93NUMPY\x01\x00");
        out.extend_from_slice(&(header.len() as u16).to_le_bytes());
        out.extend_from_slice(header.as_bytes());
        out.extend_from_slice(&self.data);
        out
    }
}

/// The `.npz` bytes of an object's label lines (`lines`: each a parsed JSON label line with a
/// `grasp_index`, sorted by it; error lines left out by the caller), for a hand of `fingers`.
///
/// # Errors
/// When the archive cannot be written (never in memory, but the zip writer may say so).
pub fn npz(lines: &[serde_json::Value], fingers: usize) -> std::io::Result<Vec<u8>> {
    let k = lines.len();
    let f64_at = |v: &serde_json::Value| v.as_f64().unwrap_or(f64::NAN);
    let flat = |key: &str, n: usize| -> Vec<f64> {
        lines
            .iter()
            .flat_map(|l| {
                let mut out: Vec<f64> = Vec::with_capacity(n);
                flatten(&l[key], &mut out);
                out.resize(n, f64::NAN);
                out
            })
            .collect()
    };
    let text = |key: &str| -> Vec<String> {
        lines
            .iter()
            .map(|l| l[key].as_str().unwrap_or("").to_string())
            .collect()
    };
    let gravity: Vec<Vec<f64>> = lines
        .first()
        .and_then(|l| l["directions"].as_array())
        .map(|d| {
            d.iter()
                .map(|g| {
                    let mut v = Vec::new();
                    flatten(&g["gravity"], &mut v);
                    v.resize(3, f64::NAN);
                    v
                })
                .collect()
        })
        .unwrap_or_default();
    let dirs = gravity.len();
    let arrays = vec![
        Array::i64s(
            "grasp_index",
            &lines
                .iter()
                .map(|l| l["grasp_index"].as_i64().unwrap_or(-1))
                .collect::<Vec<_>>(),
        ),
        Array::f64s("palm_pose", vec![k, 4, 4], flat("palm_pose", 16)),
        Array::f64s(
            "joint_angles_deg",
            vec![k, fingers, 2],
            flat("joint_angles_deg", 2 * fingers),
        ),
        Array::f64s(
            "closed_joint_angles_deg",
            vec![k, fingers, 2],
            flat("closed_joint_angles_deg", 2 * fingers),
        ),
        Array::strings("axis_name", &text("axis_name")),
        Array::strings("rules", &text("rules")),
        Array::strings("verdict", &text("verdict")),
        Array::bools(
            "as_planned",
            &lines
                .iter()
                .map(|l| l["fidelity"]["as_planned"].as_bool().unwrap_or(false))
                .collect::<Vec<_>>(),
        ),
        Array::i64s(
            "samples",
            &lines
                .iter()
                .map(|l| l["samples"].as_i64().unwrap_or(0))
                .collect::<Vec<_>>(),
        ),
        Array::f64s(
            "hold_probability",
            vec![k],
            lines.iter().map(|l| f64_at(&l["hold_probability"])),
        ),
        Array::f64s("interval", vec![k, 2], flat("interval", 2)),
        Array::f64s(
            "as_planned_probability",
            vec![k],
            lines.iter().map(|l| f64_at(&l["as_planned_probability"])),
        ),
        Array::f64s(
            "as_planned_interval",
            vec![k, 2],
            flat("as_planned_interval", 2),
        ),
        Array::f64s(
            "grade_palm",
            vec![k],
            lines.iter().map(|l| f64_at(&l["grade"]["palm"])),
        ),
        Array::f64s(
            "direction_gravity",
            vec![dirs, 3],
            gravity.iter().flatten().copied(),
        ),
        Array::f64s(
            "direction_hold_probability",
            vec![k, dirs],
            lines.iter().flat_map(|l| {
                let mut v: Vec<f64> = l["directions"]
                    .as_array()
                    .map(|d| d.iter().map(|x| f64_at(&x["hold_probability"])).collect())
                    .unwrap_or_default();
                v.resize(dirs, f64::NAN);
                v
            }),
        ),
    ];
    let mut buf = std::io::Cursor::new(Vec::new());
    {
        let mut zip = zip::ZipWriter::new(&mut buf);
        let options = zip::write::SimpleFileOptions::default()
            .compression_method(zip::CompressionMethod::Stored)
            .last_modified_time(zip::DateTime::default());
        for a in &arrays {
            zip.start_file(format!("{}.npy", a.name), options)
                .map_err(std::io::Error::other)?;
            zip.write_all(&a.npy())?;
        }
        zip.finish().map_err(std::io::Error::other)?;
    }
    Ok(buf.into_inner())
}

/// Every number of a nested JSON list, in order.
fn flatten(v: &serde_json::Value, out: &mut Vec<f64>) {
    match v {
        serde_json::Value::Array(items) => items.iter().for_each(|x| flatten(x, out)),
        x => out.push(x.as_f64().unwrap_or(f64::NAN)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_npy_header_pads_to_64_bytes_and_says_the_shape() {
        let a = Array::f64s("x", vec![2, 3], (0..6).map(f64::from));
        let npy = a.npy();
        assert_eq!(&npy[..8], b"\x93NUMPY\x01\x00");
        let len = u16::from_le_bytes([npy[8], npy[9]]) as usize;
        assert_eq!((10 + len) % 64, 0);
        let header = std::str::from_utf8(&npy[10..10 + len]).unwrap();
        assert!(header.starts_with("{'descr': '<f8', 'fortran_order': False, 'shape': (2, 3), }"));
        assert!(header.ends_with('\n'));
        assert_eq!(npy.len(), 10 + len + 48);
        assert_eq!(&npy[10 + len + 8..10 + len + 16], &1.0f64.to_le_bytes());
        let s = Array::strings("s", &["hold".into(), "slip".into(), "x".into()]);
        assert_eq!(s.descr, "<U4");
        assert_eq!(s.data.len(), 3 * 4 * 4);
        assert_eq!(&s.data[48 - 16..48 - 12], &u32::from('x').to_le_bytes());
        assert!(Array::i64s("i", &[1]).npy().len().is_multiple_of(8));
    }
}
