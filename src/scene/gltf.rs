//! glTF 2.0 loader (`.gltf` with external or `data:` buffers, and binary `.glb`).
//!
//! The `gltf` crate parses and validates the document; buffers and images are resolved here
//! (GLB blob, files next to the asset, base64 `data:` URIs) so no extra crate features are
//! needed. Node hierarchies are flattened to world space. Supported: triangle primitives,
//! the first perspective camera, metallic-roughness materials with base-colour textures
//! ([`gltf_material`]), `alphaMode` `MASK`/`BLEND` as cut-outs ([`super::gltf_alpha`]),
//! emissive materials (× `KHR_materials_emissive_strength`) as area
//! lights, and `KHR_lights_punctual` point/spot/directional lights ([`punctual_light`]).
//!
//! Photometric units: glTF gives point/spot intensity in candela and directional
//! illuminance in lux. We divide both by 683 lm/W ([`LUMENS_PER_WATT`]), the luminous
//! efficacy at 555 nm, the same factor glTF viewers and exporters (e.g. Blender) use to map
//! between watts and lumens; so 683 cd → 1 W/sr and 683 lux → 1 W/m².

use super::gltf_alpha::material_alpha;
use super::gltf_check::{Role, check_accessor, parse_document};
use super::load::{LoadOptions, Loaded, warn_if_unlit};
use super::view::{DEFAULT_FOV_DEG, apply_view_flags, auto_frame, default_film, place_auto_camera};
use super::{AreaEmission, SceneBuilder, TriangleMesh, guard};
use crate::Rgb;
use crate::camera::Camera;
use crate::geometry::{Alpha, Transform};
use crate::image::io::srgb_to_linear;
use crate::lights::{DistantLight, Light, PointLight, SpotLight};
use crate::material::texture::ImageRgb;
use crate::material::{Material, NormalPerturbation, Texture, VaryingMaterial};
use ::gltf::khr_lights_punctual::Kind;
use anyhow::{Context, anyhow, bail, ensure};
use glam::{Mat4, UVec2, Vec2, Vec3};
use std::path::Path;
use std::sync::Arc;

/// Luminous efficacy (lm/W) used to turn candela into W/sr and lux into W/m².
pub const LUMENS_PER_WATT: f32 = 683.0;

/// Deepest node hierarchy followed (guards against cycles in unvalidated files).
const MAX_DEPTH: usize = 256;

/// Load a `.gltf` or `.glb` file.
pub fn load_gltf(path: &Path, opts: &LoadOptions) -> anyhow::Result<Loaded> {
    let file = path.display().to_string();
    // The gltf crate and our accessor reads run on untrusted data: a panic becomes an error,
    // and its text stays out of the user's terminal.
    guard::catch(|| load_inner(path, opts))
        .map_err(|_| anyhow!("{file}: the glTF reader crashed on this file"))?
}

fn load_inner(path: &Path, opts: &LoadOptions) -> anyhow::Result<Loaded> {
    let file = path.display().to_string();
    let bytes = std::fs::read(path).with_context(|| format!("{file}: cannot read"))?;
    let doc = parse_document(&bytes, &file)?;
    let dir = path.parent().unwrap_or(Path::new(""));
    let buffers = load_buffers(&doc, dir, &file)?;
    let mut warnings = Vec::new();
    let mut images: Vec<ImageSlot> = vec![[None, None, None]; doc.images().len()];

    let mut b = SceneBuilder::new();
    // Materials: one per glTF material (same index), plus the spec's default material.
    let mut mats = Vec::new();
    for m in doc.materials() {
        let (mat, emission, alpha) =
            gltf_material(&m, &buffers, dir, &mut images, &file, &mut warnings);
        mats.push((b.add_material(mat), emission, alpha));
    }

    let scene = doc
        .default_scene()
        .or_else(|| doc.scenes().next())
        .ok_or_else(|| anyhow!("{file}: the file has no scene"))?;
    let mut ctx = Walk {
        buffers: &buffers,
        mats: &mats,
        default_id: None,
        dir,
        images: &mut images,
        b: &mut b,
        warnings: &mut warnings,
        file: &file,
        camera: None,
        triangles: 0,
    };
    for node in scene.nodes() {
        ctx.visit(&node, Mat4::IDENTITY, 0)?;
    }
    let Walk {
        camera, triangles, ..
    } = ctx;
    if b.primitive_count() == 0 {
        if triangles > 0 {
            bail!("{file}: no triangle is left: every one has zero area or a non-finite vertex");
        }
        bail!("{file}: the scene has no triangles");
    }
    let mut film = default_film();
    let file_camera = match camera {
        Some((m, persp)) => {
            let (cam, res) = gltf_camera(m, persp.yfov, persp.aspect)
                .with_context(|| format!("{file}: camera"))?;
            film.resolution = res;
            Some(cam)
        }
        None => None,
    };
    let has_camera = file_camera.is_some();
    // Without a camera in the file, a placeholder until the scene exists to be probed.
    let camera = match file_camera {
        Some(c) => c,
        None => auto_frame(Vec3::ZERO, Vec3::ONE, DEFAULT_FOV_DEG)?,
    };
    let mut scene = b
        .build(camera, film)
        .with_context(|| format!("{file}: building the scene"))?;
    let note = if has_camera {
        apply_view_flags(&mut scene, &opts.view)
    } else {
        place_auto_camera(&mut scene, &opts.view).map(Some)
    }
    .with_context(|| format!("{file}: camera"))?;
    warn_if_unlit(&scene, &file, "", &mut warnings);
    Ok(Loaded {
        scene,
        warnings,
        notes: note.map(|n| format!("{file}: {n}")).into_iter().collect(),
    })
}

