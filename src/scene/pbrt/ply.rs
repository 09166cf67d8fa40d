//! PLY meshes (ASCII and binary, either endianness) via `ply-rs-bw`: positions, optional
//! normals and uvs, triangle and quad faces (larger polygons are triangulated by
//! [`crate::scene::polygon`]).

use crate::scene::polygon::triangulate;
use anyhow::{Context, anyhow};
use glam::{Vec2, Vec3};
use ply_rs_bw::parser::{Parser, Reader};
use ply_rs_bw::ply::{BeginList, PropertyAccess, PropertyAccessResult};
use std::path::Path;

/// The mesh read from a PLY file (object space, unvalidated indices).
#[derive(Debug, Default)]
pub struct PlyMesh {
    /// Positions.
    pub positions: Vec<Vec3>,
    /// Per-vertex normals if the file has nx, ny, nz.
    pub normals: Option<Vec<Vec3>>,
    /// Per-vertex uvs if the file has u/v (or s/t, texture_u/texture_v, …).
    pub uvs: Option<Vec<Vec2>>,
    /// Triangle indices.
    pub indices: Vec<u32>,
    /// Faces with more than four vertices (triangulated).
    pub big_polygons: usize,
}

#[derive(Default)]
struct V {
    p: [f32; 3],
    n: [f32; 3],
    uv: [f32; 2],
}

impl V {
    fn set(&mut self, name: &str, v: f32) -> PropertyAccessResult {
        match name {
            "x" => self.p[0] = v,
            "y" => self.p[1] = v,
            "z" => self.p[2] = v,
            "nx" => self.n[0] = v,
            "ny" => self.n[1] = v,
            "nz" => self.n[2] = v,
            "u" | "s" | "texture_u" | "texture_s" => self.uv[0] = v,
            "v" | "t" | "texture_v" | "texture_t" => self.uv[1] = v,
            _ => return PropertyAccessResult::Ignored,
        }
        PropertyAccessResult::Set
    }
}

impl PropertyAccess for V {
    fn new() -> Self {
        Self::default()
    }
    fn set_float(&mut self, name: &str, v: f32) -> PropertyAccessResult {
        self.set(name, v)
    }
    fn set_double(&mut self, name: &str, v: f64) -> PropertyAccessResult {
        self.set(name, v as f32)
    }
    fn set_property(&mut self, name: &str, p: ply_rs_bw::ply::Property) -> PropertyAccessResult {
        match p.to_f32_lossy() {
            Some(v) => self.set(name, v),
            None => PropertyAccessResult::Ignored,
        }
    }
}

#[derive(Default)]
struct F {
    idx: Vec<u32>,
    signed: Vec<i32>,
}

fn is_index_list(name: &str) -> bool {
    name == "vertex_indices" || name == "vertex_index"
}

impl PropertyAccess for F {
    fn new() -> Self {
        Self::default()
    }
    fn begin_list_uint(&mut self, name: &str, _len: usize) -> BeginList<'_, u32> {
        if is_index_list(name) {
            BeginList::Fill(&mut self.idx)
        } else {
            BeginList::UseSetter
        }
    }
    fn begin_list_int(&mut self, name: &str, _len: usize) -> BeginList<'_, i32> {
        if is_index_list(name) {
            BeginList::Fill(&mut self.signed)
        } else {
            BeginList::UseSetter
        }
    }
    fn set_property(&mut self, name: &str, p: ply_rs_bw::ply::Property) -> PropertyAccessResult {
        use ply_rs_bw::ply::Property as P;
        if !is_index_list(name) {
            return PropertyAccessResult::Ignored;
        }
        match p {
            P::ListUChar(v) => self.idx = v.into_iter().map(u32::from).collect(),
            P::ListUShort(v) => self.idx = v.into_iter().map(u32::from).collect(),
            P::ListChar(v) => self.signed = v.into_iter().map(i32::from).collect(),
            P::ListShort(v) => self.signed = v.into_iter().map(i32::from).collect(),
            _ => return PropertyAccessResult::UnsupportedType,
        }
        PropertyAccessResult::Set
    }
}

