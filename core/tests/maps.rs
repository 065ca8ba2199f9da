//! Material maps in every mode (issue 39): a map that holds the exemplar's own colours renders
//! exactly the colour's bytes in every mode that renders maps, at every zoom (so every mode
//! looks maps up, filters and magnifies them exactly as it does the colour); a mode that cannot
//! render maps, or has no coordinates, refuses with a typed error; coordinates of a magnified
//! synth view name the texel patch each pixel lies in.

mod common;

use textile_core::maps::MapChoice;
use textile_core::modes::{Source, View};
use textile_core::{CoreError, Defaults, ParamReader, Pyramid, Rect};

#[test]
fn a_map_of_the_colours_renders_the_colour_in_every_mode_at_every_zoom() {
    let an = common::small();
    let ex = common::small_exemplar().clone();
    let ex = ex.clone().with_map("copy", &ex, None).expect("a map the exemplar's size");
    let src = Source::new(&ex, an);
    let map = src.exemplar.map("copy").expect("prepared");
    let defaults = Defaults::builtin(&src);
    let mut rendering = 0;
    for mode in textile_core::modes::all() {
        let p = defaults.request(&src, ParamReader::request([("mode", mode.name), ("seed", "5")]).unwrap()).unwrap();
        for zoom in [-2i64, -1, 0, 1, 2, 3, 7] {
            let view = View::at(zoom, Rect::new(-37, 1000, 70, 50));
            let colour = p.render(&src, &Pyramid::off(), view);
            let mapped = p.render(&src.with_map(map), &Pyramid::off(), view);
            if mode.name == "umbrella" {
                // Shadows, colour offsets and the gaps' calibration are the colour's alone.
                assert_eq!(colour.is_ok(), mapped.is_ok(), "{}: {mapped:?}", mode.name);
                continue;
            }
            rendering += 1;
            assert_eq!(colour.unwrap().image, mapped.unwrap().image, "{} at zoom {zoom}", mode.name);
        }
    }
    assert!(rendering >= 3 * 7, "most modes render maps");
    assert_eq!(MapChoice::default().name(), "albedo");
}

#[test]
fn native_coordinates_look_the_colour_up_and_modes_without_them_say_so() {
    let an = common::small();
    let ex = common::small_exemplar();
    let src = Source::new(ex, an);
    let defaults = Defaults::builtin(&src);
    let m = ex.width as usize;
    for mode in textile_core::modes::all() {
        let p = defaults.request(&src, ParamReader::request([("mode", mode.name)]).unwrap()).unwrap();
        let view = View::native(Rect::new(500, -300, 40, 30));
        let uv = p.coordinates(&src, &Pyramid::off(), view);
        if !mode.has_uv {
            assert!(matches!(uv, Err(CoreError::Map { .. })), "{}", mode.name);
            continue;
        }
        let uv = uv.unwrap();
        let img = p.render(&src, &Pyramid::off(), view).unwrap().image;
        // `synth` blends the low frequencies across seams (3 texels each side): there, pixels
        // whose 7×7 coordinates continue each other show their texel; elsewhere every pixel.
        let reach = if mode.name == "synth" { 3 } else { 0 };
        let texel = |i: usize| (uv.uv[i][0] as i64 / 64, uv.uv[i][1] as i64 / 64);
        let coherent = |i: usize| {
            let (x, y) = ((i % 40) as i64, (i / 40) as i64);
            let (tx, ty) = texel(i);
            (x >= reach && x < 40 - reach && y >= reach && y < 30 - reach)
                && (-reach..=reach).all(|dy| {
                    (-reach..=reach).all(|dx| {
                        let (qx, qy) = texel(((y + dy) * 40 + x + dx) as usize);
                        (qx - dx, qy - dy) == (tx, ty)
                    })
                })
        };
        let mut checked = 0;
        for (i, [u, v]) in uv.uv.iter().enumerate() {
            assert_eq!((u % 64, v % 64), (32, 32), "{}: native pixels show texel centres", mode.name);
            if !coherent(i) {
                continue;
            }
            let t = ex.pixels[(*v as usize / 64) * m + *u as usize / 64];
            assert_eq!(img.pixels[3 * i..3 * i + 3], t, "{} pixel {i}", mode.name);
            checked += 1;
        }
        assert!(checked >= 40, "{}: {checked} pixels checked", mode.name);
        // Magnified: each pixel's point lies in the patch of the texel it is in, whose native
        // coordinate is the native view's.
        let native = p.coordinates(&src, &Pyramid::off(), View::native(Rect::new(250, -75, 10, 8))).unwrap();
        for k in 1..=3u32 {
            let big = p
                .coordinates(
                    &src,
                    &Pyramid::off(),
                    View::at(-(k as i64), Rect::new(250 << k, -75 << k, 10 << k, 8 << k)),
                )
                .unwrap();
            for (i, [u, v]) in big.uv.iter().enumerate() {
                let (x, y) = (i % (10 << k), i / (10 << k));
                let q = native.uv[(y >> k) * 10 + (x >> k)];
                assert_eq!([u / 64, v / 64], [q[0] / 64, q[1] / 64], "{} k {k} pixel ({x},{y})", mode.name);
            }
        }
    }
}
