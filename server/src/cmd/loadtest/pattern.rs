//! The request paths of `textile loadtest`'s patterns: `pan` (a 1920×1080 viewport dragged
//! across the plane), `zoom` (in and out around a drifting centre), `random` (uniform tiles and
//! zooms), `hot` (one tile) and `replay` (the paths of a file, cycled).

use std::path::Path;
use std::sync::Arc;

/// An endless (or, for `replay`, cycled) sequence of request paths.
pub type Paths = Box<dyn Iterator<Item = String> + Send>;

/// Tiles of a `w × h` viewport whose top-left is texel-at-zoom `(x, y)`.
fn viewport(x: i64, y: i64, w: i64, h: i64) -> impl Iterator<Item = (i64, i64)> {
    let (tx0, ty0) = (x.div_euclid(256), y.div_euclid(256));
    let (tx1, ty1) = ((x + w - 1).div_euclid(256), (y + h - 1).div_euclid(256));
    (ty0..=ty1).flat_map(move |ty| (tx0..=tx1).map(move |tx| (tx, ty)))
}

/// SplitMix64, for reproducible random patterns.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        textile_core::hash::mix(self.0)
    }
    fn range(&mut self, lo: i64, hi: i64) -> i64 {
        lo + (self.next() % (hi - lo + 1) as u64) as i64
    }
}

/// The request paths of a pattern (endless except `replay`, which cycles its lines, or plays
/// them once when `once`).
pub fn pattern(
    name: &str,
    id: &str,
    native: u32,
    minzoom: u32,
    query: &str,
    (lines, once): (Vec<String>, bool),
    seed: u64,
) -> Paths {
    let q = if query.is_empty() { String::new() } else { format!("?{query}") };
    let id = id.to_string();
    let tile = move |z: u32, x: i64, y: i64| format!("/tiles/{id}/{z}/{x}/{y}.png{q}");
    let tile = Arc::new(tile);
    match name {
        "hot" => {
            let t = tile.clone();
            Box::new(std::iter::repeat_with(move || t(native, 0, 0)))
        }
        "random" => {
            let mut rng = Rng(seed);
            let t = tile.clone();
            Box::new(std::iter::repeat_with(move || {
                let z = rng.range(minzoom as i64, native as i64) as u32;
                t(z, rng.range(-(1 << 20), 1 << 20), rng.range(-(1 << 20), 1 << 20))
            }))
        }
        "zoom" => {
            // Zoom out from native to minzoom and back in, centred on a point that drifts by
            // three screens per cycle; every step requests the visible tiles.
            let t = tile.clone();
            let zooms: Vec<u32> = (minzoom..=native).rev().chain(minzoom + 1..native).collect();
            Box::new((0i64..).flat_map(move |cycle| {
                let t = t.clone();
                let (cx, cy) = (cycle * 3 * 1920, cycle * 1080);
                zooms.clone().into_iter().flat_map(move |z| {
                    let t = t.clone();
                    let k = native - z;
                    let (x, y) = ((cx >> k) - 960, (cy >> k) - 540);
                    viewport(x, y, 1920, 1080).map(move |(tx, ty)| t(z, tx, ty))
                })
            }))
        }
        "replay" if once => Box::new(lines.into_iter()),
        "replay" => Box::new(lines.into_iter().cycle()),
        _ => {
            // pan: drag a 1920×1080 viewport right and slightly down, 64 px per frame; request
            // each tile the first time it becomes visible (a browser caches the rest).
            let t = tile.clone();
            let mut seen = std::collections::HashSet::new();
            Box::new((0i64..).flat_map(move |f| {
                let (x, y) = (64 * f - 960, 16 * f - 540);
                viewport(x, y, 1920, 1080)
                    .filter(|c| seen.insert(*c))
                    .map(|(tx, ty)| t(native, tx, ty))
                    .collect::<Vec<_>>()
            }))
        }
    }
}

