//! glTF input checks the `gltf` crate does not make, or makes only by crashing: accessor
//! references checked before the crate's validation indexes them (it panics on a POSITION
//! accessor that does not exist), and accessor types checked against what each attribute must
//! be before the crate's readers reinterpret the bytes (a VEC2 of UNSIGNED_BYTE read as
//! float3, or a stride shorter than an element, which panics). Locations are JSON paths, e.g.
//! `meshes[0].primitives[1].attributes.POSITION`: glTF has no lines to speak of (GLB is
//! binary, and exporters write JSON on one line).

use super::guard;
use ::gltf::accessor::{DataType, Dimensions};
use ::gltf::json::validation::Checked;
use anyhow::{anyhow, bail};

/// Parse and validate a `.gltf`/`.glb` document (buffers not yet resolved).
pub fn parse_document(bytes: &[u8], file: &str) -> anyhow::Result<::gltf::Gltf> {
    let raw = guard::catch(|| ::gltf::Gltf::from_slice_without_validation(bytes))
        .map_err(|_| anyhow!("{file}: the glTF parser crashed on this file"))?
        .map_err(|e| anyhow!("{file}: invalid glTF: {e}"))?;
    let ::gltf::Gltf { document, blob } = raw;
    let json = document.into_json();
    check_references(&json).map_err(|e| anyhow!("{file}: invalid glTF: {e}"))?;
    let document = guard::catch(|| ::gltf::Document::from_json(json))
        .map_err(|_| anyhow!("{file}: the glTF validator crashed on this file"))?
        .map_err(|e| match e {
            ::gltf::Error::Validation(errors) => {
                let list: Vec<String> = errors
                    .iter()
                    .take(8)
                    .map(|(path, err)| format!("{path}: {err}"))
                    .collect();
                let more = errors.len().saturating_sub(8);
                let more = if more > 0 {
                    format!(" (and {more} more)")
                } else {
                    String::new()
                };
                anyhow!("{file}: invalid glTF: {}{more}", list.join("; "))
            }
            other => anyhow!("{file}: invalid glTF: {other}"),
        })?;
    Ok(::gltf::Gltf { document, blob })
}

/// References the crate's validation follows without a bounds check.
fn check_references(json: &::gltf::json::Root) -> anyhow::Result<()> {
    let n = json.accessors.len();
    for (m, mesh) in json.meshes.iter().enumerate() {
        for (p, prim) in mesh.primitives.iter().enumerate() {
            for (semantic, index) in &prim.attributes {
                if index.value() >= n {
                    let name = match semantic {
                        Checked::Valid(s) => s.to_string(),
                        Checked::Invalid => "?".to_string(),
                    };
                    bail!(
                        "meshes[{m}].primitives[{p}].attributes.{name}: accessor {} does not exist (the file has {n} accessors)",
                        index.value()
                    );
                }
            }
        }
    }
    Ok(())
}

/// What a vertex attribute or index list may be stored as.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Role {
    /// POSITION: VEC3 of FLOAT.
    Position,
    /// NORMAL: VEC3 of FLOAT.
    Normal,
    /// TEXCOORD_n: VEC2 of FLOAT, or of normalised UNSIGNED_BYTE / UNSIGNED_SHORT.
    TexCoord,
    /// Indices: SCALAR of UNSIGNED_BYTE, UNSIGNED_SHORT or UNSIGNED_INT.
    Indices,
}

fn type_name(d: Dimensions) -> &'static str {
    match d {
        Dimensions::Scalar => "SCALAR",
        Dimensions::Vec2 => "VEC2",
        Dimensions::Vec3 => "VEC3",
        Dimensions::Vec4 => "VEC4",
        Dimensions::Mat2 => "MAT2",
        Dimensions::Mat3 => "MAT3",
        Dimensions::Mat4 => "MAT4",
    }
}

fn component_name(t: DataType) -> &'static str {
    match t {
        DataType::I8 => "BYTE",
        DataType::U8 => "UNSIGNED_BYTE",
        DataType::I16 => "SHORT",
        DataType::U16 => "UNSIGNED_SHORT",
        DataType::U32 => "UNSIGNED_INT",
        DataType::F32 => "FLOAT",
    }
}

/// `Err(why)` unless `acc` is stored the way `role` must be (glTF 2.0 §3.7.2), with a count
/// of at least one and, in a buffer view, a stride no shorter than an element.
pub fn check_accessor(acc: &::gltf::Accessor, role: Role) -> Result<(), String> {
    let (dims, ty, norm) = (acc.dimensions(), acc.data_type(), acc.normalized());
    let ok = match role {
        Role::Position | Role::Normal => dims == Dimensions::Vec3 && ty == DataType::F32,
        Role::TexCoord => {
            dims == Dimensions::Vec2
                && (ty == DataType::F32 || (norm && matches!(ty, DataType::U8 | DataType::U16)))
        }
        Role::Indices => {
            dims == Dimensions::Scalar
                && !norm
                && matches!(ty, DataType::U8 | DataType::U16 | DataType::U32)
        }
    };
    let want = match role {
        Role::Position | Role::Normal => "VEC3 of FLOAT",
        Role::TexCoord => "VEC2 of FLOAT, or of normalized UNSIGNED_BYTE or UNSIGNED_SHORT",
        Role::Indices => "SCALAR of UNSIGNED_BYTE, UNSIGNED_SHORT or UNSIGNED_INT",
    };
    let normalized = if norm { "normalized " } else { "" };
    if !ok {
        return Err(format!(
            "accessor {} is {} of {normalized}{}, glTF requires {want}",
            acc.index(),
            type_name(dims),
            component_name(ty)
        ));
    }
    if acc.count() == 0 {
        return Err(format!("accessor {} has count 0", acc.index()));
    }
    if let Some(view) = acc.view()
        && let Some(stride) = view.stride()
        && stride < acc.size()
    {
        return Err(format!(
            "accessor {}: buffer view {} has byteStride {stride}, shorter than one element ({} bytes)",
            acc.index(),
            view.index(),
            acc.size()
        ));
    }
    Ok(())
}
