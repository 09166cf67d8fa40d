//! Polygon triangulation (issue 23 item 7): every polygon becomes n − 2 triangles that cover it
//! exactly with its winding, convex ones in linear time, and a 300,000-vertex OBJ face loads
//! (and builds its BVH) in well under the seconds the old fan took.

use glam::{Vec2, Vec3};
use penumbra::scene::load::{LoadOptions, load};
use penumbra::scene::polygon::{Split, triangulate};
use std::time::Instant;

/// Signed area of the polygon in the xy plane (shoelace).
fn area2(poly: &[Vec2]) -> f64 {
    let n = poly.len();
    (0..n)
        .map(|k| {
            let (a, b) = (poly[k].as_dvec2(), poly[(k + 1) % n].as_dvec2());
            a.perp_dot(b)
        })
        .sum::<f64>()
        * 0.5
}

/// Triangulate the xy polygon and check: n − 2 triangles, each counter-clockwise (the
/// polygon's winding), areas summing to the polygon's.
fn check(poly: &[Vec2], want: Split) {
    let positions: Vec<Vec3> = poly.iter().map(|p| p.extend(0.0)).collect();
    let idx: Vec<u32> = (0..poly.len() as u32).collect();
    let mut out = Vec::new();
    let split = triangulate(&idx, &positions, &mut out);
    assert_eq!(split, want, "{} vertices", poly.len());
    assert_eq!(out.len(), 3 * (poly.len() - 2), "triangle count");
    let mut sum = 0.0;
    for t in out.chunks_exact(3) {
        let (a, b, c) = (
            poly[t[0] as usize].as_dvec2(),
            poly[t[1] as usize].as_dvec2(),
            poly[t[2] as usize].as_dvec2(),
        );
        let a2 = 0.5 * (b - a).perp_dot(c - a);
        assert!(a2 >= 0.0, "triangle {t:?} is clockwise (area {a2})");
        sum += a2;
    }
    let want_area = area2(poly);
    assert!(
        (sum - want_area).abs() <= 1e-9 * want_area.abs().max(1.0),
        "triangles cover {sum}, polygon {want_area}"
    );
}

fn circle(n: usize) -> Vec<Vec2> {
    (0..n)
        .map(|k| {
            let a = std::f64::consts::TAU * k as f64 / n as f64;
            Vec2::new(a.cos() as f32, a.sin() as f32)
        })
        .collect()
}

#[test]
fn convex_polygons_split_into_n_minus_2_counter_clockwise_triangles() {
    for n in [5, 6, 7, 16, 17, 100] {
        check(&circle(n), Split::Balanced);
    }
    // Collinear runs along the edges are still convex.
    let square_with_midpoints = [
        Vec2::new(0.0, 0.0),
        Vec2::new(1.0, 0.0),
        Vec2::new(2.0, 0.0),
        Vec2::new(2.0, 2.0),
        Vec2::new(0.0, 2.0),
    ];
    check(&square_with_midpoints, Split::Balanced);
}

#[test]
fn concave_polygons_are_ear_clipped_exactly() {
    // An L shape and a star: a fan from vertex 0 would leave the polygon.
    let l = [
        Vec2::new(0.0, 0.0),
        Vec2::new(2.0, 0.0),
        Vec2::new(2.0, 1.0),
        Vec2::new(1.0, 1.0),
        Vec2::new(1.0, 2.0),
        Vec2::new(0.0, 2.0),
    ];
    check(&l, Split::Ears);
    let star: Vec<Vec2> = (0..10)
        .map(|k| {
            let a = std::f32::consts::TAU * k as f32 / 10.0;
            let r = if k % 2 == 0 { 1.0 } else { 0.4 };
            Vec2::new(r * a.cos(), r * a.sin())
        })
        .collect();
    check(&star, Split::Ears);
}

#[test]
fn clockwise_and_tilted_polygons_keep_their_winding() {
    // A clockwise hexagon in a tilted plane: every triangle's normal agrees with the polygon's.
    let tilt = glam::Quat::from_rotation_x(0.7) * glam::Quat::from_rotation_y(-0.4);
    let poly: Vec<Vec3> = circle(6)
        .iter()
        .rev()
        .map(|p| tilt * p.extend(0.0))
        .collect();
    let want = (tilt * Vec3::NEG_Z).normalize();
    let idx: Vec<u32> = (0..6).collect();
    let mut out = Vec::new();
    assert_eq!(triangulate(&idx, &poly, &mut out), Split::Balanced);
    for t in out.chunks_exact(3) {
        let (a, b, c) = (
            poly[t[0] as usize],
            poly[t[1] as usize],
            poly[t[2] as usize],
        );
        let n = (b - a).cross(c - a).normalize();
        assert!(n.dot(want) > 0.99, "triangle normal {n}, polygon {want}");
    }
}

#[test]
fn huge_obj_polygon_loads_fast() {
    // One 300,000-vertex face (a circle written with 7 decimals, as exporters do) and a lamp.
    let n = 300_000;
    let mut obj = String::with_capacity(n * 40);
    for k in 0..n {
        let a = std::f64::consts::TAU * k as f64 / n as f64;
        obj.push_str(&format!("v {:.7} {:.7} 0\n", a.cos(), a.sin()));
    }
    obj.push('f');
    for k in 1..=n {
        obj.push_str(&format!(" {k}"));
    }
    obj.push('\n');
    let dir = std::env::temp_dir().join(format!("penumbra-polygon-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("scratch dir");
    let p = dir.join("huge.obj");
    std::fs::write(&p, obj).expect("write");
    let t = Instant::now();
    let loaded = load(p.to_str().expect("utf8"), &LoadOptions::default()).expect("load");
    let secs = t.elapsed().as_secs_f64();
    eprintln!("300,000-vertex polygon: loaded in {secs:.2} s");
    // Rounding to 7 decimals makes some runs of three vertices collinear: those triangles
    // have no area and are dropped, so check the area covered instead of the count.
    let g = &loaded.scene.geometry;
    let tris = g.len();
    assert!(
        tris <= n - 2 && tris > n / 2,
        "{tris} triangles for a {n}-gon"
    );
    let covered: f64 = (0..tris as u32)
        .map(|i| {
            let p = g.primitive(i).expect("primitive").p.map(|v| v.as_dvec3());
            0.5 * (p[1] - p[0]).cross(p[2] - p[0]).length()
        })
        .sum();
    let want = 0.5 * n as f64 * (std::f64::consts::TAU / n as f64).sin();
    assert!(
        (covered - want).abs() < 1e-5 * want,
        "triangles cover {covered}, the polygon {want}"
    );
    assert!(secs < 10.0, "loading took {secs:.2} s");
}

#[test]
fn large_concave_polygon_is_tiled_exactly() {
    // A 20,000-vertex star (every other vertex pulled in): no balanced split tiles it, so ear
    // clipping does, with Delaunay flips against slivers.
    let n = 20_000;
    let star: Vec<Vec2> = (0..n)
        .map(|k| {
            let a = std::f64::consts::TAU * k as f64 / n as f64;
            let r = if k % 2 == 0 { 1.0 } else { 0.9 };
            Vec2::new((r * a.cos()) as f32, (r * a.sin()) as f32)
        })
        .collect();
    let t = Instant::now();
    check(&star, Split::Ears);
    let secs = t.elapsed().as_secs_f64();
    eprintln!("20,000-vertex star: triangulated in {secs:.2} s");
    assert!(secs < 5.0, "triangulation took {secs:.2} s");
}
