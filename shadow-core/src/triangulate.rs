//! Triangulation of simple polygons: the outlines of polygon lights (DESIGN section 3: polygon
//! lights are triangulated with `spade` for area-uniform sampling) and the n-gon faces of OBJ
//! files.
//!
//! A constrained Delaunay triangulation of the outline's vertices with its edges as
//! constraints, then a flood fill from the convex hull that toggles inside and outside at each
//! constraint edge. Every step is `O(n log n)` or better, so a 100,000-vertex outline
//! triangulates in well under a second (the pairwise simplicity test and the per-triangle
//! point-in-polygon test this replaces were `O(n^2)`: 43 s for such a light, issue 51 item 16).
//! Delaunay triangles are as well shaped as the outline allows: a fan from one vertex of a
//! large n-gon gives needles that make any bounding-volume hierarchy over them slow to build
//! and to traverse.
//!
//! The outline must be simple: coinciding vertices, crossing edges and a vertex lying on a
//! non-adjacent edge are errors naming the vertices or the edge.

use std::collections::VecDeque;

use glam::DVec2;
use spade::{ConstrainedDelaunayTriangulation, Point2, Triangulation};

/// Why an outline has no triangulation.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum PolygonError {
    /// Fewer than three vertices.
    #[error("{0} vertices, need at least 3")]
    TooFew(usize),
    /// A coordinate is not finite or too large for the triangulation's exact predicates.
    #[error("vertex {0} cannot be triangulated: {1}")]
    Vertex(usize, String),
    /// Two vertices are equal.
    #[error("vertices {0} and {1} coincide")]
    Coincident(usize, usize),
    /// An edge crosses an earlier edge, or passes through a vertex that is not its own.
    #[error(
        "edge {0} (from vertex {0}) crosses or touches another edge: the outline is not simple"
    )]
    NotSimple(usize),
    /// Nothing is inside (a degenerate outline).
    #[error("the outline encloses no area")]
    Empty,
}

