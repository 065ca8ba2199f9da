//! Painting a view of umbrellas over its background: coverage of each pixel's sub-samples by
//! the cells' umbrellas (or merged levels of detail), one colour evaluation per umbrella a
//! pixel sees, shadows, multisample anti-aliasing.

use super::*;

/// Render a view at level of detail `level` (whose cells are at least two pixels wide) over a
/// background (rendered meanwhile): band by band — one row of cells each, a frame of
/// [`lod::FRAME`] cells at a time — the coverage of every pixel's fixed sub-samples
/// ([`sub_samples`]: 4×4 at native zoom, 2×2 zoomed out at level 0, 3×3 at merged levels;
/// [`raster`]) by the cells' umbrellas
/// (level 0: the union of the cells' lists, each umbrella masked to the cells that list it;
/// merged levels: the merged umbrellas around the row, [`lod::list_into`]), then per pixel the
/// colour of each umbrella (or the background) its sub-samples see, evaluated once at their
/// centroid and weighted by their number, darkened by their shadows: multisample
/// anti-aliasing, with one colour evaluation for a pixel inside one umbrella.
pub(super) fn paint(
    el: &Elements,
    arr: &Arrangement,
    p: &UmbrellaParams,
    view: View,
    level: u32,
    background: impl FnOnce() -> Result<RgbWindow> + Send,
) -> Result<RgbWindow> {
    let rect = view.rect;
    let step = 1i64 << view.zoom_out.min(40);
    let side = arr.g << level;
    debug_assert!(2 * step <= side, "umbrellas are drawn while a cell is two pixels wide");
    // Pixels per cell side.
    let ppc = (side / step).max(1);
    let aa = sub_samples(view.zoom_out, level);
    let (w, a) = (rect.width() as usize, aa as i64);
    let sp = step as f32 / aa as f32;
    let shadow = p.shadow as f32 / ONE_Q16 as f32;
    let shadows = (shadow > 0.0 && arr.shadow_offset > 0.0).then_some(arr.shadow_offset);
    let mut darken = [1f32; 256];
    for n in 1..256 {
        darken[n] = darken[n - 1] * (1.0 - shadow);
    }
    let sectors = shape::SectorTable::default();
    let rays = &arr.rays;
    let (cx0, cx1) = (rect.x0.div_euclid(ppc), (rect.x1 - 1).div_euclid(ppc) + 1);
    let (cy0, cy1) = (rect.y0.div_euclid(ppc), (rect.y1 - 1).div_euclid(ppc) + 1);
    let row_cells = (cx1 - cx0) as usize;
    // The background, and meanwhile the cells: level 0, the lists of all cells at once (spawn
    // cells placed once), unless a huge window has more than is worth holding (then a row of
    // cells at a time); merged levels, the merged cells around the view, in parallel.
    let reach = if level > 0 { lod::around(arr, level) } else { 0 };
    let (mx0, my0, mw) = (cx0 - reach, cy0 - reach, (cx1 - cx0 + 2 * reach) as usize);
    let (bg, (all, merged)) = rayon::join(background, || {
        let all = (level == 0 && (cx1 - cx0) as u64 * (cy1 - cy0) as u64 <= 1 << 16).then(|| arr.lists(cx0, cy0, cx1, cy1));
        let merged: Vec<(i64, i64, Arc<Vec<lod::Merged>>)> = if level > 0 {
            let mh = (cy1 - cy0 + 2 * reach) as usize;
            (0..mw * mh)
                .into_par_iter()
                .map(|n| {
                    let (x, y) = (mx0 + (n % mw) as i64, my0 + (n / mw) as i64);
                    (x, y, lod::cell(el, arr, &sectors, level, x, y))
                })
                .collect()
        } else {
            Vec::new()
        };
        (all, merged)
    });
    let bg = bg?;
    // Per pixel column, its left edge relative to the origin of its frame of cells (the same
    // in every band).
    let oxs: Vec<f32> = (rect.x0..rect.x1).map(|x| ((x - lod::frame_of(x.div_euclid(ppc)) * ppc) * step) as f32).collect();
    let bands: Vec<Vec<u8>> = (cy0..cy1)
        .into_par_iter()
        .map(|cy| {
            let (j0, j1) = (rect.y0.max(cy * ppc), rect.y1.min((cy + 1) * ppc));
            let rows_px = (j1 - j0) as usize;
            let mut cov = raster::Coverage::new(w * aa, rows_px * aa);
            let rows = ((j0 - cy * ppc) * a, (j1 - cy * ppc) * a);
            let own;
            let mut placed: Vec<Placed> = Vec::new();
            let mut locals: Vec<lod::Local> = Vec::new();
            let lists: &[Arc<Vec<Placed>>] = match (&all, level) {
                (_, 1..) => &[],
                (Some(v), _) => &v[(cy - cy0) as usize * row_cells..][..row_cells],
                (None, _) => {
                    own = arr.lists(cx0, cy, cx1, cy + 1);
                    &own
                }
            };
            // The row in stretches, one per frame of `lod::FRAME` cells it meets, each
            // rasterised with one list, in positions relative to the frame's origin (the same
            // whichever window asks): each umbrella filled once, not once per cell it reaches.
            let mut fx = cx0;
            while fx < cx1 {
                let frame = lod::frame_of(fx);
                let end = cx1.min(frame + lod::FRAME);
                let (i0, i1) = (rect.x0.max(fx * ppc), rect.x1.min(end * ppc));
                let cols = ((i0 - frame * ppc) * a, (i1 - frame * ppc) * a);
                let band = (0, (i0 - rect.x0) * a);
                if level == 0 {
                    // The union of the cells' lists, each umbrella masked to the cells that list it.
                    let union = arr.union((fx..end).map(|cx| (cx, &lists[(cx - cx0) as usize][..])), frame);
                    let cells = raster::Cells { base: (fx - frame) * ppc * a, width: ppc * a };
                    let shape = raster::placed_shape(arr, &union);
                    cov.fill_list(union.len(), shape, cells, placed.len() as u32, sp, rows, cols, band, shadows);
                    placed.extend(union.iter().map(|(u, _)| *u));
                } else {
                    let near = (cy - reach..=cy + reach)
                        .flat_map(|y| (fx - reach..end + reach).map(move |x| (x, y)))
                        .map(|(x, y)| &*merged[(y - my0) as usize * mw + (x - mx0) as usize].2);
                    let first = locals.len();
                    lod::list_into(near, arr, level, frame, (fx, end), cy, &mut locals);
                    let list = &locals[first..];
                    let shape = |n: usize, o: f32, extent: [f32; 4]| {
                        let l = &list[n];
                        raster::disc_reaches(l.o[0] + o, l.o[1] + o, l.reach2, extent).then(|| (l.rim.shifted(o), u64::MAX))
                    };
                    cov.fill_list(list.len(), shape, raster::Cells::ALL, first as u32, sp, rows, cols, band, shadows);
                }
                fx = end;
            }
            let mut out = vec![0u8; 3 * w * rows_px];
            for (j, row) in out.chunks_exact_mut(3 * w).enumerate() {
                let y = j0 + j as i64;
                let oy = (y.rem_euclid(ppc) * step) as f32;
                let bg_row = &bg.pixels[3 * (y - rect.y0) as usize * w..][..3 * w];
                for i in 0..w {
                    let ox = oxs[i];
                    let b = &bg_row[3 * i..3 * i + 3];
                    // What a group of sub-samples sees, at `(qx, qy)` from the frame's origin.
                    let eval = |key: u64, qx: f32, qy: f32| -> [f32; 3] {
                        let (id, f) = ((key >> 8) as u32, darken[(key & 0xFF) as usize]);
                        if id == raster::NONE {
                            return [0, 1, 2].map(|k| b[k] as f32 * f);
                        }
                        if level > 0 {
                            let c = lod::colour_at(&locals[id as usize], [qx, qy], el, arr, &sectors, rays, step as f32);
                            return c.map(|v| v * f * 255.0);
                        }
                        let u = &placed[id as usize];
                        let m = &arr.table[u.modified as usize];
                        let (dx, dy) = (qx - u.cx, qy - u.cy);
                        let lx = (u.cos * dx + u.sin * dy) * u.inv_scale;
                        let ly = (-u.sin * dx + u.cos * dy) * u.inv_scale;
                        let hit = m.rim.locate_clamped(&sectors, lx, ly);
                        let c = shape::colour(&el.bases[m.base], rays, &m.colour, hit, step as f32 * u.inv_scale);
                        el.oriented(c, u.cos, u.sin, u.inv_scale).map(|v| v * f * 255.0)
                    };
                    // A pixel whose sub-samples all see the same (most are): one evaluation.
                    // A sample's key: the umbrella it sees and its shadows.
                    let k0 = j * aa * cov.width + i * aa;
                    let centre = [ox + 0.5 * step as f32, oy + 0.5 * step as f32];
                    let out = match aa {
                        2 => resolve::<2>(&cov, k0, [ox, oy], sp, centre, eval),
                        3 => resolve::<3>(&cov, k0, [ox, oy], sp, centre, eval),
                        _ => resolve::<AA>(&cov, k0, [ox, oy], sp, centre, eval),
                    };
                    for k in 0..3 {
                        // Rounded half up (non-negative; `f32::round` is a call without SSE4.1).
                        row[3 * i + k] = (out[k].clamp(0.0, 255.0) + 0.5) as u8;
                    }
                }
            }
            out
        })
        .collect();
    Ok(RgbWindow { width: w as u32, height: rect.height() as u32, pixels: bands.concat() })
}

