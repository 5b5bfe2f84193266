//! Light-space multi-resolution (GBP07 section 5.1): contours are extracted from the pyramid
//! level whose kernel stays under `t_k` texels, so the cost per receiver is bounded.
//!
//! * Level (eq. 2): `lod = ceil(log2(w_k / t_k))` bounds the kernel; following the paper's
//!   pseudo-code the level actually used is `floor(λ)` below, forced coarser only when the
//!   conservative kernel would exceed [`SAFETY`]` x t_k` texels there.
//! * Continuous level (eq. 3): `λ = log2(w̃_k / t_k)`, where `w̃_k` is eq. 1 with the
//!   occluder depth `z_occ` filtered bilinearly from the pyramid's min depths at level
//!   `floor(log2 w_k)` (each tap clamped to the receiver's depth, so missing occluders count as
//!   no penumbra). It is a hint for smoothing only; the kernel stays the conservative one.
//! * Blending: the visibility is computed at `floor(λ)` and, within `β` of a transition, blended
//!   with the neighbouring level as in the paper's pseudo-code, like trilinear mipmapping.
//! * Shrink correction: coarse levels hold min depths, which grow foreground occluders; their
//!   contours are built with `t = 1` (Fig. 7c), level 0 with the configured `t`.

use crate::contours::{self, MapFrame, MapLevel, Receiver, Scratch};
use crate::hierarchy::MinMaxPyramid;
use crate::light_domain::{Covered, LightDomain};
use crate::shadow_map::ShadowMap;

/// How far past `t_k` the conservative kernel may reach on the level the smooth hint chose
/// before a coarser level is forced.
pub const SAFETY: f64 = 4.0;

/// Settings of contour integration with light-space multi-resolution.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Contours {
    /// Contour parameter `t` on level 0 (GBP07 recommends 0).
    pub t: f32,
    /// Kernel size threshold `t_k` of eq. 2, in texels of the level used.
    pub max_kernel: f64,
    /// Width `β` of the blending band between levels (GBP07 suggests 0.05).
    pub beta: f64,
}

/// What one receiver's contour integration did.
#[derive(Debug, Clone, Copy, Default)]
pub struct Work {
    /// Contour edges integrated.
    pub edges: u64,
    /// Levels evaluated (2 inside a blending band).
    pub levels: u64,
    /// The main level used.
    pub lod: u32,
}

/// GBP07 eq. 3's smoothed occluder depth at a receiver whose conservative kernel is `w_k`.
pub fn occluder_depth(pyramid: &MinMaxPyramid, w_k: f64, x: f64, y: f64, z: f32) -> f32 {
    let k = if w_k > 1.0 {
        w_k.log2().floor() as usize
    } else {
        0
    };
    pyramid.filtered_min(k, x, y, z)
}

impl Contours {
    /// The continuous level `λ` (eq. 3) for the smoothed occluder depth `z_occ`.
    pub fn lambda(&self, sm: &ShadowMap, light_width: f32, z_occ: f32, z: f32) -> f64 {
        let w = sm.kernel_width(light_width, z_occ, z);
        if w > 0.0 {
            (w / self.max_kernel).log2()
        } else {
            f64::NEG_INFINITY
        }
    }

    /// The occluded part of the light for receiver `r` whose conservative kernel is `w_k`
    /// texels and whose continuous level is `lambda`.
    #[expect(
        clippy::too_many_arguments,
        reason = "one occlusion test reads the pyramid level, the receiver and its kernel together"
    )]
    pub fn occluded(
        &self,
        pyramid: &MinMaxPyramid,
        frame: &MapFrame,
        r: &Receiver,
        w_k: f64,
        lambda: f64,
        light: &LightDomain,
        scratch: &mut Scratch,
    ) -> (Covered, Work) {
        let top = pyramid.level_count() as i64 - 1;
        // The level follows the smooth hint (the paper's pseudo-code), but never leaves more
        // than `SAFETY x t_k` texels of the conservative kernel on a level (eq. 2's bound,
        // relaxed so blending can act).
        let needed = if w_k > SAFETY * self.max_kernel {
            (w_k / (SAFETY * self.max_kernel)).log2().ceil() as i64
        } else {
            0
        };
        let lod_f = if lambda.is_finite() { lambda } else { 0.0 };
        let lod = (lod_f.floor() as i64).clamp(0, top);
        let mut work = Work {
            lod: lod.max(needed).min(top) as u32,
            ..Work::default()
        };
        let mut vis = |k: i64, work: &mut Work| -> Covered {
            let k = k.clamp(0, top) as usize;
            let (side, depth) = pyramid.level(k);
            let level = MapLevel {
                side,
                depth,
                scale: (1u64 << k) as f64,
            };
            let t = if k == 0 { self.t as f64 } else { 1.0 };
            let (c, e) = contours::occluded(&level, frame, r, w_k, t, light, scratch);
            work.edges += e;
            work.levels += 1;
            c
        };
        let base = work.lod as i64;
        let main = vis(base, &mut work);
        // Blend only when the main level follows the smooth hint (eq. 2 did not force it).
        if base != lod || !lambda.is_finite() || lambda < 0.0 {
            return (main, work);
        }
        let d = lambda - lod as f64;
        let (other, weight) = if d < self.beta && lod > 0 {
            (lod - 1, 0.5 * (1.0 - d / self.beta))
        } else if 1.0 - d < self.beta && lod < top {
            (lod + 1, 0.5 * (1.0 - (1.0 - d) / self.beta))
        } else {
            return (main, work);
        };
        if other < needed {
            return (main, work);
        }
        let o = vis(other, &mut work);
        let lerp = |a: f64, b: f64| a + (b - a) * weight;
        (
            Covered {
                area: lerp(main.area, o.area),
                radiance: main.radiance + (o.radiance - main.radiance) * weight,
            },
            work,
        )
    }
}
