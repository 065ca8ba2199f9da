//! 3D asset documents for mesh-texturing clients: glTF 2.0 (binary GLB with embedded tile
//! images, or JSON referencing tile URLs) and X3D scenes, each a ground quad per tile.
//!
//! World frame (documented in the README): Y up, X east = texel x, Z south = texel y, 1 unit =
//! 1 texel at the native zoom. A tile at zoom z covers `s = 256·2^(N−z)` units; its node is
//! translated to `(s·x, 0, s·y)` and its mesh spans `[0, s]²` locally, so vertex positions stay
//! small (f32-exact) however far the tile is.
//!
//! Each quad's image is its tile with a border of [`BORDER`] texels of the neighbouring texture
//! on every side (a window of the one texture, so the border is exactly what the neighbours
//! show); texture coordinates map the quad onto the inner 256², and samplers filter with
//! mipmaps (`LINEAR_MIPMAP_LINEAR`). Bilinear filtering and mip levels then blend across a tile
//! edge as they would inside one big texture.

use base64::Engine;
use serde_json::{json, Value};
use textile_core::TILE_SIZE;

/// One textured ground quad.
pub struct Quad {
    /// Node name.
    pub name: String,
    /// North-west corner in world units (texels at native zoom).
    pub origin: (f64, f64),
    /// Side in world units.
    pub size: f64,
}

/// Border texels around a tile's 256² in every 3D asset image (288² images). 16 is the widest
/// border the mip levels a client builds need before the tile should be replaced by a coarser
/// zoom: at mip level `l` the border is `16 / 2^l` texels, at least one up to level 4 (1/16
/// minification, four zoom levels out), where a bilinear tap reaches half a texel past the inner
/// square; and it is even at every level up to 4, so those levels' texels fall on the same world
/// grid as one big texture's. It costs 27 % more texels than the bare tile.
pub const BORDER: u32 = 16;

/// Version of the documents' layout (border, texture coordinates, samplers, viewpoints, relief
/// mesh and its quantized vertex data, X3D lights): part of every 3D asset's cache key, so a
/// change of layout changes their ETags.
pub const LAYOUT: u32 = 5;

/// Side of a tile's image in the 3D assets, border included.
pub fn image_side() -> u32 {
    TILE_SIZE as u32 + 2 * BORDER
}

/// The texture coordinate of the inner square's near edge (the far edge is `1 - inset()`).
fn inset() -> f64 {
    BORDER as f64 / image_side() as f64
}

const GLB_MAGIC: u32 = 0x4654_6C67; // "glTF"
const CHUNK_JSON: u32 = 0x4E4F_534A;
const CHUNK_BIN: u32 = 0x004E_4942;
// Sampler constants (WebGL enums, as glTF names them).
const LINEAR: u32 = 9729;
const LINEAR_MIPMAP_LINEAR: u32 = 9987;
const CLAMP_TO_EDGE: u32 = 33071;
// Accessor component types.
const BYTE: u32 = 5120;
const UNSIGNED_SHORT: u32 = 5123;
const FLOAT: u32 = 5126;

fn pad4(v: &mut Vec<u8>, byte: u8) {
    while !v.len().is_multiple_of(4) {
        v.push(byte);
    }
}

/// Append `bytes` to the binary buffer as a new buffer view (of `target`, when given), 4-aligned.
fn push_view(bin: &mut Vec<u8>, views: &mut Vec<Value>, bytes: &[u8], target: Option<u32>) {
    let mut view = json!({ "buffer": 0, "byteOffset": bin.len(), "byteLength": bytes.len() });
    if let Some(t) = target {
        view["target"] = json!(t);
    }
    views.push(view);
    bin.extend_from_slice(bytes);
    pad4(bin, 0);
}

/// Little-endian bytes of floats.
fn le(v: &[f32]) -> Vec<u8> {
    v.iter().flat_map(|x| x.to_le_bytes()).collect()
}

