//! The modes: every engine that renders a texture is one folder here implementing [`Mode`], and
//! one line of the `modes!` list below, which generates the closed [`ModeParams`] enum and
//! its dispatch. Everything else — the server's parsing, metadata, OpenAPI, metrics, the CLI,
//! the viewer's panel — is written once against this module and learns a new mode from it.
//!
//! A mode's output bytes are a permanent contract: each mode has its own [`Mode::VERSION`],
//! part of every ETag and cache key of its tiles, bumped whenever its pixels change (the golden
//! test in `core/tests/golden.rs` says when).

pub mod declared;
pub mod magnify;
pub mod params;
pub mod prepared;

use std::collections::BTreeMap;
use std::fmt::Debug;
use std::sync::{Arc, OnceLock};

use serde_json::{Map, Value};

use crate::analysis::Analysis;
use crate::cache::Pyramid;
use crate::error::{CoreError, Result};
use crate::exemplar::Exemplar;
use crate::geom::Rect;
use crate::image::{Rendered, RgbWindow};
use crate::maps::{MaterialMap, UvWindow};
use crate::prepare::State;
pub use declared::Declared;
use params::{Common, ParamReader, ParamSpec};
use prepared::{ModeState, Slot, Step};

/// What a mode needs from a texture.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Needs {
    /// The prepared exemplar's pixels only: servable while the analysis is computed.
    Exemplar,
    /// The exemplar analysis (Gaussian stack, PCA, candidates).
    Analysis,
    /// The exemplar and what the mode prepares from it ([`Mode::State`]): servable once that
    /// is prepared.
    Prepared,
}

/// How expensive a mode's pixels are, so front ends can spend encoder effort accordingly.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Cost {
    /// Milliseconds per tile or more: worth compressing tightly.
    Heavy,
    /// Cheaper than encoding well: encode fast.
    Light,
}

/// What a texture offers a mode: its prepared exemplar, its analysis once computed, and what
/// its modes prepared ([`Mode::preparation`]).
#[derive(Clone, Copy)]
pub struct Source<'a> {
    /// The prepared exemplar (at its own width and height).
    pub exemplar: &'a Exemplar,
    /// The analysis, when available.
    pub analysis: Option<&'a Analysis>,
    /// The modes' prepared states, when the caller keeps them (a mode whose state is missing
    /// does not render: [`CoreError::NotPrepared`]).
    pub prepared: Option<&'a Prepared>,
    /// The material map to show instead of the colour ([`Source::with_map`]).
    pub map: Option<&'a MaterialMap>,
}

impl std::fmt::Debug for Source<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Source")
            .field("size", &self.exemplar.dims())
            .field("analysis", &self.analysis.map(|a| &a.header.id))
            .field("prepared", &self.prepared.map(|p| p.all().into_iter().map(|(m, _)| m).collect::<Vec<_>>()))
            .field("map", &self.map.map(|m| &m.name))
            .finish()
    }
}

impl<'a> Source<'a> {
    /// A source with both exemplar and analysis.
    pub fn new(exemplar: &'a Exemplar, analysis: &'a Analysis) -> Self {
        Source { exemplar, analysis: Some(analysis), prepared: None, map: None }
    }

    /// A source with the exemplar only.
    pub fn exemplar(exemplar: &'a Exemplar) -> Self {
        Source { exemplar, analysis: None, prepared: None, map: None }
    }

    /// This source with the modes' prepared states.
    pub fn with_prepared(self, prepared: &'a Prepared) -> Self {
        Source { prepared: Some(prepared), ..self }
    }

    /// This source showing material `map` instead of the colour: modes look it up where they
    /// would look the colour up, so every map of a view agrees texel for texel.
    pub fn with_map(self, map: &'a MaterialMap) -> Self {
        Source { map: Some(map), ..self }
    }

