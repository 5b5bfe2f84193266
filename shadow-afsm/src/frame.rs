//! The light frustum fitted to the view samples (section 4.3, "Parametrization"): a
//! perspective projection from the light's centre along the mean direction of the listed view
//! samples, cropped to the axis-aligned box of their projections, with the far plane at the
//! farthest one. The map is refitted for every batch of view samples, as the paper readapts
//! the frustum between passes.

use glam::Vec3;

use crate::params::Params;

/// Why no single frustum holds the view samples.
#[derive(Debug, Clone, PartialEq)]
pub struct FrameError(pub String);

/// A fitted light frustum and its texel mapping.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MapFrame {
    /// Light centre (the projection's apex).
    pub center: Vec3,
    /// Map plane axes.
    pub u: Vec3,
    /// Second map plane axis.
    pub v: Vec3,
    /// Frustum axis.
    pub d: Vec3,
    /// Largest depth of a view sample along `d`.
    pub far: f32,
    /// Projected box origin.
    pub origin: glam::Vec2,
    /// Texels per projected unit.
    pub scale: glam::Vec2,
    /// Map side in texels.
    pub side: u32,
}

impl MapFrame {
    /// Fits a `side` x `side` map around `points` (the listed view samples' origins) seen
    /// from `center`.
    ///
    /// # Errors
    /// [`FrameError`] when the points are empty or span a hemisphere around the centre (no
    /// single perspective frustum holds them).
    pub fn fit(center: Vec3, points: &[Vec3], side: u32) -> Result<Self, FrameError> {
        let mut sum = Vec3::ZERO;
        for p in points {
            let q = *p - center;
            let l = q.length();
            if l > 0.0 {
                sum += q / l;
            }
        }
        let d = sum.normalize_or_zero();
        if points.is_empty() || d == Vec3::ZERO {
            return Err(FrameError(
                "no view sample away from the light centre".into(),
            ));
        }
        let u = d.any_orthonormal_vector();
        let v = d.cross(u);
        let (mut zmin, mut zmax) = (f32::MAX, 0.0f32);
        let (mut lo, mut hi) = (glam::Vec2::splat(f32::MAX), glam::Vec2::splat(f32::MIN));
        for p in points {
            let q = *p - center;
            let z = q.dot(d);
            zmin = zmin.min(z / q.length().max(f32::MIN_POSITIVE));
            zmax = zmax.max(z);
            if z > 0.0 {
                let xy = glam::Vec2::new(q.dot(u), q.dot(v)) / z;
                lo = lo.min(xy);
                hi = hi.max(xy);
            }
        }
        // Cosine of the widest angle from the axis: below ~0.02 (89 degrees) the projection
        // degenerates.
        if !(zmin > 0.02) {
            return Err(FrameError(format!(
                "view samples span {:.0} degrees from the frustum axis around the light centre; one \
                 perspective shadow map cannot hold their lists",
                zmin.clamp(-1.0, 1.0).acos().to_degrees()
            )));
        }
        let ext = (hi - lo).max(glam::Vec2::splat(1e-6));
        // A hair of margin so the farthest samples fall inside the last texel.
        let pad = ext * 1e-4;
        let origin = lo - pad;
        let scale = glam::Vec2::splat(side as f32) / (ext + 2.0 * pad);
        Ok(Self {
            center,
            u,
            v,
            d,
            far: zmax * (1.0 + 1e-5),
            origin,
            scale,
            side,
        })
    }

    /// Projected coordinates and depth of `p` (`project` in `common.wgsl`).
    pub fn project(&self, p: Vec3) -> Vec3 {
        let q = p - self.center;
        let z = q.dot(self.d);
        Vec3::new(q.dot(self.u) / z, q.dot(self.v) / z, z)
    }

    /// Continuous texel coordinates of projected coordinates.
    pub fn to_texel(&self, xy: glam::Vec2) -> glam::Vec2 {
        (xy - self.origin) * self.scale
    }

    /// The texel index of `p` (clamped into the map).
    pub fn texel(&self, p: Vec3) -> u32 {
        let t = self.to_texel(self.project(p).truncate());
        let m = (self.side - 1) as f32;
        let (x, y) = (t.x.floor().clamp(0.0, m), t.y.floor().clamp(0.0, m));
        y as u32 * self.side + x as u32
    }

    /// Writes the frame's part of `params`.
    pub fn write(&self, params: &mut Params) {
        let v4 = |v: Vec3, w: f32| [v.x, v.y, v.z, w];
        params.center = v4(self.center, 1.0);
        params.axis_u = v4(self.u, 0.0);
        params.axis_v = v4(self.v, 0.0);
        params.axis_d = v4(self.d, self.far);
        params.map = [self.origin.x, self.origin.y, self.scale.x, self.scale.y];
        params.dims[0] = self.side;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fitted_map_holds_every_point_and_refuses_a_hemisphere() {
        let c = Vec3::new(0.0, 2.0, 0.0);
        let pts: Vec<Vec3> = (0..100)
            .map(|k| Vec3::new((k % 10) as f32 - 4.5, 0.0, (k / 10) as f32 - 4.5))
            .collect();
        let f = MapFrame::fit(c, &pts, 64).unwrap();
        for p in &pts {
            let t = f.to_texel(f.project(*p).truncate());
            assert!(t.x >= 0.0 && t.y >= 0.0 && t.x < 64.0 && t.y < 64.0, "{t}");
            assert!(f.project(*p).z <= f.far);
        }
        // Corner points land in corner texels: the box is tight.
        let ts: Vec<u32> = pts.iter().map(|p| f.texel(*p)).collect();
        let (xs, ys): (Vec<u32>, Vec<u32>) = ts.iter().map(|t| (t % 64, t / 64)).unzip();
        assert_eq!(
            (*xs.iter().min().unwrap(), *xs.iter().max().unwrap()),
            (0, 63)
        );
        assert_eq!(
            (*ys.iter().min().unwrap(), *ys.iter().max().unwrap()),
            (0, 63)
        );
        let around = [
            Vec3::new(5.0, 2.0, 0.0),
            Vec3::new(-5.0, 2.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
        ];
        assert!(MapFrame::fit(c, &around, 64).is_err());
    }
}
