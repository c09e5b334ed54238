//! `Write-v0`'s targets and its mark measure: the characters (stroke data), the clay slab's
//! particle lattice, a character's goal (the slab with its strokes written in), the height
//! image both are measured by and the IoU of the written marks.
//!
//! Facts from ManiSkill2 0.5.3's Write: the slab is 42 × 42 columns of 10 particles on a
//! 5 mm lattice (21 × 21 × 5 cm, centred on the world origin, standing on the table); a goal
//! is a particle set of the slab after writing, and goal and clay are measured by a **height
//! image** of 64 × 64 pixels over the 21 × 21 cm square centred on the origin: each particle
//! is drawn as a sphere of radius 2 px (2 / (64 / 0.21) m ≈ 6.6 mm; ManiSkill2's
//! `int(0.007 × 64 / 0.21)`) and a pixel holds the highest sphere top over it in mm
//! (0 where there is none). A pixel is **written** below 40 mm and **near** below 50 mm; the
//! IoU counts a pixel in the intersection when one image writes it and the other is near,
//! in the union when either writes it.
//!
//! ManiSkill2 reads its goals from `write/levels/*.h5` (a download ms2 does not read): slabs
//! written in its simulator. ms2's goals are made from stroke data of its own
//! ([`BUILTIN_STROKES`], JSON): polylines in a unit glyph box, placed on the slab
//! [`GLYPH_SIZE_M`] wide with the glyph's up along world +x (away from the robot) and its right
//! along world −y. A goal ([`goal_image`]) is the height image of the groove a good stroke
//! writes, measured: the ideal writer (a kinematic stick of the task's shape,
//! [`super::write_ideal`]) drawn along a character with its tip [`PEN_TIP_Z_M`] above the
//! table writes most pixels within 3 mm of the stroke (63-89 % in seven writings of six
//! characters by kinematic sticks and the robot, the rest covered by clay crumbs) and a varying share of those 3-9 mm away (the groove's
//! walls, one side more than the other). The goal writes the pixels within
//! [`GOAL_WRITTEN_RADIUS_M`] (4 mm: those seven writings score 0.82-0.93 against it, the same
//! with the last 15 % of each character's length unwritten 0.75 on average) and makes those within
//! [`GOAL_NEAR_RADIUS_M`] near; elsewhere it is the untouched slab.

use glam::{Vec2, Vec3};
use serde::Deserialize;

use crate::error::EnvError;

/// Side of the height image (pixels).
pub const IMAGE_SIZE: usize = 64;
/// Side (m) of the square the height image covers, centred on the world origin.
pub const IMAGE_WORLD_SIZE_M: f32 = 0.21;
/// Radius (pixels) of a particle's sphere in the height image (ManiSkill2's
/// `int(0.007 * 64 / 0.21)`).
pub const RASTER_RADIUS_PX: i32 = 2;
/// Height image values per metre (pixels hold heights in mm).
pub const HEIGHT_SCALE: f32 = 1000.0;
/// A pixel below this height (mm) is written.
pub const WRITTEN_BELOW_MM: i32 = 40;
/// A pixel below this height (mm) is near a written one.
pub const NEAR_BELOW_MM: i32 = 50;

/// Clay lattice spacing (m).
pub const SLAB_SPACING_M: f32 = 0.005;
/// Lattice columns per side of the slab.
pub const SLAB_COLUMNS: usize = 42;
/// Lattice layers of the slab (5 cm of clay).
pub const SLAB_LAYERS: usize = 10;
/// Particles of the slab.
pub const SLAB_PARTICLES: usize = SLAB_COLUMNS * SLAB_COLUMNS * SLAB_LAYERS;

