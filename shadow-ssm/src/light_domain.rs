//! The light as the visibility integrals of soft shadow mapping see it: its outline in the
//! shadow map's view plane (the light's centre at the origin, depth 0), the clipping of regions
//! to it, and the integral of the light's radiance over a region.
//!
//! * Back-projection (GBP06, BCS06 eq. 1) integrates axis-aligned rectangles clipped to the
//!   light ([`LightDomain::rect`]).
//! * Contours (GBP07 section 4.2) integrate radially from the light's centre: each oriented
//!   contour edge adds or removes the part of the light inside the wedge its end points span
//!   from the centre and beyond the edge ([`LightDomain::edge`], Fig. 5a, as penumbra wedges
//!   do, ADMAM03). The region is the light clipped by three half-planes, so any simple
//!   polygon light works, convex or not. An outline of many vertices that is star-shaped
//!   from the centre (a disk's 64-gon) first takes the wedge as a fan of the few vertices
//!   inside it, found by a binary search over their angles, and is clipped by the third
//!   half-plane only: the same region, without two passes over the whole outline.
//! * Textured rectangle lights (GBP07 section 8: edge integration fits textured planar lights)
//!   weight each region by the radiance over it: Green's theorem turns the area integral into
//!   the boundary integral of `F(u, v) = ∫_0^u L(s, v) ds`, tabulated on the light's uv square
//!   and integrated with Gauss-Legendre quadrature along the region's edges
//!   ([`RadianceTable`]). The visibility of a textured light is then
//!   `(1/A) ∫ L(x) vis(x) dx`, DCS eq. 2's limit for many samples.

use glam::{DAffine2, DVec2, DVec3, Vec2};
use shadow_core::clip::{Keep, clip_by_side};
use shadow_core::light::{AreaLight, LightGeometry};

/// Cells per side of a radiance table.
const TABLE_CELLS: usize = 64;

/// Area and radiance integrated over a region of the light.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Covered {
    /// Area (view-plane units).
    pub area: f64,
    /// Integral of the radiance over the area (zero unless the light is textured).
    pub radiance: DVec3,
}

impl std::ops::AddAssign for Covered {
    fn add_assign(&mut self, o: Self) {
        self.area += o.area;
        self.radiance += o.radiance;
    }
}

impl std::ops::SubAssign for Covered {
    fn sub_assign(&mut self, o: Self) {
        self.area -= o.area;
        self.radiance -= o.radiance;
    }
}

/// The light's outline in the shadow map's view plane and, for a textured light, its radiance.
#[derive(Debug, Clone)]
pub struct LightDomain {
    points: Vec<DVec2>,
    area: f64,
    /// The outline's bounding box, and whether the outline is that box (a rectangle light
    /// whose sides follow the map's axes): its rectangles are then clipped by two comparisons.
    bounds: (DVec2, DVec2),
    is_box: bool,
    /// The outline ordered by angle around the centre, when it is star-shaped from it with
    /// many vertices (a disk's 64-gon): [`LightDomain::edge`] then takes the few vertices
    /// inside an edge's wedge instead of clipping the whole outline.
    fan: Option<Fan>,
    texture: Option<RadianceTable>,
    full: Covered,
}

/// Outlines with more vertices than this are integrated by fans (see [`Fan`]); a rectangle's
/// four are cheaper to clip whole.
const FAN_MIN_VERTICES: usize = 8;

/// A star-shaped outline seen from the light's centre: its vertices counter-clockwise, each
/// edge turning counter-clockwise around the centre, once around in all. Every ray from the
/// centre then leaves the light through exactly one edge, and the light inside the wedge
/// between two directions is the fan of the centre, the two rays' exit points and the
/// vertices between them: the same region as the outline clipped by the wedge's two
/// half-planes, found by a binary search instead of two passes over the outline.
#[derive(Debug, Clone)]
struct Fan {
    /// Vertices, counter-clockwise.
    points: Vec<DVec2>,
    /// Each vertex's [`pseudo_angle`] less vertex 0's (`start`), increasing from 0 within
    /// `0..4`.
    turns: Vec<f64>,
    start: f64,
}

/// A number in `0..4` that increases with the direction's angle counter-clockwise from +x
/// (the "diamond angle"): it orders directions as their angles do, without a trigonometric
/// function.
fn pseudo_angle(d: DVec2) -> f64 {
    let p = d.y / (d.x.abs() + d.y.abs());
    if d.x >= 0.0 {
        if d.y >= 0.0 { p } else { 4.0 + p }
    } else {
        2.0 - p
    }
}

