//! Black-box test support: start the real `textile` binary on an ephemeral port, wait for its
//! "ready" line, talk to it over HTTP, and stop it when the test ends.
#![allow(dead_code)]

use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::mpsc;
use std::time::Duration;

/// Path of the binary under test.
pub fn binary() -> &'static str {
    env!("CARGO_BIN_EXE_textile")
}

/// A data directory shared by the tests (analyses are computed once, written atomically), one
/// per build of the binary: analyses a previous build wrote are not reused, so a local run sees
/// what a clean clone's CI sees (an analysis file whose contents changed moves ETags).
pub fn shared_data_dir() -> PathBuf {
    let built = std::fs::metadata(binary())
        .and_then(|m| m.modified())
        .ok()
        .and_then(|t| t.duration_since(std::time::UNIX_EPOCH).ok())
        .map_or(0, |d| d.as_secs());
    PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(format!("textile-test-data-{built}"))
}

/// A data directory of one server's own (a server owns its data directory: a second one on it
/// is refused), seeded with hard links to the analyses and preparations the tests have stored
/// in [`shared_data_dir`]; [`Server`]'s drop links what it computed back there, so analyses are
/// still computed once.
fn private_data_dir() -> PathBuf {
    static MADE: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let n = MADE.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let store = shared_data_dir();
    let own =
        PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("textile-servers").join(format!("{}-{n}", std::process::id()));
    let _ = std::fs::remove_dir_all(&own);
    std::fs::create_dir_all(&own).expect("private data dir");
    std::fs::create_dir_all(&store).expect("shared data dir");
    for (name, path) in stored_files(&store) {
        let _ = std::fs::hard_link(&path, own.join(name));
    }
    own
}

/// The analyses and preparations a data directory holds: its regular files but temporary ones,
/// the lock and the uploads.
fn stored_files(dir: &Path) -> Vec<(std::ffi::OsString, PathBuf)> {
    let Ok(entries) = std::fs::read_dir(dir) else { return Vec::new() };
    entries
        .flatten()
        .filter(|e| e.file_type().is_ok_and(|t| t.is_file()))
        .map(|e| (e.file_name(), e.path()))
        .filter(|(name, _)| {
            let name = name.to_string_lossy();
            !name.starts_with('.') && name != "textile.lock"
        })
        .collect()
}

/// Link into the shared store what a private data directory computed that the store lacks
/// (atomically: a link under a temporary name, renamed), then remove the private directory.
fn give_back(own: &Path) {
    let store = shared_data_dir();
    for (name, path) in stored_files(own) {
        let target = store.join(&name);
        if !target.exists() {
            let tmp = store.join(format!(".{}.give-{}", name.to_string_lossy(), std::process::id()));
            if std::fs::hard_link(&path, &tmp).is_ok() && std::fs::rename(&tmp, &target).is_err() {
                let _ = std::fs::remove_file(&tmp);
            }
        }
    }
    let _ = std::fs::remove_dir_all(own);
}

/// Write `textile.toml` in `dir` serving the embedded gravel exemplar once per `(id, extra TOML
/// lines)` entry; returns its path.
pub fn gravel_textures_config(dir: &Path, textures: &[(&str, &str)]) -> PathBuf {
    let text: String = textures
        .iter()
        .map(|(id, extra)| {
            format!("[[textures]]\nid = \"{id}\"\nname = \"{id}\"\nexemplar = \"embedded:gravel.png\"\n{extra}\n\n")
        })
        .collect();
    let path = dir.join("textile.toml");
    std::fs::write(&path, text).expect("write config");
    path
}

