//! The analysis as a texture's [`Preparation`]: stored as `<texture>.tex` in the file format of
//! [`super::file`], current while its id (exemplar content, algorithm version, search) matches;
//! its one setting is the candidate search (`index`).

use serde_json::{json, Map, Value};

use super::{Analysis, IndexChoice, Progress};
use crate::cancel::Cancel;
use crate::error::{AnalysisFileProblem, Result};
use crate::prepare::{Input, Preparation, PreparationSetting};

/// The setting choosing the candidate search.
pub const INDEX: PreparationSetting =
    PreparationSetting { name: "index", help: "candidate search of the analysis: auto, exact or coherent" };

/// The candidate search the input asks for (its default when it gives none or a bad one, which
/// configuration checks refuse first).
fn search(input: &Input) -> IndexChoice {
    input.setting(INDEX.name).and_then(|s| IndexChoice::parse(s).ok()).unwrap_or_default()
}

impl Preparation for Analysis {
    const WHAT: &'static str = "analysis";
    const EXTENSION: &'static str = "tex";
    const SETTINGS: &'static [PreparationSetting] = &[INDEX];

    fn id(input: &Input) -> String {
        Analysis::id_for(input.exemplar, search(input))
    }

    fn compute(input: &Input, progress: &dyn Progress, cancel: &Cancel) -> Result<Analysis> {
        Analysis::try_build_with(input.exemplar, search(input), progress, cancel)
    }

    fn to_bytes(&self) -> Vec<u8> {
        Analysis::to_bytes(self)
    }

    fn from_bytes(bytes: &[u8]) -> std::result::Result<Analysis, AnalysisFileProblem> {
        super::file::parse(bytes)
    }

    fn stored_id(&self) -> &str {
        &self.header.id
    }

    fn describe(&self) -> Map<String, Value> {
        let h = &self.header;
        let mut m = Map::new();
        m.insert("id".into(), json!(h.id));
        m.insert("algorithm_version".into(), json!(h.algorithm_version));
        m.insert("width".into(), json!(h.width));
        m.insert("height".into(), json!(h.height));
        m.insert("levels".into(), json!(h.levels));
        m.insert("toroidal".into(), json!(h.toroidal));
        m.insert("search".into(), json!(h.index.name()));
        m
    }

    fn summary(&self) -> String {
        self.header.id.clone()
    }

    fn memory_bytes(&self) -> u64 {
        let stack: usize = self.stack.iter().map(|l| l.len() * 6).sum::<usize>()
            + self.stack8.iter().map(|l| l.len() * 3).sum::<usize>();
        let corrected: usize = self
            .corrected
            .iter()
            .map(|l| l.proj.len() * 2 + l.cands.len() * std::mem::size_of::<[super::Candidate; 2]>())
            .sum();
        (self.exemplar.len() * 3 + stack + corrected) as u64
    }
}
