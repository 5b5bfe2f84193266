//! The stages of depth complexity sampling as the paper describes them (Forest, Barthe,
//! Paulin 2008, sections 4 and 7.3): silhouettes, the integration constant, penumbra wedges,
//! covered light samples, counters and the section 7.3 tables. Nothing here imports the
//! acceleration (`crate::accel`).

pub(crate) mod constant;
pub(crate) mod counters;
pub(crate) mod coverage;
pub mod discrete;
pub mod edges;
pub(crate) mod light_shape;
pub(crate) mod receiver_constant;
pub(crate) mod wedges;