/// Triangles (vertex indices into `outline`, counter-clockwise in the plane) covering the
/// inside of the simple polygon `outline` (either winding).
///
/// # Errors
/// [`PolygonError`] naming what makes the outline unusable.
pub fn triangulate_simple(outline: &[DVec2]) -> Result<Vec<[usize; 3]>, PolygonError> {
    let n = outline.len();
    if n < 3 {
        return Err(PolygonError::TooFew(n));
    }
    let mut cdt: ConstrainedDelaunayTriangulation<Point2<f64>> =
        ConstrainedDelaunayTriangulation::new();
    let mut handles = Vec::with_capacity(n);
    for (i, p) in outline.iter().enumerate() {
        let h = cdt
            .insert(Point2::new(p.x, p.y))
            .map_err(|e| PolygonError::Vertex(i, format!("{e:?}")))?;
        // An equal point returns the earlier vertex's handle.
        if h.index() != i {
            return Err(PolygonError::Coincident(h.index(), i));
        }
        handles.push(h);
    }
    for i in 0..n {
        let (a, b) = (handles[i], handles[(i + 1) % n]);
        if !cdt.can_add_constraint(a, b) {
            return Err(PolygonError::NotSimple(i));
        }
        cdt.add_constraint(a, b);
        // A vertex exactly on the edge splits the constraint: the outline touches itself.
        if !cdt.exists_constraint(a, b) {
            return Err(PolygonError::NotSimple(i));
        }
    }
    // Flood fill: faces beside the convex hull are inside exactly when the hull edge is an
    // outline edge; crossing an outline edge toggles inside and outside.
    let faces = cdt.num_inner_faces();
    let mut inside: Vec<Option<bool>> = vec![None; faces + 1];
    let mut queue = VecDeque::new();
    for f in cdt.inner_faces() {
        for e in f.adjacent_edges() {
            if e.rev().face().is_outer() && inside[f.fix().index()].is_none() {
                let v = e.is_constraint_edge();
                inside[f.fix().index()] = Some(v);
                queue.push_back((f.fix(), v));
            }
        }
    }
    while let Some((fixed, v)) = queue.pop_front() {
        let f = cdt.face(fixed);
        for e in f.adjacent_edges() {
            let Some(g) = e.rev().face().as_inner() else {
                continue;
            };
            let slot = &mut inside[g.fix().index()];
            if slot.is_none() {
                let w = v ^ e.is_constraint_edge();
                *slot = Some(w);
                queue.push_back((g.fix(), w));
            }
        }
    }
    let mut out = Vec::new();
    for f in cdt.inner_faces() {
        if inside[f.fix().index()] != Some(true) {
            continue;
        }
        let [a, b, c] = f.vertices().map(|v| v.fix().index());
        let (pa, pb, pc) = (outline[a], outline[b], outline[c]);
        out.push(if (pb - pa).perp_dot(pc - pa) < 0.0 {
            [a, c, b]
        } else {
            [a, b, c]
        });
    }
    if out.is_empty() {
        return Err(PolygonError::Empty);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn area(poly: &[DVec2], tris: &[[usize; 3]]) -> f64 {
        tris.iter()
            .map(|t| 0.5 * (poly[t[1]] - poly[t[0]]).perp_dot(poly[t[2]] - poly[t[0]]))
            .sum()
    }

    #[test]
    fn concave_outlines_cover_their_area_once() {
        // A comb: ten teeth, area 10 * 1 * 3 + base 19 x 1.
        let mut p = vec![DVec2::new(0.0, 0.0), DVec2::new(19.0, 0.0)];
        for k in (0..10).rev() {
            let x = 2.0 * k as f64;
            p.push(DVec2::new(x + 1.0, 1.0));
            p.push(DVec2::new(x + 1.0, 4.0));
            p.push(DVec2::new(x, 4.0));
            if k > 0 {
                p.push(DVec2::new(x, 1.0));
            }
        }
        p.dedup();
        let tris = triangulate_simple(&p).unwrap();
        assert!((area(&p, &tris) - (19.0 + 30.0)).abs() < 1e-9);
        assert!(
            tris.iter()
                .all(|t| { (p[t[1]] - p[t[0]]).perp_dot(p[t[2]] - p[t[0]]) > 0.0 })
        );
        // Clockwise input: the same area.
        let rev: Vec<DVec2> = p.iter().rev().copied().collect();
        assert!((area(&rev, &triangulate_simple(&rev).unwrap()) - 49.0).abs() < 1e-9);
    }

    #[test]
    fn bad_outlines_name_the_problem() {
        let bowtie = [(0.0, 0.0), (1.0, 1.0), (1.0, 0.0), (0.0, 1.0)].map(DVec2::from);
        assert!(matches!(
            triangulate_simple(&bowtie),
            Err(PolygonError::NotSimple(_))
        ));
        let repeated = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (1.0, 0.0)].map(DVec2::from);
        assert_eq!(
            triangulate_simple(&repeated),
            Err(PolygonError::Coincident(1, 3))
        );
        // Vertex 4 lies on edge 0-1.
        let touching = [
            (0.0, 0.0),
            (2.0, 0.0),
            (2.0, 2.0),
            (1.0, 2.0),
            (1.0, 0.0),
            (0.0, 2.0),
        ]
        .map(DVec2::from);
        assert!(matches!(
            triangulate_simple(&touching),
            Err(PolygonError::NotSimple(_))
        ));
        assert_eq!(
            triangulate_simple(&[DVec2::ZERO, DVec2::X]),
            Err(PolygonError::TooFew(2))
        );
    }

    #[test]
    fn a_large_circle_triangulates_fast_and_exactly() {
        let n = 20_000;
        let p: Vec<DVec2> = (0..n)
            .map(|k| {
                let a = std::f64::consts::TAU * k as f64 / n as f64;
                DVec2::new(a.cos(), a.sin())
            })
            .collect();
        let tris = triangulate_simple(&p).unwrap();
        assert_eq!(tris.len(), n - 2);
        let exact = 0.5 * n as f64 * (std::f64::consts::TAU / n as f64).sin();
        assert!((area(&p, &tris) - exact).abs() < 1e-9);
    }
}