/// Side (m) of the square a character's unit glyph box is scaled to on the slab.
pub const GLYPH_SIZE_M: f32 = 0.1;
/// Height (m) above the table of the stick's lowest point while it writes (2.5 cm into the
/// 5 cm slab).
pub const PEN_TIP_Z_M: f32 = 0.025;
/// Radius (m) of the stick's capsule (`ms2_assets::PANDA_STICK_RADIUS`).
pub const STICK_RADIUS_M: f32 = ms2_assets::PANDA_STICK_RADIUS as f32;
/// Contact distance (m) of the clay's particles to the stick: ManiSkill2's particle radius of
/// Write, the coupling's contact offset in ms2.
pub const CONTACT_DISTANCE_M: f32 = 0.005;
/// Distance (m) from a stroke within which the goal's clay is written: the middle of the
/// groove a kinematic stick writes (measured, see the [module docs](self)).
pub const GOAL_WRITTEN_RADIUS_M: f32 = 0.004;
/// Distance (m) from a stroke within which the goal's clay is near (below
/// [`NEAR_BELOW_MM`]): the groove's walls, written or not from stroke to stroke (measured).
pub const GOAL_NEAR_RADIUS_M: f32 = 0.009;
/// The goal's height (mm) of a written pixel: the measured grooves' median.
pub const GOAL_GROOVE_MM: i32 = 28;
/// The goal's height (mm) of a near pixel.
pub const GOAL_WALL_MM: i32 = 45;

/// ms2's characters (JSON: `{"characters": [{"id", "split", "strokes": [[[x, y], ...]]}]}`).
pub const BUILTIN_STROKES: &str = include_str!("write_strokes.json");

/// Which characters an episode draws from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TargetSplit {
    /// The training characters (the env's default).
    Train,
    /// The held-out characters.
    Test,
}

impl TargetSplit {
    fn name(self) -> &'static str {
        match self {
            Self::Train => "train",
            Self::Test => "test",
        }
    }
}

/// One character: its id, split and strokes (polylines in the unit glyph box).
#[derive(Clone, Debug, Deserialize, PartialEq)]
pub struct Character {
    /// Name, e.g. `"E"`.
    pub id: String,
    /// `"train"` or `"test"`.
    pub split: String,
    /// Polylines of (x right, y up) points in [0, 1]², written in order.
    pub strokes: Vec<Vec<[f32; 2]>>,
}

impl Character {
    /// The strokes as world xy polylines (m) on the slab ([`glyph_to_world`]).
    pub fn world_strokes(&self) -> Vec<Vec<Vec2>> {
        self.strokes
            .iter()
            .map(|s| s.iter().map(|&p| glyph_to_world(Vec2::from(p))).collect())
            .collect()
    }
}

#[derive(Deserialize)]
struct StrokeFile {
    characters: Vec<Character>,
}

/// A glyph-box point (x right, y up, unit square) on the slab (world xy, m): up along +x,
/// right along −y, the box centred on the origin.
pub fn glyph_to_world(p: Vec2) -> Vec2 {
    Vec2::new((p.y - 0.5) * GLYPH_SIZE_M, -(p.x - 0.5) * GLYPH_SIZE_M)
}

/// Parses a stroke document (`source` names it in errors) and checks every character: a
/// non-empty id, split `train` or `test`, at least one stroke, every stroke of at least two
/// finite points inside the unit box.
pub fn parse_characters(text: &str, source: &str) -> Result<Vec<Character>, EnvError> {
    let bad = |why: String| EnvError::Asset(format!("Write targets {source}: {why}"));
    let file: StrokeFile = serde_json::from_str(text).map_err(|e| bad(e.to_string()))?;
    if file.characters.is_empty() {
        return Err(bad("no characters".to_owned()));
    }
    for c in &file.characters {
        if c.id.is_empty() {
            return Err(bad("a character has an empty id".to_owned()));
        }
        if c.split != "train" && c.split != "test" {
            return Err(bad(format!(
                "character {:?} has split {:?}, expected \"train\" or \"test\"",
                c.id, c.split
            )));
        }
        let ok = !c.strokes.is_empty()
            && c.strokes.iter().all(|s| {
                s.len() >= 2
                    && s.iter()
                        .flatten()
                        .all(|v| v.is_finite() && (0.0..=1.0).contains(v))
            });
        if !ok {
            return Err(bad(format!(
                "character {:?}: every stroke needs two or more points in [0, 1]²",
                c.id
            )));
        }
    }
    Ok(file.characters)
}

/// Reads and parses the stroke file at `path`; errors name the file.
pub fn load_characters(path: &std::path::Path) -> Result<Vec<Character>, EnvError> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| EnvError::Asset(format!("Write targets {}: {e}", path.display())))?;
    parse_characters(&text, &path.display().to_string())
}