/// Read a PLY file. Errors name the file; negative indices are errors.
pub fn read_ply(path: &Path) -> anyhow::Result<PlyMesh> {
    let file =
        std::fs::File::open(path).with_context(|| format!("cannot open {}", path.display()))?;
    let mut r = Reader::new(std::io::BufReader::with_capacity(1 << 20, file));
    let vp = Parser::<V>::new();
    let fp = Parser::<F>::new();
    let header = vp
        .read_header(&mut r)
        .map_err(|e| anyhow!("{}: bad PLY header: {e}", path.display()))?;
    let mut mesh = PlyMesh::default();
    let mut have_vertices = false;
    for (_, el) in &header.elements {
        match el.name.as_str() {
            "vertex" => {
                let has = |n: &str| el.properties.contains_key(n);
                let has_n = has("nx") && has("ny") && has("nz");
                let has_uv = ["u", "s", "texture_u", "texture_s"].iter().any(|n| has(n))
                    && ["v", "t", "texture_v", "texture_t"].iter().any(|n| has(n));
                if !(has("x") && has("y") && has("z")) {
                    return Err(anyhow!(
                        "{}: PLY vertex element lacks x, y, z",
                        path.display()
                    ));
                }
                let vs = vp
                    .read_payload_for_element(&mut r, el, &header)
                    .map_err(|e| anyhow!("{}: bad PLY vertex data: {e}", path.display()))?;
                mesh.positions = vs.iter().map(|v| Vec3::from_array(v.p)).collect();
                if has_n {
                    mesh.normals = Some(vs.iter().map(|v| Vec3::from_array(v.n)).collect());
                }
                if has_uv {
                    mesh.uvs = Some(vs.iter().map(|v| Vec2::from_array(v.uv)).collect());
                }
                have_vertices = true;
            }
            "face" => {
                if !el.properties.keys().any(|k| is_index_list(k)) {
                    return Err(anyhow!(
                        "{}: PLY face element lacks vertex_indices",
                        path.display()
                    ));
                }
                let fs = fp
                    .read_payload_for_element(&mut r, el, &header)
                    .map_err(|e| anyhow!("{}: bad PLY face data: {e}", path.display()))?;
                mesh.indices.reserve(fs.len() * 3);
                let mut poly: Vec<u32> = Vec::new();
                for f in &fs {
                    let ix: &[u32] = if f.signed.is_empty() {
                        &f.idx
                    } else {
                        if f.signed.iter().any(|&i| i < 0) {
                            return Err(anyhow!(
                                "{}: negative vertex index in PLY face",
                                path.display()
                            ));
                        }
                        poly.clear();
                        poly.extend(f.signed.iter().map(|&i| i as u32));
                        &poly
                    };
                    if ix.len() < 3 {
                        return Err(anyhow!(
                            "{}: PLY face with {} vertices (expected at least 3)",
                            path.display(),
                            ix.len()
                        ));
                    }
                    if ix.len() > 4 {
                        mesh.big_polygons += 1;
                    }
                    // Quads split along (0, 2) as pbrt does; larger polygons as OBJ faces are.
                    triangulate(ix, &mesh.positions, &mut mesh.indices);
                }
            }
            _ => {
                // Other elements (e.g. pbrt's face_indices live in "face"; edges, materials)
                // must still be consumed to keep the reader in sync.
                Parser::<ply_rs_bw::ply::DefaultElement>::new()
                    .read_payload_for_element(&mut r, el, &header)
                    .map_err(|e| {
                        anyhow!("{}: bad PLY data in '{}': {e}", path.display(), el.name)
                    })?;
            }
        }
    }
    if !have_vertices {
        return Err(anyhow!(
            "{}: PLY file has no vertex element",
            path.display()
        ));
    }
    Ok(mesh)
}