    /// The texels a render shows at exemplar coordinates: the map's, or the exemplar's colours.
    pub fn texels(&self) -> &'a [[u8; 3]] {
        self.map.map_or(&self.exemplar.pixels, |m| &m.texels)
    }

    /// The centred `2^k × 2^k` box means of [`Source::texels`] for every `k ≤ levels`, when
    /// something names them: the map, or the analysis for the colour (derived once and kept in
    /// `cache`, within its bytes).
    pub fn box_stack(&self, cache: &Pyramid) -> Option<crate::cache::Stack> {
        match self.map {
            Some(m) => Some(m.box_stack(cache)),
            None => self.analysis.map(|a| a.box_stack(cache)),
        }
    }

    /// The high-resolution texels magnified views sample, when the texture has them.
    pub fn hires(&self) -> Option<&'a [[u8; 3]]> {
        match self.map {
            Some(m) => m.hires.as_deref(),
            None => self.exemplar.hires.as_deref(),
        }
    }

    /// Exemplar size `(width, height)` for indexing.
    pub fn dims(&self) -> (usize, usize) {
        self.exemplar.dims()
    }

    /// The lattice the modes keep: the analysis's when there is one (its candidate sets were
    /// built for it, [`Analysis::lattice`]), else the prepared exemplar's. Every mode reads it
    /// here.
    pub fn lattice(&self) -> Option<&'a crate::lattice::Lattice> {
        match self.analysis {
            Some(an) => an.lattice(),
            None => self.exemplar.lattice.as_ref(),
        }
    }

    /// `L = ⌈log2 max(w, h)⌉`: the native zoom and finest level.
    pub fn levels(&self) -> u32 {
        self.exemplar.levels()
    }

    /// The analysis, or [`CoreError::NotAnalysed`] for `mode`.
    pub fn analysis(&self, mode: &'static str) -> Result<&'a Analysis> {
        self.analysis.ok_or(CoreError::NotAnalysed { mode })
    }
}

/// What to render: `rect` viewed `zoom_out` steps coarser than native (0: one pixel per texel;
/// `k`: one pixel covers `2^k × 2^k` texels), or `zoom_in` steps finer (magnified: a texel
/// covers `2^k × 2^k` pixels). At most one of the two is non-zero.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct View {
    /// Steps coarser than native.
    pub zoom_out: u32,
    /// Steps finer than native (at most [`magnify::MAX_ZOOM_IN`]).
    pub zoom_in: u32,
    /// Pixels at that zoom.
    pub rect: Rect,
}

impl View {
    /// `rect` at `zoom` steps from native: coarser when positive, magnified when negative.
    pub fn at(zoom: i64, rect: Rect) -> View {
        View { zoom_out: zoom.max(0) as u32, zoom_in: (-zoom).max(0) as u32, rect }
    }

    /// `rect` at native zoom.
    pub fn native(rect: Rect) -> View {
        View::at(0, rect)
    }

    /// `rect` `k` steps coarser than native.
    pub fn out(k: u32, rect: Rect) -> View {
        View { zoom_out: k, zoom_in: 0, rect }
    }
}

/// Refuse a window that is empty or has more than `max` pixels (what a mode renders in one call).
pub(crate) fn check_window(rect: Rect, max: i64) -> Result<()> {
    if rect.is_empty() || rect.area() > max {
        return Err(CoreError::Window {
            width: rect.width(),
            height: rect.height(),
            message: format!("must be non-empty with at most {max} pixels"),
        });
    }
    Ok(())
}

/// The error of `map=uv` in a mode whose pixels are not texels looked up by coordinate.
fn no_uv(mode: &str) -> CoreError {
    CoreError::Map {
        name: "uv".into(),
        message: format!("is not available in mode={mode}: its pixels are not texels looked up by coordinate"),
    }
}

/// An engine: its name, version, parameters and rendering of any window.
pub trait Mode {
    /// Name as the API spells it (`mode=NAME`).
    const NAME: &'static str;
    /// Version of the bytes this mode renders: part of its ETags and cache keys. Bump it with
    /// every change of output, and update the golden digests.
    const VERSION: u32;
    /// One line for documentation and the viewer.
    const SUMMARY: &'static str;
    /// What it needs from a texture.
    const NEEDS: Needs;
    /// How expensive its pixels are.
    const COST: Cost;
    /// Validated parameters: everything besides the texture that determines the pixels,
    /// declared once with [`crate::declare_params!`] (specs, defaults, reading, values and the
    /// canonical text all come from that declaration).
    type Params: Declared;

