//! `POST /samples/{id}` against the real binary: integer samples equal the pixels of the tiles
//! that hold them (every mode, several zooms, negative and far coordinates, shuffled orders,
//! split batches), binary and JSON forms agree, filtered samples at texel centres with `lod = 0`
//! equal integer samples, and malformed or oversized bodies get the documented 4xx JSON while
//! the server keeps serving.

mod common;

use common::Server;
use serde_json::{json, Value};

/// A deterministic pseudo-random sequence (splitmix64).
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    fn below(&mut self, n: u64) -> i64 {
        (self.next() % n) as i64
    }
}

/// A sample and the tile pixel it must equal: `(x, y, z)` in pixels of the tile grid.
#[derive(Clone, Copy, Debug)]
struct Point {
    x: i64,
    y: i64,
    z: u32,
}

fn points(rng: &mut Rng) -> Vec<Point> {
    let mut out = Vec::new();
    // Tiles at several zooms, negative and far; a few pixels in each.
    let tiles = [(7, 0, 0), (7, -1, -1), (7, -(1i64 << 31), (1 << 31) - 1), (5, 3, -2), (3, -1, 0), (0, 0, 0)];
    for (z, tx, ty) in tiles {
        for _ in 0..12 {
            out.push(Point { x: 256 * tx + rng.below(256), y: 256 * ty + rng.below(256), z });
        }
    }
    out
}

async fn post_json(s: &Server, path: &str, body: Value) -> (u16, Value) {
    let (st, _, b) = s.post(path, "application/json", body.to_string().into_bytes()).await;
    (st, serde_json::from_slice(&b).unwrap_or_else(|_| panic!("JSON answer: {}", String::from_utf8_lossy(&b))))
}

async fn colors_json(s: &Server, path: &str, pts: &[Point]) -> Vec<[u8; 3]> {
    let body = json!({ "points": pts.iter().map(|p| json!([p.x, p.y, p.z])).collect::<Vec<_>>() });
    let (st, v) = post_json(s, path, body).await;
    assert_eq!(st, 200, "{path}: {v}");
    serde_json::from_value(v["colors"].clone()).expect("colors")
}

fn texel_records(pts: &[Point]) -> Vec<u8> {
    let mut b = Vec::new();
    for p in pts {
        b.extend(p.x.to_le_bytes());
        b.extend(p.y.to_le_bytes());
        b.extend(p.z.to_le_bytes());
    }
    b
}

fn footprint_records(fps: &[(f64, f64, f32)]) -> Vec<u8> {
    let mut b = Vec::new();
    for &(u, v, lod) in fps {
        b.extend(u.to_le_bytes());
        b.extend(v.to_le_bytes());
        b.extend(lod.to_le_bytes());
    }
    b
}

async fn colors_binary(s: &Server, path: &str, body: Vec<u8>) -> Vec<[u8; 3]> {
    let (st, h, b) = s.post(path, "application/octet-stream", body).await;
    assert_eq!(st, 200, "{path}: {}", String::from_utf8_lossy(&b));
    assert_eq!(h["content-type"], "application/octet-stream");
    b.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect()
}

#[tokio::test]
async fn samples_equal_tile_pixels_in_every_mode_order_and_batch() {
    let s = Server::builder().start();
    let modes: Vec<String> = serde_json::from_value(s.json("/textures/gravel").await["modes"].clone()).expect("modes");
    let mut rng = Rng(7);
    let pts = points(&mut rng);
    for mode in &modes {
        for extra in ["", "&seed=5&world=2"] {
            let q = format!("mode={mode}{extra}");
            // What the tiles say.
            let mut want = Vec::new();
            for p in &pts {
                let (tx, ty) = (p.x.div_euclid(256), p.y.div_euclid(256));
                let tile = s.image(&format!("/tiles/gravel/{}/{tx}/{ty}.png?{q}", p.z)).await;
                want.push(tile.get_pixel(p.x.rem_euclid(256) as u32, p.y.rem_euclid(256) as u32).0);
            }
            let path = format!("/samples/gravel?{q}");
            assert_eq!(colors_json(&s, &path, &pts).await, want, "{q}");
            // Shuffled, and in three batches.
            let mut order: Vec<usize> = (0..pts.len()).collect();
            for i in (1..order.len()).rev() {
                order.swap(i, rng.below(i as u64 + 1) as usize);
            }
            let shuffled: Vec<Point> = order.iter().map(|&i| pts[i]).collect();
            let mut got = Vec::new();
            for part in shuffled.chunks(pts.len() / 3 + 1) {
                got.extend(colors_binary(&s, &path, texel_records(part)).await);
            }
            for (k, &i) in order.iter().enumerate() {
                assert_eq!(got[k], want[i], "{q}: {:?}", pts[i]);
            }
        }
    }
}

