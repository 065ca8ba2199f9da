//! A texture's preparations: what each of its modes prepares, then its analysis — each through
//! the core's one path ([`textile_core::prepare::load_or_compute`]): read from the data directory
//! when current, else computed (watched for progress, stops and time budget) and stored there —
//! attached to the texture as it is ready, and logged.

use std::path::PathBuf;
use std::sync::atomic::Ordering;

use textile_core::prepare::{self, Input, Origin};
use textile_core::{Analysis, Cancel, Progress};

use super::analysing;
use super::registry::Registry;
use super::storage::{data_dir_storable, setting_file};
use super::{LoadError, Texture};
use crate::config::Config;

/// Load or compute the analysis of every texture of a prepared registry that `which` selects,
/// in configuration order (each texture serves its analysis-needing modes as soon as its own is
/// attached), each watched by an [`analysing::Watch`]: `stop` is asked between textures and
/// during each analysis, and ends the loading with [`LoadError::Stopped`] once it is set;
/// an analysis longer than `analysis_timeout_secs` ends it with [`LoadError::AnalysisTimeout`].
///
/// The data directory is checked first: stale temporary files of interrupted writes are removed,
/// and if analyses cannot be stored there (read-only, full, not a directory) the server warns
/// and keeps them in memory only (recomputed at each start) rather than exit after computing them.
pub fn analyse_registry(
    cfg: &Config,
    reg: &Registry,
    which: &dyn Fn(&Texture) -> bool,
    log: &dyn Fn(String),
    stop: &Cancel,
) -> Result<(), LoadError> {
    let data_dir = cfg.data_dir();
    let storable = data_dir_storable(cfg, log);
    let budget = std::time::Duration::from_secs(cfg.analysis_timeout_secs);
    // What the modes prepare first, for every texture (quick: those modes serve sooner), then
    // the analyses.
    for modes_only in [true, false] {
        for tex in reg.list.iter().filter(|t| which(t)) {
            if stop.is_set() {
                return Err(LoadError::Stopped);
            }
            let watch = analysing::Watch::new(&tex.config.id, &tex.progress, &tex.removed, stop, budget);
            let preparing = Preparing { cfg, data_dir: &data_dir, storable, tex, log };
            let done =
                if modes_only { preparing.modes(watch.cancel()) } else { preparing.analysis(&watch, watch.cancel()) };
            watch_outcome(done, &watch, tex)?;
        }
    }
    Ok(())
}

/// A texture's preparation as the start-up sees it: a timeout, a stop or a failure ends it; a
/// texture removed meanwhile (DELETE) is skipped, nothing of it kept.
fn watch_outcome(
    done: Result<(), textile_core::CoreError>,
    watch: &analysing::Watch,
    tex: &Texture,
) -> Result<(), LoadError> {
    let id = || tex.config.id.clone();
    match done {
        Ok(()) => Ok(()),
        Err(textile_core::CoreError::Cancelled) if watch.timed_out() => {
            Err(LoadError::AnalysisTimeout { id: id(), message: watch.timeout_message() })
        }
        Err(textile_core::CoreError::Cancelled) if tex.removed.is_set() => Ok(()),
        Err(textile_core::CoreError::Cancelled) => Err(LoadError::Stopped),
        Err(source) => Err(LoadError::Core { id: id(), source }),
    }
}

/// How a texture's preparations are logged and where they are stored.
struct Preparing<'a> {
    cfg: &'a Config,
    data_dir: &'a std::path::Path,
    storable: bool,
    tex: &'a Texture,
    log: &'a dyn Fn(String),
}