impl Fan {
    /// The fan of `points` (either orientation) when it is star-shaped from the origin.
    fn new(points: &[DVec2]) -> Option<Self> {
        let mut points = points.to_vec();
        if polygon_area(&points) < 0.0 {
            points.reverse();
        }
        let n = points.len();
        let start = pseudo_angle(points[0]);
        let mut turned = 0.0;
        for i in 0..n {
            let (p, q) = (points[i], points[(i + 1) % n]);
            if !(p.perp_dot(q) > 0.0) {
                return None;
            }
            turned += p.perp_dot(q).atan2(p.dot(q));
        }
        // Once around the centre, not twice.
        if (turned - std::f64::consts::TAU).abs() > 1e-9 {
            return None;
        }
        let turns: Vec<f64> = points
            .iter()
            .map(|&p| (pseudo_angle(p) - start).rem_euclid(4.0))
            .collect();
        turns.windows(2).all(|w| w[0] < w[1]).then_some(Self {
            points,
            turns,
            start,
        })
    }

    /// Where the ray from the origin along `d` leaves the outline through the edge from
    /// vertex `i`.
    fn exit(&self, i: usize, d: DVec2) -> DVec2 {
        let p = self.points[i];
        let e = self.points[(i + 1) % self.points.len()] - p;
        d * (p.perp_dot(e) / d.perp_dot(e))
    }

    /// Writes into `poly` the light inside the wedge from `a` counter-clockwise to `b` (less
    /// than half a turn).
    fn wedge(&self, a: DVec2, b: DVec2, poly: &mut Vec<DVec2>) {
        let n = self.points.len();
        // The edge `a`'s ray leaves through: the last vertex at or before its direction.
        let t = (pseudo_angle(a) - self.start).rem_euclid(4.0);
        let i = self.turns.partition_point(|&x| x <= t).max(1) - 1;
        poly.clear();
        poly.push(DVec2::ZERO);
        poly.push(self.exit(i, a));
        // The vertices strictly before `b`'s direction, in order: consecutive vertices turn
        // by less than half a turn and the wedge spans less than one, so the first vertex
        // not before `b` ends them.
        let mut last = i;
        for j in i + 1..i + 1 + n {
            let k = j % n;
            if !(self.points[k].perp_dot(b) > 0.0) {
                break;
            }
            poly.push(self.points[k]);
            last = k;
        }
        poly.push(self.exit(last, b));
    }
}

impl LightDomain {
    /// From outline points in view space (x, y; the light's centre at the origin).
    pub fn new(points: &[Vec2]) -> Self {
        let points: Vec<DVec2> = points.iter().map(|p| p.as_dvec2()).collect();
        let area = polygon_area(&points).abs();
        let lo = points.iter().copied().fold(DVec2::INFINITY, DVec2::min);
        let hi = points.iter().copied().fold(DVec2::NEG_INFINITY, DVec2::max);
        let box_area = (hi - lo).x * (hi - lo).y;
        // A convex outline with its bounding box's area is that box.
        let is_box = area > 0.0 && (box_area - area).abs() <= 1e-12 * box_area;
        let fan = (points.len() > FAN_MIN_VERTICES)
            .then(|| Fan::new(&points))
            .flatten();
        Self {
            bounds: (lo, hi),
            is_box,
            fan,
            full: Covered {
                area,
                radiance: DVec3::ZERO,
            },
            points,
            area,
            texture: None,
        }
    }

    /// Adds the radiance of a textured light; `uv_from_view` maps view-plane points to the
    /// light's uv.
    #[must_use]
    pub fn with_texture(mut self, table: RadianceTable) -> Self {
        self.full.radiance = table.integrate(&self.points);
        self.texture = Some(table);
        self
    }

    /// Area of the light.
    pub fn area(&self) -> f64 {
        self.area
    }

    /// The whole light: its area and radiance integral.
    pub fn full(&self) -> Covered {
        self.full
    }

    /// True when the radiance is integrated too.
    pub fn is_textured(&self) -> bool {
        self.texture.is_some()
    }

