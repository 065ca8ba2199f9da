//! From elements to bases: descriptors (size, colour, radial profile), clustering, the base of
//! each cluster with its members as variants, sector colours, and the orientation spread.

use super::*;

/// Mean elongation below which elements count as round (their orientation is noise).
pub(super) const ROUND: f64 = 0.15;

/// The elements' orientation spread (§5.6 arrangement statistics), in whole degrees: each
/// element's principal axis from its second moments, weighted by its elongation
/// (`√((μ20 − μ02)² + 4μ11²) / (μ20 + μ02)`); the axial circular spread of the doubled angles
/// (`½√(−2 ln R)`) doubled to cover most of them. Round elements, or elements whose axes point
/// every way, give 180.
pub(in crate::modes::umbrella) fn orientation_spread(elements: &[Element], m: usize) -> u32 {
    let (mut sx, mut sy, mut wsum, mut elong) = (0f64, 0f64, 0f64, 0f64);
    for e in elements {
        let n = e.texels.len() as f64;
        let (mx, my) = e.texels.iter().fold((0.0, 0.0), |a, &i| (a.0 + (i % m) as f64 / n, a.1 + (i / m) as f64 / n));
        let (mut m20, mut m02, mut m11) = (0f64, 0f64, 0f64);
        for &i in &e.texels {
            let (dx, dy) = ((i % m) as f64 - mx, (i / m) as f64 - my);
            m20 += dx * dx;
            m02 += dy * dy;
            m11 += dx * dy;
        }
        let a = ((m20 - m02).powi(2) + 4.0 * m11 * m11).sqrt() / (m20 + m02).max(1e-9);
        // The doubled angle's direction is (μ20 − μ02, 2μ11); weight a.
        let len = ((m20 - m02).powi(2) + 4.0 * m11 * m11).sqrt().max(1e-12);
        sx += a * (m20 - m02) / len;
        sy += a * 2.0 * m11 / len;
        wsum += a;
        elong += a / elements.len().max(1) as f64;
    }
    if elong < ROUND || wsum <= 0.0 {
        return 180;
    }
    let r = ((sx * sx + sy * sy).sqrt() / wsum).clamp(1e-9, 1.0);
    let sigma = 0.5 * (-2.0 * r.ln()).sqrt();
    ((2.0 * sigma).to_degrees().round() as u32).min(180)
}

/// An element's descriptor for clustering: size, colour and normalised radial profile.
pub(super) fn descriptor(e: &Element) -> Vec<f64> {
    let mean_r = e.radii.iter().map(|&r| r as f64).sum::<f64>() / RAYS as f64;
    let mut d = vec![(e.area as f64).sqrt() / 8.0];
    d.extend(e.mean.iter().map(|&c| 2.0 * c as f64));
    // The profile, rotation-invariant: sorted relative radii (coarsely).
    let mut prof: Vec<f64> = e.radii.iter().map(|&r| r as f64 / mean_r.max(0.5)).collect();
    prof.sort_by(f64::total_cmp);
    d.extend(prof.iter().step_by(4).copied());
    d
}

/// Cluster the elements into 4–10 groups (deterministic k-means, farthest-point start, 10
/// rounds, ties by index); each group's medoid first.
pub(super) fn cluster(elements: &[Element]) -> Vec<Vec<usize>> {
    let desc: Vec<Vec<f64>> = elements.iter().map(descriptor).collect();
    let d2 = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum::<f64>();
    let k = (elements.len() / 3).clamp(MIN_BASES, MAX_BASES).min(elements.len());
    // Start: the largest element, then farthest points.
    let first = (0..elements.len()).max_by(|&a, &b| elements[a].area.cmp(&elements[b].area).then(b.cmp(&a))).unwrap_or(0);
    let mut centres = vec![desc[first].clone()];
    while centres.len() < k {
        let far = (0..desc.len())
            .max_by(|&a, &b| {
                let da = centres.iter().map(|c| d2(&desc[a], c)).fold(f64::MAX, f64::min);
                let db = centres.iter().map(|c| d2(&desc[b], c)).fold(f64::MAX, f64::min);
                da.total_cmp(&db).then(b.cmp(&a))
            })
            .unwrap_or(0);
        centres.push(desc[far].clone());
    }
    let mut assign = vec![0usize; desc.len()];
    for _ in 0..10 {
        for (i, d) in desc.iter().enumerate() {
            assign[i] = (0..k).min_by(|&a, &b| d2(d, &centres[a]).total_cmp(&d2(d, &centres[b])).then(a.cmp(&b))).unwrap_or(0);
        }
        for (c, centre) in centres.iter_mut().enumerate() {
            let members: Vec<&Vec<f64>> = desc.iter().zip(&assign).filter(|(_, &a)| a == c).map(|(d, _)| d).collect();
            if members.is_empty() {
                continue;
            }
            for (j, v) in centre.iter_mut().enumerate() {
                *v = members.iter().map(|d| d[j]).sum::<f64>() / members.len() as f64;
            }
        }
    }
    let mut groups = Vec::new();
    for (c, centre) in centres.iter().enumerate() {
        let mut members: Vec<usize> = (0..desc.len()).filter(|&i| assign[i] == c).collect();
        if members.is_empty() {
            continue;
        }
        members.sort_by(|&a, &b| d2(&desc[a], centre).total_cmp(&d2(&desc[b], centre)).then(a.cmp(&b)));
        groups.push(members);
    }
    // Empty clusters can leave fewer than the minimum: split the largest groups.
    while groups.len() < MIN_BASES.min(elements.len()) {
        let Some(big) = (0..groups.len()).filter(|&g| groups[g].len() > 1).max_by_key(|&g| groups[g].len()) else {
            break;
        };
        let last = groups[big].pop().unwrap_or_default();
        groups.push(vec![last]);
    }
    groups
}

