//! The admin API against the real binary: uploads need the bearer token (and leave nothing
//! behind without it, or when corrupt, oversized or a decompression bomb), a good upload is
//! analysed in the background and then serves the same bytes as `textile render --exemplar` of
//! the same file, per-texture settings travel with it, concurrent uploads of one id have one
//! winner, deletion removes configured-or-not correctly, and uploads survive a restart.

mod common;

use std::path::Path;
use std::time::Duration;

use common::Server;

const TOKEN: &str = "test-admin-token-0123456789";

fn exemplar_path(name: &str) -> String {
    format!("{}/../config/exemplars/{name}", env!("CARGO_MANIFEST_DIR"))
}

fn brick() -> Vec<u8> {
    std::fs::read(exemplar_path("brick.png")).expect("brick.png")
}

fn admin_server(data: &Path, extra_env: &[(&str, &str)]) -> Server {
    let mut b = Server::builder().data_dir(data).env("TEXTILE_ADMIN_TOKEN", TOKEN);
    for (k, v) in extra_env {
        b = b.env(k, v);
    }
    b.start()
}

/// POST an upload: status, headers and JSON body.
async fn upload(
    s: &Server,
    query: &str,
    content_type: &str,
    body: Vec<u8>,
    token: Option<&str>,
) -> (u16, reqwest::header::HeaderMap, serde_json::Value) {
    let mut r = s.client.post(s.url(&format!("/admin/textures{query}"))).header("content-type", content_type);
    if let Some(t) = token {
        r = r.bearer_auth(t);
    }
    let r = r.body(body).send().await.expect("upload");
    let (status, headers) = (r.status().as_u16(), r.headers().clone());
    let body = r.json().await.unwrap_or(serde_json::Value::Null);
    (status, headers, body)
}

async fn delete(s: &Server, id: &str, token: Option<&str>) -> (u16, serde_json::Value) {
    let mut r = s.client.delete(s.url(&format!("/admin/textures/{id}")));
    if let Some(t) = token {
        r = r.bearer_auth(t);
    }
    let r = r.send().await.expect("delete");
    let status = r.status().as_u16();
    (status, r.json().await.unwrap_or(serde_json::Value::Null))
}

/// Poll a texture's status document until it is ready (or fail after a minute).
async fn until_ready(s: &Server, location: &str) -> serde_json::Value {
    let mut seen = Vec::new();
    for _ in 0..600 {
        let m = s.json(location).await;
        let p = m["progress"].as_u64().expect("progress");
        assert!(p <= 100, "{m}");
        seen.push(p);
        match m["status"].as_str() {
            Some("ready") => {
                assert_eq!(p, 100, "{m}");
                assert!(seen.windows(2).all(|w| w[0] <= w[1]), "progress never goes back: {seen:?}");
                return m;
            }
            Some("analysing") => tokio::time::sleep(Duration::from_millis(100)).await,
            other => panic!("unexpected status {other:?}: {m}"),
        }
    }
    panic!("{location} was not ready within a minute");
}

fn files_in(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .map(|d| d.flatten().map(|e| e.file_name().to_string_lossy().into_owned()).collect())
        .unwrap_or_default();
    v.sort();
    v
}

async fn catalog_ids(s: &Server) -> Vec<String> {
    let c = s.json("/catalog").await;
    c["textures"].as_array().unwrap().iter().map(|t| t["id"].as_str().unwrap().to_string()).collect()
}

/// A PNG whose header claims `w`×`h` with almost no data: a decompression bomb.
fn png_claiming(w: u32, h: u32) -> Vec<u8> {
    let mut buf = std::io::Cursor::new(Vec::new());
    image::RgbImage::new(1, 1).write_to(&mut buf, image::ImageFormat::Png).unwrap();
    let mut png = buf.into_inner();
    // IHDR data sits at bytes 16..29, its CRC (over type and data) at 29..33.
    png[16..20].copy_from_slice(&w.to_be_bytes());
    png[20..24].copy_from_slice(&h.to_be_bytes());
    let crc = crc32(&png[12..29]);
    png[29..33].copy_from_slice(&crc.to_be_bytes());
    png
}

fn crc32(bytes: &[u8]) -> u32 {
    let mut c = !0u32;
    for &b in bytes {
        c ^= b as u32;
        for _ in 0..8 {
            c = if c & 1 != 0 { 0xEDB8_8320 ^ (c >> 1) } else { c >> 1 };
        }
    }
    !c
}

#[tokio::test]
async fn admin_routes_do_not_exist_without_a_token() {
    let s = Server::builder().start();
    let (status, _, body) = upload(&s, "?id=x", "image/png", brick(), Some("anything-at-all-long")).await;
    assert_eq!((status, body["error"].as_str()), (404, Some("not_found")), "{body}");
    let (status, body) = delete(&s, "gravel", Some("anything-at-all-long")).await;
    assert_eq!(status, 404, "{body}");
    assert_eq!(s.json("/catalog").await["uploads"], false);
}