/// The parts of a glTF perspective camera we use.
#[derive(Clone, Copy, Debug)]
pub struct Perspective {
    /// Vertical field of view in radians.
    pub yfov: f32,
    /// Width / height, if the file gives it.
    pub aspect: Option<f32>,
}

/// Our camera and film resolution for a glTF perspective camera whose node has world matrix
/// `world`. glTF cameras look down their local −z with +y up and +x right (right-handed); the
/// film keeps 512 pixels on its longer axis at the file's aspect ratio. glTF's `yfov` is
/// vertical while our fov spans the shorter axis, so portrait images (aspect < 1) convert it
/// to the horizontal fov: tan(x/2) = aspect · tan(yfov/2).
pub fn gltf_camera(world: Mat4, yfov: f32, aspect: Option<f32>) -> anyhow::Result<(Camera, UVec2)> {
    ensure!(
        yfov.is_finite() && yfov > 0.0 && yfov < std::f32::consts::PI,
        "camera yfov must be in (0, π), got {yfov}"
    );
    let aspect = aspect.filter(|a| a.is_finite() && *a > 0.0).unwrap_or(1.0);
    let res = if aspect >= 1.0 {
        UVec2::new(512, ((512.0 / aspect).round() as u32).max(1))
    } else {
        UVec2::new(((512.0 * aspect).round() as u32).max(1), 512)
    };
    let fov = if aspect >= 1.0 {
        yfov
    } else {
        2.0 * (aspect * (0.5 * yfov).tan()).atan()
    };
    let eye = world.transform_point3(Vec3::ZERO);
    let fwd = world.transform_vector3(Vec3::NEG_Z);
    let up = world.transform_vector3(Vec3::Y);
    let cam = super::view::right_handed_look_at(eye, eye + fwd, up, fov.to_degrees())
        .context("glTF camera node")?;
    Ok((cam, res))
}

/// Depth-first traversal state: accumulates geometry, lights and the first camera.
struct Walk<'a> {
    buffers: &'a [Vec<u8>],
    mats: &'a [MaterialIds],
    /// The spec's default material, added when a primitive first needs it.
    default_id: Option<MaterialIds>,
    dir: &'a Path,
    images: &'a mut [ImageSlot],
    b: &'a mut SceneBuilder,
    warnings: &'a mut Vec<String>,
    file: &'a str,
    camera: Option<(Mat4, Perspective)>,
    /// Triangles found, before repair (tells "all dropped" from "none there").
    triangles: usize,
}