    /// What the mode prepares per texture and renders from: `()` for nothing, or a
    /// [`crate::prepare::Preparation`] (see [`prepared`]). Its render receives it.
    type State: ModeState;

    /// A picture of what the mode prepared for the texture, as parameters `p` use it
    /// (`textile render --sheet`): none by default.
    fn sheet(_p: &Self::Params, _state: &Self::State, _src: &Source) -> Option<Result<RgbWindow>> {
        None
    }

    /// Why the mode does not serve the texture of `src`, if it does not: its renders then
    /// answer [`CoreError::Declined`] instead of pixels that betray the exemplar. Every
    /// texture is served by default.
    fn declines(_src: &Source) -> Option<String> {
        None
    }

    /// Whether the mode's pixels are exemplar texels looked up by coordinate, which
    /// [`Mode::coordinates`] then gives (`map=uv`).
    const HAS_UV: bool = false;

    /// The exemplar coordinates each pixel of `view` shows (`map=uv`), for modes whose pixels
    /// are exemplar texels looked up by coordinate; others answer [`CoreError::Map`] saying why.
    fn coordinates(
        _p: &Self::Params,
        _state: &Self::State,
        _src: &Source,
        _cache: &Pyramid,
        _view: View,
    ) -> Result<UvWindow> {
        Err(no_uv(Self::NAME))
    }

    /// Render a view that is not magnified (`view.zoom_in = 0`); `cache` is the shared
    /// pyramidal cache (modes that keep nothing ignore it).
    fn render(p: &Self::Params, state: &Self::State, src: &Source, cache: &Pyramid, view: View) -> Result<Rendered>;

    /// Render `rect` magnified `k` steps beyond native (design note §1.8). By default the
    /// native pixels are magnified bilinearly; modes that synthesize exemplar coordinates
    /// extrapolate each texel's patch instead ([`magnify::patches`]).
    fn magnify(
        p: &Self::Params,
        state: &Self::State,
        src: &Source,
        cache: &Pyramid,
        k: u32,
        rect: Rect,
    ) -> Result<Rendered> {
        let native = Self::render(p, state, src, cache, View::native(magnify::source_rect(rect, k)))?;
        Ok(Rendered { image: magnify::bilinear(&native.image, k, rect), synthesized: native.synthesized })
    }
}

/// A mode as data: what the server, the CLI and the viewer describe.
#[derive(Clone, Copy)]
pub struct ModeInfo {
    /// Name.
    pub name: &'static str,
    /// Version of its bytes.
    pub version: u32,
    /// One line.
    pub summary: &'static str,
    /// What it needs from a texture.
    pub needs: Needs,
    /// How expensive its pixels are.
    pub cost: Cost,
    /// Its own parameters.
    pub specs: &'static [ParamSpec],
    /// What it prepares per texture, if anything.
    pub preparation: Option<&'static dyn Step>,
    /// Whether it gives its coordinates ([`Mode::HAS_UV`]).
    pub has_uv: bool,
}

impl std::fmt::Debug for ModeInfo {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ModeInfo")
            .field("name", &self.name)
            .field("version", &self.version)
            .field("preparation", &self.preparation.map(|p| p.what()))
            .finish_non_exhaustive()
    }
}

impl ModeInfo {
    fn of<M: Slot>() -> ModeInfo {
        ModeInfo {
            name: M::NAME,
            version: M::VERSION,
            summary: M::SUMMARY,
            needs: M::NEEDS,
            cost: M::COST,
            specs: <M::Params as Declared>::SPECS,
            preparation: <M::State as ModeState>::step::<M>(),
            has_uv: M::HAS_UV,
        }
    }

    /// Whether `key` is one of the texture settings its preparation reads.
    pub fn prepares_with(&self, key: &str) -> bool {
        self.preparation.is_some_and(|p| p.settings().iter().any(|s| s.name == key))
    }
}

/// What every mode prepares per texture: `(mode name, preparation)`, in [`MODE_NAMES`] order.
pub fn preparations() -> Vec<(&'static str, &'static dyn Step)> {
    all().into_iter().filter_map(|m| m.preparation.map(|p| (m.name, p))).collect()
}

