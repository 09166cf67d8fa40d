//! `KEY=VALUE` parameters of a warp routine: the declared keys with their defaults, user
//! overrides checked against them, and typed getters whose errors name the offending key.

use anyhow::{Context, bail};
use glam::{Vec2, Vec3};
use std::collections::BTreeMap;

/// One declared parameter of a routine.
#[derive(Clone, Copy, Debug)]
pub struct ParamSpec {
    /// The key, as typed after `--param`.
    pub key: &'static str,
    /// Default value, in the same text form the user types ("" = unset).
    pub default: &'static str,
    /// What it means, with its unit.
    pub help: &'static str,
}

/// The parameter values of one routine: defaults overlaid with the user's `KEY=VALUE` pairs.
#[derive(Clone, Debug)]
pub struct Params {
    routine: &'static str,
    values: BTreeMap<&'static str, String>,
}

impl Params {
    /// Defaults of `specs` overridden by `overrides` (each `KEY=VALUE`); an unknown key or a
    /// pair without `=` is an error that lists the valid keys.
    pub fn new(
        routine: &'static str,
        specs: &[ParamSpec],
        overrides: &[String],
    ) -> anyhow::Result<Self> {
        let mut values: BTreeMap<&'static str, String> = specs
            .iter()
            .map(|s| (s.key, s.default.to_string()))
            .collect();
        let keys = || {
            if specs.is_empty() {
                "it takes no parameters".to_string()
            } else {
                let k: Vec<&str> = specs.iter().map(|s| s.key).collect();
                format!("valid keys: {}", k.join(", "))
            }
        };
        for pair in overrides {
            let Some((key, value)) = pair.split_once('=') else {
                bail!(
                    "--param {pair:?}: expected KEY=VALUE ({routine}: {})",
                    keys()
                );
            };
            let key = key.trim();
            let Some(spec) = specs.iter().find(|s| s.key == key) else {
                bail!(
                    "--param {pair:?}: {routine} has no parameter {key:?} ({})",
                    keys()
                );
            };
            values.insert(spec.key, value.trim().to_string());
        }
        Ok(Self { routine, values })
    }

    /// The raw text of `key` (empty if unset).
    pub fn raw(&self, key: &str) -> &str {
        self.values.get(key).map(String::as_str).unwrap_or("")
    }

    /// Whether `key` has a non-empty value.
    pub fn is_set(&self, key: &str) -> bool {
        !self.raw(key).is_empty()
    }

    /// `key` parsed as `n` comma-separated finite numbers.
    fn numbers(&self, key: &str, n: usize) -> anyhow::Result<Vec<f32>> {
        let raw = self.raw(key);
        let what = || format!("{}: parameter {key}={raw:?}", self.routine);
        let v: Vec<f32> = raw
            .split(',')
            .map(|t| t.trim().parse::<f32>())
            .collect::<Result<_, _>>()
            .with_context(|| format!("{}: expected {n} number(s) separated by commas", what()))?;
        if v.len() != n {
            bail!("{}: expected {n} number(s), got {}", what(), v.len());
        }
        if v.iter().any(|x| !x.is_finite()) {
            bail!("{}: values must be finite", what());
        }
        Ok(v)
    }

    /// `key` as one finite number.
    pub fn float(&self, key: &str) -> anyhow::Result<f32> {
        Ok(self.numbers(key, 1)?[0])
    }

    /// `key` as `x,y`.
    pub fn vec2(&self, key: &str) -> anyhow::Result<Vec2> {
        let v = self.numbers(key, 2)?;
        Ok(Vec2::new(v[0], v[1]))
    }

    /// `key` as `x,y,z`.
    pub fn vec3(&self, key: &str) -> anyhow::Result<Vec3> {
        let v = self.numbers(key, 3)?;
        Ok(Vec3::new(v[0], v[1], v[2]))
    }

    /// `key` as a colour: one grey value or `r,g,b`.
    pub fn rgb(&self, key: &str) -> anyhow::Result<Vec3> {
        if self.raw(key).contains(',') {
            self.vec3(key)
        } else {
            Ok(Vec3::splat(self.float(key)?))
        }
    }

    /// Error for a value that parses but is out of range: names routine, key and value.
    pub fn invalid(&self, key: &str, why: impl std::fmt::Display) -> anyhow::Error {
        anyhow::anyhow!(
            "{}: parameter {key}={:?} {why}",
            self.routine,
            self.raw(key)
        )
    }
}
