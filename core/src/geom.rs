//! Integer plane geometry: half-open rectangles with `i64` coordinates and the floor/parity
//! helpers that stay correct for negative coordinates (design note §0); and the arithmetic of an
//! exemplar's size: its synthesis levels, wrapping coordinates at its sides, its centred square.

/// `floor(x / 2)` for any sign (arithmetic shift).
#[inline]
pub fn fl2(x: i64) -> i64 {
    x >> 1
}

/// Parity `x mod 2` in `{0, 1}` for any sign.
#[inline]
pub fn par(x: i64) -> i64 {
    x & 1
}

/// A half-open rectangle `[x0, x1) × [y0, y1)` of pixels at some pyramid level.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Rect {
    /// First column.
    pub x0: i64,
    /// First row.
    pub y0: i64,
    /// One past the last column.
    pub x1: i64,
    /// One past the last row.
    pub y1: i64,
}

impl Rect {
    /// The rectangle with origin `(x, y)` and size `w × h`.
    pub fn new(x: i64, y: i64, w: i64, h: i64) -> Self {
        Rect { x0: x, y0: y, x1: x + w, y1: y + h }
    }

    /// Width in pixels (0 if empty).
    pub fn width(&self) -> i64 {
        (self.x1 - self.x0).max(0)
    }

    /// Height in pixels (0 if empty).
    pub fn height(&self) -> i64 {
        (self.y1 - self.y0).max(0)
    }

    /// Number of pixels.
    pub fn area(&self) -> i64 {
        self.width() * self.height()
    }

    /// True when the rectangle holds no pixel.
    pub fn is_empty(&self) -> bool {
        self.x1 <= self.x0 || self.y1 <= self.y0
    }

    /// The rectangle grown by `n` pixels on every side.
    pub fn grow(&self, n: i64) -> Self {
        Rect { x0: self.x0 - n, y0: self.y0 - n, x1: self.x1 + n, y1: self.y1 + n }
    }

    /// Smallest rectangle containing both (an empty operand is ignored).
    pub fn union(&self, o: &Rect) -> Self {
        if self.is_empty() {
            return *o;
        }
        if o.is_empty() {
            return *self;
        }
        Rect { x0: self.x0.min(o.x0), y0: self.y0.min(o.y0), x1: self.x1.max(o.x1), y1: self.y1.max(o.y1) }
    }

    /// The pixels in both (empty when they do not overlap).
    pub fn intersect(&self, o: &Rect) -> Self {
        let r = Rect { x0: self.x0.max(o.x0), y0: self.y0.max(o.y0), x1: self.x1.min(o.x1), y1: self.y1.min(o.y1) };
        if r.is_empty() {
            Rect::new(r.x0, r.y0, 0, 0)
        } else {
            r
        }
    }

    /// True when `o` lies inside `self`.
    pub fn contains_rect(&self, o: &Rect) -> bool {
        o.x0 >= self.x0 && o.y0 >= self.y0 && o.x1 <= self.x1 && o.y1 <= self.y1
    }

    /// The parents (one level coarser) of every pixel: `[a, b) → [a >> 1, (b + 1) >> 1)`.
    pub fn parents(&self) -> Self {
        Rect { x0: fl2(self.x0), y0: fl2(self.y0), x1: fl2(self.x1 + 1), y1: fl2(self.y1 + 1) }
    }

    /// The children (one level finer) of every pixel: `[2a, 2b)`.
    pub fn children(&self) -> Self {
        Rect { x0: self.x0 * 2, y0: self.y0 * 2, x1: self.x1 * 2, y1: self.y1 * 2 }
    }
}

/// An exemplar's size, and what follows from it: its longer side (which periods, lattices and
/// searches are measured against) and its levels (the native zoom). The one place these are
/// computed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Size {
    /// Width in texels.
    pub width: u32,
    /// Height in texels.
    pub height: u32,
}

impl Size {
    /// A `width × height` exemplar's size.
    pub fn new(width: u32, height: u32) -> Size {
        Size { width, height }
    }

    /// A `(w, h)` size in `usize`, as exemplar dimensions are indexed.
    pub fn of_dims((w, h): (usize, usize)) -> Size {
        Size::new(w as u32, h as u32)
    }

    /// The longer side.
    pub fn longer(self) -> u32 {
        self.width.max(self.height)
    }

    /// Synthesis levels: `L = ⌈log2 max(w, h)⌉`, so that one pixel of level 0 covers the whole
    /// exemplar (for a power-of-two square of side `m`, `log2 m`). It is also the native zoom.
    pub fn levels(self) -> u32 {
        let m = self.longer().max(1);
        32 - (m - 1).leading_zeros()
    }
}

/// Synthesis levels of a `w × h` exemplar ([`Size::levels`]).
pub fn levels_for(w: u32, h: u32) -> u32 {
    Size::new(w, h).levels()
}

/// The largest centred square of a `w × h` image (itself when square) and its side: what the
/// analyses that look at a square (structure detection, umbrella extraction) see of a
/// non-square exemplar.
pub fn centred_square<T: Copy>(pixels: &[T], (w, h): (usize, usize)) -> (std::borrow::Cow<'_, [T]>, usize) {
    if w == h {
        return (std::borrow::Cow::Borrowed(pixels), w);
    }
    let side = w.min(h);
    let (ox, oy) = ((w - side) / 2, (h - side) / 2);
    let square = (0..side).flat_map(|y| &pixels[(oy + y) * w + ox..][..side]).copied().collect();
    (std::borrow::Cow::Owned(square), side)
}

/// `v` wrapped onto `0..n` (`n > 0`): a mask when `n` is a power of two, else the Euclidean
/// remainder. Exemplar coordinates wrap at the exemplar's width and height.
#[inline(always)]
pub fn wrap(v: i64, n: i64) -> i64 {
    if n & (n - 1) == 0 {
        v & (n - 1)
    } else {
        v.rem_euclid(n)
    }
}

/// Exemplar coordinates `(x, y)` wrapped onto a `w × h` exemplar and packed as `x | y << 16`.
#[inline(always)]
pub fn pack_wrapped(x: i64, y: i64, (w, h): (i64, i64)) -> u32 {
    (wrap(x, w) | wrap(y, h) << 16) as u32
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parents_of_negative_rect_keep_the_edge_parent() {
        let r = Rect { x0: -11, y0: -11, x1: 267, y1: 267 };
        let p = r.parents();
        assert_eq!((p.x0, p.x1), (-6, 134));
    }

    #[test]
    fn floor_and_parity_for_negatives() {
        assert_eq!(fl2(-1), -1);
        assert_eq!(fl2(-2), -1);
        assert_eq!(fl2(-3), -2);
        assert_eq!(par(-1), 1);
        assert_eq!(par(-2), 0);
    }
}
