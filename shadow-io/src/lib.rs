//! # shadow-io: scene files in, images out
//!
//! * [`load`]: glTF 2.0 (`.gltf`, `.glb`; emissive meshes as area lights,
//!   `KHR_materials_emissive_strength`, `KHR_lights_punctual`, base-colour and emissive
//!   textures) and Wavefront OBJ, into a validated [`SceneSetup`], every size a file declares
//!   checked against [`LoadLimits`] before anything is allocated;
//! * [`image_io`]: float EXR and 8-bit PNG output of visibility buffers, view-sample AOVs and
//!   shaded images;
//! * [`npy`]: NumPy `.npy` output of visibility buffers.
//!
//! It depends on `shadow-core` alone, so a renderer that takes one technique crate and this
//! one builds neither the reference, the GPU stack nor the harness.
//!
//! ```
//! use shadow_core::Scene;
//! use shadow_io::load::{LoadLimits, load_obj_slice};
//!
//! let obj = b"v 0 0 0\nv 1 0 0\nv 0 0 1\nf 1 3 2\n";
//! let setup = load_obj_slice(obj, "tri", &LoadLimits::default()).unwrap();
//! assert_eq!(setup.scene.triangle_count(), 1);
//! assert!(setup.lights.is_empty()); // an OBJ file has no emissive mesh: the caller brings a light
//! ```

#![deny(missing_docs)]

pub mod image_io;
pub mod load;
pub mod npy;

pub use load::{LoadError, LoadLimits, SceneSetup, load_scene};
