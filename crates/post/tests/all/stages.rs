//! The motion stage and the check on their own, with `Vec` sinks: the
//! linearization keeps the contact point on the straight CL segment
//! (checked by the forward kinematics of the blocks, independently of the
//! stage), and every built-in dialect's program reads back through the
//! read-back stage as it was written.

use kinpost_post::diag::Site;
use kinpost_post::machine::{Kinematics, builtin};
use kinpost_post::motion::{MotionBlock, MotionSink, MotionStage};
use kinpost_post::nc::{ArcMotion, ArcPlane, Block, Dialect, Motion};
use kinpost_post::plan::{Node, PlanSink, Planned};
use kinpost_post::{
    Config, Pending, PostError, PostOptions, ReadBackError, compare_read_back, post_read_back,
};
use nalgebra::Vector3;

use crate::common;

/// The blocks the motion stage hands on, as they come.
#[derive(Default)]
struct Blocks(Vec<(Option<usize>, Motion, Vec<f64>)>);

impl MotionSink for Blocks {
    fn block(&mut self, kin: &Kinematics, b: &MotionBlock<'_>) -> Result<f64, PostError> {
        let n = kin.axis_count();
        self.0.push((b.cl_line, b.motion, b.values[..n].to_vec()));
        Ok(f64::INFINITY)
    }

    fn command(&mut self, _: Pending) -> Result<(), PostError> {
        Ok(())
    }

    fn inverse_time(&mut self, _: bool) -> Result<(), PostError> {
        Ok(())
    }

    fn feed_rounds_to_zero(&self, word: f64) -> bool {
        word == 0.0
    }
}

fn distance_to_segment(p: &Vector3<f64>, a: &Vector3<f64>, b: &Vector3<f64>) -> f64 {
    let ab = b - a;
    let t = ((p - a).dot(&ab) / ab.norm_squared()).clamp(0.0, 1.0);
    (p - (a + ab * t)).norm()
}

/// A long feed move on the A/C trunnion that turns the table by 40°: the
/// stage inserts blocks, and the contact point of every straight joint
/// move between them stays within the tolerance of the CL segment.
#[test]
fn the_linearization_keeps_the_contact_point_on_the_segment() {
    let m = builtin::load("trunnion-ac").unwrap().unwrap();
    let kin = Kinematics::new(&m);
    let options = PostOptions {
        lintol_mm: Some(0.002),
        ..Default::default()
    };
    let config = Config::resolve(&options, &m, &Dialect::builtin("sinumerik").unwrap()).unwrap();
    let mut stage = MotionStage::new(&m, &kin, &config, None, Blocks::default());
    let ends = [[0.0, 0.0, 20.0, 0.0, 0.0], [0.0, 0.0, 20.0, 20.0, 40.0]];
    let nodes: Vec<Node> = ends
        .iter()
        .map(|q| {
            let mut joints = [0.0; 9];
            joints[..5].copy_from_slice(q);
            Node {
                pose: kin.fk(q),
                joints,
                hold: None,
                branch: 0,
            }
        })
        .collect();
    for (k, node) in nodes.iter().enumerate() {
        let planned = Planned {
            node,
            motion: if k == 0 { Motion::Rapid } else { Motion::Feed },
            feed: Some(300.0),
            pressure: f64::NAN,
            continuous: true,
            cut: k > 0,
            site: Site {
                file: "stage.cls",
                line: k + 1,
                text: b"GOTO",
            },
        };
        stage.point(&kin, &planned).unwrap();
    }
    let (blocks, report) = stage.finish().unwrap();
    let blocks = blocks.0;
    assert!(report.inserted_blocks > 10, "{}", report.inserted_blocks);
    assert_eq!(blocks.len() as u64, 2 + report.inserted_blocks);
    assert_eq!(blocks.first().unwrap().0, Some(1));
    assert_eq!(blocks.last().unwrap().0, Some(2));
    assert!(blocks[1..blocks.len() - 1].iter().all(|b| b.0.is_none()));
    let (a, b) = (nodes[0].pose.point, nodes[1].pose.point);
    let mut worst: f64 = 0.0;
    for w in blocks.windows(2) {
        for s in 1..8 {
            let t = f64::from(s) / 8.0;
            let q: Vec<f64> = w[0]
                .2
                .iter()
                .zip(&w[1].2)
                .map(|(x, y)| x + (y - x) * t)
                .collect();
            worst = worst.max(distance_to_segment(&kin.fk(&q).point, &a, &b));
        }
        // Every inserted block lies on the segment.
        assert!(distance_to_segment(&kin.fk(&w[1].2).point, &a, &b) < 1e-6);
    }
    // (Sampled at eighths: the midpoint bound the stage uses is 0.002 mm.)
    assert!(worst <= 0.002 + 1e-6, "{worst}");
    assert!(report.linearization.max_error_mm <= 0.002);
}

