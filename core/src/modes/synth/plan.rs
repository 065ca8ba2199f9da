//! Window pyramid arithmetic (design note §1.5–1.6): which rectangle each level must compute so
//! that a requested window comes out exact. The padding is derived by propagating the needed
//! rectangles backwards through the correction subpasses, per parity class.

use crate::analysis::FIRST_CORRECTED_LEVEL;
use crate::geom::Rect;

/// Which pixels a correction subpass updates.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Class {
    /// Every pixel (one subpass per pass).
    All,
    /// Pixels with `(x mod 2, y mod 2) = (px, py)`.
    Parity(i64, i64),
}

/// The subpass sequence for `passes` passes of `subpasses` (1 or 4) subpasses each. With 4,
/// passes alternate LH05's orders `(0,0) (1,1) (1,0) (0,1)` and `(1,1) (0,0) (1,0) (0,1)`.
pub fn schedule(passes: u32, subpasses: u32) -> Vec<Class> {
    const A: [(i64, i64); 4] = [(0, 0), (1, 1), (1, 0), (0, 1)];
    const B: [(i64, i64); 4] = [(1, 1), (0, 0), (1, 0), (0, 1)];
    let mut out = Vec::new();
    for p in 0..passes {
        if subpasses == 1 {
            out.push(Class::All);
        } else {
            let order = if p % 2 == 0 { A } else { B };
            out.extend(order.iter().map(|&(x, y)| Class::Parity(x, y)));
        }
    }
    out
}

/// The subpass schedule of every level `0..=levels`: empty where a level is not corrected (below
/// [`FIRST_CORRECTED_LEVEL`], or with `passes = 0`). Level `L − 2` gets one pass more than the
/// others: it holds a sixteenth of the finest level's pixels, and the extra pass settles the
/// arrangement the two finest levels inherit (with the quieter jitter of `L − 2` in the default
/// randomness schedule, mean nn_err/nn_ref over the development set 1.32 → 1.20; an extra pass
/// at `L − 3` as well gained a little more but made leaves' large-scale streaks exceed 3;
/// bench/README.md).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Schedules(Vec<Vec<Class>>);

impl Schedules {
    /// Schedules for `passes` passes of `subpasses` subpasses (one more at `L − 2`) in a
    /// pyramid whose finest level is `levels`.
    pub fn new(passes: u32, subpasses: u32, levels: u32) -> Self {
        Self::with_extra(passes, subpasses, levels, 1)
    }

    /// The same schedule at every corrected level (the design note's worked example).
    #[cfg(test)]
    fn uniform(passes: u32, subpasses: u32, levels: u32) -> Self {
        Self::with_extra(passes, subpasses, levels, 0)
    }

    fn with_extra(passes: u32, subpasses: u32, levels: u32, extra_at_l_minus_2: u32) -> Self {
        let at = |l: u32| match l {
            _ if passes == 0 || l < FIRST_CORRECTED_LEVEL => Vec::new(),
            _ if l + 2 == levels => schedule(passes + extra_at_l_minus_2, subpasses),
            _ => schedule(passes, subpasses),
        };
        Schedules((0..=levels).map(at).collect())
    }

    /// The schedule of level `l` (empty: not corrected).
    pub fn level(&self, l: u32) -> &[Class] {
        self.0.get(l as usize).map(Vec::as_slice).unwrap_or(&[])
    }
}

/// What to compute at one level.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct LevelPlan {
    /// Pyramid level.
    pub level: u32,
    /// Pixels that must come out exact (the window, or the parents the next level reads).
    pub need: Rect,
    /// Pixels to upsample and jitter (⊇ `need`), so that correction of `need` is exact.
    pub padded: Rect,
    /// For each subpass, its class and the rectangle of class pixels it corrects.
    pub subpasses: Vec<(Class, Rect)>,
}

/// Snap a rect inward to the pixels of one parity class (empty if none).
fn snap(r: Rect, cx: i64, cy: i64) -> Rect {
    let x0 = r.x0 + (cx - r.x0).rem_euclid(2);
    let y0 = r.y0 + (cy - r.y0).rem_euclid(2);
    let x1 = (r.x1 - 1) - ((r.x1 - 1) - cx).rem_euclid(2) + 1;
    let y1 = (r.y1 - 1) - ((r.y1 - 1) - cy).rem_euclid(2) + 1;
    Rect { x0, y0, x1: x1.max(x0), y1: y1.max(y0) }
}

/// The backward cone of a window through a subpass schedule (§1.5).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Cone {
    /// For each generation `k = 0..=K` (values after `k` subpasses), the pixels of each parity
    /// class (index `px + 2·py`) whose generation-`k` value is needed; nested, growing as `k`
    /// falls.
    pub needs: Vec<[Rect; 4]>,
    /// For each subpass, its class and the rectangle of class pixels it corrects.
    pub subpasses: Vec<(Class, Rect)>,
    /// Everything generation 0 must hold: the padded window.
    pub padded: Rect,
}