#[tokio::test]
async fn refused_uploads_leave_nothing_behind() {
    let data = tempfile::tempdir().unwrap();
    let uploads = data.path().join("uploads");
    let s = admin_server(data.path(), &[("TEXTILE_MAX_UPLOAD_MIB", "1")]);
    assert_eq!(s.json("/catalog").await["uploads"], true);
    let before = catalog_ids(&s).await;
    let (status, headers, body) = upload(&s, "?id=nope", "image/png", brick(), None).await;
    assert_eq!((status, body["error"].as_str()), (401, Some("unauthorized")), "{body}");
    assert!(headers.get("www-authenticate").is_some_and(|v| v.to_str().unwrap().starts_with("Bearer")));
    let (status, _, body) = upload(&s, "?id=nope", "image/png", brick(), Some("test-admin-token-0123456788")).await;
    assert_eq!(status, 401, "{body}");
    let (status, body) = delete(&s, "gravel", None).await;
    assert_eq!(status, 401, "{body}");
    let mut truncated = brick();
    truncated.truncate(truncated.len() / 3);
    let mut jpeg = std::io::Cursor::new(Vec::new());
    image::RgbImage::new(64, 64).write_to(&mut jpeg, image::ImageFormat::Jpeg).unwrap();
    let mut truncated_jpeg = jpeg.into_inner();
    truncated_jpeg.truncate(200);
    let cases: Vec<(&str, &str, Vec<u8>, u16, &str)> = vec![
        ("?id=nope", "image/png", b"not an image at all".to_vec(), 400, "invalid_image"),
        ("?id=nope", "image/png", truncated, 400, "invalid_image"),
        ("?id=nope", "image/jpeg", truncated_jpeg, 400, "invalid_image"),
        ("?id=nope", "image/png", png_claiming(200_000, 200_000), 413, "image_too_large"),
        ("?id=Bad%20Id", "image/png", brick(), 400, "invalid_upload"),
        ("?id=nope&toroidal=sometimes", "image/png", brick(), 400, "invalid_upload"),
        ("?id=nope&synth.kappa=9", "image/png", brick(), 400, "invalid_upload"),
        ("?id=nope&lattice=sometimes", "image/png", brick(), 400, "invalid_upload"),
        ("?id=nope&lattice=20@0,20@5", "image/png", brick(), 400, "invalid_upload"),
        ("?id=nope&lattice=%5B%5B0,0%5D%5D", "image/png", brick(), 400, "invalid_upload"),
        ("?id=nope&lattice=%5B%5B10,10%5D,%5B20,21%5D%5D", "image/png", brick(), 400, "invalid_upload"),
        ("?id=nope&lattice=%5B%5B0,500%5D%5D", "image/png", brick(), 400, "invalid_upload"),
        ("?id=nope&colour=red", "image/png", brick(), 400, "invalid_upload"),
        ("?name=no-id", "image/png", brick(), 400, "invalid_upload"),
        ("?id=nope", "text/plain", brick(), 415, "unsupported_media_type"),
        ("?id=gravel", "image/png", brick(), 409, "texture_exists"),
    ];
    for (query, ct, body, want, code) in cases {
        let (status, _, got) = upload(&s, query, ct, body, Some(TOKEN)).await;
        assert_eq!((status, got["error"].as_str()), (want, Some(code)), "{query} {ct}: {got}");
        assert!(got["message"].as_str().is_some_and(|m| !m.is_empty() && m.len() < 1100), "{got}");
    }
    // Over the body limit: refused from the declared length, before the body is sent.
    let (status, answer) = declared_upload(&s, (1 << 20) + 1).await;
    assert_eq!(status, 413, "{answer}");
    assert!(answer.contains("\"body_too_large\""), "{answer}");
    assert!(files_in(&uploads).is_empty(), "left behind: {:?}", files_in(&uploads));
    assert_eq!(catalog_ids(&s).await, before);
    common::assert_error(&s, "/textures/nope", 404, "unknown_texture").await;
    let (status, body) = delete(&s, "gravel", Some(TOKEN)).await;
    assert_eq!((status, body["error"].as_str()), (409, Some("configured_texture")), "{body}");
    let (status, body) = delete(&s, "nosuch", Some(TOKEN)).await;
    assert_eq!((status, body["error"].as_str()), (404, Some("unknown_texture")), "{body}");
    let r = s.client.delete(s.url("/textures/gravel")).send().await.unwrap();
    assert_eq!(r.status(), 401, "DELETE /textures/{{id}} is the same route");
    let (status, _) = s.get_bytes("/tiles/gravel/7/0/0.png").await;
    assert_eq!(status, 200, "still serving");
}