/// Start the binary with these arguments and environment, its stderr (its log) in a file of its
/// own; returns the child and the log's path.
fn launch(args: &[std::ffi::OsString], env: &[(&str, &str)], stdout: Stdio) -> (Child, PathBuf) {
    let log_dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("server-logs");
    std::fs::create_dir_all(&log_dir).expect("log dir");
    static STARTED: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let n = STARTED.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let log = log_dir.join(format!("{}-{n}.log", std::process::id()));
    let stderr = std::fs::File::create(&log).expect("log file");
    let mut cmd = Command::new(binary());
    cmd.args(args).envs(env.iter().copied()).stdout(stdout).stderr(stderr).stdin(Stdio::null());
    (cmd.spawn().expect("start textile"), log)
}

/// A running server process.
pub struct Server {
    child: Child,
    /// Its data directory, when it is a private one seeded from the shared store.
    private: Option<PathBuf>,
    /// `http://127.0.0.1:PORT`.
    pub base: String,
    /// A client with its own connection pool.
    pub client: reqwest::Client,
    /// Where the server's stderr (its log) goes; shown if the server died during the test.
    log: PathBuf,
}

/// How to start a server: `Server::builder().args(&[…]).queueing().start()`.
#[derive(Default)]
pub struct Builder {
    args: Vec<std::ffi::OsString>,
    env: Vec<(String, String)>,
    data_dir: Option<PathBuf>,
    bare: bool,
}

impl Builder {
    /// Extra command-line arguments of `serve`.
    pub fn args(mut self, args: &[&str]) -> Self {
        self.args.extend(args.iter().map(|a| a.into()));
        self
    }

    /// An environment variable.
    pub fn env(mut self, key: &str, value: &str) -> Self {
        self.env.push((key.into(), value.into()));
        self
    }

    /// Another data directory than the tests' shared one.
    pub fn data_dir(mut self, dir: &Path) -> Self {
        self.data_dir = Some(dir.to_path_buf());
        self
    }

    /// Lift the queue-wait bound: for tests that send many cold tiles at once and need every one
    /// answered 200 even on a slow machine (shedding has tests of its own).
    pub fn queueing(self) -> Self {
        self.env("TEXTILE_MAX_QUEUE_WAIT_MS", "600000")
    }

    /// Run the bare binary with only the given arguments and environment (no `serve --bind
    /// --data-dir`): the environment must make it bind a free port.
    pub fn bare(mut self) -> Self {
        self.bare = true;
        self
    }

    /// Start it on a free port and return as soon as it answers `/health`, before its textures
    /// are analysed (the "ready" line comes only after every analysis).
    pub async fn start_loading(self) -> Server {
        let port = std::net::TcpListener::bind("127.0.0.1:0").expect("free port").local_addr().expect("addr").port();
        let private = self.data_dir.is_none().then(private_data_dir);
        let dir = self.data_dir.or_else(|| private.clone()).expect("a data directory");
        let mut args: Vec<std::ffi::OsString> =
            vec!["serve".into(), "--bind".into(), format!("127.0.0.1:{port}").into()];
        args.extend(["--data-dir".into(), dir.into_os_string()]);
        args.extend(self.args);
        let env: Vec<(&str, &str)> = self.env.iter().map(|(k, v)| (k.as_str(), v.as_str())).collect();
        let (child, log) = launch(&args, &env, Stdio::null());
        let base = format!("http://127.0.0.1:{port}");
        let server = Server { child, private, base, client: reqwest::Client::new(), log };
        for _ in 0..600 {
            if server.client.get(server.url("/health")).send().await.is_ok_and(|r| r.status() == 200) {
                return server;
            }
            tokio::time::sleep(Duration::from_millis(50)).await;
        }
        panic!("textile did not answer /health within 30 s");
    }

    /// Start it and wait until it is ready.
    pub fn start(self) -> Server {
        let mut args: Vec<std::ffi::OsString> = Vec::new();
        let private = (!self.bare && self.data_dir.is_none()).then(private_data_dir);
        if !self.bare {
            let dir = self.data_dir.or_else(|| private.clone()).expect("a data directory");
            args.extend(["serve".into(), "--bind".into(), "127.0.0.1:0".into(), "--data-dir".into()]);
            args.push(dir.into_os_string());
        }
        args.extend(self.args);
        let env: Vec<(&str, &str)> = self.env.iter().map(|(k, v)| (k.as_str(), v.as_str())).collect();
        Server::spawn(&args, &env, private)
    }
}