/// The base umbrella of a group: its medoid's crop, with the other members as variants.
pub(super) fn base(px: &[[u8; 3]], m: usize, elements: &[Element], group: &[usize]) -> BaseUmbrella {
    let e = &elements[group[0]];
    let (mut x0, mut y0, mut x1, mut y1) = (usize::MAX, usize::MAX, 0, 0);
    for &i in &e.texels {
        let (x, y) = (i % m, i / m);
        (x0, y0, x1, y1) = (x0.min(x), y0.min(y), x1.max(x), y1.max(y));
    }
    let (x0, y0) = (x0.saturating_sub(2), y0.saturating_sub(2));
    let (x1, y1) = ((x1 + 2).min(m - 1), (y1 + 2).min(m - 1));
    let (w, h) = (x1 - x0 + 1, y1 - y0 + 1);
    let mut texture = Vec::with_capacity(w * h);
    for y in y0..=y1 {
        for x in x0..=x1 {
            texture.push(px[y * m + x].map(|c| c as f32 / 255.0));
        }
    }
    let mut alpha = vec![false; w * h];
    for &i in &e.texels {
        alpha[(i / m - y0) * w + (i % m - x0)] = true;
    }
    let centre = [(e.centre.0 - x0) as f32 + 0.5, (e.centre.1 - y0) as f32 + 0.5];
    let base_colour = sector_colours(px, m, e);
    let mean_r = e.radii.iter().sum::<f32>() / RAYS as f32;
    let mut variants = vec![Variant { radii: e.radii, colour: [[0.0; 3]; RAYS + 1] }];
    for &o in group.iter().skip(1).take(MAX_VARIANTS - 1) {
        let other = &elements[o];
        let other_mean = other.radii.iter().sum::<f32>() / RAYS as f32;
        let radii = other.radii.map(|r| r * mean_r / other_mean.max(0.5));
        let theirs = sector_colours(px, m, other);
        let mut colour = [[0f32; 3]; RAYS + 1];
        for (v, c) in colour.iter_mut().enumerate() {
            *c = [0, 1, 2].map(|k| theirs[v][k] - base_colour[v][k]);
        }
        variants.push(Variant { radii, colour });
    }
    BaseUmbrella {
        w: w as u32,
        h: h as u32,
        mips: mipmap(w as u32, h as u32, &texture, &alpha),
        texture,
        alpha,
        centre,
        radii: e.radii,
        variants,
        source: [e.centre.0 as u32, e.centre.1 as u32],
    }
}

/// Mean colour near each vertex of an element: at the centre (within a third of the mean
/// radius) and along each ray between 30 % and 90 % of its radius.
pub(super) fn sector_colours(px: &[[u8; 3]], m: usize, e: &Element) -> [[f32; 3]; RAYS + 1] {
    let at = |x: f32, y: f32| {
        let (xi, yi) = ((x.floor() as i64).clamp(0, m as i64 - 1) as usize, (y.floor() as i64).clamp(0, m as i64 - 1) as usize);
        px[yi * m + xi].map(|c| c as f32 / 255.0)
    };
    let (cx, cy) = (e.centre.0 as f32 + 0.5, e.centre.1 as f32 + 0.5);
    let mut out = [[0f32; 3]; RAYS + 1];
    let mean_r = e.radii.iter().sum::<f32>() / RAYS as f32;
    let mut acc = [0f32; 3];
    let mut n = 0.0;
    for i in 0..RAYS {
        let d = ray(i);
        for s in 0..3 {
            let t = mean_r / 3.0 * s as f32 / 3.0;
            let c = at(cx + d[0] * t, cy + d[1] * t);
            for k in 0..3 {
                acc[k] += c[k];
            }
            n += 1.0;
        }
    }
    out[0] = acc.map(|v| v / n);
    for i in 0..RAYS {
        let d = ray(i);
        let mut acc = [0f32; 3];
        for s in 0..4 {
            let t = e.radii[i] * (0.3 + 0.2 * s as f32);
            let c = at(cx + d[0] * t, cy + d[1] * t);
            for k in 0..3 {
                acc[k] += c[k];
            }
        }
        out[i + 1] = acc.map(|v| v / 4.0);
    }
    out
}
