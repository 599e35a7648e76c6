//! Studies: procedures that run a model many times (strength reduction, parameter sweeps) and
//! the wedge study of the seed paper. Owns no physics of its own: it varies scenes and calls the
//! pipeline stages.

pub mod rigid_level;
pub mod ssr;
pub mod wedge;
pub mod wedge_report;
