//! What the technique adds on top of the paper's stages (`crate::stages`) to run fast on a
//! CPU: the wedge search hierarchy, single-precision light-centred forms, tiles in lanes,
//! per-pixel angular indices and shared sample sets. Each module may import the stages; no
//! stage imports these.

pub(crate) mod angular;
pub(crate) mod bins;
pub(crate) mod centred;
pub(crate) mod centred_wedges;
pub(crate) mod lanes;
pub(crate) mod planar;
pub(crate) mod shared_sets;
