//! Raster-dem tiles over HTTP: `map=height&encoding=terrarium|mapbox` decodes to the heights of
//! the `map=height` tile (or a texture's luma) times `height_scale` plus `base`, within the
//! encoding's quantum; TileJSON names the encoding; bad values answer 400 naming the allowed
//! ones; the bytes are the same in another process.

mod common;

use common::Server;

/// Decodes a pixel's elevation, in metres.
type Decoder = fn(&image::Rgb<u8>) -> f64;

fn terrarium(p: &image::Rgb<u8>) -> f64 {
    p[0] as f64 * 256.0 + p[1] as f64 + p[2] as f64 / 256.0 - 32768.0
}

fn mapbox(p: &image::Rgb<u8>) -> f64 {
    -10000.0 + (p[0] as f64 * 65536.0 + p[1] as f64 * 256.0 + p[2] as f64) * 0.1
}

fn luma(p: &image::Rgb<u8>) -> f64 {
    ((0.299 * p[0] as f32 + 0.587 * p[1] as f32 + 0.114 * p[2] as f32) / 255.0 * 255.0).round() as f64
}

#[tokio::test]
async fn terrain_tiles_carry_the_heights_scaled_in_either_encoding() {
    let s = Server::builder().start();
    let decoders: [(&str, Decoder, f64); 2] = [("terrarium", terrarium, 1.0 / 256.0), ("mapbox", mapbox, 0.1)];
    // A material's height map, a landscape's blended heights, and a texture's luma.
    for (tile, heights) in [
        ("flagstones/8/3/-2", "flagstones/8/3/-2.png?map=height"),
        ("meadow/7/1/5", "meadow/7/1/5.png?map=height"),
        ("gravel/7/2/1", "gravel/7/2/1.png"),
    ] {
        let h = s.image(&format!("/tiles/{heights}")).await;
        let from_colour = !heights.contains("map=height");
        for (enc, decode, quantum) in decoders {
            for (scale, base) in [(None, 0.0), (Some(37.5), -120.0)] {
                let mut q = format!("map=height&encoding={enc}");
                if let Some(sc) = scale {
                    q.push_str(&format!("&height_scale={sc}&base={base}"));
                }
                let dem = s.image(&format!("/tiles/{tile}.png?{q}")).await;
                let tj = s.json(&format!("/tiles/{}/tilejson.json?{q}", tile.split('/').next().unwrap_or(""))).await;
                assert_eq!(tj["encoding"], enc, "TileJSON says the encoding");
                assert!(tj["tiles"][0].as_str().unwrap_or("").contains(&format!("encoding={enc}")));
                // The default scale: a few texels' width at the native zoom, in metres.
                let sc = scale.unwrap_or_else(|| {
                    let native = tj["center"][2].as_f64().unwrap_or(0.0);
                    4.0 * 40_075_016.685_578_5 / (256.0 * 2f64.powf(native))
                });
                let mut worst: f64 = 0.0;
                for (x, y, p) in dem.enumerate_pixels() {
                    let v = if from_colour { luma(h.get_pixel(x, y)) } else { h.get_pixel(x, y)[0] as f64 };
                    let want = base + v / 255.0 * sc;
                    worst = worst.max((decode(p) - want).abs());
                }
                assert!(worst <= quantum / 2.0 + 1e-6, "{tile} {q}: off by {worst} m (quantum {quantum})");
            }
        }
    }
    for (q, what) in [
        ("map=height&encoding=lerc", "terrarium, mapbox"),
        ("encoding=mapbox", "map=height"),
        ("map=height&encoding=mapbox&height_scale=-3", "height_scale"),
        ("map=height&encoding=mapbox&base=1e9", "base"),
        ("height_scale=10", "encoding"),
    ] {
        let (st, body) = s.get_bytes(&format!("/tiles/flagstones/8/0/0.png?{q}")).await;
        let body = String::from_utf8_lossy(&body);
        assert_eq!(st, 400, "{q}: {body}");
        assert!(body.contains(what), "{q}: {body}");
    }
    let (st, _) = s.get_bytes("/tiles/flagstones/8/0/0.webp?map=height&encoding=terrarium").await;
    assert_eq!(st, 400, "a raster-dem is PNG only");
    // Byte-identical across processes.
    let path = "/tiles/meadow/7/-3/2.png?map=height&encoding=mapbox";
    let first = s.get_bytes(path).await;
    drop(s);
    let again = Server::builder().args(&["--workers", "1"]).start();
    assert!(again.get_bytes(path).await == first, "the same bytes in another process");
}