/// ms2's built-in characters of `split`, in file order.
pub fn builtin_characters(split: TargetSplit) -> Vec<Character> {
    parse_characters(BUILTIN_STROKES, "(built in)")
        .unwrap_or_default()
        .into_iter()
        .filter(|c| c.split == split.name())
        .collect()
}

/// The slab's lattice (m, world), column by column (x slowest, then y, then z), before jitter:
/// columns 5 mm apart centred on the origin, layers from 2.5 mm above the table.
pub fn slab_lattice() -> Vec<Vec3> {
    let half = (SLAB_COLUMNS - 1) as f32 * SLAB_SPACING_M / 2.0;
    let mut points = Vec::with_capacity(SLAB_PARTICLES);
    for i in 0..SLAB_COLUMNS {
        for j in 0..SLAB_COLUMNS {
            for k in 0..SLAB_LAYERS {
                points.push(Vec3::new(
                    i as f32 * SLAB_SPACING_M - half,
                    j as f32 * SLAB_SPACING_M - half,
                    (k as f32 + 0.5) * SLAB_SPACING_M,
                ));
            }
        }
    }
    points
}

/// The world xy (m) of the centre of height-image pixel (`x`, `y`).
pub fn pixel_centre(x: usize, y: usize) -> Vec2 {
    let scale = IMAGE_SIZE as f32 / IMAGE_WORLD_SIZE_M;
    Vec2::new(x as f32, y as f32) / scale - Vec2::splat(IMAGE_WORLD_SIZE_M / 2.0)
}

/// Distance (m) from `p` to segment `a`-`b` (world xy).
fn segment_distance(p: Vec2, a: Vec2, b: Vec2) -> f32 {
    let ab = b - a;
    let t = if ab.length_squared() > 0.0 {
        ((p - a).dot(ab) / ab.length_squared()).clamp(0.0, 1.0)
    } else {
        0.0
    };
    p.distance(a + ab * t)
}

/// The goal height image (mm, as [`height_image`]) of `character`: the untouched slab's
/// image with its strokes' groove drawn in: pixels within [`GOAL_WRITTEN_RADIUS_M`] of a
/// stroke at [`GOAL_GROOVE_MM`] (written), pixels within [`GOAL_NEAR_RADIUS_M`] at no more
/// than [`GOAL_WALL_MM`] (near).
pub fn goal_image(character: &Character) -> Vec<i32> {
    let strokes = character.world_strokes();
    let mut image = height_image(&slab_lattice());
    for y in 0..IMAGE_SIZE {
        for x in 0..IMAGE_SIZE {
            let p = pixel_centre(x, y);
            let d = strokes
                .iter()
                .flat_map(|s| s.windows(2))
                .map(|w| segment_distance(p, w[0], w[1]))
                .fold(f32::INFINITY, f32::min);
            let px = &mut image[y * IMAGE_SIZE + x];
            if d < GOAL_WRITTEN_RADIUS_M {
                *px = GOAL_GROOVE_MM;
            } else if d < GOAL_NEAR_RADIUS_M {
                *px = (*px).min(GOAL_WALL_MM);
            }
        }
    }
    image
}

/// The height image (row `y`, column `x`, [`IMAGE_SIZE`]² values in mm) of `points` (m,
/// world), as ManiSkill2 rasterises particles: pixel (x, y) sits at world
/// (x, y) / scale − half the covered side; each point raises the pixels within
/// [`RASTER_RADIUS_PX`] of it to its sphere's top.
pub fn height_image(points: &[Vec3]) -> Vec<i32> {
    let n = IMAGE_SIZE as i32;
    let scale = IMAGE_SIZE as f32 / IMAGE_WORLD_SIZE_M;
    let offset = IMAGE_WORLD_SIZE_M / 2.0;
    let r = RASTER_RADIUS_PX as f32 / scale;
    let mut image = vec![0i32; IMAGE_SIZE * IMAGE_SIZE];
    for p in points {
        let (cx, cy) = (p.x + offset, p.y + offset);
        let sx = (cx * scale - RASTER_RADIUS_PX as f32).round() as i32;
        let sy = (cy * scale - RASTER_RADIUS_PX as f32).round() as i32;
        for i in 0..=2 * RASTER_RADIUS_PX {
            for j in 0..=2 * RASTER_RADIUS_PX {
                let (gx, gy) = (sx + i, sy + j);
                if gx < 0 || gx >= n || gy < 0 || gy >= n {
                    continue;
                }
                let x = gx as f32 / scale - cx;
                let y = gy as f32 / scale - cy;
                let z2 = r * r - x * x - y * y;
                if z2 > 0.0 {
                    let v = ((z2.sqrt() + p.z) * HEIGHT_SCALE) as i32;
                    let px = &mut image[gy as usize * IMAGE_SIZE + gx as usize];
                    *px = (*px).max(v);
                }
            }
        }
    }
    image
}