/// The cone of `w` for a schedule: needs are propagated backwards through the subpasses, a
/// corrected pixel needing its 5×5 neighbourhood one generation earlier.
pub fn correction_cone(w: Rect, sched: &[Class]) -> Cone {
    let mut need = [w; 4];
    let mut needs = vec![need; sched.len() + 1];
    let mut subpasses = vec![(Class::All, Rect::new(0, 0, 0, 0)); sched.len()];
    for (k, &class) in sched.iter().enumerate().rev() {
        let r = match class {
            Class::All => need.iter().fold(Rect::new(0, 0, 0, 0), |a, b| a.union(b)),
            Class::Parity(px, py) => snap(need[(px + 2 * py) as usize], px, py),
        };
        subpasses[k] = (class, r);
        if !r.is_empty() {
            let g = r.grow(2);
            for n in need.iter_mut() {
                *n = n.union(&g);
            }
        }
        needs[k] = need;
    }
    let padded = need.iter().fold(w, |a, b| a.union(b));
    Cone { needs, subpasses, padded }
}

/// The exact padding of `w` for a subpass schedule (§1.5): returns the padded rect and each
/// subpass's rect.
pub fn pad_for_correction(w: Rect, sched: &[Class]) -> (Rect, Vec<(Class, Rect)>) {
    let cone = correction_cone(w, sched);
    (cone.padded, cone.subpasses)
}

/// Plan the synthesis of `rect` at `target` level: one entry per level `0..=target`, coarse first.
pub fn plan_window(target: u32, rect: Rect, scheds: &Schedules) -> Vec<LevelPlan> {
    let mut plans = Vec::with_capacity(target as usize + 1);
    let mut need = rect;
    for l in (0..=target).rev() {
        let sched = scheds.level(l);
        let (padded, subpasses) =
            if sched.is_empty() { (need, Vec::new()) } else { pad_for_correction(need, sched) };
        plans.push(LevelPlan { level: l, need, padded, subpasses });
        need = padded.parents();
    }
    plans.reverse();
    plans
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sizes(r: Rect) -> (i64, i64) {
        (r.width(), r.height())
    }

    /// The worked example of design note §1.6 (m = 128, L = 7, tile [0,256)²), with one change:
    /// level 3 is no longer corrected (`FIRST_CORRECTED_LEVEL` = 4), so it needs no padding and
    /// the coarser levels need less. Levels 7–4 are the note's table exactly.
    #[test]
    fn plan_matches_design_table_for_tile_at_origin() {
        let plans = plan_window(7, Rect::new(0, 0, 256, 256), &Schedules::uniform(2, 4, 7));
        let expect = [
            (7, (0, 256, 0, 256), (275, 277)),
            (6, (-5, 133, -5, 134), (157, 161)),
            (5, (-7, 72, -8, 73), (97, 101)),
            (4, (-8, 41, -9, 42), (69, 73)),
            (3, (-9, 26, -10, 27), (35, 37)),
            (2, (-5, 13, -5, 14), (18, 19)),
            (1, (-3, 7, -3, 7), (10, 10)),
            (0, (-2, 4, -2, 4), (6, 6)),
        ];
        for (l, (x0, x1, y0, y1), size) in expect {
            let p = &plans[l];
            assert_eq!(p.level, l as u32);
            assert_eq!((p.need.x0, p.need.x1, p.need.y0, p.need.y1), (x0, x1, y0, y1), "need at level {l}");
            assert_eq!(sizes(p.padded), size, "padded at level {l}");
        }
        let top = &plans[7];
        assert_eq!((top.padded.x0, top.padded.x1, top.padded.y0, top.padded.y1), (-10, 265, -10, 267));
    }

    #[test]
    fn level_l_minus_2_gets_one_pass_more() {
        let (uniform, ours) = (Schedules::uniform(2, 4, 7), Schedules::new(2, 4, 7));
        for l in 0..=7 {
            let extra = if l == 5 { 4 } else { 0 };
            assert_eq!(ours.level(l).len(), uniform.level(l).len() + extra, "level {l}");
        }
        assert!(Schedules::new(0, 4, 7).0.iter().all(Vec::is_empty), "passes = 0 corrects nothing");
        let (a, b) = (plan_window(7, Rect::new(0, 0, 256, 256), &uniform), plan_window(7, Rect::new(0, 0, 256, 256), &ours));
        assert_eq!(a[6..], b[6..], "the finest two levels are planned as before");
        assert_eq!(a[5].need, b[5].need);
        assert!(b[5].padded.contains_rect(&a[5].padded) && b[5].padded != a[5].padded, "more padding for the extra pass");
    }

    #[test]
    fn plan_for_negative_tile_has_the_same_sizes() {
        let a = plan_window(7, Rect::new(0, 0, 256, 256), &Schedules::new(2, 4, 7));
        let b = plan_window(7, Rect::new(-256, -256, 256, 256), &Schedules::new(2, 4, 7));
        for (p, q) in a.iter().zip(&b) {
            assert_eq!(sizes(p.padded), sizes(q.padded), "level {}", p.level);
        }
        assert_eq!((b[6].need.x0, b[6].need.x1, b[6].need.y0, b[6].need.y1), (-133, 5, -133, 6));
    }
}