#[tokio::test]
async fn uploads_are_served_like_rendered_exemplars_and_survive_restarts() {
    let data = tempfile::tempdir().unwrap();
    let uploads = data.path().join("uploads");
    let s = admin_server(data.path(), &[]);

    // A raw PNG body, fields in the query.
    let (status, headers, body) = upload(&s, "?id=mine&name=My%20brick", "image/png", brick(), Some(TOKEN)).await;
    assert_eq!(status, 202, "{body}");
    let location = headers.get("location").expect("Location").to_str().unwrap().to_string();
    assert_eq!(location, "/textures/mine");
    assert_eq!(body["status"], "analysing");
    // Modes that need only the exemplar serve at once.
    let (status, _) = s.get_bytes("/tiles/mine/7/0/0.png?mode=mosaic").await;
    assert_eq!(status, 200);
    let meta = until_ready(&s, &location).await;
    assert_eq!((meta["name"].as_str(), meta["uploaded"].as_bool()), (Some("My brick"), Some(true)));
    assert_eq!(meta["exemplar"]["lattice"]["kind"], "stripes", "uploads detect the lattice: {}", meta["exemplar"]);
    assert_eq!(meta["structure"]["class"], "lattice", "and report their structure: {}", meta["structure"]);
    assert_eq!(meta["structure"]["dimensions"], 1, "{}", meta["structure"]);
    let (status, tile) = s.get_bytes("/tiles/mine/7/1/2.png?seed=3").await;
    assert_eq!(status, 200);
    let out = tempfile::tempdir().unwrap();
    let rendered = out.path().join("tile.png");
    let done = std::process::Command::new(common::binary())
        .args(["render", "--exemplar", &exemplar_path("brick.png"), "--x", "1", "--y", "2", "--seed", "3", "-o"])
        .arg(&rendered)
        .output()
        .expect("render");
    assert!(done.status.success(), "{}", String::from_utf8_lossy(&done.stderr));
    assert_eq!(std::fs::read(&rendered).unwrap(), tile, "the uploaded texture's tile equals textile render's");

    // A multipart form with a per-mode setting: brick with κ = 0.5 is the configured brick.
    // (Sent to `POST /textures`, the contract's name for the same route.)
    let form = reqwest::multipart::Form::new()
        .text("id", "brick2")
        .text("synth.kappa", "0.5")
        .part("image", reqwest::multipart::Part::bytes(brick()).file_name("brick.png").mime_str("image/png").unwrap());
    let r = s.client.post(s.url("/textures")).bearer_auth(TOKEN).multipart(form).send().await.unwrap();
    assert_eq!(r.status(), 202);
    until_ready(&s, "/textures/brick2").await;
    let (_, a) = s.get_bytes("/tiles/brick2/7/-1/3.png?seed=5").await;
    let (_, b) = s.get_bytes("/tiles/brick/7/-1/3.png?seed=5").await;
    assert_eq!(a, b, "settings travel with the upload");

    // toroidal=synthesize: the exemplar is replaced by a seamless one synthesized from it, which
    // wraps (and so differs from the plain upload's).
    let (status, _, body) =
        upload(&s, "?id=seamless&toroidal=synthesize&index=coherent", "image/png", brick(), Some(TOKEN)).await;
    assert_eq!(status, 202, "{body}");
    let meta = until_ready(&s, "/textures/seamless").await;
    assert_eq!(meta["analysis"]["index"], "coherent", "the upload's candidate search: {meta}");
    assert_eq!(meta["exemplar"]["toroidal"], true, "{meta}");
    assert_eq!(meta["exemplar"]["toroidal_synthesized"], true, "{meta}");
    let (_, own) = s.get_bytes("/textures/seamless/exemplar.png").await;
    let (_, plain) = s.get_bytes("/textures/mine/exemplar.png").await;
    assert_ne!(own, plain);
    let (status, _) = s.get_bytes("/tiles/seamless/7/1/2.png?seed=3").await;
    assert_eq!(status, 200);
    let (status, _) = delete(&s, "seamless", Some(TOKEN)).await;
    assert_eq!(status, 204);

    // Concurrent uploads of one id: one wins, the others are told it exists; nothing is torn.
    let mut tries = tokio::task::JoinSet::new();
    for _ in 0..4 {
        let (client, url) = (s.client.clone(), s.url("/admin/textures?id=race"));
        tries.spawn(async move {
            let r = client.post(url).bearer_auth(TOKEN).header("content-type", "image/png").body(brick());
            r.send().await.expect("upload").status().as_u16()
        });
    }
    let statuses: Vec<u16> = tries.join_all().await;
    assert_eq!(statuses.iter().filter(|&&st| st == 202).count(), 1, "{statuses:?}");
    assert_eq!(statuses.iter().filter(|&&st| st == 409).count(), 3, "{statuses:?}");
    until_ready(&s, "/textures/race").await;
    assert_eq!(files_in(&uploads), ["brick2.png", "brick2.toml", "mine.png", "mine.toml", "race.png", "race.toml"]);

    // Deletion: gone from the catalogue, its files and analysis removed.
    let (status, _) = delete(&s, "brick2", Some(TOKEN)).await;
    assert_eq!(status, 204);
    common::assert_error(&s, "/textures/brick2", 404, "unknown_texture").await;
    common::assert_error(&s, "/tiles/brick2/7/0/0.png", 404, "unknown_texture").await;
    assert!(!data.path().join("brick2.tex").exists() && !data.path().join("brick2.umbrella").exists());
    assert!(data.path().join("mine.umbrella").exists(), "the kept uploads keep their extraction");
    assert_eq!(files_in(&uploads), ["mine.png", "mine.toml", "race.png", "race.toml"]);
    let ids = catalog_ids(&s).await;
    assert_eq!(ids, ["gravel", "grass", "brick", "corkboard", "flagstones", "mine", "race"]);
    drop(s);

    // A restart serves the uploads that were kept, with the same bytes.
    let s = admin_server(data.path(), &[]);
    assert_eq!(catalog_ids(&s).await, ["gravel", "grass", "brick", "corkboard", "flagstones", "mine", "race"]);
    // Uploads are loaded after readiness (issue 71): wait for this one.
    until_ready(&s, "/textures/mine").await;
    let (status, again) = s.get_bytes("/tiles/mine/7/1/2.png?seed=3").await;
    assert_eq!((status, again), (200, tile));
    assert!(s.log_text().contains("texture 'mine': loaded analysis"), "the analysis was kept, not recomputed");
}