impl Walk<'_> {
    fn visit(&mut self, node: &::gltf::Node, parent: Mat4, depth: usize) -> anyhow::Result<()> {
        let file = self.file;
        ensure!(
            depth < MAX_DEPTH,
            "{file}: node hierarchy deeper than {MAX_DEPTH} (a cycle?)"
        );
        let local = Mat4::from_cols_array_2d(&node.transform().matrix());
        let world = parent * local;
        ensure!(
            world.is_finite(),
            "{file}: node {} has a non-finite transform",
            node.index()
        );
        if let Some(cam) = node.camera() {
            match cam.projection() {
                ::gltf::camera::Projection::Perspective(p) => {
                    if self.camera.is_none() {
                        self.camera = Some((
                            world,
                            Perspective {
                                yfov: p.yfov(),
                                aspect: p.aspect_ratio(),
                            },
                        ));
                    }
                }
                ::gltf::camera::Projection::Orthographic(_) => self.warnings.push(format!(
                    "{file}: node {}: orthographic cameras are not supported, ignored",
                    node.index()
                )),
            }
        }
        if let Some(light) = node.light() {
            if light.range().is_some() {
                self.warnings.push(format!(
                    "{file}: light {}: range is ignored (inverse-square falloff only)",
                    light.index()
                ));
            }
            let color = Rgb::from_array(light.color());
            let (i, at) = (
                light.intensity(),
                format!("{file}: KHR_lights_punctual lights[{}]", light.index()),
            );
            if !(i.is_finite() && i >= 0.0) {
                self.warnings.push(format!(
                    "{at}: intensity {i} is not a finite non-negative number; the light is black"
                ));
            }
            if !(color.is_finite() && color.min_element() >= 0.0) {
                self.warnings.push(format!(
                    "{at}: color [{} {} {}] is not finite and non-negative; negative or non-finite components taken as 0",
                    color.x, color.y, color.z
                ));
            }
            self.b.add_light(punctual_light(
                light.kind(),
                color,
                light.intensity(),
                world,
            ));
        }
        if let Some(mesh) = node.mesh() {
            self.add_mesh(&mesh, world)
                .with_context(|| format!("{file}: nodes[{}]", node.index()))?;
        }
        for child in node.children() {
            self.visit(&child, world, depth + 1)?;
        }
        Ok(())
    }

    fn add_mesh(&mut self, mesh: &::gltf::Mesh, world: Mat4) -> anyhow::Result<()> {
        let xf = Transform::new(world).ok_or_else(|| anyhow!("singular node transform"))?;
        let mesh_name = match mesh.name() {
            Some(n) => format!("meshes[{}] '{n}'", mesh.index()),
            None => format!("meshes[{}]", mesh.index()),
        };
        for prim in mesh.primitives() {
            let at = format!("{}: {mesh_name} primitives[{}]", self.file, prim.index());
            if prim.mode() != ::gltf::mesh::Mode::Triangles {
                self.warnings.push(format!(
                    "{at}: mode {:?} skipped (triangles only)",
                    prim.mode()
                ));
                continue;
            }
            let pos_acc = prim.get(&::gltf::Semantic::Positions).ok_or_else(|| {
                anyhow!(
                    "{mesh_name} primitives[{}]: no POSITION attribute",
                    prim.index()
                )
            })?;
            check_accessor(&pos_acc, Role::Position)
                .map_err(|e| anyhow!("{mesh_name} primitives[{}]: POSITION {e}", prim.index()))?;
            if let Some(ix) = prim.indices() {
                check_accessor(&ix, Role::Indices).map_err(|e| {
                    anyhow!("{mesh_name} primitives[{}]: indices {e}", prim.index())
                })?;
            }
            // Attributes a renderer can do without are dropped with a warning when misdeclared.
            let normals_ok = match prim.get(&::gltf::Semantic::Normals) {
                Some(acc) => check_accessor(&acc, Role::Normal)
                    .map_err(|e| {
                        self.warnings
                            .push(format!("{at}: NORMAL {e}; geometric normals used"))
                    })
                    .is_ok(),
                None => false,
            };
            let uvs_ok = match prim.get(&::gltf::Semantic::TexCoords(0)) {
                Some(acc) => check_accessor(&acc, Role::TexCoord)
                    .map_err(|e| {
                        self.warnings
                            .push(format!("{at}: TEXCOORD_0 {e}; texture coordinates ignored"))
                    })
                    .is_ok(),
                None => false,
            };
            let buffers = self.buffers;
            let reader = prim.reader(|buf| buffers.get(buf.index()).map(|v| v.as_slice()));
            let positions: Vec<Vec3> = reader
                .read_positions()
                .ok_or_else(|| {
                    anyhow!(
                        "{mesh_name} primitives[{}]: POSITION accessor {} lies outside its buffer",
                        prim.index(),
                        pos_acc.index()
                    )
                })?
                .map(|p| xf.point(Vec3::from_array(p)))
                .collect();
            let nv = positions.len();
            let indices: Vec<u32> = match reader.read_indices() {
                Some(ix) => ix.into_u32().collect(),
                None if prim.indices().is_some() => bail!(
                    "{mesh_name} primitives[{}]: the indices accessor lies outside its buffer",
                    prim.index()
                ),
                None => (0..nv as u32).collect(),
            };
            let mut normals = None;
            if normals_ok {
                normals = reader.read_normals().map(|ns| {
                    ns.map(|n| xf.normal(Vec3::from_array(n)))
                        .collect::<Vec<_>>()
                });
                match &normals {
                    Some(n) if n.len() == nv => {}
                    _ => {
                        self.warnings.push(format!(
                            "{at}: NORMAL does not match POSITION (missing data or another count); geometric normals used"
                        ));
                        normals = None;
                    }
                }
            }
            // glTF's uv origin is the image's top-left, ours (pbrt) the bottom-left.
            let mut uvs = None;
            if uvs_ok {
                uvs = reader.read_tex_coords(0).map(|t| {
                    t.into_f32()
                        .map(|[u, v]| Vec2::new(u, 1.0 - v))
                        .collect::<Vec<_>>()
                });
                match &uvs {
                    Some(u) if u.len() == nv => {}
                    _ => {
                        self.warnings.push(format!(
                            "{at}: TEXCOORD_0 does not match POSITION (missing data or another count); texture coordinates ignored"
                        ));
                        uvs = None;
                    }
                }
            }
            let (mat, emission, alpha) = match prim.material().index() {
                Some(i) => self
                    .mats
                    .get(i)
                    .ok_or_else(|| anyhow!("material {i} out of range"))?
                    .clone(),
                None => match &self.default_id {
                    Some(d) => d.clone(),
                    None => {
                        let (m, e, a) = gltf_material(
                            &prim.material(),
                            buffers,
                            self.dir,
                            self.images,
                            self.file,
                            self.warnings,
                        );
                        let d = (self.b.add_material(m), e, a);
                        self.default_id = Some(d.clone());
                        d
                    }
                },
            };
            self.triangles += indices.len() / 3;
            let mesh = TriangleMesh {
                positions,
                normals,
                uvs,
                indices,
                flip_normals: xf.swaps_handedness(),
            };
            let repair = self
                .b
                .add_mesh_cut_out(mesh, mat, emission, alpha)
                .with_context(|| format!("{mesh_name} primitives[{}]", prim.index()))?;
            if !repair.is_clean() {
                self.warnings.push(format!("{at}: {}", repair.describe()));
            }
        }
        Ok(())
    }
}