impl Server {
    /// A builder of a server (shared data dir, `serve` on a free port).
    pub fn builder() -> Builder {
        Builder::default()
    }

    fn spawn(args: &[std::ffi::OsString], env: &[(&str, &str)], private: Option<PathBuf>) -> Server {
        let (mut child, log) = launch(args, env, Stdio::piped());
        let stdout = child.stdout.take().expect("stdout");
        let (tx, rx) = mpsc::channel();
        std::thread::spawn(move || {
            for line in BufReader::new(stdout).lines().map_while(Result::ok) {
                let _ = tx.send(line);
            }
        });
        let deadline = std::time::Instant::now() + Duration::from_secs(180);
        loop {
            let left = deadline.saturating_duration_since(std::time::Instant::now());
            match rx.recv_timeout(left) {
                Ok(line) => {
                    if let Some(rest) = line.strip_prefix("textile ready: viewer at ") {
                        let url = rest.split_whitespace().next().unwrap_or_default().trim_end_matches('/');
                        let base = url.to_string();
                        return Server { child, private, base, client: reqwest::Client::new(), log };
                    }
                }
                Err(_) => {
                    let _ = child.kill();
                    let _ = child.wait();
                    if let Some(own) = &private {
                        give_back(own);
                    }
                    let log = std::fs::read_to_string(&log).unwrap_or_default();
                    panic!("textile did not report ready within 180 s (or exited); its log:\n{log}");
                }
            }
        }
    }

    /// Absolute URL of a path.
    pub fn url(&self, path: &str) -> String {
        format!("{}{}", self.base, path)
    }

    /// GET a path.
    pub async fn get(&self, path: &str) -> reqwest::Response {
        self.client.get(self.url(path)).send().await.expect("request")
    }

    /// GET a path and return status and body bytes.
    pub async fn get_bytes(&self, path: &str) -> (u16, Vec<u8>) {
        let r = self.get(path).await;
        let s = r.status().as_u16();
        (s, r.bytes().await.expect("body").to_vec())
    }

    /// POST a body of a content type to a path; status, headers and body bytes.
    pub async fn post(
        &self,
        path: &str,
        content_type: &str,
        body: Vec<u8>,
    ) -> (u16, reqwest::header::HeaderMap, Vec<u8>) {
        let r = self.client.post(self.url(path)).header("content-type", content_type).body(body).send().await;
        let r = r.expect("request");
        let (s, h) = (r.status().as_u16(), r.headers().clone());
        (s, h, r.bytes().await.expect("body").to_vec())
    }

    /// GET a path expecting 200 JSON.
    pub async fn json(&self, path: &str) -> serde_json::Value {
        let r = self.get(path).await;
        assert_eq!(r.status(), 200, "GET {path}");
        r.json().await.expect("json")
    }

    /// GET a path expecting a 200 image, decoded to RGB8.
    pub async fn image(&self, path: &str) -> image::RgbImage {
        let (s, b) = self.get_bytes(path).await;
        assert_eq!(s, 200, "GET {path}: {}", String::from_utf8_lossy(&b[..b.len().min(300)]));
        image::load_from_memory(&b).expect("decode").to_rgb8()
    }

    /// The server's process id.
    pub fn pid(&self) -> u32 {
        self.child.id()
    }

    /// What the server logged so far.
    pub fn log_text(&self) -> String {
        std::fs::read_to_string(&self.log).unwrap_or_default()
    }

    /// Send SIGTERM and wait for exit; returns the exit code.
    pub fn terminate(mut self) -> Option<i32> {
        let _ = Command::new("kill").arg("-TERM").arg(self.child.id().to_string()).status();
        let code = self.child.wait().ok().and_then(|s| s.code());
        let _ = std::fs::remove_file(&self.log);
        if let Some(own) = self.private.take() {
            give_back(&own);
        }
        std::mem::forget(self);
        code
    }
}

