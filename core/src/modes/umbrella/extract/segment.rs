//! Segmentation of the exemplar into elements: a luminance threshold, erosion to separate
//! touching elements, connected components, each regrown within the foreground and given its
//! deepest interior point.

/// One connected component of the foreground.
pub(super) struct Component {
    pub(super) texels: Vec<usize>,
    pub(super) bbox: (usize, usize, usize, usize),
}

/// Luminance ×1000 of each texel, smoothed by a 3×3 box (wrapping or clamped).
pub(super) fn luma(px: &[[u8; 3]], m: usize, toroidal: bool) -> Vec<i32> {
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
pub(super) fn erode(mask: &[bool], m: usize, r: usize) -> Vec<bool> {
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
pub(super) fn components(mask: &[bool], m: usize) -> Vec<Component> {
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
pub(super) fn neighbours(i: usize, m: usize) -> impl Iterator<Item = usize> {
    let (x, y) = (i % m, i / m);
    [(x > 0).then(|| i - 1), (x + 1 < m).then_some(i + 1), (y > 0).then(|| i - m), (y + 1 < m).then_some(i + m)]
        .into_iter()
        .flatten()
}

/// A component grown back by `r` texels within `fg` (undoing the erosion that split it from
/// its neighbours), clipped to the exemplar; sorted texel indices. `seen` is scratch space, an
/// `m × m` mask left all false as it was found (so one serves every component: work in the
/// component's size, not the exemplar's).
pub(super) fn regrow(c: &Component, fg: &[bool], m: usize, r: usize, taken: &[bool], seen: &mut [bool]) -> Vec<usize> {
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

/// The deepest interior texel of `texels` (largest 4-neighbour distance to the outside; ties:
/// smallest index).
pub(super) fn deepest(texels: &[usize], m: usize) -> usize {
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
