//! What the umbrella mode prepares per texture ([`Extraction`]): the elements extracted from
//! the exemplar (or given by a hand-made set, the texture setting `set`), stored beside the
//! analysis as `<texture>.umbrella` ([`super::store`]), and the caches its requests share — cell
//! lists, merged levels of detail, colour calibrations ([`Caches`]) — bounded in bytes
//! ([`Preparation::limit_caches`]) and counted in what the texture holds.

use std::path::Path;
use std::sync::{Arc, Mutex};

use serde_json::{json, Map, Value};

use super::caches::Caches;
use super::extract::{self, Elements};
use super::store::{self, Outcome};
use crate::progress::Progress;
use crate::cancel::Cancel;
use crate::error::{AnalysisFileProblem, CoreError, Result};
use crate::exemplar::Exemplar;
use crate::geom::centred_square;
use crate::maps::MaterialMap;
use crate::prepare::{Input, Preparation, PreparationSetting};

/// The setting naming a hand-made set.
pub const SET: PreparationSetting = PreparationSetting {
    name: "set",
    help: "a hand-made umbrella set instead of elements extracted from the exemplar: JSON naming element images \
           with alpha, relative to the set file (path relative to the configuration)",
};

/// A texture's umbrella state: its elements (or why it has none), their id, and its caches.
pub struct Extraction {
    id: String,
    /// The elements, or why there are none.
    pub outcome: Outcome,
    /// The hash of the hand-made set it was given, if it was.
    handmade: Option<String>,
    /// The caches its requests share.
    pub caches: Arc<Caches>,
    /// The elements showing each material map rendered so far, by the map's hash
    /// ([`Elements::of_map`]; one entry per map of the texture at most).
    maps: Mutex<Vec<(String, Arc<Elements>)>>,
}

impl Extraction {
    /// An extraction of `outcome` with id `id`.
    fn new(id: String, outcome: Outcome, handmade: Option<String>) -> Extraction {
        Extraction { id, outcome, handmade, caches: Arc::new(Caches::default()), maps: Mutex::default() }
    }

    /// The elements showing material `map` of exemplar `ex` instead of its colours, with the
    /// id that names them (the colour's and the map's hash): the same umbrellas, their
    /// textures re-cut from the map. A hand-made set, whose elements were not cut from the
    /// exemplar, has no maps: a map error saying so.
    pub fn map_elements(&self, ex: &Exemplar, map: &MaterialMap) -> Result<(Arc<Elements>, String)> {
        let (el, id) = self.elements()?;
        let fail = |message: &str| CoreError::Map { name: map.name.clone(), message: message.into() };
        if self.handmade.is_some() {
            return Err(fail("cannot be rendered with a hand-made umbrella set (`set`): its elements were not cut from the exemplar"));
        }
        if map.dims() != ex.dims() {
            return Err(fail("is not the exemplar's size"));
        }
        let id = format!("{id}~{}", map.hash);
        let mut maps = self.maps.lock().unwrap_or_else(|e| e.into_inner());
        if let Some((_, e)) = maps.iter().find(|(h, _)| *h == map.hash) {
            return Ok((e.clone(), id));
        }
        let (texels, side) = centred_square(&map.texels, map.dims());
        let e = Arc::new(el.of_map(&texels, side, map.normal));
        maps.push((map.hash.clone(), e.clone()));
        Ok((e, id))
    }

    /// The elements with the id that names them; none → a parameter error naming the mode.
    pub fn elements(&self) -> Result<(Arc<Elements>, String)> {
        let el = self.outcome.clone().map_err(|message| CoreError::Param { name: "umbrella", message })?;
        Ok((el, self.id.clone()))
    }

    /// Extract the elements of `ex`, now: of a non-square exemplar, from its largest centred
    /// square ([`centred_square`]; elements are cut from a square image), which wraps only
    /// when it is the whole exemplar.
    pub fn extract(ex: &Exemplar) -> Extraction {
        let (square, side) = centred_square(&ex.pixels, ex.dims());
        let toroidal = ex.toroidal && ex.width == ex.height;
        let outcome = match extract::extract(&square, side, toroidal) {
            Ok(e) => Ok(Arc::new(e)),
            Err(CoreError::Param { message, .. }) => Err(message),
            Err(e) => Err(e.to_string()),
        };
        Extraction::new(extraction_id(ex), outcome, None)
    }

