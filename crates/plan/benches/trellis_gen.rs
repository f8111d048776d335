//! Synthetic layers for the trellis benchmark and profile: a smooth A/C path
//! on trunnion-ac with `per_point` candidates per point (the C value, its
//! 360° equivalent, the other branch and its equivalent), cuts with small
//! turns and a free move every 5,000 points.

use kinpost_machine::{MAX_AXES, Solution};
use kinpost_plan::Link;

pub fn layers(points: usize, per_point: usize) -> Vec<(Vec<Solution>, Link)> {
    let sol = |a: f64, c: f64, branch: u8| {
        let mut joints = [0.0; MAX_AXES];
        joints[0] = 100.0 + a;
        joints[3] = a;
        joints[4] = c;
        Solution {
            joints,
            branch,
            singular: false,
            nearest_axis: false,
            violation: None,
        }
    };
    (0..points)
        .map(|k| {
            let t = k as f64 / points as f64;
            let a = 40.0 * (7.0 * t).sin() + 5.0;
            let c = 170.0 * (3.0 * t).sin();
            let all = [
                sol(a, c, 0),
                sol(-a, c - 180.0, 1),
                sol(a, c + 360.0 * if c < 0.0 { 1.0 } else { -1.0 }, 0),
                sol(-a, c + 180.0, 1),
            ];
            let link = if k % 5000 == 0 {
                Link::Free
            } else {
                Link::Cut {
                    turn_deg: 0.05,
                    across_singular: false,
                    fold_deg: 0.0,
                    across_fold: false,
                }
            };
            (all[..per_point].to_vec(), link)
        })
        .collect()
}