/// The list of modes: `Variant => folder::Type`. Adding a mode is a folder and a line here.
macro_rules! modes {
    ($($variant:ident => $module:ident :: $ty:ident),+ $(,)?) => {
        $(pub mod $module;)+

        /// The states one texture's modes have prepared: a slot per mode, each of that mode's
        /// own [`Mode::State`] (filled from the start for a mode that prepares nothing).
        pub struct Prepared {
            $($module: OnceLock<Arc<<$module::$ty as Mode>::State>>,)+
        }

        impl Default for Prepared {
            fn default() -> Self {
                Prepared { $($module: prepared::empty_slot(),)+ }
            }
        }

        $(impl Slot for $module::$ty {
            fn slot(p: &Prepared) -> &OnceLock<Arc<Self::State>> {
                &p.$module
            }
        })+

        impl Prepared {
            /// Every state prepared so far, by mode name, without its type (modes that prepare
            /// nothing have none).
            pub fn all(&self) -> Vec<(&'static str, Arc<dyn State>)> {
                let mut all = Vec::new();
                $(if let Some(s) = self.$module.get().and_then(ModeState::erased) {
                    all.push((<$module::$ty as Mode>::NAME, s));
                })+
                all
            }

            /// Mode `mode`'s state without its type, once prepared (none for a mode that
            /// prepares nothing).
            pub fn state_of(&self, mode: &str) -> Option<Arc<dyn State>> {
                $(if mode == <$module::$ty as Mode>::NAME {
                    return self.$module.get().and_then(ModeState::erased);
                })+
                None
            }

            /// Whether mode `mode` has what it needs to render (a mode that prepares nothing
            /// always has).
            pub fn has(&self, mode: &str) -> bool {
                $(if mode == <$module::$ty as Mode>::NAME {
                    return self.$module.get().is_some();
                })+
                false
            }
        }

        /// Names of all modes, in the order they are listed.
        pub const MODE_NAMES: &[&str] = &[$(<$module::$ty as Mode>::NAME),+];

        /// Every mode, described.
        pub fn all() -> Vec<ModeInfo> {
            vec![$(ModeInfo::of::<$module::$ty>()),+]
        }

        /// A mode with its validated parameters: everything besides the texture that
        /// determines a tile's pixels.
        #[derive(Debug, Clone, PartialEq, Eq, Hash)]
        pub enum ModeParams {
            $(
                #[doc = concat!("`mode=", stringify!($module), "`.")]
                $variant(<$module::$ty as Mode>::Params)
            ),+
        }

        impl ModeParams {
            /// The built-in defaults of the mode called `name`.
            pub fn defaults(name: &str) -> Option<ModeParams> {
                match name {
                    $(n if n == <$module::$ty as Mode>::NAME => Some(ModeParams::$variant(Default::default())),)+
                    _ => None,
                }
            }

            /// The mode's description.
            pub fn info(&self) -> ModeInfo {
                match self {
                    $(ModeParams::$variant(_) => ModeInfo::of::<$module::$ty>(),)+
                }
            }

            /// Read the mode's keys over these parameters (see [`Mode::parse`]).
            pub fn parse(&self, common: &Common, r: &mut ParamReader, src: &Source) -> Result<ModeParams> {
                match self {
                    $(ModeParams::$variant(p) => Declared::parse(p, common, r, src).map(ModeParams::$variant),)+
                }
            }

            /// Current values as JSON (see [`Mode::values`]).
            pub fn values(&self, src: &Source) -> Map<String, Value> {
                match self {
                    $(ModeParams::$variant(p) => Declared::values(p, src),)+
                }
            }

            /// Each parameter as text that reads back to its value (see [`Declared::texts`]).
            pub fn texts(&self) -> Vec<(&'static str, String)> {
                match self {
                    $(ModeParams::$variant(p) => Declared::texts(p),)+
                }
            }

            /// Canonical text, mode name and version included: the identity of the pixels for
            /// cache keys and ETags.
            pub fn canonical(&self) -> String {
                match self {
                    $(ModeParams::$variant(p) => format!(
                        "mode={};v{};{}",
                        <$module::$ty as Mode>::NAME,
                        <$module::$ty as Mode>::VERSION,
                        Declared::canonical(p)
                    ),)+
                }
            }

            /// Why the mode does not serve `src`'s texture, if it does not (see [`Mode::declines`]).
            pub fn declines(&self, src: &Source) -> Option<String> {
                match self {
                    $(ModeParams::$variant(_) => <$module::$ty as Mode>::declines(src),)+
                }
            }

            /// [`ModeParams::declines`] as the error a render answers.
            fn served(&self, src: &Source) -> Result<()> {
                match self.declines(src) {
                    Some(reason) => Err(CoreError::Declined { mode: self.name(), reason }),
                    None => Ok(()),
                }
            }

            /// A picture of what the mode prepared (see [`Mode::sheet`]).
            pub fn sheet(&self, src: &Source) -> Option<Result<RgbWindow>> {
                if let Err(e) = self.served(src) {
                    return Some(Err(e));
                }
                match self {
                    $(ModeParams::$variant(p) => prepared::with_state::<$module::$ty, _>(src.prepared, |st| Ok(<$module::$ty as Mode>::sheet(p, st, src))).unwrap_or_else(|e| Some(Err(e))),)+
                }
            }

            /// The exemplar coordinates each pixel of a view shows (see [`Mode::coordinates`]).
            pub fn coordinates(&self, src: &Source, cache: &Pyramid, view: View) -> Result<UvWindow> {
                if view.zoom_in > 0 {
                    magnify::check_steps(view.zoom_in)?;
                }
                self.served(src)?;
                match self {
                    $(ModeParams::$variant(_) if !<$module::$ty as Mode>::HAS_UV => Err(no_uv(<$module::$ty as Mode>::NAME)),)+
                    $(ModeParams::$variant(p) => prepared::with_state::<$module::$ty, _>(src.prepared, |st| <$module::$ty as Mode>::coordinates(p, st, src, cache, view)),)+
                }
            }

            /// Render a view, magnified or not, of the colour or of `src`'s map (a normal map's
            /// blended normals renormalised).
            pub fn render(&self, src: &Source, cache: &Pyramid, view: View) -> Result<Rendered> {
                let Some(map) = src.map else { return self.render_texels(src, cache, view) };
                let mut r = self.render_texels(src, cache, view)?;
                if map.normal {
                    crate::maps::renormalise(&mut r.image.pixels);
                }
                Ok(r)
            }

            fn render_texels(&self, src: &Source, cache: &Pyramid, view: View) -> Result<Rendered> {
                self.served(src)?;
                if view.zoom_in > 0 {
                    magnify::check_steps(view.zoom_in)?;
                    return match self {
                        $(ModeParams::$variant(p) => prepared::with_state::<$module::$ty, _>(src.prepared, |st| <$module::$ty as Mode>::magnify(p, st, src, cache, view.zoom_in, view.rect)),)+
                    };
                }
                match self {
                    $(ModeParams::$variant(p) => prepared::with_state::<$module::$ty, _>(src.prepared, |st| <$module::$ty as Mode>::render(p, st, src, cache, view)),)+
                }
            }
        }
    };
}