/// The path (and query) of a URL or `/path`; `None` for anything else.
pub fn path_of(s: &str) -> Option<String> {
    match reqwest::Url::parse(s) {
        Ok(u) => Some(format!("{}{}", u.path(), u.query().map(|q| format!("?{q}")).unwrap_or_default())),
        Err(_) if s.starts_with('/') && !s.contains(char::is_whitespace) => Some(s.to_string()),
        Err(_) => None,
    }
}

/// One line of a replay file: the path (and query) to request, and when the log saw it
/// (seconds since the Unix epoch; access-log lines only).
#[derive(Debug, Clone, PartialEq)]
pub struct Entry {
    /// Path and query.
    pub path: String,
    /// The log's timestamp.
    pub at: Option<f64>,
}

/// Month numbers of access-log dates.
const MONTHS: [&str; 12] = ["Jan", "Feb", "Mar", "Apr", "May", "Jun", "Jul", "Aug", "Sep", "Oct", "Nov", "Dec"];

/// Days since 1970-01-01 of a civil date (proleptic Gregorian).
fn days_from_civil(y: i64, m: i64, d: i64) -> i64 {
    let y = if m <= 2 { y - 1 } else { y };
    let era = y.div_euclid(400);
    let yoe = y - era * 400;
    let doy = (153 * (m + if m > 2 { -3 } else { 9 }) + 2) / 5 + d - 1;
    let doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
    era * 146_097 + doe - 719_468
}

/// An access-log time, `10/Oct/2000:13:55:36 -0700`, as seconds since the epoch.
fn log_time(s: &str) -> Option<f64> {
    let (dt, tz) = s.split_once(' ')?;
    let mut p = dt.splitn(4, [':', '/']);
    let (d, mon, y) = (p.next()?.parse::<i64>().ok()?, p.next()?, p.next()?.parse::<i64>().ok()?);
    let m = MONTHS.iter().position(|x| *x == mon)? as i64 + 1;
    let mut hms = p.next()?.split(':').map(|v| v.parse::<f64>().ok());
    let (h, mi, sec) = (hms.next()??, hms.next()??, hms.next()??);
    let (sign, tz) = match tz.as_bytes().first()? {
        b'+' => (1.0, &tz[1..]),
        b'-' => (-1.0, &tz[1..]),
        _ => return None,
    };
    if tz.len() != 4 || !(1..=31).contains(&d) {
        return None;
    }
    let off = sign * (tz[..2].parse::<f64>().ok()? * 3600.0 + tz[2..].parse::<f64>().ok()? * 60.0);
    Some(days_from_civil(y, m, d) as f64 * 86_400.0 + h * 3600.0 + mi * 60.0 + sec - off)
}

/// A combined or common access-log line (nginx, Apache): `HOST - USER [TIME] "METHOD PATH
/// PROTO" STATUS SIZE …` → (method, path, status, time).
fn access_log(l: &str) -> Option<(&str, &str, u16, f64)> {
    let (_, rest) = l.split_once('[')?;
    let (time, rest) = rest.split_once(']')?;
    let rest = rest.trim_start().strip_prefix('"')?;
    let (request, rest) = rest.split_once('"')?;
    let mut r = request.split(' ');
    let (method, path) = (r.next()?, r.next()?);
    let status = rest.split_whitespace().next()?.parse().ok()?;
    Some((method, path, status, log_time(time)?))
}

/// A line of textile's own JSON access log (`access_log_format = "json"`) → (method, path,
/// status, time): `ts` is the request's arrival in Unix milliseconds.
fn json_log(l: &str) -> Result<(String, String, u16, f64), String> {
    let v: serde_json::Value = serde_json::from_str(l).map_err(|e| format!("not a JSON access-log line: {e}"))?;
    let text = |k: &str| v.get(k).and_then(|x| x.as_str()).map(str::to_owned);
    let path = text("path").ok_or("a JSON access-log line without \"path\"")?;
    let ts = v.get("ts").and_then(|x| x.as_f64()).ok_or("a JSON access-log line without \"ts\" (milliseconds)")?;
    let status = v.get("status").and_then(|x| x.as_u64()).and_then(|s| u16::try_from(s).ok()).unwrap_or(200);
    Ok((text("method").unwrap_or_else(|| "GET".into()), path, status, ts / 1000.0))
}

