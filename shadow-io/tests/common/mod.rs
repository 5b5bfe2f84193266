//! Shared by the glTF test files: a tiny glTF writer and a loader call.

// Each test file takes the helpers it needs.
#![allow(dead_code)]

use std::io::Cursor;

use base64::Engine;
use glam::{Vec2, Vec3};
use serde_json::{Value, json};
use shadow_io::load::{LoadError, LoadLimits, SceneSetup, load_gltf_slice};

/// A tiny glTF writer: one binary buffer, one accessor set per mesh.
#[derive(Default)]
pub struct Writer {
    bin: Vec<u8>,
    views: Vec<Value>,
    accessors: Vec<Value>,
    meshes: Vec<Value>,
    materials: Vec<Value>,
    images: Vec<Value>,
}

impl Writer {
    pub fn view(&mut self, bytes: &[u8], target: Option<u32>) -> usize {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        let offset = self.bin.len();
        self.bin.extend_from_slice(bytes);
        let mut v = json!({"buffer": 0, "byteOffset": offset, "byteLength": bytes.len()});
        if let Some(t) = target {
            v["target"] = json!(t);
        }
        self.views.push(v);
        self.views.len() - 1
    }

    pub fn accessor(
        &mut self,
        view: usize,
        ctype: u32,
        count: usize,
        ty: &str,
        extra: Value,
    ) -> usize {
        let mut a = json!({"bufferView": view, "componentType": ctype, "count": count, "type": ty});
        if let Value::Object(m) = extra {
            for (k, v) in m {
                a[k] = v;
            }
        }
        self.accessors.push(a);
        self.accessors.len() - 1
    }

    pub fn material(&mut self, m: Value) -> usize {
        self.materials.push(m);
        self.materials.len() - 1
    }

    pub fn mesh(
        &mut self,
        name: &str,
        pos: &[Vec3],
        idx: &[u32],
        uv: Option<&[Vec2]>,
        material: usize,
    ) -> usize {
        let pb: Vec<u8> = pos
            .iter()
            .flat_map(|p| p.to_array())
            .flat_map(f32::to_le_bytes)
            .collect();
        let (lo, hi) = pos
            .iter()
            .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(a, b), p| {
                (a.min(*p), b.max(*p))
            });
        let pv = self.view(&pb, Some(34962));
        let pa = self.accessor(
            pv,
            5126,
            pos.len(),
            "VEC3",
            json!({"min": lo.to_array(), "max": hi.to_array()}),
        );
        let ib: Vec<u8> = idx.iter().flat_map(|i| (*i as u16).to_le_bytes()).collect();
        let iv = self.view(&ib, Some(34963));
        let ia = self.accessor(iv, 5123, idx.len(), "SCALAR", json!({}));
        let mut attrs = json!({"POSITION": pa});
        if let Some(uv) = uv {
            let ub: Vec<u8> = uv
                .iter()
                .flat_map(|p| p.to_array())
                .flat_map(f32::to_le_bytes)
                .collect();
            let uvv = self.view(&ub, Some(34962));
            attrs["TEXCOORD_0"] = json!(self.accessor(uvv, 5126, uv.len(), "VEC2", json!({})));
        }
        self.meshes.push(json!({"name": name, "primitives": [{"attributes": attrs, "indices": ia, "material": material}]}));
        self.meshes.len() - 1
    }

    pub fn png_image(&mut self, w: u32, h: u32, rgb: &[[u8; 3]]) -> usize {
        let img = image::RgbImage::from_fn(w, h, |x, y| image::Rgb(rgb[(y * w + x) as usize]));
        let mut png = Vec::new();
        img.write_to(&mut Cursor::new(&mut png), image::ImageFormat::Png)
            .unwrap();
        let v = self.view(&png, None);
        self.images
            .push(json!({"bufferView": v, "mimeType": "image/png"}));
        self.images.len() - 1
    }

    pub fn document(&self, nodes: Value, cameras: Value) -> Value {
        let n = nodes.as_array().unwrap().len();
        let b64 = base64::engine::general_purpose::STANDARD.encode(&self.bin);
        let mut doc = json!({
            "asset": {"version": "2.0"},
            "extensionsUsed": ["KHR_materials_emissive_strength"],
            "scene": 0,
            "scenes": [{"nodes": (0..n).collect::<Vec<_>>()}],
            "nodes": nodes,
            "meshes": self.meshes,
            "materials": self.materials,
            "buffers": [{"byteLength": self.bin.len(), "uri": format!("data:application/octet-stream;base64,{b64}")}],
            "bufferViews": self.views,
            "accessors": self.accessors,
        });
        if !cameras.as_array().unwrap().is_empty() {
            doc["cameras"] = cameras;
        }
        if !self.images.is_empty() {
            doc["images"] = json!(self.images);
            doc["textures"] = json!(
                (0..self.images.len())
                    .map(|i| json!({"source": i}))
                    .collect::<Vec<_>>()
            );
        }
        doc
    }
}

pub fn square(half: f32) -> (Vec<Vec3>, Vec<u32>) {
    // In the XZ plane, wound so the normal points down (-Y), as a ceiling light.
    (
        vec![
            Vec3::new(-half, 0.0, -half),
            Vec3::new(half, 0.0, -half),
            Vec3::new(half, 0.0, half),
            Vec3::new(-half, 0.0, half),
        ],
        vec![0, 1, 2, 0, 2, 3],
    )
}

pub fn load(doc: &Value) -> Result<SceneSetup, LoadError> {
    load_gltf_slice(
        doc.to_string().as_bytes(),
        None,
        "test",
        &LoadLimits::default(),
    )
}