impl Drop for Server {
    fn drop(&mut self) {
        // A server that exited before the test stopped it crashed: say how, with its last words.
        if let Ok(Some(status)) = self.child.try_wait() {
            let log = std::fs::read_to_string(&self.log).unwrap_or_default();
            let tail: Vec<&str> = log.lines().rev().take(40).collect();
            let tail: Vec<&str> = tail.into_iter().rev().collect();
            eprintln!("textile at {} exited early ({status}); its last log lines:\n{}", self.base, tail.join("\n"));
        }
        let _ = std::fs::remove_file(&self.log);
        let _ = self.child.kill();
        let _ = self.child.wait();
        if let Some(own) = self.private.take() {
            give_back(&own);
        }
    }
}

/// Assert an error answer: status, JSON body with `error` = code, a non-empty message.
pub async fn assert_error(s: &Server, path: &str, status: u16, code: &str) {
    let r = s.get(path).await;
    assert_eq!(r.status().as_u16(), status, "GET {path}");
    let ct = r.headers().get("content-type").map(|v| v.to_str().unwrap_or("").to_string()).unwrap_or_default();
    assert!(ct.starts_with("application/json"), "GET {path}: content-type {ct}");
    let body: serde_json::Value = r.json().await.expect("json error body");
    assert_eq!(body["error"], code, "GET {path}: {body}");
    assert!(body["message"].as_str().is_some_and(|m| !m.is_empty()), "GET {path}: {body}");
}

/// Copy `src` (w×h) into `dst` at (x, y).
pub fn paste(dst: &mut image::RgbImage, src: &image::RgbImage, x: u32, y: u32) {
    image::imageops::replace(dst, src, x as i64, y as i64);
}

/// Make the npm packages of a test folder ready: `npm ci` (pinned by its lockfile) when
/// `node_modules/<package>` is missing. `Err` says why it cannot be (no node or npm, no
/// registry), for [`skip`].
pub fn npm_ready(dir: &Path, package: &str) -> Result<(), String> {
    let works = |cmd: &str| Command::new(cmd).arg("--version").output().is_ok_and(|o| o.status.success());
    if !works("node") {
        return Err("node is not installed (Debian: apt-get install nodejs npm)".into());
    }
    if dir.join("node_modules").join(package).exists() {
        return Ok(());
    }
    if !works("npm") {
        return Err(format!("npm is not installed, and {} has no node_modules", dir.display()));
    }
    let out = Command::new("npm")
        .args(["ci", "--no-audit", "--no-fund", "--loglevel=error"])
        .current_dir(dir)
        .output()
        .map_err(|e| format!("npm ci: {e}"))?;
    if !out.status.success() || !dir.join("node_modules").join(package).exists() {
        return Err(format!("`npm ci` in {} failed: {}", dir.display(), String::from_utf8_lossy(&out.stderr).trim()));
    }
    Ok(())
}

/// A suite that cannot run here: under `CI` that is a failure; elsewhere the notice goes to the
/// terminal itself (cargo's output capture swallows `eprintln!` of passing tests), so the
/// README's test command shows what it skipped and why.
pub fn skip(test: &str, why: &str) {
    assert!(std::env::var_os("CI").is_none(), "{test} cannot run under CI: {why}");
    use std::io::Write;
    let _ = writeln!(std::io::stderr(), "\n    SKIPPED {test}: {why}\n");
}

pub fn u32le(b: &[u8], at: usize) -> u32 {
    u32::from_le_bytes([b[at], b[at + 1], b[at + 2], b[at + 3]])
}

