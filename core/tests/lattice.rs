//! Near-regular textures (design note §1.9, issue 14): with its lattice, the rectified
//! corkboard's output keeps the exemplar's grid (autocorrelation peaks at the lattice vectors)
//! while without it the grid is lost; coarse candidates keep their lattice phase; windows stay
//! the same pixels cut from larger ones; the lattice is part of the analysis id and survives
//! the analysis file; bad lattices are refused with a message naming them.

mod common;

use textile_core::analysis::FIRST_CORRECTED_LEVEL;
use textile_core::{
    Analysis, Defaults, Exemplar, ExemplarOptions, NoProgress, ParamReader, Pyramid, Rect, RgbWindow, Source, View,
};

/// The embedded corkboard: rectified so that 2×4 cells of 64×32 texels tile it.
fn corkboard(lattice: Option<(u32, u32)>) -> Exemplar {
    let bytes = std::fs::read(common::embedded_exemplar("corkboard.png")).expect("read corkboard");
    let ex = Exemplar::from_bytes(&bytes, &ExemplarOptions { toroidal: Some(true), ..Default::default() }).unwrap();
    match lattice {
        Some((nx, ny)) => ex.with_lattice(nx, ny).expect("lattice"),
        None => ex,
    }
}

fn render(ex: &Exemplar, an: &Analysis, query: Vec<(&str, &str)>, rect: Rect) -> RgbWindow {
    let src = Source::new(ex, an);
    let p = Defaults::builtin(&src).request(&src, ParamReader::request(query).unwrap()).unwrap();
    p.render(&src, &Pyramid::off(), View::native(rect)).unwrap().image
}

/// Normalised autocorrelation of the luma at offset `(dx, dy)`.
fn autocorrelation(img: &RgbWindow, dx: usize, dy: usize) -> f64 {
    let (w, h) = (img.width as usize, img.height as usize);
    let luma: Vec<f64> =
        img.pixels.chunks(3).map(|p| 0.299 * p[0] as f64 + 0.587 * p[1] as f64 + 0.114 * p[2] as f64).collect();
    let mean = luma.iter().sum::<f64>() / luma.len() as f64;
    let g: Vec<f64> = luma.iter().map(|v| v - mean).collect();
    let var = g.iter().map(|v| v * v).sum::<f64>() / g.len() as f64;
    let (mut sum, mut n) = (0.0, 0usize);
    for y in 0..h - dy {
        for x in 0..w - dx {
            sum += g[y * w + x] * g[(y + dy) * w + x + dx];
            n += 1;
        }
    }
    sum / n as f64 / var
}

#[test]
fn the_lattice_keeps_the_grid_and_without_it_the_grid_is_lost() {
    let rect = Rect::new(-300, 4000, 512, 512);
    let mut with = Vec::new();
    let mut without = Vec::new();
    for (lattice, out) in [(Some((2, 4)), &mut with), (None, &mut without)] {
        let ex = corkboard(lattice);
        let an = Analysis::build(&ex, &NoProgress);
        for seed in ["1", "2"] {
            let img = render(&ex, &an, vec![("mode", "synth"), ("seed", seed)], rect);
            out.push([autocorrelation(&img, 64, 0), autocorrelation(&img, 0, 32), autocorrelation(&img, 32, 0)]);
        }
    }
    eprintln!("autocorrelation at (64,0), (0,32), (32,0): with lattice {with:?}, without {without:?}");
    for (w, wo) in with.iter().zip(&without) {
        // With the lattice: peaks at both lattice vectors, none at half a cell.
        assert!(w[0] > 0.15 && w[1] > 0.15 && w[2] < 0.05, "with lattice: {w:?}");
        // Without: the cells drift apart, so the peaks are gone.
        assert!(wo[0] < 0.08 && wo[1] < 0.1, "without lattice: {wo:?}");
        // And the lattice does not freeze the texture into a tiling: the cells vary.
        assert!(w[0] < 0.9 && w[1] < 0.9, "with lattice, too regular: {w:?}");
    }
}

