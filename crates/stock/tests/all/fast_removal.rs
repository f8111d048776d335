//! The fast removal gives the stock of the straightforward one, bit for bit
//! (every interval end and move id), on random tools, poses and stocks, and
//! the same bytes for 1, 2 and 4 threads.
//!
//! The stocks: random boxes on either side of the origin (so the rays'
//! coordinates, the tools' offsets from the ray origins and the material's
//! levels take every sign), first cut by random moves (the reference path),
//! so that rays hold several intervals. The moves: every tool kind, axes at
//! random and exactly along or across a lattice axis (the degenerate
//! branches of the kernels), translations (swept exactly), five-axis moves
//! (sampled) and single poses.

use kinpost_stock::{Move as Batched, Removal, Stock, Tool, ToolPose};
use nalgebra::{Point3, Vector3};
use proptest::prelude::*;

/// Every ray's intervals and move ids, as bytes.
fn bytes(s: &Stock) -> Vec<u8> {
    let mut out = Vec::new();
    for k in 0..3 {
        for ray in &s.family(k).rays {
            out.extend((ray.len() as u32).to_le_bytes());
            for seg in ray {
                out.extend(seg.lo.to_bits().to_le_bytes());
                out.extend(seg.hi.to_bits().to_le_bytes());
                out.extend(seg.lo_move.to_le_bytes());
                out.extend(seg.hi_move.to_le_bytes());
            }
        }
    }
    out
}

fn tool_strategy() -> impl Strategy<Value = Tool> {
    prop_oneof![
        (0.5f64..8.0, 1.0f64..15.0, any::<bool>()).prop_map(|(d, l, shank)| Tool::FlatEnd {
            diameter: d,
            flute_length: l,
            shank: shank.then_some(kinpost_stock::Shank {
                diameter: d * 0.8,
                length: 5.0
            }),
        }),
        (0.5f64..8.0, 0.2f64..15.0).prop_map(|(d, l)| Tool::BallEnd {
            diameter: d,
            flute_length: l,
            shank: None,
        }),
        (1.0f64..8.0, 0.05f64..0.5, 1.0f64..15.0).prop_map(|(d, f, l)| Tool::BullNose {
            diameter: d,
            corner_radius: d * f,
            flute_length: l,
            shank: None,
        }),
        (1.0f64..8.0, 60.0f64..150.0, 2.0f64..15.0).prop_map(|(d, a, l)| Tool::Drill {
            diameter: d,
            point_angle_deg: a,
            flute_length: l,
        }),
        (3.0f64..60.0, 1.0f64..25.0, 0.0f64..0.5).prop_map(|(r, w, e)| Tool::ContactWheel {
            radius: r,
            width: w,
            edge_radius: if e < 0.25 {
                0.0
            } else {
                (w / 2.0).min(r) * e * 0.9
            },
        }),
        (3.0f64..30.0, 1.0f64..6.0).prop_map(|(r, t)| Tool::DiscWheel {
            radius: r,
            thickness: t
        }),
    ]
}

/// A unit axis: at random, or exactly along or across a lattice axis.
fn axis_strategy() -> impl Strategy<Value = Vector3<f64>> {
    prop_oneof![
        3 => (0.0f64..6.3, 0.0f64..3.15)
            .prop_map(|(a, b)| Vector3::new(a.cos() * b.sin(), a.sin() * b.sin(), b.cos())),
        1 => (0usize..6).prop_map(|i| {
            let mut v = Vector3::zeros();
            v[i % 3] = if i < 3 { 1.0 } else { -1.0 };
            v
        }),
        1 => (0.0f64..6.3).prop_map(|a| Vector3::new(a.cos(), a.sin(), 0.0)),
        // Nearly along Z: the rays' quadratic nearly linear.
        1 => (-1e-7f64..1e-7, -1e-7f64..1e-7).prop_map(|(x, y)| Vector3::new(x, y, 1.0).normalize()),
    ]
}

