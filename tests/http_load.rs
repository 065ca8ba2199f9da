//! Caching under concurrency: one synthesis for 100 simultaneous requests of one uncached
//! tile, all with identical bodies; beyond the in-flight limit only 200 or 503 + Retry-After.

mod common;

use common::Server;

async fn synthesized(s: &Server) -> u64 {
    s.json("/health").await["tiles_synthesized"].as_u64().unwrap()
}

#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn concurrent_requests_for_one_tile_cause_one_synthesis() {
    let s = Server::builder().start();
    let before = synthesized(&s).await;
    let path = "/tiles/brick/7/123/-456.png?seed=99";
    let mut tasks = Vec::new();
    for _ in 0..100 {
        let c = s.client.clone();
        let url = s.url(path);
        tasks.push(tokio::spawn(async move {
            let r = c.get(url).send().await.expect("request");
            assert_eq!(r.status(), 200);
            r.bytes().await.expect("body").to_vec()
        }));
    }
    let mut bodies = Vec::new();
    for t in tasks {
        bodies.push(t.await.unwrap());
    }
    assert!(bodies.iter().all(|b| *b == bodies[0]));
    assert_eq!(synthesized(&s).await - before, 1);
}

#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn overload_sheds_with_503_and_retry_after() {
    let s = Server::builder().args(&["--max-in-flight", "1", "--workers", "1"]).start();
    let mut tasks = Vec::new();
    for i in 0..24 {
        let c = s.client.clone();
        let url = s.url(&format!("/tiles/gravel/6/{i}/77@2x.png"));
        tasks.push(tokio::spawn(async move {
            let r = c.get(url).send().await.expect("request");
            (r.status().as_u16(), r.headers().get("retry-after").is_some())
        }));
    }
    let mut statuses = Vec::new();
    for t in tasks {
        statuses.push(t.await.unwrap());
    }
    assert!(statuses.iter().all(|(s, _)| *s == 200 || *s == 503), "{statuses:?}");
    assert!(statuses.iter().any(|(s, _)| *s == 503), "expected some shedding: {statuses:?}");
    assert!(statuses.iter().any(|(s, _)| *s == 200), "{statuses:?}");
    assert!(statuses.iter().filter(|(s, _)| *s == 503).all(|(_, ra)| *ra));
    assert!(s.json("/health").await["shed"].as_u64().unwrap() > 0);
}

#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn bytes_do_not_depend_on_the_caches_or_the_order() {
    // A: the default caches, forward order. B: a 1 MiB tile cache (about a dozen tiles) and a
    // 1 MiB pyramidal cache (under a hundred blocks), both evicting constantly, reverse order,
    // twice (the second pass re-synthesizes evicted tiles from partly evicted levels). C: no
    // pyramidal cache, requests all at once.
    let a = Server::builder().start();
    let b = Server::builder().args(&["--cache-mib", "1", "--level-cache-mib", "1"]).start();
    // C sends everything at once: on a slow machine the last of those may queue longer than the
    // default 1 s queue-wait bound and be shed, so that bound is lifted for C.
    let c = Server::builder().args(&["--level-cache-mib", "0"]).queueing().start();
    let mut paths: Vec<String> = (0..30)
        .map(|i| {
            let mode = if i % 3 == 0 { "&mode=mosaic" } else { "" };
            format!("/tiles/gravel/{}/{}/{}.png?seed=6{mode}", 5 + i % 3, i * 7 - 100, 50 - i * 3)
        })
        .collect();
    // Neighbours at native zoom and one step out: they share padding and coarse levels.
    for (z, x, y) in [(7, -1, -1), (7, 0, -1), (7, -1, 0), (7, 0, 0), (6, 0, 0), (6, -1, -1), (7, 1, 0), (7, 1, 1)] {
        paths.push(format!("/tiles/gravel/{z}/{x}/{y}.png?seed=6"));
    }
    let mut want = Vec::new();
    for p in &paths {
        want.push(a.get_bytes(p).await);
    }
    for _ in 0..2 {
        for (p, w) in paths.iter().zip(&want).rev() {
            assert_eq!(&b.get_bytes(p).await, w, "{p}");
        }
    }
    let all: Vec<_> = paths
        .iter()
        .map(|p| {
            let (client, url) = (c.client.clone(), c.url(p));
            tokio::spawn(async move {
                let r = client.get(url).send().await.expect("request");
                (r.status().as_u16(), r.bytes().await.expect("body").to_vec())
            })
        })
        .collect();
    for ((p, w), t) in paths.iter().zip(&want).zip(all) {
        let (status, body) = t.await.unwrap();
        assert_eq!(status, 200, "{p} without the pyramidal cache: {}", String::from_utf8_lossy(&body));
        assert_eq!(body, w.1, "{p} without the pyramidal cache");
    }
    let h = a.json("/health").await;
    assert!(h["level_cache"]["hits"].as_u64().unwrap() > 0, "neighbours shared levels: {h}");
    let h = b.json("/health").await;
    assert!(h["cache"]["evictions"].as_u64().unwrap() > 0, "the small cache evicted: {h}");
    assert!(h["cache"]["bytes"].as_u64().unwrap() <= 1 << 20);
    assert!(h["level_cache"]["evictions"].as_u64().unwrap() > 0, "the small level cache evicted: {h}");
    assert!(h["level_cache"]["bytes"].as_u64().unwrap() <= 1 << 20);
    assert_eq!(c.json("/health").await["level_cache"]["blocks"], 0);
}
