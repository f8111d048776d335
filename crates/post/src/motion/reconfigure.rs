//! Retract and reconfigure: where no continuous motion inside the travel
//! takes the machine from one CL point of a cut to the next (the travel
//! forces a flip), the tool retracts along its axis, the rotary axes turn
//! to the new configuration above the point, and the tool re-approaches
//! it, so that the segment is cut in the new configuration.

use kinpost_machine::{Joints, Kinematics, Pose};
use kinpost_nc::Motion;
use kinpost_plan::{Near, Node, Planned, STEP_CEILING_DEG, solve_near};

use super::{Last, MotionSink, MotionStage, Reconfiguration};
use crate::error::{MotionError, MotionWarning, PostError};

impl<S: MotionSink> MotionStage<S> {
    /// Retract along the tool axis from the last block, turn the rotary axes
    /// to the new configuration above the point before `t` and re-approach
    /// it, so that the segment to `t` is cut in the new configuration: the
    /// rapid and approach blocks are written here, and the feed blocks
    /// that linearize the segment are returned for the caller to write
    /// before `t`. Where the new configuration cannot reach the point
    /// before, or not move on from it continuously, the re-approach is onto
    /// `t` itself and the segment is left uncut (a warning).
    pub(super) fn reconfigure(
        &mut self,
        kin: &Kinematics,
        last: &Last,
        t: &Planned<'_>,
    ) -> Result<Vec<Node>, PostError> {
        let (from, to) = (&last.node, t.node);
        let (axis, a, b) = self.largest_jump(&from.joints, &to.joints);
        if !self.reconfigure {
            return Err(t
                .site
                .locate(MotionError::ReconfigurationForbidden {
                    from_line: last.line,
                    axis: self.names[axis].clone(),
                    from_deg: a,
                    to_deg: b,
                })
                .into());
        }
        let d = self.retract_mm;
        let lift = |node: &Node| Pose {
            point: node.pose.point + node.pose.axis * d,
            ..node.pose
        };
        // The point before, in the configuration of `t`.
        let resumed = self.resume(kin, from, to);
        let down = resumed.as_ref().map_or(to, |(node, _)| node);
        let (up, over) = (lift(from), lift(down));
        let mut nodes = [*from, *down];
        for (k, (pose, near)) in [(up, from), (over, down)].into_iter().enumerate() {
            let near = Near {
                joints: &near.joints,
                hold: near.hold,
                branch: Some(near.branch),
            };
            let Some((pose, sol)) =
                solve_near(kin, &pose, &near, &self.rotary, &mut self.solutions)
            else {
                return Err(t
                    .site
                    .locate(MotionError::RetractOutsideTravel {
                        retract_mm: d,
                        above: k == 1,
                    })
                    .into());
            };
            nodes[k] = Node::solved(pose, &sol, near.hold);
        }
        let uncut_mm = match resumed {
            Some(_) => 0.0,
            None => (to.pose.point - from.pose.point).norm(),
        };
        if uncut_mm > 0.0 {
            self.report
                .warnings
                .push(t.site.warning(MotionWarning::Uncut {
                    from_line: last.line,
                    uncut_mm,
                    axis: self.names[axis].clone(),
                    from_deg: a,
                    to_deg: b,
                }));
        }
        self.report.reconfigurations.push(Reconfiguration {
            line: t.site.line,
            previous_line: Some(last.line),
            axis: self.names[axis].clone(),
            from_deg: a,
            to_deg: b,
            retract_mm: d,
            uncut_mm,
        });
        for node in &nodes {
            self.inserted(kin, node, Motion::Rapid, t)?;
        }
        Ok(match resumed {
            // The approach onto the point before, then the segment.
            Some((node, between)) => std::iter::once(node).chain(between).collect(),
            None => Vec::new(),
        })
    }

    /// The point before a reconfiguration (`from`) in the configuration of
    /// the point after it (`to`), and the nodes that linearize the segment
    /// between them: `None` when that configuration cannot reach `from`, or
    /// the segment needs a jump of a rotary axis (beyond the planner's
    /// ceiling of a continuous step) or does not converge to the straight
    /// segment.
    fn resume(&mut self, kin: &Kinematics, from: &Node, to: &Node) -> Option<(Node, Vec<Node>)> {
        let near = Near {
            joints: &to.joints,
            hold: to.hold,
            branch: Some(to.branch),
        };
        let (pose, sol) = solve_near(kin, &from.pose, &near, &self.rotary, &mut self.solutions)?;
        let node = Node::solved(pose, &sol, to.hold);
        let step = self
            .rotary
            .iter()
            .map(|&i| (to.joints[i] - node.joints[i]).abs())
            .fold(0.0, f64::max);
        if node.branch != to.branch || step > STEP_CEILING_DEG {
            return None;
        }
        let mut between = Vec::new();
        if let Some(l) = &mut self.linearizer {
            // (A segment that is then not cut does not count.)
            let before = l.report;
            if l.linearize(kin, &node, to, f64::INFINITY, 0, &mut between)
                .is_err()
            {
                l.report.max_error_mm = before.max_error_mm;
                return None;
            }
        }
        Some((node, between))
    }

    /// The rotary axis that jumps most from `a` to `b`, and its two values.
    fn largest_jump(&self, a: &Joints, b: &Joints) -> (usize, f64, f64) {
        let i = self
            .rotary
            .iter()
            .copied()
            .max_by(|&i, &j| (b[i] - a[i]).abs().total_cmp(&(b[j] - a[j]).abs()))
            .unwrap_or(0);
        (i, a[i], b[i])
    }
}
