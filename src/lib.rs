//! # jointquake
//!
//! From Gmsh geometry to an earthquake simulation of jointed structures (rock wedges,
//! arch dams with contraction joints) with sliding and opening joints, and on to
//! ParaView series, CSV histories and charts.
//!
//! ```text
//! geo/*.geo --gmsh--> .msh --pipeline::load_scene_mesh--> Mesh (+ the scene's group patterns
//!   expanded) --Problem::build--> Problem {
//!     model   (elements, NodalMass: inertia vs weight, supports; built once, immutable)
//!     joints  (their own stage: tagged once by interface/, laws, frames)
//!     loads   (gravity, base records, tractions, the reservoir's hydrostatic forces) }
//!   --Simulation::new(&problem)--> .equilibrate() (the one door to the static state: the
//!       scene's equilibrium.sequence, construction stages in statics/) --> .run(&mut recorder)
//!       State (t, u[n], u[n−1], energy, contact history) stepped by ExplicitSolver (scratch
//!       only); after each prediction the step calls its constraints (constraint.rs: contact)
//!   --Recorder (output/)--> out/<scene>/ frames/*.vtu, <scene>.pvd, joints/, histories/*.csv,
//!       summary.json (RunSummary, read back by RunSummary::read) --report--> charts
//! ```
//!
//! Units: SI throughout (m, kg, s, Pa, N); records are read in g and converted to m/s² once,
//! in [`dynamics::record`]. Axes: x east, y north, z up.
//!
//! Where each convention lives:
//! - node order of cells, outward face order: [`mesh::cell`]
//! - scene fields, units and defaults, and the rules checked once (friction μ or φ, time-step
//!   knobs, contact method enums): [`scene`] (and `docs/scenes.md`)
//! - time integration, damping: [`dynamics`]; the one time-step rule: [`dynamics::time`]
//! - masses (inertial vs gravitational, 3×3 inertia blocks, massless nodes): [`model::mass`]; selective mass scaling: [`model::mass_scaling`]
//! - contact conventions (normal, gap sign, frame, forces): [`contact`]; the contact mobility of
//!   an anisotropic mass: `docs/contact.md`
//! - the face-integration kernel (nodal weights of a tri3/quad4 face, for the tagger, the
//!   tractions and the reservoir): [`interface::face_nodal_weights_into`]
//! - errors (what the user must fix): [`error`]
//! - charts (PNG + SVG) and Markdown tables for study reports: [`report`]
//! - study files, run ids, the results layout: [`study`] (and `docs/studies.md`); what each
//!   study adds (metrics, tables, charts): [`studies`]
//!
//! [`pipeline::run`] is the recipe: the only function that sequences the stages, through the
//! run object [`simulation::Simulation`], which strength reduction, the tests and the benchmarks
//! drive too. Every module, its job and what it may import, and the rules written once:
//! `docs/architecture.md` (a test keeps its module list true); dependencies point down (no
//! import loop; `make test` checks it).

pub mod constraint;
pub mod contact;
pub mod dynamics;
pub mod error;
pub mod files;
pub mod gmsh;
pub mod interface;
pub mod interrupt;
pub mod linalg;
pub mod mesh;
pub mod model;
pub mod motion;
pub mod output;
pub mod par;
pub mod pipeline;
pub mod problem;
pub mod report;
pub mod rigid;
pub mod scene;
pub mod simulation;
pub mod statics;
pub mod studies;
pub mod study;
pub mod testcase;
pub mod vtk;

pub use error::{Error, Result};
