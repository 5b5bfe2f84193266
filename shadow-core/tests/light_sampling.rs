//! Light sampling: samples lie on the light, are area-uniform (chi-square over equal-area
//! cells), reproducible by seed, stratified as promised, and uniform over concave polygons.

use std::f32::consts::PI;

use glam::{UVec2, Vec2, Vec3};
use shadow_core::light::TexturedRadiance;
use shadow_core::prelude::*;
use shadow_core::sampling::{MAX_SAMPLES, hash_words, unit_float};

fn white() -> Radiance {
    Radiance::Constant(Vec3::ONE)
}

/// Independent uniform points of the unit square.
fn uniform(n: usize, seed: u64) -> Vec<Vec2> {
    (0..n)
        .map(|i| {
            let h = hash_words(&[seed, i as u64]);
            Vec2::new(unit_float(h), unit_float(hash_words(&[h])))
        })
        .collect()
}

/// Chi-square statistic of `counts` against equal expectation.
fn chi_square(counts: &[u32]) -> f64 {
    let n: u32 = counts.iter().sum();
    let e = n as f64 / counts.len() as f64;
    counts.iter().map(|&c| (c as f64 - e).powi(2) / e).sum()
}

/// 99.9% quantile of chi-square with `df` degrees of freedom (Wilson-Hilferty).
fn chi_square_limit(df: usize) -> f64 {
    let k = df as f64;
    let z = 3.09;
    k * (1.0 - 2.0 / (9.0 * k) + z * (2.0 / (9.0 * k)).sqrt()).powi(3)
}

const N: usize = 64_000;

#[test]
fn rectangle_samples_are_on_the_light_and_uniform() {
    let l = RectLight::facing(
        Vec3::new(1.0, 2.0, 3.0),
        Vec3::new(0.3, -1.0, 0.2),
        2.0,
        0.5,
        white(),
    )
    .unwrap();
    let (c, hu, hv) = match l.geometry() {
        shadow_core::light::LightGeometry::Rectangle {
            center,
            half_u,
            half_v,
            ..
        } => (center, half_u, half_v),
        _ => unreachable!(),
    };
    let mut counts = vec![0u32; 64];
    for u in uniform(N, 1) {
        let s = l.sample(u);
        let d = s.position - c;
        let (a, b) = (
            d.dot(hu) / hu.length_squared(),
            d.dot(hv) / hv.length_squared(),
        );
        assert!(a.abs() <= 1.0 + 1e-5 && b.abs() <= 1.0 + 1e-5);
        assert!(d.dot(s.normal).abs() < 1e-5);
        let (i, j) = (
            (((a + 1.0) * 4.0) as usize).min(7),
            (((b + 1.0) * 4.0) as usize).min(7),
        );
        counts[j * 8 + i] += 1;
    }
    assert!(
        chi_square(&counts) < chi_square_limit(63),
        "{}",
        chi_square(&counts)
    );
}

#[test]
fn disk_samples_are_uniform_over_equal_area_cells() {
    let l = DiskLight::new(Vec3::ZERO, Vec3::Y, 0.5, white()).unwrap();
    // 8 rings of equal area x 8 sectors.
    let mut counts = vec![0u32; 64];
    for u in uniform(N, 2) {
        let p = l.sample(u).position;
        assert!(p.y.abs() < 1e-6 && Vec2::new(p.x, p.z).length() <= 0.5 + 1e-5);
        let r2 = (p.x * p.x + p.z * p.z) / 0.25;
        let ring = ((r2 * 8.0) as usize).min(7);
        let sector = (((p.z.atan2(p.x) + PI) / (2.0 * PI) * 8.0) as usize).min(7);
        counts[ring * 8 + sector] += 1;
    }
    assert!(
        chi_square(&counts) < chi_square_limit(63),
        "{}",
        chi_square(&counts)
    );
}

