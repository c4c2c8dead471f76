//! The analytic gradient and Hessian of eq. (4–5) against central finite
//! differences of the score of eq. (1).

mod common;

use nalgebra::{Matrix3, Vector2, Vector3};
use ndt_core::cell::CellStats;
use ndt_core::{Gaussian, MatchOptions, NdtGrid, Order, Pose2, ScoreTerms};
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};

const H: f64 = 1e-6;

fn terms_one(x: Vector2<f64>, g: &Gaussian, p: [f64; 3]) -> ScoreTerms {
    let pose = Pose2 {
        x: p[0],
        y: p[1],
        theta: p[2],
    };
    let mut t = ScoreTerms::default();
    t.add(x, pose.transform(x), p[2].sin_cos(), g, Order::Derivatives);
    t
}

fn rel(a: f64, b: f64, scale: f64) -> f64 {
    (a - b).abs() / scale
}

fn random_gaussian(rng: &mut StdRng) -> Gaussian {
    let mut s = CellStats::default();
    for _ in 0..6 {
        s.add_point(Vector2::new(
            rng.random_range(-0.05..0.05),
            rng.random_range(-0.05..0.05),
        ));
    }
    // Spread above the 5 mm σ floor, so the inverses are anisotropic.
    let origin = Vector2::new(rng.random_range(-3.0..3.0), rng.random_range(-3.0..3.0));
    Gaussian::from_stats(&s, origin, 0.005, rng.random_range(1.0..20.0)).unwrap()
}

#[test]
fn per_point_gradient_and_hessian_equal_central_differences() {
    let mut rng = StdRng::seed_from_u64(1);
    let mut checked = 0;
    for _ in 0..500 {
        let g = random_gaussian(&mut rng);
        let p = [
            rng.random_range(-2.0..2.0),
            rng.random_range(-2.0..2.0),
            rng.random_range(-3.1..3.1),
        ];
        // Choose the scan point so that it lands about 1σ from the mean.
        let sigma = g.covariance().trace().sqrt();
        let target =
            g.mean + Vector2::new(rng.random_range(-1.5..1.5), rng.random_range(-1.5..1.5)) * sigma;
        let pose = Pose2 {
            x: p[0],
            y: p[1],
            theta: p[2],
        };
        let xv = pose.inverse().transform(target);
        let t = terms_one(xv, &g, p);
        let f = |q: [f64; 3]| -terms_one(xv, &g, q).score;
        let gr = |q: [f64; 3]| terms_one(xv, &g, q).gradient;
        // The step scales with the distribution's width and the lever arm of θ,
        // so that truncation error stays far below the tolerance.
        let (_, l2, _) = ndt_core::cell::symmetric_eigen2(&g.covariance());
        let h = 1e-4 * l2.sqrt() / (1.0 + xv.norm());
        let mut g_fd = Vector3::zeros();
        let mut h_fd = Matrix3::zeros();
        for k in 0..3 {
            let mut a = p;
            let mut b = p;
            a[k] += h;
            b[k] -= h;
            g_fd[k] = (f(a) - f(b)) / (2.0 * h);
            let col = (gr(a) - gr(b)) / (2.0 * h);
            h_fd.set_column(k, &col);
        }
        let gs = t.gradient.norm().max(1e-300);
        let hs = t.hessian.norm().max(1e-300);
        if t.score < 1e-6 {
            continue;
        }
        for k in 0..3 {
            assert!(rel(t.gradient[k], g_fd[k], gs) < 1e-6, "g {t:?} vs {g_fd}");
            for l in 0..3 {
                assert!(
                    rel(t.hessian[(k, l)], h_fd[(k, l)], hs) < 1e-6,
                    "H[{k},{l}] {} vs {}",
                    t.hessian[(k, l)],
                    h_fd[(k, l)]
                );
            }
        }
        // The Hessian is symmetric.
        assert!((t.hessian - t.hessian.transpose()).norm() <= 1e-12 * hs);
        checked += 1;
    }
    assert!(
        checked > 400,
        "only {checked} poses had a non-negligible score"
    );
}

