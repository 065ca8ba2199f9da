//! Every answer's bytes, one way. An [`Output`] is what a front end asks for — an image (a
//! PNG/JPEG/WebP tile or window, a material map, `map=uv`), a tile's or a patch's GLB (3D Tiles
//! content too), a .gltf document and its material images, an X3D scene — with its cache key
//! and ETag (computed without rendering), its content type, the images it is made of
//! ([`Output::parts`], each an [`ImageJob`] of the pipeline) and how its bytes are assembled
//! from them ([`Output::assemble`], a pure function). The server makes the parts through the
//! tile cache and the synthesis pool ([`produce`]); `textile render` makes them directly
//! ([`Output::bytes`]): the same parts and the same assembly, so the CLI writes what the
//! server serves, byte for byte.

use std::sync::Arc;

use axum::body::Bytes;
use textile_core::Pyramid;

use crate::error::ApiError;
use crate::metrics::GLTF_LABEL;
use crate::pipeline::landscape::LandscapeJob;
use crate::pipeline::{self, etag_for, ImageJob, Picture};
use crate::scene::assets::{glb, gltf_json, x3d, Relief, Slot};
use crate::scene::model::{generator, material_images, Model};
use crate::state::AppState;

/// Something textile serves or writes.
#[derive(Clone)]
pub enum Output {
    /// An image: a tile or window of the colour, a material map or the coordinates.
    Image(ImageJob),
    /// A landscape's image: its layers' images joined.
    Landscape(LandscapeJob),
    /// A GLB: a tile's textured quad with its material and, with `relief`, its displaced mesh;
    /// or a patch's quads, one node per tile.
    Glb(Model),
    /// A tile's .gltf document, its images beside it; `base` is the server's URL, for the
    /// tile URL in the image's extras.
    Gltf {
        /// The tile.
        model: Model,
        /// The server's base URL.
        base: String,
    },
    /// One material image of a tile's .gltf document.
    MaterialImage {
        /// The tile.
        model: Model,
        /// The slot it fills.
        slot: Slot,
    },
    /// An X3D scene of a tile or a patch whose textures point at the tiles' images under
    /// `base`.
    X3d {
        /// The tile or patch.
        model: Model,
        /// The server's base URL.
        base: String,
    },
}

impl From<Picture> for Output {
    fn from(p: Picture) -> Output {
        match p {
            Picture::Texture(job) => Output::Image(job),
            Picture::Landscape(job) => Output::Landscape(job),
        }
    }
}

impl Output {
    /// The cache key: everything that determines the bytes.
    pub fn key(&self) -> String {
        match self {
            Output::Image(job) => job.key(),
            Output::Landscape(job) => job.key(),
            Output::Glb(m) if m.tiles > 1 => m.key("patch", &m.tiles.to_string()),
            Output::Glb(m) => {
                let relief = m.relief.map(|v| format!("|relief={v}")).unwrap_or_default();
                m.key("glb", &format!("{}{relief}", m.material_key()))
            }
            Output::Gltf { model: m, base } => m.key("gltf", &m.with_material(base)),
            Output::MaterialImage { model: m, slot } => m.key("slot", &format!("{}|{}", slot.name(), m.material_key())),
            Output::X3d { model: m, base } if m.tiles > 1 => {
                m.key("x3d-patch", &m.with_material(&format!("{}|{base}", m.tiles)))
            }
            Output::X3d { model: m, base } => m.key("x3d", &m.with_material(base)),
        }
    }

    /// The strong ETag (quoted).
    pub fn etag(&self) -> String {
        match self {
            Output::Image(job) => job.etag(),
            _ => etag_for(&self.key()),
        }
    }

