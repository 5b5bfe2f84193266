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

/// `uri` with every percent-encoded byte (`%XX`, RFC 3986 section 2.1) decoded, the bytes read
/// as UTF-8.
///
/// # Errors
/// [`LoadError::Gltf`] for a `%` not followed by two hexadecimal digits, or bytes that are not
/// UTF-8.
pub(super) fn percent_decode(uri: &str) -> Result<String, LoadError> {
    let bad = |why: &str| LoadError::Gltf(format!("URI `{uri}`: {why}"));
    let bytes = uri.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%' {
            let hex = bytes
                .get(i + 1..i + 3)
                .and_then(|h| std::str::from_utf8(h).ok())
                .and_then(|h| u8::from_str_radix(h, 16).ok())
                .ok_or_else(|| bad("`%` is not followed by two hexadecimal digits"))?;
            out.push(hex);
            i += 3;
        } else {
            out.push(bytes[i]);
            i += 1;
        }
    }
    String::from_utf8(out).map_err(|_| bad("the decoded bytes are not UTF-8"))
}

/// The file a relative URI names beside `base` (percent-encoding decoded), refused when it is
/// absolute, remote or leaves `base`'s folder (checked after decoding, so `%2E%2E` is `..`).
pub(super) fn resolve(base: Option<&Path>, uri: &str) -> Result<PathBuf, LoadError> {
    let base = base.ok_or_else(|| {
        LoadError::Missing(format!("external URI `{uri}` with no base directory"))
    })?;
    let uri = percent_decode(uri)?;
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn percent_encoded_bytes_other_than_spaces_are_decoded() {
        assert_eq!(
            percent_decode("a%20b%23c%2Bd%C3%BC.bin").unwrap(),
            "a b#c+d\u{fc}.bin"
        );
        assert_eq!(percent_decode("plain.bin").unwrap(), "plain.bin");
        assert!(percent_decode("bad%2").is_err());
        assert!(percent_decode("bad%zz.bin").is_err());
        assert!(percent_decode("%FF.bin").is_err());
    }

    #[test]
    fn an_encoded_parent_folder_is_still_refused() {
        let base = Path::new("/scenes");
        assert!(resolve(Some(base), "%2E%2E/secret.bin").is_err());
        assert_eq!(
            resolve(Some(base), "sub/a%2Bb.bin").unwrap(),
            base.join("sub/a+b.bin")
        );
    }
}
