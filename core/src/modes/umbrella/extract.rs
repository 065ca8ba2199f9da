//! Base umbrellas extracted from the exemplar (design note §5.6): the texture's elements —
//! stones, leaves — segmented by a luminance threshold, each a star-shaped patch around its
//! deepest interior point with a rim found by ray casting, its texture cropped with an alpha
//! mask; a few bases chosen by clustering the elements, the other members of each cluster giving
//! colour offsets and morph targets; and the arrangement statistics (density, size spread).
//! Deterministic: integer image work, fixed orders, ties by index.

use crate::error::{CoreError, Result};

/// Rays cast from an element's centre: its rim vertices, one per ray at angles `2πi/RAYS`.
pub const RAYS: usize = 24;
/// Fewest and most bases kept.
pub const MIN_BASES: usize = 4;
/// Most bases kept.
pub const MAX_BASES: usize = 10;
/// Version of what extraction computes: bump it whenever an exemplar's extraction changes, so
/// that stored extractions of earlier versions are recomputed.
pub const EXTRACTION_VERSION: u32 = 3;
/// Variants (colour offsets and morph targets) kept per base at most.
pub const MAX_VARIANTS: usize = 4;

/// A base umbrella: an element of the exemplar as a star-shaped patch.
#[derive(Debug, Clone, PartialEq)]
pub struct BaseUmbrella {
    /// Crop width (the element's bounding box plus a 2-texel margin).
    pub w: u32,
    /// Crop height.
    pub h: u32,
    /// Crop pixels, RGB in `[0, 1]`, row-major.
    pub texture: Vec<[f32; 3]>,
    /// The element's mask over the crop (its alpha: true on the element's texels).
    pub alpha: Vec<bool>,
    /// The texture box-filtered by halves (levels 1, 2, … down to one texel), for lookups
    /// whose footprint spans several texels.
    pub mips: Vec<Mip>,
    /// Centre in crop coordinates (the texture coordinate of the centre vertex).
    pub centre: [f32; 2],
    /// Rim radius along each of the [`RAYS`] rays (texels): vertex `i` is at
    /// `centre + radii[i]·(cos 2πi/RAYS, sin 2πi/RAYS)`.
    pub radii: [f32; RAYS],
    /// Colour offsets and morph targets from the other members of its cluster (the first is the
    /// base itself: no offset, no morph).
    pub variants: Vec<Variant>,
    /// Where the element was in the exemplar (its centre), for inspection.
    pub source: [u32; 2],
}

/// One level of a base texture's mipmap.
#[derive(Debug, Clone, PartialEq)]
pub struct Mip {
    /// Width.
    pub w: u32,
    /// Height.
    pub h: u32,
    /// Texels, RGB in `[0, 1]`, row-major.
    pub texels: Vec<[f32; 3]>,
}

/// The mipmap of a `w × h` texture whose element texels are `alpha`: each level the mean of
/// (up to) 2×2 texels of the one before weighted by their share of element texels (so that the
/// margin around the element does not bleed into its colour), until one texel is left.
pub fn mipmap(w: u32, h: u32, texture: &[[f32; 3]], alpha: &[bool]) -> Vec<Mip> {
    let mut levels: Vec<Mip> = Vec::new();
    let (mut w, mut h) = (w as usize, h as usize);
    let mut prev: Vec<([f32; 3], f32)> = texture.iter().zip(alpha).map(|(&c, &a)| (c, a as u8 as f32)).collect();
    while w > 1 || h > 1 {
        let (nw, nh) = (w.div_ceil(2), h.div_ceil(2));
        let mut next = Vec::with_capacity(nw * nh);
        for y in 0..nh {
            for x in 0..nw {
                let (mut sum, mut wsum, mut plain, mut n) = ([0f32; 3], 0f32, [0f32; 3], 0f32);
                for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                    let (sx, sy) = (2 * x + dx, 2 * y + dy);
                    if sx < w && sy < h {
                        let (c, a) = prev[sy * w + sx];
                        for k in 0..3 {
                            sum[k] += a * c[k];
                            plain[k] += c[k];
                        }
                        wsum += a;
                        n += 1.0;
                    }
                }
                let c = if wsum > 0.0 { sum.map(|v| v / wsum) } else { plain.map(|v| v / n) };
                next.push((c, wsum / n));
            }
        }
        levels.push(Mip { w: nw as u32, h: nh as u32, texels: next.iter().map(|t| t.0).collect() });
        (w, h, prev) = (nw, nh, next);
    }
    levels
}

