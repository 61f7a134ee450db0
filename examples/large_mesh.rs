//! Writes a 200k-triangle object and its scenario for the large-mesh measurement of
//! BENCHMARKS.md: the cup's shape (56 → 80 mm, 110 mm high) tessellated with 720 segments
//! around and 139 bands up its side.
//!
//!     cargo run --release --example large_mesh -- target/large
//!     /usr/bin/time -v target/release/grasp-sim --no-sim target/large/cup_200k.toml

use grasp_sim::objects::{radial_solid, uniform_angles, Ring};

fn main() {
    let dir = std::path::PathBuf::from(std::env::args().nth(1).unwrap_or("target/large".into()));
    std::fs::create_dir_all(&dir).expect("create the output folder");
    let angles = uniform_angles(720);
    let bands = 139;
    let rings: Vec<Ring> = (0..=bands)
        .map(|k| {
            let z = 110.0 * k as f64 / bands as f64;
            let r = (56.0 + 24.0 * z / 110.0) / 2.0;
            Ring {
                z,
                radii: vec![r; angles.len()],
            }
        })
        .collect();
    let mesh = radial_solid(&angles, &rings);
    std::fs::write(dir.join("cup_200k.stl"), mesh.to_binary_stl()).expect("write the STL");
    let hand = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/hands/thesis.toml");
    std::fs::write(
        dir.join("cup_200k.toml"),
        format!(
            "name = \"cup_200k\"\n[object]\nmesh = \"cup_200k.stl\"\n[hand]\nfile = \"{}\"\n[expect]\noutcome = \"hold\"\n",
            hand.display()
        ),
    )
    .expect("write the scenario");
    println!(
        "{}: {} triangles",
        dir.join("cup_200k.stl").display(),
        mesh.triangles.len()
    );
}