/// An authorized upload declaring `len` bytes, asking `Expect: 100-continue` and sending no
/// body: the status and raw answer.
async fn declared_upload(s: &Server, len: usize) -> (u16, String) {
    use tokio::io::{AsyncReadExt, AsyncWriteExt};
    let addr = s.base.trim_start_matches("http://");
    let mut c = tokio::net::TcpStream::connect(addr).await.expect("connect");
    let head = format!(
        "POST /admin/textures?id=big HTTP/1.1\r\nHost: {addr}\r\nAuthorization: Bearer {TOKEN}\r\n\
         Content-Type: image/png\r\nContent-Length: {len}\r\nExpect: 100-continue\r\nConnection: close\r\n\r\n"
    );
    c.write_all(head.as_bytes()).await.expect("write");
    let mut answer = Vec::new();
    let read = tokio::time::timeout(Duration::from_secs(20), c.read_to_end(&mut answer)).await;
    assert!(read.is_ok(), "no answer before the body was sent");
    let text = String::from_utf8_lossy(&answer).to_string();
    (text.split(' ').nth(1).and_then(|s| s.parse().ok()).unwrap_or(0), text)
}

/// Brick enlarged to 256² (an analysis of some seconds), as PNG.
fn big_brick() -> Vec<u8> {
    let img = image::load_from_memory(&brick()).unwrap().to_rgb8();
    let big = image::imageops::resize(&img, 256, 256, image::imageops::FilterType::Triangle);
    let mut buf = std::io::Cursor::new(Vec::new());
    big.write_to(&mut buf, image::ImageFormat::Png).unwrap();
    buf.into_inner()
}

#[tokio::test]
async fn analyses_of_uploads_wait_their_turn_and_stop_on_shutdown() {
    let data = tempfile::tempdir().unwrap();
    let s = admin_server(data.path(), &[("TEXTILE_MAX_CONCURRENT_ANALYSES", "1")]);
    for id in ["first", "second"] {
        let (status, _, body) = upload(&s, &format!("?id={id}"), "image/png", big_brick(), Some(TOKEN)).await;
        assert_eq!(status, 202, "{body}");
    }
    // They run one at a time: when the first is done, the second has barely started (run
    // together, it would be as far along as the first, the finest level being the last quarter
    // of the work and shown from 25 %).
    let t = std::time::Instant::now();
    let second = loop {
        let (a, b) = (s.json("/textures/first").await, s.json("/textures/second").await);
        if a["status"] == "ready" {
            break b;
        }
        assert!(t.elapsed() < Duration::from_secs(180), "the first analysis never finished: {a}");
        tokio::time::sleep(Duration::from_millis(20)).await;
    };
    assert_eq!(second["status"], "analysing", "{second}");
    assert!(second["progress"].as_u64().unwrap() < 25, "the second ran beside the first: {second}");
    // SIGTERM during the second analysis: the process exits promptly and cleanly, leaving no
    // analysis file of it, whole or partial (what its modes prepared before the analysis began
    // is complete, and the next start reads it).
    let started = std::time::Instant::now();
    assert_eq!(s.terminate(), Some(0));
    assert!(started.elapsed() < Duration::from_secs(5), "shutdown waited {:?}", started.elapsed());
    let stray: Vec<String> = files_in(data.path())
        .into_iter()
        .filter(|f| f.contains("second") && (f.contains(".tex") || f.contains(".tmp")))
        .collect();
    assert!(stray.is_empty(), "{stray:?}");
    // The uploads were kept: the next start analyses them (in the background: the service is
    // ready at once), and serves them.
    // (A cold 256² tile beside the other tests' servers on two cores may wait long: queued, not
    // shed.)
    let s = admin_server(data.path(), &[("TEXTILE_MAX_QUEUE_WAIT_MS", "600000")]);
    until_ready(&s, "/textures/second").await;
    until_ready(&s, "/textures/first").await;
    let (status, body) = s.get_bytes("/tiles/first/8/0/0.png").await;
    assert_eq!(status, 200, "{}", String::from_utf8_lossy(&body));
}

#[tokio::test]
async fn a_data_directory_that_cannot_store_uploads_is_a_507_naming_no_path() {
    let data = tempfile::tempdir().unwrap();
    let s = admin_server(data.path(), &[]);
    // The uploads folder's place is taken by a file: nothing can be stored there.
    std::fs::write(data.path().join("uploads"), b"not a folder").unwrap();
    let (status, _, body) = upload(&s, "?id=nowhere", "image/png", brick(), Some(TOKEN)).await;
    assert_eq!(status, 507, "{body}");
    assert_eq!(body["error"], "storage_failed", "{body}");
    let msg = body["message"].as_str().unwrap();
    let dir = data.path().to_string_lossy().to_string();
    assert!(msg.contains("could not be stored in the data directory") && !msg.contains(&dir), "{msg}");
    assert!(!msg.contains('/'), "no path at all: {msg}");
    assert!(s.log_text().contains(&dir), "the path is in the log");
    common::assert_error(&s, "/textures/nowhere", 404, "unknown_texture").await;
}

#[tokio::test]
async fn a_restarted_server_serves_stored_uploads_and_never_overwrites_their_files() {
    let data = tempfile::tempdir().unwrap();
    let a = admin_server(data.path(), &[]);
    let (status, _, body) = upload(&a, "?id=shared", "image/png", brick(), Some(TOKEN)).await;
    assert_eq!(status, 202, "{body}");
    until_ready(&a, "/textures/shared").await;
    let (_, from_a) = a.get_bytes("/tiles/shared/7/1/1.png").await;
    // One owner per data directory: the next server starts once this one is gone.
    drop(a);
    let b = admin_server(data.path(), &[]);
    until_ready(&b, "/textures/shared").await;
    assert_eq!(b.get_bytes("/tiles/shared/7/1/1.png").await, (200, from_a));
    // Files of an id put in the directory while it runs are never overwritten by an upload.
    let uploads = data.path().join("uploads");
    std::fs::copy(uploads.join("shared.png"), uploads.join("placed.png")).unwrap();
    let (status, _, body) = upload(&b, "?id=placed", "image/png", brick(), Some(TOKEN)).await;
    assert_eq!(status, 409, "{body}");
    assert_eq!(body["error"], "texture_exists", "{body}");
    assert!(body["message"].as_str().unwrap().contains("does not serve"), "{body}");
    common::assert_error(&b, "/textures/placed", 404, "unknown_texture").await;
    assert_eq!(std::fs::read(uploads.join("placed.png")).unwrap(), std::fs::read(uploads.join("shared.png")).unwrap());
}

