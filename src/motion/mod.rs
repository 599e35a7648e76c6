//! Ground motions: response spectra, intensity measures, baseline correction, target spectra
//! and spectrum-compatible synthesis (docs/motion.md).
//!
//! Owns: the motion stage a dam engineer would otherwise do in a separate tool. Inputs are plain
//! uniformly sampled acceleration arrays (`dt` [s], values in m/s² unless a function says g) so
//! that this module depends on no other stage (it sits below `dynamics`, which reads records and
//! calls it, and above `report`, whose charts it uses). Outputs: spectra, measures, corrected or
//! synthetic arrays, two-column files (t [s], a [g]) and charts.
//!
//! Conventions, written once here:
//! - acceleration in m/s² inside the library, g only in files and target spectra (Sa in g);
//! - the input between samples is linear (the Nigam–Jennings and the integration reading of a
//!   record; `dynamics::record::Record::at` interpolates the same way) and zero after
//!   the last sample;
//! - integration starts at rest (v = d = 0 at the first sample);
//! - spectra are 5 %-damped pseudo-accelerations PSA = ω² max|u| unless a damping is given;
//! - nothing is corrected silently: every correction is a [`baseline::Baseline`] the caller
//!   passes, and [`baseline::Drift`] reports what is left.

pub mod baseline;
pub mod chart;
pub mod column;
pub mod commands;
pub mod io;
pub mod measures;
pub mod spectrum;
pub mod synth;
pub mod target;

pub use baseline::{Baseline, Drift, correct, drift};
pub use measures::{IntensityMeasures, integrate, intensity_measures};
pub use spectrum::{log_periods, response_spectrum};
pub use synth::{Envelope, MatchCheck, SynthComponent, SynthRequest, SynthSet, match_record, synthesize_set};
pub use target::{TargetSpec, TargetSpectrum};

use std::path::PathBuf;
use thiserror::Error;

/// Failures of the motion stage; each names the field (or file and line) to fix.
#[derive(Debug, Error)]
pub enum MotionError {
    /// A parameter or a table entry that cannot be used.
    #[error("{field}: {message}")]
    Invalid { field: String, message: String },
    #[error("cannot read {path}: {source}")]
    Io { path: PathBuf, source: std::io::Error },
    #[error("cannot write {path}: {source}")]
    Write { path: PathBuf, source: std::io::Error },
    /// The synthesis or the matching did not reach the tolerance: never silently accepted.
    #[error("{0}")]
    NotMatched(String),
    #[error(transparent)]
    Report(#[from] crate::error::ReportError),
}

impl MotionError {
    pub(crate) fn invalid(field: impl Into<String>, message: impl Into<String>) -> MotionError {
        MotionError::Invalid { field: field.into(), message: message.into() }
    }
}

/// Standard gravity used where the motion stage converts g (the scene's `g` overrides it there).
pub const G_STANDARD: f64 = 9.81;
