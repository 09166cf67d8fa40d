//! Accuracy of the warps' polynomial sincos (`sampling::warps::sin_cos_turn`) against f64.

use penumbra::sampling::warps::sin_cos_turn;

/// Max absolute error of sin 2πt and cos 2πt over a dense grid of t ∈ [0, 1] plus the
/// quadrant boundaries and the largest f32 below 1 (the warps' ξ < 1).
#[test]
fn sin_cos_turn_max_abs_error_below_2e7() {
    let n = 1 << 22;
    let mut ts: Vec<f32> = (0..=n).map(|i| i as f32 / n as f32).collect();
    ts.extend([0.125, 0.375, 0.625, 0.875, 1.0 - f32::EPSILON / 2.0]);
    // Values just either side of every eighth of a turn, where the quadrant choice flips.
    for k in 0..=8 {
        let x = k as f32 / 8.0;
        ts.extend([f32::from_bits(x.to_bits().saturating_sub(1)), x.next_up()]);
    }
    let mut max_err = 0.0f64;
    for &t in ts.iter().filter(|t| (0.0..=1.0).contains(*t)) {
        let (s, c) = sin_cos_turn(t);
        let (se, ce) = (std::f64::consts::TAU * t as f64).sin_cos();
        max_err = max_err
            .max((s as f64 - se).abs())
            .max((c as f64 - ce).abs());
        assert!(
            s.abs() <= 1.0 && c.abs() <= 1.0,
            "t = {t}: ({s}, {c}) outside [-1, 1]"
        );
    }
    println!("max abs error {max_err:e}");
    assert!(max_err <= 2e-7, "max abs error {max_err:e} > 2e-7");
}

/// The exact points of the circle come out exact (a zero azimuth must give the +x axis).
#[test]
fn sin_cos_turn_exact_at_quadrants() {
    assert_eq!(sin_cos_turn(0.0), (0.0, 1.0));
    let (s, c) = sin_cos_turn(0.25);
    assert_eq!((s, c.abs()), (1.0, 0.0));
    let (s, c) = sin_cos_turn(0.5);
    assert_eq!((s.abs(), c), (0.0, -1.0));
    let (s, c) = sin_cos_turn(0.75);
    assert_eq!((s, c.abs()), (-1.0, 0.0));
}
