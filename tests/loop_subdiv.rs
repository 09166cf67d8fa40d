//! Loop subdivision (`Shape "loopsubdiv"`): a regular tetrahedron's corners go to their known
//! limit 0.2·v (valence 3: γ = 1/5, limit 0.4·v + 0.2·Σ others = 0.2·v), every vertex's limit
//! position is the same computed at any later level (the limit masks match the rules), the
//! output is closed and consistently oriented (V − E + F = 2), normals agree with the surface;
//! an open square keeps its boundary on the square's outline with the boundary limit
//! 2/3·v + 1/6·(neighbours) (the cubic B-spline's), in its plane.

use glam::Vec3;
use penumbra::scene::loop_subdiv::{LoopMesh, limit, loop_subdivide, subdivide_once};
use penumbra::scene::pbrt::parse_pbrt_str;
use penumbra::scene::pbrt::shapes::ShapeGeom;
use std::collections::HashMap;
use std::path::Path;

const TETRA: [Vec3; 4] = [
    Vec3::new(1.0, 1.0, 1.0),
    Vec3::new(1.0, -1.0, -1.0),
    Vec3::new(-1.0, 1.0, -1.0),
    Vec3::new(-1.0, -1.0, 1.0),
];

/// Outward counter-clockwise faces of [`TETRA`].
fn tetra_faces() -> Vec<u32> {
    let mut out = Vec::new();
    for f in [[0u32, 1, 2], [0, 3, 1], [0, 2, 3], [1, 3, 2]] {
        let (a, b, c) = (
            TETRA[f[0] as usize],
            TETRA[f[1] as usize],
            TETRA[f[2] as usize],
        );
        let n = (b - a).cross(c - a);
        assert!(n.dot(a + b + c) > 0.0, "face {f:?} is not outward");
        out.extend_from_slice(&f);
    }
    out
}

/// Undirected edges → (uses a→b, uses b→a).
fn edges(indices: &[u32]) -> HashMap<(u32, u32), (u32, u32)> {
    let mut e: HashMap<(u32, u32), (u32, u32)> = HashMap::new();
    for t in indices.chunks_exact(3) {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            let c = e.entry((a.min(b), a.max(b))).or_default();
            if a < b {
                c.0 += 1;
            } else {
                c.1 += 1;
            }
        }
    }
    e
}

fn face_normal(m: &LoopMesh, t: &[u32]) -> Vec3 {
    let p = |i: u32| m.positions[i as usize];
    (p(t[1]) - p(t[0])).cross(p(t[2]) - p(t[0])).normalize()
}

#[test]
fn tetrahedron_converges_to_its_known_limit_closed_and_smooth() {
    let faces = tetra_faces();
    let mut prev_worst = f32::INFINITY;
    for levels in 0..=5u32 {
        let m = loop_subdivide(&TETRA, &faces, levels).unwrap();
        // The corners' limit positions: 0.2·v, at every level.
        for (i, v) in TETRA.iter().enumerate() {
            let got = m.positions[i];
            assert!(
                (got - 0.2 * *v).length() < 1e-5,
                "level {levels} corner {i}: {got}"
            );
            // By symmetry the limit normal there is along v, outward.
            assert!(
                m.normals[i].dot(v.normalize()) > 1.0 - 1e-5,
                "{}",
                m.normals[i]
            );
        }
        // Closed and consistently oriented: every edge used once each way; V − E + F = 2.
        let f = m.indices.len() / 3;
        assert_eq!(f, 4 * 4usize.pow(levels));
        let e = edges(&m.indices);
        assert!(
            e.values().all(|&c| c == (1, 1)),
            "level {levels}: open or flipped edge"
        );
        assert_eq!(m.positions.len() as i64 - e.len() as i64 + f as i64, 2);
        // Vertex normals are unit and lean ever closer to their faces' normals.
        let mut worst = 0.0f32;
        for t in m.indices.chunks_exact(3) {
            let fnrm = face_normal(&m, t);
            for &v in t {
                let n = m.normals[v as usize];
                assert!((n.length() - 1.0).abs() < 1e-5);
                worst = worst.max(n.dot(fnrm).clamp(-1.0, 1.0).acos());
            }
        }
        // The facets' deviation from the smooth limit halves with each level.
        if levels >= 3 {
            assert!(
                worst < 0.6 * prev_worst,
                "level {levels}: {worst} rad vs {prev_worst}"
            );
        }
        prev_worst = worst;
    }
    assert!(
        prev_worst < 0.12,
        "level 5: normals {prev_worst} rad off their faces"
    );
    // Before the limit step, the corners approach 0.2·v geometrically.
    let mut m = LoopMesh {
        positions: TETRA.to_vec(),
        normals: Vec::new(),
        indices: faces,
    };
    let mut err = Vec::new();
    for _ in 0..8 {
        m = subdivide_once(&m).unwrap();
        err.push((m.positions[0] - 0.2 * TETRA[0]).length());
    }
    // Each level cuts the distance by ~16 (measured 0.0866, 0.0054, 3.4e-4, 2.1e-5, ...).
    assert!(err.windows(2).take(4).all(|w| w[1] < 0.1 * w[0]), "{err:?}");
    assert!(err[7] < 1e-6, "{err:?}");
}