/// A variant of a base: another element of its cluster.
#[derive(Debug, Clone, PartialEq)]
pub struct Variant {
    /// Morph target: rim radius per ray, rescaled to the base's mean radius.
    pub radii: [f32; RAYS],
    /// Signed colour offset per vertex (centre first, then the rim), RGB in `[-1, 1]`.
    pub colour: [[f32; 3]; RAYS + 1],
}

/// What extraction found: the bases and the arrangement statistics.
#[derive(Debug, Clone, PartialEq)]
pub struct Elements {
    /// The base umbrellas (4–10).
    pub bases: Vec<BaseUmbrella>,
    /// Elements found (before choosing the bases).
    pub found: usize,
    /// Mean element area (texels).
    pub mean_area: f64,
    /// Scale spread of the elements: 10th and 90th percentile of `sqrt(area / mean area)`.
    pub scale_spread: (f64, f64),
    /// Mean colour of the exemplar, RGB in `[0, 1]`.
    pub mean_colour: [f32; 3],
    /// How the elements were segmented, for `textile info` and reports.
    pub segmentation: String,
    /// Fraction of the exemplar in the elements' class (the foreground): how much of the plane
    /// elements should cover.
    pub foreground: f64,
    /// How far the elements' orientations spread, in whole degrees (0–180): placed umbrellas
    /// are rotated by at most this either way from the orientation they were cut in. 180 (any
    /// rotation) for round elements or elements pointing every way.
    pub orientation_spread: u32,
}

/// One connected component of the foreground.
struct Component {
    texels: Vec<usize>,
    bbox: (usize, usize, usize, usize),
}

/// Luminance ×1000 of each texel, smoothed by a 3×3 box (wrapping or clamped).
fn luma(px: &[[u8; 3]], m: usize, toroidal: bool) -> Vec<i32> {
    let raw: Vec<i32> = px.iter().map(|c| 299 * c[0] as i32 + 587 * c[1] as i32 + 114 * c[2] as i32).collect();
    let at = |x: i64, y: i64| {
        let (x, y) = if toroidal {
            (x.rem_euclid(m as i64), y.rem_euclid(m as i64))
        } else {
            (x.clamp(0, m as i64 - 1), y.clamp(0, m as i64 - 1))
        };
        raw[y as usize * m + x as usize]
    };
    (0..m * m)
        .map(|i| {
            let (x, y) = ((i % m) as i64, (i / m) as i64);
            let mut s = 0;
            for dy in -1..=1 {
                for dx in -1..=1 {
                    s += at(x + dx, y + dy);
                }
            }
            s / 9
        })
        .collect()
}

/// Erode a mask by `r` (4-neighbourhood, `r` times); texels outside the exemplar count as set.
fn erode(mask: &[bool], m: usize, r: usize) -> Vec<bool> {
    let mut cur = mask.to_vec();
    for _ in 0..r {
        let prev = cur.clone();
        for y in 0..m {
            for x in 0..m {
                let i = y * m + x;
                if !prev[i] {
                    continue;
                }
                let off = |dx: i64, dy: i64| {
                    let (nx, ny) = (x as i64 + dx, y as i64 + dy);
                    nx < 0 || ny < 0 || nx >= m as i64 || ny >= m as i64 || prev[ny as usize * m + nx as usize]
                };
                cur[i] = off(1, 0) && off(-1, 0) && off(0, 1) && off(0, -1);
            }
        }
    }
    cur
}

/// Connected components (4-connected) of `mask`, in raster order of their first texel.
fn components(mask: &[bool], m: usize) -> Vec<Component> {
    let mut label = vec![usize::MAX; m * m];
    let mut out = Vec::new();
    let mut stack = Vec::new();
    for start in 0..m * m {
        if !mask[start] || label[start] != usize::MAX {
            continue;
        }
        let id = out.len();
        label[start] = id;
        stack.push(start);
        let mut texels = Vec::new();
        let mut bbox = (usize::MAX, usize::MAX, 0, 0);
        while let Some(i) = stack.pop() {
            texels.push(i);
            let (x, y) = (i % m, i / m);
            bbox = (bbox.0.min(x), bbox.1.min(y), bbox.2.max(x), bbox.3.max(y));
            for j in neighbours(i, m) {
                if mask[j] && label[j] == usize::MAX {
                    label[j] = id;
                    stack.push(j);
                }
            }
        }
        texels.sort_unstable();
        out.push(Component { texels, bbox });
    }
    out
}

