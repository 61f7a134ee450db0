//! Convex decompositions kept on disk between runs (issue 57): `--collider-cache DIR`, or the
//! environment's `GRASP_SIM_COLLIDER_CACHE`, keeps each V-HACD decomposition (0.1–0.4 s of an
//! object's fixed cost, made once, in the thesis axis's frame) under the digest of the mesh it was
//! made of, so that a sweep, a tuning or a labelling run that meets the same object again
//! skips it. What is kept is the decomposition's parts exactly as V-HACD gave them (each
//! part's points and triangles): the collider made from them is the one made without the
//! cache, bit for bit. A file that cannot be read back whole (truncated, another version's,
//! its checksum off) is made again and replaced; a folder that cannot be written to costs
//! only the time.
//!
//! One file a decomposition, `<digest>.vhacd`: the magic `GSVHACD1`, the part count, each
//! part's point count, points (three `f32` each, metres), triangle count and triangles
//! (three `u32` each), all little-endian, then the SHA-256 of everything before it.

use rapier3d::parry::math::Vector;
use sha2::{Digest, Sha256};
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// The environment variable that names the cache's folder (`--collider-cache` sets it, so
/// that `batch` and `label` workers inherit it).
pub const ENV: &str = "GRASP_SIM_COLLIDER_CACHE";

/// The first bytes of a cache file; a new layout or a change to what is decomposed (the
/// V-HACD parameters, parry's version) takes a new one.
const MAGIC: &[u8; 8] = b"GSVHACD1";

/// What the key adds to the mesh's digest: the decomposition's settings and the crate that
/// makes it, so a file made by other ones is never read.
pub(super) const MAKER: &str = "vhacd resolution 64, parry3d 0.31";

/// The parts of a convex decomposition: each part's points `[m]` and triangles.
pub type Parts = Vec<(Vec<Vector>, Vec<[u32; 3]>)>;

/// A bound on what a cache file may hold, checked before reading it (a file of the cache's
/// folder could be anything): 64 MiB.
const MAX_FILE_BYTES: u64 = 64 << 20;

/// The cache's folder, from [`ENV`] once per process; none when it is unset or empty.
pub fn folder() -> Option<&'static Path> {
    static DIR: OnceLock<Option<PathBuf>> = OnceLock::new();
    DIR.get_or_init(|| {
        std::env::var_os(ENV)
            .filter(|v| !v.is_empty())
            .map(PathBuf::from)
    })
    .as_deref()
}

/// The decomposition kept under `key` in `dir`, or `make`'s, which is then kept there.
pub fn load_or_make(dir: Option<&Path>, key: &[u8; 32], make: impl FnOnce() -> Parts) -> Parts {
    let Some(dir) = dir else { return make() };
    let path = dir.join(format!("{}.vhacd", hex(key)));
    if let Some(parts) = crate::files::read_regular(&path, MAX_FILE_BYTES)
        .ok()
        .and_then(|bytes| decode(&bytes))
    {
        return parts;
    }
    let parts = make();
    // Another run may write the same file at once: each writes a private temporary file and
    // renames it, so a reader sees one whole file or the other, and both are the same.
    let _ = crate::files::write_replacing(&path, &encode(&parts));
    parts
}

/// `key` in lowercase hexadecimal.
fn hex(key: &[u8; 32]) -> String {
    key.iter().map(|b| format!("{b:02x}")).collect()
}

/// The bytes of a cache file holding `parts`.
pub(super) fn encode(parts: &Parts) -> Vec<u8> {
    let mut out = MAGIC.to_vec();
    let count = |n: usize| u32::try_from(n).unwrap_or(u32::MAX).to_le_bytes();
    out.extend(count(parts.len()));
    for (points, triangles) in parts {
        out.extend(count(points.len()));
        for p in points {
            for c in [p.x, p.y, p.z] {
                out.extend(c.to_le_bytes());
            }
        }
        out.extend(count(triangles.len()));
        for t in triangles {
            for i in t {
                out.extend(i.to_le_bytes());
            }
        }
    }
    let digest: [u8; 32] = Sha256::digest(&out).into();
    out.extend(digest);
    out
}