#[test]
fn sphere_samples_are_uniform_over_equal_area_cells() {
    let l = SphereLight::new(Vec3::ONE, 2.0, white()).unwrap();
    let mut counts = vec![0u32; 64];
    for u in uniform(N, 3) {
        let s = l.sample(u);
        let d = s.position - Vec3::ONE;
        assert!((d.length() - 2.0).abs() < 1e-5);
        assert!((s.normal - d / 2.0).length() < 1e-5);
        // Archimedes: equal-height bands have equal area.
        let band = (((d.y / 2.0 + 1.0) * 4.0) as usize).min(7);
        let sector = (((d.z.atan2(d.x) + PI) / (2.0 * PI) * 8.0) as usize).min(7);
        counts[band * 8 + sector] += 1;
    }
    assert!(
        chi_square(&counts) < chi_square_limit(63),
        "{}",
        chi_square(&counts)
    );
}

#[test]
fn concave_polygon_samples_are_uniform() {
    // L shape of three unit squares in the plane y = 1; 12 cells of 0.5 x 0.5 inside it.
    let outline: Vec<Vec3> = [
        (0.0, 0.0),
        (0.0, 2.0),
        (1.0, 2.0),
        (1.0, 1.0),
        (2.0, 1.0),
        (2.0, 0.0),
    ]
    .iter()
    .map(|&(x, z)| Vec3::new(x, 1.0, z))
    .collect();
    let l = PolygonLight::new(outline, white()).unwrap();
    assert!((l.area() - 3.0).abs() < 1e-5);
    let mut counts = std::collections::BTreeMap::new();
    for u in uniform(N, 4) {
        let p = l.sample(u).position;
        assert!((p.y - 1.0).abs() < 1e-5);
        let inside = (0.0..=2.0).contains(&p.x)
            && (0.0..=2.0).contains(&p.z)
            && !(p.x > 1.0 + 1e-5 && p.z > 1.0 + 1e-5);
        assert!(inside, "{p:?} outside the L");
        let cell = (((p.x * 2.0) as u32).min(3), ((p.z * 2.0) as u32).min(3));
        *counts.entry(cell).or_insert(0u32) += 1;
    }
    assert_eq!(counts.len(), 12);
    let c: Vec<u32> = counts.values().copied().collect();
    assert!(chi_square(&c) < chi_square_limit(11), "{}", chi_square(&c));
}

#[test]
fn samplers_are_reproducible_by_seed() {
    for strategy in [
        SamplingStrategy::Correlated,
        SamplingStrategy::Decorrelated,
        SamplingStrategy::Stratified,
        SamplingStrategy::Interleaved { tile: 4 },
    ] {
        let a = LightSampler::new(strategy, 64, 9).unwrap();
        let b = LightSampler::new(strategy, 64, 9).unwrap();
        let c = LightSampler::new(strategy, 64, 10).unwrap();
        let (mut sa, mut sb, mut sc) = (Vec::new(), Vec::new(), Vec::new());
        a.unit_samples(UVec2::new(5, 7), &mut sa);
        b.unit_samples(UVec2::new(5, 7), &mut sb);
        c.unit_samples(UVec2::new(5, 7), &mut sc);
        assert_eq!(sa, sb, "{strategy:?}");
        assert_ne!(sa, sc, "{strategy:?}");
        assert!(
            sa.iter()
                .all(|u| u.x >= 0.0 && u.x < 1.0 && u.y >= 0.0 && u.y < 1.0)
        );
    }
}

fn one_per_cell(samples: &[Vec2], grid: UVec2, shift: Vec2) -> bool {
    let mut seen = vec![false; (grid.x * grid.y) as usize];
    for u in samples {
        let s = *u - shift;
        let s = s - s.floor();
        let (i, j) = (
            ((s.x * grid.x as f32) as u32).min(grid.x - 1),
            ((s.y * grid.y as f32) as u32).min(grid.y - 1),
        );
        let k = (j * grid.x + i) as usize;
        if seen[k] {
            return false;
        }
        seen[k] = true;
    }
    seen.iter().all(|&s| s)
}

