//! The first stage: the file's bytes as a checked `gltf` document and its buffers, with the
//! extensions it uses sorted into read, left out (listed) and refused.

use std::path::Path;
use std::string::{String, ToString};
use std::vec::Vec;

use super::LeftOut;
use crate::load::{LoadError, LoadErrorKind};

/// Extensions the loader interprets.
const READ: &[&str] = &[
    "KHR_lights_punctual",
    "KHR_materials_emissive_strength",
    "EXT_mesh_gpu_instancing",
    "KHR_texture_transform",
];

/// Extensions that change only textures, shading or lights: a file that requires one
/// still loads, with the extension listed as left out.
fn shading_only(name: &str) -> bool {
    [
        "KHR_materials_",
        "KHR_texture_",
        "EXT_texture_",
        "MSFT_texture_",
    ]
    .iter()
    .any(|prefix| name.starts_with(prefix))
        || matches!(name, "KHR_xmp_json_ld" | "EXT_lights_image_based")
}

/// The document of `bytes` (a `.gltf`'s JSON or a `.glb`) and its buffers (from files
/// beside `base`, inline, or the GLB's own chunk), every reference a primitive makes
/// checked; what the file uses and the loader does not read pushed to `left_out`.
pub(super) fn document(
    bytes: &[u8],
    path: &Path,
    base: Option<&Path>,
    left_out: &mut Vec<LeftOut>,
) -> Result<(gltf::Document, Vec<gltf::buffer::Data>), LoadError> {
    let parse = |what: String| LoadError::new(path, LoadErrorKind::Parse(what));
    let (json, blob) = if bytes.starts_with(b"glTF") {
        let (json, bin) = split_glb(bytes).map_err(|e| parse(format!("a GLB file: {e}")))?;
        (json.to_vec(), bin.map(<[u8]>::to_vec))
    } else if bytes.trim_ascii_start().starts_with(b"{") {
        (bytes.to_vec(), None)
    } else {
        // Neither JSON nor a GLB: name what its first bytes are, rather than a JSON
        // parser's complaint about its first character.
        let head: String = bytes
            .iter()
            .take(4)
            .map(|&b| {
                if b.is_ascii_graphic() {
                    char::from(b).to_string()
                } else {
                    format!("\\x{b:02x}")
                }
            })
            .collect();
        return Err(parse(format!(
            "it begins with \"{head}\", neither a GLB's magic \"glTF\" nor a JSON object"
        )));
    };
    let mut root: gltf::json::Root =
        gltf::json::deserialize::from_slice(&json).map_err(|e| parse(e.to_string()))?;
    for name in &root.extensions_required {
        if !READ.contains(&name.as_str()) && !shading_only(name) {
            let what = format!("the required extension {name}");
            return Err(LoadError::new(path, LoadErrorKind::Unsupported(what)));
        }
    }
    for name in &root.extensions_used {
        if !READ.contains(&name.as_str()) && !left_out.contains(&LeftOut::Extension(name.clone())) {
            left_out.push(LeftOut::Extension(name.clone()));
        }
    }
    // What is left is read, or changes nothing here: the `gltf` crate need not know it.
    root.extensions_required.clear();
    check_references(&root, path)?;
    // A texture whose image is in a format of an extension (`KHR_texture_basisu`'s KTX2,
    // `EXT_texture_webp`) names it in the extension, not in `source`: that image is the
    // texture's (listed as left out where it cannot be decoded).
    for texture in &mut root.textures {
        if texture.source.value() == u32::MAX as usize {
            let named = texture
                .extensions
                .as_ref()
                .and_then(|e| e.others.values().find_map(|v| v.get("source")?.as_u64()));
            if let Some(image) = named.and_then(|i| u32::try_from(i).ok()) {
                texture.source = gltf::json::Index::new(image);
            }
        }
    }
    // An image with neither a file nor a buffer view, or a buffer view without a type
    // (which glTF requires), is not read (the `gltf` crate unwraps both).
    for (image, json) in root.images.iter().enumerate() {
        let reason = match (&json.uri, &json.buffer_view, &json.mime_type) {
            (None, None, _) => "it names neither a file nor a buffer view",
            (_, Some(_), None) => "it is in a buffer view without a mimeType",
            _ => continue,
        };
        left_out.push(LeftOut::Image {
            image,
            reason: reason.into(),
        });
    }
    let document = gltf::Document::from_json(root).map_err(|e| parse(e.to_string()))?;
    // The `gltf` crate decodes a file name's percent escapes and unwraps the result: one
    // that is not UTF-8 once decoded would panic there.
    for buffer in document.buffers() {
        if let gltf::buffer::Source::Uri(uri) = buffer.source()
            && !uri.contains(':')
            && !percent_decodes(uri)
        {
            let what = format!(
                "buffer {}'s file name is not UTF-8 once decoded",
                buffer.index()
            );
            return Err(parse(what));
        }
    }
    let buffers = buffers(&document, path, base, blob)?;
    Ok((document, buffers))
}

