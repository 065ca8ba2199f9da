//! OGC 3D Tiles 1.1 documents for the glTF tiles: the tileset JSON (implicit quadtree tiling,
//! `REPLACE` refinement, glTF content) and its binary subtree files, and the root transform that
//! anchors the tileset on the WGS 84 ellipsoid for Earth-based clients.
//!
//! **Frame.** 3D Tiles is Z-up; clients turn glTF content from Y-up to Z-up, so the glTF frame of
//! [`crate::assets`] (X east, Y up, Z south, 1 unit = 1 native texel) becomes x east, y north,
//! z up: texel `(tx, ty)` lies at `(tx, −ty, 0)`. That is an east-north-up frame, the local frame
//! of [`enu_to_ecef`].
//!
//! **Tree.** The root is tile `0/0/0` of the XYZ scheme at the coarsest zoom, covering
//! `[0, 256·2^native]²` texels; implicit level `l` is zoom `l`, up to the largest zoom served.
//! Implicit tile coordinates count x east and y north from the root's south-west corner, XYZ rows
//! count south from its north edge: row = `2^l − 1 − y` ([`xyz_row`]).
//!
//! **Subtrees.** Every tile of every available level exists, so a subtree is constant
//! availability, except the deepest subtrees, whose last levels lie beyond the tree: their tile
//! and content availability is a bitstream with those levels cleared, and they have no child
//! subtrees.

use serde_json::{json, Value};

/// Levels per subtree file: 85 tiles (1 + 4 + 16 + 64), few enough for clients that expand a
/// subtree's tiles at once, and a zoom range of 0..=10 in three subtree levels.
pub const SUBTREE_LEVELS: u32 = 4;

/// Screen-space error, in pixels, at which the clients' defaults refine (CesiumJS
/// `maximumScreenSpaceError`, 3DTilesRendererJS `errorTarget`: both 16).
const DEFAULT_SSE: f64 = 16.0;

/// The tree of one texture: its zooms and the root's size.
#[derive(Debug, Clone, Copy)]
pub struct Tree {
    /// The texture's native zoom.
    pub native: u32,
    /// Implicit levels: zooms `0..levels`.
    pub levels: u32,
}

impl Tree {
    /// Side of the root tile in world units (native texels).
    pub fn root_side(&self) -> f64 {
        256.0 * 2f64.powi(self.native as i32)
    }

    /// Geometric error of level `l`: the size of a texel of zoom `l` times the clients' default
    /// screen-space error, so that with their defaults a tile is replaced by its children once
    /// its texels would cover more than a pixel. It halves with every level, as implicit tiling
    /// requires.
    pub fn geometric_error(&self, level: u32) -> f64 {
        DEFAULT_SSE * 2f64.powi(self.native as i32 - level as i32)
    }

    /// Whether `level/x/y` is a tile of the tree.
    pub fn contains(&self, level: u32, x: i64, y: i64) -> bool {
        let n = 1i64 << level.min(62);
        level < self.levels && (0..n).contains(&x) && (0..n).contains(&y)
    }
}

/// The XYZ row of implicit tile `y` at `level` (the y flip: implicit y counts north).
pub fn xyz_row(level: u32, y: i64) -> i64 {
    (1i64 << level) - 1 - y
}

/// Column-major 4×4 matrix from the east-north-up frame at `lon`, `lat` (degrees) and `height`
/// (metres above the WGS 84 ellipsoid) to Earth-centred, Earth-fixed coordinates.
pub fn enu_to_ecef(lon: f64, lat: f64, height: f64) -> [f64; 16] {
    const A: f64 = 6_378_137.0;
    const E2: f64 = 6.694_379_990_141_316e-3;
    let (sl, cl) = lon.to_radians().sin_cos();
    let (sp, cp) = lat.to_radians().sin_cos();
    let n = A / (1.0 - E2 * sp * sp).sqrt();
    let p = [(n + height) * cp * cl, (n + height) * cp * sl, (n * (1.0 - E2) + height) * sp];
    let east = [-sl, cl, 0.0];
    let north = [-sp * cl, -sp * sl, cp];
    let up = [cp * cl, cp * sl, sp];
    [east[0], east[1], east[2], 0.0, north[0], north[1], north[2], 0.0, up[0], up[1], up[2], 0.0, p[0], p[1], p[2], 1.0]
}

