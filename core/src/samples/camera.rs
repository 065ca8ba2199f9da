//! A perspective camera over the infinite textured ground plane (Wei & Levoy 2003, Figure 6):
//! for each screen pixel, the point of the plane its centre sees and the level of detail of its
//! footprint, as a GPU would choose it (`log2` of the longer screen-space derivative of the
//! texture position). The plane is `z = 0` in native texels, `v` growing southwards as tile rows
//! do; pixels above the horizon see the sky and have no sample.

use super::filter::Footprint;

/// The camera: position, orientation, lens and image size.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GroundCamera {
    /// Position over the plane, in native texels.
    pub x: f64,
    /// Position over the plane, in native texels.
    pub y: f64,
    /// Height above the plane, in native texels (> 0).
    pub height: f64,
    /// Angle of the view below the horizon, degrees (0: level, 90: straight down).
    pub pitch: f64,
    /// Heading, degrees clockwise from north (−v).
    pub yaw: f64,
    /// Vertical field of view, degrees (0, 180).
    pub fov: f64,
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height_px: u32,
}

type V3 = [f64; 3];

impl GroundCamera {
    /// A camera at `(x, y)`, `height` texels above the plane, with a 60° lens and a 30° pitch.
    pub fn new(x: f64, y: f64, height: f64, width: u32, height_px: u32) -> Self {
        GroundCamera { x, y, height, pitch: 30.0, yaw: 0.0, fov: 60.0, width, height_px }
    }

    /// Why the camera cannot render, if it cannot.
    pub fn check(&self) -> Result<(), String> {
        let finite = [self.x, self.y, self.height, self.pitch, self.yaw, self.fov].iter().all(|v| v.is_finite());
        if !finite {
            return Err("camera values must be finite numbers".into());
        }
        if self.height <= 0.0 {
            return Err("camera height must be above the plane (> 0)".into());
        }
        if !(-90.0..=90.0).contains(&self.pitch) {
            return Err("pitch must be within -90..=90 degrees".into());
        }
        if !(self.fov > 0.0 && self.fov < 180.0) {
            return Err("field of view must be within (0, 180) degrees".into());
        }
        if self.width == 0 || self.height_px == 0 {
            return Err("image size must be at least 1x1".into());
        }
        Ok(())
    }

    /// The camera moved `d` texels forward along its heading.
    pub fn forward(&self, d: f64) -> Self {
        let yaw = self.yaw.to_radians();
        GroundCamera { x: self.x + d * yaw.sin(), y: self.y - d * yaw.cos(), ..*self }
    }

    /// Forward, right and up unit vectors.
    fn basis(&self) -> (V3, V3, V3) {
        let (p, y) = (self.pitch.to_radians(), self.yaw.to_radians());
        let f = [y.sin() * p.cos(), -y.cos() * p.cos(), -p.sin()];
        let r = [y.cos(), y.sin(), 0.0];
        let up = [f[1] * r[2] - f[2] * r[1], f[2] * r[0] - f[0] * r[2], f[0] * r[1] - f[1] * r[0]];
        (f, r, up)
    }

    /// Where the ray through screen position `(sx, sy)` (pixels, continuous) meets the plane.
    fn hit(&self, basis: &(V3, V3, V3), sx: f64, sy: f64) -> Option<(f64, f64)> {
        let (f, r, up) = basis;
        let t = (self.fov.to_radians() / 2.0).tan();
        let (w, h) = (self.width as f64, self.height_px as f64);
        let a = (2.0 * sx / w - 1.0) * t * w / h;
        let b = (1.0 - 2.0 * sy / h) * t;
        let d: Vec<f64> = (0..3).map(|i| f[i] + a * r[i] + b * up[i]).collect();
        if d[2] >= -1e-12 {
            return None;
        }
        let s = self.height / -d[2];
        Some((self.x + s * d[0], self.y + s * d[1]))
    }

    /// Per pixel, row-major: the footprint its centre sees, or `None` for sky. The level of
    /// detail is `log2` of the longer of the texture-space steps to the neighbouring pixel
    /// centres across it (horizontally and vertically); where a neighbour sees the sky the
    /// footprint is unbounded and the level is the coarsest (`f32::MAX`, clamped by the sampler).
    pub fn footprints(&self) -> Vec<Option<Footprint>> {
        let basis = self.basis();
        let mut out = Vec::with_capacity(self.width as usize * self.height_px as usize);
        for j in 0..self.height_px {
            for i in 0..self.width {
                let (cx, cy) = (i as f64 + 0.5, j as f64 + 0.5);
                let Some((u, v)) = self.hit(&basis, cx, cy) else {
                    out.push(None);
                    continue;
                };
                let span = |a: Option<(f64, f64)>, b: Option<(f64, f64)>| match (a, b) {
                    (Some(a), Some(b)) => ((a.0 - b.0).powi(2) + (a.1 - b.1).powi(2)).sqrt(),
                    _ => f64::INFINITY,
                };
                let dx = span(self.hit(&basis, cx + 0.5, cy), self.hit(&basis, cx - 0.5, cy));
                let dy = span(self.hit(&basis, cx, cy + 0.5), self.hit(&basis, cx, cy - 0.5));
                let rho = dx.max(dy);
                let lod = if rho.is_finite() { rho.max(1e-9).log2() as f32 } else { f32::MAX };
                out.push(Some(Footprint { u, v, lod }));
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn looking_straight_down_sees_the_plane_at_uniform_scale() {
        // 90° pitch, 90° lens, height 64: the image spans 128 texels over 128 pixels.
        let cam = GroundCamera { pitch: 90.0, fov: 90.0, ..GroundCamera::new(1000.0, -50.0, 64.0, 128, 128) };
        let fp = cam.footprints();
        assert!(fp.iter().all(|f| f.is_some()));
        let c = fp[64 * 128 + 64].unwrap();
        assert!((c.u - 1000.5).abs() < 1e-6 && (c.v - (-49.5)).abs() < 1e-6, "{c:?}");
        assert!(c.lod.abs() < 1e-3, "{c:?}");
    }

    #[test]
    fn level_view_has_sky_above_and_coarser_lods_towards_the_horizon() {
        let cam = GroundCamera { pitch: 0.0, ..GroundCamera::new(0.0, 0.0, 16.0, 64, 64) };
        let fp = cam.footprints();
        assert!(fp[..32 * 64].iter().all(|f| f.is_none()), "upper half is sky");
        let near = fp[63 * 64 + 32].unwrap().lod;
        let far = fp[33 * 64 + 32].unwrap().lod;
        assert!(far > near + 2.0, "near {near}, far {far}");
        assert!(fp[63 * 64 + 32].unwrap().v < 0.0, "yaw 0 looks north (−v)");
    }

    #[test]
    fn bad_cameras_are_refused() {
        let ok = GroundCamera::new(0.0, 0.0, 10.0, 8, 8);
        assert!(ok.check().is_ok());
        for bad in [
            GroundCamera { height: 0.0, ..ok },
            GroundCamera { fov: 180.0, ..ok },
            GroundCamera { pitch: 91.0, ..ok },
            GroundCamera { x: f64::NAN, ..ok },
            GroundCamera { width: 0, ..ok },
        ] {
            assert!(bad.check().is_err(), "{bad:?}");
        }
    }
}