/// A `KHR_lights_punctual` light at the node with world matrix `world` (lights shine down
/// their local −z). Intensities are photometric: see [`LUMENS_PER_WATT`].
pub fn punctual_light(kind: Kind, color: Rgb, intensity: f32, world: Mat4) -> Light {
    let intensity = if intensity.is_finite() {
        intensity.max(0.0)
    } else {
        0.0
    };
    let color = Rgb::from_array(
        color
            .to_array()
            .map(|c| if c.is_finite() { c.max(0.0) } else { 0.0 }),
    );
    let radiometric = color * intensity / LUMENS_PER_WATT;
    let p = world.transform_point3(Vec3::ZERO);
    let dir = world.transform_vector3(Vec3::NEG_Z).normalize_or_zero();
    match kind {
        Kind::Point => Light::Point(PointLight::new(p, radiometric)),
        Kind::Spot {
            inner_cone_angle,
            outer_cone_angle,
        } => Light::Spot(SpotLight::new(
            p,
            dir,
            radiometric,
            inner_cone_angle.cos(),
            outer_cone_angle.cos(),
        )),
        Kind::Directional => Light::Distant(DistantLight::new(-dir, radiometric)),
    }
}

/// Map a glTF material to ours plus its emission (the one place the mapping lives).
///
/// Base colour = `baseColorFactor` × `baseColorTexture` (sRGB-decoded); GGX alpha =
/// roughness² (the glTF/Disney remapping). By `metallicFactor` m (textures are not read):
/// - m = 0 → Lambertian diffuse with the base colour (glTF's ~4 % dielectric specular is
///   dropped, so diffuse scenes compare exactly with diffuse references);
/// - 0 < m < 0.5 → coated diffuse (IOR 1.5 coat, base colour × (1 − m)), the closest of our
///   materials to glTF's dielectric/metal blend that stays mostly dielectric;
/// - m ≥ 0.5 → GGX conductor whose normal-incidence reflectance is the base colour (glTF's
///   metal F0).
///
/// Emission = `emissiveFactor` × `emissiveStrength`, two-sided if the material is
/// double-sided.
fn gltf_material(
    m: &::gltf::Material,
    buffers: &[Vec<u8>],
    dir: &Path,
    images: &mut [ImageSlot],
    file: &str,
    warnings: &mut Vec<String>,
) -> (Material, Option<AreaEmission>, Option<Alpha>) {
    let name = m
        .name()
        .map(str::to_string)
        .unwrap_or_else(|| format!("#{}", m.index().map_or(-1, |i| i as i64)));
    let pbr = m.pbr_metallic_roughness();
    let [r, g, bl, a] = pbr.base_color_factor();
    let factor = Rgb::new(r, g, bl);
    let factor = if factor.is_finite() {
        factor.max(Rgb::ZERO)
    } else {
        Rgb::ONE
    };
    // Image `img` decoded (sRGB-linearised for colours, as stored for data), once per use.
    let mut decoded_image =
        |img: ::gltf::Image, how: Decode, instead: &str, warnings: &mut Vec<String>| {
            let idx = img.index();
            match images.get_mut(idx) {
                Some(slot) => slot[how as usize]
                    .get_or_insert_with(|| match decode_image(&img, buffers, dir, how) {
                        Ok(i) => Some(Arc::new(i)),
                        Err(e) => {
                            warnings.push(format!(
                                "{file}: image {idx}: {e:#}; material '{name}' {instead}"
                            ));
                            None
                        }
                    })
                    .clone(),
                None => None,
            }
        };
    let base = match pbr.base_color_texture() {
        Some(info) => {
            let decoded = decoded_image(
                info.texture().source(),
                Decode::Srgb,
                "uses its base colour factor",
                warnings,
            );
            if info.tex_coord() != 0 {
                warnings.push(format!(
                    "{file}: material '{name}': texture uses TEXCOORD_{}, only TEXCOORD_0 is read",
                    info.tex_coord()
                ));
            }
            match decoded {
                Some(image) => Texture::Image {
                    image,
                    scale: factor,
                },
                None => Texture::Constant(factor),
            }
        }
        None => Texture::Constant(factor),
    };
    // The cut-out (`alphaMode`): the base-colour texture's alpha channel, where it has one
    // that is not 1 everywhere.
    let alpha_image = match (m.alpha_mode(), pbr.base_color_texture()) {
        (::gltf::material::AlphaMode::Opaque, _) | (_, None) => None,
        (_, Some(info)) => decoded_image(
            info.texture().source(),
            Decode::Alpha,
            "uses its base colour factor's alpha",
            warnings,
        )
        .filter(|img| img.pixels.iter().any(|p| p.x < 1.0)),
    };
    let cut_out = material_alpha(m.alpha_mode(), m.alpha_cutoff(), a, alpha_image);
    let at = match m.index() {
        Some(i) => format!("{file}: materials[{i}] '{name}'"),
        None => format!("{file}: default material"),
    };
    let strength = match m.emissive_strength() {
        Some(s) if !(s.is_finite() && s >= 0.0) => {
            warnings.push(format!(
                "{at}: KHR_materials_emissive_strength {s} is not a finite non-negative number; 1 used"
            ));
            1.0
        }
        Some(s) => s,
        None => 1.0,
    };
    let factor_e = Rgb::from_array(m.emissive_factor());
    let le = factor_e * strength;
    let le = if !factor_e.is_finite() {
        warnings.push(format!(
            "{at}: emissiveFactor [{} {} {}] is not finite (beyond f32); the material does not emit",
            factor_e.x, factor_e.y, factor_e.z
        ));
        Rgb::ZERO
    } else if !le.is_finite() {
        warnings.push(format!(
            "{at}: emissiveFactor × emissive strength {strength} overflows f32; the material does not emit"
        ));
        Rgb::ZERO
    } else {
        if le.min_element() < 0.0 {
            warnings.push(format!(
                "{at}: emissiveFactor [{} {} {}] has a negative component, taken as 0",
                factor_e.x, factor_e.y, factor_e.z
            ));
        }
        le.max(Rgb::ZERO)
    };
    let emission = (le.max_element() > 0.0).then(|| AreaEmission {
        l: le,
        two_sided: m.double_sided(),
    });
    let finite01 = |x: f32, d: f32| if x.is_finite() { x.clamp(0.0, 1.0) } else { d };
    let metallic = finite01(pbr.metallic_factor(), 1.0);
    let roughness = finite01(pbr.roughness_factor(), 1.0);
    if pbr.metallic_roughness_texture().is_some() {
        warnings.push(format!(
            "{file}: material '{name}': metallicRoughnessTexture ignored (factors only)"
        ));
    }
    let alpha = Vec2::splat(roughness * roughness);
    let material = if metallic == 0.0 {
        Material::Diffuse { reflectance: base }
    } else if metallic < 0.5 {
        let reflectance = match base {
            Texture::Image { image, scale } => Texture::Image {
                image,
                scale: scale * (1.0 - metallic),
            },
            Texture::Constant(c) => Texture::Constant(c * (1.0 - metallic)),
            other => other,
        };
        Material::CoatedDiffuse {
            reflectance,
            alpha,
            eta: 1.5,
            layer: None,
        }
    } else {
        Material::Conductor {
            eta: Rgb::ONE,
            k: Rgb::ZERO,
            alpha,
            reflectance: Some(base),
        }
    };
    // The normal texture: tangent-space normals, x along ∂p/∂u, y on ∂p/∂v's side (the
    // bitangent sign MikkTSpace stores in TANGENT.w), scaled in x and y by `scale`.
    let material = match m.normal_texture() {
        Some(info) => {
            let decoded = decoded_image(
                info.texture().source(),
                Decode::Linear,
                "has no normal map",
                warnings,
            );
            if info.tex_coord() != 0 {
                warnings.push(format!(
                    "{file}: material '{name}': normalTexture uses TEXCOORD_{}, only TEXCOORD_0 is read",
                    info.tex_coord()
                ));
            }
            match decoded {
                Some(image) => {
                    warnings.push(format!(
                        "{file}: material '{name}': normalTexture tangents are each triangle's ∂p/∂u (TANGENT attributes and MikkTSpace's per-vertex smoothing are not used)"
                    ));
                    let scale = if info.scale().is_finite() {
                        info.scale()
                    } else {
                        1.0
                    };
                    Material::Varying(Box::new(VaryingMaterial {
                        base: material,
                        roughness: None,
                        coat_roughness: None,
                        normal: Some(NormalPerturbation::NormalMap {
                            image,
                            scale,
                            uv_handed: true,
                        }),
                        layer: None,
                    }))
                }
                None => material,
            }
        }
        None => material,
    };
    (material, emission, cut_out)
}

