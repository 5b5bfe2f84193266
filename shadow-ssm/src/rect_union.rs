//! The union of axis-aligned rectangles as disjoint rectangles, by a sweep over x: between
//! consecutive x edges the rectangles spanning the slab give y intervals, merged; consecutive
//! slabs with the same merged intervals are one piece. Back-projection sums its samples'
//! rectangles (BCS06 eq. 1), which counts an overlap twice; the union counts it once
//! (`docs/history/ssm-peeling-2026-12-07.md`: overlapping back-projections of depth-peeled
//! layers are what makes more layers darker than one).

use glam::DVec2;

/// Buffers of [`disjoint_strips`], reused across receivers.
#[derive(Debug, Default)]
pub struct UnionScratch {
    rects: Vec<(DVec2, DVec2)>,
    xs: Vec<f64>,
    active: Vec<usize>,
    intervals: Vec<(f64, f64)>,
    merged: Vec<(f64, f64)>,
    open: Vec<(f64, f64)>,
}

/// Hands `piece` disjoint strips whose union is the union of `rects` (empty or inverted
/// rectangles and non-finite ones are ignored): each strip is an x range and the disjoint,
/// increasing y intervals covered across it.
pub fn disjoint_strips(
    rects: &[(DVec2, DVec2)],
    scratch: &mut UnionScratch,
    mut piece: impl FnMut(f64, f64, &[(f64, f64)]),
) {
    let s = scratch;
    s.rects.clear();
    s.rects.extend(
        rects
            .iter()
            .copied()
            .filter(|(lo, hi)| lo.is_finite() && hi.is_finite() && lo.x < hi.x && lo.y < hi.y),
    );
    if s.rects.is_empty() {
        return;
    }
    s.rects.sort_by(|a, b| a.0.x.total_cmp(&b.0.x));
    s.xs.clear();
    s.xs.extend(s.rects.iter().flat_map(|(lo, hi)| [lo.x, hi.x]));
    s.xs.sort_by(f64::total_cmp);
    s.xs.dedup();
    s.active.clear();
    s.open.clear();
    let mut next = 0;
    let mut open_x = s.xs[0];
    for k in 0..s.xs.len() {
        let x0 = s.xs[k];
        // The slab [x0, x1]: every rectangle starting at or before x0 and ending after it
        // spans it (every edge is in `xs`). The active rectangles are kept in order of their lower y, so that the slab's
        // intervals come sorted.
        let rects = &s.rects;
        while next < rects.len() && rects[next].0.x <= x0 {
            let y = rects[next].0.y;
            let at = s.active.partition_point(|&i| rects[i].0.y <= y);
            s.active.insert(at, next);
            next += 1;
        }
        s.active.retain(|&i| rects[i].1.x > x0);
        s.intervals.clear();
        s.intervals
            .extend(s.active.iter().map(|&i| (rects[i].0.y, rects[i].1.y)));
        s.merged.clear();
        for &(y0, y1) in &s.intervals {
            match s.merged.last_mut() {
                Some(last) if y0 <= last.1 => last.1 = last.1.max(y1),
                _ => s.merged.push((y0, y1)),
            }
        }
        if s.merged != s.open {
            // The open strip ends here; the slab's own begins.
            if !s.open.is_empty() {
                piece(open_x, x0, &s.open);
            }
            std::mem::swap(&mut s.open, &mut s.merged);
            open_x = x0;
        }
    }
    // The last edge ends every rectangle: nothing is open past it.
    debug_assert!(s.open.is_empty());
}

#[cfg(test)]
mod tests {
    use super::*;

    fn area(pieces: &[(DVec2, DVec2)]) -> f64 {
        pieces
            .iter()
            .map(|(lo, hi)| (hi.x - lo.x) * (hi.y - lo.y))
            .sum()
    }

    /// The strips as rectangles.
    fn disjoint_pieces(
        rects: &[(DVec2, DVec2)],
        scratch: &mut UnionScratch,
        out: &mut Vec<(DVec2, DVec2)>,
    ) {
        disjoint_strips(rects, scratch, |x0, x1, ys| {
            out.extend(
                ys.iter()
                    .map(|&(y0, y1)| (DVec2::new(x0, y0), DVec2::new(x1, y1))),
            );
        });
    }

    fn r(x0: f64, y0: f64, x1: f64, y1: f64) -> (DVec2, DVec2) {
        (DVec2::new(x0, y0), DVec2::new(x1, y1))
    }

    /// Closed forms: two overlapping squares (7 = 4 + 4 - 1), a square inside another, a
    /// cross, disjoint and touching rectangles, and degenerate ones ignored; the pieces never
    /// overlap (their areas sum to the union's).
    #[test]
    fn union_areas_match_closed_forms() {
        let cases: Vec<(Vec<(DVec2, DVec2)>, f64)> = vec![
            (vec![r(0., 0., 2., 2.), r(1., 1., 3., 3.)], 7.0),
            (vec![r(0., 0., 4., 4.), r(1., 1., 2., 2.)], 16.0),
            (vec![r(0., 1., 3., 2.), r(1., 0., 2., 3.)], 5.0),
            (vec![r(0., 0., 1., 1.), r(2., 2., 3., 3.)], 2.0),
            (vec![r(0., 0., 1., 1.), r(1., 0., 2., 1.)], 2.0),
            (
                vec![
                    r(0., 0., 1., 1.),
                    r(1., 1., 1., 2.),
                    r(f64::NAN, 0., 1., 1.),
                    r(3., 3., 2., 4.),
                ],
                1.0,
            ),
            (vec![], 0.0),
        ];
        let mut scratch = UnionScratch::default();
        for (rects, want) in cases {
            let mut out = Vec::new();
            disjoint_pieces(&rects, &mut scratch, &mut out);
            assert!(
                (area(&out) - want).abs() < 1e-12,
                "{rects:?}: {}",
                area(&out)
            );
        }
    }

    /// Many random rectangles: the pieces' area equals a fine point count of the union, and
    /// no two pieces overlap.
    #[test]
    fn pieces_are_disjoint_and_cover_the_union() {
        let mut state = 12345u64;
        let mut next = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let rects: Vec<(DVec2, DVec2)> = (0..60)
            .map(|_| {
                let (x, y) = (next() * 8.0, next() * 8.0);
                r(x, y, x + next() * 2.0, y + next() * 2.0)
            })
            .collect();
        let mut out = Vec::new();
        disjoint_pieces(&rects, &mut UnionScratch::default(), &mut out);
        for (i, a) in out.iter().enumerate() {
            for b in &out[i + 1..] {
                let w = (a.1.x.min(b.1.x) - a.0.x.max(b.0.x)).max(0.0);
                let h = (a.1.y.min(b.1.y) - a.0.y.max(b.0.y)).max(0.0);
                assert!(w * h < 1e-12, "{a:?} overlaps {b:?}");
            }
        }
        let n = 400;
        let inside = |p: DVec2, rs: &[(DVec2, DVec2)]| {
            rs.iter()
                .any(|(lo, hi)| p.x >= lo.x && p.x < hi.x && p.y >= lo.y && p.y < hi.y)
        };
        let mut agree = 0;
        for j in 0..n {
            for i in 0..n {
                let p = DVec2::new(
                    (i as f64 + 0.5) * 10.0 / n as f64,
                    (j as f64 + 0.5) * 10.0 / n as f64,
                );
                agree += u32::from(inside(p, &rects) == inside(p, &out));
            }
        }
        assert_eq!(agree, n * n);
    }
}
