//! pbrt-v3 files, read the way pbrt-v4's `pbrt --upgrade` rewrites them (its
//! `FormattingParserTarget`): v3 material, light and film names and parameters are renamed to
//! their pbrt-v4 equivalents before the v4 code reads them, and each rewrite is said once per
//! kind. Parameters `--upgrade` drops with a warning are dropped with a warning here too. Only
//! names pbrt-v4 does not define are rewritten, so pbrt-v4 files pass through unchanged.

use super::params::{ParamSet, ParamType, Values};
use super::textures::Warn;
use super::tokenizer::Loc;

/// Drop `name`; warn (as `--upgrade` does) unless it is the grey constant `value`. Returns
/// whether it was present and that constant.
fn remove_if_constant(
    ps: &mut ParamSet,
    ty: &str,
    name: &str,
    value: f64,
    warn: &mut Warn,
) -> bool {
    let Some(p) = ps.remove(name) else {
        return false;
    };
    let matches = p.constant() == Some(value);
    if !matches {
        warn(
            &format!("upgrade-drop-{ty}-{name}"),
            &p.loc,
            format!(
                "pbrt-v3 material \"{ty}\": parameter \"{name}\" has no pbrt-v4 equivalent and is dropped (as pbrt-v4's --upgrade does)"
            ),
        );
    }
    matches
}

fn said(warn: &mut Warn, loc: &Loc, what: &str, from: &str, to: &str) {
    warn(
        &format!("upgrade-{what}-{from}"),
        loc,
        format!(
            "pbrt-v3 {what} \"{from}\" read as pbrt-v4 \"{to}\" (the mapping of pbrt-v4's --upgrade)"
        ),
    );
}

/// v3 `index` → v4 `eta` (glass, uber).
fn index_to_eta(ps: &mut ParamSet) {
    if ps.has("index") && !ps.has("eta") {
        ps.rename("index", "eta");
    }
}

/// Rewrite a v3 material type and its parameters; returns the pbrt-v4 type.
pub fn material(ty: &str, ps: &mut ParamSet, loc: &Loc, warn: &mut Warn) -> String {
    ps.rename("bumpmap", "displacement");
    let new = match ty {
        "matte" => {
            ps.rename("Kd", "reflectance");
            "diffuse"
        }
        "plastic" => {
            let ks_zero = remove_if_constant(ps, ty, "Ks", 0.0, warn);
            ps.rename("Kd", "reflectance");
            if ks_zero {
                ps.remove("roughness");
                ps.remove("eta");
                "diffuse"
            } else {
                "coateddiffuse"
            }
        }
        "substrate" => {
            remove_if_constant(ps, ty, "Ks", 1.0, warn);
            ps.rename("Kd", "reflectance");
            "coateddiffuse"
        }
        "uber" => {
            index_to_eta(ps);
            let ks_zero = remove_if_constant(ps, ty, "Ks", 0.0, warn);
            remove_if_constant(ps, ty, "Kr", 0.0, warn);
            remove_if_constant(ps, ty, "Kt", 0.0, warn);
            ps.rename("Kd", "reflectance");
            if let Some(p) = ps.remove("opacity")
                && p.constant() != Some(1.0)
            {
                warn(
                    "upgrade-uber-opacity",
                    &p.loc,
                    "pbrt-v3 \"uber\" opacity is not supported by pbrt-v4 (its --upgrade refuses it); the surface is opaque".into(),
                );
            }
            if ks_zero {
                ps.remove("eta");
                ps.remove("roughness");
                "diffuse"
            } else {
                "coateddiffuse"
            }
        }
        "glass" => {
            index_to_eta(ps);
            remove_if_constant(ps, ty, "Kr", 1.0, warn);
            remove_if_constant(ps, ty, "Kt", 1.0, warn);
            "dielectric"
        }
        "metal" => {
            remove_if_constant(ps, ty, "Kr", 1.0, warn);
            "conductor"
        }
        "mirror" => {
            remove_if_constant(ps, ty, "Kr", 0.0, warn);
            let l = loc.clone();
            ps.push(
                ParamType::Float,
                "roughness",
                Values::Nums(vec![0.0]),
                l.clone(),
            );
            ps.push(
                ParamType::Spectrum,
                "eta",
                Values::Strs(vec!["metal-Ag-eta".into()]),
                l.clone(),
            );
            ps.push(
                ParamType::Spectrum,
                "k",
                Values::Strs(vec!["metal-Ag-k".into()]),
                l,
            );
            "conductor"
        }
        "translucent" => {
            ps.rename("Kd", "transmittance");
            remove_if_constant(ps, ty, "reflect", 0.0, warn);
            remove_if_constant(ps, ty, "transmit", 1.0, warn);
            remove_if_constant(ps, ty, "Ks", 0.0, warn);
            ps.remove("roughness");
            "diffusetransmission"
        }
        "disney" => {
            ps.rename("color", "reflectance");
            "diffuse"
        }
        "kdsubsurface" => {
            ps.rename("Kd", "reflectance");
            "subsurface"
        }
        "mix" if ps.has("namedmaterial1") => {
            mix(ps, loc, warn);
            return "mix".into();
        }
        _ => return ty.to_string(),
    };
    said(warn, loc, "material", ty, new);
    new.to_string()
}