/// Bytes of every buffer: the GLB blob, a file next to the asset, or a base64 `data:` URI.
fn load_buffers(doc: &::gltf::Gltf, dir: &Path, file: &str) -> anyhow::Result<Vec<Vec<u8>>> {
    let mut out = Vec::new();
    for buf in doc.buffers() {
        let data = match buf.source() {
            ::gltf::buffer::Source::Bin => doc.blob.clone().ok_or_else(|| {
                anyhow!(
                    "{file}: buffer {} refers to a missing GLB binary chunk",
                    buf.index()
                )
            })?,
            ::gltf::buffer::Source::Uri(uri) => {
                read_uri(uri, dir).with_context(|| format!("{file}: buffer {}", buf.index()))?
            }
        };
        ensure!(
            data.len() >= buf.length(),
            "{file}: buffer {} holds {} bytes but declares {} (truncated file?)",
            buf.index(),
            data.len(),
            buf.length()
        );
        out.push(data);
    }
    Ok(out)
}

/// Read a URI: `data:...;base64,` inline data or a (percent-encoded) relative file path.
fn read_uri(uri: &str, dir: &Path) -> anyhow::Result<Vec<u8>> {
    if let Some(rest) = uri.strip_prefix("data:") {
        let (_, payload) = rest
            .split_once(";base64,")
            .ok_or_else(|| anyhow!("only base64 data URIs are supported"))?;
        return decode_base64(payload);
    }
    let p = dir.join(percent_decode(uri));
    std::fs::read(&p).with_context(|| format!("cannot read {}", p.display()))
}