/// Check a GLB's container and return (JSON, BIN chunk).
pub fn parse_glb(b: &[u8]) -> (serde_json::Value, Vec<u8>) {
    assert_eq!(&b[0..4], b"glTF");
    assert_eq!(u32le(b, 4), 2);
    assert_eq!(u32le(b, 8) as usize, b.len());
    let jlen = u32le(b, 12) as usize;
    assert_eq!(u32le(b, 16), 0x4E4F_534A);
    assert_eq!(jlen % 4, 0);
    let json: serde_json::Value = serde_json::from_slice(&b[20..20 + jlen]).expect("JSON chunk");
    let at = 20 + jlen;
    let blen = u32le(b, at) as usize;
    assert_eq!(u32le(b, at + 4), 0x004E_4942);
    assert_eq!(blen % 4, 0);
    assert_eq!(at + 8 + blen, b.len());
    let bin = b[at + 8..].to_vec();
    assert_eq!(json["buffers"][0]["byteLength"].as_u64().unwrap() as usize, blen);
    for v in json["bufferViews"].as_array().unwrap() {
        let (o, l) = (v["byteOffset"].as_u64().unwrap() as usize, v["byteLength"].as_u64().unwrap() as usize);
        assert!(o % 4 == 0 && o + l <= blen);
    }
    (json, bin)
}

/// The bytes of image `i` embedded in a GLB.
pub fn glb_image(json: &serde_json::Value, bin: &[u8], i: usize) -> Vec<u8> {
    let view = &json["bufferViews"][json["images"][i]["bufferView"].as_u64().unwrap() as usize];
    let (o, l) = (view["byteOffset"].as_u64().unwrap() as usize, view["byteLength"].as_u64().unwrap() as usize);
    bin[o..o + l].to_vec()
}

/// The floats of accessor `accessor` of a GLB.
pub fn f32s(json: &serde_json::Value, bin: &[u8], accessor: usize) -> Vec<f32> {
    let a = &json["accessors"][accessor];
    let view = &json["bufferViews"][a["bufferView"].as_u64().unwrap() as usize];
    let (o, l) = (view["byteOffset"].as_u64().unwrap() as usize, view["byteLength"].as_u64().unwrap() as usize);
    bin[o..o + l].chunks(4).map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]])).collect()
}

/// Write `rough.toml` in `dir`: a texture `rough` whose roughness and metallic maps are the
/// forest floor's height and specular maps (stand-ins: no embedded material has them).
pub fn rough_metal_config(dir: &Path) -> PathBuf {
    let m = |f: &str| format!("embedded:materials/forest_floor/{f}.png");
    let text = format!(
        "[[textures]]\nid = \"rough\"\nexemplar = \"{}\"\n[textures.maps]\nroughness = \"{}\"\nmetallic = \"{}\"\n",
        m("albedo"),
        m("height"),
        m("specular")
    );
    let cfg = dir.join("rough.toml");
    std::fs::write(&cfg, text).expect("write rough.toml");
    cfg
}

/// Whether the independent archive readers are here: Python with the `pmtiles` package
/// (installed by `.ci/run` from `tests/export/requirements.txt`).
pub fn reader_available() -> bool {
    Command::new("python3").args(["-c", "import pmtiles.reader"]).output().is_ok_and(|o| o.status.success())
}

/// The independent readers (PyPI pmtiles, Python's sqlite3: `tests/export/check_archive.py`)
/// read an archive back: its header against its tiles, and every tile of its lowest zoom plus
/// `samples` tiles at random (all of them when `samples` is at least its count) equal to the
/// running server's answer for its URL.
pub fn check_archive(archive: &Path, s: &Server, samples: usize) {
    let script = format!("{}/../tests/export/check_archive.py", env!("CARGO_MANIFEST_DIR"));
    let out = Command::new("python3")
        .args([&script, archive.to_str().unwrap(), &s.base, &samples.to_string()])
        .output()
        .expect("python3");
    let report = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{}: {report}{}", archive.display(), String::from_utf8_lossy(&out.stderr));
    assert!(report.contains("\"problems\": []"), "{report}");
}
