//! Parameter lists: `"type name" value` or `"type name" [ values ]`, typed and checked when read,
//! with typed accessors that report the parameter's location on a type or count mismatch.

use super::tokenizer::{Loc, Tok, Tokenizer, err_at};
use crate::Rgb;
use glam::{Vec2, Vec3};
use std::cell::Cell;

/// The declared type of a parameter.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ParamType {
    /// `float`
    Float,
    /// `integer`
    Integer,
    /// `point2`
    Point2,
    /// `vector2`
    Vector2,
    /// `point3` (alias `point`)
    Point3,
    /// `vector3` (alias `vector`)
    Vector3,
    /// `normal` (alias `normal3`)
    Normal,
    /// `rgb` (alias `color`)
    Rgb,
    /// `spectrum`: (λ, value) pairs or a named/file spectrum
    Spectrum,
    /// `blackbody`: a temperature in kelvin
    Blackbody,
    /// `bool`
    Bool,
    /// `string`
    String,
    /// `texture`: the name of a texture
    Texture,
}

impl ParamType {
    fn parse(s: &str) -> Option<Self> {
        Some(match s {
            "float" => Self::Float,
            "integer" => Self::Integer,
            "point2" => Self::Point2,
            "vector2" => Self::Vector2,
            "point3" | "point" => Self::Point3,
            "vector3" | "vector" => Self::Vector3,
            "normal" | "normal3" => Self::Normal,
            "rgb" | "color" => Self::Rgb,
            "spectrum" => Self::Spectrum,
            "blackbody" => Self::Blackbody,
            "bool" => Self::Bool,
            "string" => Self::String,
            "texture" => Self::Texture,
            _ => return None,
        })
    }

    /// pbrt's name of the type.
    pub fn name(self) -> &'static str {
        match self {
            Self::Float => "float",
            Self::Integer => "integer",
            Self::Point2 => "point2",
            Self::Vector2 => "vector2",
            Self::Point3 => "point3",
            Self::Vector3 => "vector3",
            Self::Normal => "normal",
            Self::Rgb => "rgb",
            Self::Spectrum => "spectrum",
            Self::Blackbody => "blackbody",
            Self::Bool => "bool",
            Self::String => "string",
            Self::Texture => "texture",
        }
    }
}

/// The values of a parameter (already checked against its type).
#[derive(Clone, Debug, PartialEq)]
pub enum Values {
    /// Numbers (every numeric type, and sampled spectra).
    Nums(Vec<f64>),
    /// Strings (string, texture, named spectrum).
    Strs(Vec<String>),
    /// Booleans.
    Bools(Vec<bool>),
}

/// One parsed parameter.
#[derive(Clone, Debug)]
pub struct Param {
    /// Declared type.
    pub ty: ParamType,
    /// Parameter name.
    pub name: String,
    /// Values.
    pub values: Values,
    /// Location of the `"type name"` string.
    pub loc: Loc,
    used: Cell<bool>,
}

impl Param {
    /// The value of a numeric parameter whose values are all equal (a grey `rgb`, a single
    /// `float`), else `None`.
    pub fn constant(&self) -> Option<f64> {
        match (&self.ty, &self.values) {
            (ParamType::Float | ParamType::Integer | ParamType::Rgb, Values::Nums(v))
                if !v.is_empty() && v.iter().all(|x| *x == v[0]) =>
            {
                Some(v[0])
            }
            _ => None,
        }
    }
}

/// A spectrum-valued parameter before conversion to RGB (see `spectra`).
#[derive(Clone, Debug, PartialEq)]
pub enum SpecVal {
    /// `rgb [r g b]`
    Rgb(Rgb),
    /// `blackbody [T]`
    Blackbody(f32),
    /// `spectrum [λ0 v0 λ1 v1 …]`
    Sampled(Vec<(f32, f32)>),
    /// `spectrum "name"` (pbrt's named spectra, e.g. `metal-Cu-eta`)
    Named(String),
}

