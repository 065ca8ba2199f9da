//! `mode=mosaic` served exactly like `synth`: tiles equal windows, bytes are stable across
//! processes, parameters are validated, and a texture can default to it in the config.

mod common;

use common::{assert_error, gravel_textures_config, paste, Server};

#[tokio::test]
async fn mosaic_tiles_equal_windows_and_differ_from_synth() {
    let s = Server::builder().start();
    for (z, tx, ty, q) in
        [(7, 0, 0, "mode=mosaic"), (7, -5, 3, "mode=mosaic&seed=4&world=8"), (5, -1, -1, "mode=mosaic")]
    {
        let mut tiles = image::RgbImage::new(512, 512);
        for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
            let t = s.image(&format!("/tiles/brick/{z}/{}/{}.png?{q}", tx + dx, ty + dy)).await;
            paste(&mut tiles, &t, 256 * dx as u32, 256 * dy as u32);
        }
        let win = s.image(&format!("/windows/brick.png?x={}&y={}&w=512&h=512&z={z}&{q}", 256 * tx, 256 * ty)).await;
        assert!(tiles == win, "z{z} ({tx},{ty}) {q}");
    }
    let m = s.get_bytes("/tiles/brick/7/0/0.png?mode=mosaic").await;
    assert_ne!(m, s.get_bytes("/tiles/brick/7/0/0.png").await);
    // world: periodic.
    assert_eq!(
        s.get_bytes("/tiles/brick/7/1/1.png?mode=mosaic&world=2").await,
        s.get_bytes("/tiles/brick/7/3/-1.png?mode=mosaic&world=2").await
    );
}

#[tokio::test]
async fn mosaic_is_deterministic_across_processes() {
    let a = Server::builder().args(&["--workers", "1"]).start();
    let b = Server::builder().args(&["--workers", "2"]).start();
    for p in [
        "/tiles/grass/7/9/-9.png?mode=mosaic&seed=2",
        "/tiles/grass/4/0/0.png?mode=mosaic",
        "/tiles/grass/7/0/0.webp?mode=mosaic&iterations=0",
    ] {
        let x = a.get_bytes(p).await;
        assert_eq!(x.0, 200, "{p}");
        assert_eq!(b.get_bytes(p).await, x, "{p}");
    }
}

#[tokio::test]
async fn mosaic_parameters_are_validated() {
    let s = Server::builder().start();
    for q in [
        "mode=mosaic&iterations=65",
        "mode=mosaic&iterations=-1",
        "mode=mosaic&smoothing=4",
        "mode=mosaic&block_area=0.9,0.5",
        "mode=mosaic&block_area=0.5",
        "mode=mosaic&block_area=0.01,0.5",
        "mode=mosaic&randomness=0.5",
        "iterations=3",
        "mode=synth&smoothing=1",
    ] {
        assert_error(&s, &format!("/tiles/gravel/7/0/0.png?{q}"), 400, "invalid_parameter").await;
    }
    let ok = s.get("/tiles/gravel/7/0/0.png?mode=mosaic&iterations=0&smoothing=0&block_area=0.3,0.4").await;
    assert_eq!(ok.status(), 200);
}

#[tokio::test]
async fn a_texture_can_default_to_mosaic() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = gravel_textures_config(dir.path(), &[("gravel", ""), ("cheap", "default_mode = \"mosaic\"")]);
    let s = Server::builder().args(&["--config", cfg.to_str().unwrap()]).start();
    let cat = s.json("/catalog").await;
    assert_eq!(cat["textures"][1]["default_mode"], "mosaic");
    let cheap = s.get_bytes("/tiles/cheap/7/2/2.png").await;
    assert_eq!(cheap.0, 200);
    assert_eq!(cheap, s.get_bytes("/tiles/gravel/7/2/2.png?mode=mosaic").await);
    assert_eq!(s.get_bytes("/tiles/cheap/7/2/2.png?mode=synth").await, s.get_bytes("/tiles/gravel/7/2/2.png").await);
}