/// v3 `mix`: `namedmaterial1/2` and an RGB `amount` → v4 `materials [m2 m1]` and a float.
fn mix(ps: &mut ParamSet, loc: &Loc, warn: &mut Warn) {
    let name = |ps: &mut ParamSet, n: &str| match ps.remove(n).map(|p| p.values) {
        Some(Values::Strs(v)) => v.first().cloned().unwrap_or_default(),
        _ => String::new(),
    };
    let (m1, m2) = (name(ps, "namedmaterial1"), name(ps, "namedmaterial2"));
    if let Some(a) = ps.remove("amount") {
        let v = match &a.values {
            Values::Nums(v) if !v.is_empty() => v.iter().sum::<f64>() / v.len() as f64,
            _ => 0.5,
        };
        ps.push(ParamType::Float, "amount", Values::Nums(vec![v]), a.loc);
    }
    // pbrt-v3's amount weights namedmaterial1; pbrt-v4's picks materials[1] with it.
    ps.push(
        ParamType::String,
        "materials",
        Values::Strs(vec![m2, m1]),
        loc.clone(),
    );
    said(
        warn,
        loc,
        "material",
        "mix (namedmaterial1/2)",
        "mix (materials)",
    );
}

/// Fold a v3 `[T scale]` blackbody and an RGB `scale` into the light's float `scale`.
fn light_scale(ps: &mut ParamSet, spectrum: &str, loc: &Loc, warn: &mut Warn) {
    let mut total = 1.0;
    if let Some(p) = ps.remove("scale") {
        match (p.ty, p.constant()) {
            (ParamType::Float, Some(v)) => total *= v,
            (ParamType::Rgb, Some(v)) => total *= v,
            _ => {
                let v = match &p.values {
                    Values::Nums(v) if !v.is_empty() => v.iter().sum::<f64>() / v.len() as f64,
                    _ => 1.0,
                };
                warn(
                    "upgrade-light-scale",
                    &p.loc,
                    format!(
                        "pbrt-v3 coloured light \"scale\" replaced by its average {v} (pbrt-v4's scale is a float)"
                    ),
                );
                total *= v;
            }
        }
    }
    if let Some(p) = ps.remove(spectrum) {
        let mut p2 = p.clone();
        if p.ty == ParamType::Blackbody
            && let Values::Nums(v) = &p.values
            && v.len() == 2
        {
            total *= v[1];
            p2.values = Values::Nums(vec![v[0]]);
            said(
                warn,
                loc,
                "parameter",
                "blackbody [T scale]",
                "blackbody T, float scale",
            );
        }
        ps.push(p2.ty, &p2.name, p2.values, p2.loc);
    }
    ps.push(
        ParamType::Float,
        "scale",
        Values::Nums(vec![total]),
        loc.clone(),
    );
}