#[derive(Debug, Clone)]
struct Move {
    from: ToolPose,
    to: Option<ToolPose>,
}

fn pose(lo: Point3<f64>, size: Vector3<f64>) -> impl Strategy<Value = ToolPose> {
    (
        prop::array::uniform3(-0.3f64..1.3),
        axis_strategy(),
        axis_strategy(),
    )
        .prop_filter_map("reference along the axis", move |(f, axis, r)| {
            if axis.cross(&r).norm() < 1e-3 {
                return None;
            }
            let p = lo + Vector3::new(f[0] * size.x, f[1] * size.y, f[2] * size.z);
            Some(ToolPose::new(p, axis).with_reference(r))
        })
}

/// A move from a pose: a translation, a small turn with a translation, or
/// a single pose.
fn move_strategy(lo: Point3<f64>, size: Vector3<f64>) -> impl Strategy<Value = Move> {
    (
        pose(lo, size),
        0usize..3,
        prop::array::uniform3(-2.0f64..2.0),
        prop::array::uniform3(-0.3f64..0.3),
    )
        .prop_map(|(from, kind, step, turn)| {
            let t = Vector3::from(step);
            let to = match kind {
                0 => Some(ToolPose {
                    point: from.point + t,
                    ..from
                }),
                1 => {
                    let axis = (from.axis.into_inner() + Vector3::from(turn)).normalize();
                    let r = from
                        .reference
                        .map(|r| r.into_inner())
                        .unwrap_or(Vector3::x());
                    Some(
                        ToolPose::new(from.point + t * 0.2, axis)
                            .with_reference(r + Vector3::from(turn) * 0.5),
                    )
                }
                _ => None,
            };
            Move { from, to }
        })
}

#[derive(Debug, Clone)]
struct Case {
    lo: Point3<f64>,
    size: Vector3<f64>,
    h: f64,
    tool: Tool,
    moves: Vec<Move>,
}

fn case_strategy() -> impl Strategy<Value = Case> {
    case_with_moves(1..6)
}

fn case_with_moves(moves: std::ops::Range<usize>) -> impl Strategy<Value = Case> {
    (
        prop::array::uniform3(-12.0f64..4.0),
        prop::array::uniform3(2.0f64..10.0),
        0.15f64..0.4,
    )
        .prop_flat_map(move |(lo, size, h)| {
            let (lo, size) = (Point3::from(lo), Vector3::from(size));
            (
                Just(lo),
                Just(size),
                Just(h),
                tool_strategy(),
                prop::collection::vec(move_strategy(lo, size), moves.clone()),
            )
        })
        .prop_map(|(lo, size, h, tool, moves)| Case {
            lo,
            size,
            h,
            tool,
            moves,
        })
}

/// Cuts the moves: the first half with the reference path (a stock with
/// several intervals a ray), the rest with `removal`. Moves a pose does not
/// allow (a half turn, a reference along the axis) are errors for both.
fn run(case: &Case, removal: Removal) -> Vec<u8> {
    let mut s = Stock::from_box(case.lo, case.lo + case.size, case.h).unwrap();
    let half = case.moves.len() / 2;
    for (i, m) in case.moves.iter().enumerate() {
        s.set_removal(if i < half {
            Removal::Reference
        } else {
            removal
        });
        let _ = match m.to {
            Some(to) => s.cut_move(&case.tool, &m.from, &to, i as u32).map(|_| ()),
            None => s.cut_pose(&case.tool, &m.from, i as u32),
        };
    }
    bytes(&s)
}