/// The tileset JSON. `query` is the request's query string (mode and its parameters, without
/// the anchoring ones), carried into the content URIs; `transform` anchors the root; `relief`
/// the height of a displaced mesh's highest point, which the bounding volumes contain (from its
/// skirts' foot, [`crate::assets::SKIRT_DEPTH`] below the ground, to `relief` above).
pub fn tileset(tree: &Tree, query: &str, transform: Option<[f64; 16]>, relief: Option<f32>, generator: &str) -> Value {
    let h = tree.root_side() / 2.0;
    let sep = if query.is_empty() { "" } else { "?" };
    // The vertical extent: a flat quad lies in the ground (one texel thick around it).
    let (z0, z1) = match relief {
        Some(r) => (-(crate::assets::SKIRT_DEPTH as f64), r as f64),
        None => (-0.5, 0.5),
    };
    let (zc, zh) = ((z0 + z1) / 2.0, (z1 - z0) / 2.0);
    let mut root = json!({
        // Centre, then the x, y and z half-axes: the root square, as thick as its content.
        "boundingVolume": { "box": [h, -h, zc, h, 0.0, 0.0, 0.0, h, 0.0, 0.0, 0.0, zh] },
        "geometricError": tree.geometric_error(0),
        "refine": "REPLACE",
        "content": { "uri": format!("tiles/{{level}}/{{x}}/{{y}}.glb{sep}{query}") },
        "implicitTiling": {
            "subdivisionScheme": "QUADTREE",
            "subtreeLevels": SUBTREE_LEVELS.min(tree.levels),
            "availableLevels": tree.levels,
            "subtrees": { "uri": "subtrees/{level}/{x}/{y}.subtree" },
        },
    });
    if let Some(m) = transform {
        root["transform"] = json!(m);
    }
    json!({
        "asset": { "version": "1.1", "generator": generator },
        "geometricError": 2.0 * tree.geometric_error(0),
        "root": root,
    })
}

/// The subtree file rooted at `level` (every subtree at one level is the same).
pub fn subtree(tree: &Tree, level: u32) -> Vec<u8> {
    let levels = SUBTREE_LEVELS.min(tree.levels);
    // Levels of this subtree inside the tree.
    let inside = tree.levels.saturating_sub(level).min(levels);
    let (json, bin) = if inside == levels {
        let children = if level + levels < tree.levels { 1 } else { 0 };
        let doc = json!({
            "tileAvailability": { "constant": 1 },
            "contentAvailability": [{ "constant": 1 }],
            "childSubtreeAvailability": { "constant": children },
        });
        (doc, Vec::new())
    } else {
        // Tiles level by level (Morton order within a level), one bit each, least significant
        // bit first: the first `(4^inside − 1) / 3` are the available ones.
        let total = tiles_in(levels);
        let available = tiles_in(inside);
        let mut bits = vec![0u8; total.div_ceil(8) as usize];
        for i in 0..available {
            bits[(i / 8) as usize] |= 1 << (i % 8);
        }
        let len = bits.len();
        let doc = json!({
            "buffers": [{ "byteLength": len.next_multiple_of(8) }],
            "bufferViews": [{ "buffer": 0, "byteOffset": 0, "byteLength": len }],
            "tileAvailability": { "bitstream": 0, "availableCount": available },
            "contentAvailability": [{ "bitstream": 0, "availableCount": available }],
            "childSubtreeAvailability": { "constant": 0 },
        });
        (doc, bits)
    };
    subtree_bytes(&json, bin)
}

/// Tiles in the first `levels` levels of a quadtree.
fn tiles_in(levels: u32) -> u64 {
    ((1u64 << (2 * levels)) - 1) / 3
}

/// The binary subtree container: a 24-byte header (magic `subt`, version 1, JSON and binary
/// lengths as u64), the JSON padded with spaces and the binary with zeros to 8 bytes.
fn subtree_bytes(json: &Value, mut bin: Vec<u8>) -> Vec<u8> {
    let mut js = serde_json::to_vec(json).unwrap_or_default();
    while !js.len().is_multiple_of(8) {
        js.push(b' ');
    }
    while !bin.len().is_multiple_of(8) {
        bin.push(0);
    }
    let mut out = Vec::with_capacity(24 + js.len() + bin.len());
    out.extend_from_slice(b"subt");
    out.extend_from_slice(&1u32.to_le_bytes());
    out.extend_from_slice(&(js.len() as u64).to_le_bytes());
    out.extend_from_slice(&(bin.len() as u64).to_le_bytes());
    out.extend_from_slice(&js);
    out.extend_from_slice(&bin);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn enu_frame_is_orthonormal_on_the_ellipsoid() {
        let m = enu_to_ecef(2.35, 48.85, 0.0);
        let col = |i: usize| [m[4 * i], m[4 * i + 1], m[4 * i + 2]];
        let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
        for i in 0..3 {
            assert!((dot(col(i), col(i)) - 1.0).abs() < 1e-12);
            for j in 0..i {
                assert!(dot(col(i), col(j)).abs() < 1e-12);
            }
        }
        let r = dot(col(3), col(3)).sqrt();
        assert!((6_356_752.0..6_378_138.0).contains(&r), "{r}");
    }

    #[test]
    fn deepest_subtrees_clear_the_levels_beyond_the_tree() {
        let tree = Tree { native: 7, levels: 11 };
        // Subtrees at 0, 4 and 8; the one at 8 holds levels 8, 9 and 10 of its four.
        let b = subtree(&tree, 8);
        let jl = u64::from_le_bytes(b[8..16].try_into().unwrap()) as usize;
        let json: Value = serde_json::from_slice(&b[24..24 + jl]).unwrap();
        assert_eq!(json["tileAvailability"]["availableCount"], 21);
        let bits = &b[24 + jl..];
        let set = (0..85).filter(|i| bits[i / 8] >> (i % 8) & 1 == 1).count();
        assert_eq!(set, 21);
        assert_eq!(xyz_row(3, 0), 7);
    }
}