    fn covered(&self, poly: &[DVec2]) -> Covered {
        if poly.len() < 3 {
            return Covered::default();
        }
        Covered {
            area: polygon_area(poly).abs(),
            radiance: self
                .texture
                .as_ref()
                .map_or(DVec3::ZERO, |t| t.integrate(poly)),
        }
    }

    /// The light clipped to the axis-aligned rectangle `lo..hi` (empty when they miss).
    fn clip_rect(&self, lo: DVec2, hi: DVec2) -> Vec<DVec2> {
        if !(lo.x < hi.x && lo.y < hi.y) {
            return Vec::new();
        }
        let mut poly = self.points.clone();
        let mut scratch = Vec::with_capacity(poly.len() + 4);
        for (n, c) in [
            (DVec2::X, lo.x),
            (DVec2::NEG_X, -hi.x),
            (DVec2::Y, lo.y),
            (DVec2::NEG_Y, -hi.y),
        ] {
            clip(&mut poly, &mut scratch, n, c);
            if poly.len() < 3 {
                return Vec::new();
            }
        }
        poly
    }

    /// The area of a box outline inside `lo..hi`, when the outline is a box.
    fn box_overlap(&self, lo: DVec2, hi: DVec2) -> Option<f64> {
        if !self.is_box {
            return None;
        }
        let (a, b) = (lo.max(self.bounds.0), hi.min(self.bounds.1));
        Some(if a.x < b.x && a.y < b.y {
            (b.x - a.x) * (b.y - a.y)
        } else {
            0.0
        })
    }

    /// The light inside the axis-aligned rectangle `lo..hi`.
    pub fn rect(&self, lo: DVec2, hi: DVec2) -> Covered {
        if self.texture.is_none()
            && let Some(area) = self.box_overlap(lo, hi)
        {
            return Covered {
                area,
                radiance: DVec3::ZERO,
            };
        }
        self.covered(&self.clip_rect(lo, hi))
    }

    /// The light inside the rectangles `x0..x1` by each of the disjoint intervals `ys`: the
    /// light is clipped to the strip once, then to each interval.
    pub fn strip(&self, x0: f64, x1: f64, ys: &[(f64, f64)]) -> Covered {
        let mut sum = Covered::default();
        if self.texture.is_none() && self.is_box {
            for &(y0, y1) in ys {
                sum.area += self
                    .box_overlap(DVec2::new(x0, y0), DVec2::new(x1, y1))
                    .unwrap_or(0.0);
            }
            return sum;
        }
        if !(x0 < x1) {
            return sum;
        }
        let mut strip = self.points.clone();
        let mut scratch = Vec::with_capacity(strip.len() + 4);
        for (n, c) in [(DVec2::X, x0), (DVec2::NEG_X, -x1)] {
            clip(&mut strip, &mut scratch, n, c);
            if strip.len() < 3 {
                return sum;
            }
        }
        let mut poly = Vec::with_capacity(strip.len() + 2);
        for &(y0, y1) in ys {
            if !(y0 < y1) {
                continue;
            }
            poly.clear();
            poly.extend_from_slice(&strip);
            for (n, c) in [(DVec2::Y, y0), (DVec2::NEG_Y, -y1)] {
                clip(&mut poly, &mut scratch, n, c);
                if poly.len() < 3 {
                    break;
                }
            }
            sum += self.covered(&poly);
        }
        sum
    }

    /// Area of the light inside the axis-aligned rectangle `lo..hi`.
    pub fn clipped_area(&self, lo: DVec2, hi: DVec2) -> f64 {
        if let Some(area) = self.box_overlap(lo, hi) {
            return area;
        }
        let poly = self.clip_rect(lo, hi);
        if poly.len() < 3 {
            0.0
        } else {
            polygon_area(&poly).abs()
        }
    }

