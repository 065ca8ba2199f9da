//! Exemplars at their own size and shape through the real interface (issue 72): what
//! `/textures/{id}` and `textile info` report for square, non-square and non-power-of-two
//! exemplars, seamless and not; a too-small upload refused by name; a seamless non-square
//! exemplar tiled by `tiling` and `mosaic` without a seam at its period; and synth on such an
//! exemplar deterministic across processes, thread counts and request orders, its tiles the
//! window they tile.

mod common;

use std::path::Path;

use common::{paste, Server};

/// `(id, width, height, seamless)` of the exemplars made below.
const SHAPES: [(&str, u32, u32, bool); 5] = [
    ("leafy", 50, 50, true),
    ("cork", 78, 43, true),
    ("bark", 82, 90, true),
    ("ramp", 100, 100, false),
    ("photo", 300, 200, false),
];

/// A deterministic pixel noise in `0..=16`.
fn noise(x: u32, y: u32, salt: u32) -> i32 {
    let h = (x.wrapping_mul(0x9E37_79B1) ^ y.wrapping_mul(0x85EB_CA77) ^ salt.wrapping_mul(0xC2B2_AE3D))
        .wrapping_mul(0x27D4_EB2F);
    (h >> 27) as i32
}

/// A `w × h` exemplar: seamless (waves with whole periods across it, and pixel noise) or not
/// (a ramp across it, so its left and right edges differ by most of the range).
fn exemplar(w: u32, h: u32, seamless: bool) -> image::RgbImage {
    let tau = std::f64::consts::TAU;
    image::RgbImage::from_fn(w, h, |x, y| {
        let (u, v) = (x as f64 / w as f64, y as f64 / h as f64);
        let base = if seamless {
            128.0 + 55.0 * (tau * (2.0 * u + v)).sin() + 35.0 * (tau * 3.0 * v).cos()
        } else {
            30.0 + 190.0 * u + 20.0 * (tau * 5.0 * v).sin()
        };
        let c = |salt: u32, scale: f64| (base * scale + (noise(x, y, salt) - 8) as f64 * 1.5).clamp(0.0, 255.0) as u8;
        image::Rgb([c(1, 1.0), c(2, 0.8), c(3, 0.6)])
    })
}

/// A configuration of one texture per [`SHAPES`] entry, images written beside it.
fn config(dir: &Path) -> std::path::PathBuf {
    let mut toml = String::new();
    for (id, w, h, seamless) in SHAPES {
        exemplar(w, h, seamless).save(dir.join(format!("{id}.png"))).unwrap();
        toml += &format!("[[textures]]\nid = \"{id}\"\nexemplar = \"{id}.png\"\n\n");
    }
    let path = dir.join("textile.toml");
    std::fs::write(&path, toml).unwrap();
    path
}

#[tokio::test]
async fn exemplars_are_used_at_their_own_size() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = config(dir.path());
    let s = Server::builder().args(&["--config", cfg.to_str().unwrap()]).start();
    for (id, w, h, seamless) in SHAPES {
        let meta = s.json(&format!("/textures/{id}")).await;
        let e = &meta["exemplar"];
        let got = [&e["input_width"], &e["input_height"], &e["width"], &e["height"]].map(|v| v.as_u64());
        assert_eq!(got, [w, h, w, h].map(|v| Some(v as u64)), "{id}: {e}");
        assert_eq!(e["toroidal"], seamless, "{id}: the wrap-around is judged on the image as given");
        let native = 32 - (w.max(h) - 1).leading_zeros();
        assert_eq!(meta["native_zoom"], native, "{id}");
        // Every mode serves it, native and zoomed out.
        for mode in ["synth", "mosaic", "tiling", "umbrella"] {
            for z in [native, native - 2] {
                let r = s.get(&format!("/tiles/{id}/{z}/-1/2.png?mode={mode}")).await;
                let status = r.status().as_u16();
                let body = r.bytes().await.unwrap();
                // Umbrella may decline an exemplar (no elements, or a lattice), but says why.
                let declined = mode == "umbrella" && (status == 400 || status == 422);
                assert!(status == 200 || declined, "{id} {mode} z{z}: {status} {}", String::from_utf8_lossy(&body));
            }
        }
    }
    // The analysis file records the size, and `textile info` reports it.
    let file = dir.path().join("cork.tex");
    let out = std::process::Command::new(common::binary())
        .args(["analyze", "-o", file.to_str().unwrap(), dir.path().join("cork.png").to_str().unwrap()])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let stdout = String::from_utf8_lossy(&out.stdout).to_string();
    assert!(stdout.contains("78x43 → 78x43"), "{stdout}");
    let out = std::process::Command::new(common::binary()).args(["info", file.to_str().unwrap()]).output().unwrap();
    let info = String::from_utf8_lossy(&out.stdout).to_string();
    assert!(info.lines().any(|l| l.starts_with("exemplar:") && l.contains("78x43 (input 78x43)")), "{info}");
    assert!(info.contains("native zoom 7"), "{info}");
}

