//! # textile-core
//!
//! Infinite, deterministic, example-based texture synthesis. Give it a small exemplar image;
//! it synthesizes any rectangle of an endless, non-repeating texture that looks like it, and
//! the same rectangle always comes out bit-for-bit the same, however it is requested.
//!
//! The main engine is Lefebvre & Hoppe's *parallel controllable texture synthesis* (2005).
//! The pipeline, one module per stage:
//!
//! 1. [`exemplar`] — decode and prepare the input (power-of-two square, toroidal flag);
//! 2. [`analysis`] — Gaussian [`stack`], PCA [`features`], k-coherence [`candidates`], computed
//!    once and stored with [`analysis_file`];
//! 3. [`plan`] — which padded rectangle each level must compute for a window to be exact;
//! 4. [`synth`] — upsample, jitter by a [`hash`] of absolute coordinates, correct; the
//!    [`pyramid`] cache lets neighbouring windows share coarse levels and padding;
//! 5. [`mod@render`] — exemplar coordinates to colours, at native or zoomed-out scale.
//!
//! The cheap mode, [`mosaic`], is Xu, Guo & Shum's chaos mosaic: the tiled exemplar with blocks
//! moved by the cat map, evaluated lazily for any window.
//!
//! ```
//! use textile_core::{Analysis, Exemplar, ExemplarOptions, NoProgress, Rect, SynthParams, render};
//!
//! // A small synthetic exemplar: diagonal stripes with some variation.
//! let px: Vec<[u8; 4]> = (0..64 * 64)
//!     .map(|i| { let (x, y) = (i % 64, i / 64); [((x + y) * 4 % 256) as u8, (x * 3) as u8, 90, 255] })
//!     .collect();
//! let ex = Exemplar::from_rgba(64, 64, &px, &ExemplarOptions::default());
//! let analysis = Analysis::build(&ex, &NoProgress);
//! let params = SynthParams { seed: 7, ..SynthParams::default() };
//! // Any window, anywhere: negative and far coordinates included.
//! let tile = render(&analysis, &params, 0, Rect::new(-1 << 40, 12, 32, 32)).unwrap();
//! assert_eq!((tile.width, tile.height), (32, 32));
//! ```

pub mod analysis;
pub mod analysis_file;
pub mod candidates;
pub mod error;
pub mod exemplar;
pub mod features;
mod generations;
pub mod geom;
pub mod hash;
mod history;
pub mod kdtree;
mod kernel;
pub mod mosaic;
pub mod params;
pub mod plan;
pub mod pyramid;
pub mod render;
pub mod stack;
pub mod synth;

pub use analysis::{Analysis, AnalysisHeader, NoProgress, Progress, ALGORITHM_VERSION};
pub use error::{AnalysisFileProblem, CoreError, Result};
pub use exemplar::{Exemplar, ExemplarOptions};
pub use geom::Rect;
pub use mosaic::MosaicParams;
pub use params::{Randomness, SynthParams};
pub use pyramid::{Pyramid, PyramidStats};
pub use render::{render, render_with, Rendered, RgbWindow};
pub use synth::{synthesize, synthesize_with, CoordWindow, Synthesized};