#[tokio::test]
async fn footprints_at_texel_centres_equal_texels_and_forms_agree() {
    let s = Server::builder().start();
    let mut rng = Rng(11);
    let pts: Vec<Point> = points(&mut rng).into_iter().filter(|p| p.z == 7).collect();
    let texels = colors_binary(&s, "/samples/gravel", texel_records(&pts)).await;
    assert_eq!(texels, colors_json(&s, "/samples/gravel", &pts).await);
    let fps: Vec<(f64, f64, f32)> = pts.iter().map(|p| (p.x as f64 + 0.5, p.y as f64 + 0.5, 0.0)).collect();
    let bin = colors_binary(&s, "/samples/gravel?records=footprints", footprint_records(&fps)).await;
    assert_eq!(bin, texels);
    let body = json!({ "footprints": fps.iter().map(|f| json!([f.0, f.1, f.2])).collect::<Vec<_>>() });
    let (st, v) = post_json(&s, "/samples/gravel", body).await;
    assert_eq!(st, 200, "{v}");
    assert_eq!(serde_json::from_value::<Vec<[u8; 3]>>(v["colors"].clone()).unwrap(), texels);
    // A coarse level of detail: the zoomed-out tile's pixel (lod 2 at its texel centre).
    let zoomed = s.image("/tiles/gravel/5/0/0.png").await;
    let got =
        colors_binary(&s, "/samples/gravel?records=footprints", footprint_records(&[(4.0 * 9.5, 4.0 * 3.5, 2.0)]))
            .await;
    assert_eq!(got[0], zoomed.get_pixel(9, 3).0);
}

/// Announce a binary body of `len` bytes with `Expect: 100-continue` and read the answer given
/// before any of it is sent: status and body text.
async fn expect_continue(s: &Server, path: &str, len: usize) -> (u16, String) {
    use tokio::io::{AsyncReadExt, AsyncWriteExt};
    let addr = s.base.trim_start_matches("http://");
    let mut c = tokio::net::TcpStream::connect(addr).await.expect("connect");
    let head = format!(
        "POST {path} HTTP/1.1\r\nHost: {addr}\r\nContent-Type: application/octet-stream\r\nContent-Length: {len}\r\nExpect: 100-continue\r\nConnection: close\r\n\r\n"
    );
    c.write_all(head.as_bytes()).await.expect("write");
    let mut answer = Vec::new();
    let read = tokio::time::timeout(std::time::Duration::from_secs(20), c.read_to_end(&mut answer)).await;
    assert!(read.is_ok(), "no answer before the body was sent");
    let text = String::from_utf8_lossy(&answer).to_string();
    let status = text.split(' ').nth(1).and_then(|s| s.parse().ok()).unwrap_or(0);
    (status, text)
}