#[tokio::test]
async fn a_too_small_upload_is_refused_by_name_and_a_non_square_one_kept() {
    let data = tempfile::tempdir().unwrap();
    let token = "test-admin-token-0123456789";
    let s = Server::builder().data_dir(data.path()).env("TEXTILE_ADMIN_TOKEN", token).start();
    let upload = |img: image::RgbImage, id: &str| {
        let mut png = Vec::new();
        img.write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png).unwrap();
        let r = s.client.post(s.url(&format!("/admin/textures?id={id}"))).header("content-type", "image/png");
        r.bearer_auth(token).body(png).send()
    };
    let r = upload(exemplar(15, 40, true), "tiny").await.unwrap();
    let status = r.status().as_u16();
    let body: serde_json::Value = r.json().await.unwrap();
    assert!((400..500).contains(&status) && body["error"] == "image_too_small", "{status} {body}");
    let message = body["message"].as_str().unwrap_or_default();
    assert!(message.contains("15x40") && message.contains("16x16"), "names the size and the least: {body}");
    let r = upload(exemplar(82, 90, true), "bark").await.unwrap();
    assert!(r.status().is_success(), "{}", r.text().await.unwrap());
    let meta = s.json("/textures/bark").await;
    assert_eq!((meta["exemplar"]["width"].as_u64(), meta["exemplar"]["height"].as_u64()), (Some(82), Some(90)));
}

/// Mean absolute step between columns `x − 1` and `x` (all channels) of `img`, for the columns
/// `x` at a multiple of `period` after `x0` (absolute), and for every other column.
fn column_steps(img: &image::RgbImage, x0: i64, period: i64) -> (f64, f64) {
    let (mut at, mut na, mut inside, mut ni) = (0u64, 0u64, 0u64, 0u64);
    for y in 0..img.height() {
        for x in 1..img.width() {
            let (a, b) = (img.get_pixel(x - 1, y).0, img.get_pixel(x, y).0);
            let d: u64 = (0..3).map(|c| a[c].abs_diff(b[c]) as u64).sum();
            if (x0 + x as i64).rem_euclid(period) == 0 {
                (at, na) = (at + d, na + 1);
            } else {
                (inside, ni) = (inside + d, ni + 1);
            }
        }
    }
    (at as f64 / na.max(1) as f64, inside as f64 / ni.max(1) as f64)
}

/// The image turned a quarter, so that its rows are columns.
fn transposed(img: &image::RgbImage) -> image::RgbImage {
    image::RgbImage::from_fn(img.height(), img.width(), |x, y| *img.get_pixel(y, x))
}

#[tokio::test]
async fn a_seamless_non_square_exemplar_tiles_without_a_seam() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = config(dir.path());
    let s = Server::builder().args(&["--config", cfg.to_str().unwrap()]).start();
    let (x0, y0) = (-300i64, 170i64);
    for (id, w, h, seamless) in [SHAPES[1], SHAPES[3]] {
        for q in ["mode=tiling", "mode=mosaic"] {
            let img = s.image(&format!("/windows/{id}.png?x={x0}&y={y0}&w=1024&h=768&z=7&{q}")).await;
            let (across, inside) = column_steps(&img, x0, w as i64);
            let (down, inside_v) = column_steps(&transposed(&img), y0, h as i64);
            let seam = across / inside;
            let seam_v = down / inside_v;
            if seamless {
                assert!(
                    seam <= 1.2 && seam_v <= 1.2,
                    "{id} {q}: steps at the period {across:.1} / {down:.1}, inside {inside:.1} / {inside_v:.1}"
                );
            } else if q == "mode=tiling" {
                // The same measure sees the seam of an exemplar that does not wrap.
                assert!(seam > 2.0, "{id} {q}: the ramp's seam should show: {across:.1} vs {inside:.1}");
            }
        }
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn synth_on_a_non_square_exemplar_is_deterministic_and_its_tiles_are_its_windows() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = config(dir.path());
    let cfg = cfg.to_str().unwrap();
    let a = Server::builder().args(&["--config", cfg, "--workers", "1"]).start();
    let b = Server::builder().args(&["--config", cfg, "--workers", "2"]).queueing().start();
    for id in ["cork", "photo"] {
        let z = if id == "cork" { 7 } else { 9 };
        let paths: Vec<String> = [(z, 0, 0), (z, -3, 12), (z - 1, 1, -1), (z, -(1i64 << 20), (1i64 << 20) - 1)]
            .iter()
            .flat_map(|&(z, x, y)| ["png", "webp"].map(|f| format!("/tiles/{id}/{z}/{x}/{y}.{f}?seed=3")))
            .collect();
        let mut first = Vec::new();
        for p in &paths {
            let got = a.get_bytes(p).await;
            assert_eq!(got.0, 200, "{p}");
            first.push(got);
        }
        // The other process, the other thread count, the reverse order, all at once.
        let tasks: Vec<_> = paths
            .iter()
            .rev()
            .map(|p| {
                let (c, url) = (b.client.clone(), b.url(p));
                tokio::spawn(async move {
                    let r = c.get(url).send().await.expect("request");
                    (r.status().as_u16(), r.bytes().await.expect("body").to_vec())
                })
            })
            .collect();
        for ((p, want), t) in paths.iter().zip(&first).rev().zip(tasks) {
            assert_eq!(t.await.unwrap(), *want, "{p} differs between processes");
        }
        // Four tiles are the window they cover.
        let (tx, ty) = (-2i64, 5i64);
        let mut tiles = image::RgbImage::new(512, 512);
        for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
            let t = a.image(&format!("/tiles/{id}/{z}/{}/{}.png", tx + dx, ty + dy)).await;
            paste(&mut tiles, &t, 256 * dx as u32, 256 * dy as u32);
        }
        let window = b.image(&format!("/windows/{id}.png?x={}&y={}&w=512&h=512&z={z}", 256 * tx, 256 * ty)).await;
        assert!(tiles == window, "{id}: tiles differ from the window");
    }
}
