//! The angular index against the exact test on every sample.

use super::*;
use crate::stages::coverage::RelativeSamples;
use crate::stages::light_shape::LightShape;
use glam::DVec3;
use shadow_core::light::AreaLight;
use shadow_core::light::{Radiance, RectLight};
use shadow_core::sampling::{LightSampler, SamplingStrategy, hash_words, unit_float};

/// Four directions' pseudo-angles and buckets at once equal those one by one, at the
/// axes, at the zero vector, at NaN and infinities, and at pseudo-angles on either side of
/// every bucket's border.
#[test]
fn four_buckets_at_once_equal_one_by_one() {
    let mut dirs: Vec<(f32, f32)> = vec![
        (1.0, 0.0),
        (0.0, 1.0),
        (-1.0, 0.0),
        (0.0, -1.0),
        (0.0, 0.0),
        (-0.0, -0.0),
        (1.0, -1e-30),
        (f32::NAN, 1.0),
        (f32::INFINITY, 1.0),
        (3.0, f32::NEG_INFINITY),
    ];
    dirs.extend((0..4000u64).map(|k| {
        let r = |i: u64| unit_float(hash_words(&[k, i])) * 2.0 - 1.0;
        (r(0), r(1) * 10f32.powi((k % 7) as i32 - 3))
    }));
    for q in dirs.chunks(4) {
        let mut four = [(0.0f32, 0.0f32); 4];
        four[..q.len()].copy_from_slice(q);
        let (x, y) = (four.map(|d| d.0), four.map(|d| d.1));
        let a = direction_angles(Vec4::from(x), Vec4::from(y));
        for j in 0..4 {
            let one = direction_angle(x[j], y[j]);
            assert_eq!(a[j].to_bits(), one.to_bits(), "{:?}", four[j]);
            assert_eq!(buckets(a)[j], bucket(one), "{:?}", four[j]);
        }
    }
    // Pseudo-angles around every border, below 0, at and above a whole turn, NaN.
    let step = TURN / BUCKETS as f32;
    let mut angles: Vec<f32> = (0..=BUCKETS)
        .flat_map(|b| {
            let a = b as f32 * step;
            [a.next_down(), a, a.next_up()]
        })
        .collect();
    angles.extend([
        -1.0,
        -0.0,
        4.0,
        1e30,
        f32::NAN,
        f32::INFINITY,
        -f32::INFINITY,
    ]);
    for q in angles.chunks(4) {
        let mut four = [0.0f32; 4];
        four[..q.len()].copy_from_slice(q);
        let b = buckets(Vec4::from(four));
        for j in 0..4 {
            assert_eq!(b[j], bucket(four[j]), "{}", four[j]);
        }
    }
}

/// The prefix tables of every path (one word, two to four words through the hit table,
/// five words through rows of any length) hold exactly the samples of the buckets below
/// each row, build after build on one index whose sample counts change, so a hit table
/// left dirty by a build or a stale row of a longer table shows.
#[test]
fn prefix_tables_hold_the_samples_below_each_bucket_build_after_build() {
    let mut index = AngularIndex::default();
    let counts = [256, 128, 320, 64, 192, 256, 100, 256, 17, 130, 256];
    for (round, &n) in counts.iter().enumerate() {
        // Buckets spread over the turn, with runs of one bucket and the last bucket.
        index.buckets = (0..n as u64)
            .map(|k| match k % 5 {
                0 => (BUCKETS - 1) as u32,
                1 => 7,
                _ => (hash_words(&[round as u64, k]) % BUCKETS as u64) as u32,
            })
            .collect();
        index.index_buckets(n);
        let words = n.div_ceil(64);
        assert_eq!(index.words, words);
        assert_eq!(index.prefix.len(), (BUCKETS + 1) * words);
        for j in 0..=BUCKETS {
            for w in 0..words {
                let want = (0..n)
                    .filter(|&k| k / 64 == w && (index.buckets[k] as usize) < j)
                    .fold(0u64, |m, k| m | 1 << (k % 64));
                assert_eq!(
                    index.prefix[j * words + w],
                    want,
                    "{n} samples, row {j}, word {w}"
                );
            }
        }
        assert!(index.hits.iter().all(|h| *h == 0), "{n} samples: hits left");
    }
}