/// The parts a cache file's `bytes` hold, if it is whole: its magic, its checksum, its counts
/// within its length, every point finite and every index one of its part's points.
pub(super) fn decode(bytes: &[u8]) -> Option<Parts> {
    let (body, sum) = bytes.split_at(bytes.len().checked_sub(32)?);
    let digest: [u8; 32] = Sha256::digest(body).into();
    if digest[..] != sum[..] {
        return None;
    }
    let mut r = Reader(body.strip_prefix(MAGIC)?);
    let parts = r.count(4)?;
    let mut out = Vec::with_capacity(parts);
    for _ in 0..parts {
        let n = r.count(12)?;
        let mut points = Vec::with_capacity(n);
        for _ in 0..n {
            let (x, y, z) = (r.f32()?, r.f32()?, r.f32()?);
            if !(x.is_finite() && y.is_finite() && z.is_finite()) {
                return None;
            }
            points.push(Vector::new(x, y, z));
        }
        let m = r.count(12)?;
        let mut triangles = Vec::with_capacity(m);
        for _ in 0..m {
            let t = [r.u32()?, r.u32()?, r.u32()?];
            if t.iter().any(|&i| i as usize >= n) {
                return None;
            }
            triangles.push(t);
        }
        out.push((points, triangles));
    }
    r.0.is_empty().then_some(out)
}

/// Bytes read from the front.
struct Reader<'a>(&'a [u8]);

impl Reader<'_> {
    /// The next four bytes, little-endian.
    fn u32(&mut self) -> Option<u32> {
        let (head, rest) = self.0.split_first_chunk::<4>()?;
        self.0 = rest;
        Some(u32::from_le_bytes(*head))
    }

    /// The next four bytes as an `f32`.
    fn f32(&mut self) -> Option<f32> {
        self.u32().map(f32::from_bits)
    }

    /// A count of items of `size` bytes each that the bytes left can hold.
    fn count(&mut self, size: usize) -> Option<usize> {
        let n = self.u32()? as usize;
        (n.checked_mul(size)? <= self.0.len()).then_some(n)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parts() -> Parts {
        vec![
            (
                vec![
                    Vector::new(0.0, 0.0, 0.0),
                    Vector::new(0.01, 0.0, 0.0),
                    Vector::new(0.0, 0.02, 0.0),
                    Vector::new(0.0, 0.0, -0.03),
                ],
                vec![[0, 1, 2], [0, 3, 1], [1, 3, 2], [2, 3, 0]],
            ),
            (vec![Vector::new(1.5, -2.25, 1e-7)], vec![]),
        ]
    }

    #[test]
    fn a_file_reads_back_bit_for_bit_and_a_damaged_one_not_at_all() {
        let bytes = encode(&parts());
        // 8 magic, 4 parts, (4 + 4·12 + 4 + 4·12) + (4 + 12 + 4), 32 checksum.
        assert_eq!(bytes.len(), 8 + 4 + 104 + 20 + 32);
        let back = decode(&bytes).expect("a whole file reads back");
        assert_eq!(back.len(), 2);
        for ((p, t), (q, u)) in back.iter().zip(&parts()) {
            assert_eq!(t, u);
            let bits = |v: &Vec<Vector>| -> Vec<u32> {
                v.iter()
                    .flat_map(|p| [p.x, p.y, p.z])
                    .map(f32::to_bits)
                    .collect()
            };
            assert_eq!(bits(p), bits(q));
        }
        // Truncated, a byte flipped anywhere, another magic: none is read.
        assert!(decode(&bytes[..bytes.len() - 1]).is_none());
        assert!(decode(&bytes[..20]).is_none());
        assert!(decode(&[]).is_none());
        for k in [0, 9, 30, bytes.len() - 40, bytes.len() - 1] {
            let mut bad = bytes.clone();
            bad[k] ^= 0x10;
            assert!(decode(&bad).is_none(), "byte {k} flipped was read");
        }
    }

    #[test]
    fn a_decomposition_is_made_once_and_then_read() {
        let dir = tempfile::tempdir().unwrap();
        let key = [7u8; 32];
        let mut made = 0;
        let first = load_or_make(Some(dir.path()), &key, || {
            made += 1;
            parts()
        });
        let second = load_or_make(Some(dir.path()), &key, || {
            made += 1;
            Vec::new()
        });
        assert_eq!(made, 1, "the second call reads the file");
        assert_eq!(first.len(), second.len());
        let file = dir.path().join(format!("{}.vhacd", hex(&key)));
        assert!(file.is_file());
        // A damaged file is made again and replaced.
        std::fs::write(&file, b"GSVHACD1 not a decomposition").unwrap();
        let third = load_or_make(Some(dir.path()), &key, || {
            made += 1;
            parts()
        });
        assert_eq!((made, third.len()), (2, 2));
        assert!(decode(&std::fs::read(&file).unwrap()).is_some());
        // Without a folder nothing is kept.
        let none = load_or_make(None, &key, || {
            made += 1;
            Vec::new()
        });
        assert_eq!((made, none.len()), (3, 0));
    }
}
