//! A stable-toolchain driver for issue 56's fuzz targets (`fuzz/fuzz_targets/input_classes.rs`):
//! each target's function fed `FUZZ_RUNS` inputs (10⁶ by default), mutated from seeds and from
//! earlier inputs by a fixed-seed generator (byte flips, insertions, deletions, splices), without
//! coverage feedback. Ignored in the suite (minutes each):
//!
//!     cargo test --test it fuzz_drive -- --ignored --nocapture

#[path = "../../fuzz/fuzz_targets/input_classes.rs"]
mod input_classes;

/// xorshift64*: a fixed-seed generator, so a run can be repeated.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }

    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

/// `input` changed by one to four mutations, at most `max_len` bytes.
fn mutate(rng: &mut Rng, input: &[u8], other: &[u8], max_len: usize) -> Vec<u8> {
    let mut v = input.to_vec();
    for _ in 0..1 + rng.below(4) {
        match rng.below(6) {
            0 if !v.is_empty() => {
                let k = rng.below(v.len());
                v[k] ^= 1 << rng.below(8);
            }
            1 if !v.is_empty() => {
                let k = rng.below(v.len());
                v[k] = rng.next() as u8;
            }
            2 => {
                let k = rng.below(v.len() + 1);
                let n = 1 + rng.below(16);
                let bytes: Vec<u8> = (0..n).map(|_| rng.next() as u8).collect();
                v.splice(k..k, bytes);
            }
            3 if !v.is_empty() => {
                let k = rng.below(v.len());
                let n = (1 + rng.below(16)).min(v.len() - k);
                v.drain(k..k + n);
            }
            4 if !other.is_empty() => {
                let k = rng.below(v.len() + 1);
                let (a, n) = (rng.below(other.len()), 1 + rng.below(64));
                v.splice(k..k, other[a..(a + n).min(other.len())].iter().copied());
            }
            _ => {
                let k = rng.below(v.len() + 1);
                v.splice(
                    k..k,
                    [0u8, 0xff, 0x7f, 0x80][rng.below(4)..].iter().copied(),
                );
            }
        }
    }
    v.truncate(max_len);
    v
}

/// Runs `target` on `FUZZ_RUNS` inputs grown from `seeds`; prints the count and the time.
fn drive(name: &str, seeds: &[Vec<u8>], max_len: usize, mut target: impl FnMut(&[u8])) {
    let runs: usize = std::env::var("FUZZ_RUNS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(1_000_000);
    let mut rng = Rng(0x9E37_79B9_7F4A_7C15 ^ name.len() as u64);
    let mut pool: Vec<Vec<u8>> = seeds.to_vec();
    let t0 = std::time::Instant::now();
    for i in 0..runs {
        let a = rng.below(pool.len());
        let b = rng.below(pool.len());
        let input = mutate(&mut rng, &pool[a], &pool[b], max_len);
        target(&input);
        // Some inputs join the pool, so mutations build on mutations; it stays small.
        if i % 64 == 0 {
            if pool.len() < 512 {
                pool.push(input);
            } else {
                let k = seeds.len() + rng.below(pool.len() - seeds.len());
                pool[k] = input;
            }
        }
    }
    eprintln!(
        "{name}: {runs} executions in {:.1} s",
        t0.elapsed().as_secs_f64()
    );
}

#[test]
#[ignore]
fn obj_polygons() {
    let seeds = vec![
        vec![4, 1, 2, 3, 9, 17, 25, 3, 8, 16, 24],
        vec![0, 0xd0, 0x07, 1, 2, 3],
    ];
    drive("obj_polygons", &seeds, 512, input_classes::obj_polygons);
}

#[test]
#[ignore]
fn stl_solids() {
    let cube: Vec<u8> = (0..200u8).map(|i| 128 + (i % 3) * 40).collect();
    let seeds = vec![vec![1, 0, 1, 12], [vec![3, 0, 3, 12], cube].concat()];
    drive("stl_solids", &seeds, 512, input_classes::stl_solids);
}

#[test]
#[ignore]
fn scenario_name() {
    let scenarios = crate::root().join("scenarios");
    let seeds: Vec<Vec<u8>> = [
        "cup",
        "../../escape",
        "..",
        "/abs",
        "a\0b",
        "\u{202e}x",
        "a b",
    ]
    .iter()
    .map(|s| s.as_bytes().to_vec())
    .collect();
    drive("scenario_name", &seeds, 300, |d| {
        input_classes::scenario_name(d, &scenarios)
    });
}

/// The hand importer's trees, from the bundled BarrettHand's URDF or MJCF.
fn hand_tree(ext: &str, seed: &str) {
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(crate::root().join("assets/hands").join(seed)).unwrap();
    let file = dir.path().join(format!("hand.{ext}"));
    let seeds = vec![vec![1, 0, 0], vec![3, 5, 2, 7, 9, 3, 1], vec![2, 8, 7, 0]];
    drive(&format!("hand_tree ({ext})"), &seeds, 64, |d| {
        input_classes::hand_tree(d, &text, &file)
    });
}

#[test]
#[ignore]
fn hand_tree_urdf() {
    hand_tree("urdf", "bh8.urdf");
}

#[test]
#[ignore]
fn hand_tree_mjcf() {
    hand_tree("xml", "bh8.xml");
}
