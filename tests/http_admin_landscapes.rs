//! Landscapes added through the admin API, over HTTP against the real binary: a noise and a
//! painted one are served at once and after a restart; bad configurations and splats are 400s
//! naming the field and the limit; a texture a landscape uses cannot be deleted (409 naming
//! it); a server killed during an upload leaves nothing behind, and orphans of an interrupted
//! store are removed at the next start.

mod common;

use std::io::Write;
use std::path::Path;

use common::Server;

const TOKEN: &str = "test-admin-token-0123456789";

fn admin_server(data: &Path) -> Server {
    Server::builder().data_dir(data).env("TEXTILE_ADMIN_TOKEN", TOKEN).start()
}

/// POST a landscape form (`config` JSON, optional `splat` PNG): status and JSON body.
async fn post(
    s: &Server,
    config: &serde_json::Value,
    splat: Option<Vec<u8>>,
    token: Option<&str>,
) -> (u16, serde_json::Value) {
    let mut form = reqwest::multipart::Form::new().text("config", config.to_string());
    if let Some(png) = splat {
        form = form.part("splat", reqwest::multipart::Part::bytes(png).file_name("splat.png"));
    }
    let mut r = s.client.post(s.url("/admin/landscapes")).multipart(form);
    if let Some(t) = token {
        r = r.bearer_auth(t);
    }
    let r = r.send().await.expect("post");
    let status = r.status().as_u16();
    (status, r.json().await.unwrap_or(serde_json::Value::Null))
}

async fn delete(s: &Server, what: &str, id: &str) -> (u16, serde_json::Value) {
    let r = s.client.delete(s.url(&format!("/admin/{what}/{id}"))).bearer_auth(TOKEN).send().await.expect("delete");
    let status = r.status().as_u16();
    (status, r.json().await.unwrap_or(serde_json::Value::Null))
}

fn noise(id: &str, layers: &[&str]) -> serde_json::Value {
    let layers: Vec<_> = layers.iter().map(|t| serde_json::json!({ "texture": t, "share": 0.5 })).collect();
    serde_json::json!({ "id": id, "layers": layers, "splat": { "kind": "noise", "feature": 256 } })
}

fn painted(id: &str) -> serde_json::Value {
    serde_json::json!({
        "id": id,
        "layers": [{ "texture": "gravel", "colour": "#ff0000" }, { "texture": "grass", "colour": "#0000ff" }],
        "splat": { "kind": "image", "image": "splat", "texels_per_pixel": 64, "outside": "repeat" },
        "blend": { "kind": "linear" }
    })
}

fn splat_png() -> Vec<u8> {
    let img =
        image::RgbImage::from_fn(8, 8, |x, y| image::Rgb(if (x + y) % 2 == 0 { [255, 0, 0] } else { [0, 0, 255] }));
    let mut out = Vec::new();
    img.write_to(&mut std::io::Cursor::new(&mut out), image::ImageFormat::Png).expect("png");
    out
}

fn files(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .map(|d| d.flatten().map(|e| e.file_name().to_string_lossy().into_owned()).collect())
        .unwrap_or_default();
    v.sort();
    v
}