/// Every vertex's limit from level L equals its limit computed after one more level: the
/// limit masks are the rules' eigenvectors (wrong masks or rules break this). Interior
/// normals agree as closely; boundary normals within `boundary_deg` degrees (the book's
/// across-boundary tangent masks are Hoppe et al.'s, not exact for these rules). Returns the
/// largest boundary normal deviation seen, in degrees.
fn assert_limit_invariant(positions: &[Vec3], faces: &[u32], boundary_deg: f32) -> f32 {
    let mut m = LoopMesh {
        positions: positions.to_vec(),
        normals: Vec::new(),
        indices: faces.to_vec(),
    };
    let mut worst = 0.0f32;
    for level in 0..4 {
        let here = limit(&m).unwrap();
        let next_level = subdivide_once(&m).unwrap();
        let there = limit(&next_level).unwrap();
        let mut on_boundary = vec![false; m.positions.len()];
        for (&(a, b), c) in &edges(&m.indices) {
            if c.0 + c.1 == 1 {
                on_boundary[a as usize] = true;
                on_boundary[b as usize] = true;
            }
        }
        for (i, (a, b)) in here.positions.iter().zip(&there.positions).enumerate() {
            assert!(
                (*a - *b).length() < 1e-5,
                "level {level} vertex {i}: {a} vs {b}"
            );
            let (na, nb) = (here.normals[i], there.normals[i]);
            let deg = na.dot(nb).clamp(-1.0, 1.0).acos().to_degrees();
            if on_boundary[i] {
                worst = worst.max(deg);
                assert!(
                    deg < boundary_deg,
                    "level {level} boundary vertex {i}: {na} vs {nb}"
                );
            } else {
                assert!(deg < 0.5, "level {level} vertex {i}: {na} vs {nb}");
            }
        }
        m = next_level;
    }
    worst
}

#[test]
fn limit_positions_and_normals_do_not_move_with_more_levels() {
    assert_limit_invariant(&TETRA, &tetra_faces(), 0.0);
    // An irregular closed mesh: an octahedron with one vertex pulled out (valences 4 and 5).
    let oct = [
        Vec3::X,
        -Vec3::X,
        Vec3::Y,
        -Vec3::Y,
        Vec3::Z * 2.0,
        -Vec3::Z,
        Vec3::new(0.7, 0.7, 0.0) * 1.3,
    ];
    let faces = [
        4, 0, 6, 4, 6, 2, 4, 2, 1, 4, 1, 3, 4, 3, 0, 5, 6, 0, 5, 2, 6, 5, 1, 2, 5, 3, 1, 5, 0, 3,
    ];
    assert!(edges(&faces).values().all(|&c| c == (1, 1)));
    assert_limit_invariant(&oct, &faces, 0.0);
    // An open fan with boundary vertices of valences 2 to 5.
    let fan = [
        Vec3::ZERO,
        Vec3::new(1.0, 0.0, 0.1),
        Vec3::new(0.6, 0.8, -0.2),
        Vec3::new(-0.3, 0.9, 0.3),
        Vec3::new(-1.0, 0.1, 0.0),
        Vec3::new(-0.5, -0.8, 0.2),
    ];
    let worst = assert_limit_invariant(&fan, &[0, 1, 2, 0, 2, 3, 0, 3, 4, 0, 4, 5], 2.0);
    eprintln!("fan: boundary normals move by up to {worst}° with the level");
}