/// A directive's parameter list.
#[derive(Clone, Debug, Default)]
pub struct ParamSet {
    /// Parameters in file order.
    pub params: Vec<Param>,
}

fn want_count(p: &Param, n: usize, unit: usize, exact: bool) -> anyhow::Result<()> {
    let len = match &p.values {
        Values::Nums(v) => v.len(),
        Values::Strs(v) => v.len(),
        Values::Bools(v) => v.len(),
    };
    let ok = if exact {
        len == n
    } else {
        len > 0 && len % unit == 0
    };
    if ok {
        return Ok(());
    }
    let what = if exact {
        format!("{n} value(s)")
    } else {
        format!("a non-zero multiple of {unit} values")
    };
    Err(err_at(
        &p.loc,
        format!(
            "expected {what} for {} '{}', found {len}",
            p.ty.name(),
            p.name
        ),
    ))
}

impl ParamSet {
    /// Parse parameters from the tokenizer until the next token is not a string.
    pub fn parse(t: &mut Tokenizer) -> anyhow::Result<Self> {
        let mut params = Vec::new();
        loop {
            match t.peek()? {
                Some(tok) if matches!(tok.tok, Tok::Str(_)) => {}
                _ => break,
            }
            let Some(decl) = t.next_token()? else { break };
            let Tok::Str(text) = decl.tok else { break };
            params.push(Self::parse_one(t, &text, decl.loc)?);
        }
        Ok(Self { params })
    }

    fn parse_one(t: &mut Tokenizer, decl: &str, loc: Loc) -> anyhow::Result<Param> {
        let parts: Vec<&str> = decl.split_whitespace().collect();
        if parts.len() != 2 {
            return Err(err_at(
                &loc,
                format!("expected a parameter declaration \"type name\", found \"{decl}\""),
            ));
        }
        let ty = ParamType::parse(parts[0]).ok_or_else(|| {
            err_at(
                &loc,
                format!("unknown parameter type '{}' in \"{decl}\"", parts[0]),
            )
        })?;
        let name = parts[1].to_string();
        // Values: one bare value or a bracketed list.
        let mut raw: Vec<Tok> = Vec::new();
        let first = t.next_token()?.ok_or_else(|| {
            err_at(
                &t.here(),
                format!("expected a value for '{name}', found end of file"),
            )
        })?;
        match first.tok {
            Tok::Open => loop {
                let tok = t.next_token()?.ok_or_else(|| {
                    err_at(
                        &first.loc,
                        format!("expected ']' closing the values of '{name}', found end of file"),
                    )
                })?;
                match tok.tok {
                    Tok::Close => break,
                    Tok::Open => {
                        return Err(err_at(&tok.loc, "expected a value or ']', found '['"));
                    }
                    other => raw.push(other),
                }
            },
            Tok::Close => {
                return Err(err_at(
                    &first.loc,
                    format!("expected a value for '{name}', found ']'"),
                ));
            }
            other => raw.push(other),
        }
        let values = Self::convert(ty, &name, raw, &first.loc)?;
        let p = Param {
            ty,
            name,
            values,
            loc,
            used: Cell::new(false),
        };
        match ty {
            ParamType::Point2 | ParamType::Vector2 => want_count(&p, 0, 2, false)?,
            ParamType::Point3 | ParamType::Vector3 | ParamType::Normal => {
                want_count(&p, 0, 3, false)?
            }
            ParamType::Rgb => want_count(&p, 3, 0, true)?,
            ParamType::Spectrum => match &p.values {
                Values::Nums(_) => want_count(&p, 0, 2, false)?,
                _ => want_count(&p, 1, 0, true)?,
            },
            ParamType::Blackbody => {
                // pbrt-v3 files give [T scale]; lights fold the scale in (`upgrade`).
                if let Values::Nums(v) = &p.values {
                    if v.len() != 1 && v.len() != 2 {
                        want_count(&p, 1, 0, true)?;
                    }
                    if v[0] <= 0.0 {
                        return Err(err_at(
                            &p.loc,
                            format!("blackbody temperature must be positive, found {}", v[0]),
                        ));
                    }
                }
            }
            _ => want_count(&p, 0, 1, false)?,
        }
        Ok(p)
    }