/// The 4-neighbours of texel `i` inside an `m × m` exemplar (left, right, up, down).
fn neighbours(i: usize, m: usize) -> impl Iterator<Item = usize> {
    let (x, y) = (i % m, i / m);
    [(x > 0).then(|| i - 1), (x + 1 < m).then_some(i + 1), (y > 0).then(|| i - m), (y + 1 < m).then_some(i + m)]
        .into_iter()
        .flatten()
}

/// A component grown back by `r` texels within `fg` (undoing the erosion that split it from
/// its neighbours), clipped to the exemplar; sorted texel indices. `seen` is scratch space, an
/// `m × m` mask left all false as it was found (so one serves every component: work in the
/// component's size, not the exemplar's).
fn regrow(c: &Component, fg: &[bool], m: usize, r: usize, taken: &[bool], seen: &mut [bool]) -> Vec<usize> {
    let mut out = c.texels.clone();
    for &i in &c.texels {
        seen[i] = true;
    }
    let mut from = 0;
    for _ in 0..r {
        let to = out.len();
        for k in from..to {
            for j in neighbours(out[k], m) {
                if fg[j] && !seen[j] && !taken[j] {
                    seen[j] = true;
                    out.push(j);
                }
            }
        }
        from = to;
    }
    for &i in &out {
        seen[i] = false;
    }
    out.sort_unstable();
    out
}

/// A segmented element: its texels (a mask over the exemplar), centre and rim.
pub(super) struct Element {
    pub(super) texels: Vec<usize>,
    centre: (usize, usize),
    radii: [f32; RAYS],
    area: usize,
    mean: [f32; 3],
}

/// The deepest interior texel of `texels` (largest 4-neighbour distance to the outside; ties:
/// smallest index).
fn deepest(texels: &[usize], m: usize) -> usize {
    let mut inside = vec![false; m * m];
    for &i in texels {
        inside[i] = true;
    }
    let mut dist = vec![0u32; m * m];
    let mut queue = std::collections::VecDeque::new();
    for &i in texels {
        let (x, y) = (i % m, i / m);
        let edge = x == 0
            || y == 0
            || x + 1 == m
            || y + 1 == m
            || !inside[i - 1]
            || !inside[i + 1]
            || !inside[i - m]
            || !inside[i + m];
        if edge {
            dist[i] = 1;
            queue.push_back(i);
        }
    }
    while let Some(i) = queue.pop_front() {
        for j in neighbours(i, m) {
            if inside[j] && dist[j] == 0 {
                dist[j] = dist[i] + 1;
                queue.push_back(j);
            }
        }
    }
    let mut best = texels[0];
    for &i in texels {
        if dist[i] > dist[best] {
            best = i;
        }
    }
    best
}

/// The unit direction of ray `i`.
pub fn ray(i: usize) -> [f32; 2] {
    let a = std::f64::consts::TAU * i as f64 / RAYS as f64;
    [a.cos() as f32, a.sin() as f32]
}

/// A rim radius more than this many times its rim's radial opening there is a spike.
const SPIKE: f32 = 3.0;
/// What a spike is cut to, in times the opening.
const SPIKE_CUT: f32 = 1.5;

/// Rim radii with spikes cut: a radius more than [`SPIKE`] times the rim's radial opening there
/// (the largest of the minima over the three-ray windows that hold it) is cut to [`SPIKE_CUT`]
/// times the opening. A ray cast along a thin bridge into a neighbouring element, or along a
/// crack, runs far past its neighbours (gravel: 3.7 and 4 times the opening); mapped onto a
/// sector, it stretches a sliver of texture into a long streak. Lobes three rays wide or more,
/// smooth profiles such as an ellipse's and a leaf's pointed lobes (leaves: 2.6 times) are left
/// as they are. Cutting a radius keeps the spoke on the element: it is a part of the one that was.
fn despike(radii: [f32; RAYS]) -> [f32; RAYS] {
    let at = |r: &[f32; RAYS], i: usize, d: usize| r[(i + RAYS - 1 + d) % RAYS];
    let eroded: [f32; RAYS] = std::array::from_fn(|i| (0..3).map(|d| at(&radii, i, d)).fold(f32::MAX, f32::min));
    std::array::from_fn(|i| {
        let opened = (0..3).map(|d| at(&eroded, i, d)).fold(0f32, f32::max);
        if radii[i] > SPIKE * opened {
            SPIKE_CUT * opened
        } else {
            radii[i]
        }
    })
}