/// The entries of a replay file: one URL, `/path`, access-log line (nginx or Apache combined or
/// common) or line of textile's JSON access log per line; blank lines and `#` comments skipped.
/// Access-log lines other than GET or HEAD, or whose status is not in `statuses` (when given),
/// are left out. A log whose every line has a time is played in the order of those times (a
/// log is written as answers end, so its lines are not quite in arrival order).
pub fn replay_lines(f: &Path, statuses: &[u16]) -> Result<Vec<Entry>, String> {
    let text = std::fs::read_to_string(f).map_err(|e| format!("{}: {e}", f.display()))?;
    let mut v = Vec::new();
    for (n, l) in text.lines().enumerate().map(|(n, l)| (n + 1, l.trim())) {
        if l.is_empty() || l.starts_with('#') {
            continue;
        }
        let logged = if l.starts_with('{') {
            Some(json_log(l).map_err(|e| format!("{}:{n}: {e}", f.display()))?)
        } else {
            access_log(l).map(|(m, p, s, t)| (m.to_owned(), p.to_owned(), s, t))
        };
        if let Some((method, path, status, at)) = logged {
            if !path.starts_with('/') {
                return Err(format!("{}:{n}: the request path '{path}' does not start with '/'", f.display()));
            }
            if matches!(method.as_str(), "GET" | "HEAD") && (statuses.is_empty() || statuses.contains(&status)) {
                v.push(Entry { path, at: Some(at) });
            }
            continue;
        }
        let path = path_of(l).ok_or_else(|| {
            format!("{}:{n}: '{l}' is neither a URL, a /path, nor a combined or common access-log line", f.display())
        })?;
        v.push(Entry { path, at: None });
    }
    if v.is_empty() {
        return Err(format!("{}: no requests to replay", f.display()));
    }
    if v.iter().all(|e| e.at.is_some()) {
        v.sort_by(|a, b| a.at.partial_cmp(&b.at).unwrap_or(std::cmp::Ordering::Equal));
    }
    Ok(v)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn access_log_lines_are_read() {
        let l = r#"127.0.0.1 - frank [10/Oct/2000:13:55:36 -0700] "GET /tiles/a/7/0/0.png?seed=2 HTTP/1.1" 200 2326 "-" "curl/8""#;
        let (m, p, s, t) = access_log(l).unwrap();
        assert_eq!((m, p, s), ("GET", "/tiles/a/7/0/0.png?seed=2", 200));
        assert_eq!(t, 971_211_336.0, "2000-10-10 20:55:36 UTC");
        assert!(access_log("/tiles/a/7/0/0.png").is_none());
        assert_eq!(days_from_civil(1970, 1, 1), 0);
        assert_eq!(days_from_civil(2000, 3, 1), 11_017);
    }

    #[test]
    fn textile_json_log_lines_are_read_in_arrival_order() {
        let dir = std::env::temp_dir().join(format!("textile-replay-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let f = dir.join("access.log");
        std::fs::write(
            &f,
            concat!(
                r#"{"ts":1000250,"method":"GET","path":"/b?x=1","status":200}"#,
                "\n",
                r#"{"ts":1000000,"method":"GET","path":"/a","status":200}"#,
                "\n",
                r#"{"ts":1000100,"method":"POST","path":"/textures","status":201}"#,
                "\n",
                r#"{"ts":1000300,"method":"GET","path":"/c","status":404}"#,
                "\n",
            ),
        )
        .unwrap();
        let e = replay_lines(&f, &[200]).unwrap();
        let got: Vec<(&str, f64)> = e.iter().map(|e| (e.path.as_str(), e.at.unwrap())).collect();
        assert_eq!(got, [("/a", 1000.0), ("/b?x=1", 1000.25)]);
        std::fs::write(&f, "{\"ts\":1}\n").unwrap();
        assert!(replay_lines(&f, &[]).unwrap_err().contains(":1: a JSON access-log line without \"path\""));
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
