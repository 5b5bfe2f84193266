//! The URIs a glTF file names for its buffers and images: base64 data URIs decoded within a
//! limit, relative file URIs resolved beside the scene, never outside its folder.

use std::path::{Path, PathBuf};

use base64::Engine;

use super::LoadError;

/// The bytes of a `data:` URI (`None` for any other URI), refused when the decoded length
/// would exceed `limit`.
pub(super) fn decode_data_uri(uri: &str, limit: u64) -> Result<Option<Vec<u8>>, LoadError> {
    let Some(rest) = uri.strip_prefix("data:") else {
        return Ok(None);
    };
    let (_, data) = rest
        .split_once(";base64,")
        .ok_or_else(|| LoadError::Gltf("data URI is not base64".into()))?;
    let decoded_len = (data.len() as u64 / 4) * 3;
    if decoded_len > limit {
        return Err(LoadError::Limit {
            what: "a data URI's decoded length in bytes".into(),
            size: decoded_len,
            limit,
        });
    }
    base64::engine::general_purpose::STANDARD
        .decode(data)
        .map(Some)
        .map_err(|e| LoadError::Gltf(format!("bad base64 in data URI: {e}")))
}

/// The file a relative URI names beside `base` (`%20` decoded), refused when it is absolute,
/// remote or leaves `base`'s folder.
pub(super) fn resolve(base: Option<&Path>, uri: &str) -> Result<PathBuf, LoadError> {
    let base = base.ok_or_else(|| {
        LoadError::Missing(format!("external URI `{uri}` with no base directory"))
    })?;
    let uri = uri.replace("%20", " ");
    if uri.contains("://") || Path::new(&uri).is_absolute() {
        return Err(LoadError::Unsupported {
            mesh: uri,
            reason: "only relative file URIs and data URIs are supported".into(),
        });
    }
    // A file may name data beside it or below it, never outside its own folder.
    if Path::new(&uri).components().any(|c| {
        !matches!(
            c,
            std::path::Component::Normal(_) | std::path::Component::CurDir
        )
    }) {
        return Err(LoadError::Unsupported {
            mesh: uri,
            reason: "a URI may not leave the scene's folder (`..`)".into(),
        });
    }
    Ok(base.join(uri))
}