    fn convert(ty: ParamType, name: &str, raw: Vec<Tok>, loc: &Loc) -> anyhow::Result<Values> {
        let mismatch = |found: &Tok, expected: &str| {
            err_at(
                loc,
                format!(
                    "expected {expected} for {} '{name}', found {}",
                    ty.name(),
                    found.describe()
                ),
            )
        };
        match ty {
            ParamType::Bool => {
                let mut v = Vec::with_capacity(raw.len());
                for tok in &raw {
                    v.push(match tok {
                        Tok::Word(w) | Tok::Str(w) if w == "true" => true,
                        Tok::Word(w) | Tok::Str(w) if w == "false" => false,
                        other => return Err(mismatch(other, "true or false")),
                    });
                }
                Ok(Values::Bools(v))
            }
            ParamType::String | ParamType::Texture => {
                let mut v = Vec::with_capacity(raw.len());
                for tok in raw {
                    match tok {
                        Tok::Str(s) => v.push(s),
                        other => return Err(mismatch(&other, "a quoted string")),
                    }
                }
                Ok(Values::Strs(v))
            }
            ParamType::Spectrum if matches!(raw.first(), Some(Tok::Str(_))) => {
                let mut v = Vec::new();
                for tok in raw {
                    match tok {
                        Tok::Str(s) => v.push(s),
                        other => return Err(mismatch(&other, "a spectrum name")),
                    }
                }
                Ok(Values::Strs(v))
            }
            _ => {
                let mut v = Vec::with_capacity(raw.len());
                for tok in &raw {
                    match tok {
                        Tok::Num(x) => {
                            if ty == ParamType::Integer && x.fract() != 0.0 {
                                return Err(mismatch(tok, "an integer"));
                            }
                            v.push(*x)
                        }
                        other => return Err(mismatch(other, "a number")),
                    }
                }
                Ok(Values::Nums(v))
            }
        }
    }

    /// Replace every `"spectrum"` string that is not one of pbrt-v4's named spectra by the
    /// (λ, value) pairs of the `.spd` file it names, relative to `dir` (pbrt's format: pairs of
    /// numbers, `#` comments). A missing file is an error listing the named spectra; a bad file
    /// an error at its own line.
    pub fn resolve_spectrum_files(&mut self, dir: &std::path::Path) -> anyhow::Result<()> {
        for p in &mut self.params {
            if p.ty != ParamType::Spectrum {
                continue;
            }
            let Values::Strs(names) = &p.values else {
                continue;
            };
            let Some(name) = names.first().cloned() else {
                continue;
            };
            if super::named_spectra::kind(&name).is_some() {
                continue;
            }
            let path = super::textures::resolve(dir, &name);
            let text = match std::fs::read_to_string(&path) {
                Ok(t) => t,
                Err(e) => {
                    return Err(err_at(
                        &p.loc,
                        format!(
                            "spectrum '{}': \"{name}\" is neither a named spectrum nor a readable file ({}: {e}); named spectra: {}",
                            p.name,
                            path.display(),
                            super::named_spectra::all_names().join(", ")
                        ),
                    ));
                }
            };
            p.values = Values::Nums(read_spd(&path, &text)?);
        }
        Ok(())
    }

    /// Rename every parameter called `from` (pbrt-v4's `--upgrade` renames).
    pub fn rename(&mut self, from: &str, to: &str) {
        for p in &mut self.params {
            if p.name == from {
                p.name = to.to_string();
            }
        }
    }

