//! Dual mortar geometry (segment-to-segment contact; Wohlmuth 2000; Popp, Gee & Wall 2009,
//! 2010): pure kernels, no mesh, no state.
//!
//! Owns: the slave face's **dual shape functions** Φ_j ([`dual`]), the **clipping** of a
//! master face against a slave face in the slave face's auxiliary plane ([`clip`]), and the
//! **overlap quadrature** that gives a (slave face, master face) pair's contribution to the
//! mortar integrals ([`segment`]).
//!
//! Inputs: the node positions of one slave face and one master face (m), tri3 or quad4, in
//! Gmsh (outward) order. Outputs: [`segment::Overlap`]: per slave face node j,
//! `D_j = ∫ Φ_j dA` (m²) and per master face node k, `M_jk = ∫ Φ_j N_k dA` (m²), integrated
//! over the overlap; `None` when the faces do not overlap.
//!
//! # Conventions (written once, used by the mortar files)
//!
//! - **Auxiliary plane** of a slave face: through its centre `x_c` (the mean of its nodes),
//!   normal `n_0` = the face's unit outward normal at the centre (for a quad the cross product
//!   of its diagonals, as the tagger's, design §3), with the in-plane axes of
//!   [`super::query::tangent_frame`]. Slave and master nodes are projected on it orthogonally;
//!   the overlap is the intersection of the two projected polygons (Sutherland–Hodgman).
//! - **Dual basis**: `Φ_j = Σ_l A_jl N_l` on each slave face, `A = D_e M_e⁻¹` with
//!   `D_e = diag(∫_e N_j)`, `(M_e)_jl = ∫_e N_j N_l` over the whole face, so that
//!   `∫_e Φ_j N_l = δ_jl ∫_e N_j` (biorthogonality). On a fully covered slave face
//!   `Σ_seg ∫ Φ_j = ∫_e N_j`; the solver takes `D_jj = Σ_seg ∫ Φ_j` (the row sum of M, since the
//!   master shape functions sum to one), so that a slave node's master weights `M_jk / D_jj` sum
//!   to one exactly and the contact force conserves momentum on partly covered faces too.
//! - **Quadrature**: each overlap polygon (convex) is cut into a fan of triangles from its first
//!   vertex, each integrated with the 7-point degree-5 rule of Dunavant (1985). On a flat slave
//!   face and a master face that are parallelograms (or triangles), Φ_j N_k is a polynomial of
//!   degree ≤ 4 in the plane, integrated exactly; when either is a quad of another shape, each
//!   fan triangle is cut into 6² sub-triangles first (`segment::SUBDIVISIONS`). The area element is the slave face's
//!   (`|x_ξ × x_η| / |n_0 · (x_ξ × x_η)|` times the plane's; 1 on a flat face).
//!
//! Invariants: `Σ_k M_jk = D_j` to round-off for every overlap; the integrals of a face pair do
//! not depend on the order in which pairs are visited.

pub mod clip;
pub mod dual;
pub mod segment;

pub use segment::{overlap_integrals, Overlap, SlaveFace};