#[test]
fn stratification_holds_for_every_strategy() {
    for count in [1, 16, 64, 128, 1024] {
        let strat = LightSampler::new(SamplingStrategy::Stratified, count, 3).unwrap();
        let mut s = Vec::new();
        for px in [UVec2::ZERO, UVec2::new(17, 3)] {
            strat.unit_samples(px, &mut s);
            assert_eq!(s.len(), count as usize);
            assert!(
                one_per_cell(&s, strat.grid(), Vec2::ZERO),
                "stratified {count}"
            );
        }
    }
    // Correlated: the same set everywhere; interleaved: repeats with the tile period.
    let corr = LightSampler::new(SamplingStrategy::Correlated, 64, 3).unwrap();
    let (mut a, mut b) = (Vec::new(), Vec::new());
    corr.unit_samples(UVec2::new(0, 0), &mut a);
    corr.unit_samples(UVec2::new(40, 9), &mut b);
    assert_eq!(a, b);
    assert!(one_per_cell(&a, corr.grid(), Vec2::ZERO));
    let il = LightSampler::new(SamplingStrategy::Interleaved { tile: 3 }, 64, 3).unwrap();
    il.unit_samples(UVec2::new(1, 2), &mut a);
    il.unit_samples(UVec2::new(4, 8), &mut b);
    assert_eq!(a, b);
    il.unit_samples(UVec2::new(2, 2), &mut b);
    assert_ne!(a, b);
    assert!(one_per_cell(&a, il.grid(), Vec2::ZERO) && one_per_cell(&b, il.grid(), Vec2::ZERO));
    // Decorrelated: a toroidal shift of the correlated set, different per pixel, still one
    // sample per (shifted) cell.
    let dec = LightSampler::new(SamplingStrategy::Decorrelated, 64, 3).unwrap();
    dec.unit_samples(UVec2::new(0, 0), &mut a);
    dec.unit_samples(UVec2::new(1, 0), &mut b);
    assert_ne!(a, b);
    let mut base = Vec::new();
    LightSampler::new(SamplingStrategy::Correlated, 64, 3)
        .unwrap()
        .unit_samples(UVec2::ZERO, &mut base);
    let shift = a[0] - base[0];
    assert!(one_per_cell(&a, dec.grid(), shift - shift.floor()));
}

#[test]
fn sample_counts_span_one_to_many() {
    assert!(LightSampler::new(SamplingStrategy::Stratified, 1, 0).is_ok());
    assert!(LightSampler::new(SamplingStrategy::Stratified, 4096, 0).is_ok());
    assert!(LightSampler::new(SamplingStrategy::Stratified, MAX_SAMPLES, 0).is_ok());
    // Light samples carry the light's radiance and lie on the light.
    let l = RectLight::facing(
        Vec3::ZERO,
        Vec3::Y,
        1.0,
        1.0,
        Radiance::Constant(Vec3::new(2.0, 1.0, 0.5)),
    )
    .unwrap();
    let s = LightSampler::new(SamplingStrategy::Stratified, 1024, 1).unwrap();
    let mut out = Vec::new();
    s.light_samples(&l, UVec2::new(3, 3), &mut out);
    assert_eq!(out.len(), 1024);
    assert!(
        out.iter()
            .all(|x| x.position.y.abs() < 1e-6 && x.radiance == Vec3::new(2.0, 1.0, 0.5))
    );
    // A point light is the zero-size limit: every sample at the point.
    let p = PointLight::new(Vec3::ONE, Radiance::Constant(Vec3::ONE)).unwrap();
    s.light_samples(&p, UVec2::ZERO, &mut out);
    assert!(out.iter().all(|x| x.position == Vec3::ONE));
    assert_eq!(p.area(), 0.0);
}

