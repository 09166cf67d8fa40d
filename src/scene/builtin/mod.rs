//! Built-in scenes, selectable by name wherever a scene path is accepted.

pub mod cornell;
mod cornell_data;
mod dense;
mod many_mesh;
mod many_open;
mod many_rooms;
mod many_street;
mod many_util;

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
    /// The [`BuiltinOptions`] it reads, by flag name (`light-count`, `rooms`, `triangles`).
    pub knobs: &'static [&'static str],
}

/// Every built-in scene, default first.
pub const BUILTINS: &[Builtin] = &[
    Builtin {
        name: "cornell",
        description: "Cornell box of ../shared/scenes/cornell-box-bitterli/scene-v4.pbrt (default), 512x512",
        build: cornell::cornell,
        knobs: &[],
    },
    Builtin {
        name: "cornell-phong",
        description: "Cornell box with Phong (n = 10, 100, 1000) and GGX conductor spheres",
        build: cornell::cornell_phong,
        knobs: &[],
    },
    Builtin {
        name: "dense",
        description: "Cornell box around a displaced sphere of ~1.05M triangles (--triangles)",
        build: dense::dense,
        knobs: &["triangles"],
    },
    Builtin {
        name: "many-open",
        description: "10k small area lights over an open floor with occluders (--light-count up to 1M)",
        build: many_open::many_open,
        knobs: &["light-count"],
    },
    Builtin {
        name: "many-rooms",
        description: "8x8 rooms with doorways, 4 ceiling lights each (--rooms, --light-count)",
        build: many_rooms::many_rooms,
        knobs: &["rooms", "light-count"],
    },
    Builtin {
        name: "many-mesh",
        description: "emissive torus of 8192 triangle lights plus strip lights (--light-count)",
        build: many_mesh::many_mesh,
        knobs: &["light-count", "triangles"],
    },
    Builtin {
        name: "many-street",
        description: "night city of 6x6 blocks, 32.6k emissive triangles (windows, lamps, signs, cars) (--light-count)",
        build: many_street::many_street,
        knobs: &["light-count"],
    },
];

/// The built-in scene called `name`, if there is one.
pub fn find(name: &str) -> Option<&'static Builtin> {
    BUILTINS.iter().find(|b| b.name == name)
}