/// A PNG of `w × h` pixels, `colour(x, y)` each.
fn png(w: u32, h: u32, colour: impl Fn(u32, u32) -> [u8; 3]) -> Vec<u8> {
    let img = image::RgbImage::from_fn(w, h, |x, y| image::Rgb(colour(x, y)));
    let mut out = Vec::new();
    img.write_to(&mut std::io::Cursor::new(&mut out), image::ImageFormat::Png).unwrap();
    out
}

/// A JPEG of `img` carrying an EXIF orientation tag (1–8) in an APP1 segment after SOI.
fn jpeg_with_orientation(img: &image::RgbImage, orientation: u16) -> Vec<u8> {
    let mut plain = Vec::new();
    img.write_to(&mut std::io::Cursor::new(&mut plain), image::ImageFormat::Jpeg).unwrap();
    // TIFF header (big-endian), one IFD with one entry: Orientation (0x0112), SHORT, count 1.
    let mut tiff = b"MM\0\x2a\0\0\0\x08\0\x01\x01\x12\0\x03\0\0\0\x01".to_vec();
    tiff.extend_from_slice(&orientation.to_be_bytes());
    tiff.extend_from_slice(&[0, 0, 0, 0, 0, 0]);
    let mut app1 = vec![0xFF, 0xE1];
    app1.extend_from_slice(&((2 + 6 + tiff.len()) as u16).to_be_bytes());
    app1.extend_from_slice(b"Exif\0\0");
    app1.extend_from_slice(&tiff);
    let mut out = plain[..2].to_vec();
    out.extend_from_slice(&app1);
    out.extend_from_slice(&plain[2..]);
    out
}

/// The hostile run's findings on uploads and deletion (issue 62, items 8 and 10): an image too
/// small is named so (not "too large"), an EXIF orientation is applied, and a texture whose
/// record cannot be removed is kept, with an error saying so — never a 204 for a texture that
/// comes back.
#[tokio::test]
async fn small_images_exif_orientation_and_failed_deletions_are_answered_truly() {
    let data = tempfile::tempdir().unwrap();
    let s = admin_server(data.path(), &[]);
    let tiny = png(8, 8, |x, y| [(x * 30) as u8, (y * 30) as u8, 90]);
    let (status, _, body) = upload(&s, "?id=tiny", "image/png", tiny, Some(TOKEN)).await;
    assert_eq!((status, body["error"].as_str()), (422, Some("image_too_small")), "{body}");
    assert!(body["message"].as_str().unwrap_or("").contains("8x8"), "{body}");
    // Stored sideways with orientation 6 (turn 90° clockwise to view): the red quadrant, top
    // left as stored, is top right as meant.
    let stored = image::RgbImage::from_fn(64, 64, |x, y| {
        let n = ((x * 7 + y * 13) % 23) as u8;
        if x < 32 && y < 32 {
            image::Rgb([220, 30 + n, 30])
        } else {
            image::Rgb([30, 30 + n, 220])
        }
    });
    let (status, _, body) =
        upload(&s, "?id=turned", "image/jpeg", jpeg_with_orientation(&stored, 6), Some(TOKEN)).await;
    assert_eq!(status, 202, "{body}");
    let ex = s.image("/textures/turned/exemplar.png").await;
    let (tl, tr) = (ex.get_pixel(8, 8).0, ex.get_pixel(56, 8).0);
    assert!(tr[0] > 150 && tr[2] < 100 && tl[2] > 150, "top left {tl:?}, top right {tr:?}: not turned upright");
    // A record that cannot be removed (a directory in its place): the texture stays.
    let (status, _, body) = upload(&s, "?id=keep", "image/png", brick(), Some(TOKEN)).await;
    assert_eq!(status, 202, "{body}");
    let record = data.path().join("uploads").join("keep.toml");
    assert!(record.is_file(), "{record:?}");
    let text = std::fs::read(&record).unwrap();
    std::fs::remove_file(&record).unwrap();
    std::fs::create_dir_all(record.join("stuck")).unwrap();
    let (status, body) = delete(&s, "keep", Some(TOKEN)).await;
    assert_eq!((status, body["error"].as_str()), (500, Some("not_deleted")), "{body}");
    assert_eq!(s.get("/textures/keep").await.status(), 200, "a texture that could not be deleted is kept");
    std::fs::remove_dir_all(&record).unwrap();
    std::fs::write(&record, text).unwrap();
    let (status, _) = delete(&s, "keep", Some(TOKEN)).await;
    assert_eq!(status, 204);
    assert!(!record.exists());
    assert_eq!(s.get("/textures/keep").await.status(), 404);
}