/// A refused upload: its config and splat, and the status, a word of the message and the code.
type Refusal = (serde_json::Value, Option<Vec<u8>>, u16, &'static str, &'static str);

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn landscapes_added_served_restarted_and_deleted() {
    let data = tempfile::tempdir().expect("temp dir");
    let s = admin_server(data.path());
    // A noise landscape and a painted one: served at once.
    let (code, body) = post(&s, &noise("pond", &["gravel", "grass"]), None, Some(TOKEN)).await;
    assert_eq!(code, 201, "{body}");
    assert_eq!(body["kind"], "landscape");
    let (code, body) = post(&s, &painted("plot"), Some(splat_png()), Some(TOKEN)).await;
    assert_eq!(code, 201, "{body}");
    let (code, pond) = s.get_bytes("/tiles/pond/7/1/1.png").await;
    assert_eq!(code, 200);
    let (code, plot) = s.get_bytes("/tiles/plot/7/0/0.png?seed=3").await;
    assert_eq!(code, 200);
    let catalog = s.json("/catalog").await;
    let ids: Vec<&str> =
        catalog["landscapes"].as_array().expect("landscapes").iter().filter_map(|l| l["id"].as_str()).collect();
    assert!(ids.contains(&"pond") && ids.contains(&"plot"), "{ids:?}");
    let dir = data.path().join("landscapes");
    assert_eq!(files(&dir), ["plot.json", "plot.splat.png", "pond.json"]);

    // Refusals name the field and the limit, and store nothing.
    let mut no_layers = noise("bad", &["gravel"]);
    no_layers.as_object_mut().expect("object").remove("layers");
    let huge = {
        let img = image::RgbImage::new(4100, 2);
        let mut out = Vec::new();
        img.write_to(&mut std::io::Cursor::new(&mut out), image::ImageFormat::Png).expect("png");
        out
    };
    let mut elsewhere = painted("bad");
    elsewhere["splat"]["image"] = serde_json::json!("/etc/passwd");
    let cases: Vec<Refusal> = vec![
        (no_layers, None, 400, "layers", "invalid_landscape"),
        (noise("bad", &["gravel"]), None, 400, "2 to", "invalid_landscape"),
        (noise("bad", &["gravel", "nosuch"]), None, 400, "config.layers[1].texture", "invalid_landscape"),
        (painted("bad"), Some(huge), 400, "4096", "invalid_landscape"),
        (painted("bad"), Some(b"\x89PNG\r\n\x1a\nnot really".to_vec()), 400, "splat", "invalid_landscape"),
        (painted("bad"), None, 400, "part 'splat'", "invalid_landscape"),
        (elsewhere, Some(splat_png()), 400, "config.splat.image", "invalid_landscape"),
        (noise("pond", &["gravel", "grass"]), None, 409, "pond", "landscape_exists"),
        (noise("brick", &["gravel", "grass"]), None, 409, "brick", "landscape_exists"),
    ];
    for (config, splat, status, says, code) in cases {
        let (got, body) = post(&s, &config, splat, Some(TOKEN)).await;
        assert_eq!((got, body["error"].as_str()), (status, Some(code)), "{config}: {body}");
        assert!(body["message"].as_str().unwrap_or("").contains(says), "{config}: {body}");
    }
    let (code, _) = post(&s, &noise("x", &["gravel", "grass"]), None, None).await;
    assert_eq!(code, 401);
    let (code, _) = post(&s, &noise("x", &["gravel", "grass"]), None, Some("wrong")).await;
    assert_eq!(code, 401);
    assert_eq!(files(&dir), ["plot.json", "plot.splat.png", "pond.json"], "refusals store nothing");

    // A texture a landscape uses cannot go while it does.
    let (code, body) = delete(&s, "textures", "gravel").await;
    assert_eq!((code, body["error"].as_str()), (409, Some("configured_texture")), "{body}");
    let brick = std::fs::read(format!("{}/../config/exemplars/brick.png", env!("CARGO_MANIFEST_DIR"))).expect("brick");
    let r = s
        .client
        .post(s.url("/admin/textures?id=bricks"))
        .bearer_auth(TOKEN)
        .header("content-type", "image/png")
        .body(brick)
        .send()
        .await
        .expect("upload");
    assert_eq!(r.status().as_u16(), 202);
    let (code, body) = post(&s, &noise("walls", &["bricks", "gravel"]), None, Some(TOKEN)).await;
    assert_eq!(code, 201, "{body}");
    // A landscape stands where its layers do: analysing while the upload is, then ready.
    let status = |v: serde_json::Value| v["status"].as_str().unwrap_or("").to_string();
    let mut seen = Vec::new();
    for _ in 0..600 {
        let before = status(s.json("/textures/bricks").await);
        let walls = s.json("/textures/walls").await;
        let after = status(s.json("/textures/bricks").await);
        if before == after {
            assert_eq!(status(walls.clone()), before, "the landscape says its layer's status: {walls}");
            seen.push(before.clone());
        }
        if after == "ready" {
            break;
        }
        tokio::time::sleep(std::time::Duration::from_millis(50)).await;
    }
    eprintln!("walls' status as its layer was analysed: {:?}", seen.first().zip(seen.last()));
    assert_eq!(seen.last().map(String::as_str), Some("ready"), "{seen:?}");
    assert_eq!(s.get_bytes("/tiles/walls/7/0/0.png").await.0, 200);
    let (code, body) = delete(&s, "textures", "bricks").await;
    assert_eq!((code, body["error"].as_str()), (409, Some("texture_in_use")), "{body}");
    assert!(body["message"].as_str().unwrap_or("").contains("walls"), "{body}");
    let (code, body) = delete(&s, "landscapes", "meadow").await;
    assert_eq!((code, body["error"].as_str()), (409, Some("configured_landscape")), "{body}");

    // A restart serves them as they were.
    s.terminate();
    let s = admin_server(data.path());
    assert_eq!(s.get_bytes("/tiles/pond/7/1/1.png").await, (200, pond));
    assert_eq!(s.get_bytes("/tiles/plot/7/0/0.png?seed=3").await, (200, plot));
    assert_eq!(s.json("/textures/walls").await["kind"], "landscape");

    // Deleted: gone, with its files; then its texture can go.
    assert_eq!(delete(&s, "landscapes", "walls").await.0, 204);
    assert_eq!(delete(&s, "landscapes", "plot").await.0, 204);
    // The same URL as before the deletion: its remembered ETag is not used once the catalogue changed.
    assert_eq!(s.get_bytes("/tiles/plot/7/0/0.png?seed=3").await.0, 404);
    assert_eq!(delete(&s, "landscapes", "plot").await.0, 404);
    assert_eq!(delete(&s, "textures", "bricks").await.0, 204);
    assert_eq!(files(&dir), ["pond.json"]);
    s.terminate();
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_server_killed_during_an_upload_leaves_nothing_behind() {
    let data = tempfile::tempdir().expect("temp dir");
    let s = admin_server(data.path());
    assert_eq!(post(&s, &noise("pond", &["gravel", "grass"]), None, Some(TOKEN)).await.0, 201);
    // Half of a painted landscape's form is sent, then the server is killed.
    let boundary = "textile-boundary";
    let config = painted("plot").to_string();
    let png = splat_png();
    let mut body = format!(
        "--{boundary}\r\nContent-Disposition: form-data; name=\"config\"\r\n\r\n{config}\r\n--{boundary}\r\n\
         Content-Disposition: form-data; name=\"splat\"; filename=\"splat.png\"\r\nContent-Type: image/png\r\n\r\n"
    )
    .into_bytes();
    body.extend_from_slice(&png);
    body.extend_from_slice(format!("\r\n--{boundary}--\r\n").as_bytes());
    let addr = s.base.trim_start_matches("http://").to_string();
    let mut conn = std::net::TcpStream::connect(&addr).expect("connect");
    let head = format!(
        "POST /admin/landscapes HTTP/1.1\r\nHost: {addr}\r\nAuthorization: Bearer {TOKEN}\r\n\
         Content-Type: multipart/form-data; boundary={boundary}\r\nContent-Length: {}\r\n\r\n",
        body.len()
    );
    conn.write_all(head.as_bytes()).expect("head");
    conn.write_all(&body[..body.len() - 40]).expect("half the body");
    std::thread::sleep(std::time::Duration::from_millis(300));
    let killed = std::process::Command::new("kill").args(["-KILL", &s.pid().to_string()]).status().expect("kill");
    assert!(killed.success());
    drop(conn);
    drop(s);
    let dir = data.path().join("landscapes");
    assert_eq!(files(&dir), ["pond.json"], "nothing of the killed upload is on disk");
    // What a store interrupted between its files would leave: a splat without its record and a
    // record's temporary file of a process that is gone. The next start removes them.
    std::fs::write(dir.join("plot.splat.png"), &png).expect("orphan");
    std::fs::write(dir.join("half.json.tmp-999999999"), b"{\"id\": \"ha").expect("temporary");
    let s = admin_server(data.path());
    assert_eq!(files(&dir), ["pond.json"], "orphans are removed at start-up");
    assert!(s.log_text().contains("interrupted landscape upload"), "{}", s.log_text());
    assert_eq!(s.get_bytes("/tiles/pond/7/1/1.png").await.0, 200);
    assert_eq!(s.get_bytes("/tiles/plot/7/1/1.png").await.0, 404);
    // And the upload can be made again.
    assert_eq!(post(&s, &painted("plot"), Some(png), Some(TOKEN)).await.0, 201);
    s.terminate();
}