/// Every built-in machine's job in every built-in dialect reads back, block
/// for block, as the writer wrote it.
#[test]
fn every_dialect_reads_back_as_written() {
    for machine in builtin::names() {
        let m = builtin::load(machine).unwrap().unwrap();
        let cl = common::job(&m);
        for dialect in Dialect::builtin_names() {
            let d = Dialect::builtin(dialect).unwrap();
            let options = PostOptions {
                cl_file: "job.cls".into(),
                ..Default::default()
            };
            let (read_back, summary) =
                post_read_back(cl.as_bytes(), &m, &d, Vec::new(), &options).unwrap();
            let out = read_back.unwrap_or_else(|e| panic!("{machine} {dialect}: {e}"));
            assert!(
                summary.blocks >= 10 && !out.is_empty(),
                "{machine} {dialect}"
            );
        }
    }
}

/// A block as written at program `line`.
fn written(line: usize, motion: Motion, values: Vec<f64>) -> Block<Vec<f64>> {
    Block {
        line: Some(line),
        number: None,
        motion,
        ..Block::rapid(values)
    }
}

/// The read-back comparison finds a block that does not read back as
/// written: a value changed, a block missing, another motion.
#[test]
fn a_block_that_does_not_read_back_is_found() {
    let d = Dialect::builtin("linuxcnc").unwrap();
    let axes = [
        kinpost_post::nc::AxisSpec::linear("X"),
        kinpost_post::nc::AxisSpec::linear("Y"),
    ];
    let text = "%\nG0 X1.0000 Y2.0000\nG1 X1.5000 F250.0\nM2\n%\n";
    let written = |y: f64, line: usize, motion| written(line, motion, vec![1.5, y]);
    let first = written(2.0, 2, Motion::Rapid).map_axes(|_| vec![1.0, 2.0]);
    let ok = [first.clone(), written(2.0, 3, Motion::Feed)];
    assert!(compare_read_back(&d, &axes, &ok, text).is_ok());
    let value = [first.clone(), written(2.5, 3, Motion::Feed)];
    assert!(matches!(
        compare_read_back(&d, &axes, &value, text),
        Err(ReadBackError::Block {
            index: 1,
            line: 3,
            ..
        })
    ));
    let motion = [first.clone(), written(2.0, 3, Motion::Rapid)];
    assert!(compare_read_back(&d, &axes, &motion, text).is_err());
    let missing = [first, written(2.0, 4, Motion::Feed)];
    assert!(matches!(
        compare_read_back(&d, &axes, &missing, text),
        Err(ReadBackError::Missing { index: 1, line: 4 })
    ));
}

/// A circular block reads back with its plane, sense and the centre words
/// of its plane; another centre, sense or plane, or a straight block where
/// an arc was written, is found.
#[test]
fn an_arc_reads_back_as_written() {
    let d = Dialect::builtin("fanuc").unwrap();
    let axes = [
        kinpost_post::nc::AxisSpec::linear("X"),
        kinpost_post::nc::AxisSpec::linear("Y"),
        kinpost_post::nc::AxisSpec::linear("Z"),
    ];
    let text = "%\nG0 X10.000 Y0.000 Z5.000\nG18 G02 X0.000 Z15.000 I-10.000 K0.000 F300.\nG17 G03 X-10.000 Y0.000 J0.000 I-10.000\nG1 X0.000\nM30\n%\n";
    let arc = |plane, clockwise, centre_offset| {
        Some(ArcMotion {
            plane,
            clockwise,
            centre_offset,
        })
    };
    let blocks = |second: Option<ArcMotion>| {
        let mut b = vec![
            written(2, Motion::Rapid, vec![10.0, 0.0, 5.0]),
            written(3, Motion::Feed, vec![0.0, 0.0, 15.0]),
            written(4, Motion::Feed, vec![-10.0, 0.0, 15.0]),
            written(5, Motion::Feed, vec![0.0, 0.0, 15.0]),
        ];
        b[1].arc = second;
        // (The centre word along the plane's normal is not written: any
        // value there reads back.)
        b[2].arc = arc(ArcPlane::Xy, false, [-10.0, 0.0, 7.0]);
        b
    };
    let good = blocks(arc(ArcPlane::Zx, true, [-10.0, 3.0, 0.0]));
    compare_read_back(&d, &axes, &good, text).unwrap();
    for bad in [
        blocks(arc(ArcPlane::Zx, true, [-10.0, 0.0, 0.5])),
        blocks(arc(ArcPlane::Zx, false, [-10.0, 0.0, 0.0])),
        blocks(arc(ArcPlane::Xy, true, [-10.0, 0.0, 0.0])),
        blocks(None),
    ] {
        assert!(
            matches!(
                compare_read_back(&d, &axes, &bad, text),
                Err(ReadBackError::Block {
                    index: 1,
                    line: 3,
                    ..
                })
            ),
            "{bad:?}"
        );
    }
    let mut straight = good.clone();
    straight[3].arc = arc(ArcPlane::Xy, false, [-10.0, 0.0, 0.0]);
    assert!(compare_read_back(&d, &axes, &straight, text).is_err());
}