modes! {
    Synth => synth::Synth,
    Mosaic => mosaic::Mosaic,
    Tiling => tiling::Tiling,
    Umbrella => umbrella::Umbrella,
}

impl ModeParams {
    /// The mode's name.
    pub fn name(&self) -> &'static str {
        self.info().name
    }
}

/// The mode of requests that name none, unless a texture's configuration says otherwise: the
/// first of the `modes!` list. Named here only.
pub const DEFAULT_MODE: &str = MODE_NAMES[0];

/// Every mode's parameters, for naming the mode a stray key belongs to.
fn all_specs() -> Vec<(&'static str, &'static [ParamSpec])> {
    all().iter().map(|m| (m.name, m.specs)).collect()
}

/// The parameters a texture starts every request from: its default mode, and each mode's
/// parameters with the texture's configured defaults and settings.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct Defaults {
    /// Mode of requests that name none.
    pub mode: &'static str,
    /// One entry per mode, in [`MODE_NAMES`] order.
    pub params: Vec<ModeParams>,
}

/// A configured default that could not be used: which mode's table, and why.
#[derive(Debug, thiserror::Error)]
#[error("{}{source}", .mode.as_ref().map(|m| format!("[{m}] ")).unwrap_or_default())]
pub struct DefaultsError {
    /// The mode whose table was wrong (none: the mode name itself).
    pub mode: Option<String>,
    /// Why.
    #[source]
    pub source: CoreError,
}

