//! Verification under load: every answer checked against reference bytes, which turns any load
//! test into a determinism test of a server or a fleet of replicas behind a proxy. References are
//! the SHA-256 of each distinct path's body, fetched once before the run (one request at a time,
//! nothing else running), or read from an `--expect` file of `URL-or-path sha256` lines — the
//! format `--record` writes.

use std::collections::{BTreeMap, HashMap};
use std::path::Path;

use sha2::{Digest, Sha256};

use super::pattern::{path_of, target};

/// Reference digests by request path.
pub type References = HashMap<String, String>;

/// The SHA-256 of `bytes`, lowercase hex.
pub fn digest(bytes: &[u8]) -> String {
    Sha256::digest(bytes).iter().map(|b| format!("{b:02x}")).collect()
}

/// Read an `--expect` file: `URL-or-path sha256` per line; blank lines and `#` comments skipped.
pub fn read(f: &Path) -> Result<References, String> {
    let text = std::fs::read_to_string(f).map_err(|e| format!("{}: {e}", f.display()))?;
    let mut refs = References::new();
    for (n, l) in text.lines().enumerate().map(|(n, l)| (n + 1, l.trim())) {
        if l.is_empty() || l.starts_with('#') {
            continue;
        }
        let bad = || format!("{}:{n}: expected 'URL-or-path sha256', got '{l}'", f.display());
        let (url, hash) = l.split_once(char::is_whitespace).ok_or_else(bad)?;
        let hash = hash.trim();
        if hash.len() != 64 || !hash.bytes().all(|b| b.is_ascii_hexdigit()) {
            return Err(bad());
        }
        refs.insert(path_of(url).ok_or_else(bad)?, hash.to_ascii_lowercase());
    }
    Ok(refs)
}

/// Fetch the reference of every path of `paths` not in `refs` yet, one at a time. Only 200
/// answers can be references.
pub async fn fetch(
    client: &reqwest::Client,
    root: &reqwest::Url,
    paths: impl Iterator<Item = String>,
    refs: &mut References,
) -> Result<(), String> {
    for p in paths {
        if refs.contains_key(&p) {
            continue;
        }
        let r = client.get(target(root, &p)).send().await.map_err(|e| format!("reference of {p}: {e}"))?;
        if r.status() != 200 {
            return Err(format!("reference of {p}: HTTP {}", r.status()));
        }
        let body = r.bytes().await.map_err(|e| format!("reference of {p}: {e}"))?;
        refs.insert(p, digest(&body));
    }
    Ok(())
}

/// Write references as `--expect` reads them, sorted by path, whole or not at all.
pub fn write(f: &Path, root: &str, refs: &References) -> Result<(), String> {
    let sorted: BTreeMap<_, _> = refs.iter().collect();
    let mut text = String::from("# textile loadtest --record: URL sha256 of the body\n");
    for (p, h) in sorted {
        text += &format!("{root}{p} {h}\n");
    }
    textile_core::files::write_atomic(f, text.as_bytes()).map_err(|e| format!("{}: {e}", f.display()))
}
