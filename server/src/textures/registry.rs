//! The catalogue of served textures: configured ones, then uploaded ones, replaced whole on
//! every change; [`prepare_registry`] decodes every exemplar (modes that need only the exemplar
//! serve from then on).

use std::borrow::Cow;
use std::collections::HashMap;
use std::sync::Arc;

use textile_core::recipe::Images;

use super::storage::{exemplar_bytes, image_bytes};
use super::Landscape;
use super::{LoadError, Texture};
use crate::config::{Config, TextureConfig};

/// All served textures: configured ones in configuration order, then uploaded ones in upload
/// order. Never changed in place: a change makes a new registry ([`Registry::with`],
/// [`Registry::without`]) that replaces the old one whole.
pub struct Registry {
    /// Textures in catalogue order.
    pub list: Vec<Arc<Texture>>,
    by_id: HashMap<String, Arc<Texture>>,
    /// Landscapes in configuration order.
    pub landscapes: Vec<Arc<Landscape>>,
}

impl Registry {
    /// A registry of these textures (ids unique).
    pub fn new(list: Vec<Arc<Texture>>) -> Self {
        let by_id = list.iter().map(|t| (t.config.id.clone(), t.clone())).collect();
        Registry { list, by_id, landscapes: Vec::new() }
    }

    /// This registry serving these landscapes too.
    pub fn with_landscapes(mut self, landscapes: Vec<Arc<Landscape>>) -> Self {
        self.landscapes = landscapes;
        self
    }

    /// The landscape with this id.
    pub fn landscape(&self, id: &str) -> Option<&Arc<Landscape>> {
        self.landscapes.iter().find(|l| l.config.id == id)
    }

    /// This registry with landscape `l` added at the end.
    pub fn with_landscape(&self, l: Arc<Landscape>) -> Self {
        let mut landscapes: Vec<_> = self.landscapes.iter().filter(|m| m.config.id != l.config.id).cloned().collect();
        landscapes.push(l);
        Registry::new(self.list.clone()).with_landscapes(landscapes)
    }

    /// This registry without the landscape `id`.
    pub fn without_landscape(&self, id: &str) -> Self {
        let landscapes = self.landscapes.iter().filter(|m| m.config.id != id).cloned().collect();
        Registry::new(self.list.clone()).with_landscapes(landscapes)
    }

    /// The landscapes that have texture `id` as a layer.
    pub fn landscapes_using(&self, id: &str) -> Vec<&str> {
        let uses = |l: &&Arc<Landscape>| l.layers.iter().any(|y| y.tex.config.id == id);
        self.landscapes.iter().filter(uses).map(|l| l.config.id.as_str()).collect()
    }

    /// Landscapes added through the admin API in it.
    pub fn stored_landscapes(&self) -> usize {
        self.landscapes.iter().filter(|l| l.config.uploaded).count()
    }

    /// This registry with `tex` added at the end.
    pub fn with(&self, tex: Arc<Texture>) -> Self {
        let mut list: Vec<_> = self.list.iter().filter(|t| t.config.id != tex.config.id).cloned().collect();
        list.push(tex);
        Registry::new(list).with_landscapes(self.landscapes.clone())
    }

    /// This registry without the texture `id`.
    pub fn without(&self, id: &str) -> Self {
        Registry::new(self.list.iter().filter(|t| t.config.id != id).cloned().collect())
            .with_landscapes(self.landscapes.clone())
    }

    /// Uploaded textures in it.
    pub fn uploads(&self) -> usize {
        self.list.iter().filter(|t| t.config.uploaded).count()
    }

    /// The texture with this id.
    pub fn get(&self, id: &str) -> Option<&Arc<Texture>> {
        self.by_id.get(id)
    }
}

/// Decode one texture's exemplar from its bytes: a texture without its analysis yet (`index`:
/// its place in the configuration, for errors). Its maps are read from their files, but for
/// those `given` by name with their bytes (an upload's, not stored yet). `log` hears of any
/// crop or resize.
pub fn prepare_texture(
    cfg: &Config,
    t: &TextureConfig,
    index: usize,
    bytes: &[u8],
    given: &[(String, Vec<u8>)],
    log: &dyn Fn(String),
) -> Result<Texture, LoadError> {
    let mask = t.randomness_mask.as_deref().map(|path| image_bytes(cfg, t, path)).transpose()?;
    // An upload's maps come with their bytes; the others are read from their files.
    let mut maps: Vec<(&str, &str, Cow<[u8]>)> = Vec::new();
    for (name, image) in t.map_images() {
        let bytes = match given.iter().find(|(n, _)| n == name) {
            Some((_, b)) => Cow::Borrowed(b.as_slice()),
            None => Cow::Owned(image_bytes(cfg, t, image)?),
        };
        maps.push((name, image, bytes));
    }
    let maps: Vec<(&str, &str, &[u8])> = maps.iter().map(|(n, i, b)| (*n, *i, b.as_ref())).collect();
    let images = Images { exemplar: bytes, mask: mask.as_deref(), maps: &maps };
    let ex = t
        .recipe(cfg.max_exemplar_side)
        .make(&images, &|note| log(format!("texture '{}': {note}", t.id)))
        .map_err(|source| LoadError::Core { id: t.id.clone(), source })?;
    Texture::prepare(t.clone(), index, ex)
}

/// Decode every texture's exemplar: a registry whose textures have no analysis yet. A
/// configured texture that cannot be prepared is an error; an uploaded one (which was checked
/// when it was uploaded) is skipped with a warning, so a changed limit cannot stop the service.
/// `log` receives one line per event.
pub fn prepare_registry(cfg: &Config, log: &dyn Fn(String)) -> Result<Registry, LoadError> {
    let mut list = Vec::new();
    for (index, t) in cfg.textures.iter().enumerate() {
        let prepared = exemplar_bytes(cfg, t).and_then(|bytes| prepare_texture(cfg, t, index, &bytes, &[], log));
        match prepared {
            Ok(tex) => {
                // A stored upload that names a server file is kept, failed, with the way out.
                if let Some(why) = t.upload_refusal() {
                    log(format!("warning: uploaded texture '{}': {why}", t.id));
                    let _ = tex.failure.set(why);
                }
                list.push(Arc::new(tex))
            }
            Err(e) if t.uploaded => log(format!("warning: uploaded {e}; not served")),
            Err(e) => return Err(e),
        }
    }
    let reg = Registry::new(list);
    let landscapes = super::landscape::build_all(cfg, &reg, log)?;
    Ok(reg.with_landscapes(landscapes))
}
