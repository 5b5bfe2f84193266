//! Edge adjacency and closedness, the queries silhouette-based techniques need (DCS section 4.1,
//! AFSM section 3.3): each undirected edge with the faces that share it, boundary and non-manifold
//! edges reported, and the connected meshes with whether each is closed.

use std::collections::HashMap;

use serde::Serialize;

/// How many faces share an edge.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum EdgeKind {
    /// One face: the edge lies on the border of an open surface.
    Boundary,
    /// Exactly two faces.
    Manifold,
    /// Three or more faces.
    NonManifold,
}

/// One connected mesh: triangles connected through shared edges.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Component {
    /// Number of triangles.
    pub triangle_count: u32,
    /// Every edge is shared by exactly two faces (watertight).
    pub closed: bool,
    /// Every manifold edge is traversed in opposite directions by its two faces.
    pub consistently_oriented: bool,
}

/// Edge adjacency of a triangle soup whose vertices are shared by index.
///
/// Edges are undirected, stored with `vertices[0] < vertices[1]`; [`Topology::faces`] lists the
/// faces of an edge in increasing triangle order, so the result is deterministic.
#[derive(Debug, Clone, Default)]
pub struct Topology {
    edges: Vec<[u32; 2]>,
    face_start: Vec<u32>,
    faces: Vec<u32>,
    component_of_triangle: Vec<u32>,
    components: Vec<Component>,
}

impl Topology {
    /// Builds the adjacency of `triangles` (indices assumed valid).
    pub fn build(triangles: &[[u32; 3]]) -> Self {
        let mut map: HashMap<(u32, u32), u32> = HashMap::with_capacity(triangles.len() * 2);
        let mut edges: Vec<[u32; 2]> = Vec::new();
        let mut pairs: Vec<(u32, u32)> = Vec::with_capacity(triangles.len() * 3);
        for (t, tri) in triangles.iter().enumerate() {
            for k in 0..3 {
                let (a, b) = (tri[k], tri[(k + 1) % 3]);
                let key = (a.min(b), a.max(b));
                let next = edges.len() as u32;
                let e = *map.entry(key).or_insert_with(|| {
                    edges.push([key.0, key.1]);
                    next
                });
                pairs.push((e, t as u32));
            }
        }
        pairs.sort_unstable();
        pairs.dedup();
        let mut face_start = vec![0u32; edges.len() + 1];
        for &(e, _) in &pairs {
            face_start[e as usize + 1] += 1;
        }
        for i in 0..edges.len() {
            face_start[i + 1] += face_start[i];
        }
        let faces: Vec<u32> = pairs.iter().map(|&(_, t)| t).collect();

        // Connected components through shared edges (union-find).
        let mut parent: Vec<u32> = (0..triangles.len() as u32).collect();
        fn find(parent: &mut [u32], mut x: u32) -> u32 {
            while parent[x as usize] != x {
                parent[x as usize] = parent[parent[x as usize] as usize];
                x = parent[x as usize];
            }
            x
        }
        for e in 0..edges.len() {
            let fs = &faces[face_start[e] as usize..face_start[e + 1] as usize];
            for w in fs.windows(2) {
                let (a, b) = (find(&mut parent, w[0]), find(&mut parent, w[1]));
                if a != b {
                    parent[a.max(b) as usize] = a.min(b);
                }
            }
        }
        let mut id_of_root: HashMap<u32, u32> = HashMap::new();
        let mut component_of_triangle = Vec::with_capacity(triangles.len());
        let mut components: Vec<Component> = Vec::new();
        for t in 0..triangles.len() as u32 {
            let r = find(&mut parent, t);
            let next = components.len() as u32;
            let id = *id_of_root.entry(r).or_insert_with(|| {
                components.push(Component {
                    triangle_count: 0,
                    closed: true,
                    consistently_oriented: true,
                });
                next
            });
            components[id as usize].triangle_count += 1;
            component_of_triangle.push(id);
        }
        let mut topo = Self {
            edges,
            face_start,
            faces,
            component_of_triangle,
            components,
        };
        for e in 0..topo.edges.len() {
            let fs = topo.faces(e);
            let c = topo.component_of_triangle[fs[0] as usize] as usize;
            match topo.kind(e) {
                EdgeKind::Manifold => {
                    let [a, b] = topo.edges[e];
                    let d0 = directed(&triangles[fs[0] as usize], a, b);
                    let d1 = directed(&triangles[fs[1] as usize], a, b);
                    if d0 == d1 {
                        topo.components[c].consistently_oriented = false;
                    }
                }
                _ => topo.components[c].closed = false,
            }
        }
        topo
    }