    /// Remove the parameters called `name`, returning the last one.
    pub fn remove(&mut self, name: &str) -> Option<Param> {
        let i = self.params.iter().rposition(|p| p.name == name)?;
        let p = self.params.remove(i);
        self.params.retain(|q| q.name != name);
        Some(p)
    }

    /// Add a parameter (replacing any of the same name).
    pub fn push(&mut self, ty: ParamType, name: &str, values: Values, loc: Loc) {
        self.params.retain(|q| q.name != name);
        self.params.push(Param {
            ty,
            name: name.to_string(),
            values,
            loc,
            used: Cell::new(false),
        });
    }

    /// The parameter called `name`, marking it used.
    pub fn find(&self, name: &str) -> Option<&Param> {
        let p = self.params.iter().rev().find(|p| p.name == name)?;
        p.used.set(true);
        Some(p)
    }

    /// True if a parameter called `name` is present (does not mark it used).
    pub fn has(&self, name: &str) -> bool {
        self.params.iter().any(|p| p.name == name)
    }

    /// Parameters nobody asked for (reported as warnings).
    pub fn unused(&self) -> impl Iterator<Item = &Param> {
        self.params.iter().filter(|p| !p.used.get())
    }

    fn typed(&self, name: &str, types: &[ParamType]) -> anyhow::Result<Option<&Param>> {
        let Some(p) = self.find(name) else {
            return Ok(None);
        };
        if types.contains(&p.ty) {
            return Ok(Some(p));
        }
        let names: Vec<&str> = types.iter().map(|t| t.name()).collect();
        Err(err_at(
            &p.loc,
            format!(
                "parameter '{name}': expected type {}, found {}",
                names.join(" or "),
                p.ty.name()
            ),
        ))
    }