    /// The signed contribution of the oriented contour edge `a -> b` (view-plane points) to the
    /// occluded part of the light, for an occluder lying on the edge's right (`(b - a) x (o - a)
    /// < 0` for occluded points `o`): the light inside the wedge spanned by `a` and `b` from the
    /// centre and beyond the edge, counted positively when the edge turns counter-clockwise
    /// around the centre (the ray from the centre enters the occluder there) and negatively
    /// otherwise (GBP07 section 4.2, Fig. 5a). With the centre's own state as the start, the
    /// sum over a contour is the occluded part of the light.
    pub fn edge(
        &self,
        a: DVec2,
        b: DVec2,
        poly: &mut Vec<DVec2>,
        scratch: &mut Vec<DVec2>,
    ) -> Covered {
        let turn = a.perp_dot(b);
        if turn == 0.0 || !turn.is_finite() {
            return Covered::default();
        }
        let (a, b, sign) = if turn > 0.0 {
            (a, b, 1.0)
        } else {
            (b, a, -1.0)
        };
        // Now a -> b turns counter-clockwise: the wedge is {x: a x x >= 0, x x b >= 0}; beyond
        // the edge is the side of line ab away from the origin.
        let beyond = DVec2::new(b.y - a.y, a.x - b.x); // right normal of a -> b
        let wedge = if let Some(fan) = &self.fan {
            fan.wedge(a, b, poly);
            &[][..]
        } else {
            poly.clear();
            poly.extend_from_slice(&self.points);
            &[(a.perp(), 0.0), (-b.perp(), 0.0)][..]
        };
        for &(n, c) in wedge.iter().chain(&[(beyond, beyond.dot(a))]) {
            clip(poly, scratch, n, c);
            if poly.len() < 3 {
                return Covered::default();
            }
        }
        let mut c = self.covered(poly);
        c.area *= sign;
        c.radiance *= sign;
        c
    }
}

/// Clips `poly` to the half-plane `n . x >= c` (Sutherland-Hodgman; a concave subject gives
/// extra zero-area edges, never a wrong area).
fn clip(poly: &mut Vec<DVec2>, scratch: &mut Vec<DVec2>, n: DVec2, c: f64) {
    clip_by_side(poly, scratch, |x| n.dot(x) - c, Keep::NonNegative);
    std::mem::swap(poly, scratch);
}

/// Signed area of a polygon (positive counter-clockwise).
pub fn polygon_area(p: &[DVec2]) -> f64 {
    let n = p.len();
    let mut s = 0.0;
    for i in 0..n {
        s += p[i].perp_dot(p[(i + 1) % n]);
    }
    0.5 * s
}

/// The radiance of a textured rectangle light, ready for integration over polygons of its
/// plane: `F(u, v) = ∫_0^u L(s, v) ds` on a grid of the uv square, bilinearly interpolated.
#[derive(Debug, Clone)]
pub struct RadianceTable {
    /// `F` at `(i / n, j / n)`, `j` major, `n + 1` a side.
    f: Vec<DVec3>,
    uv_from_view: DAffine2,
    /// View-plane area of one unit of uv area.
    jacobian: f64,
}

impl RadianceTable {
    /// The table of a textured rectangle light seen in a view whose x and y axes are
    /// `view_x`, `view_y` (world directions); `None` for other lights or constant radiance.
    pub fn new(light: &dyn AreaLight, view_x: glam::Vec3, view_y: glam::Vec3) -> Option<Self> {
        if !light.is_textured() {
            return None;
        }
        let LightGeometry::Rectangle { half_u, half_v, .. } = light.geometry() else {
            return None;
        };
        let (hu, hv) = (half_u.as_dvec3(), half_v.as_dvec3());
        let (x, y) = (view_x.as_dvec3(), view_y.as_dvec3());
        // uv = 0.5 + 0.5 (d . hu / |hu|^2, d . hv / |hv|^2), d = x_view X + y_view Y.
        let (su, sv) = (0.5 / hu.length_squared(), 0.5 / hv.length_squared());
        let uv_from_view = DAffine2::from_cols(
            DVec2::new(x.dot(hu) * su, x.dot(hv) * sv),
            DVec2::new(y.dot(hu) * su, y.dot(hv) * sv),
            DVec2::splat(0.5),
        );
        let det = uv_from_view.matrix2.determinant().abs();
        if !(det > 0.0) {
            return None;
        }
        let n = TABLE_CELLS;
        // Each cell of a row integrated with 8 midpoint samples.
        const SUB: usize = 8;
        let radiance = light.radiance();
        let mut f = vec![DVec3::ZERO; (n + 1) * (n + 1)];
        for j in 0..=n {
            let v = j as f32 / n as f32;
            let mut acc = DVec3::ZERO;
            for i in 0..n {
                let mut cell = DVec3::ZERO;
                for k in 0..SUB {
                    let u = (i as f32 + (k as f32 + 0.5) / SUB as f32) / n as f32;
                    cell += radiance.at(Vec2::new(u, v)).as_dvec3();
                }
                acc += cell / (SUB * n) as f64;
                f[j * (n + 1) + i + 1] = acc;
            }
        }
        Some(Self {
            f,
            uv_from_view,
            jacobian: 1.0 / det,
        })
    }