/// Rewrite a v3 `LightSource`; returns the type.
pub fn light(ty: &str, ps: &mut ParamSet, loc: &Loc, warn: &mut Warn) -> String {
    ps.remove("samples");
    ps.remove("nsamples");
    if ps.has("mapname") {
        ps.rename("mapname", "filename");
        said(warn, loc, "parameter", "mapname", "filename");
    }
    let spectrum = if ty == "point" || ty == "spot" || ty == "goniometric" || ty == "projection" {
        "I"
    } else {
        "L"
    };
    if ps.has("scale") || ps.type_of(spectrum) == Some(ParamType::Blackbody) {
        light_scale(ps, spectrum, loc, warn);
    }
    ty.to_string()
}

/// Rewrite a v3 `AreaLightSource`; returns the type.
pub fn area_light(ty: &str, ps: &mut ParamSet, loc: &Loc, warn: &mut Warn) -> String {
    ps.remove("nsamples");
    ps.remove("samples");
    if ps.has("scale") || ps.type_of("L") == Some(ParamType::Blackbody) {
        light_scale(ps, "L", loc, warn);
    }
    if ty == "area" {
        said(warn, loc, "area light", "area", "diffuse");
        return "diffuse".into();
    }
    ty.to_string()
}

/// Rewrite a v3 `Film`; returns the type.
pub fn film(ty: &str, ps: &mut ParamSet, loc: &Loc, warn: &mut Warn) -> String {
    if let Some(p) = ps.remove("scale")
        && let Some(s) = p.constant()
    {
        ps.push(
            ParamType::Float,
            "iso",
            Values::Nums(vec![100.0 * s]),
            p.loc,
        );
        said(warn, loc, "film parameter", "scale", "iso = 100 × scale");
    }
    if ps.has("maxsampleluminance") {
        ps.rename("maxsampleluminance", "maxcomponentvalue");
    }
    if ty == "image" {
        said(warn, loc, "film", "image", "rgb");
        return "rgb".into();
    }
    ty.to_string()
}

/// Rewrite v3 `PixelFilter` parameters (`xwidth` → `xradius`, Gaussian `alpha` → `sigma`).
pub fn filter(ty: &str, ps: &mut ParamSet) {
    ps.rename("xwidth", "xradius");
    ps.rename("ywidth", "yradius");
    if ty == "gaussian"
        && let Some(p) = ps.remove("alpha")
        && let Some(a) = p.constant()
        && a > 0.0
    {
        ps.push(
            ParamType::Float,
            "sigma",
            Values::Nums(vec![1.0 / (2.0 * a).sqrt()]),
            p.loc,
        );
    }
}

/// Rewrite v3 shape parameters (`st` → `uv`, per-shape `Kd`, dropped v3-only flags).
pub fn shape(ty: &str, ps: &mut ParamSet) {
    if ps.has("st") && !ps.has("uv") {
        ps.rename("st", "uv");
    }
    if ty == "loopsubdiv" && ps.has("nlevels") {
        ps.rename("nlevels", "levels");
    }
    ps.remove("discarddegenerateUVs");
    ps.remove("shadowalpha");
}

/// Rewrite a v3 `Texture` class's parameters (`scale` texture's `tex1`/`tex2`, `gamma`).
pub fn texture(class: &str, ps: &mut ParamSet) {
    if class == "scale" && (ps.has("tex1") || ps.has("tex2")) && !ps.has("tex") {
        // tex1 × tex2: the v4 texture is `tex` scaled by the float `scale`; the grey constant
        // of the two becomes the scale.
        let is_const = |ps: &ParamSet, n: &str| {
            ps.params
                .iter()
                .any(|p| p.name == n && p.constant().is_some())
        };
        let (s, t) = if is_const(ps, "tex1") {
            ("tex1", "tex2")
        } else {
            ("tex2", "tex1")
        };
        if is_const(ps, s) {
            let p = ps.remove(s).expect("checked");
            let v = p.constant().unwrap_or(1.0);
            ps.push(ParamType::Float, "scale", Values::Nums(vec![v]), p.loc);
            ps.rename(t, "tex");
        } else {
            ps.rename("tex1", "tex");
            ps.rename("tex2", "scale");
        }
    }
    ps.remove("gamma");
    ps.remove("trilinear");
}