/// A request body that stops arriving (issue 62, item 6) is answered `408 body_timeout` within
/// the headers' deadline, on the samples route and the upload route alike.
#[tokio::test]
async fn a_stalled_body_is_answered_within_the_header_deadline() {
    use std::io::{Read, Write};
    let data = tempfile::tempdir().unwrap();
    let s = admin_server(data.path(), &[("TEXTILE_HEADER_READ_TIMEOUT_SECS", "2")]);
    let addr = s.base.trim_start_matches("http://").to_string();
    for (path, ctype, auth) in [
        ("/samples/gravel", "application/json", String::new()),
        ("/admin/textures?id=slow", "image/png", format!("Authorization: Bearer {TOKEN}\r\n")),
    ] {
        let mut c = std::net::TcpStream::connect(&addr).unwrap();
        c.set_read_timeout(Some(Duration::from_secs(20))).unwrap();
        let head = format!(
            "POST {path} HTTP/1.1\r\nHost: {addr}\r\nContent-Type: {ctype}\r\n{auth}Content-Length: 1000\r\n\r\n"
        );
        c.write_all(head.as_bytes()).unwrap();
        c.write_all(b"0123456789").unwrap();
        let started = std::time::Instant::now();
        let mut answer = vec![0u8; 4096];
        let n = c.read(&mut answer).unwrap_or(0);
        let answer = String::from_utf8_lossy(&answer[..n]).to_string();
        let took = started.elapsed();
        assert!(answer.starts_with("HTTP/1.1 408"), "{path}: {answer:?} after {took:?}");
        assert!(answer.contains("body_timeout"), "{path}: {answer}");
        assert!(took < Duration::from_secs(8), "{path}: answered after {took:?}");
    }
    assert!(!data.path().join("uploads").join("slow.toml").exists());
}

#[tokio::test]
async fn uploads_report_their_structure_and_take_a_lattice_field() {
    let data = tempfile::tempdir().unwrap();
    let s = admin_server(data.path(), &[]);
    let smallstone = std::fs::read(exemplar_path("test/smallstone.png")).expect("smallstone.png");
    // The development set's smallstone crop is its 64 px tile repeated 2 × 2: exact.
    let (status, headers, body) = upload(&s, "?id=stones", "image/png", smallstone.clone(), Some(TOKEN)).await;
    assert_eq!(status, 202, "{body}");
    let location = headers.get("location").unwrap().to_str().unwrap().to_string();
    let meta = until_ready(&s, &location).await;
    let st = &meta["structure"];
    assert_eq!(st["class"], "exact", "{st}");
    assert_eq!(st["basis"], serde_json::json!([[0.0, 64.0], [64.0, 0.0]]), "{st}");
    assert_eq!((st["tile"]["width"].as_i64(), st["tile"]["height"].as_i64()), (Some(64), Some(64)), "{st}");
    assert_eq!(st["scores"]["repeat"], 1.0, "{st}");
    assert_eq!(st["inner"]["class"], "none", "{st}");
    // `lattice=none` turns detection off: no structure, and the bytes of an exemplar whose
    // copies were never looked for (its copies change the analysis, so its id differs).
    let (status, headers, body) = upload(&s, "?id=stones-off&lattice=none", "image/png", smallstone, Some(TOKEN)).await;
    assert_eq!(status, 202, "{body}");
    let off = until_ready(&s, headers.get("location").unwrap().to_str().unwrap()).await;
    assert!(off["structure"].is_null(), "{}", off["structure"]);
    assert!(off["exemplar"]["lattice"].is_null(), "{}", off["exemplar"]);
    assert_ne!(off["analysis"]["id"], meta["analysis"]["id"], "copies refused as candidates are part of the analysis");
    // A given lattice is kept, and detection still reports what it found.
    let (status, headers, body) = upload(&s, "?id=brick-waves&lattice=18.5@0", "image/png", brick(), Some(TOKEN)).await;
    assert_eq!(status, 202, "{body}");
    let given = until_ready(&s, headers.get("location").unwrap().to_str().unwrap()).await;
    assert_eq!(given["exemplar"]["lattice"]["origin"], "given", "{}", given["exemplar"]);
    assert_eq!(given["structure"]["class"], "lattice", "{}", given["structure"]);
    // Basis vectors [dy, dx]: a staggered grid, kept as given.
    let (status, headers, body) =
        upload(&s, "?id=brick-bond&lattice=%5B%5B16,18%5D,%5B-16,18%5D%5D", "image/png", brick(), Some(TOKEN)).await;
    assert_eq!(status, 202, "{body}");
    let bond = until_ready(&s, headers.get("location").unwrap().to_str().unwrap()).await;
    let lattice = &bond["exemplar"]["lattice"];
    assert_eq!((lattice["kind"].as_str(), lattice["origin"].as_str()), (Some("grid"), Some("given")), "{lattice}");
    // Its reduced basis is the given one, up to sign and order ([dy, dx], as given).
    let mut basis: Vec<[i64; 2]> = lattice["basis"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| {
            let (dy, dx) = (v[0].as_f64().unwrap().round() as i64, v[1].as_f64().unwrap().round() as i64);
            if dy < 0 || (dy == 0 && dx < 0) {
                [-dy, -dx]
            } else {
                [dy, dx]
            }
        })
        .collect();
    basis.sort();
    assert_eq!(basis, [[16, -18], [16, 18]], "{lattice}");
}