    fn f_at(&self, uv: DVec2) -> DVec3 {
        let n = TABLE_CELLS;
        let (x, y) = (
            (uv.x.clamp(0.0, 1.0) * n as f64).min(n as f64 - 1e-9),
            (uv.y.clamp(0.0, 1.0) * n as f64).min(n as f64 - 1e-9),
        );
        let (i, j) = (x.floor() as usize, y.floor() as usize);
        let (fx, fy) = (x - i as f64, y - j as f64);
        let at = |i: usize, j: usize| self.f[j * (n + 1) + i];
        let top = at(i, j) * (1.0 - fx) + at(i + 1, j) * fx;
        let bottom = at(i, j + 1) * (1.0 - fx) + at(i + 1, j + 1) * fx;
        top * (1.0 - fy) + bottom * fy
    }

    /// The radiance integrated over a polygon of the view plane (its orientation does not
    /// matter): `∮ F dv` by 2-point Gauss-Legendre on pieces of at most one table cell.
    pub fn integrate(&self, poly: &[DVec2]) -> DVec3 {
        let g = 0.5 / 3f64.sqrt();
        let mut sum = DVec3::ZERO;
        let m = poly.len();
        for k in 0..m {
            let (a, b) = (
                self.uv_from_view.transform_point2(poly[k]),
                self.uv_from_view.transform_point2(poly[(k + 1) % m]),
            );
            let dv = b.y - a.y;
            if dv == 0.0 {
                continue;
            }
            let pieces =
                (((b - a).abs().max_element() * TABLE_CELLS as f64).ceil() as usize).max(1);
            let step = 1.0 / pieces as f64;
            let mut s = DVec3::ZERO;
            for p in 0..pieces {
                let t0 = p as f64 * step;
                for t in [t0 + step * (0.5 - g), t0 + step * (0.5 + g)] {
                    s += self.f_at(a + (b - a) * t);
                }
            }
            sum += s * (0.5 * step * dv);
        }
        (sum * self.jacobian).abs()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;
    use shadow_core::light::{Radiance, RectLight, TexturedRadiance};

    /// A fan-integrated outline (a disk's 64-gon, an off-centre star-shaped 12-gon, either
    /// orientation) gives every edge the area of the whole outline clipped by the wedge,
    /// and a closed contour around the centre the whole light.
    #[test]
    fn fan_edges_equal_clipped_outline_edges() {
        let disk: Vec<Vec2> = (0..64)
            .map(|k| {
                let t = std::f32::consts::TAU * k as f32 / 64.0;
                Vec2::new(0.7 * t.cos() + 0.05, 0.7 * t.sin() - 0.1)
            })
            .collect();
        let star: Vec<Vec2> = (0..12)
            .rev()
            .map(|k| {
                let t = std::f32::consts::TAU * k as f32 / 12.0;
                let r = if k % 2 == 0 { 1.0 } else { 0.45 };
                Vec2::new(r * t.cos() + 0.1, r * t.sin())
            })
            .collect();
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64 * 2.4 - 1.2
        };
        for outline in [disk, star] {
            let fan = LightDomain::new(&outline);
            assert!(fan.fan.is_some());
            let mut whole = fan.clone();
            whole.fan = None;
            let (mut poly, mut scratch) = (Vec::new(), Vec::new());
            for _ in 0..20_000 {
                let (a, b) = (DVec2::new(next(), next()), DVec2::new(next(), next()));
                let got = fan.edge(a, b, &mut poly, &mut scratch).area;
                let want = whole.edge(a, b, &mut poly, &mut scratch).area;
                assert!((got - want).abs() <= 1e-12, "{a} {b}: {got} {want}");
            }
            // A square contour around the centre, counter-clockwise, hides the light inside it.
            let c =
                [(-2.0, -2.0), (2.0, -2.0), (2.0, 2.0), (-2.0, 2.0)].map(|(x, y)| DVec2::new(x, y));
            let total: f64 = (0..4)
                .map(|i| fan.edge(c[i], c[(i + 1) % 4], &mut poly, &mut scratch).area)
                .sum();
            assert!(total.abs() < 1e-12, "{total}");
        }
    }