#[tokio::test]
async fn bad_bodies_get_json_errors_and_the_server_keeps_serving() {
    let s = Server::builder().start();
    let check = |what: &'static str, want: u16, code: &'static str, got: (u16, reqwest::header::HeaderMap, Vec<u8>)| {
        let (st, h, b) = got;
        assert_eq!(st, want, "{what}: {}", String::from_utf8_lossy(&b));
        assert!(h["content-type"].to_str().unwrap().starts_with("application/json"), "{what}");
        let v: Value = serde_json::from_slice(&b).expect("JSON error");
        assert_eq!(v["error"], code, "{what}: {v}");
        assert!(v["message"].as_str().is_some_and(|m| !m.is_empty()), "{what}");
    };
    let bin = "application/octet-stream";
    let one = texel_records(&[Point { x: 1, y: 2, z: 7 }]);
    check("truncated record", 400, "invalid_body", s.post("/samples/gravel", bin, one[..13].to_vec()).await);
    let nan = footprint_records(&[(0.5, 0.5, 0.0), (f64::NAN, 1.0, 0.0)]);
    check("NaN", 400, "invalid_sample", s.post("/samples/gravel?records=footprints", bin, nan).await);
    let nan_lod = footprint_records(&[(0.5, 0.5, f32::NAN)]);
    check("NaN lod", 400, "invalid_sample", s.post("/samples/gravel?records=footprints", bin, nan_lod).await);
    // Infinite levels of detail, binary (±inf) and JSON (a number beyond f32): refused, naming
    // the sample and why.
    let json = "application/json";
    for (what, path, ct, body) in [
        ("+inf lod", "?records=footprints", bin, footprint_records(&[(0.5, 0.5, 0.0), (0.5, 0.5, f32::INFINITY)])),
        ("-inf lod", "?records=footprints", bin, footprint_records(&[(0.5, 0.5, 0.0), (0.5, 0.5, f32::NEG_INFINITY)])),
        ("JSON lod beyond f32", "", json, br#"{"footprints": [[0.5, 0.5, 0], [0.5, 0.5, 1e300]]}"#.to_vec()),
    ] {
        let (st, h, b) = s.post(&format!("/samples/gravel{path}"), ct, body).await;
        let v: Value = serde_json::from_slice(&b).expect("JSON error");
        let msg = v["message"].as_str().unwrap_or_default();
        assert!(msg.starts_with("sample 1:") && msg.contains("lod") && msg.contains("not finite"), "{what}: {v}");
        check(what, 400, "invalid_sample", (st, h, b));
    }
    check("content type", 415, "unsupported_media_type", s.post("/samples/gravel", "text/plain", one.clone()).await);
    check("records kind", 400, "invalid_parameter", s.post("/samples/gravel?records=pixels", bin, one.clone()).await);
    check("unknown parameter", 400, "unknown_parameter", s.post("/samples/gravel?sharpness=2", bin, one.clone()).await);
    check("unknown texture", 404, "unknown_texture", s.post("/samples/nope", bin, one.clone()).await);
    let far = texel_records(&[Point { x: 1 << 39, y: 0, z: 7 }]);
    check("beyond the tile range", 400, "invalid_sample", s.post("/samples/gravel", bin, far).await);
    let zoom = texel_records(&[Point { x: 0, y: 0, z: 8 }]);
    check("zoom", 400, "invalid_sample", s.post("/samples/gravel", bin, zoom).await);
    check(
        "malformed JSON",
        400,
        "invalid_body",
        s.post("/samples/gravel", json, b"{\"points\": [[1, 2]".to_vec()).await,
    );
    check("wrong arity", 400, "invalid_sample", s.post("/samples/gravel", json, b"{\"points\": [[1]]}".to_vec()).await);
    check(
        "both forms",
        400,
        "invalid_body",
        s.post("/samples/gravel", json, b"{\"points\": [], \"footprints\": []}".to_vec()).await,
    );
    let many = texel_records(&vec![Point { x: 0, y: 0, z: 7 }; 262_145]);
    check("too many samples", 413, "too_many_samples", s.post("/samples/gravel", bin, many).await);
    // A body over 8 MiB is refused from its declared length, before it is sent (a client that
    // asks `Expect: 100-continue` gets the 413 instead of the go-ahead).
    let (status, body) = expect_continue(&s, "/samples/gravel", (8 << 20) + 20).await;
    assert_eq!(status, 413, "{body}");
    assert!(body.contains("\"body_too_large\""), "{body}");
    let r = s.client.get(s.url("/samples/gravel")).send().await.expect("GET");
    assert_eq!(r.status(), 405);
    // Still serving, samples and tiles.
    assert_eq!(colors_binary(&s, "/samples/gravel", one).await.len(), 1);
    assert_eq!(s.get_bytes("/tiles/gravel/7/0/0.png").await.0, 200);
    // The limits are documented.
    let doc = s.json("/openapi.json").await;
    let post = &doc["paths"]["/samples/{id}"]["post"];
    assert!(post["responses"]["413"].is_object(), "{post}");
    assert!(post["parameters"].as_array().is_some_and(|p| p.iter().any(|p| p["name"] == "seed")), "{post}");
}
