//! OGC 3D Tiles 1.1 documents for the glTF tiles: the tileset JSON (implicit quadtree tiling,
//! `REPLACE` refinement, glTF content) and its binary subtree files, and the root transform that
//! anchors the tileset on the WGS 84 ellipsoid for Earth-based clients.
//!
//! **Frame.** 3D Tiles is Z-up; clients turn glTF content from Y-up to Z-up, so the glTF frame of
//! [`crate::scene::assets`] (X east, Y up, Z south, 1 unit = 1 native texel) becomes x east, y north,
//! z up: texel `(tx, ty)` lies at `(tx, −ty, 0)`. That is an east-north-up frame, the local frame
//! of [`enu_to_ecef`].
//!
//! **Tree.** The world has no edge a viewer reaches: the root is a square of
//! [`WORLD_TEXELS`]² native texels centred on texel `(0, 0)` (67 million texels a side, five
//! times the Earth's diameter in metres), far larger than any view (`/3d.html` sees at most
//! 30 million texels away, from at most [`MAX_VIEW_HEIGHT`] above the ground). Implicit level
//! `l` is zoom `l − lift` (`lift` = [`Tree::lift`] levels above zoom 0); XYZ tile `(z, col, row)`
//! is implicit tile `(z + lift, col + 2^(l−1), 2^(l−1) − 1 − row)` (implicit y counts north from
//! the root's south-west corner, XYZ rows south: [`Tree::content`]). The levels above zoom 0
//! show what zoom 0 shows, the texture's mean colour (every pixel of a zoom-0 tile covers the
//! whole exemplar), on quads that span `2^(lift − l)` zoom-0 tiles a side.
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

/// Side of the world (the root tile), in native texels: 2^26.
pub const WORLD_TEXELS: f64 = (1u64 << 26) as f64;

/// Highest a viewer's camera goes above the ground, in native texels (`/3d.html`'s
/// `maxDistance`, the README CesiumJS recipe's `maximumZoomDistance`): from there the ground's
/// far end, at least half the world away, lies within a hundredth of a degree of the horizon.
pub const MAX_VIEW_HEIGHT: f64 = 20_000.0;

/// The tree of one texture: its zooms and the root's size.
#[derive(Debug, Clone, Copy)]
pub struct Tree {
    /// The texture's native zoom.
    pub native: u32,
    /// Implicit levels: zooms `−lift..levels − lift`.
    pub levels: u32,
    /// Levels above zoom 0, so that the root is [`WORLD_TEXELS`] a side.
    pub lift: u32,
}

/// What an implicit tile shows.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Content {
    /// XYZ tile `(z, col, row)`.
    Tile { z: u32, x: i64, y: i64 },
    /// Above zoom 0: the zoom-0 image on a quad of `2^span` zoom-0 tiles a side whose
    /// north-west tile is `(col, row)` of zoom 0.
    Lifted { span: u32, x: i64, y: i64 },
}

impl Tree {
    /// The tree of a texture of native zoom `native` served up to zoom `max_zoom`.
    pub fn new(native: u32, max_zoom: u32) -> Tree {
        let zoom0 = 256u64 << native.min(40);
        let lift = (WORLD_TEXELS as u64 / zoom0).max(1).ilog2();
        Tree { native, levels: lift + max_zoom + 1, lift }
    }

    /// Side of the root tile in world units (native texels).
    pub fn root_side(&self) -> f64 {
        256.0 * 2f64.powi((self.native + self.lift) as i32)
    }

    /// Geometric error of level `l`: the size of a texel of its zoom times the clients' default
    /// screen-space error, so that with their defaults a tile is replaced by its children once
    /// its texels would cover more than a pixel. It halves with every level, as implicit tiling
    /// requires.
    pub fn geometric_error(&self, level: u32) -> f64 {
        DEFAULT_SSE * 2f64.powi((self.native + self.lift) as i32 - level as i32)
    }

    /// What implicit tile `level/x/y` shows (a tile of the tree).
    pub fn content(&self, level: u32, x: i64, y: i64) -> Content {
        match level.checked_sub(self.lift) {
            Some(z) => {
                // Half the tiles across, at this level: the root is centred on texel (0, 0).
                let half = (1i64 << level) / 2;
                Content::Tile { z, x: x - half, y: xyz_row(level, y) - half }
            }
            None => {
                // 2^span zoom-0 tiles a side; the root's 2^lift start 2^(lift−1) west and north
                // of texel (0, 0).
                let span = self.lift - level;
                let half = 1i64 << (self.lift - 1);
                Content::Lifted { span, x: (x << span) - half, y: (xyz_row(level, y) << span) - half }
            }
        }
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
/// skirts' foot, [`crate::scene::assets::SKIRT_DEPTH`] below the ground, to `relief` above).
pub fn tileset(tree: &Tree, query: &str, transform: Option<[f64; 16]>, relief: Option<f32>, generator: &str) -> Value {
    let h = tree.root_side() / 2.0;
    let sep = if query.is_empty() { "" } else { "?" };
    // The vertical extent: a flat quad lies in the ground (one texel thick around it).
    let (z0, z1) = match relief {
        Some(r) => (-(crate::scene::assets::SKIRT_DEPTH as f64), r as f64),
        None => (-0.5, 0.5),
    };
    let (zc, zh) = ((z0 + z1) / 2.0, (z1 - z0) / 2.0);
    let mut root = json!({
        // Centre, then the x, y and z half-axes: the root square around texel (0, 0), as thick
        // as its content.
        "boundingVolume": { "box": [0.0, 0.0, zc, h, 0.0, 0.0, 0.0, h, 0.0, 0.0, 0.0, zh] },
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
        // How implicit levels and tiles map to the XYZ tiles (module comment).
        "extras": { "level_of_zoom_0": tree.lift, "world_texels": tree.root_side() },
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
        let tree = Tree { native: 7, levels: 11, lift: 0 };
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

    /// Every level's tiles cover the root square exactly once: zoom 0's tile (0, 0) starts at
    /// texel (0, 0), each implicit tile's content covers its box, and lifted tiles tile the
    /// zoom-0 grid.
    #[test]
    fn implicit_tiles_map_onto_the_xyz_grid() {
        let tree = Tree::new(7, 10);
        assert_eq!((tree.lift, tree.levels, tree.root_side()), (11, 22, WORLD_TEXELS));
        let zoom0 = 256.0 * 128.0;
        // Level l, tile (x, y): texel x0 = x·w − half and north edge (2^l − 1 − y)·w − half.
        for level in [0u32, 1, 2, 5, 10, 11, 12, 21] {
            let n = 1i64 << level;
            let w = WORLD_TEXELS / n as f64;
            for (x, y) in [(0, 0), (n - 1, 0), (n / 2, (n / 2 - 1).max(0)), (n / 3, n - 1)] {
                let (x0, y0) = (x as f64 * w - WORLD_TEXELS / 2.0, (n - 1 - y) as f64 * w - WORLD_TEXELS / 2.0);
                let got = match tree.content(level, x, y) {
                    Content::Tile { z, x, y } => {
                        let t = 256.0 * 2f64.powi(7 - z as i32);
                        (x as f64 * t, y as f64 * t, t)
                    }
                    Content::Lifted { span, x, y } => {
                        (x as f64 * zoom0, y as f64 * zoom0, zoom0 * 2f64.powi(span as i32))
                    }
                };
                assert_eq!(got, (x0, y0, w), "{level}/{x}/{y}");
            }
        }
        assert_eq!(tree.content(11, 1024, 1023), Content::Tile { z: 0, x: 0, y: 0 });
    }
}