    /// Number of undirected edges.
    pub fn edge_count(&self) -> usize {
        self.edges.len()
    }

    /// The two vertex indices of edge `e`, smallest first.
    pub fn edge(&self, e: usize) -> [u32; 2] {
        self.edges[e]
    }

    /// The faces sharing edge `e`, in increasing order.
    pub fn faces(&self, e: usize) -> &[u32] {
        &self.faces[self.face_start[e] as usize..self.face_start[e + 1] as usize]
    }

    /// Whether edge `e` is a boundary, manifold or non-manifold edge.
    pub fn kind(&self, e: usize) -> EdgeKind {
        match self.faces(e).len() {
            0 | 1 => EdgeKind::Boundary,
            2 => EdgeKind::Manifold,
            _ => EdgeKind::NonManifold,
        }
    }

    /// Indices of the boundary edges.
    pub fn boundary_edges(&self) -> impl Iterator<Item = usize> + '_ {
        (0..self.edges.len()).filter(|&e| self.kind(e) == EdgeKind::Boundary)
    }

    /// Indices of the non-manifold edges.
    pub fn non_manifold_edges(&self) -> impl Iterator<Item = usize> + '_ {
        (0..self.edges.len()).filter(|&e| self.kind(e) == EdgeKind::NonManifold)
    }

    /// The connected meshes.
    pub fn components(&self) -> &[Component] {
        &self.components
    }

    /// The connected mesh a triangle belongs to.
    pub fn component_of(&self, triangle: usize) -> usize {
        self.component_of_triangle[triangle] as usize
    }

    /// True when every connected mesh is closed.
    pub fn all_closed(&self) -> bool {
        self.components.iter().all(|c| c.closed)
    }
}

/// +1 when the triangle traverses `a -> b`, -1 when it traverses `b -> a`.
fn directed(tri: &[u32; 3], a: u32, b: u32) -> i8 {
    for k in 0..3 {
        if tri[k] == a && tri[(k + 1) % 3] == b {
            return 1;
        }
    }
    -1
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tetrahedron() -> Vec<[u32; 3]> {
        vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [2, 0, 3]]
    }

    #[test]
    fn tetrahedron_is_closed() {
        let t = Topology::build(&tetrahedron());
        assert_eq!(t.edge_count(), 6);
        assert_eq!(t.components().len(), 1);
        assert!(t.components()[0].closed && t.components()[0].consistently_oriented);
        assert_eq!(t.boundary_edges().count(), 0);
    }

    #[test]
    fn open_and_non_manifold_edges_are_reported() {
        // Two separate meshes: a single triangle (open) and a fan of three triangles on one edge.
        let tris = vec![[0, 1, 2], [3, 4, 5], [3, 4, 6], [4, 3, 7]];
        let t = Topology::build(&tris);
        assert_eq!(t.components().len(), 2);
        assert!(!t.components()[0].closed && !t.components()[1].closed);
        assert_eq!(t.non_manifold_edges().count(), 1);
        let e = t.non_manifold_edges().next().unwrap();
        assert_eq!(t.edge(e), [3, 4]);
        assert_eq!(t.faces(e), &[1, 2, 3]);
        assert_eq!(t.boundary_edges().count(), 3 + 6);
    }

    #[test]
    fn flipped_face_breaks_orientation() {
        let mut tris = tetrahedron();
        tris[0] = [0, 1, 2];
        let t = Topology::build(&tris);
        assert!(t.components()[0].closed);
        assert!(!t.components()[0].consistently_oriented);
    }
}