/// Minimal RFC 4648 base64 decoder (padding and whitespace tolerated).
fn decode_base64(s: &str) -> anyhow::Result<Vec<u8>> {
    let val = |c: u8| -> Option<u32> {
        Some(match c {
            b'A'..=b'Z' => c - b'A',
            b'a'..=b'z' => c - b'a' + 26,
            b'0'..=b'9' => c - b'0' + 52,
            b'+' | b'-' => 62,
            b'/' | b'_' => 63,
            _ => return None,
        } as u32)
    };
    let mut out = Vec::with_capacity(s.len() * 3 / 4);
    let (mut acc, mut bits) = (0u32, 0u32);
    for &c in s.as_bytes() {
        if c == b'=' || c.is_ascii_whitespace() {
            continue;
        }
        let v = val(c).ok_or_else(|| anyhow!("invalid base64 character {:?}", c as char))?;
        acc = (acc << 6) | v;
        bits += 6;
        if bits >= 8 {
            bits -= 8;
            out.push((acc >> bits) as u8);
            acc &= (1 << bits) - 1;
        }
    }
    Ok(out)
}

/// Undo `%XX` escapes in a relative URI (file names with spaces etc.).
fn percent_decode(s: &str) -> String {
    let b = s.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'%' && i + 2 < b.len() {
            let hex = std::str::from_utf8(&b[i + 1..i + 3]).ok();
            if let Some(v) = hex.and_then(|h| u8::from_str_radix(h, 16).ok()) {
                out.push(v);
                i += 3;
                continue;
            }
        }
        out.push(b[i]);
        i += 1;
    }
    String::from_utf8_lossy(&out).into_owned()
}

