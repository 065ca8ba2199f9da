//! # textile-core
//!
//! Infinite, deterministic, example-based texture synthesis. Give it a small exemplar image;
//! it renders any rectangle of an endless, non-repeating texture that looks like it, and the
//! same rectangle always comes out bit-for-bit the same, however it is requested.
//!
//! The pipeline, one module per stage:
//!
//! 1. [`exemplar`] — decode and prepare the input at its own size and shape (scaled only past
//!    [`exemplar::MAX_SIDE`]), its toroidal flag, randomness mask and material maps ([`maps`],
//!    [`mask`]), in the order one [`recipe`] applies for every caller (a texture's settings:
//!    largest side, wrap-around or a seamless replacement, high-resolution source, lattice,
//!    mask, maps), its sizes read through [`geom::Size`];
//! 2. [`lattice`] — its structure, found from the pixels or given: an exact repeat (a tile
//!    repeated), a near-regular lattice (1-D or 2-D, real-valued periods), or none;
//! 3. [`analysis`] — Gaussian stack ([`stack`], also the low-pass of material maps), PCA
//!    neighbourhoods, k-coherence candidates, computed once and stored in a file; with what
//!    each mode prepares per texture, it goes through one path, [`prepare`];
//! 4. [`modes`] — the engines, one folder each behind one [`Mode`] trait:
//!    [`modes::synth`] (Lefebvre & Hoppe's parallel controllable synthesis, the main engine),
//!    [`modes::mosaic`] (Xu, Guo & Shum's chaos mosaic, the cheap one),
//!    [`modes::umbrella`] (just-in-time umbrella patches, for textures of elements) and
//!    [`modes::tiling`] (the exemplar repeated, the reference); their parameters are declared
//!    once as [`modes::params::ParamSpec`]s and read by one [`modes::params::ParamReader`];
//! 5. [`cache`] — the pyramidal cache that lets neighbouring windows share work;
//! 6. [`image`] — the RGB windows the modes produce;
//! 7. [`samples`] — per-sample queries (Wei & Levoy 2003): scattered texels and filtered
//!    footprints in any order, equal to the tiles' pixels, through the same cache;
//! 8. [`tileable`] — one seamless, finite tileable image by Wei & Levoy's 2000 algorithm,
//!    its searches through the [`tsvq`] index.
//!
//! ```
//! use textile_core::{Analysis, Defaults, Exemplar, ExemplarOptions, NoProgress, ParamReader, Pyramid, Rect, Source, View};
//!
//! // A small synthetic exemplar: diagonal stripes with some variation.
//! let px: Vec<[u8; 4]> = (0..64 * 64)
//!     .map(|i| { let (x, y) = (i % 64, i / 64); [((x + y) * 4 % 256) as u8, (x * 3) as u8, 90, 255] })
//!     .collect();
//! let ex = Exemplar::from_rgba(64, 64, &px, &ExemplarOptions::default());
//! let analysis = Analysis::build(&ex, &NoProgress);
//! let src = Source::new(&ex, &analysis);
//! // A request's parameters, read as the server reads a query string.
//! let params = Defaults::builtin(&src).request(&src, ParamReader::request([("mode", "synth"), ("seed", "7")])?)?;
//! // Any window, anywhere: negative and far coordinates included.
//! let tile = params.render(&src, &Pyramid::off(), View::native(Rect::new(-1 << 40, 12, 32, 32)))?;
//! assert_eq!((tile.image.width, tile.image.height), (32, 32));
//! # Ok::<(), textile_core::CoreError>(())
//! ```

pub mod analysis;
pub mod cache;
pub mod cancel;
pub mod error;
pub mod exemplar;
pub mod files;
pub mod geom;
pub mod hash;
pub mod image;
pub mod landscape;
pub mod lattice;
pub mod maps;
pub mod mask;
pub mod memo;
pub mod modes;
pub mod prepare;
pub mod progress;
pub mod recipe;
pub mod samples;
pub mod stack;
pub mod tileable;
pub mod tsvq;

pub use analysis::{Analysis, AnalysisHeader, NoProgress, Progress, ALGORITHM_VERSION};
pub use cache::{Pyramid, PyramidStats};
pub use cancel::Cancel;
pub use error::{AnalysisFileProblem, CoreError, Result};
pub use exemplar::{Exemplar, ExemplarOptions};
pub use geom::Rect;
pub use image::{Rendered, RgbWindow};
pub use modes::params::{ParamReader, ParamSpec, TILE_SIZE};
pub use modes::{Defaults, Mode, ModeInfo, ModeParams, Source, View, MODE_NAMES};
pub use samples::{Footprint, Sampled, Texel};
