//! Issue 56's `hand_tree` class from fuzz bytes (see `input_classes.rs`, shared with the stable
//! driver `tests/it/fuzz_drive.rs`).
#![no_main]
use libfuzzer_sys::fuzz_target;

#[path = "input_classes.rs"]
mod input_classes;

fuzz_target!(|data: &[u8]| {
    // The first byte picks the seed hand: the BH8's URDF or its MJCF.
    let (pick, rest) = data.split_first().unwrap_or((&0, &[]));
    let hands = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../assets/hands");
    let ext = if pick % 2 == 0 { "urdf" } else { "xml" };
    let Ok(seed) = std::fs::read_to_string(hands.join(format!("bh8.{ext}"))) else {
        return;
    };
    let file = std::env::temp_dir().join(format!("grasp-sim-fuzz-{}.{ext}", std::process::id()));
    input_classes::hand_tree(rest, &seed, &file);
    let _ = std::fs::remove_file(&file);
});