/// A pixel's colour from its `A × A` sub-samples starting at `k0` in `cov` (the pixel's corner
/// at `o`, sub-samples `sp` apart): one evaluation at the pixel's `centre` when all see the
/// same (most do), else one per group of equal sub-samples at the group's centroid, weighted by
/// its size. `eval(key, x, y)` colours what a key (the umbrella seen and its shadows) shows.
/// Generic in `A` so that each sub-sample count's loops are unrolled.
#[inline]
fn resolve<const A: usize>(
    cov: &raster::Coverage,
    k0: usize,
    o: [f32; 2],
    sp: f32,
    centre: [f32; 2],
    eval: impl Fn(u64, f32, f32) -> [f32; 3],
) -> [f32; 3] {
    let key = |k: usize| (cov.hit[k] as u64) << 8 | cov.shade[k] as u64;
    let (h0, s0) = (cov.hit[k0], cov.shade[k0]);
    let uniform = (0..A).all(|sy| {
        let k = k0 + sy * cov.width;
        cov.hit[k..k + A].iter().all(|&h| h == h0) && cov.shade[k..k + A].iter().all(|&s| s == s0)
    });
    if uniform {
        return eval(key(k0), centre[0], centre[1]);
    }
    // Groups of equal sub-samples: key, count, sum of positions.
    let mut groups = [(0u64, 0u32, 0f32, 0f32); AA * AA];
    let mut ng = 0;
    for n in 0..A * A {
        let key = key(k0 + (n / A) * cov.width + n % A);
        let qx = o[0] + ((n % A) as f32 + 0.5) * sp;
        let qy = o[1] + ((n / A) as f32 + 0.5) * sp;
        match groups[..ng].iter_mut().find(|g| g.0 == key) {
            Some(g) => {
                g.1 += 1;
                g.2 += qx;
                g.3 += qy;
            }
            None => {
                groups[ng] = (key, 1, qx, qy);
                ng += 1;
            }
        }
    }
    let mut acc = [0f32; 3];
    for &(key, n, sx, sy) in &groups[..ng] {
        let c = eval(key, sx / n as f32, sy / n as f32);
        for k in 0..3 {
            acc[k] += c[k] * n as f32;
        }
    }
    acc.map(|v| v / (A * A) as f32)
}