    fn nums<'a>(
        &'a self,
        name: &str,
        types: &[ParamType],
    ) -> anyhow::Result<Option<(&'a Param, &'a [f64])>> {
        Ok(self.typed(name, types)?.and_then(|p| match &p.values {
            Values::Nums(v) => Some((p, v.as_slice())),
            _ => None,
        }))
    }

    fn one_num(&self, name: &str, types: &[ParamType]) -> anyhow::Result<Option<f64>> {
        match self.nums(name, types)? {
            None => Ok(None),
            Some((p, v)) if v.len() == 1 => {
                let _ = p;
                Ok(Some(v[0]))
            }
            Some((p, v)) => Err(err_at(
                &p.loc,
                format!(
                    "expected 1 value for {} '{name}', found {}",
                    p.ty.name(),
                    v.len()
                ),
            )),
        }
    }

    /// A single float (integers accepted too), or `None` if absent.
    pub fn opt_float(&self, name: &str) -> anyhow::Result<Option<f32>> {
        Ok(self
            .one_num(name, &[ParamType::Float, ParamType::Integer])?
            .map(|x| x as f32))
    }

    /// A single float with a default.
    pub fn float(&self, name: &str, default: f32) -> anyhow::Result<f32> {
        Ok(self.opt_float(name)?.unwrap_or(default))
    }

    /// A single integer with a default.
    pub fn int(&self, name: &str, default: i64) -> anyhow::Result<i64> {
        Ok(self
            .one_num(name, &[ParamType::Integer])?
            .map(|x| x as i64)
            .unwrap_or(default))
    }

    /// Several floats.
    pub fn floats(&self, name: &str) -> anyhow::Result<Option<Vec<f32>>> {
        Ok(self
            .nums(name, &[ParamType::Float])?
            .map(|(_, v)| v.iter().map(|&x| x as f32).collect()))
    }

    /// Several integers.
    pub fn ints(&self, name: &str) -> anyhow::Result<Option<(Vec<i64>, Loc)>> {
        Ok(self
            .nums(name, &[ParamType::Integer])?
            .map(|(p, v)| (v.iter().map(|&x| x as i64).collect(), p.loc.clone())))
    }

    /// Several 3D points (`point3`).
    pub fn point3s(&self, name: &str) -> anyhow::Result<Option<Vec<Vec3>>> {
        self.vec3s(name, &[ParamType::Point3])
    }

    /// Several normals (`normal`).
    pub fn normals(&self, name: &str) -> anyhow::Result<Option<Vec<Vec3>>> {
        self.vec3s(name, &[ParamType::Normal])
    }

    fn vec3s(&self, name: &str, types: &[ParamType]) -> anyhow::Result<Option<Vec<Vec3>>> {
        Ok(self.nums(name, types)?.map(|(_, v)| {
            v.chunks_exact(3)
                .map(|c| Vec3::new(c[0] as f32, c[1] as f32, c[2] as f32))
                .collect()
        }))
    }

    /// Several 2D points (`point2`, or pbrt-v3's `float uv` pairs).
    pub fn point2s(&self, name: &str) -> anyhow::Result<Option<Vec<Vec2>>> {
        match self.nums(name, &[ParamType::Point2, ParamType::Float])? {
            None => Ok(None),
            Some((p, v)) => {
                if v.len() % 2 != 0 {
                    return Err(err_at(
                        &p.loc,
                        format!(
                            "expected an even number of values for '{name}', found {}",
                            v.len()
                        ),
                    ));
                }
                Ok(Some(
                    v.chunks_exact(2)
                        .map(|c| Vec2::new(c[0] as f32, c[1] as f32))
                        .collect(),
                ))
            }
        }
    }

    /// One 3D point or vector with a default.
    pub fn vec3(&self, name: &str, default: Vec3) -> anyhow::Result<Vec3> {
        match self.nums(
            name,
            &[ParamType::Point3, ParamType::Vector3, ParamType::Normal],
        )? {
            None => Ok(default),
            Some((_, v)) if v.len() == 3 => Ok(Vec3::new(v[0] as f32, v[1] as f32, v[2] as f32)),
            Some((p, v)) => Err(err_at(
                &p.loc,
                format!(
                    "expected 3 values for {} '{name}', found {}",
                    p.ty.name(),
                    v.len()
                ),
            )),
        }
    }

    /// A single string, or `None`.
    pub fn string(&self, name: &str) -> anyhow::Result<Option<String>> {
        self.one_str(name, &[ParamType::String])
    }

    /// A texture name, or `None`.
    pub fn texture(&self, name: &str) -> anyhow::Result<Option<String>> {
        self.one_str(name, &[ParamType::Texture])
    }

    /// Several strings.
    pub fn strings(&self, name: &str) -> anyhow::Result<Option<Vec<String>>> {
        Ok(self
            .typed(name, &[ParamType::String])?
            .and_then(|p| match &p.values {
                Values::Strs(v) => Some(v.clone()),
                _ => None,
            }))
    }

    fn one_str(&self, name: &str, types: &[ParamType]) -> anyhow::Result<Option<String>> {
        let Some(p) = self.typed(name, types)? else {
            return Ok(None);
        };
        match &p.values {
            Values::Strs(v) if v.len() == 1 => Ok(Some(v[0].clone())),
            Values::Strs(v) => Err(err_at(
                &p.loc,
                format!(
                    "expected 1 value for {} '{name}', found {}",
                    p.ty.name(),
                    v.len()
                ),
            )),
            _ => Ok(None),
        }
    }

    /// A single bool with a default.
    pub fn bool(&self, name: &str, default: bool) -> anyhow::Result<bool> {
        let Some(p) = self.typed(name, &[ParamType::Bool])? else {
            return Ok(default);
        };
        match &p.values {
            Values::Bools(v) if v.len() == 1 => Ok(v[0]),
            _ => Err(err_at(
                &p.loc,
                format!("expected 1 value for bool '{name}'"),
            )),
        }
    }

    /// The type of parameter `name`, if present (does not mark it used).
    pub fn type_of(&self, name: &str) -> Option<ParamType> {
        self.params
            .iter()
            .rev()
            .find(|p| p.name == name)
            .map(|p| p.ty)
    }

    /// Location of parameter `name`, if present.
    pub fn loc_of(&self, name: &str) -> Option<Loc> {
        self.params
            .iter()
            .rev()
            .find(|p| p.name == name)
            .map(|p| p.loc.clone())
    }

    /// A spectrum-valued parameter (`rgb`, `blackbody` or `spectrum`), or `None`.
    pub fn spectrum(&self, name: &str) -> anyhow::Result<Option<SpecVal>> {
        let Some(p) = self.typed(
            name,
            &[ParamType::Rgb, ParamType::Blackbody, ParamType::Spectrum],
        )?
        else {
            return Ok(None);
        };
        Ok(Some(match (&p.ty, &p.values) {
            (ParamType::Rgb, Values::Nums(v)) => {
                SpecVal::Rgb(Rgb::new(v[0] as f32, v[1] as f32, v[2] as f32))
            }
            (ParamType::Blackbody, Values::Nums(v)) => SpecVal::Blackbody(v[0] as f32),
            (_, Values::Nums(v)) => {
                let pairs: Vec<(f32, f32)> = v
                    .chunks_exact(2)
                    .map(|c| (c[0] as f32, c[1] as f32))
                    .collect();
                if pairs.windows(2).any(|w| w[1].0 <= w[0].0) {
                    return Err(err_at(
                        &p.loc,
                        format!("spectrum '{name}': wavelengths must increase"),
                    ));
                }
                SpecVal::Sampled(pairs)
            }
            (_, Values::Strs(v)) => SpecVal::Named(v[0].clone()),
            _ => return Ok(None),
        }))
    }
}