/// The first half of the moves as [`run`]; then the rest, with ids from
/// `ids` (repeated and out of order), one by one with the reference path
/// (`batch` false) or as one batch with `removal`, up to the first move
/// that cannot be cut (a single pose is a move to itself).
fn run_rest(case: &Case, ids: &[u32], batch: Option<Removal>) -> Vec<u8> {
    let mut s = Stock::from_box(case.lo, case.lo + case.size, case.h).unwrap();
    s.set_removal(Removal::Reference);
    let half = case.moves.len() / 2;
    for (i, m) in case.moves[..half].iter().enumerate() {
        let _ = match m.to {
            Some(to) => s.cut_move(&case.tool, &m.from, &to, i as u32).map(|_| ()),
            None => s.cut_pose(&case.tool, &m.from, i as u32),
        };
    }
    let rest: Vec<Batched> = case.moves[half..]
        .iter()
        .enumerate()
        .map(|(i, m)| Batched {
            from: m.from,
            to: m.to.unwrap_or(m.from),
            id: ids[i % ids.len()],
        })
        .collect();
    match batch {
        Some(removal) => {
            s.set_removal(removal);
            let _ = s.cut_moves(&case.tool, &rest);
        }
        None => {
            for m in &rest {
                if s.cut_move(&case.tool, &m.from, &m.to, m.id).is_err() {
                    break;
                }
            }
        }
    }
    bytes(&s)
}

fn in_pool<T: Send>(threads: usize, f: impl FnOnce() -> T + Send) -> T {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
        .install(f)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    #[test]
    fn the_fast_removal_gives_the_reference_stock_bit_for_bit(case in case_strategy()) {
        let reference = run(&case, Removal::Reference);
        let fast = run(&case, Removal::Fast);
        prop_assert!(reference == fast, "the fast removal differs from the reference");
    }

    #[test]
    fn a_batch_of_moves_gives_the_stock_of_its_moves_one_by_one(
        case in case_with_moves(2..14),
        ids in prop::collection::vec(0u32..4, 1..4),
    ) {
        let one_by_one = run_rest(&case, &ids, None);
        for removal in [Removal::Fast, Removal::Reference] {
            let batch = run_rest(&case, &ids, Some(removal));
            prop_assert!(batch == one_by_one, "the {removal:?} batch differs");
        }
    }

    #[test]
    fn the_fast_removal_gives_the_same_bytes_for_1_2_and_4_threads(case in case_strategy()) {
        let one = in_pool(1, || run(&case, Removal::Fast));
        for n in [2, 4] {
            let other = in_pool(n, || run(&case, Removal::Fast));
            prop_assert!(one == other, "{n} threads differ from 1");
        }
    }
}

/// The benchmark's cases in small: the contact wheel tilting across a
/// zig-zag (five-axis, sampled) and a ball end mill (translations), many
/// consecutive moves on one stock, fast against reference.
#[test]
fn consecutive_wheel_and_ball_moves_match_the_reference() {
    let run = |removal: Removal, batched: bool| {
        let mut s = Stock::from_box(
            Point3::new(0.0, 0.0, 0.0),
            Point3::new(30.0, 12.0, 6.0),
            0.05,
        )
        .unwrap();
        s.set_removal(removal);
        let wheel = Tool::ContactWheel {
            radius: 20.0,
            width: 6.0,
            edge_radius: 0.0,
        };
        let ball = Tool::BallEnd {
            diameter: 3.0,
            flute_length: 10.0,
            shank: None,
        };
        let mut id = 0;
        for (tool, z, tilt_deg, y0) in [(wheel, 5.95, 0.3f64, 4.0), (ball, 5.5, 0.0, 8.0)] {
            for pass in 0..2 {
                let y = y0 + 0.7 * pass as f64;
                let poses: Vec<ToolPose> = (0..120)
                    .map(|i| {
                        let s = 3.0 + 0.1 * i as f64;
                        let x = if pass % 2 == 0 { s } else { 30.0 - s };
                        let tilt = tilt_deg.to_radians() * (x / 3.0).cos();
                        let axis = Vector3::new(0.0, -tilt.sin(), tilt.cos());
                        ToolPose::new(Point3::new(x, y, z), axis).with_reference(Vector3::x())
                    })
                    .collect();
                if batched {
                    let moves: Vec<Batched> = poses
                        .windows(2)
                        .enumerate()
                        .map(|(i, w)| Batched {
                            from: w[0],
                            to: w[1],
                            id: id + i as u32,
                        })
                        .collect();
                    s.cut_moves(&tool, &moves).unwrap();
                    id += moves.len() as u32;
                } else {
                    for w in poses.windows(2) {
                        s.cut_move(&tool, &w[0], &w[1], id).unwrap();
                        id += 1;
                    }
                }
            }
        }
        bytes(&s)
    };
    let reference = run(Removal::Reference, false);
    assert!(reference == run(Removal::Fast, false), "one by one");
    assert!(reference == run(Removal::Fast, true), "in batches");
    assert!(
        reference == run(Removal::Reference, true),
        "in batches, reference"
    );
}