/// Issue 71, item 4: flatness is judged on the image as it was sent. A 1-px checkerboard
/// larger than the largest side used shrinks to grey, but it was not sent flat: it is accepted;
/// an image that is flat as sent is still refused.
#[tokio::test]
async fn an_upload_is_judged_flat_as_it_was_sent_not_as_shrunk() {
    let data = tempfile::tempdir().unwrap();
    let s = admin_server(data.path(), &[]);
    let png = |f: &dyn Fn(u32, u32) -> u8| {
        let img = image::RgbImage::from_fn(600, 600, |x, y| {
            let v = f(x, y);
            image::Rgb([v, v, v])
        });
        let mut out = std::io::Cursor::new(Vec::new());
        img.write_to(&mut out, image::ImageFormat::Png).unwrap();
        out.into_inner()
    };
    let checkerboard = png(&|x, y| if (x + y) % 2 == 0 { 30 } else { 220 });
    let (status, _, body) = upload(&s, "?id=checker", "image/png", checkerboard, Some(TOKEN)).await;
    assert_eq!(status, 202, "a 600² 1-px checkerboard is not flat as sent: {body}");
    let meta = s.json("/textures/checker").await;
    assert_eq!(meta["exemplar"]["input_width"], 600, "{meta}");
    let (status, _, body) = upload(&s, "?id=grey", "image/png", png(&|_, _| 128), Some(TOKEN)).await;
    assert_eq!((status, body["error"].as_str()), (400, Some("flat_image")), "{body}");
}

/// Issue 71, item 5: `/ready` is the configured textures', not the stored uploads'. An upload's
/// stored analysis is replaced by a named pipe that nobody writes: reading it blocks until the
/// test writes the file's bytes into it. The restarted server is ready all the same, serves its
/// configured textures and shows the upload `analysing`; once the bytes arrive, the upload is
/// ready with the analysis it had (loaded, not recomputed).
#[tokio::test]
async fn ready_does_not_wait_for_stored_uploads() {
    let data = tempfile::tempdir().unwrap();
    let s = admin_server(data.path(), &[]);
    let (status, headers, body) = upload(&s, "?id=later", "image/png", brick(), Some(TOKEN)).await;
    assert_eq!(status, 202, "{body}");
    let before = until_ready(&s, headers.get("location").unwrap().to_str().unwrap()).await;
    drop(s);
    let stored = data.path().join("later.tex");
    let bytes = std::fs::read(&stored).expect("the upload's stored analysis");
    std::fs::remove_file(&stored).unwrap();
    let made = std::process::Command::new("mkfifo").arg(&stored).status().expect("mkfifo");
    assert!(made.success());

    let s = admin_server(data.path(), &[]);
    let (status, _) = s.get_bytes("/ready").await;
    assert_eq!(status, 200, "ready while an upload's analysis is still being read");
    let (status, _) = s.get_bytes("/tiles/gravel/7/0/0.png").await;
    assert_eq!(status, 200);
    assert_eq!(s.json("/textures/later").await["status"], "analysing");
    // Feed the pipe: the upload comes in with the analysis it had.
    let writer = std::thread::spawn(move || {
        use std::io::Write;
        let mut pipe = std::fs::OpenOptions::new().write(true).open(&stored).expect("open the pipe");
        let _ = pipe.write_all(&bytes);
    });
    let after = until_ready(&s, "/textures/later").await;
    writer.join().unwrap();
    assert_eq!(after["analysis"]["id"], before["analysis"]["id"], "{after}");
    assert!(s.log_text().contains("texture 'later': loaded analysis"), "read from the pipe, not recomputed");
}