    fn square() -> LightDomain {
        LightDomain::new(&[
            Vec2::new(-0.5, -0.5),
            Vec2::new(0.5, -0.5),
            Vec2::new(0.5, 0.5),
            Vec2::new(-0.5, 0.5),
        ])
    }

    #[test]
    fn clipped_rectangles_of_a_square_light() {
        let l = square();
        assert!((l.area() - 1.0).abs() < 1e-12);
        let a = l.clipped_area(DVec2::new(0.0, 0.0), DVec2::new(2.0, 2.0));
        assert!((a - 0.25).abs() < 1e-12);
        let a = l.rect(DVec2::new(-0.1, -0.2), DVec2::new(0.1, 0.2)).area;
        assert!((a - 0.08).abs() < 1e-12);
        assert_eq!(
            l.clipped_area(DVec2::new(1.0, 1.0), DVec2::new(2.0, 2.0)),
            0.0
        );
    }

    /// A strip of intervals is the sum of its rectangles and of their polygon clips, on a box
    /// light (the fast path) and on a hexagon (clipped once to the strip, then to each
    /// interval).
    #[test]
    fn strips_are_the_sums_of_their_rectangles() {
        let hexagon: Vec<Vec2> = (0..6)
            .map(|k| {
                let a = k as f32 * std::f32::consts::TAU / 6.0;
                Vec2::new(0.5 * a.cos(), 0.5 * a.sin())
            })
            .collect();
        let ys = [(-0.6, -0.3), (-0.1, 0.05), (0.2, 0.7)];
        for l in [square(), LightDomain::new(&hexagon)] {
            for (x0, x1) in [(-0.7, -0.2), (-0.3, 0.4), (0.45, 0.9)] {
                let strip = l.strip(x0, x1, &ys).area;
                let sum: f64 = ys
                    .iter()
                    .map(|&(y0, y1)| l.rect(DVec2::new(x0, y0), DVec2::new(x1, y1)).area)
                    .sum();
                assert!((strip - sum).abs() < 1e-12, "{strip} against {sum}");
                let by_clip: f64 = ys
                    .iter()
                    .map(|&(y0, y1)| {
                        polygon_area(&l.clip_rect(DVec2::new(x0, y0), DVec2::new(x1, y1))).abs()
                    })
                    .sum();
                assert!((strip - by_clip).abs() < 1e-12, "{strip} against {by_clip}");
            }
        }
        assert!(square().is_box && !LightDomain::new(&hexagon).is_box);
    }

    /// GBP07 section 4.2: the radial integral of one edge is the light clipped to the wedge
    /// and beyond the edge, here checked against the clipped polygon worked by hand.
    #[test]
    fn radial_integral_of_one_edge_is_the_clipped_polygon_area() {
        let l = square();
        let (mut p, mut s) = (Vec::new(), Vec::new());
        // A horizontal edge at y = 0.25 from x = 0.25 to x = -0.25 (counter-clockwise around
        // the centre): the wedge beyond it is the trapezoid between y = 0.25 and y = 0.5 under
        // the rays through the end points, widths 0.5 and 1.0: area 0.25 * 0.75 = 0.1875.
        let c = l.edge(
            DVec2::new(0.25, 0.25),
            DVec2::new(-0.25, 0.25),
            &mut p,
            &mut s,
        );
        assert!((c.area - 0.1875).abs() < 1e-12, "{c:?}");
        // Reversed, the sign flips.
        let c = l.edge(
            DVec2::new(-0.25, 0.25),
            DVec2::new(0.25, 0.25),
            &mut p,
            &mut s,
        );
        assert!((c.area + 0.1875).abs() < 1e-12, "{c:?}");
        // An edge reaching past the light: its wedge spans nearly the upper half-plane, so it
        // covers the whole part of the light above it, 1 x 0.4.
        let c = l.edge(DVec2::new(2.0, 0.1), DVec2::new(-2.0, 0.1), &mut p, &mut s);
        assert!((c.area - 0.4).abs() < 1e-12, "{c:?}");
        // A short edge at the same height: the wedge from (0.2, 0.1) to (-0.1, 0.1) reaches
        // y = 0.5 at x = 1.0 and -0.5, clipped at x = 0.5: the trapezoid of widths 0.3 and 1.5
        // over 0.4 (0.36) minus the triangle beyond x = 0.5 (from y = 0.25, legs 0.25 and 0.5:
        // 0.0625).
        let c = l.edge(DVec2::new(0.2, 0.1), DVec2::new(-0.1, 0.1), &mut p, &mut s);
        assert!((c.area - 0.2975).abs() < 1e-12, "{c:?}");
        // An edge entirely outside the light adds nothing.
        let c = l.edge(DVec2::new(1.0, 1.0), DVec2::new(-1.0, 1.0), &mut p, &mut s);
        assert_eq!(c.area, 0.0);
    }

