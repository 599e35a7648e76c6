//! Per-slave-node envelopes of the joints over the record (`joint_envelope.json`): for each
//! joint and each of its slave nodes, the node's position at rest and the largest opening and
//! the largest net slip it reached during the run (the joint maps of the dam report,
//! `studies/dam/joint_maps.rs`, resolve them along the height).
//!
//! Definitions (the same as the joint histories, `super::joints`): opening = max(gap, 0) [m]
//! over the samples where the node found a master face (a lost node has no gap and adds
//! nothing); net slip = |d_t|, the accumulated relative tangential displacement vector's norm
//! [m] (design §7, the seed's "tangential slip"), not the path Σ|Δd_t|.
//! Sampling: at every joint-history row (the recorder's history schedule, t[0] and the last
//! row included), so the largest value over a joint's nodes equals the largest value of that
//! joint's `max_opening` and `max_tangential_displacement` history columns, exactly.
//! Written at the end of the run by [`JointEnvelopeWriter::write`]; read back by
//! [`JointEnvelope::read`], which checks that every per-node list has one value per node.

use crate::contact::joint::ContactJoint;
use crate::contact::state::JointRecord;
use crate::error::OutputError;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// File name of the per-node joint envelopes in a run directory.
pub const JOINT_ENVELOPE_FILE: &str = "joint_envelope.json";

/// The envelope of one joint's slave nodes.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct JointNodeEnvelope {
    /// The joint's name (its scene entry expanded, e.g. `J05`).
    pub joint: String,
    /// Per slave node: its position at rest [m].
    pub points: Vec<[f64; 3]>,
    /// Per slave node: the largest opening max(gap, 0) over the samples [m].
    pub max_opening: Vec<f64>,
    /// Per slave node: the largest net slip |d_t| over the samples [m].
    pub max_net_slip: Vec<f64>,
}

/// What `joint_envelope.json` holds.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct JointEnvelope {
    /// Samples taken (joint-history rows).
    pub samples: usize,
    /// Time of the last sample [s].
    pub t_last: f64,
    pub joints: Vec<JointNodeEnvelope>,
}

impl JointEnvelope {
    /// Read `joint_envelope.json` (`path` is the file or the run directory). A per-node list
    /// whose length is not the joint's node count, or a negative or non-finite value, is an
    /// error naming the file and the joint.
    pub fn read(path: &Path) -> Result<JointEnvelope, OutputError> {
        let file = if path.is_dir() { path.join(JOINT_ENVELOPE_FILE) } else { path.to_path_buf() };
        let text = std::fs::read_to_string(&file).map_err(|e| OutputError::read(&file, e))?;
        let env: JointEnvelope = serde_json::from_str(&text).map_err(|e| OutputError::read(&file, format!("not a joint envelope: {e}")))?;
        for j in &env.joints {
            let n = j.points.len();
            if j.max_opening.len() != n || j.max_net_slip.len() != n {
                return Err(OutputError::read(&file, format!("joint \"{}\": {n} nodes but {} openings and {} slips (the file is damaged: run again)", j.joint, j.max_opening.len(), j.max_net_slip.len())));
            }
            if let Some(v) = j.max_opening.iter().chain(&j.max_net_slip).find(|v| !(v.is_finite() && **v >= 0.0)) {
                return Err(OutputError::read(&file, format!("joint \"{}\": a node's largest opening or slip is {v}, not a finite value ≥ 0 (the file is damaged: run again)", j.joint)));
            }
        }
        Ok(env)
    }

    /// The envelope of joint `name`.
    pub fn joint(&self, name: &str) -> Option<&JointNodeEnvelope> {
        self.joints.iter().find(|j| j.joint == name)
    }
}

/// Tracks the per-node envelopes while a run steps (held by the joint writer, sampled with
/// its history rows).
pub struct JointEnvelopeWriter {
    env: JointEnvelope,
}

impl JointEnvelopeWriter {
    pub fn create(joints: &[ContactJoint]) -> JointEnvelopeWriter {
        let joints = joints
            .iter()
            .map(|j| {
                let n = j.tag.n_slave();
                JointNodeEnvelope { joint: j.tag.name.clone(), points: j.tag.slave.points.clone(), max_opening: vec![0.0; n], max_net_slip: vec![0.0; n] }
            })
            .collect();
        JointEnvelopeWriter { env: JointEnvelope { samples: 0, t_last: 0.0, joints } }
    }

    /// Update joint `k` with its contact record `r` (as the outputs show it). Counts a sample
    /// when `k` is the last joint.
    pub fn sample(&mut self, k: usize, r: &JointRecord, t: f64) {
        let e = &mut self.env.joints[k];
        for (i, p) in r.pairs.iter().enumerate().take(e.points.len()) {
            if p.gap.is_finite() {
                e.max_opening[i] = e.max_opening[i].max(p.gap);
            }
            e.max_net_slip[i] = e.max_net_slip[i].max(p.d_t[0].hypot(p.d_t[1]));
        }
        if k + 1 == self.env.joints.len() {
            self.env.samples += 1;
            self.env.t_last = t;
        }
    }

    /// The envelopes so far.
    pub fn envelope(&self) -> &JointEnvelope {
        &self.env
    }

    /// Write `joint_envelope.json` into `out_dir` (nothing when no sample was taken).
    pub fn write(&self, out_dir: &Path) -> Result<Option<PathBuf>, OutputError> {
        if self.env.samples == 0 {
            return Ok(None);
        }
        let p = out_dir.join(JOINT_ENVELOPE_FILE);
        let text = serde_json::to_string(&self.env).map_err(|e| OutputError::write(&p, e))?;
        crate::files::write_whole(&p, text.as_bytes()).map_err(|(q, m)| OutputError::write(q, m))?;
        Ok(Some(p))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn env(opening: Vec<f64>) -> JointEnvelope {
        JointEnvelope { samples: 1, t_last: 0.0, joints: vec![JointNodeEnvelope { joint: "J01".into(), points: vec![[0.0; 3]; 2], max_opening: opening, max_net_slip: vec![0.0; 2] }] }
    }

    #[test]
    fn a_damaged_joint_envelope_is_an_error_naming_the_joint() {
        let dir = std::env::temp_dir().join(format!("jq_joint_env_{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join(JOINT_ENVELOPE_FILE);
        std::fs::write(&p, serde_json::to_string(&env(vec![1e-3, 2e-3])).unwrap()).unwrap();
        assert_eq!(JointEnvelope::read(&dir).unwrap(), env(vec![1e-3, 2e-3]));
        std::fs::write(&p, serde_json::to_string(&env(vec![1e-3])).unwrap()).unwrap();
        let e = JointEnvelope::read(&dir).unwrap_err().to_string();
        assert!(e.contains("J01") && e.contains("2 nodes"), "{e}");
        std::fs::write(&p, serde_json::to_string(&env(vec![1e-3, -1.0])).unwrap()).unwrap();
        let e = JointEnvelope::read(&p).unwrap_err().to_string();
        assert!(e.contains("J01") && e.contains("-1"), "{e}");
        std::fs::remove_dir_all(&dir).ok();
    }
}