#[test]
fn windows_with_a_lattice_are_stitched_parts() {
    let ex = corkboard(Some((2, 4)));
    let an = Analysis::build(&ex, &NoProgress);
    let q = vec![("mode", "synth"), ("seed", "9")];
    let big = render(&ex, &an, q.clone(), Rect::new(-77, 1000, 300, 200));
    for (x, y, w, h) in [(0u32, 0u32, 150u32, 100u32), (150, 0, 150, 100), (13, 57, 64, 129), (255, 199, 45, 1)] {
        let part = render(&ex, &an, q.clone(), Rect::new(-77 + x as i64, 1000 + y as i64, w as i64, h as i64));
        assert_eq!(part, common::crop(&big, x, y, w, h), "part at {x},{y}");
    }
    // Far away too.
    let far = Rect::new((1 << 40) + 5, -(1 << 38), 96, 64);
    let whole = render(&ex, &an, q.clone(), far);
    let left = render(&ex, &an, q.clone(), Rect::new(far.x0, far.y0, 40, 64));
    assert_eq!(left, common::crop(&whole, 0, 0, 40, 64));
}

#[test]
fn coarse_candidates_keep_their_lattice_phase() {
    // 4×4 cells of 32×32 texels on a 128² exemplar: a grid wave repeating 4 times holds from
    // a quarter of its period up, so levels of stride 8 and more keep the phase, stride 4, 2
    // and 1 do not have to.
    let ex = common::toroidal_exemplar(128, 11).with_lattice(4, 4).unwrap();
    let an = Analysis::build(&ex, &NoProgress);
    let free = Analysis::build(&common::toroidal_exemplar(128, 11), &NoProgress);
    assert_ne!(an.header.id, free.header.id, "the lattice is part of the analysis id");
    for l in FIRST_CORRECTED_LEVEL..=an.levels() {
        let h = 1u32 << (an.levels() - l);
        let cl = an.correction_level(l).unwrap();
        let off_phase = cl
            .cands
            .iter()
            .enumerate()
            .filter(|(u, c)| {
                let (ux, uy) = ((u % 128) as u32, (u / 128) as u32);
                let (vx, vy) = (c[1].coord & 0xFFFF, c[1].coord >> 16);
                vx % 32 != ux % 32 || vy % 32 != uy % 32
            })
            .count();
        if 4 * h >= 32 {
            assert_eq!(off_phase, 0, "level {l} (stride {h})");
        } else {
            assert!(off_phase > 0, "level {l} (stride {h}) should be free");
        }
    }
    // Stored and read back, the lattice is still there (synthesis reads it from the header).
    let dir = std::env::temp_dir().join(format!("textile-lattice-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("a.textile");
    an.save(&path).unwrap();
    let back = Analysis::load(&path).unwrap();
    assert_eq!(back.header.lattice, an.header.lattice);
    let rect = Rect::new(3, -40, 70, 50);
    let q = vec![("mode", "synth")];
    assert_eq!(render(&ex, &back, q.clone(), rect), render(&ex, &an, q, rect));
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn bad_lattices_are_refused_by_name() {
    let ex = corkboard(None);
    for (nx, ny) in [(3, 4), (0, 1), (256, 2)] {
        let e = ex.clone().with_lattice(nx, ny).unwrap_err().to_string();
        assert!(e.contains("lattice") && e.contains(&format!("{nx}x{ny}")), "{e}");
    }
    let bytes = std::fs::read(common::embedded_exemplar("gravel.png")).unwrap();
    let gravel =
        Exemplar::from_bytes(&bytes, &ExemplarOptions { toroidal: Some(false), ..Default::default() }).unwrap();
    let e = gravel.with_lattice(2, 2).unwrap_err().to_string();
    assert!(e.contains("toroidal"), "{e}");
}
