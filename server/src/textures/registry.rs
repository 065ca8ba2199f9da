//! The catalogue of served textures: configured ones, then uploaded ones, replaced whole on
//! every change; [`prepare_registry`] decodes every exemplar (modes that need only the exemplar
//! serve from then on).

use std::collections::HashMap;
use std::sync::Arc;

use textile_core::{Exemplar, ExemplarOptions};

use super::storage::{exemplar_bytes, image_bytes};
use super::{LoadError, Texture};
use crate::config::{Config, TextureConfig};

/// All served textures: configured ones in configuration order, then uploaded ones in upload
/// order. Never changed in place: a change makes a new registry ([`Registry::with`],
/// [`Registry::without`]) that replaces the old one whole.
pub struct Registry {
    /// Textures in catalogue order.
    pub list: Vec<Arc<Texture>>,
    by_id: HashMap<String, Arc<Texture>>,
}

impl Registry {
    /// A registry of these textures (ids unique).
    pub fn new(list: Vec<Arc<Texture>>) -> Self {
        let by_id = list.iter().map(|t| (t.config.id.clone(), t.clone())).collect();
        Registry { list, by_id }
    }

    /// This registry with `tex` added at the end.
    pub fn with(&self, tex: Arc<Texture>) -> Self {
        let mut list: Vec<_> = self.list.iter().filter(|t| t.config.id != tex.config.id).cloned().collect();
        list.push(tex);
        Registry::new(list)
    }

    /// This registry without the texture `id`.
    pub fn without(&self, id: &str) -> Self {
        Registry::new(self.list.iter().filter(|t| t.config.id != id).cloned().collect())
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
    // A lattice tiles the exemplar, which therefore wraps around.
    let toroidal = if t.lattice.needs_toroidal() { Some(true) } else { t.toroidal.as_option() };
    let opts = ExemplarOptions { max_input_side: cfg.max_exemplar_side, toroidal };
    let core = |source| LoadError::Core { id: t.id.clone(), source };
    let mut ex = Exemplar::from_bytes(bytes, &opts).map_err(core)?;
    ex.check_not_flat().map_err(core)?;
    // The mask is prepared like the exemplar's image, so that they stay aligned.
    let mask = match &t.randomness_mask {
        Some(path) => Some(Exemplar::from_bytes(&image_bytes(cfg, t, path)?, &opts).map_err(core)?),
        None => None,
    };
    if t.exemplar_hires.is_some() {
        ex = Exemplar::from_hires(ex).map_err(core)?;
        let (w, h) = (ex.width, ex.height);
        log(format!("texture '{}': exemplar {w}x{h} reduced from its {}x{} exemplar_hires", t.id, 2 * w, 2 * h));
    }
    if t.toroidal == crate::config::Toroidal::Synthesize {
        let started = std::time::Instant::now();
        ex = textile_core::tileable::make_toroidal(&ex, 0).map_err(core)?;
        log(format!(
            "texture '{}': exemplar made toroidal by synthesis (toroidal = \"synthesize\") in {:.2}s",
            t.id,
            started.elapsed().as_secs_f64()
        ));
    }
    ex = ex.with_lattice_choice(&t.lattice).map_err(core)?;
    if let Some(mask) = &mask {
        ex = ex.with_randomness_mask(mask).map_err(core)?;
    }
    // Each map is prepared like the exemplar's image, so that they stay co-registered.
    for (name, image) in t.map_images() {
        let read;
        let bytes = match given.iter().find(|(n, _)| n == name) {
            Some((_, b)) => b,
            None => {
                read = image_bytes(cfg, t, image)?;
                &read
            }
        };
        let map = Exemplar::from_bytes(bytes, &opts).map_err(|e| LoadError::Core {
            id: t.id.clone(),
            source: textile_core::CoreError::Map { name: name.into(), message: format!("({image}): {e}") },
        })?;
        ex = ex.with_map(name, &map, t.normal_convention()).map_err(core)?;
    }
    let prep = &ex.preparation;
    if (prep.input_width, prep.input_height) != (prep.width, prep.height) {
        log(format!(
            "texture '{}': exemplar {}x{} scaled to {}x{} (exemplars are used up to {} texels a side)",
            t.id,
            prep.input_width,
            prep.input_height,
            prep.width,
            prep.height,
            textile_core::exemplar::MAX_SIDE
        ));
    }
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
    Ok(Registry::new(list))
}