    /// A closed square contour (occluder on the right of each edge, i.e. clockwise) sums, with
    /// the centre's state as the start, to the occluded area, wherever it lies.
    #[test]
    fn a_closed_contour_integrates_to_its_clipped_area() {
        let l = square();
        let (mut p, mut s) = (Vec::new(), Vec::new());
        for (lo, hi, centre_inside) in [
            (DVec2::new(-0.2, -0.1), DVec2::new(0.3, 0.2), true),
            (DVec2::new(0.1, 0.1), DVec2::new(0.9, 0.3), false),
            (DVec2::new(-2.0, -0.3), DVec2::new(-0.25, 2.0), false),
            (DVec2::new(-2.0, -2.0), DVec2::new(2.0, 2.0), true),
        ] {
            // Clockwise: occluder on the right.
            let pts = [lo, DVec2::new(lo.x, hi.y), hi, DVec2::new(hi.x, lo.y)];
            let mut occluded = if centre_inside { l.area() } else { 0.0 };
            for k in 0..4 {
                occluded += l.edge(pts[k], pts[(k + 1) % 4], &mut p, &mut s).area;
            }
            let want = l.clipped_area(lo, hi);
            assert!(
                (occluded - want).abs() < 1e-12,
                "{lo} {hi}: {occluded} vs {want}"
            );
        }
    }

    #[test]
    fn radiance_integral_matches_a_fine_sum() {
        let mut texels = Vec::new();
        for y in 0..4 {
            for x in 0..4 {
                texels.push(Vec3::new(x as f32, y as f32, 1.0 + (x * y) as f32));
            }
        }
        let tex = TexturedRadiance::new(4, 4, texels, Vec3::ONE, glam::Affine2::IDENTITY).unwrap();
        let light = RectLight::facing(
            Vec3::new(0.0, 2.0, 0.0),
            Vec3::NEG_Y,
            2.0,
            1.0,
            Radiance::Textured(tex),
        )
        .unwrap();
        let LightGeometry::Rectangle { half_u, half_v, .. } = light.geometry() else {
            unreachable!()
        };
        // A view whose axes are the light's own, rotated by 30 degrees.
        let (a, b) = (half_u.normalize(), half_v.normalize());
        let (c, s) = (30f32.to_radians().cos(), 30f32.to_radians().sin());
        let (vx, vy) = (a * c + b * s, b * c - a * s);
        let table = RadianceTable::new(&light, vx, vy).unwrap();
        let tri = [
            DVec2::new(-0.6, -0.3),
            DVec2::new(0.7, -0.2),
            DVec2::new(0.1, 0.4),
        ];
        let got = table.integrate(&tri);
        // Brute force: midpoint sum on a fine grid of the triangle's bounds.
        let n = 600;
        let mut want = DVec3::ZERO;
        let (lo, hi) = (DVec2::new(-0.6, -0.3), DVec2::new(0.7, 0.4));
        let cell = (hi - lo) / n as f64;
        let inside =
            |p: DVec2| (0..3).all(|k| (tri[(k + 1) % 3] - tri[k]).perp_dot(p - tri[k]) >= 0.0);
        for j in 0..n {
            for i in 0..n {
                let p = lo + cell * DVec2::new(i as f64 + 0.5, j as f64 + 0.5);
                if inside(p) {
                    let w = light.center().as_dvec3() + vx.as_dvec3() * p.x + vy.as_dvec3() * p.y;
                    let uv = light.uv_of(w.as_vec3());
                    want += light.radiance().at(uv).as_dvec3() * cell.x * cell.y;
                }
            }
        }
        assert!(
            (got - want).abs().max_element() < 2e-3 * want.max_element(),
            "{got} vs {want}"
        );
    }
}