/// Whole-scan terms from the grid (pairing, fusion and expansion included)
/// against finite differences, at poses where no point is within the
/// difference step of a cell border (there the score is only piecewise smooth).
#[test]
fn whole_scan_terms_equal_central_differences() {
    let walls = common::room();
    let map_pose = Pose2::new(0.0, 0.0, 0.0);
    let mut grid = NdtGrid::new(0.05).unwrap();
    grid.insert(&common::urg_scan(&walls, map_pose, 0.01, 3), map_pose)
        .unwrap();
    let mut rng = StdRng::seed_from_u64(2);
    let options = MatchOptions {
        neighbor_search: false,
        ..MatchOptions::default()
    };
    let scan = common::urg_scan(&walls, Pose2::new(0.1, -0.05, 0.05), 0.01, 4);
    let mut checked = 0;
    for _ in 0..50 {
        let p = [
            0.1 + rng.random_range(-0.02..0.02),
            -0.05 + rng.random_range(-0.02..0.02),
            0.05 + rng.random_range(-0.02..0.02),
        ];
        let pose = Pose2 {
            x: p[0],
            y: p[1],
            theta: p[2],
        };
        // Keep only points well inside their cell at this pose.
        let pts: Vec<[f64; 2]> = scan
            .iter()
            .copied()
            .filter(|q| {
                let w = pose.transform(Vector2::new(q[0], q[1]));
                let fx = (w.x / 0.05).fract().abs();
                let fy = (w.y / 0.05).fract().abs();
                fx > 0.01 && fx < 0.99 && fy > 0.01 && fy < 0.99
            })
            .collect();
        let eval = |q: [f64; 3]| {
            grid.score_terms(
                &pts,
                Pose2 {
                    x: q[0],
                    y: q[1],
                    theta: q[2],
                },
                &options,
            )
            .unwrap()
        };
        let t = eval(p);
        assert!(t.matched > 100);
        let mut g_fd = Vector3::zeros();
        let mut h_fd = Matrix3::zeros();
        for k in 0..3 {
            let mut a = p;
            let mut b = p;
            a[k] += H;
            b[k] -= H;
            let (ta, tb) = (eval(a), eval(b));
            assert_eq!(ta.matched, tb.matched);
            g_fd[k] = (-ta.score + tb.score) / (2.0 * H);
            h_fd.set_column(k, &((ta.gradient - tb.gradient) / (2.0 * H)));
        }
        let gs = t.gradient.norm();
        let hs = t.hessian.norm();
        assert!(
            (t.gradient - g_fd).norm() / gs < 1e-6,
            "{} vs {}",
            t.gradient,
            g_fd
        );
        assert!(
            (t.hessian - h_fd).norm() / hs < 1e-6,
            "{} vs {}",
            t.hessian,
            h_fd
        );
        checked += 1;
    }
    assert_eq!(checked, 50);
}

#[test]
fn a_weighted_point_counts_as_that_many_copies_and_weight_one_is_bit_identical() {
    use ndt_core::score::Accumulator;
    let mut rng = StdRng::seed_from_u64(11);
    for _ in 0..200 {
        let g = random_gaussian(&mut rng);
        let x = Vector2::new(rng.random_range(-2.0..2.0), rng.random_range(-2.0..2.0));
        let p = Pose2::new(
            g.mean.x - x.x + rng.random_range(-0.05..0.05),
            g.mean.y - x.y + rng.random_range(-0.05..0.05),
            rng.random_range(-0.02..0.02),
        );
        let (xw, sc) = (p.transform(x), p.theta.sin_cos());
        let mut once = Accumulator::default();
        once.add(x, xw, sc, &g, 3.0, Order::Derivatives);
        let mut thrice = Accumulator::default();
        for _ in 0..3 {
            thrice.add(x, xw, sc, &g, 1.0, Order::Derivatives);
        }
        let (a, b) = (once.finish(), thrice.finish());
        assert!((a.score - b.score).abs() <= 1e-12 * b.score.abs().max(1e-300));
        assert!((a.gradient - b.gradient).norm() <= 1e-12 * b.gradient.norm().max(1e-300));
        assert!((a.hessian - b.hessian).norm() <= 1e-12 * b.hessian.norm().max(1e-300));
        // Weight 1 through the accumulator is the public per-point path, bit for bit.
        let mut one = Accumulator::default();
        one.add(x, xw, sc, &g, 1.0, Order::Derivatives);
        let mut t = ScoreTerms::default();
        t.add(x, xw, sc, &g, Order::Derivatives);
        assert_eq!(one.finish(), t);
    }
}

#[test]
fn score_alone_equals_the_score_of_score_terms() {
    let walls = common::room();
    let mut grid = NdtGrid::new(0.02).unwrap();
    let at = Pose2::new(0.1, -0.2, 0.3);
    grid.insert(&common::urg_scan(&walls, at, 0.0, 1), at)
        .unwrap();
    let scan = common::urg_scan(&walls, at, 0.0, 2);
    let options = MatchOptions::default();
    for d in [0.0, 0.01, 0.05] {
        let p = Pose2::new(at.x + d, at.y - d, at.theta + d);
        let full = grid.score_terms(&scan, p, &options).unwrap().score;
        assert_eq!(grid.score(&scan, p, &options).unwrap(), full);
        assert!(full > 0.0);
    }
}