/// Rim radii: along each ray from the centre, the distance to the first texel outside the
/// element (in steps of a quarter texel), so the rim encloses the element's star-shaped part;
/// spikes cut ([`despike`]).
fn rim(inside: &dyn Fn(i64, i64) -> bool, c: (usize, usize)) -> [f32; RAYS] {
    let mut radii = [0f32; RAYS];
    for (i, r) in radii.iter_mut().enumerate() {
        let d = ray(i);
        let mut t = 0.0f32;
        loop {
            let next = t + 0.25;
            let (x, y) = (c.0 as f32 + 0.5 + d[0] * next, c.1 as f32 + 0.5 + d[1] * next);
            if !inside(x.floor() as i64, y.floor() as i64) || next > 512.0 {
                break;
            }
            t = next;
        }
        *r = t.max(0.5);
    }
    despike(radii)
}

/// Extract the elements of an exemplar (`m × m` RGB) and choose its base umbrellas.
pub fn extract(px: &[[u8; 3]], m: usize, toroidal: bool) -> Result<Elements> {
    let lum = luma(px, m, toroidal);
    let mut sorted = lum.clone();
    sorted.sort_unstable();
    let total = (m * m) as f64;
    let (amin, amax) = ((0.002 * total).ceil() as usize, (0.10 * total) as usize);
    // Try thresholds, polarities and erosions; keep the segmentation whose usable elements
    // (area within [0.2 %, 10 %] of the exemplar, not touching its border) cover the most.
    let mut best: Option<(usize, String, Vec<Vec<usize>>, f64)> = None;
    for q in [30, 40, 50, 60, 70] {
        let th = sorted[(sorted.len() - 1) * q / 100];
        for bright in [true, false] {
            let fg: Vec<bool> = lum.iter().map(|&v| if bright { v > th } else { v < th }).collect();
            for r in [0usize, 1, 2] {
                let core = erode(&fg, m, r);
                let mut taken = vec![false; m * m];
                let mut seen = vec![false; m * m];
                let mut kept = Vec::new();
                for c in components(&core, m) {
                    if c.bbox.0 == 0 || c.bbox.1 == 0 || c.bbox.2 + 1 >= m || c.bbox.3 + 1 >= m {
                        continue;
                    }
                    let grown = regrow(&c, &fg, m, r, &taken, &mut seen);
                    let touches = grown.iter().any(|&i| i % m == 0 || i / m == 0 || i % m == m - 1 || i / m == m - 1);
                    if touches || grown.len() < amin || grown.len() > amax {
                        continue;
                    }
                    for &i in &grown {
                        taken[i] = true;
                    }
                    kept.push(grown);
                }
                // Score: the area the usable elements cover (many tiny specks lose to fewer,
                // real elements); at least the minimum count.
                let score = if kept.len() >= MIN_BASES { kept.iter().map(Vec::len).sum::<usize>() } else { kept.len() };
                if best.as_ref().is_none_or(|b| score > b.0) {
                    let name = format!(
                        "luminance {} the {q}th percentile, eroded by {r}",
                        if bright { "above" } else { "below" }
                    );
                    let fraction = fg.iter().filter(|&&f| f).count() as f64 / total;
                    best = Some((score, name, kept, fraction));
                }
            }
        }
    }
    let (_, segmentation, kept, foreground) = best.unwrap_or_default();
    if kept.len() < MIN_BASES {
        return Err(CoreError::Param {
            name: "umbrella",
            message: format!(
                "found {} separate elements in the exemplar, at least {MIN_BASES} are needed: it does not look like a texture of discrete elements",
                kept.len()
            ),
        });
    }
    let elements = elements_of(px, m, kept);
    let groups = cluster(&elements);
    let mut mean_colour = [0f32; 3];
    for p in px {
        for k in 0..3 {
            mean_colour[k] += p[k] as f32 / 255.0;
        }
    }
    mean_colour = mean_colour.map(|v| v / (m * m) as f32);
    let spread = orientation_spread(&elements, m);
    Ok(assemble(px, m, &elements, &groups, Summary { mean_colour, segmentation, foreground, orientation_spread: spread }))
}

/// What [`assemble`] takes as given: the statistics not computed from the elements.
pub(super) struct Summary {
    pub mean_colour: [f32; 3],
    pub segmentation: String,
    pub foreground: f64,
    pub orientation_spread: u32,
}

