//! # jointquake
//!
//! From Gmsh geometry to an earthquake simulation of jointed structures (rock wedges,
//! arch dams with contraction joints) with sliding and opening joints, and on to
//! ParaView series, CSV histories and charts.
//!
//! ```text
//! geo/*.geo --gmsh--> .msh --mesh--> Mesh --interface (tagger)--> joints: slave normals, Layer1/Layer2, NTN
//!     --model--> Model (elements, lumped mass, BCs; built once, immutable)
//!     --dynamics--> State (u, u_prev, contact history) stepped by ExplicitSolver (scratch only)
//!     --output--> out/<scene>/ frames/*.vtu, <scene>.pvd, histories/*.csv, summary.json --report--> charts
//! ```
//!
//! Units: SI throughout (m, kg, s, Pa, N); records are read in g and converted to m/s² once,
//! in [`dynamics::record`]. Axes: x east, y north, z up.
//!
//! Where each convention lives:
//! - node order of cells, outward face order: [`mesh::cell`]
//! - scene fields, units and defaults: [`scene`] (and `docs/scenes.md`)
//! - time integration, damping, stable step: [`dynamics`]
//! - errors (what the user must fix): [`error`]
//! - charts (PNG + SVG) and Markdown tables for study reports: [`report`]
//!
//! [`pipeline::run`] is the recipe: the only function that sequences the stages.

pub mod constraint;
pub mod contact;
pub mod dynamics;
pub mod error;
pub mod foundation;
pub mod gmsh;
pub mod interface;
pub mod linalg;
pub mod mesh;
pub mod modes;
pub mod model;
pub mod output;
pub mod pipeline;
pub mod problem;
pub mod report;
pub mod reservoir;
pub mod rigid;
pub mod scene;
pub mod simulation;
pub mod study;
pub mod vtk;

pub use error::{Error, Result};
