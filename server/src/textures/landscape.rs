//! Landscapes in the catalogue: configured textures composed into one endless ground. A
//! [`Landscape`] holds its configuration, its layers (each a served [`Texture`] with its
//! parameters and zoom offset), its splat and blend (from `textile_core::landscape`), and what
//! follows from them (zooms, the hash its ETags carry). `crate::pipeline::landscape` renders
//! one: each layer a window needs, rendered as that texture's own tiles are, then joined. The
//! modes never see a landscape.

use std::sync::Arc;

use textile_core::landscape::splat::{ImageSplat, Key, NoiseSplat, Outside, Placement};
use textile_core::landscape::{Blend, Splat};
use textile_core::ParamReader;

use super::{LoadError, Registry, Status, Texture, Zooms};
use crate::config::{parse_colour, Config, LandscapeConfig, LayerConfig, SplatConfig};

/// One layer of a landscape.
pub struct Layer {
    /// The texture it shows.
    pub tex: Arc<Texture>,
    /// Its configuration.
    pub config: LayerConfig,
    /// Zoom steps its own zoom is magnified by at the landscape's native zoom:
    /// `native − (its native + scale)`.
    pub offset: u32,
    /// Its colour in the splat overlay.
    pub colour: [u8; 3],
}

/// A landscape ready to serve.
pub struct Landscape {
    /// Its configuration.
    pub config: LandscapeConfig,
    /// The layers, in order.
    pub layers: Vec<Layer>,
    /// Where each layer shows.
    pub splat: Splat,
    /// How they join.
    pub blend: Blend,
    /// Hash of the configuration and the splat image: part of every ETag of the landscape.
    pub hash: String,
    /// Zoom at which one tile pixel is one texel of the finest layer (the highest layer zoom
    /// after its scale).
    pub native_zoom: u32,
    /// Smallest zoom every layer serves.
    pub min_zoom: u32,
    /// Largest zoom every layer serves.
    pub max_zoom: u32,
}

/// Overlay colours of layers that name none.
const OVERLAY: [[u8; 3]; 8] = [
    [90, 143, 60],
    [154, 148, 136],
    [176, 104, 58],
    [70, 110, 180],
    [200, 180, 60],
    [140, 70, 150],
    [60, 160, 160],
    [200, 80, 80],
];

impl Landscape {
    /// Make a landscape from its configuration (at `at`: `landscapes[2]` in a file, `config` in
    /// an upload) and the registry's textures, its painted splat from `splat` when given (an
    /// upload's), else from the file it names; errors name the landscape and the field.
    pub fn build(
        cfg: &Config,
        l: &LandscapeConfig,
        at: &str,
        reg: &Registry,
        splat: Option<&[u8]>,
    ) -> Result<Landscape, LoadError> {
        let fail = |field: String, message: String| LoadError::Landscape {
            id: l.id.clone(),
            field: format!("{at}.{field}"),
            message,
        };
        let mut zooms = Vec::new();
        for (i, y) in l.layers.iter().enumerate() {
            let tex = reg
                .get(&y.texture)
                .ok_or_else(|| fail(format!("layers[{i}].texture"), format!("'{}' is not served", y.texture)))?;
            // The layer's parameters must read as a request's would.
            let r = ParamReader::request(y.query()).map_err(|e| fail(format!("layers[{i}].params"), e.to_string()))?;
            tex.defaults.request(&tex.source(), r).map_err(|e| fail(format!("layers[{i}].params"), e.to_string()))?;
            let s = i64::from(y.scale);
            zooms.push((
                tex.clone(),
                tex.native_zoom() as i64 + s,
                tex.min_zoom() as i64 + s,
                tex.max_zoom() as i64 + s,
            ));
        }
        let native = zooms.iter().map(|z| z.1).max().unwrap_or(0);
        let (lo, hi) =
            (zooms.iter().map(|z| z.2).max().unwrap_or(0).max(0), zooms.iter().map(|z| z.3).min().unwrap_or(0));
        if lo > hi || native > hi {
            return Err(fail(
                "layers".into(),
                format!("with these scales the layers share no zoom range that includes the native zoom {native}"),
            ));
        }
        let layers = zooms
            .into_iter()
            .zip(&l.layers)
            .enumerate()
            .map(|(i, ((tex, n, _, _), y))| Layer {
                tex,
                config: y.clone(),
                offset: (native - n) as u32,
                colour: y.colour.as_deref().and_then(parse_colour).unwrap_or(OVERLAY[i % OVERLAY.len()]),
            })
            .collect::<Vec<_>>();
        let mut h = blake3::Hasher::new();
        h.update(serde_json::to_string(l).unwrap_or_default().as_bytes());
        let splat = match &l.splat {
            SplatConfig::Noise { feature, octaves, transition, .. } => {
                let shares: Vec<f64> = l.layers.iter().map(|y| y.share.unwrap_or(0.0)).collect();
                Splat::Noise(
                    NoiseSplat::new(&shares, *feature, *octaves, *transition)
                        .map_err(|e| fail("splat".into(), e.to_string()))?,
                )
            }
            SplatConfig::Image { image, key, texels_per_pixel, origin, outside, warp, .. } => {
                let bytes = match splat {
                    Some(b) => b.to_vec(),
                    None => super::storage::file_bytes(
                        cfg,
                        &l.id,
                        image,
                        textile_core::landscape::splat::MAX_IMAGE_BYTES as u64,
                    )
                    .map_err(|e| fail("splat.image".into(), e.to_string()))?,
                };
                h.update(&bytes);
                let key = match key.as_str() {
                    "rgba" => Key::Channels,
                    _ => Key::Palette(layers.iter().map(|y| y.colour).collect()),
                };
                let outside = match outside.as_str() {
                    "repeat" => Outside::Repeat,
                    id => Outside::Layer(l.layers.iter().position(|y| y.texture == id).unwrap_or(0)),
                };
                let place = Placement {
                    texels_per_pixel: *texels_per_pixel,
                    origin: (origin[0], origin[1]),
                    outside,
                    warp: *warp,
                };
                Splat::Image(
                    ImageSplat::decode(&bytes, layers.len(), &key, place)
                        .map_err(|e| fail("splat".into(), e.to_string()))?,
                )
            }
        };
        let blend = match l.blend.kind.as_str() {
            "linear" => Blend::Linear,
            _ => Blend::Height { depth: l.blend.depth as f32 },
        };
        Ok(Landscape {
            config: l.clone(),
            layers,
            splat,
            blend,
            hash: h.finalize().to_hex()[..16].to_string(),
            native_zoom: native as u32,
            min_zoom: lo as u32,
            max_zoom: hi as u32,
        })
    }

