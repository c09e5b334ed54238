//! Generates the procedural object families into an asset directory and measures them:
//! `cargo run --release -p ms2-assets --example generate_objects -- [asset dir]`
//! (default: the store's asset directory, `$MS2_ASSET_DIR` or `~/.ms2/data`).
//!
//! Prints per family: generation time (0 when already generated), disk size, model count,
//! mean visual / collision triangles and convex pieces per model, and the memory of the meshes
//! of one model once read (vertex and index arrays; and the process's resident-set growth).

use std::path::Path;
use std::time::Instant;

use ms2_assets::objects::{
    ensure_family_in, load_model_db, model_files, read_collision_pieces, read_visual_parts,
    ObjectFamily, Split,
};

fn disk_bytes(p: &Path) -> u64 {
    let Ok(rd) = std::fs::read_dir(p) else {
        return 0;
    };
    rd.flatten()
        .map(|e| match e.file_type() {
            Ok(t) if t.is_dir() => disk_bytes(&e.path()),
            _ => e.metadata().map(|m| m.len()).unwrap_or(0),
        })
        .sum()
}

fn rss_bytes() -> u64 {
    std::fs::read_to_string("/proc/self/statm")
        .ok()
        .and_then(|s| s.split_whitespace().nth(1)?.parse::<u64>().ok())
        .map(|pages| pages * 4096)
        .unwrap_or(0)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let dir = std::env::args()
        .nth(1)
        .map(std::path::PathBuf::from)
        .unwrap_or_else(ms2_assets::asset_dir);
    for family in [ObjectFamily::Household, ObjectFamily::Egad] {
        let t = Instant::now();
        let root = ensure_family_in(family, &dir)?;
        let secs = t.elapsed().as_secs_f64();
        let kind = family.kind();
        let splits: &[Option<Split>] = match family {
            ObjectFamily::Household => &[None],
            ObjectFamily::Egad => &[Some(Split::Train), Some(Split::Eval)],
        };
        let (mut n, mut vis_tris, mut col_tris, mut pieces, mut bytes) = (0usize, 0, 0, 0, 0);
        let rss0 = rss_bytes();
        let mut keep = Vec::new();
        let t_load = Instant::now();
        for split in splits {
            let db = load_model_db(&root, kind, *split)?;
            for id in db.ids() {
                let f = model_files(&root, kind, id);
                let vis = read_visual_parts(&f.visual, id)?;
                let col = read_collision_pieces(&f.collision, id)?;
                for p in vis.iter().chain(&col) {
                    bytes += p.vertices.len() * 12 + p.triangles.len() * 12;
                }
                vis_tris += vis.iter().map(|p| p.triangles.len()).sum::<usize>();
                col_tris += col.iter().map(|p| p.triangles.len()).sum::<usize>();
                pieces += col.len();
                n += 1;
                keep.push((vis, col));
            }
        }
        let load_ms = t_load.elapsed().as_secs_f64() * 1e3 / n as f64;
        let rss = rss_bytes().saturating_sub(rss0);
        println!(
            "{}: {} models in {} | generated in {secs:.2} s | disk {:.1} MB | \
             per model: {:.0} visual + {:.0} collision triangles, {:.1} convex pieces, \
             read in {load_ms:.2} ms, {:.1} KB of mesh arrays ({:.1} KB resident)",
            family.dir_name(),
            n,
            root.display(),
            disk_bytes(&root) as f64 / 1e6,
            vis_tris as f64 / n as f64,
            col_tris as f64 / n as f64,
            pieces as f64 / n as f64,
            bytes as f64 / n as f64 / 1e3,
            rss as f64 / n as f64 / 1e3,
        );
        drop(keep);
    }
    Ok(())
}
