#[path = "../tests/common/mod.rs"]
mod common;
use ndt_core::{MatchOptions, NdtGrid, Pose2};
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
fn main() {
    let args: Vec<String> = std::env::args().collect();
    let cell: f64 = args[1].parse().unwrap();
    let k: f64 = args[2].parse().unwrap();
    let radius: u32 = args[3].parse().unwrap();
    let maxt: f64 = args[4].parse().unwrap();
    let walls = common::room();
    let noise: f64 = std::env::var("NOISE")
        .map(|s| s.parse().unwrap())
        .unwrap_or(0.0);
    let mut grid = NdtGrid::new(cell).unwrap();
    for (i, p) in [
        (0.0, 0.0, 0.0),
        (0.3, 0.2, 1.0),
        (-0.4, -0.3, 2.5),
        (0.5, -0.5, -1.8),
    ]
    .iter()
    .enumerate()
    {
        let pose = Pose2::new(p.0, p.1, p.2);
        grid.insert(&common::urg_scan(&walls, pose, noise, i as u64), pose)
            .unwrap();
    }
    let truth = Pose2::new(0.12, -0.08, 0.2);
    let scan = common::urg_scan(&walls, truth, noise, 99);
    let ms: f64 = std::env::var("MS")
        .map(|s| s.parse().unwrap())
        .unwrap_or(2.0);
    let mut opts = MatchOptions {
        expansion: k,
        search_radius: radius,
        neighbor_search: radius > 0,
        ..MatchOptions::default()
    };
    opts.max_step_cells = ms;
    opts.max_step_rotation = 0.05;
    let mut rng = StdRng::seed_from_u64(1);
    let mut ok = 0;
    for _ in 0..40 {
        let guess = Pose2::new(
            truth.x + rng.random_range(-maxt..maxt),
            truth.y + rng.random_range(-maxt..maxt),
            truth.theta + rng.random_range(-1.5f64..1.5).to_radians(),
        );
        let res = grid.match_scan(&scan, guess, &opts).unwrap();
        let dt = ((res.pose.x - truth.x).powi(2) + (res.pose.y - truth.y).powi(2)).sqrt();
        let dr = (res.pose.theta - truth.theta).abs().to_degrees();
        if dt < 1e-3 && dr < 0.05 {
            ok += 1;
        } else {
            let st = grid.score_terms(&scan, truth, &opts).unwrap();
            println!("dt {dt:.4} ({:.4},{:.4}) dr {dr:.3} it {} conv {} matched {} score {:.2} truth score {:.2} matched {}", res.pose.x-truth.x, res.pose.y-truth.y, res.iterations, res.converged, res.num_matched, res.score, st.score, st.matched);
        }
    }
    println!("ok {ok}/40");
}