    /// Use the hand-made `elements` for exemplar `ex`.
    pub fn hand_made(ex: &Exemplar, elements: Elements) -> Extraction {
        let outcome: Outcome = Ok(Arc::new(elements));
        let hash = blake3::hash(&store::to_bytes("hand-made", &outcome)).to_hex().to_string();
        let mut h = blake3::Hasher::new();
        h.update(extraction_id(ex).as_bytes());
        h.update(b"umbrella-set");
        h.update(hash.as_bytes());
        Extraction::new(h.finalize().to_hex()[..16].to_string(), outcome, Some(hash))
    }
}

/// The extraction id of an exemplar: a hash of its content and [`extract::EXTRACTION_VERSION`]
/// (what a stored extraction must match).
pub fn extraction_id(ex: &Exemplar) -> String {
    let mut h = blake3::Hasher::new();
    h.update(b"textile-umbrella-elements");
    h.update(&extract::EXTRACTION_VERSION.to_le_bytes());
    ex.hash_content(&mut h);
    h.finalize().to_hex()[..16].to_string()
}

impl Preparation for Extraction {
    const WHAT: &'static str = "umbrella extraction";
    const EXTENSION: &'static str = "umbrella";
    const SETTINGS: &'static [PreparationSetting] = &[SET];

    fn given(input: &Input) -> Result<Option<Extraction>> {
        let Some(set) = input.setting(SET.name) else { return Ok(None) };
        let json = (input.read)(set)?;
        // The set's images are named relative to the set file.
        let dir = Path::new(set).parent().unwrap_or(Path::new(""));
        let read = |name: &str| (input.read)(&dir.join(name).to_string_lossy());
        let elements = super::handmade::load(&json, &read)?;
        Ok(Some(Extraction::hand_made(input.exemplar, elements)))
    }

    fn id(input: &Input) -> String {
        extraction_id(input.exemplar)
    }

    fn compute(input: &Input, _: &dyn Progress, cancel: &Cancel) -> Result<Extraction> {
        cancel.check()?;
        Ok(Extraction::extract(input.exemplar))
    }

    fn to_bytes(&self) -> Vec<u8> {
        store::to_bytes(&self.id, &self.outcome)
    }

    fn from_bytes(bytes: &[u8]) -> std::result::Result<Extraction, AnalysisFileProblem> {
        let (id, outcome) = store::from_bytes(bytes)?;
        Ok(Extraction::new(id, outcome, None))
    }

    fn stored_id(&self) -> &str {
        &self.id
    }

    fn describe(&self) -> Map<String, Value> {
        let mut m = Map::new();
        m.insert("source".into(), json!(if self.handmade.is_some() { "hand-made" } else { "extracted" }));
        m.insert("extraction_version".into(), json!(extract::EXTRACTION_VERSION));
        match &self.outcome {
            Ok(e) => {
                m.insert("found".into(), json!(e.found));
                m.insert("bases".into(), json!(e.bases.len()));
                m.insert("mean_area".into(), json!(e.mean_area.round()));
                m.insert("sizes".into(), json!([e.scale_spread.0, e.scale_spread.1]));
                m.insert("orientation_spread".into(), json!(e.orientation_spread));
                m.insert("foreground".into(), json!(e.foreground));
                m.insert("segmentation".into(), json!(e.segmentation));
            }
            Err(why) => {
                m.insert("none".into(), json!(why));
            }
        }
        m
    }

    fn summary(&self) -> String {
        match &self.outcome {
            Ok(e) => format!("{} bases{}", e.bases.len(), if self.handmade.is_some() { ", hand-made" } else { "" }),
            Err(_) => "no elements".into(),
        }
    }

    fn etag(&self) -> String {
        self.handmade.as_ref().map(|h| format!("set={}", &h[..16])).unwrap_or_default()
    }

    fn memory_bytes(&self) -> u64 {
        // Texture (3 f32s) and alpha per texel, and about a third more for the mipmaps.
        let bytes = |e: &Elements| e.bases.iter().map(|b| b.texture.len() as u64 * 13 * 4 / 3).sum::<u64>();
        let maps: u64 = self.maps.lock().map_or(0, |m| m.iter().map(|(_, e)| bytes(e)).sum());
        self.outcome.as_ref().map_or(0, |e| bytes(e)) + maps + self.caches.bytes()
    }

    fn limit_caches(&self, bytes: u64) {
        self.caches.set_limit(bytes);
    }
}
