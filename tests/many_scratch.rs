use glam::Vec3;
use penumbra::light_selection::*;
use penumbra::light_selection::bvh::BvhSelector;
use penumbra::scene::builtin::{BuiltinOptions, find};

#[test]
#[ignore]
fn scratch() {
    let scene = (find("many-open").unwrap().build)(&BuiltinOptions::default()).unwrap();
    let set = LightSet::new(&scene.lights);
    let bvh = BvhSelector::new(&set.bounds);
    let ex = ExhaustiveSelector::new(&set.bounds);
    for p in [Vec3::new(0.0, 0.0, -20.0), Vec3::new(10.0, 0.0, 0.0), Vec3::new(-30.0, 0.0, 20.0)] {
        let sp = ShadingPoint { p, n: Vec3::Y, wo: Vec3::Y };
        let mut f = 0.0f64; let mut fb = 0.0; let mut sb = 0.0;
        let mut worst = (0.0f64, 0u32, 0.0f32, 0.0f32);
        for i in 0..set.bounds.len() as u32 {
            let pe = ex.pmf(&sp, i) as f64; let pb = bvh.pmf(&sp, i) as f64;
            sb += pb;
            if pe > 0.0 { f += pe * pe / pb; fb += pe; }
            if pe > 0.0 && pe / pb > worst.0 { worst = (pe / pb, i, pe as f32, pb as f32); }
        }
        eprintln!("{p}: sum_ex {fb:.4} sum_bvh {sb:.4} variance factor {f:.3} worst {worst:?} {:?}", set.bounds[worst.1 as usize]);
    }
}
#[test]
#[ignore]
fn scratch_path() {
    let scene = (find("many-open").unwrap().build)(&BuiltinOptions::default()).unwrap();
    let set = LightSet::new(&scene.lights);
    let bvh = BvhSelector::new(&set.bounds);
    let sp = ShadingPoint { p: Vec3::new(10.0, 0.0, 0.0), n: Vec3::Y, wo: Vec3::Y };
    for (b, a, o) in bvh.path(&sp, 8342) {
        eprintln!("take {a:.3e} other {o:.3e}  p {:.3} box {:?} {:?} w {:?} co {:.3} ce {:.3}", a as f64/(a as f64+o as f64), b.min, b.max, b.w, b.cos_theta_o, b.cos_theta_e);
    }
}
