//! Contact between the two sides of a joint: the pure kernels (design.md §5).
//!
//! Owns: the local search geometry ([`query`]: where the line from a slave node along its
//! normal meets a master face, and whether it lands inside) and the per-pair contact law
//! ([`law`]: the dynamic contact force of one pair in its local frame, Mohr-Coulomb with
//! cohesion, tension and tied joints), and the dual mortar geometry ([`mortar`]: dual shape
//! functions, overlap clipping and quadrature, whose integrals make a mortar slave node's
//! master weights). All are pure functions of their arguments: no mesh,
//! no state, no allocation. Geometry is kept apart from mechanics: a query says *where*
//! a slave node lands on the master surface; the law says *what force* the pair carries.
//!
//! Inputs: positions (m), the slave node's unit outward normal, trial gaps and trial
//! relative displacement increments (m), `dt² w` (m/N), tributary areas (m²).
//! Outputs: [`query::Projection`] (point, gap, local coordinates, shape-function weights,
//! where on the face it landed) or `None` for "no contact"; [`law::PairResponse`]
//! (force components, state, updated history).
//!
//! # Conventions (written once, used by every contact file)
//!
//! - **Normal** `n`: the slave node's outward unit normal, pointing *out of the slave block,
//!   towards the master*. It is both the projection direction of the local search and the
//!   direction of the normal contact force.
//! - **Local frame** `(n, t1, t2)`: right-handed and orthonormal; `t1`, `t2` span the tangent
//!   plane. Tangential quantities are 2-vectors of their `(t1, t2)` components.
//! - **Master point** `x̄ = x_s + t n`: where the line from the slave node `x_s` along `n` meets
//!   the master face; `x̄ = Σ N_I x_I` with the face's shape functions `N_I` at the local
//!   coordinates `(ξ1, ξ2)`.
//! - **Gap** `g = n · (x̄ − x_s)` (m): positive = open, negative = penetration. With a unit `n`
//!   it equals the signed distance `t` along `n`.
//! - **Relative displacement** `d = u_s − Σ N_I u_I`, so `g = g₀ − n · d` for a fixed frame.
//! - **Forces**: the pair force `R` acts as `+R` on the slave node and `−N_I R` on each master
//!   node `I`. In the local frame `R = −r_n n + r_t[0] t1 + r_t[1] t2`: `r_n` is the
//!   **compressive** normal force magnitude (N, `r_n > 0` pushes the slave back out of the
//!   master; `r_n < 0` is tension, only in bonded pairs), and `r_t` are the tangential
//!   components of the force on the slave (N).
//! - **Pair compliance** `dt² w` with `w = 1/m_s + Σ N_I² / m_I` (1/kg): a force `R` on the pair
//!   changes its relative displacement at the end of the step by `dt² w R`.
//!
//! A lost slave node (no master face found) is classified by [`free_edge`]: beyond the master's
//! free edge (expected when a block slides out) or lost inside its outline.
//!
//! Invariants: a query returns exactly one face per slave node or `None`, the same whatever
//! the order of the candidates; a law response closes the trial gap exactly in compression and
//! never exceeds the Mohr-Coulomb limit in shear.

pub mod force;
pub mod free_edge;
pub mod joint;
pub mod law;
pub mod mortar;
pub mod query;
pub mod state;

pub use state::ContactState;