/// The document's buffers; a buffer that cannot be read is an error naming its own file
/// (not the `.gltf` that names it).
fn buffers(
    document: &gltf::Document,
    path: &Path,
    base: Option<&Path>,
    mut blob: Option<Vec<u8>>,
) -> Result<Vec<gltf::buffer::Data>, LoadError> {
    let mut buffers = Vec::new();
    for buffer in document.buffers() {
        let file = match buffer.source() {
            gltf::buffer::Source::Uri(uri) if !uri.contains(':') => {
                base.map(|b| b.join(decoded(uri)))
            }
            _ => None,
        };
        let data = gltf::buffer::Data::from_source_and_blob(buffer.source(), base, &mut blob)
            .map_err(|e| match e {
                gltf::Error::Io(e) => {
                    LoadError::new(file.as_deref().unwrap_or(path), LoadErrorKind::Io(e))
                }
                gltf::Error::ExternalReferenceInSliceImport => LoadError::new(
                    path,
                    LoadErrorKind::Io(std::io::Error::new(
                        std::io::ErrorKind::NotFound,
                        "a buffer in another file, for a file held in memory",
                    )),
                ),
                e => LoadError::new(
                    path,
                    LoadErrorKind::Parse(format!("buffer {}: {e}", buffer.index())),
                ),
            })?;
        if data.len() < buffer.length() {
            let what = format!(
                "buffer {} holds {} bytes where the file says {}",
                buffer.index(),
                data.len(),
                buffer.length()
            );
            return Err(LoadError::new(
                file.as_deref().unwrap_or(path),
                LoadErrorKind::Parse(what),
            ));
        }
        buffers.push(data);
    }
    Ok(buffers)
}

/// `uri` with its percent escapes (a `%` and two hex digits; any other `%` kept as it is)
/// decoded, as bytes.
fn percent_decoded(uri: &str) -> Vec<u8> {
    let bytes = uri.as_bytes();
    let mut decoded = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        let hex = |b: u8| char::from(b).to_digit(16);
        match (
            bytes[i],
            bytes.get(i + 1).copied().and_then(hex),
            bytes.get(i + 2).copied().and_then(hex),
        ) {
            (b'%', Some(high), Some(low)) => {
                decoded.push((high * 16 + low) as u8);
                i += 3;
            }
            (b, _, _) => {
                decoded.push(b);
                i += 1;
            }
        }
    }
    decoded
}

/// `uri` decoded as a file name (bytes that are not UTF-8 replaced: only for messages).
pub(super) fn decoded(uri: &str) -> String {
    String::from_utf8_lossy(&percent_decoded(uri)).into_owned()
}

/// Whether `uri`'s percent escapes decode to UTF-8.
fn percent_decodes(uri: &str) -> bool {
    String::from_utf8(percent_decoded(uri)).is_ok()
}

/// A GLB file's JSON chunk and its binary chunk, if any, with every length checked
/// against the bytes there are (the `gltf` crate's own split subtracts a header's length
/// unchecked, which overflows on a short one).
fn split_glb(bytes: &[u8]) -> Result<(&[u8], Option<&[u8]>), String> {
    let word = |at: usize| -> Result<u32, String> {
        bytes
            .get(at..at + 4)
            .map(|w| u32::from_le_bytes([w[0], w[1], w[2], w[3]]))
            .ok_or_else(|| {
                format!(
                    "it ends at byte {} inside its header or a chunk's",
                    bytes.len()
                )
            })
    };
    let (version, length) = (word(4)?, word(8)? as usize);
    if version != 2 {
        return Err(format!(
            "version {version}, where glTF 2.0 files are version 2"
        ));
    }
    if length > bytes.len() || length < 12 {
        return Err(format!(
            "a length of {length} bytes, in a file of {}",
            bytes.len()
        ));
    }
    let mut chunks = Vec::new();
    let mut at = 12;
    while at < length {
        let (size, kind) = (word(at)? as usize, word(at + 4)?);
        let start = at + 8;
        let end = start
            .checked_add(size)
            .filter(|&end| end <= length)
            .ok_or_else(|| format!("a chunk of {size} bytes at byte {at} past the file's end"))?;
        chunks.push((kind, &bytes[start..end]));
        at = end;
    }
    match chunks[..] {
        [(0x4E4F_534A, json)] => Ok((json, None)),
        [(0x4E4F_534A, json), (0x004E_4942, bin), ..] => Ok((json, Some(bin))),
        _ => Err("its first chunk is not its JSON".into()),
    }
}

/// The references the `gltf` crate's own checks follow before checking them: every
/// primitive's attributes and indices name an accessor of the file. (Its check of a
/// `POSITION` accessor's bounds indexes the accessors with the primitive's number.)
fn check_references(root: &gltf::json::Root, path: &Path) -> Result<(), LoadError> {
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, primitive) in mesh.primitives.iter().enumerate() {
            let named = primitive
                .attributes
                .values()
                .chain(primitive.indices.as_ref());
            for accessor in named {
                if accessor.value() >= root.accessors.len() {
                    let mesh = mesh.name.clone().unwrap_or_else(|| format!("mesh {m}"));
                    return Err(LoadError::new(
                        path,
                        LoadErrorKind::Malformed {
                            mesh: format!("{mesh}#{p}"),
                            accessor: accessor.value(),
                            problem: format!(
                                "no such accessor (the file has {})",
                                root.accessors.len()
                            ),
                        },
                    ));
                }
            }
        }
    }
    Ok(())
}
