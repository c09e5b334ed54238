//! Wavefront OBJ files of object models: reading pieces (one per `o` / `g` object, as SAPIEN
//! reads ManiSkill2's multi-convex collision files) and writing them.
//!
//! `mesh-loader` (used by ms2-physics for URDF meshes) splits OBJ files on `g` only and ignores
//! `o`; ManiSkill2's convex-piece files start each piece with `o`, so this module reads both.

use std::collections::HashMap;
use std::fmt::Write as _;
use std::path::Path;

use crate::error::AssetError;

/// One piece of an OBJ file: an `o` / `g` object (or the part of it under one material).
#[derive(Clone, Debug, PartialEq)]
pub struct MeshPiece {
    /// The object / group name (empty when the file names none).
    pub name: String,
    /// Vertices (m, model frame, scale 1).
    pub vertices: Vec<[f32; 3]>,
    /// Triangles (indices into `vertices`).
    pub triangles: Vec<[u32; 3]>,
    /// Diffuse RGBA of the piece's material (`Kd`, `d` of the `.mtl`), when it has one.
    pub rgba: Option<[f32; 4]>,
}

/// Reads the convex pieces of a collision file (each `o` / `g` object is one piece).
/// A missing file, a parse error or a file without triangles is an error naming the file and
/// `model_id`.
pub fn read_collision_pieces(path: &Path, model_id: &str) -> Result<Vec<MeshPiece>, AssetError> {
    read_obj(path, model_id, false)
}

/// Reads the visual parts of a model's mesh: one part per object / group and material, with
/// the material's diffuse colour when the `.mtl` gives one.
pub fn read_visual_parts(path: &Path, model_id: &str) -> Result<Vec<MeshPiece>, AssetError> {
    read_obj(path, model_id, true)
}

fn read_obj(path: &Path, model_id: &str, materials: bool) -> Result<Vec<MeshPiece>, AssetError> {
    let err = |reason: String| AssetError::BadMesh {
        id: model_id.to_owned(),
        file: path.to_path_buf(),
        reason,
    };
    let text = std::fs::read_to_string(path).map_err(|e| {
        if e.kind() == std::io::ErrorKind::NotFound {
            err("the file does not exist".into())
        } else {
            err(format!("cannot read: {e}"))
        }
    })?;
    let mut colours: HashMap<String, [f32; 4]> = HashMap::new();
    let mut positions: Vec<[f32; 3]> = Vec::new();
    let mut pieces: Vec<MeshPiece> = Vec::new();
    // The piece being filled and its map from file vertex index to piece vertex index.
    let mut cur = MeshPiece {
        name: String::new(),
        vertices: Vec::new(),
        triangles: Vec::new(),
        rgba: None,
    };
    let mut remap: HashMap<usize, u32> = HashMap::new();
    let flush = |cur: &mut MeshPiece, remap: &mut HashMap<usize, u32>, pieces: &mut Vec<_>| {
        if !cur.triangles.is_empty() {
            pieces.push(std::mem::replace(
                cur,
                MeshPiece {
                    name: cur.name.clone(),
                    vertices: Vec::new(),
                    triangles: Vec::new(),
                    rgba: cur.rgba,
                },
            ));
        } else {
            cur.vertices.clear();
        }
        remap.clear();
    };
    for (lineno, line) in text.lines().enumerate() {
        let line = line.split('#').next().unwrap_or("").trim();
        let mut tok = line.split_whitespace();
        let Some(key) = tok.next() else { continue };
        let at = |what: &str| err(format!("line {}: {what}: \"{line}\"", lineno + 1));
        match key {
            "v" => {
                let mut p = [0f32; 3];
                for c in &mut p {
                    *c = tok
                        .next()
                        .and_then(|t| t.parse().ok())
                        .ok_or_else(|| at("a vertex needs three numbers"))?;
                }
                if !p.iter().all(|c| c.is_finite()) {
                    return Err(at("vertex is not finite"));
                }
                positions.push(p);
            }
            "f" => {
                let mut idx = Vec::with_capacity(4);
                for t in tok {
                    let first = t.split('/').next().unwrap_or("");
                    let i: i64 = first.parse().map_err(|_| at("bad face index"))?;
                    let n = positions.len() as i64;
                    let abs = if i > 0 { i - 1 } else { n + i };
                    if abs < 0 || abs >= n {
                        return Err(at("face index out of range"));
                    }
                    let abs = abs as usize;
                    let local = *remap.entry(abs).or_insert_with(|| {
                        cur.vertices.push(positions[abs]);
                        (cur.vertices.len() - 1) as u32
                    });
                    idx.push(local);
                }
                if idx.len() < 3 {
                    return Err(at("a face needs at least three vertices"));
                }
                for k in 1..idx.len() - 1 {
                    cur.triangles.push([idx[0], idx[k], idx[k + 1]]);
                }
            }
            "o" | "g" => {
                flush(&mut cur, &mut remap, &mut pieces);
                cur.name = tok.collect::<Vec<_>>().join(" ");
            }
            "usemtl" if materials => {
                flush(&mut cur, &mut remap, &mut pieces);
                let name = tok.collect::<Vec<_>>().join(" ");
                cur.rgba = colours.get(&name).copied();
            }
            "mtllib" if materials => {
                let name = tok.collect::<Vec<_>>().join(" ");
                let mtl = path.parent().unwrap_or(Path::new(".")).join(&name);
                // A missing material library leaves the parts uncoloured, as renderers do.
                if let Ok(m) = std::fs::read_to_string(&mtl) {
                    colours.extend(parse_mtl(&m));
                }
            }
            _ => {}
        }
    }
    flush(&mut cur, &mut remap, &mut pieces);
    if pieces.is_empty() {
        return Err(err("the file holds no triangles".into()));
    }
    Ok(pieces)
}