#[test]
fn open_square_keeps_its_outline_and_plane() {
    let p = [
        Vec3::new(0.0, 0.0, 0.0),
        Vec3::new(1.0, 0.0, 0.0),
        Vec3::new(1.0, 1.0, 0.0),
        Vec3::new(0.0, 1.0, 0.0),
    ];
    let faces = [0, 1, 2, 0, 2, 3];
    let m = loop_subdivide(&p, &faces, 4).unwrap();
    // Boundary limit 2/3·v + 1/6·(boundary neighbours): corner (0,0) → (1/6, 1/6); the
    // diagonal's ends are corners too.
    assert!((m.positions[0] - Vec3::new(1.0 / 6.0, 1.0 / 6.0, 0.0)).length() < 1e-6);
    assert!((m.positions[2] - Vec3::new(5.0 / 6.0, 5.0 / 6.0, 0.0)).length() < 1e-6);
    let e = edges(&m.indices);
    let boundary: Vec<_> = e.iter().filter(|(_, c)| c.0 + c.1 == 1).collect();
    // 4 sides × 2^4 segments, and nothing else is open.
    assert_eq!(boundary.len(), 4 * 16);
    assert!(e.values().all(|&c| c.0 + c.1 <= 2 && c.0 <= 1 && c.1 <= 1));
    for (i, q) in m.positions.iter().enumerate() {
        assert!(q.z.abs() < 1e-6, "{i}: {q}");
        assert!(
            m.normals[i].dot(Vec3::Z) > 1.0 - 1e-5,
            "{i}: {}",
            m.normals[i]
        );
    }
    // Boundary vertices stay on the outline's cubic B-spline, which lies in the square.
    for &((a, b), _) in &boundary {
        for v in [*a, *b] {
            let q = m.positions[v as usize];
            assert!(q.x >= -1e-6 && q.x <= 1.0 + 1e-6 && q.y >= -1e-6 && q.y <= 1.0 + 1e-6);
        }
    }
}

#[test]
fn pbrt_loopsubdiv_shape_and_bad_meshes() {
    let tet = "\"point3 P\" [1 1 1  1 -1 -1  -1 1 -1  -1 -1 1] \"integer indices\" [0 1 2 0 3 1 0 2 3 1 3 2]";
    let s = parse_pbrt_str(
        "l.pbrt",
        &format!("WorldBegin\nShape \"loopsubdiv\" \"integer levels\" 2 {tet}\n"),
        Path::new("."),
    )
    .unwrap();
    assert!(s.warnings.is_empty(), "{:?}", s.warnings);
    match &s.shapes[0].geom {
        ShapeGeom::Mesh(m) => {
            assert_eq!(m.indices.len() / 3, 64);
            assert!(m.normals.is_some());
        }
        g => panic!("{g:?}"),
    }
    // Default levels 3 and pbrt-v3's 'nlevels'.
    for p in ["", "\"integer nlevels\" 1"] {
        let s = parse_pbrt_str(
            "l.pbrt",
            &format!("WorldBegin\nShape \"loopsubdiv\" {p} {tet}\n"),
            Path::new("."),
        )
        .unwrap();
        let want = if p.is_empty() { 256 } else { 16 };
        match &s.shapes[0].geom {
            ShapeGeom::Mesh(m) => assert_eq!(m.indices.len() / 3, want, "{p}"),
            g => panic!("{g:?}"),
        }
    }
    // Three triangles on one edge: the control mesh, with one located warning.
    let s = parse_pbrt_str(
        "l.pbrt",
        "WorldBegin\nShape \"loopsubdiv\" \"point3 P\" [0 0 0 1 0 0 0 1 0 0 -1 0 0 0 1] \
         \"integer indices\" [0 1 2 1 0 3 0 1 4]\n",
        Path::new("."),
    )
    .unwrap();
    assert_eq!(s.warnings.len(), 1, "{:?}", s.warnings);
    assert!(
        s.warnings[0].contains("l.pbrt:2") && s.warnings[0].contains("control mesh"),
        "{:?}",
        s.warnings
    );
    match &s.shapes[0].geom {
        ShapeGeom::Mesh(m) => assert_eq!(m.indices.len() / 3, 3),
        g => panic!("{g:?}"),
    }
    let e = parse_pbrt_str(
        "l.pbrt",
        &format!("WorldBegin\nShape \"loopsubdiv\" \"integer levels\" -1 {tet}\n"),
        Path::new("."),
    )
    .unwrap_err();
    assert!(format!("{e:#}").contains("'levels' must be ≥ 0"), "{e:#}");
}
