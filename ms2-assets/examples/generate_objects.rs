//! Generates the procedural object families into an asset directory and reports the time each
//! took: `cargo run --release -p ms2-assets --example generate_objects -- [asset dir]`
//! (default: the store's asset directory, `$MS2_ASSET_DIR` or `~/.ms2/data`).

use std::time::Instant;

use ms2_assets::objects::{ensure_family_in, ObjectFamily};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let dir = std::env::args()
        .nth(1)
        .map(std::path::PathBuf::from)
        .unwrap_or_else(ms2_assets::asset_dir);
    for family in [ObjectFamily::Household, ObjectFamily::Egad] {
        let t = Instant::now();
        let root = ensure_family_in(family, &dir)?;
        println!(
            "{}: {} in {:.2} s",
            family.dir_name(),
            root.display(),
            t.elapsed().as_secs_f64()
        );
    }
    Ok(())
}
