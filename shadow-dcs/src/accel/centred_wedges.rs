//! The penumbra wedges of DCS section 4.2 ([`crate::stages::wedges`]) in the form the wedge scan
//! tests: every bounding plane and fold plane around the light centre in single precision
//! ([`CentredPlane`]), with the edge's single-precision weight ([`FastWeight`]). The exact
//! planes stay with the paper's stage; this is their acceleration.

use rayon::prelude::*;

use crate::accel::centred::{CentredPlane, FastWeight};
use crate::stages::edges::SceneEdge;
use crate::stages::light_shape::LightShape;
use crate::stages::wedges::{Plane, fold_planes, wedge_planes};

/// The plane around the light centre `c`, in single precision.
fn centred(p: &Plane, c: glam::DVec3) -> CentredPlane {
    CentredPlane::new(p.normal(), p.offset(), c)
}

/// What the wedge scan needs of one silhouette edge, prepared once per light, around the light
/// centre in single precision.
#[derive(Debug, Clone)]
pub(crate) struct Wedge {
    /// The scene edge.
    pub edge: u32,
    /// The half-spaces holding the wedge ([`wedge_planes`]).
    pub planes: Vec<CentredPlane>,
    /// The planes of the edge's two faces, oriented by the edge, when the edge's weight can
    /// only be non-zero where it is a silhouette of the view sample ([`fold_planes`]).
    pub fold: Option<(CentredPlane, CentredPlane)>,
    /// The weight from plane signs, for edges with one or two faces.
    pub weight: Option<FastWeight>,
}

/// The wedges of every silhouette edge, in silhouette order.
pub(crate) fn wedges(edges: &[SceneEdge], silhouettes: &[u32], light: &LightShape) -> Vec<Wedge> {
    let c = light.center.as_dvec3();
    silhouettes
        .par_iter()
        .map(|&ei| {
            let e = &edges[ei as usize];
            let weight = FastWeight::new(e, c);
            // The fold planes are the weight's own face planes where it has them (the same
            // planes up to scale and rounding), so that the scan hands the fold test's values
            // to the weight.
            let fold = fold_planes(e).map(|(a, b)| {
                weight
                    .as_ref()
                    .and_then(FastWeight::face_planes)
                    .unwrap_or((centred(&a, c), centred(&b, c)))
            });
            Wedge {
                edge: ei,
                planes: wedge_planes(e, light)
                    .iter()
                    .map(|p| centred(p, c))
                    .collect(),
                fold,
                weight,
            }
        })
        .collect()
}
