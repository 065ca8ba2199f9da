//! An element's rim: rays cast from its centre to where the element ends, with spikes (rays
//! that escape through a narrow gap) cut back.

use super::*;

/// The unit direction of ray `i`.
pub fn ray(i: usize) -> [f32; 2] {
    let a = std::f64::consts::TAU * i as f64 / RAYS as f64;
    [a.cos() as f32, a.sin() as f32]
}

/// A rim radius more than this many times its rim's radial opening there is a spike.
pub(super) const SPIKE: f32 = 3.0;

/// What a spike is cut to, in times the opening.
pub(super) const SPIKE_CUT: f32 = 1.5;

/// Rim radii with spikes cut: a radius more than [`SPIKE`] times the rim's radial opening there
/// (the largest of the minima over the three-ray windows that hold it) is cut to [`SPIKE_CUT`]
/// times the opening. A ray cast along a thin bridge into a neighbouring element, or along a
/// crack, runs far past its neighbours (gravel: 3.7 and 4 times the opening); mapped onto a
/// sector, it stretches a sliver of texture into a long streak. Lobes three rays wide or more,
/// smooth profiles such as an ellipse's and a leaf's pointed lobes (leaves: 2.6 times) are left
/// as they are. Cutting a radius keeps the spoke on the element: it is a part of the one that was.
pub(super) fn despike(radii: [f32; RAYS]) -> [f32; RAYS] {
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
pub(super) fn rim(inside: &dyn Fn(i64, i64) -> bool, c: (usize, usize)) -> [f32; RAYS] {
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