fn parse_mtl(text: &str) -> HashMap<String, [f32; 4]> {
    let mut out = HashMap::new();
    let mut name: Option<String> = None;
    for line in text.lines() {
        let mut tok = line.split_whitespace();
        match tok.next() {
            Some("newmtl") => {
                let n = tok.collect::<Vec<_>>().join(" ");
                out.insert(n.clone(), [1.0, 1.0, 1.0, 1.0]);
                name = Some(n);
            }
            Some("Kd") => {
                let v: Vec<f32> = tok.filter_map(|t| t.parse().ok()).collect();
                if let (Some(n), [r, g, b]) = (&name, v.as_slice()) {
                    if let Some(c) = out.get_mut(n) {
                        c[..3].copy_from_slice(&[*r, *g, *b]);
                    }
                }
            }
            Some("d") => {
                let v: Option<f32> = tok.next().and_then(|t| t.parse().ok());
                if let (Some(n), Some(d)) = (&name, v) {
                    if let Some(c) = out.get_mut(n) {
                        c[3] = d;
                    }
                }
            }
            _ => {}
        }
    }
    out
}

/// OBJ text of `pieces`: each piece an `o` and a `g` object (so readers that split on either
/// see the same pieces), with `usemtl <piece name>` when `mtllib` is given. Coordinates are
/// written with 6 decimals (µm).
pub fn obj_text(pieces: &[MeshPiece], mtllib: Option<&str>) -> String {
    let mut s = String::new();
    s.push_str("# generated by ms2-assets\n");
    if let Some(m) = mtllib {
        let _ = writeln!(s, "mtllib {m}");
    }
    let mut base = 1usize;
    for p in pieces {
        let _ = writeln!(s, "o {}\ng {}", p.name, p.name);
        if mtllib.is_some() {
            let _ = writeln!(s, "usemtl {}", p.name);
        }
        for v in &p.vertices {
            let _ = writeln!(s, "v {:.6} {:.6} {:.6}", v[0], v[1], v[2]);
        }
        for t in &p.triangles {
            let _ = writeln!(
                s,
                "f {} {} {}",
                t[0] as usize + base,
                t[1] as usize + base,
                t[2] as usize + base
            );
        }
        base += p.vertices.len();
    }
    s
}

/// `.mtl` text with one diffuse material per piece, named after the piece.
pub fn mtl_text(pieces: &[MeshPiece]) -> String {
    let mut s = String::from("# generated by ms2-assets\n");
    for p in pieces {
        let c = p.rgba.unwrap_or([0.8, 0.8, 0.8, 1.0]);
        let _ = writeln!(
            s,
            "newmtl {}\nKa 0 0 0\nKd {:.4} {:.4} {:.4}\nKs 0.1 0.1 0.1\nd {:.4}\nillum 2\n",
            p.name, c[0], c[1], c[2], c[3]
        );
    }
    s
}