/// The elements of an `m × m` image from their texels' masks: centre, rim, area, mean colour.
pub(super) fn elements_of(px: &[[u8; 3]], m: usize, masks: Vec<Vec<usize>>) -> Vec<Element> {
    masks
        .into_iter()
        .map(|texels| {
            let mut inside = vec![false; m * m];
            for &i in &texels {
                inside[i] = true;
            }
            let c = deepest(&texels, m);
            let centre = (c % m, c / m);
            let radii = rim(
                &|x, y| x >= 0 && y >= 0 && (x as usize) < m && (y as usize) < m && inside[y as usize * m + x as usize],
                centre,
            );
            let mut mean = [0f32; 3];
            for &i in &texels {
                for k in 0..3 {
                    mean[k] += px[i][k] as f32 / 255.0;
                }
            }
            let area = texels.len();
            mean = mean.map(|v| v / area as f32);
            Element { texels, centre, radii, area, mean }
        })
        .collect()
}

/// The bases of `groups` of `elements` (each group's first is the base, the others its
/// variants) with the size statistics.
pub(super) fn assemble(px: &[[u8; 3]], m: usize, elements: &[Element], groups: &[Vec<usize>], s: Summary) -> Elements {
    let mean_area = elements.iter().map(|e| e.area as f64).sum::<f64>() / elements.len().max(1) as f64;
    let mut scales: Vec<f64> = elements.iter().map(|e| (e.area as f64 / mean_area).sqrt()).collect();
    scales.sort_by(f64::total_cmp);
    let pick = |q: usize| scales.get(scales.len().saturating_sub(1) * q / 100).copied().unwrap_or(1.0);
    let scale_spread = (pick(10), pick(90));
    let bases = groups.iter().map(|g| base(px, m, elements, g)).collect();
    Elements {
        bases,
        found: elements.len(),
        mean_area,
        scale_spread,
        mean_colour: s.mean_colour,
        segmentation: s.segmentation,
        foreground: s.foreground,
        orientation_spread: s.orientation_spread,
    }
}

/// Mean elongation below which elements count as round (their orientation is noise).
const ROUND: f64 = 0.15;

/// The elements' orientation spread (§5.6 arrangement statistics), in whole degrees: each
/// element's principal axis from its second moments, weighted by its elongation
/// (`√((μ20 − μ02)² + 4μ11²) / (μ20 + μ02)`); the axial circular spread of the doubled angles
/// (`½√(−2 ln R)`) doubled to cover most of them. Round elements, or elements whose axes point
/// every way, give 180.
pub(super) fn orientation_spread(elements: &[Element], m: usize) -> u32 {
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
fn descriptor(e: &Element) -> Vec<f64> {
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
fn cluster(elements: &[Element]) -> Vec<Vec<usize>> {
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
fn base(px: &[[u8; 3]], m: usize, elements: &[Element], group: &[usize]) -> BaseUmbrella {
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
fn sector_colours(px: &[[u8; 3]], m: usize, e: &Element) -> [[f32; 3]; RAYS + 1] {
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spikes_are_cut_and_lobes_and_smooth_rims_kept() {
        // A spike two rays wide on a disc of radius 10: cut to 1.5 times the disc.
        let mut radii = [10f32; RAYS];
        radii[5] = 40.0;
        radii[6] = 36.0;
        let cut = despike(radii);
        assert_eq!((cut[5], cut[6]), (15.0, 15.0));
        assert!((0..RAYS).filter(|i| ![5, 6].contains(i)).all(|i| cut[i] == 10.0));
        // A pointed lobe (2.6 times its neighbours) stays, and so does a lobe three rays wide.
        let mut lobe = [10f32; RAYS];
        lobe[5] = 26.0;
        assert_eq!(despike(lobe), lobe);
        radii[7] = 38.0;
        assert_eq!(despike(radii), radii);
        // An ellipse with semi-axes 7 and 3 (the tip is the narrowest part of its profile) stays.
        let ellipse: [f32; RAYS] = std::array::from_fn(|i| {
            let d = ray(i);
            21.0 / ((3.0 * d[0]).powi(2) + (7.0 * d[1]).powi(2)).sqrt()
        });
        assert_eq!(despike(ellipse), ellipse);
        // No radius ever grows.
        for n in 0..200u32 {
            let r: [f32; RAYS] = std::array::from_fn(|i| 0.5 + ((n as usize * 7 + i * i * 13) % 29) as f32);
            assert!(despike(r).iter().zip(&r).all(|(a, b)| a <= b));
        }
    }
}