/// Words of storage of the paper's Table 1, `J = b·w·h + 2·b·v + n·(1 + 3v) + k·W·H`, for a
/// region of `cells_x × cells_y` grid cells: bases' texels, their vertices, the modified
/// umbrellas and the cell lists.
pub fn storage_words(el: &Elements, arr: &Arrangement, cells_x: u64, cells_y: u64) -> u64 {
    let v = (RAYS + 1) as u64;
    let textures: u64 = el.bases.iter().map(|b| b.w as u64 * b.h as u64).sum();
    let b = el.bases.len() as u64;
    let n = arr.table.len() as u64;
    textures + 2 * b * v + n * (1 + 3 * v) + arr.k as u64 * cells_x * cells_y
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::exemplar::ExemplarOptions;

    #[test]
    fn a_row_filled_with_the_union_of_its_lists_is_each_list_filled_in_its_cell() {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../config/exemplars/gravel.png");
        let ex = Exemplar::from_bytes(&std::fs::read(path).unwrap(), &ExemplarOptions::default()).unwrap();
        let (el, id) = elements(&ex).unwrap();
        let p = UmbrellaParams { shadow_offset: 3, k: 3, ..UmbrellaParams::default() };
        let arr = Arrangement::new(&el, &p, &id);
        let (sp, n, cy, cells) = (0.25f32, arr.g * 4, -2i64, 61..69i64);
        let width = (n * (cells.end - cells.start)) as usize;
        let lists: Vec<Arc<Vec<Placed>>> = cells.clone().map(|cx| arr.list(cx, cy)).collect();
        // Each list in its cell, in the cell's coordinates.
        let mut each = raster::Coverage::new(width, n as usize);
        let mut ids = Vec::new();
        for (i, list) in lists.iter().enumerate() {
            let listed: Vec<(Placed, u64)> = list.iter().map(|u| (*u, u64::MAX)).collect();
            let shape = raster::placed_shape(&arr, &listed);
            let band = (0, i as i64 * n);
            each.fill_list(list.len(), shape, raster::Cells::ALL, ids.len() as u32, sp, (0, n), (0, n), band, Some(3.0));
            ids.extend(list.iter().map(|u| u.id));
        }
        // The union, in the frame's coordinates (cells 0..64), masked.
        let union = arr.union(cells.clone().zip(&lists).map(|(cx, l)| (cx, &l[..])), 0);
        assert!(union.iter().any(|(_, m)| m.count_ones() > 1), "umbrellas listed in several cells");
        let mut once = raster::Coverage::new(width, n as usize);
        let mask = raster::Cells { base: cells.start * n, width: n };
        let cols = (cells.start * n, cells.end * n);
        once.fill_list(union.len(), raster::placed_shape(&arr, &union), mask, 0, sp, (0, n), cols, (0, 0), Some(3.0));
        let who = |hit: u32, ids: &dyn Fn(usize) -> (i64, i64, u32)| (hit != raster::NONE).then(|| ids(hit as usize));
        let (mut differ, mut hits) = (0, 0);
        for k in 0..each.hit.len() {
            let a = (who(each.hit[k], &|i| ids[i]), each.shade[k]);
            let b = (who(once.hit[k], &|i| union[i].0.id), once.shade[k]);
            differ += (a != b) as usize;
            hits += a.0.is_some() as usize;
        }
        eprintln!("{hits} of {} samples hit, {differ} differ (rounding at rims)", each.hit.len());
        assert!(hits * 2 > each.hit.len() && differ * 1000 <= each.hit.len(), "{differ} samples differ");
    }

    #[test]
    fn coverage_sees_the_first_umbrella_and_shadows_come_only_from_those_in_front_of_it() {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../config/exemplars/gravel.png");
        let ex = Exemplar::from_bytes(&std::fs::read(path).unwrap(), &ExemplarOptions::default()).unwrap();
        let (el, id) = elements(&ex).unwrap();
        let p = UmbrellaParams { shadow_offset: 4, shadow: ONE_Q16 / 2, ..UmbrellaParams::default() };
        let arr = Arrangement::new(&el, &p, &id);
        let (angles, rays) = (shape::ray_angles(), arr.rays);
        // Independently, per point: inside by the barycentric test in the umbrella's frame.
        let contains = |u: &Placed, qx: f32, qy: f32| {
            let (dx, dy) = (qx - u.cx, qy - u.cy);
            let lx = (u.cos * dx + u.sin * dy) * u.inv_scale;
            let ly = (-u.sin * dx + u.cos * dy) * u.inv_scale;
            shape::locate(&angles, &rays, &arr.table[u.modified as usize].radii, lx, ly).is_some()
        };
        // Whether a rim passes within 0.01 texels of the point (where the two tests may round
        // differently).
        let on_rim = |u: &Placed, qx: f32, qy: f32| {
            let c = contains(u, qx, qy);
            [(0.01, 0.0), (-0.01, 0.0), (0.0, 0.01), (0.0, -0.01)].iter().any(|&(ex, ey)| contains(u, qx + ex, qy + ey) != c)
        };
        let (sp, n) = (0.25f32, arr.g * 4);
        let (mut shaded, mut hits, mut total, mut borderline) = (0, 0, 0, 0);
        for cy in -2..3 {
            for cx in -2..3 {
                let list = arr.list(cx, cy);
                let mut cov = raster::Coverage::new(n as usize, n as usize);
                let listed: Vec<(Placed, u64)> = list.iter().map(|u| (*u, u64::MAX)).collect();
                cov.fill_list(list.len(), raster::placed_shape(&arr, &listed), raster::Cells::ALL, 0, sp, (0, n), (0, n), (0, 0), Some(4.0));
                for r in 0..n {
                    for c in 0..n {
                        let (qx, qy) = ((c as f32 + 0.5) * sp, (r as f32 + 0.5) * sp);
                        // The first umbrella of the list containing the point is hit; only those
                        // before it containing the point moved by −ℓ shade it.
                        let hit = list.iter().position(|u| contains(u, qx, qy));
                        let front = &list[..hit.unwrap_or(list.len())];
                        let shade = front.iter().filter(|u| contains(u, qx - 4.0, qy - 4.0)).count();
                        let k = (r * n + c) as usize;
                        let got = ((cov.hit[k] != raster::NONE).then_some(cov.hit[k] as usize), cov.shade[k] as usize);
                        if got != (hit, shade) {
                            let near = list.iter().any(|u| on_rim(u, qx, qy) || on_rim(u, qx - 4.0, qy - 4.0));
                            assert!(near, "cell {cx},{cy} sample {c},{r}: coverage {got:?}, walk {:?}", (hit, shade));
                            borderline += 1;
                        }
                        total += 1;
                        shaded += (shade > 0) as u32;
                        hits += hit.is_some() as u32;
                    }
                }
            }
        }
        eprintln!("{hits} of {total} samples hit an umbrella, {shaded} shaded, {borderline} differ on a rim");
        assert!(borderline * 1000 <= total, "{borderline} of {total} samples differ");
        assert!(shaded > 100 && hits > 1000, "the test saw shadows ({shaded}) and hits ({hits})");
    }
}