/// Moves that cut exactly the same spans (the same move again under
/// another id, the later visited first): the first move makes the ends and
/// names them, as one by one.
#[test]
fn the_first_of_two_equal_moves_names_the_ends_in_a_batch() {
    let wheel = Tool::ContactWheel {
        radius: 10.0,
        width: 4.0,
        edge_radius: 0.0,
    };
    let ball = Tool::BallEnd {
        diameter: 2.0,
        flute_length: 8.0,
        shank: None,
    };
    let a = ToolPose::new(Point3::new(3.0, 4.0, 4.7), Vector3::new(0.0, -0.01, 1.0))
        .with_reference(Vector3::x());
    let b = ToolPose::new(Point3::new(9.0, 4.2, 4.6), Vector3::new(0.0, 0.01, 1.0))
        .with_reference(Vector3::x());
    let c = ToolPose::new(Point3::new(9.0, 4.2, 4.6), Vector3::new(0.0, 0.0, 1.0))
        .with_reference(Vector3::x());
    // From outside the stock, a translation: the rays along X are cut from
    // their start.
    let d = ToolPose::new(Point3::new(-2.0, 4.0, 4.7), Vector3::z()).with_reference(Vector3::x());
    for tool in [wheel, ball] {
        for (from, to) in [(a, b), (a, c), (d, c)] {
            let moves = [
                Batched { from, to, id: 5 },
                Batched { from, to, id: 7 },
                Batched {
                    from: to,
                    to: from,
                    id: 9,
                },
                Batched { from, to, id: 11 },
            ];
            let stock = || {
                Stock::from_box(Point3::new(0.0, 0.0, 0.0), Point3::new(12.0, 8.0, 5.0), 0.1)
                    .unwrap()
            };
            let mut one = stock();
            one.set_removal(Removal::Reference);
            for m in &moves {
                one.cut_move(&tool, &m.from, &m.to, m.id).unwrap();
            }
            for removal in [Removal::Fast, Removal::Reference] {
                let mut batch = stock();
                batch.set_removal(removal);
                batch.cut_moves(&tool, &moves).unwrap();
                assert!(bytes(&batch) == bytes(&one), "{tool:?} {removal:?}");
            }
            // The ends below the tool are move 5's (or 9's, where the way
            // back cut deeper), never 7's or 11's.
            let z = one.family(2);
            let named: std::collections::BTreeSet<u32> = z
                .rays
                .iter()
                .filter_map(|r| r.last().map(|s| s.hi_move))
                .collect();
            assert!(named.contains(&5), "{named:?}");
            assert!(!named.contains(&7) && !named.contains(&11), "{named:?}");
            // And the starts the moves from outside make along X.
            if from == d {
                let starts: std::collections::BTreeSet<u32> = one
                    .family(0)
                    .rays
                    .iter()
                    .filter_map(|r| r.first().map(|s| s.lo_move))
                    .collect();
                assert!(starts.contains(&5), "{starts:?}");
                assert!(!starts.contains(&7) && !starts.contains(&11), "{starts:?}");
            }
        }
    }
}