/// A glTF image decoded as data (`[0]`: normal maps) and as sRGB-linearised colour (`[1]`),
/// each when first used (`Some(None)`: it failed, and said so once).
type ImageSlot = [Option<Option<Arc<ImageRgb>>>; 3];

/// A glTF material as the scene holds it: material index, emission, cut-out.
type MaterialIds = (u32, Option<AreaEmission>, Option<Alpha>);

/// How an image is decoded: the slot of [`ImageSlot`] it fills.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Decode {
    /// Code value / 255 (normal textures are linear data).
    Linear = 0,
    /// sRGB-linearised colour (base-colour textures).
    Srgb = 1,
    /// The alpha channel (linear, as the spec stores it) in every channel.
    Alpha = 2,
}

/// Decode a glTF image (PNG/JPEG from a buffer view or URI) as `how` says.
fn decode_image(
    img: &::gltf::Image,
    buffers: &[Vec<u8>],
    dir: &Path,
    how: Decode,
) -> anyhow::Result<ImageRgb> {
    let owned;
    let bytes: &[u8] = match img.source() {
        ::gltf::image::Source::View { view, .. } => {
            let buf = buffers
                .get(view.buffer().index())
                .ok_or_else(|| anyhow!("buffer {} missing", view.buffer().index()))?;
            buf.get(view.offset()..view.offset() + view.length())
                .ok_or_else(|| anyhow!("buffer view {} out of range", view.index()))?
        }
        ::gltf::image::Source::Uri { uri, .. } => {
            owned = read_uri(uri, dir)?;
            &owned
        }
    };
    let decoded = image::load_from_memory(bytes).context("cannot decode image")?;
    let (w, h, pixels) = if how == Decode::Alpha {
        let rgba = decoded.to_rgba32f();
        let pixels = rgba.pixels().map(|p| Rgb::splat(p[3])).collect();
        (rgba.width(), rgba.height(), pixels)
    } else {
        let rgb = decoded.to_rgb32f();
        let srgb = how == Decode::Srgb;
        let f = |v: f32| if srgb { srgb_to_linear(v) } else { v };
        let pixels = rgb
            .pixels()
            .map(|p| Rgb::new(f(p[0]), f(p[1]), f(p[2])))
            .collect();
        (rgb.width(), rgb.height(), pixels)
    };
    Ok(ImageRgb {
        width: w,
        height: h,
        pixels,
    })
}