    /// The media type of its bytes.
    pub fn content_type(&self) -> &'static str {
        match self {
            Output::Image(job) => job.format().content_type(),
            Output::Landscape(job) => job.format().content_type(),
            Output::Glb(_) => "model/gltf-binary",
            Output::Gltf { .. } => "model/gltf+json",
            Output::MaterialImage { .. } => "image/png",
            Output::X3d { .. } => "model/x3d+xml",
        }
    }

    /// Whether its bytes are kept in the tile cache under its ETag (images and GLBs, which are
    /// work to make; documents are assembled afresh).
    fn kept(&self) -> bool {
        matches!(self, Output::Image(_) | Output::Landscape(_) | Output::Glb(_))
    }

    /// The images it is assembled from, in the order [`Output::assemble`] takes them.
    pub fn parts(&self) -> Vec<Picture> {
        match self {
            Output::Image(_) | Output::Landscape(_) | Output::Gltf { .. } | Output::X3d { .. } => Vec::new(),
            Output::Glb(m) if m.tiles > 1 => m.tile_specs().map(|t| m.image_at(t)).collect(),
            Output::Glb(m) => {
                let mut parts = vec![m.image()];
                parts.extend(m.material_maps().iter().map(|(_, n)| m.map_image(n)));
                parts.extend(m.relief.map(|_| m.map_image("height")));
                parts
            }
            Output::MaterialImage { model: m, slot } => {
                m.material_maps_of(Some(*slot)).iter().map(|(_, n)| m.map_image(n)).collect()
            }
        }
    }

    /// Its bytes from its parts' bytes (in the order of [`Output::parts`]).
    pub fn assemble(&self, mut parts: Vec<Vec<u8>>) -> Result<Vec<u8>, ApiError> {
        let encode = |doc: &serde_json::Value| serde_json::to_vec(doc).map_err(|e| ApiError::internal(e.to_string()));
        match self {
            Output::Image(_) | Output::Landscape(_) => Err(ApiError::internal("an image is rendered, not assembled")),
            Output::Glb(m) if m.tiles > 1 => {
                let quads: Vec<_> = m.tile_specs().map(|t| m.quad(&t)).collect();
                let images: Vec<(Vec<u8>, &str)> = parts.into_iter().map(|p| (p, "image/png")).collect();
                Ok(glb(&quads, &images, &[], None, &generator()))
            }
            Output::Glb(m) => {
                let height = if m.relief.is_some() { parts.pop() } else { None };
                let mut parts = parts.into_iter();
                let colour = parts.next().ok_or_else(|| ApiError::internal("a GLB without its image"))?;
                let maps = material_images(m.material_maps().into_iter().map(|(s, _)| s).zip(parts).collect())?;
                let relief = match (m.relief, height) {
                    (Some(scale), Some(png)) => {
                        let img = image::load_from_memory(&png)
                            .map_err(|e| ApiError::internal(format!("height map: {e}")))?;
                        Some(Relief::from_border_image(&img.to_luma8(), scale))
                    }
                    _ => None,
                };
                Ok(glb(&[m.quad(&m.spec)], &[(colour, "image/png")], &maps, relief.as_ref(), &generator()))
            }
            Output::Gltf { model: m, base } => {
                // glTF wants relative URIs without a query: the image is served beside this
                // document as `{y}.png` or `{y}.{token}.png` (the parameters, base64url) with the
                // tile's bytes. The tile endpoint's absolute URL is in the image's extras for
                // clients that prefer it.
                let maps: Vec<(Slot, String)> =
                    m.material_slots().into_iter().map(|s| (s, m.sibling_image(&m.spec, Some(s)))).collect();
                let mut doc = gltf_json(&[m.quad(&m.spec)], &[m.sibling_image(&m.spec, None)], &maps, &generator());
                doc["images"][0]["extras"] = serde_json::json!({ "tile_url": m.tile_url(base, &m.spec) });
                encode(&doc)
            }
            Output::MaterialImage { model: m, slot } => {
                let slots = m.material_maps_of(Some(*slot)).into_iter().map(|(s, _)| s);
                let mut images = material_images(slots.zip(parts).collect())?;
                images.pop().map(|(_, b)| b).ok_or_else(|| ApiError::internal("a material image went missing"))
            }
            Output::X3d { model: m, base } => {
                let tiles: Vec<_> = m.tile_specs().collect();
                let quads: Vec<_> = tiles.iter().map(|t| m.quad(t)).collect();
                let urls: Vec<String> = tiles.iter().map(|t| m.image_url(base, t, None)).collect();
                let maps: Vec<Vec<(Slot, String)>> = tiles.iter().map(|t| m.material_urls(base, t)).collect();
                Ok(x3d(&quads, &urls, &maps, &generator()).into_bytes())
            }
        }
    }

    /// Its bytes made here and now (no tile cache, no pool): what `textile render` writes.
    pub fn bytes(&self, cache: &Pyramid) -> Result<Vec<u8>, ApiError> {
        match self {
            Output::Image(job) => return Ok(job.bytes(cache)?.0),
            Output::Landscape(job) => return job.bytes(cache, &textile_core::Cancel::default()),
            _ => {}
        }
        let cancel = textile_core::Cancel::default();
        let parts = self.parts().iter().map(|p| p.bytes(cache, &cancel)).collect::<Result<Vec<_>, ApiError>>()?;
        self.assemble(parts)
    }

    /// Working memory it holds while assembled (a patch's images and document together).
    fn working_bytes(&self) -> u64 {
        match self {
            Output::Glb(m) if m.tiles > 1 => (4 << 20) + (m.tiles * m.tiles) as u64 * (320 << 10),
            _ => 0,
        }
    }
}

/// An output's bytes as the server makes them, with whether they came from the tile cache:
/// an image through [`pipeline::produce`]; anything else from its parts, each produced that
/// way (so shared with the image tiles that show them), assembled on the synthesis pool and
/// kept in the tile cache where it is work to make. `etag` is the output's [`Output::etag`].
pub async fn produce(st: &Arc<AppState>, etag: &str, out: Output) -> (Result<Bytes, ApiError>, bool) {
    let out = match out {
        Output::Image(job) => return pipeline::produce(st, etag, job).await,
        Output::Landscape(job) => return pipeline::produce_picture(st, etag, Picture::Landscape(job)).await,
        out => out,
    };
    if out.kept() {
        if let Some(b) = st.cache.peek(etag) {
            return (Ok(b), true);
        }
    }
    let made = async {
        let _memory = match out.working_bytes() {
            0 => None,
            bytes => Some(st.reserve(bytes).await?),
        };
        let mut parts = Vec::new();
        for p in out.parts() {
            parts.push(pipeline::produce_picture(st, &p.etag(), p).await.0?.to_vec());
        }
        if !out.kept() {
            return Ok((Bytes::from(out.assemble(parts)?), false));
        }
        let (bytes, hit) = pipeline::cached(st, etag, GLTF_LABEL, move |_| out.assemble(parts)).await;
        Ok((bytes?, hit))
    };
    match made.await {
        Ok((bytes, hit)) => (Ok(bytes), hit),
        Err(e) => (Err(e), false),
    }
}