/// The candidates hold every sample the exact test covers, and leave most uncovered
/// samples out.
#[test]
fn candidates_hold_every_covered_sample() {
    // One word of samples (the running union's single-word path), two, four (the hit
    // table's paths) and five (rows of any length).
    for count in [64, 128, 256, 320] {
        candidates_hold_every_covered_sample_of(count);
    }
}

/// The 1.2 x 0.8 rectangle light of these tests, facing `normal`.
fn test_light(normal: Vec3) -> RectLight {
    RectLight::facing(
        Vec3::new(0.2, 3.0, -0.1),
        normal,
        1.2,
        0.8,
        Radiance::constant(Vec3::ONE).unwrap(),
    )
    .unwrap()
}

fn candidates_hold_every_covered_sample_of(count: u32) {
    let light = test_light(Vec3::NEG_Y);
    let shape = LightShape::new(&light, "test").unwrap();
    let plane = shape.plane.clone().unwrap();
    let sampler = LightSampler::new(SamplingStrategy::Stratified, count, 3).unwrap();
    let c = shape.center.as_dvec3();
    let (mut units, mut rel, mut index) = (
        Vec::new(),
        RelativeSamples::default(),
        AngularIndex::default(),
    );
    let (mut covered, mut candidates, mut total, mut inner_total) = (0u32, 0u32, 0u32, 0u32);
    for k in 0..3000u64 {
        let r = |i: u64| unit_float(hash_words(&[k, i])) as f64 * 2.0 - 1.0;
        let p = DVec3::new(r(0) * 2.0, 0.0, r(1) * 2.0);
        let mid = DVec3::new(r(2), 1.5 + r(3), r(4));
        let dir = DVec3::new(r(5), r(6) * 0.3, r(7)) * 0.3 * r(8).abs();
        let Some(test) = EdgeTest::new(p, c, mid - dir, mid + dir) else {
            continue;
        };
        sampler.unit_samples(glam::UVec2::new(k as u32, 7), &mut units);
        let pos: Vec<Vec3> = units.iter().map(|u| light.sample(*u).position).collect();
        rel.set(p.as_vec3(), &pos);
        index.build(&plane, shape.center, &pos);
        let words = count as usize / 64;
        let allowed = vec![u64::MAX; words];
        let (mut exact, mut cand) = (vec![0u64; words], vec![0u64; words]);
        test.mask(&rel, &allowed, &mut exact);
        index.candidates(&test, &allowed, &mut cand);
        // The batched form gives the same words in every lane: the test last in batches of
        // 1 to 8, after the reversed edge's tests.
        let m = 1 + (k as usize % BATCH);
        let mut batch = vec![EdgeTest::new(p, c, mid + dir, mid - dir).unwrap_or(test); m - 1];
        batch.push(test);
        let mut out = vec![0u64; words * m];
        let any = index.candidates_batch(&batch, &allowed, &mut out, None);
        assert_eq!(
            out[words * (m - 1)..],
            cand,
            "case {k}: batch lane {}",
            m - 1
        );
        assert_eq!(any >> (m - 1) & 1 == 1, cand.iter().any(|w| *w != 0));
        // The inner buckets hold candidates only, each inside the sector (the side of
        // both sector planes, `s - p` in double precision, away from their planes).
        let mut inner = vec![0u64; words];
        index.candidates_batch(
            std::slice::from_ref(&test),
            &allowed,
            &mut cand.clone(),
            Some(&mut inner),
        );
        let (ga, gb) = test.sector_normals();
        for (i, s) in pos.iter().enumerate() {
            if inner[i / 64] >> (i % 64) & 1 == 1 {
                let d = s.as_dvec3() - p;
                let (fa, fb) = (ga.as_dvec3().dot(d), gb.as_dvec3().dot(d));
                assert!(
                    fa > 0.0 && fb < 0.0,
                    "case {k}: inner sample {i} outside the sector"
                );
                inner_total += 1;
            }
        }
        for w in 0..words {
            assert_eq!(
                inner[w] & !cand[w],
                0,
                "case {k}: an inner sample is no candidate"
            );
            assert_eq!(
                exact[w] & !cand[w],
                0,
                "case {k}: a covered sample is no candidate"
            );
            covered += exact[w].count_ones();
            candidates += cand[w].count_ones();
        }
        total += count;
    }
    assert!(covered > 1000, "{covered}");
    // Most candidates lie in inner buckets.
    assert!(
        inner_total > candidates / 2,
        "{inner_total} of {candidates}"
    );
    // The cone holds little more than the covered samples, far fewer than all.
    assert!(candidates < total / 16, "{candidates} of {total}");
}