/// `bounding_quad`: a rectangle's own corners; a 12-gon (tilted) inside its quad, in the
/// polygon's plane, touching every side; none for spheres.
#[test]
fn bounding_quads_hold_their_lights() {
    let r = Radiance::constant(Vec3::ONE).unwrap();
    let rect =
        RectLight::facing(Vec3::new(0.0, 2.0, 0.0), Vec3::NEG_Y, 1.0, 0.5, r.clone()).unwrap();
    let q = rect.geometry().bounding_quad().unwrap();
    for c in q {
        let d = c - Vec3::new(0.0, 2.0, 0.0);
        assert!(
            (d.x.abs() - 0.5).abs() < 1e-6 || (d.x.abs() - 0.25).abs() < 1e-6,
            "{c}"
        );
        assert!(d.y.abs() < 1e-6);
    }
    let outline: Vec<Vec3> = (0..12)
        .map(|k| {
            let a = k as f32 * std::f32::consts::TAU / 12.0;
            Vec3::new(a.cos(), 1.0 + 0.3 * a.cos(), a.sin())
        })
        .collect();
    let poly = PolygonLight::new(outline.clone(), r.clone()).unwrap();
    let q = poly.geometry().bounding_quad().unwrap();
    let (e1, e2) = (q[1] - q[0], q[3] - q[0]);
    assert!(e1.dot(e2).abs() < 1e-4, "a rectangle");
    let n = e1.cross(e2).normalize();
    let (mut lo, mut hi) = (glam::Vec2::splat(f32::MAX), glam::Vec2::splat(f32::MIN));
    for p in &outline {
        let d = *p - q[0];
        assert!(d.dot(n).abs() < 1e-4, "in the plane");
        let uv = glam::Vec2::new(
            d.dot(e1) / e1.length_squared(),
            d.dot(e2) / e2.length_squared(),
        );
        lo = lo.min(uv);
        hi = hi.max(uv);
    }
    assert!(
        lo.abs().max_element() < 1e-4 && (hi - 1.0).abs().max_element() < 1e-4,
        "{lo} {hi}"
    );
    let sphere = SphereLight::new(Vec3::ZERO, 0.5, r).unwrap();
    assert!(sphere.geometry().bounding_quad().is_none());
}

/// A set's samples (`sample_into`) and radiances (`radiances_into`) equal the single samples
/// of [`AreaLight::sample`], for every light kind, with constant and textured radiance.
#[test]
fn set_samples_and_radiances_equal_single_samples() {
    let texels: Vec<Vec3> = (0..12)
        .map(|k| Vec3::new(k as f32, (k * 5 % 7) as f32, 1.0 + (k % 3) as f32))
        .collect();
    let textured = Radiance::Textured(
        TexturedRadiance::new(
            4,
            3,
            texels,
            Vec3::new(1.0, 0.5, 2.0),
            glam::Affine2::from_scale(Vec2::new(1.5, -2.0)),
        )
        .unwrap(),
    );
    let square =
        [(0.0, 0.0), (0.0, 1.0), (1.0, 1.0), (1.0, 0.0)].map(|(x, z)| Vec3::new(x, 1.0, z));
    let units = uniform(500, 11);
    for radiance in [Radiance::Constant(Vec3::new(2.0, 1.0, 0.5)), textured] {
        let lights: Vec<Box<dyn AreaLight>> = vec![
            Box::new(RectLight::new(Vec3::Y, Vec3::X, Vec3::Z, radiance.clone()).unwrap()),
            Box::new(DiskLight::new(Vec3::Y, Vec3::NEG_Y, 0.5, radiance.clone()).unwrap()),
            Box::new(SphereLight::new(Vec3::Y, 0.5, radiance.clone()).unwrap()),
            Box::new(PolygonLight::new(square.to_vec(), radiance.clone()).unwrap()),
        ];
        for l in &lights {
            let (mut set, mut radiances) = (vec![], vec![]);
            l.sample_into(&units, &mut set);
            l.radiances_into(&units, &mut radiances);
            assert_eq!(set.len(), units.len());
            assert_eq!(radiances.len(), units.len());
            for ((s, r), u) in set.iter().zip(&radiances).zip(&units) {
                let one = l.sample(*u);
                assert_eq!(*s, one, "{l:?} at {u}");
                assert_eq!(*r, one.radiance, "{l:?} at {u}");
                assert_eq!(one.radiance, l.radiance().at(one.uv));
            }
        }
    }
}