/// Geometry shared by every quad of a document: positions, normals, texture coordinates and
/// indices of a `size × size` quad facing up, as one little-endian byte block with its views.
fn geometry(size: f32) -> (Vec<u8>, Vec<Value>, Vec<Value>) {
    let mut b = Vec::new();
    let pos = [[0.0, 0.0, 0.0], [size, 0.0, 0.0], [size, 0.0, size], [0.0, 0.0, size]];
    let nrm = [[0.0f32, 1.0, 0.0]; 4];
    let (near, far) = (inset() as f32, 1.0 - inset() as f32);
    let uv = [[near, near], [far, near], [far, far], [near, far]];
    let idx: [u16; 6] = [0, 2, 1, 0, 3, 2];
    let mut views = Vec::new();
    push_view(&mut b, &mut views, &le(pos.as_flattened()), Some(34962));
    push_view(&mut b, &mut views, &le(nrm.as_flattened()), Some(34962));
    push_view(&mut b, &mut views, &le(uv.as_flattened()), Some(34962));
    push_view(&mut b, &mut views, &idx.iter().flat_map(|v| v.to_le_bytes()).collect::<Vec<u8>>(), Some(34963));
    let accessors = vec![
        json!({ "bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0.0, 0.0, 0.0], "max": [size, 0.0, size] }),
        json!({ "bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC3" }),
        json!({ "bufferView": 2, "componentType": 5126, "count": 4, "type": "VEC2" }),
        json!({ "bufferView": 3, "componentType": 5123, "count": 6, "type": "SCALAR" }),
    ];
    (b, views, accessors)
}

/// The glTF JSON for quads of equal size, one material and texture per quad; `images[i]` is
/// filled in by the caller (embedded buffer view or URI).
fn document(quads: &[Quad], generator: &str, views: Vec<Value>, accessors: Vec<Value>, images: Vec<Value>) -> Value {
    let n = quads.len();
    json!({
        "asset": { "version": "2.0", "generator": generator },
        "scene": 0,
        "scenes": [{ "nodes": (0..n).collect::<Vec<_>>() }],
        "nodes": quads.iter().enumerate().map(|(i, q)| json!({
            "name": q.name, "mesh": i, "translation": [q.origin.0, 0.0, q.origin.1],
        })).collect::<Vec<_>>(),
        "meshes": (0..n).map(|i| json!({ "primitives": [{
            "attributes": { "POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2 }, "indices": 3, "material": i,
        }]})).collect::<Vec<_>>(),
        "materials": quads.iter().enumerate().map(|(i, q)| json!({
            "name": q.name,
            "pbrMetallicRoughness": { "baseColorTexture": { "index": i }, "metallicFactor": 0.0, "roughnessFactor": 1.0 },
        })).collect::<Vec<_>>(),
        "textures": (0..n).map(|i| json!({ "sampler": 0, "source": i })).collect::<Vec<_>>(),
        "samplers": [{ "magFilter": LINEAR, "minFilter": LINEAR_MIPMAP_LINEAR, "wrapS": CLAMP_TO_EDGE, "wrapT": CLAMP_TO_EDGE }],
        "images": images,
        "accessors": accessors,
        "bufferViews": views,
    })
}

/// Tile pixels per cell of a relief mesh: a tile's mesh is a grid of 32 × 32 cells (33² vertices),
/// its density following the tile's level like its texels do (a tile is refined once its texels
/// would cover more than a pixel, so a cell never spans more than 8 screen pixels).
pub const RELIEF_STEP: u32 = 8;

/// How far below the lowest height (0, the height map's black) a relief's skirts reach, in
/// world units: a tile's edge and a finer neighbour's meet along different polylines, and the
/// skirt hanging from each edge down past every height closes the gap between them.
pub const SKIRT_DEPTH: f32 = 0.5;

/// A displaced mesh (`relief=SCALE`): one vertex per corner of a grid of [`RELIEF_STEP`]-pixel
/// cells over the tile, exactly its extent, so that neighbours share their edge vertices,
/// heights included; each vertex's height is the mean of the [`RELIEF_STEP`]² height texels
/// around it (the height filtered to the mesh's density: texel noise does not become spikes).
pub struct Relief {
    /// Vertices per side.
    pub n: usize,
    /// Heights in world units (native texels), row-major.
    pub heights: Vec<f32>,
}

impl Relief {
    /// The relief of a tile from its bordered height image ([`image_side`]²): white is `scale`
    /// texels high. Corner `(i, j)` of the grid lies at tile pixel corner `(8i, 8j)`; its
    /// height averages pixels `8i − 4 .. 8i + 4` across and down, inside the border.
    pub fn from_border_image(img: &image::GrayImage, scale: f32) -> Relief {
        let step = RELIEF_STEP as usize;
        let n = TILE_SIZE as usize / step + 1;
        let b = BORDER as usize;
        let w = img.width() as usize;
        let px = img.as_raw();
        let at = |x: usize, y: usize| px.get(y * w + x).copied().unwrap_or(0) as u32;
        let mut heights = Vec::with_capacity(n * n);
        for j in 0..n {
            for i in 0..n {
                let (x0, y0) = (b + step * i - step / 2, b + step * j - step / 2);
                let sum: u32 = (y0..y0 + step).flat_map(|y| (x0..x0 + step).map(move |x| at(x, y))).sum();
                heights.push(scale * sum as f32 / (255 * step * step) as f32);
            }
        }
        Relief { n, heights }
    }
}

/// The displaced grid of a `size × size` tile: vertex `(i, j)` at grid corner `(i, j)` (cells of
/// `size / 32` units), at its height; along every edge a skirt down to `−`[`SKIRT_DEPTH`] (faces
/// both ways), so no gap opens where a coarser or finer neighbour's edge runs at other heights;
/// normals up (the normal map shades the relief), texture coordinates on the image's pixel
/// corners; `u16` indices. The accessors are in [`geometry`]'s order.
///
/// Its vertex data is compact (`KHR_mesh_quantization`, which the document then requires):
/// normals as normalized bytes, texture coordinates as normalized `u16` (within 0.002 texel of
/// the pixel corners): 24 bytes a vertex with the tangent of [`add_tangent`], against 48 in floats.
/// Positions stay floats, so that neighbours' shared edge vertices are bit for bit the same.
fn relief_geometry(size: f32, r: &Relief) -> (Vec<u8>, Vec<Value>, Vec<Value>) {
    let n = r.n;
    let cell = size / (n - 1) as f32;
    let (side, px) = (image_side() as f32, RELIEF_STEP as f32);
    let mut pos = Vec::with_capacity((n * n + 4 * n) * 3);
    let mut uv = Vec::with_capacity((n * n + 4 * n) * 2);
    let mut hi = 0f32;
    let vertex = |i: usize, j: usize, y: f32, pos: &mut Vec<f32>, uv: &mut Vec<f32>| {
        pos.extend([i as f32 * cell, y, j as f32 * cell]);
        uv.extend([(BORDER as f32 + i as f32 * px) / side, (BORDER as f32 + j as f32 * px) / side]);
    };
    for j in 0..n {
        for i in 0..n {
            let h = r.heights[j * n + i];
            hi = hi.max(h);
            vertex(i, j, h, &mut pos, &mut uv);
        }
    }
    let mut idx: Vec<u16> = Vec::with_capacity((n - 1) * (n - 1) * 6 + 4 * (n - 1) * 12);
    for j in 0..n - 1 {
        for i in 0..n - 1 {
            let (a, b) = ((j * n + i) as u16, (j * n + i + 1) as u16);
            let (c, d) = (((j + 1) * n + i + 1) as u16, ((j + 1) * n + i) as u16);
            idx.extend([a, c, b, a, d, c]);
        }
    }
    // The skirts: each edge's vertices again, lowered, joined to the edge by quads facing both ways.
    let edges: [Vec<(usize, usize)>; 4] = [
        (0..n).map(|i| (i, 0)).collect(),
        (0..n).map(|i| (i, n - 1)).collect(),
        (0..n).map(|j| (0, j)).collect(),
        (0..n).map(|j| (n - 1, j)).collect(),
    ];
    for edge in &edges {
        let first = (pos.len() / 3) as u16;
        for &(i, j) in edge {
            vertex(i, j, -SKIRT_DEPTH, &mut pos, &mut uv);
        }
        for (k, w) in edge.windows(2).enumerate() {
            let (a, b) = ((w[0].1 * n + w[0].0) as u16, (w[1].1 * n + w[1].0) as u16);
            let (c, d) = (first + k as u16 + 1, first + k as u16);
            idx.extend([a, b, c, a, c, d, a, c, b, a, d, c]);
        }
    }
    let count = pos.len() / 3;
    // Up, as normalized bytes padded to 4 (vertex elements are 4-byte aligned).
    let nrm: Vec<u8> = (0..count).flat_map(|_| [0, 127, 0, 0]).collect();
    let uv16: Vec<u8> = uv.iter().flat_map(|&u| unorm16(u).to_le_bytes()).collect();
    let (mut b, mut views) = (Vec::new(), Vec::new());
    push_view(&mut b, &mut views, &le(&pos), Some(34962));
    push_view(&mut b, &mut views, &nrm, Some(34962));
    views[1]["byteStride"] = json!(4);
    push_view(&mut b, &mut views, &uv16, Some(34962));
    push_view(&mut b, &mut views, &idx.iter().flat_map(|v| v.to_le_bytes()).collect::<Vec<u8>>(), Some(34963));
    let accessors = vec![
        json!({ "bufferView": 0, "componentType": FLOAT, "count": count, "type": "VEC3", "min": [0.0, -SKIRT_DEPTH, 0.0], "max": [size, hi, size] }),
        json!({ "bufferView": 1, "componentType": BYTE, "normalized": true, "count": count, "type": "VEC3" }),
        json!({ "bufferView": 2, "componentType": UNSIGNED_SHORT, "normalized": true, "count": count, "type": "VEC2" }),
        json!({ "bufferView": 3, "componentType": UNSIGNED_SHORT, "count": idx.len(), "type": "SCALAR" }),
    ];
    (b, views, accessors)
}

/// `v` in 0..=1 as a normalized `u16` (`v · 65535`, rounded).
fn unorm16(v: f32) -> u16 {
    (v.clamp(0.0, 1.0) * 65535.0).round() as u16
}

/// Add extension `name` to those `doc` uses (and, if `required`, to those it requires).
fn use_extension(doc: &mut Value, name: &str, required: bool) {
    let lists: &[&str] = if required { &["extensionsUsed", "extensionsRequired"] } else { &["extensionsUsed"] };
    for list in lists {
        let mut names = doc[*list].as_array().cloned().unwrap_or_default();
        if !names.iter().any(|n| n == name) {
            names.push(json!(name));
        }
        doc[*list] = json!(names);
    }
}

/// What a material map is to a glTF material.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Slot {
    /// `normalTexture`: tangent-space normals, +Y up (the maps' served convention).
    Normal,
    /// `occlusionTexture` (its R channel).
    Occlusion,
    /// `KHR_materials_specular`'s `specularColorTexture`: a game's grey specular intensity `s`
    /// scales the dielectric reflectance, `F0 = 0.04 · s` (1 = a plain dielectric's highlight).
    Specular,
    /// A roughness map: the G channel of `metallicRoughnessTexture` ([`metallic_roughness`]).
    Roughness,
    /// A metallic map: the B channel of `metallicRoughnessTexture`.
    Metallic,
    /// `metallicRoughnessTexture` itself: G roughness, B metalness (factors 1).
    MetallicRoughness,
}

/// glTF's packed `metallicRoughnessTexture` of a tile: G from the roughness map (fully rough
/// where there is none), B from the metallic map (no metal where there is none), R unused
/// (255). Both images, when given, are the tile's bordered windows of those maps.
pub fn metallic_roughness(
    roughness: Option<&image::GrayImage>,
    metallic: Option<&image::GrayImage>,
) -> image::RgbImage {
    let side = image_side();
    image::RgbImage::from_fn(side, side, |x, y| {
        let g = roughness.and_then(|r| r.get_pixel_checked(x, y)).map_or(255, |p| p.0[0]);
        let b = metallic.and_then(|m| m.get_pixel_checked(x, y)).map_or(0, |p| p.0[0]);
        image::Rgb([255, g, b])
    })
}

impl Slot {
    /// The slot of a material map, by its name (`normal`, `ao`, `specular`).
    pub fn of(map: &str) -> Option<Slot> {
        match map {
            "normal" => Some(Slot::Normal),
            "ao" => Some(Slot::Occlusion),
            "specular" => Some(Slot::Specular),
            "roughness" => Some(Slot::Roughness),
            "metallic" => Some(Slot::Metallic),
            _ => None,
        }
    }

    /// The name of a slot a material's image fills, in the URIs of `.gltf` documents' images.
    pub fn name(self) -> &'static str {
        match self {
            Slot::Normal => "normal",
            Slot::Occlusion => "occlusion",
            Slot::Specular => "specular",
            Slot::Roughness => "roughness",
            Slot::Metallic => "metallic",
            Slot::MetallicRoughness => "metallic_roughness",
        }
    }

    /// The material image a map fills: its own, or for roughness and metallic maps the packed
    /// `metallicRoughnessTexture`.
    pub fn image(self) -> Slot {
        match self {
            Slot::Roughness | Slot::Metallic => Slot::MetallicRoughness,
            s => s,
        }
    }

    /// The slot of a material image, by [`Slot::name`] (packed slots only: roughness and
    /// metallic maps are in `metallic_roughness`).
    pub fn parse(name: &str) -> Option<Slot> {
        [Slot::Normal, Slot::Occlusion, Slot::Specular, Slot::MetallicRoughness].into_iter().find(|s| s.name() == name)
    }
}

/// Add a `TANGENT` of +X (increasing u) with w = +1 to the first mesh of `doc`, for a normal
/// map's tangent space: the bitangent N × T = −Z is north, the image's up, as the maps' +Y.
/// `quantized`: as normalized bytes (`KHR_mesh_quantization`), else floats.
fn add_tangent(doc: &mut Value, bin: &mut Vec<u8>, quantized: bool) {
    let vertices = doc["accessors"][0]["count"].as_u64().unwrap_or(4) as usize;
    let view = doc["bufferViews"].as_array().map_or(0, Vec::len);
    let mut views = std::mem::take(&mut doc["bufferViews"]).as_array().cloned().unwrap_or_default();
    let (bytes, component) = if quantized {
        ([127u8, 0, 0, 127].repeat(vertices), BYTE)
    } else {
        (le(vec![[1.0f32, 0.0, 0.0, 1.0]; vertices].as_flattened()), FLOAT)
    };
    let mut tangent = json!({ "bufferView": view, "componentType": component, "count": vertices, "type": "VEC4" });
    if quantized {
        tangent["normalized"] = json!(true);
    }
    push_view(bin, &mut views, &bytes, Some(34962));
    doc["bufferViews"] = json!(views);
    let accessor = doc["accessors"].as_array().map_or(0, Vec::len);
    if let Some(a) = doc["accessors"].as_array_mut() {
        a.push(tangent);
    }
    doc["meshes"][0]["primitives"][0]["attributes"]["TANGENT"] = json!(accessor);
}

/// Add material maps (PNG images already in `images`, by index) to material `m` of `doc`.
fn add_maps(doc: &mut Value, m: usize, maps: &[(Slot, usize)]) {
    for &(slot, image) in maps {
        let texture = doc["textures"].as_array().map_or(0, Vec::len);
        if let Some(t) = doc["textures"].as_array_mut() {
            t.push(json!({ "sampler": 0, "source": image }));
        }
        let mat = &mut doc["materials"][m];
        match slot {
            Slot::Normal => mat["normalTexture"] = json!({ "index": texture }),
            Slot::Occlusion => mat["occlusionTexture"] = json!({ "index": texture }),
            Slot::Specular => {
                mat["extensions"]["KHR_materials_specular"] =
                    json!({ "specularColorTexture": { "index": texture }, "specularFactor": 1.0 });
                use_extension(doc, "KHR_materials_specular", false);
            }
            Slot::MetallicRoughness => {
                let pbr = &mut mat["pbrMetallicRoughness"];
                pbr["metallicRoughnessTexture"] = json!({ "index": texture });
                pbr["metallicFactor"] = json!(1.0);
                pbr["roughnessFactor"] = json!(1.0);
            }
            // Packed into MetallicRoughness by the caller.
            Slot::Roughness | Slot::Metallic => {}
        }
    }
}

/// A GLB with each quad's image (`(bytes, mime)`) embedded; `maps` are PNG material maps of the
/// first quad (its tile's normals, occlusion, specular), one texture each.
pub fn glb(
    quads: &[Quad],
    images: &[(Vec<u8>, &str)],
    maps: &[(Slot, Vec<u8>)],
    relief: Option<&Relief>,
    generator: &str,
) -> Vec<u8> {
    let size = quads.first().map(|q| q.size as f32).unwrap_or(1.0);
    let (mut bin, mut views, accessors) = match relief {
        Some(r) => relief_geometry(size, r),
        None => geometry(size),
    };
    let mut imgs = Vec::new();
    let all = images.iter().map(|(b, mime)| (b, *mime)).chain(maps.iter().map(|(_, b)| (b, "image/png")));
    for (bytes, mime) in all {
        imgs.push(json!({ "bufferView": views.len(), "mimeType": mime }));
        push_view(&mut bin, &mut views, bytes, None);
    }
    let mut doc = document(quads, generator, views, accessors, imgs);
    // A relief's vertex data is quantized ([`relief_geometry`]); a flat quad's is not.
    let quantized = relief.is_some();
    if quantized {
        use_extension(&mut doc, "KHR_mesh_quantization", true);
    }
    if maps.iter().any(|(s, _)| *s == Slot::Normal) {
        add_tangent(&mut doc, &mut bin, quantized);
    }
    let slots: Vec<(Slot, usize)> = maps.iter().enumerate().map(|(i, (s, _))| (*s, images.len() + i)).collect();
    add_maps(&mut doc, 0, &slots);
    doc["buffers"] = json!([{ "byteLength": bin.len() }]);
    let mut js = serde_json::to_vec(&doc).unwrap_or_default();
    pad4(&mut js, b' ');
    let total = 12 + 8 + js.len() + 8 + bin.len();
    let mut out = Vec::with_capacity(total);
    for v in [GLB_MAGIC, 2, total as u32, js.len() as u32, CHUNK_JSON] {
        out.extend_from_slice(&v.to_le_bytes());
    }
    out.extend_from_slice(&js);
    out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
    out.extend_from_slice(&CHUNK_BIN.to_le_bytes());
    out.extend_from_slice(&bin);
    out
}

/// glTF JSON whose images are URLs (clients fetch the tiles themselves), `maps` the URLs of the
/// first quad's material images by slot; the geometry is an embedded base64 buffer.
pub fn gltf_json(quads: &[Quad], image_urls: &[String], maps: &[(Slot, String)], generator: &str) -> Value {
    let size = quads.first().map(|q| q.size as f32).unwrap_or(1.0);
    let (mut bin, views, accessors) = geometry(size);
    let imgs = image_urls.iter().chain(maps.iter().map(|(_, u)| u)).map(|u| json!({ "uri": u })).collect();
    let mut doc = document(quads, generator, views, accessors, imgs);
    if maps.iter().any(|(s, _)| *s == Slot::Normal) {
        add_tangent(&mut doc, &mut bin, false);
    }
    let slots: Vec<(Slot, usize)> = maps.iter().enumerate().map(|(i, (s, _))| (*s, image_urls.len() + i)).collect();
    add_maps(&mut doc, 0, &slots);
    let data = base64::engine::general_purpose::STANDARD.encode(&bin);
    doc["buffers"] =
        json!([{ "byteLength": bin.len(), "uri": format!("data:application/octet-stream;base64,{data}") }]);
    doc
}

fn xml_escape(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;").replace('\'', "&apos;")
}

/// An X3D scene of quads (equal sizes) whose `ImageTexture`s point at `image_urls`, with a
/// `Viewpoint` looking straight down at them from a height equal to their extent, which frames
/// them in a square view. A quad without material images (`maps[i]` empty) has no `Material`:
/// X3D then shows the texture unlit, as it is. One with them (its normal, occlusion or packed
/// metallic-roughness images, by slot) has an X3D 4 `PhysicalMaterial` — the glTF material
/// model — lit from straight above by a `DirectionalLight` of intensity π, the headlight off:
/// a physical material reflects `albedo / π` of a light's intensity (X_ITE's headlight, of
/// intensity 1, showed flagstones at 92 against their albedo's 158), so π shows a level
/// surface at its albedo; X3D 4 lets intensity exceed 1. The specular map has no X3D field and
/// is left out.
pub fn x3d(quads: &[Quad], image_urls: &[String], maps: &[Vec<(Slot, String)>], generator: &str) -> String {
    let s = quads.first().map(|q| q.size).unwrap_or(1.0);
    let (mut x0, mut z0, mut x1, mut z1) = (f64::MAX, f64::MAX, f64::MIN, f64::MIN);
    for q in quads {
        (x0, z0) = (x0.min(q.origin.0), z0.min(q.origin.1));
        (x1, z1) = (x1.max(q.origin.0 + s), z1.max(q.origin.1 + s));
    }
    let extent = (x1 - x0).max(z1 - z0);
    // Looking down: the default view (along −Z, up +Y) turned −90° about X looks along −Y with
    // north (−Z) up, so the screen shows the texture as its images do.
    let (a, b) = (inset(), 1.0 - inset());
    let texture = |field: &str, url: &str| {
        format!(
            r#"<ImageTexture{field} url='"{url}"' repeatS="false" repeatT="false">
            <TextureProperties generateMipMaps="true" minificationFilter="AVG_PIXEL_AVG_MIPMAP" magnificationFilter="AVG_PIXEL" boundaryModeS="CLAMP_TO_EDGE" boundaryModeT="CLAMP_TO_EDGE"/>
          </ImageTexture>"#,
            url = xml_escape(url)
        )
    };
    let no_maps = Vec::new();
    let mut shapes = String::new();
    for (i, (q, url)) in quads.iter().zip(image_urls).enumerate() {
        let images: Vec<(&str, &String)> = maps
            .get(i)
            .unwrap_or(&no_maps)
            .iter()
            .filter_map(|(slot, u)| match slot {
                Slot::Normal => Some(("normalTexture", u)),
                Slot::Occlusion => Some(("occlusionTexture", u)),
                Slot::MetallicRoughness => Some(("metallicRoughnessTexture", u)),
                _ => None,
            })
            .collect();
        // A normal map's tangent space as the GLB's: +X (east, increasing s) with w = +1, so
        // that the bitangent N × T is north, the image's up, as the maps' +Y. (Left to derive
        // it from the texture coordinates, X_ITE turns +Y south.)
        let tangent = if images.iter().any(|(f, _)| *f == "normalTexture") {
            "\n          <Tangent vector=\"1 0 0 1, 1 0 0 1, 1 0 0 1, 1 0 0 1\"/>"
        } else {
            ""
        };
        let appearance = if images.is_empty() {
            texture("", url)
        } else {
            let packed = images.iter().any(|(f, _)| *f == "metallicRoughnessTexture");
            let mut m = format!(
                "<PhysicalMaterial metallic=\"{}\" roughness=\"1\">\n          {}",
                if packed { 1 } else { 0 },
                texture(r#" containerField="baseTexture""#, url)
            );
            for (field, u) in images {
                m += &format!("\n          {}", texture(&format!(r#" containerField="{field}""#), u));
            }
            m + "\n          </PhysicalMaterial>"
        };
        shapes += &format!(
            r#"    <Transform DEF="{def}" translation="{x} 0 {z}">
      <Shape>
        <Appearance>
          {appearance}
        </Appearance>
        <IndexedFaceSet solid="false" coordIndex="0 2 1 -1 0 3 2 -1" texCoordIndex="0 2 1 -1 0 3 2 -1">
          <Coordinate point="0 0 0, {s} 0 0, {s} 0 {s}, 0 0 {s}"/>
          <TextureCoordinate point="{a} {b}, {b} {b}, {b} {a}, {a} {a}"/>{tangent}
        </IndexedFaceSet>
      </Shape>
    </Transform>
"#,
            def = xml_escape(&q.name),
            x = q.origin.0,
            z = q.origin.1,
        );
    }
    // PhysicalMaterial is X3D 4; Tangent, Rendering level 5.
    let physical = maps.iter().any(|m| !m.is_empty());
    let (version, components) =
        if physical { ("4.0", "\n    <component name=\"Rendering\" level=\"5\"/>") } else { ("3.3", "") };
    let light = if physical {
        format!(
            "headlight=\"false\"/>\n    <DirectionalLight direction=\"0 -1 0\" intensity=\"{}\" global=\"true\"/>",
            std::f64::consts::PI
        )
    } else {
        "headlight=\"true\"/>".to_string()
    };
    let names = quads.iter().map(|q| q.name.as_str()).collect::<Vec<_>>().join(", ");
    format!(
        r#"<?xml version="1.0" encoding="UTF-8"?>
<X3D profile="Interchange" version="{version}" xmlns:xsd="http://www.w3.org/2001/XMLSchema-instance">
  <head>
    <component name="Texturing" level="3"/>{components}
    <meta name="generator" content="{gen}"/>
    <meta name="description" content="{names}: ground quads (Y up, X east, Z south, 1 unit = 1 native texel)"/>
  </head>
  <Scene>
    <NavigationInfo type='"EXAMINE" "ANY"' {light}
    <Viewpoint description="top down" position="{cx} {h} {cz}" orientation="1 0 0 -1.5707963267948966" fieldOfView="0.9272952180016122" centerOfRotation="{cx} 0 {cz}"/>
{shapes}  </Scene>
</X3D>
"#,
        gen = xml_escape(generator),
        names = xml_escape(&names),
        cx = (x0 + x1) / 2.0,
        cz = (z0 + z1) / 2.0,
        h = extent,
    )
}
