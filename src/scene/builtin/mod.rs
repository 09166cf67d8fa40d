//! Built-in scenes, selectable by name wherever a scene path is accepted.

pub mod cornell;
mod cornell_data;

use super::Scene;

/// Knobs that scale the procedural built-in scenes.
#[derive(Clone, Debug, Default)]
pub struct BuiltinOptions {
    /// Number of lights (many-light scenes).
    pub light_count: Option<u32>,
    /// Rooms per side (`many-rooms`).
    pub rooms: Option<u32>,
    /// Triangle count hint (procedural meshes).
    pub triangles: Option<u32>,
}

/// A built-in scene: its name, a one-line description and its constructor.
pub struct Builtin {
    /// Name accepted on the command line.
    pub name: &'static str,
    /// What it shows.
    pub description: &'static str,
    /// Build it.
    pub build: fn(&BuiltinOptions) -> anyhow::Result<Scene>,
}

/// Every built-in scene, default first.
pub const BUILTINS: &[Builtin] = &[
    Builtin {
        name: "cornell",
        description: "Cornell box of ../shared/scenes/cornell-box-bitterli/scene-v4.pbrt (default), 512x512",
        build: cornell::cornell,
    },
    Builtin {
        name: "cornell-phong",
        description: "Cornell box with Phong (n = 10, 100, 1000) and GGX conductor spheres",
        build: cornell::cornell_phong,
    },
];

/// The built-in scene called `name`, if there is one.
pub fn find(name: &str) -> Option<&'static Builtin> {
    BUILTINS.iter().find(|b| b.name == name)
}