/// The light-plane form: the ranges of four tests at once hold every sample each test
/// covers, leave most other samples out, and the fixed words (one, two and four of them)
/// give the same candidates as the slice form and the same covered samples as the
/// whole-word test.
#[test]
fn light_plane_candidates_hold_every_covered_sample() {
    light_plane_candidates_of::<1>();
    light_plane_candidates_of::<2>();
    light_plane_candidates_of::<4>();
}

fn light_plane_candidates_of<const W: usize>() {
    use crate::accel::centred::CentredEdge;
    use crate::accel::planar::{PlanarEdge, PlanarSamples};
    use crate::stages::edges::SceneEdge;
    let light = test_light(Vec3::new(0.1, -1.0, 0.05));
    let shape = LightShape::new(&light, "test").unwrap();
    let plane = shape.plane.clone().unwrap();
    let count = 64 * W as u32;
    let sampler = LightSampler::new(SamplingStrategy::Stratified, count, 3).unwrap();
    let c = shape.center.as_dvec3();
    let (u, v) = (plane.u.as_dvec3(), plane.v.as_dvec3());
    let (mut units, mut samples, mut index) = (
        Vec::new(),
        PlanarSamples::default(),
        AngularIndex::default(),
    );
    let (mut covered, mut candidates, mut total) = (0u32, 0u32, 0u32);
    for k in 0..1500u64 {
        let r = |i: u64| unit_float(hash_words(&[k, i])) as f64 * 2.0 - 1.0;
        let p = DVec3::new(r(0) * 2.0, 0.0, r(1) * 2.0);
        sampler.unit_samples(glam::UVec2::new(k as u32, 7), &mut units);
        let pos: Vec<Vec3> = units.iter().map(|u| light.sample(*u).position).collect();
        samples.set(&pos, shape.center, plane.u, plane.v);
        index.build_planar(&samples, pos.len());
        let tests: Vec<_> = (0..4u64)
            .filter_map(|j| {
                let mid = DVec3::new(r(2 + 8 * j), 1.5 + r(3 + 8 * j), r(4 + 8 * j));
                let dir = DVec3::new(r(5 + 8 * j), r(6 + 8 * j) * 0.3, r(7 + 8 * j)) * 0.3;
                let (a, b) = (mid - dir, mid + dir);
                let e = SceneEdge::boundary(a, b, mid + DVec3::Z * 0.1);
                let ce = CentredEdge::new(&e, c);
                let pc = p - c;
                PlanarEdge::new(&e, c, u, v).test(pc.as_vec3(), pc.length() as f32 * 2.0, || {
                    ce.orientation(pc)
                })
            })
            .collect();
        let mut four = [PlanarTest::NONE; 4];
        four[..tests.len()].copy_from_slice(&tests);
        let ranges = QuadRanges::of_tests(&four);
        let (xs, ys) = (samples.words_x::<W>(), samples.words_y::<W>());
        for (j, t) in tests.iter().enumerate() {
            let cand = index.quad_words::<W>(&ranges, j);
            let mut slice = [0u64; W];
            index.quad_candidates(&ranges, j, &[u64::MAX; W], &mut slice);
            assert_eq!(
                slice, cand,
                "case {k} test {j}: fixed words and slices differ"
            );
            for w in 0..W {
                let exact = t.covered_word(&samples, w);
                assert_eq!(
                    exact & !cand[w],
                    0,
                    "case {k} test {j} word {w}: a covered sample is no candidate"
                );
                assert_eq!(t.covered_of(&xs[w], &ys[w], cand[w]), exact);
                covered += exact.count_ones();
                candidates += cand[w].count_ones();
            }
            total += count;
        }
    }
    assert!(covered > 1000 * W as u32, "{covered}");
    assert!(candidates < total / 8, "{candidates} of {total}");
}