/// Pixels written in `image` (below [`WRITTEN_BELOW_MM`]).
pub fn written_pixels(image: &[i32]) -> usize {
    image.iter().filter(|&&v| v < WRITTEN_BELOW_MM).count()
}

/// ManiSkill2's IoU of the marks of two height images (see the [module docs](self)); 0 when
/// neither writes a pixel.
pub fn mark_iou(goal: &[i32], current: &[i32]) -> f32 {
    let (mut inter, mut union) = (0usize, 0usize);
    for (&g, &c) in goal.iter().zip(current) {
        let (a, an) = (g < WRITTEN_BELOW_MM, g < NEAR_BELOW_MM);
        let (b, bn) = (c < WRITTEN_BELOW_MM, c < NEAR_BELOW_MM);
        if (an && b) || (a && bn) {
            inter += 1;
        }
        if a || b {
            union += 1;
        }
    }
    if union == 0 {
        0.0
    } else {
        inter as f32 / union as f32
    }
}

/// The goal image as ManiSkill2 observes it (`extra/goal`, [`IMAGE_SIZE`]² uint8): the height
/// image with its columns reversed, clipped to 0-255 mm.
pub fn goal_display(image: &[i32]) -> Vec<u8> {
    let mut out = Vec::with_capacity(image.len());
    for row in image.chunks_exact(IMAGE_SIZE) {
        out.extend(row.iter().rev().map(|&v| v.clamp(0, 255) as u8));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn builtin_characters_parse_and_split() {
        let train = builtin_characters(TargetSplit::Train);
        let test = builtin_characters(TargetSplit::Test);
        assert!(train.len() >= 8 && !test.is_empty());
        assert!(train.iter().all(|c| !test.iter().any(|t| t.id == c.id)));
    }

    #[test]
    fn flat_slab_writes_nothing_and_goal_writes_its_strokes() {
        let flat = height_image(&slab_lattice());
        assert_eq!(written_pixels(&flat), 0);
        let e = builtin_characters(TargetSplit::Train)
            .into_iter()
            .find(|c| c.id == "E")
            .unwrap();
        let goal = goal_image(&e);
        let written = written_pixels(&goal);
        assert!(written > 100, "{written} pixels written");
        assert_eq!(mark_iou(&goal, &goal), 1.0);
        assert_eq!(mark_iou(&goal, &flat), 0.0);
        // The glyph's vertical stroke (x = 0 in the glyph) runs along world x at y = +5 cm.
        let px = |x: f32, y: f32| {
            let s = IMAGE_SIZE as f32 / IMAGE_WORLD_SIZE_M;
            let (gx, gy) = (((x + 0.105) * s) as usize, ((y + 0.105) * s) as usize);
            goal[gy * IMAGE_SIZE + gx]
        };
        assert!(px(0.0, 0.05) < WRITTEN_BELOW_MM);
        assert!(px(0.0, -0.08) > NEAR_BELOW_MM);
        // Its walls, 6 mm aside (between the bars), are near but not written.
        let wall = px(-0.025, 0.044);
        assert!((WRITTEN_BELOW_MM..NEAR_BELOW_MM).contains(&wall), "{wall}");
    }

    #[test]
    fn malformed_documents_are_errors_naming_the_source() {
        for text in [
            "not json",
            r#"{"characters": []}"#,
            r#"{"characters": [{"id": "Q", "split": "dev", "strokes": [[[0, 0], [1, 1]]]}]}"#,
            r#"{"characters": [{"id": "Q", "split": "train", "strokes": [[[0, 0]]]}]}"#,
            r#"{"characters": [{"id": "Q", "split": "train", "strokes": [[[0, 0], [2, 1]]]}]}"#,
        ] {
            let e = parse_characters(text, "my_strokes.json").unwrap_err();
            assert!(e.to_string().contains("my_strokes.json"), "{e}");
        }
    }
}