#[tokio::test]
async fn no_upload_reads_a_file_on_the_server() {
    let data = tempfile::tempdir().unwrap();
    let secret = data.path().join("secret.json");
    std::fs::write(&secret, br#"{"elements": []}"#).unwrap();
    let a = admin_server(data.path(), &[]);
    // A field naming a file is refused by name, whatever the path.
    for path in [secret.to_str().unwrap(), "../secret.json", "/nonexistent/x.json", "embedded:gravel.png"] {
        let query = format!("?id=sneaky&umbrella.set={}", path.replace('/', "%2F"));
        let (status, _, body) = upload(&a, &query, "image/png", brick(), Some(TOKEN)).await;
        assert_eq!((status, body["error"].as_str()), (400, Some("invalid_upload")), "{path}: {body}");
        let message = body["message"].as_str().unwrap();
        assert!(message.contains("'umbrella.set'") && message.contains("reads no file on the server"), "{message}");
        assert!(!message.contains(path), "the answer repeats no path: {message}");
    }
    common::assert_error(&a, "/textures/sneaky", 404, "unknown_texture").await;
    // A record stored before the rule: kept, failed with the way out, no path shown.
    let (status, _, body) = upload(&a, "?id=legacy", "image/png", brick(), Some(TOKEN)).await;
    assert_eq!(status, 202, "{body}");
    until_ready(&a, "/textures/legacy").await;
    drop(a);
    let record = data.path().join("uploads/legacy.toml");
    let mut text = std::fs::read_to_string(&record).unwrap();
    text.push_str(&format!("\n[umbrella]\nset = {:?}\n", secret.to_str().unwrap()));
    std::fs::write(&record, &text).unwrap();
    let b = admin_server(data.path(), &[]);
    let mut m = serde_json::Value::Null;
    for _ in 0..300 {
        m = b.json("/textures/legacy").await;
        if m["status"] != "analysing" {
            break;
        }
        tokio::time::sleep(Duration::from_millis(100)).await;
    }
    assert_eq!(m["status"], "failed", "{m}");
    let why = m["analysis"]["error"].as_str().unwrap();
    assert!(why.contains("umbrella.set") && why.contains("upload it again"), "{why}");
    assert!(!m.to_string().contains(data.path().to_str().unwrap()), "public metadata shows no server path: {m}");
    let (status, _) = b.get_bytes("/tiles/legacy/7/0/0.png?mode=umbrella").await;
    assert_ne!(status, 200, "nothing of the named file is drawn");
    assert!(record.exists() && data.path().join("uploads/legacy.png").exists(), "the stored upload is not deleted");
    // The way out works: delete it, upload it again.
    assert_eq!(delete(&b, "legacy", Some(TOKEN)).await.0, 204);
    let (status, _, body) = upload(&b, "?id=legacy", "image/png", brick(), Some(TOKEN)).await;
    assert_eq!(status, 202, "{body}");
    until_ready(&b, "/textures/legacy").await;
}

/// `img` encoded in `format`.
fn encoded(img: &image::RgbImage, format: image::ImageFormat) -> Vec<u8> {
    let mut out = std::io::Cursor::new(Vec::new());
    img.write_to(&mut out, format).unwrap();
    out.into_inner()
}

#[tokio::test]
async fn truncated_or_lying_jpeg_and_webp_uploads_are_refused() {
    let data = tempfile::tempdir().unwrap();
    let s = admin_server(data.path(), &[]);
    let img =
        image::RgbImage::from_fn(128, 128, |x, y| image::Rgb([(x * 2) as u8, (y * 2) as u8, ((x ^ y) * 3) as u8]));
    let jpeg = encoded(&img, image::ImageFormat::Jpeg);
    let webp = encoded(&img, image::ImageFormat::WebP);
    // Half of each file.
    let half_jpeg = jpeg[..jpeg.len() / 2].to_vec();
    let half_webp = webp[..webp.len() / 2].to_vec();
    // A JPEG whose frame header claims 1000×1000 over the 128² image's data.
    let mut lying_jpeg = jpeg.clone();
    let sof = lying_jpeg.windows(2).position(|w| w == [0xFF, 0xC0]).expect("a baseline frame");
    lying_jpeg[sof + 5..sof + 9].copy_from_slice(&[0x03, 0xE8, 0x03, 0xE8]);
    // A WebP whose lossless header claims 1000×1000.
    let mut lying_webp = webp.clone();
    let at = lying_webp.windows(4).position(|w| w == b"VP8L").expect("a lossless WebP") + 9;
    let bits = u32::from_le_bytes(lying_webp[at..at + 4].try_into().unwrap());
    let lie = (bits & !((1 << 28) - 1)) | 999 | (999 << 14);
    lying_webp[at..at + 4].copy_from_slice(&lie.to_le_bytes());
    for (what, ct, body) in [
        ("half a JPEG", "image/jpeg", half_jpeg),
        ("a lying JPEG", "image/jpeg", lying_jpeg),
        ("half a WebP", "image/webp", half_webp),
        ("a lying WebP", "image/webp", lying_webp),
    ] {
        let (status, _, got) = upload(&s, "?id=broken", ct, body, Some(TOKEN)).await;
        assert_eq!((status, got["error"].as_str()), (400, Some("invalid_image")), "{what}: {got}");
        assert!(got["message"].as_str().is_some_and(|m| !m.is_empty()), "{what}: {got}");
    }
    let three_quarters = jpeg[..jpeg.len() * 3 / 4].to_vec();
    let (status, _, got) = upload(&s, "?id=broken", "image/jpeg", three_quarters, Some(TOKEN)).await;
    assert_eq!(status, 400, "{got}");
    assert!(got["message"].as_str().unwrap().contains("truncated"), "the answer says what is wrong: {got}");
    assert!(files_in(&data.path().join("uploads")).is_empty());
    // The whole files are accepted.
    let (status, _, got) = upload(&s, "?id=whole-jpeg", "image/jpeg", jpeg, Some(TOKEN)).await;
    assert_eq!(status, 202, "{got}");
    let (status, _, got) = upload(&s, "?id=whole-webp", "image/webp", webp, Some(TOKEN)).await;
    assert_eq!(status, 202, "{got}");
}

#[tokio::test]
async fn small_things_said_truly() {
    let data = tempfile::tempdir().unwrap();
    let s = admin_server(data.path(), &[]);
    // The bearer scheme in any case.
    for scheme in ["bearer", "BEARER", "Bearer"] {
        let r = s
            .client
            .delete(s.url("/admin/textures/nosuch"))
            .header("authorization", format!("{scheme} {TOKEN}"))
            .send()
            .await
            .unwrap();
        assert_eq!(r.status(), 404, "{scheme}: past the token check");
    }
    // Lattice values as given, and no 300-digit echo.
    for (lattice, says) in [
        ("-20@0", "period -20 is outside"),
        ("1e9@1", "period 1.000e9 is outside"),
        ("%5B%5B1e300,1e300%5D%5D", "basis vector [1.000e300, 1.000e300] is longer"),
    ] {
        let (status, _, body) =
            upload(&s, &format!("?id=l&lattice={lattice}"), "image/png", brick(), Some(TOKEN)).await;
        assert_eq!(status, 400, "{lattice}: {body}");
        let message = body["message"].as_str().unwrap();
        assert!(message.contains(says) && message.len() < 300, "{lattice}: {message}");
    }
    // The tileset's unknown-parameter answer names its anchoring parameters among the allowed.
    let (status, body) = s.get_bytes("/3dtiles/gravel/tileset.json?bogus=1").await;
    assert_eq!(status, 400);
    let v: serde_json::Value = serde_json::from_slice(&body).unwrap();
    let message = v["message"].as_str().unwrap();
    for key in ["lon", "lat", "height"] {
        assert!(message.contains(key), "{message}");
    }
}
