//! What a request that is not one image shows — a 3D model, an export, a batch of samples: a
//! texture with its mode's parameters and map, or a landscape (its job, whose seed, period and
//! map every image keeps). Each image of it is a [`Picture`] of some place.

use std::sync::Arc;

use textile_core::maps::MapChoice;
use textile_core::ModeParams;

use super::landscape::{LandscapeJob, LandscapeMap};
use super::{cache_key, ImageJob, Picture, Target};
use crate::textures::{Texture, Zooms};

/// A texture with a mode's parameters and a map, or a landscape.
#[derive(Clone)]
pub enum Subject {
    /// A texture.
    Texture {
        /// The texture.
        tex: Arc<Texture>,
        /// The mode and its parameters.
        params: ModeParams,
        /// The colour or a material map.
        map: MapChoice,
    },
    /// A landscape: its job for some place, whose seed, period and map its images keep.
    Landscape(LandscapeJob),
}

impl Subject {
    /// The id of the texture or landscape.
    pub fn id(&self) -> &str {
        match self {
            Subject::Texture { tex, .. } => &tex.config.id,
            Subject::Landscape(j) => &j.land.config.id,
        }
    }

    /// The zooms it serves.
    pub fn zooms(&self) -> Zooms {
        match self {
            Subject::Texture { tex, .. } => tex.zooms(),
            Subject::Landscape(j) => j.land.zooms(),
        }
    }

    /// The names of its maps: a texture's own; a landscape's that every layer has.
    pub fn maps(&self) -> Vec<String> {
        match self {
            Subject::Texture { tex, .. } => tex.exemplar.maps.iter().map(|m| m.name.clone()).collect(),
            Subject::Landscape(j) => j.land.maps(),
        }
    }

    /// The hashes of map `name`'s images (every layer's, for a landscape), for cache keys.
    pub fn map_hashes(&self, name: &str) -> Option<String> {
        match self {
            Subject::Texture { tex, .. } => tex.exemplar.map(name).map(|m| m.hash.clone()),
            Subject::Landscape(j) => {
                let each: Vec<&str> =
                    j.land.layers.iter().filter_map(|y| y.tex.exemplar.map(name).map(|m| m.hash.as_str())).collect();
                (!each.is_empty()).then(|| each.join("+"))
            }
        }
    }

    /// Its picture of `target`, showing its own map.
    pub fn picture(&self, target: Target) -> Picture {
        match self {
            Subject::Texture { tex, params, map } => Picture::Texture(ImageJob {
                tex: tex.clone(),
                params: params.clone(),
                target,
                map: map.clone(),
                dem: None,
            }),
            Subject::Landscape(j) => Picture::Landscape(j.at(target, j.map.clone())),
        }
    }

    /// Its picture of `target` showing the colour (`None`) or map `name` instead.
    pub fn picture_of(&self, target: Target, map: Option<&str>) -> Picture {
        match self {
            Subject::Texture { tex, params, .. } => Picture::Texture(ImageJob {
                tex: tex.clone(),
                params: params.clone(),
                target,
                map: map.map_or(MapChoice::Albedo, |n| MapChoice::Map(n.to_string())),
                dem: None,
            }),
            Subject::Landscape(j) => {
                Picture::Landscape(j.at(target, map.map_or(LandscapeMap::Albedo, |n| LandscapeMap::Map(n.to_string()))))
            }
        }
    }

    /// A cache key of something made of it: a texture's as its tiles' keys are made (so
    /// textures' 3D keys stay as they were); a landscape's after its job's key.
    pub fn key(&self, what: std::fmt::Arguments) -> String {
        match self {
            Subject::Texture { tex, params, .. } => cache_key(tex, params, what),
            Subject::Landscape(j) => format!("{}|model|{what}", j.key()),
        }
    }
}