impl Defaults {
    /// A texture's defaults: `mode` names the default mode, `seed` the default seed of every
    /// mode, and `tables` holds, per mode name, the configured `key = value` pairs (request
    /// parameters as defaults, and texture settings).
    pub fn configure(
        src: &Source,
        mode: &str,
        seed: u64,
        tables: &BTreeMap<String, Vec<(String, String)>>,
    ) -> std::result::Result<Defaults, DefaultsError> {
        let mode_name = MODE_NAMES.iter().copied().find(|m| *m == mode).ok_or_else(|| DefaultsError {
            mode: None,
            source: params::MODE.error(format!(
                "'{}' is not one of {}",
                crate::error::clip(mode),
                MODE_NAMES.join(", ")
            )),
        })?;
        if let Some(unknown) = tables.keys().find(|k| !MODE_NAMES.contains(&k.as_str())) {
            return Err(DefaultsError {
                mode: None,
                source: CoreError::ParamKey {
                    key: unknown.clone(),
                    message: format!("is not a mode; per-mode tables are {}", MODE_NAMES.join(", ")),
                },
            });
        }
        let common = Common { seed: Some(seed), period: None };
        let mut out = Vec::new();
        for name in MODE_NAMES {
            let fail = |source| DefaultsError { mode: Some(name.to_string()), source };
            let Some(base) = ModeParams::defaults(name) else { continue };
            // Settings of the mode's preparation are its, not its parameters'.
            let info = base.info();
            let table: Vec<(String, String)> =
                tables.get(*name).into_iter().flatten().filter(|(k, _)| !info.prepares_with(k)).cloned().collect();
            let mut r = ParamReader::texture(table).map_err(fail)?;
            let p = base.parse(&common, &mut r, src).map_err(fail)?;
            r.finish(name, &all_specs()).map_err(fail)?;
            out.push(p);
        }
        Ok(Defaults { mode: mode_name, params: out })
    }

    /// Built-in defaults for every mode, default mode [`DEFAULT_MODE`].
    pub fn builtin(src: &Source) -> Defaults {
        Defaults::configure(src, DEFAULT_MODE, 0, &BTreeMap::new())
            .unwrap_or_else(|e| unreachable!("built-in defaults are valid: {e}"))
    }

    /// The defaults of the mode called `name`.
    pub fn get(&self, name: &str) -> Option<&ModeParams> {
        MODE_NAMES.iter().position(|m| *m == name).and_then(|i| self.params.get(i))
    }

    /// Read a request: `mode` (or the default), `seed` and `world`, then the mode's keys over
    /// this texture's defaults, then reject whatever is left. The caller takes its own keys
    /// from `r` first.
    pub fn request(&self, src: &Source, mut r: ParamReader) -> Result<ModeParams> {
        let mode = r.get(&params::MODE).unwrap_or_else(|| self.mode.to_string());
        let base = self.get(&mode).ok_or_else(|| {
            params::MODE.error(format!(
                "'{}' is not available; allowed: {}",
                crate::error::clip(&mode),
                MODE_NAMES.join(", ")
            ))
        })?;
        let common = Common::read(&mut r, src.exemplar.size().longer())?;
        let p = base.parse(&common, &mut r, src)?;
        r.finish(&mode, &all_specs())?;
        Ok(p)
    }

    /// Canonical text of every mode's defaults: changes whenever any default does.
    pub fn canonical(&self) -> String {
        let each: Vec<String> = self.params.iter().map(ModeParams::canonical).collect();
        format!("default={}|{}", self.mode, each.join("|"))
    }
}