impl Preparing<'_> {
    fn path(&self, extension: &str) -> PathBuf {
        self.data_dir.join(format!("{}.{extension}", self.tex.config.id))
    }

    /// A texture removed meanwhile leaves nothing behind.
    fn keep(&self) -> bool {
        !self.tex.removed.is_set()
    }

    fn report(&self, what: &str, summary: String, origin: &Origin, path: &std::path::Path, took: std::time::Duration) {
        let (id, took) = (&self.tex.config.id, took.as_secs_f64());
        (self.log)(match origin {
            Origin::Given => format!("texture '{id}': {what} ({summary}) given by its settings"),
            Origin::Loaded => format!("texture '{id}': loaded {what} ({summary}) from {}", path.display()),
            Origin::Stored { why } => {
                format!("texture '{id}': {why}; computed {what} ({summary}) in {took:.2}s, stored {}", path.display())
            }
            Origin::Computed { why, not_stored } => format!(
                "texture '{id}': {why}; computed {what} ({summary}) in {took:.2}s, {}",
                match not_stored {
                    Some(e) => format!("warning: not stored ({e}); kept in memory only"),
                    None if !self.keep() => "not stored (the texture was removed)".to_string(),
                    None => "kept in memory only".to_string(),
                }
            ),
        })
    }

    /// What each mode prepares, unless the texture has it already.
    fn modes(&self, cancel: &Cancel) -> Result<(), textile_core::CoreError> {
        let t = &self.tex.config;
        let read = |name: &str| setting_file(self.cfg, t, name);
        let tables = t.mode_tables();
        for (mode, step) in textile_core::modes::preparations() {
            if self.tex.prepared.has(mode) {
                continue;
            }
            let settings: Vec<(String, String)> = tables
                .get(mode)
                .into_iter()
                .flatten()
                .filter(|(k, _)| step.settings().iter().any(|s| s.name == k))
                .cloned()
                .collect();
            let input = Input { exemplar: &self.tex.exemplar, settings: &settings, read: &read };
            let path = self.path(step.extension());
            let started = std::time::Instant::now();
            let keep = || self.keep();
            let (state, origin) = step.run(
                &self.tex.prepared,
                &input,
                Some(&path),
                self.storable,
                &keep,
                &textile_core::NoProgress,
                cancel,
            )?;
            self.report(step.what(), state.summary(), &origin, &path, started.elapsed());
            state.limit_caches(self.tex.cache_limit.load(Ordering::Relaxed));
        }
        Ok(())
    }

    /// The analysis, after what the modes prepare: attaching it makes the texture ready, with
    /// every file in place.
    fn analysis(&self, progress: &dyn Progress, cancel: &Cancel) -> Result<(), textile_core::CoreError> {
        self.modes(cancel)?;
        let t = &self.tex.config;
        let read = |name: &str| setting_file(self.cfg, t, name);
        let settings = [(textile_core::analysis::INDEX.name.to_string(), t.candidate_search.name().to_string())];
        let input = Input { exemplar: &self.tex.exemplar, settings: &settings, read: &read };
        let path = self.path(<Analysis as prepare::Preparation>::EXTENSION);
        let started = std::time::Instant::now();
        let keep = || self.keep();
        let (analysis, origin) =
            prepare::load_or_compute::<Analysis>(&input, Some(&path), self.storable, &keep, progress, cancel)?;
        self.report("analysis", analysis.header.id.clone(), &origin, &path, started.elapsed());
        self.tex.set_analysis(analysis)
    }
}

/// A texture's preparations, one after the other, each by [`prepare::load_or_compute`]: what
/// each mode prepares, then the analysis — read from `data_dir` when current, else computed
/// (stopped when `cancel` is set) and stored there if `storable` — each attached to the texture
/// as it is ready.
pub fn analyse_texture(
    cfg: &Config,
    data_dir: &std::path::Path,
    storable: bool,
    tex: &Texture,
    log: &dyn Fn(String),
    progress: &dyn Progress,
    cancel: &Cancel,
) -> Result<(), textile_core::CoreError> {
    Preparing { cfg, data_dir, storable, tex, log }.analysis(progress, cancel)
}

/// Both phases: every texture with its analysis.
pub fn load_registry(cfg: &Config, log: &dyn Fn(String)) -> Result<Registry, LoadError> {
    let reg = super::registry::prepare_registry(cfg, log)?;
    analyse_registry(cfg, &reg, &|_| true, log, &Cancel::new())?;
    Ok(reg)
}