/// Parse a pbrt `.spd` file: whitespace-separated numbers in (λ, value) pairs with
/// increasing λ; `#` starts a comment. Errors name `path:line`.
pub fn read_spd(path: &std::path::Path, text: &str) -> anyhow::Result<Vec<f64>> {
    let mut v = Vec::new();
    let mut last_line = 1;
    for (i, line) in text.lines().enumerate() {
        let body = line.split('#').next().unwrap_or("");
        for w in body.split_whitespace() {
            let x: f64 = w.parse().map_err(|_| {
                anyhow::anyhow!(
                    "{}:{}: expected a number in the spectrum file, found \"{w}\"",
                    path.display(),
                    i + 1
                )
            })?;
            if !x.is_finite() {
                anyhow::bail!("{}:{}: non-finite value {w}", path.display(), i + 1);
            }
            if v.len() % 2 == 0 && v.len() >= 2 && x <= v[v.len() - 2] {
                anyhow::bail!(
                    "{}:{}: wavelengths must increase, found {x} after {}",
                    path.display(),
                    i + 1,
                    v[v.len() - 2]
                );
            }
            v.push(x);
            last_line = i + 1;
        }
    }
    if v.is_empty() || v.len() % 2 != 0 {
        anyhow::bail!(
            "{}:{}: expected (wavelength, value) pairs, found {} number(s)",
            path.display(),
            last_line,
            v.len()
        );
    }
    Ok(v)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ps(src: &str) -> anyhow::Result<ParamSet> {
        let mut t = Tokenizer::new("p.pbrt", src);
        ParamSet::parse(&mut t)
    }

    #[test]
    fn every_parameter_type_parses() {
        let p = ps(r#""float f" 2.5 "integer i" [ 3 4 ] "point2 uv" [0 1 1 0]
            "vector2 v2" [1 2] "point3 P" [1 2 3] "point p" [0 0 1] "vector3 d" [0 1 0]
            "normal N" [0 0 1] "rgb c" [0.1 0.2 0.3] "color c2" [1 1 1]
            "spectrum s" [400 1 700 2] "spectrum m" "metal-Cu-eta" "blackbody bb" 6500
            "bool b" true "bool b2" "false" "string s1" "x" "texture t" ["tex"]"#)
        .unwrap();
        assert_eq!(p.float("f", 0.0).unwrap(), 2.5);
        assert_eq!(p.ints("i").unwrap().unwrap().0, vec![3, 4]);
        assert_eq!(p.point2s("uv").unwrap().unwrap().len(), 2);
        assert_eq!(p.type_of("v2"), Some(ParamType::Vector2));
        assert_eq!(
            p.point3s("P").unwrap().unwrap(),
            vec![Vec3::new(1.0, 2.0, 3.0)]
        );
        assert_eq!(p.point3s("p").unwrap().unwrap(), vec![Vec3::Z]);
        assert_eq!(p.vec3("d", Vec3::ZERO).unwrap(), Vec3::Y);
        assert_eq!(p.normals("N").unwrap().unwrap(), vec![Vec3::Z]);
        assert_eq!(
            p.spectrum("c").unwrap(),
            Some(SpecVal::Rgb(Rgb::new(0.1, 0.2, 0.3)))
        );
        assert_eq!(p.spectrum("c2").unwrap(), Some(SpecVal::Rgb(Rgb::ONE)));
        assert_eq!(
            p.spectrum("s").unwrap(),
            Some(SpecVal::Sampled(vec![(400.0, 1.0), (700.0, 2.0)]))
        );
        assert_eq!(
            p.spectrum("m").unwrap(),
            Some(SpecVal::Named("metal-Cu-eta".into()))
        );
        assert_eq!(p.spectrum("bb").unwrap(), Some(SpecVal::Blackbody(6500.0)));
        assert!(p.bool("b", false).unwrap());
        assert!(!p.bool("b2", true).unwrap());
        assert_eq!(p.string("s1").unwrap().as_deref(), Some("x"));
        assert_eq!(p.texture("t").unwrap().as_deref(), Some("tex"));
        assert_eq!(p.unused().count(), 1, "only v2 is unused");
    }

    #[test]
    fn defaults_apply_when_absent() {
        let p = ps("").unwrap();
        assert_eq!(p.float("fov", 90.0).unwrap(), 90.0);
        assert_eq!(p.int("n", 7).unwrap(), 7);
        assert!(p.bool("b", true).unwrap());
        assert!(p.string("s").unwrap().is_none());
    }

    #[test]
    fn mismatches_are_errors_at_the_parameter() {
        for (src, get, what) in [
            (
                "\n \"string fov\" \"x\"",
                "float",
                "p.pbrt:2:2: parameter 'fov': expected type float",
            ),
            ("\"float fov\" [1 2]", "float", "expected 1 value"),
            (
                "\"rgb c\" [1 2]",
                "",
                "expected 3 value(s) for rgb 'c', found 2",
            ),
            ("\"point3 P\" [1 2 3 4]", "", "multiple of 3"),
            ("\"integer i\" 1.5", "", "expected an integer"),
            ("\"float f\" \"one\"", "", "expected a number"),
            ("\"bool b\" 1", "", "true or false"),
            ("\"floaty f\" 1", "", "unknown parameter type 'floaty'"),
            ("\"float\" 1", "", "expected a parameter declaration"),
            ("\"float f\" [1 2", "", "expected ']'"),
            ("\"float f\"", "", "found end of file"),
            ("\"float f\" []", "", "non-zero multiple"),
            ("\"blackbody b\" -5", "", "must be positive"),
        ] {
            let r = ps(src).and_then(|p| match get {
                "float" => p.float("fov", 0.0).map(|_| ()),
                _ => Ok(()),
            });
            let e = r.expect_err(src).to_string();
            assert!(e.contains(what), "{src}: {e}");
            assert!(e.starts_with("p.pbrt:"), "{e}");
        }
    }
}
