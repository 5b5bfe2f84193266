//! Robust ray origins (Wachter and Binder, Ray Tracing Gems ch. 6). The implementation lives in
//! [`shadow_core::offset`] so that every technique offsets its view samples exactly as the
//! reference does; it is re-exported here for existing users.

pub use shadow_core::offset::RayOffset;
