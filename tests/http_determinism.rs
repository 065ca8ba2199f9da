//! Determinism through the real interface: tiles equal windows of the same area, bytes are the
//! same across processes, thread counts and request orders, far and negative tiles work, zoomed-out
//! tiles are reduced views of their children, and `world` makes the texture exactly periodic.

mod common;

use common::{paste, Server};

/// A 2×2 block of native tiles at `(tx, ty)` stitched into one 512 image.
async fn block(s: &Server, id: &str, z: u32, tx: i64, ty: i64, q: &str) -> image::RgbImage {
    let mut out = image::RgbImage::new(512, 512);
    for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
        let t = s.image(&format!("/tiles/{id}/{z}/{}/{}.png{q}", tx + dx, ty + dy)).await;
        paste(&mut out, &t, 256 * dx as u32, 256 * dy as u32);
    }
    out
}

#[tokio::test]
async fn two_by_two_tiles_equal_one_window() {
    let s = Server::builder().start();
    let edge = (1i64 << 31) - 2;
    for (id, tx, ty) in [("gravel", 0, 0), ("grass", -1, -1), ("brick", 5, -9), ("gravel", edge, -(1 << 31))] {
        let tiles = block(&s, id, 7, tx, ty, "?seed=11").await;
        let window = s.image(&format!("/windows/{id}.png?x={}&y={}&w=512&h=512&seed=11", 256 * tx, 256 * ty)).await;
        assert!(tiles == window, "{id} at ({tx},{ty}): tiles differ from the window");
    }
    // Zoomed out too.
    let tiles = block(&s, "gravel", 5, -2, 1, "").await;
    let window = s.image("/windows/gravel.png?x=-512&y=256&w=512&h=512&z=5").await;
    assert!(tiles == window, "zoom 5 tiles differ from the window");
}

#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn same_bytes_across_processes_thread_counts_and_orders() {
    let a = Server::builder().args(&["--workers", "1"]).start();
    // b is also sent everything at once below; lift the queue-wait bound so that a slow machine
    // queues those requests instead of shedding some with 503.
    let b = Server::builder().args(&["--workers", "2"]).queueing().start();
    let paths: Vec<String> = [(7, 0, 0), (7, -3, 12), (6, 1, -1), (7, -(1i64 << 31), (1i64 << 31) - 1), (3, 0, 0)]
        .iter()
        .flat_map(|&(z, x, y)| {
            ["png", "webp", "jpg"].map(|f| format!("/tiles/grass/{z}/{x}/{y}.{f}?seed=3&randomness=0.7"))
        })
        .collect();
    let mut first = Vec::new();
    for p in &paths {
        first.push(a.get_bytes(p).await);
    }
    for (p, want) in paths.iter().zip(&first).rev() {
        assert_eq!(want.0, 200, "{p}");
        assert_eq!(&b.get_bytes(p).await, want, "{p} differs between processes");
    }
    // Concurrent, reversed order on the second server gives the same bytes again.
    let tasks: Vec<_> = paths
        .iter()
        .rev()
        .map(|p| {
            let (c, url) = (b.client.clone(), b.url(&format!("{p}&v=x")));
            tokio::spawn(async move {
                let r = c.get(url).send().await.expect("request");
                (r.status().as_u16(), r.bytes().await.expect("body").to_vec())
            })
        })
        .collect();
    for ((p, want), t) in paths.iter().zip(&first).rev().zip(tasks) {
        assert_eq!(t.await.unwrap(), *want, "{p} differs under concurrency");
    }
}

#[tokio::test]
async fn zoomed_out_tiles_are_reduced_views_of_their_children() {
    let s = Server::builder().start();
    // A zoomed-out tile shows a coarser synthesis level's coordinates with the exact box
    // mean of the exemplar block under each (so it costs what a native tile does): close to its
    // children box-filtered, not exact — what the finer levels' correction moved differs. Bound
    // 8 of 255 per channel, as core/tests/zoom_consistency.rs keeps for synth (measured there
    // on 16 tiles: gravel 3.5, 5.6, 7.2 one to three steps out). Brick's detected lattice
    // holds its columns at every level while the bricks along them stay free, so where its
    // thin, bright mortar falls along a column differs more between levels: 8.3 here (4.2
    // before the lattice), the columns in place in both; its bound is 10.
    for (id, z, x, y) in [("gravel", 6, 0, 0), ("brick", 6, -3, 2), ("gravel", 5, 0, 0), ("gravel", 4, 1, -1)] {
        let parent = s.image(&format!("/tiles/{id}/{z}/{x}/{y}.png")).await;
        let children = block(&s, id, z + 1, 2 * x, 2 * y, "").await;
        let mad = mean_abs_diff(&parent, &box_half(&children));
        eprintln!("{id}: z{z} vs z{} mean abs difference {mad}", z + 1);
        let bound = if id == "brick" { 10.0 } else { 8.0 };
        assert!(mad < bound, "{id} z{z}: mean abs difference {mad}");
    }
}

/// 2×2 box downsampling with rounding.
fn box_half(img: &image::RgbImage) -> image::RgbImage {
    image::RgbImage::from_fn(img.width() / 2, img.height() / 2, |x, y| {
        let mut s = [0u32; 3];
        for (a, b) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
            let p = img.get_pixel(2 * x + a, 2 * y + b);
            for c in 0..3 {
                s[c] += p[c] as u32;
            }
        }
        image::Rgb(s.map(|v| ((v + 2) / 4) as u8))
    })
}

fn mean_abs_diff(a: &image::RgbImage, b: &image::RgbImage) -> f64 {
    let s: u64 = a.as_raw().iter().zip(b.as_raw()).map(|(x, y)| x.abs_diff(*y) as u64).sum();
    s as f64 / a.as_raw().len() as f64
}

#[tokio::test]
async fn world_parameter_makes_the_texture_periodic() {
    let s = Server::builder().start();
    let a = s.get_bytes("/tiles/gravel/7/1/2.png?world=4").await;
    assert_eq!(a.0, 200);
    assert_eq!(s.get_bytes("/tiles/gravel/7/5/2.png?world=4").await, a);
    assert_eq!(s.get_bytes("/tiles/gravel/7/1/-2.png?world=4").await, a);
    assert_ne!(s.get_bytes("/tiles/gravel/7/5/2.png").await, a);
    // Zoomed out, the same world repeats every 2 tiles.
    let z = s.get_bytes("/tiles/gravel/6/0/1.png?world=4").await;
    assert_eq!(s.get_bytes("/tiles/gravel/6/2/-1.png?world=4").await, z);
}