    /// The zooms it serves.
    pub fn zooms(&self) -> Zooms {
        Zooms { min: self.min_zoom, max: self.max_zoom, native: self.native_zoom }
    }

    /// Metres per unit of height in its raster-dem tiles, unless a request says.
    pub fn height_scale(&self) -> f64 {
        self.config.height_scale.unwrap_or_else(|| crate::terrain::default_height_scale(self.native_zoom))
    }

    /// The splat's seed, unless a request gives one.
    pub fn splat_seed(&self) -> u64 {
        match &self.config.splat {
            SplatConfig::Noise { seed, .. } | SplatConfig::Image { seed, .. } => *seed,
        }
    }

    /// Where it stands: ready when every layer is; failed, naming the layer, when one failed;
    /// else analysing.
    pub fn status(&self) -> (Status, Option<String>) {
        if let Some(y) = self.layers.iter().find(|y| y.tex.status() == Status::Failed) {
            let why = y.tex.failure.get().cloned().unwrap_or_default();
            return (Status::Failed, Some(format!("layer '{}' failed: {why}", y.tex.config.id)));
        }
        match self.layers.iter().all(|y| y.tex.status() == Status::Ready) {
            true => (Status::Ready, None),
            false => (Status::Analysing, None),
        }
    }

    /// Maps every layer has (`height` always: a layer without a height map gives its luma).
    pub fn maps(&self) -> Vec<String> {
        let mut names: Vec<String> = vec!["height".into()];
        if let Some(first) = self.layers.first() {
            for m in &first.tex.exemplar.maps {
                let all = self.layers.iter().all(|y| y.tex.exemplar.map(&m.name).is_some());
                if all && m.name != "height" {
                    names.push(m.name.clone());
                }
            }
        }
        names
    }
}

/// Make every configured landscape from the registry's textures. A stored one (added through
/// the admin API) that cannot be made — a layer's upload failed to load, a limit changed — is
/// skipped with a warning, so it cannot stop the service.
pub fn build_all(cfg: &Config, reg: &Registry, log: &dyn Fn(String)) -> Result<Vec<Arc<Landscape>>, LoadError> {
    let mut out = Vec::new();
    for (i, l) in cfg.landscapes.iter().enumerate() {
        if !l.uploaded {
            out.push(Arc::new(Landscape::build(cfg, l, &format!("landscapes[{i}]"), reg, None)?));
            continue;
        }
        let ids: Vec<&str> = reg.list.iter().map(|t| t.config.id.as_str()).collect();
        let made = l
            .validate("landscape", &ids)
            .map_err(|(field, message)| LoadError::Landscape { id: l.id.clone(), field, message })
            .and_then(|()| Landscape::build(cfg, l, "landscape", reg, None));
        match made {
            Ok(land) => out.push(Arc::new(land)),
            Err(e) => log(format!("warning: stored {e}; not served")),
        }
    }
    Ok(out)
}

/// What `GET /textures/{id}` says of a landscape: its kind, layers, splat, blend and status.
pub fn describe(l: &Landscape) -> serde_json::Value {
    let (status, error) = l.status();
    let layers: Vec<serde_json::Value> = l
        .layers
        .iter()
        .map(|y| {
            let colour = format!("#{:02x}{:02x}{:02x}", y.colour[0], y.colour[1], y.colour[2]);
            serde_json::json!({
                "texture": y.tex.config.id, "name": y.tex.config.name, "status": y.tex.status().as_str(),
                "mode": y.config.mode.clone().unwrap_or_else(|| y.tex.defaults.mode.to_string()),
                "params": y.config.query().into_iter().filter(|(k, _)| k != "mode").collect::<std::collections::BTreeMap<_, _>>(),
                "scale": y.config.scale, "magnified_at_native": y.offset, "share": y.config.share, "colour": colour,
                "native_zoom": y.tex.native_zoom(),
            })
        })
        .collect();
    serde_json::json!({
        "id": l.config.id,
        "name": l.config.name,
        "kind": "landscape",
        "status": status.as_str(),
        "error": error,
        "attribution": l.config.attribution,
        "layers": layers,
        "splat": l.config.splat,
        "blend": l.config.blend,
        "maps": std::iter::once("albedo".to_string()).chain(l.maps()).chain(["splat".to_string()]).collect::<Vec<_>>(),
        "native_zoom": l.native_zoom,
        "minzoom": l.min_zoom,
        "maxzoom": l.max_zoom,
        "tile_size": textile_core::TILE_SIZE,
        "hash": l.hash,
        "seed": "a request's seed=N reseeds the splat and gives layer i the seed (hash of N and i); without it each layer uses its configured parameters",
    })
}
