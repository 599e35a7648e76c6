//! The model: built once from the mesh and the scene, never mutated during a run.
//!
//! Owns: materials per volume group, element data (tet4 geometry, shared hex8 shapes),
//! nodal masses ([`mass`]: inertia and weight apart), fixed components, and the element
//! colouring used for deterministic parallel assembly. Joints are not part of the model: they
//! are their own stage (`contact::joint::build_joints`), built once from the tagger.
//! Inputs: [`Mesh`], scene materials and boundary conditions.
//! Outputs: `K u` ([`Model::internal_forces_into`]), element stresses, the stable step.
//!
//! Invariants:
//! - Degrees of freedom are `3 * node + component` (x, y, z), for every mesh node; nodes in no
//!   material volume are inactive and treated as fixed. Nodes of massless elements (ρ = 0) are
//!   active but have no inertia: the explicit step leaves them to a constraint ([`Model::held`]).
//! - Elements are stored in assembly order ([`Schedule`]): sorted along a Morton (Z-order)
//!   curve of their centroids, cut into chunks of consecutive elements, and the chunks grouped
//!   by colour (no two chunks of one colour share a node). One thread runs the chunks in
//!   storage order; more threads run a chunk as soon as the chunks before it that share one of
//!   its nodes are done ([`ChunkGraph`]), each chunk's elements in order on one thread; the sum
//!   order at every node is then the storage order whatever the number of threads
//!   (bit-identical results). A chunk's nodes stay in cache while it is
//!   assembled, so a step streams the nodal vectors about once instead of once per colour.
//! - Sign: `internal_forces_into` gives f_int = K u; the equation of motion is
//!   M ü + C u̇ + f_int = F_ext + R.

pub mod hex8;
pub mod mass;
pub mod mass_scaling;
pub mod material;
pub mod tet4;

use crate::error::{MeshError, ModelError};
use crate::mesh::{CellKind, Mesh};
use crate::scene::Scene;
use hex8::HexShape;
use mass::NodalMass;
use mass_scaling::MassScaling;
use material::{Lame, Material};
use nalgebra::Vector3;
use rayon::prelude::*;
use std::collections::HashMap;
use std::ops::Range;
use std::sync::atomic::{AtomicU32, Ordering};

/// Assembly order of the elements of one kind: chunks of consecutive elements, grouped by colour.
#[derive(Clone, Debug, Default)]
pub struct Schedule {
    /// Element ranges of the chunks, in storage order (the chunks cover all elements).
    pub chunks: Vec<Range<usize>>,
    /// Ranges of `chunks` per colour: no two chunks of one colour share a node.
    pub colors: Vec<Range<usize>>,
    /// The distinct nodes of each chunk, ascending: chunk k's are
    /// `chunk_nodes[chunk_node_start[k]..chunk_node_start[k + 1]]`.
    pub chunk_nodes: Vec<u32>,
    pub chunk_node_start: Vec<usize>,
}

/// Tetrahedra, in assembly order ([`Schedule`]).
#[derive(Clone, Debug, Default)]
pub struct Tet4Set {
    pub nodes: Vec<[u32; 4]>,
    pub geom: Vec<tet4::TetGeom>,
    pub mat: Vec<u16>,
    /// Mesh cell index of each element.
    pub cell: Vec<u32>,
    pub schedule: Schedule,
}

/// Hexahedra, in assembly order ([`Schedule`]); congruent elements share a [`HexShape`].
#[derive(Clone, Debug, Default)]
pub struct Hex8Set {
    pub nodes: Vec<[u32; 8]>,
    pub shape: Vec<u32>,
    pub mat: Vec<u16>,
    pub cell: Vec<u32>,
    pub schedule: Schedule,
    pub shapes: Vec<HexShape>,
}

/// The critical element of the stable-step estimate.
#[derive(Clone, Debug)]
pub struct CriticalElement {
    /// Gmsh element tag.
    pub tag: u64,
    pub group: String,
    /// Largest element eigenvalue ω² [1/s²].
    pub omega2: f64,
    /// Its shape quality: the scaled Jacobian ([`crate::mesh::quality`]; 1 for a regular tet
    /// or a cube, about 0 for a sliver, below [`crate::mesh::quality::SLIVER_SCALED_JACOBIAN`]
    /// the run warns).
    pub scaled_jacobian: f64,
    /// The Rayleigh pair of its elements (α [1/s], β [s]): the scene's, or the rock's own
    /// ([`Model::damping_of_material`]); the stable step is its damped step.
    pub alpha: f64,
    pub beta: f64,
    /// Its element step 2/ω over the mean element step of its block (the elements of its
    /// material group): how much smaller than the block's typical element's its step is (1 when
    /// every element of the block is alike).
    pub step_ratio: f64,
    /// The factor its density was scaled by for its inertia (`time.mass_scaling`; 1 unscaled).
    /// Above 1, its step is the scaling's target, not its shape's.
    pub mass_factor: f64,
}

impl CriticalElement {
    /// Whether the element setting the step is a sliver (scaled Jacobian below
    /// [`crate::mesh::quality::SLIVER_SCALED_JACOBIAN`]).
    pub fn is_sliver(&self) -> bool {
        self.omega2 > 0.0 && self.scaled_jacobian < crate::mesh::quality::SLIVER_SCALED_JACOBIAN
    }
}

/// The rock's own Rayleigh pair (issue 29 §3; docs/dam_physics.md "Foundation models").
#[derive(Clone, Debug)]
pub struct RockRayleigh {
    /// α [1/s] on the rock's nodes (those of no mass-damped group of the scene's) and β [s] on
    /// the rock's elements.
    pub alpha: f64,
    pub beta: f64,
    /// Per material: a rock material (its elements carry this pair).
    pub material: Vec<bool>,
}

/// Everything that does not change during a run.
#[derive(Debug)]
pub struct Model {
    pub mesh: Mesh,
    pub materials: Vec<Material>,
    pub tets: Tet4Set,
    pub hexes: Hex8Set,
    /// Which element chunk must wait for which ([`ChunkGraph`]): the element loop's order on
    /// more than one thread.
    pub chunk_graph: ChunkGraph,
    /// Inertial and gravitational mass per node ([`mass`]).
    pub mass: NodalMass,
    /// Fixed components per node: bit 0 = x, 1 = y, 2 = z. Inactive nodes are fully fixed.
    pub fixed: Vec<u8>,
    /// Components the explicit step does not integrate (u[n+1] = 0 in the prediction): the fixed
    /// ones, and all three of a node without inertia (set by a constraint instead).
    pub held: Vec<u8>,
    /// The scene's Rayleigh damping C = αM + βK: α [1/s], β [s]: every element's, unless the
    /// rock has its own pair ([`Model::rock_damping`]).
    pub alpha: f64,
    /// Per node: α [1/s] of the mass-proportional term αM in the dynamic stage
    /// ([`node_alphas`]: the scene's α on the nodes of `damping.mass_groups`, all by default;
    /// the rock's own α on the rock's other nodes). Relaxation damping applies to every node
    /// regardless.
    pub node_alpha: Vec<f64>,
    pub beta: f64,
    /// The rock's own Rayleigh pair (scene `foundation.damping` given as a pair; issue 29 §3);
    /// `None`: every element has the scene's (α, β).
    pub rock_damping: Option<RockRayleigh>,
    pub critical: CriticalElement,
    /// Per material: a massless block (stiffness only; the foundation module condenses it).
    pub massless: Vec<bool>,
    /// Per node: the components condensed statically (nodes of massless blocks without mass,
    /// components not fixed by the boundary conditions); such nodes are also in `fixed` (7), so
    /// the explicit update leaves them to the condensation. 0 elsewhere.
    pub condensed: Vec<u8>,
    /// Per mesh cell: an element of a massless block (not of its layer along a joint): stiffness
    /// only, no mass, no stable step.
    pub massless_cells: Vec<bool>,
    /// Per node: carries mass but no weight (its mass comes only from the layer of a massless
    /// block's elements along a joint face: docs/dam_physics.md).
    pub weightless: Vec<bool>,
    /// Per mesh cell: the factor its density was scaled by for the inertial mass (scene
    /// `time.mass_scaling`; [`mass_scaling`]); empty when no element is scaled (every factor 1).
    pub mass_scale: Vec<f64>,
    /// What the mass scaling did (`None` without `time.mass_scaling`).
    pub mass_scaling: Option<MassScaling>,
}

/// Scatter target shared across threads. Safe use requires that no two concurrent writers touch
/// the same index: guaranteed by the colouring (see the module invariants).
#[derive(Clone, Copy)]
struct SharedMut(*mut f64);
unsafe impl Send for SharedMut {}
unsafe impl Sync for SharedMut {}

/// Entries per parallel task when zeroing the force vector. Default 16384 (128 kB of f64);
/// vectors shorter than 4 blocks are zeroed on the calling thread (cheaper than waking others).
const NODAL_BLOCK: usize = 16384;

/// Elements of a model below which its element loop runs on one thread. Default 512: below
/// that the whole loop (≈ 10 µs for tet4) costs about as much as waking the other threads.
const PAR_MIN: usize = 512;

/// Largest chunk [elements]. Default 2048: the u and f_int entries of a chunk's nodes
/// (≈ 2500 nodes × 48 B = 120 kB for hex8, ≈ 450 nodes for tet4) stay in the L2 cache while
/// the chunk is assembled, and the element data streams past.
const CHUNK_MAX: usize = 2048;
/// Smallest chunk [elements]. Default 160: smaller chunks share more of their nodes with their
/// neighbours (the nodal data is fetched more often) and need more colours (measured on the
/// 10⁴-element tet4 box: 8 colours with chunks of 162 elements, 15 with chunks of 64, and two
/// threads gained 1.3× against 1.15×).
const CHUNK_MIN: usize = 160;
/// Chunks a mesh is cut into when that gives chunks between [`CHUNK_MIN`] and [`CHUNK_MAX`]
/// elements. Default 256: enough chunks per colour (8–16 colours) for the threads to share
/// evenly (measured on the 10⁵-element tet4 box: 64 chunks gave two threads 1.2×, 256 chunks
/// 1.5–1.6×). Depends only on the element count, never on the thread count (results must not
/// depend on the number of threads).
const CHUNK_COUNT: usize = 256;

/// Spread the low 21 bits of `v` to every third bit (Morton interleaving).
fn spread_bits3(v: u64) -> u64 {
    let mut x = v & 0x1f_ffff;
    x = (x | x << 32) & 0x001f_0000_0000_ffff;
    x = (x | x << 16) & 0x001f_0000_ff00_00ff;
    x = (x | x << 8) & 0x100f_00f0_0f00_f00f;
    x = (x | x << 4) & 0x10c3_0c30_c30c_30c3;
    x = (x | x << 2) & 0x1249_2492_4924_9249;
    x
}

/// Morton (Z-order) keys of the element centroids, on a 2²¹ grid over their bounding box.
fn morton_keys<const N: usize>(conn: &[[u32; N]], x: &[[f64; 3]]) -> Vec<u64> {
    let centroid = |c: &[u32; N]| -> [f64; 3] {
        let mut s = [0.0; 3];
        for &n in c {
            for i in 0..3 {
                s[i] += x[n as usize][i];
            }
        }
        s.map(|v| v / N as f64)
    };
    let (lo, hi) = conn.iter().fold(([f64::MAX; 3], [f64::MIN; 3]), |(mut lo, mut hi), c| {
        let p = centroid(c);
        for i in 0..3 {
            lo[i] = lo[i].min(p[i]);
            hi[i] = hi[i].max(p[i]);
        }
        (lo, hi)
    });
    let ext = (0..3).map(|i| hi[i] - lo[i]).fold(0.0f64, f64::max);
    let scale = if ext > 0.0 { ((1u64 << 21) - 1) as f64 / ext } else { 0.0 };
    conn.iter()
        .map(|c| {
            let p = centroid(c);
            (0..3).fold(0u64, |k, i| k | spread_bits3(((p[i] - lo[i]) * scale) as u64) << i)
        })
        .collect()
}

/// Assembly order of elements with connectivity `conn` (see [`Schedule`]): the permutation
/// (storage position → input index) and the schedule in storage positions.
fn assembly_order<const N: usize>(conn: &[[u32; N]], x: &[[f64; 3]]) -> Result<(Vec<u32>, Schedule), ModelError> {
    let n = conn.len();
    if n == 0 {
        return Ok((Vec::new(), Schedule::default()));
    }
    let keys = morton_keys(conn, x);
    let mut curve: Vec<u32> = (0..n as u32).collect();
    curve.sort_unstable_by_key(|&e| (keys[e as usize], e));
    drop(keys);
    let len = (n / CHUNK_COUNT).clamp(CHUNK_MIN, CHUNK_MAX);
    let n_chunks = n.div_ceil(len);
    // greedy colouring of the chunks (a chunk takes the lowest colour none of its nodes has)
    let mut used = vec![0u128; x.len()];
    let mut color = vec![0u8; n_chunks];
    let mut ncolors = 0;
    for k in 0..n_chunks {
        let members = &curve[k * len..((k + 1) * len).min(n)];
        let mask = members.iter().flat_map(|&e| conn[e as usize].iter()).fold(0u128, |m, &v| m | used[v as usize]);
        let c = mask.trailing_ones();
        if c >= 128 {
            return Err(ModelError::Invalid(format!(
                "element colouring needs more than 128 colours (chunk {k} of {len} elements): a node has too many elements"
            )));
        }
        color[k] = c as u8;
        ncolors = ncolors.max(c as usize + 1);
        for &e in members {
            for &v in &conn[e as usize] {
                used[v as usize] |= 1u128 << c;
            }
        }
    }
    drop(used);
    let mut by_color: Vec<usize> = (0..n_chunks).collect();
    by_color.sort_by_key(|&k| (color[k], k));
    let mut order = Vec::with_capacity(n);
    let mut chunks = Vec::with_capacity(n_chunks);
    let mut colors = Vec::with_capacity(ncolors);
    let mut first = 0;
    for (i, &k) in by_color.iter().enumerate() {
        if i > 0 && color[k] != color[by_color[i - 1]] {
            colors.push(first..i);
            first = i;
        }
        let start = order.len();
        order.extend_from_slice(&curve[k * len..((k + 1) * len).min(n)]);
        chunks.push(start..order.len());
    }
    colors.push(first..n_chunks);
    let mut chunk_nodes = Vec::new();
    let mut chunk_node_start = vec![0];
    for r in &chunks {
        let start = chunk_nodes.len();
        chunk_nodes.extend(order[r.clone()].iter().flat_map(|&e| conn[e as usize]));
        chunk_nodes[start..].sort_unstable();
        let mut w = start;
        for i in start..chunk_nodes.len() {
            if i == start || chunk_nodes[i] != chunk_nodes[w - 1] {
                chunk_nodes[w] = chunk_nodes[i];
                w += 1;
            }
        }
        chunk_nodes.truncate(w);
        chunk_node_start.push(w);
    }
    chunk_nodes.shrink_to_fit();
    Ok((order, Schedule { chunks, colors, chunk_nodes, chunk_node_start }))
}

fn permute<T: Clone>(v: &[T], order: &[u32]) -> Vec<T> {
    order.iter().map(|&i| v[i as usize].clone()).collect()
}

impl Schedule {
    /// Chunk `k`: `warm(nodes)` on its distinct nodes (ascending), then `body(e)` for its
    /// elements in storage order. The warm-up is independent loads that bring the chunk's nodal
    /// data into cache at full memory parallelism, before the element loop's gathers, which wait
    /// on each other through the scatter (measured: about 10 % faster at 10⁶ elements, where the
    /// nodal vectors do not fit in cache).
    fn run_chunk(&self, k: usize, warm: &impl Fn(&[u32]), body: &impl Fn(usize)) {
        warm(&self.chunk_nodes[self.chunk_node_start[k]..self.chunk_node_start[k + 1]]);
        self.chunks[k].clone().for_each(body)
    }
}

/// The order the element loop keeps on more than one thread: the chunks of the element kinds'
/// [`Schedule`]s numbered in the one-thread order (the tets' chunks colour by colour, then the
/// hexes'), and an edge from chunk i to chunk j > i when j is the next chunk after i to touch
/// one of i's nodes. So the chunks that touch a node form a chain of edges in the one-thread
/// order: two of them never run at the same time, and every node sums its elements' forces in
/// the order of one thread (bit-identical results on any number of threads). A chunk starts as
/// soon as its predecessors are done, not when a whole colour is: the loop is one parallel
/// region (one fork-join a step instead of one per colour), and a thread that finishes its
/// last chunk of a colour takes a ready chunk of the next colour instead of waiting for the
/// other thread.
#[derive(Clone, Debug, Default)]
pub struct ChunkGraph {
    /// Per chunk, its number of predecessors.
    preds: Vec<u32>,
    /// Chunk k's successors: `succ[succ_start[k]..succ_start[k + 1]]`, ascending.
    succ_start: Vec<usize>,
    succ: Vec<u32>,
    /// The chunks without predecessors, ascending.
    roots: Vec<u32>,
}

impl ChunkGraph {
    /// The graph of the schedules' chunks in that order (`nodes`: the mesh's node count).
    fn new(schedules: &[&Schedule], nodes: usize) -> ChunkGraph {
        let total: usize = schedules.iter().map(|s| s.chunks.len()).sum();
        let mut last = vec![u32::MAX; nodes];
        let mut edges: Vec<(u32, u32)> = Vec::new();
        let mut k = 0u32;
        for s in schedules {
            for c in 0..s.chunks.len() {
                for &v in &s.chunk_nodes[s.chunk_node_start[c]..s.chunk_node_start[c + 1]] {
                    let prev = std::mem::replace(&mut last[v as usize], k);
                    if prev != u32::MAX {
                        edges.push((prev, k));
                    }
                }
                k += 1;
            }
        }
        edges.sort_unstable();
        edges.dedup();
        let mut preds = vec![0u32; total];
        let mut succ_start = vec![0usize; total + 1];
        for &(i, j) in &edges {
            preds[j as usize] += 1;
            succ_start[i as usize + 1] += 1;
        }
        for i in 0..total {
            succ_start[i + 1] += succ_start[i];
        }
        let succ = edges.iter().map(|&(_, j)| j).collect();
        let roots = (0..total as u32).filter(|&j| preds[j as usize] == 0).collect();
        ChunkGraph { preds, succ_start, succ, roots }
    }

    /// Chunks in the graph.
    pub fn len(&self) -> usize {
        self.preds.len()
    }

    pub fn is_empty(&self) -> bool {
        self.preds.is_empty()
    }

    /// Chunk `k`'s successors, ascending.
    pub fn successors(&self, k: usize) -> &[u32] {
        &self.succ[self.succ_start[k]..self.succ_start[k + 1]]
    }

    /// Chunk `k`'s number of predecessors.
    pub fn predecessors(&self, k: usize) -> u32 {
        self.preds[k]
    }

    /// `run(k)` for every chunk `k`, each after its predecessors, on the threads of rayon's
    /// pool: one parallel region. A chunk that completes a successor's predecessors runs it
    /// next on its own thread (the first such; the others are spawned for any thread to take).
    fn run_all(&self, run: &(impl Fn(usize) + Sync)) {
        let pending: Vec<AtomicU32> = self.preds.iter().map(|&p| AtomicU32::new(p)).collect();
        let pending = &pending[..];
        crate::par::region();
        rayon::scope(|s| {
            for &r in &self.roots {
                s.spawn(move |s| self.run_from(s, pending, run, r as usize));
            }
        });
    }

    /// Run chunk `k`, then the successors it makes ready (see [`ChunkGraph::run_all`]).
    fn run_from<'s>(&'s self, s: &rayon::Scope<'s>, pending: &'s [AtomicU32], run: &'s (impl Fn(usize) + Sync), mut k: usize) {
        loop {
            run(k);
            let mut next = None;
            for &j in self.successors(k) {
                // AcqRel: the thread that takes j sees the writes of all of j's predecessors
                if pending[j as usize].fetch_sub(1, Ordering::AcqRel) == 1 {
                    if let Some(other) = next.replace(j) {
                        s.spawn(move |s| self.run_from(s, pending, run, other as usize));
                    }
                }
            }
            match next {
                Some(j) => k = j as usize,
                None => return,
            }
        }
    }
}

impl Model {
    /// Build the model: materials, elements, masses, fixed components, stable-step data. The
    /// steps, in order: the material of every cell ([`material_owners`]), the nodes of the joint
    /// faces (the massive layer of a massless block, [`joint_face_nodes`]), the elements and
    /// their lumped masses in cell order ([`ElementScan`]), the assembly order
    /// ([`ElementScan::take_sets`]), the supports ([`supports`]), the mass-scaling summary
    /// ([`mass_scaling_summary`]), the nodes' αM ([`node_alphas`]), then the critical element.
    pub fn build(mesh: Mesh, scene: &Scene) -> Result<Model, crate::Error> {
        let n = mesh.nodes.len();
        let (materials, owner) = material_owners(&mesh, scene)?;
        let (alpha, beta) = scene.damping.coefficients().map_err(ModelError::Invalid)?;
        let rock_damping = rock_rayleigh(scene)?;
        let pair_of = |mi: usize| match &rock_damping {
            Some(r) if r.material[mi] => (r.alpha, r.beta),
            _ => (alpha, beta),
        };
        // mass scaling (scene time.mass_scaling): the element ω² above which an element's density
        // is scaled, its factor per mesh cell, and the scaled (inertial) nodal masses; `mass`
        // stays the unscaled one (the weight)
        // (per material: its Rayleigh pair's)
        let target_w2: Option<Vec<f64>> = match &scene.time.mass_scaling {
            Some(ms) => Some(
                (0..scene.materials.len())
                    .map(|mi| {
                        let (a, b) = pair_of(mi);
                        mass_scaling::target_omega2(ms.target_dt / scene.time.courant_or_default(), a, b)
                    })
                    .collect::<Result<_, _>>()
                    .map_err(ModelError::Invalid)?,
            ),
            None => None,
        };
        let massless: Vec<bool> = scene.materials.iter().map(|m| m.massless).collect();
        let joint_node = joint_face_nodes(&mesh, scene, &massless)?;
        let mut scan = ElementScan::new(n, mesh.cells.len(), target_w2.is_some());
        for (c, &mi) in owner.iter().enumerate() {
            if mi != u32::MAX {
                scan.add_cell(&mesh, &materials, &massless, &joint_node, target_w2.as_ref().map(|t| t[mi as usize]), c, mi as usize)?;
            }
        }
        drop(owner);
        if scan.tn.is_empty() && scan.hn.is_empty() {
            return Err(ModelError::Invalid("the material groups hold no tet4 or hex8 elements".into()).into());
        }
        let (tets, hexes) = scan.take_sets(&mesh)?;
        let ElementScan { mass, mut inertial, mut mass_scale, massive_mass, massless_cell: element_massless_cell, active, .. } = scan;
        let (fixed, condensed) = supports(&mesh, scene, &active, &mass, &element_massless_cell)?;
        if mass.iter().all(|&m| m == 0.0) {
            return Err(ModelError::Invalid("every material group is massless: nothing carries mass to integrate in time (a massless block supports a massive one)".into()).into());
        }
        let weightless: Vec<bool> = (0..n).map(|i| mass[i] > 0.0 && massive_mass[i] == 0.0).collect();
        drop(massive_mass);
        let mass_scaling = mass_scaling_summary(&mesh, scene, &mass_scale, &mass, &inertial);
        // without a scaled element the inertia is the unscaled mass (and no separate weight)
        let scaled = mass_scaling.as_ref().is_some_and(|m| m.scaled_elements > 0);
        if !scaled {
            inertial = Vec::new();
            mass_scale = Vec::new();
        }
        let node_alpha = node_alphas(&mesh, scene, alpha, rock_damping.as_ref())?;
        let held = fixed.iter().zip(&mass).map(|(&f, &m)| if m > 0.0 { f } else { 7 }).collect();
        let mut model = Model {
            mesh,
            materials,
            chunk_graph: ChunkGraph::new(&[&tets.schedule, &hexes.schedule], n),
            tets,
            hexes,
            mass: {
                // the layer of a massless block along a joint: inertia, no weight; scaled
                // elements: their weight is their unscaled mass
                let weight: Option<Vec<f64>> = (scaled || weightless.iter().any(|&w| w)).then(|| mass.iter().zip(&weightless).map(|(&m, &w)| if w { 0.0 } else { m }).collect());
                let mut m = NodalMass::lumped(if scaled { inertial } else { mass });
                if let Some(g) = weight {
                    m.set_gravitational(g);
                }
                m
            },
            fixed,
            held,
            alpha,
            node_alpha,
            beta,
            rock_damping,
            critical: CriticalElement { tag: 0, group: String::new(), omega2: 0.0, alpha, beta, scaled_jacobian: 1.0, step_ratio: 1.0, mass_factor: 1.0 },
            massless,
            massless_cells: element_massless_cell,
            condensed,
            weightless,
            mass_scale,
            mass_scaling,
        };
        model.critical = model.max_element_eigenvalue();
        Ok(model)
    }

    /// Whether the model has massless blocks to condense.
    pub fn has_massless(&self) -> bool {
        self.massless.iter().any(|&m| m)
    }

    pub fn n_nodes(&self) -> usize {
        self.mesh.nodes.len()
    }

    pub fn n_elements(&self) -> usize {
        self.tets.nodes.len() + self.hexes.nodes.len()
    }

    /// Add the symmetric inertia `a` [kg] (no weight) to `node`, e.g. a reservoir's added mass
    /// m_a n nᵀ ([`NodalMass::add_inertia`]). The stable step stays that of the elements alone:
    /// added inertia only lowers the frequencies, so the element bound remains an upper bound.
    pub fn add_inertia(&mut self, node: usize, a: nalgebra::Matrix3<f64>) {
        self.mass.add_inertia(node, a, self.fixed[node]);
        if self.held[node] == 7 && self.fixed[node] != 7 {
            self.held[node] = self.fixed[node];
        }
    }

    /// Diagonal of the size of the mesh's bounding box [m] (0 for an empty mesh).
    pub fn size(&self) -> f64 {
        self.mesh.diagonal()
    }

    /// Whether dof (node, component) is free.
    #[inline]
    pub fn is_free(&self, node: usize, comp: usize) -> bool {
        self.fixed[node] & (1 << comp) == 0
    }

    /// The element with the smallest damped step: per Rayleigh pair (the scene's, the rock's
    /// own) the element with the largest ω²_max (element eigenvalue theorem: the global ω_max is
    /// bounded by the largest element ω_max with lumped mass), and of those the one whose
    /// [`damped_step`] with its pair is smaller (the scene's on a tie; with one pair, the largest
    /// ω²_max).
    fn max_element_eigenvalue(&self) -> CriticalElement {
        let group = |mi: usize| self.rock_damping.as_ref().is_some_and(|r| r.material[mi]) as usize;
        // an element of a massless block sets no stable step (its nodes are condensed, or carry
        // the mass of other elements: the foundation's bound on them is the foundation module's);
        // its layer elements along a joint have their mass and count as usual
        let pure_massless = |cell: u32| self.massless_cells[cell as usize];
        // per tet its ω²_max (0 for a pure massless one: it sets no step)
        let tet_omega: Vec<f64> = (0..self.tets.nodes.len())
            .into_par_iter()
            .map(|e| {
                if pure_massless(self.tets.cell[e]) {
                    return 0.0;
                }
                let m = &self.materials[self.tets.mat[e] as usize];
                let g = &self.tets.geom[e];
                // a massless element (ρ = 0) sets no stable step: its nodes are condensed statically
                if m.rho > 0.0 { tet4::max_eigenvalue(&g.grad, g.vol, m.rho, &m.lame) / self.scale_of(self.tets.cell[e]) } else { 0.0 }
            })
            .collect();
        // per pair: (ω², cell, material) of its element with the largest ω²
        let mut best = [(0.0, 0, 0); 2];
        for (e, &w) in tet_omega.iter().enumerate() {
            let c = self.tets.cell[e] as usize;
            let mi = self.tets.mat[e] as usize;
            let t = &mut best[group(mi)];
            if w > t.0 || (w == t.0 && c < t.1) {
                *t = (w, c, mi);
            }
        }
        // shapes are shared: one eigenvalue per (shape), with the material of its first element
        // (a shape belongs to one material: the congruence key includes it)
        let mut shape_mat = vec![u16::MAX; self.hexes.shapes.len()];
        for (e, &si) in self.hexes.shape.iter().enumerate() {
            if shape_mat[si as usize] == u16::MAX {
                shape_mat[si as usize] = self.hexes.mat[e];
            }
        }
        let shape_omega: Vec<f64> = self
            .hexes
            .shapes
            .par_iter()
            .zip(&shape_mat)
            .map(|(s, &mi)| {
                let m = &self.materials[mi as usize];
                if m.rho > 0.0 { hex8::max_eigenvalue(s, m.rho, &m.lame) } else { 0.0 }
            })
            .collect();
        for e in 0..self.hexes.nodes.len() {
            if pure_massless(self.hexes.cell[e]) {
                continue;
            }
            let w = shape_omega[self.hexes.shape[e] as usize] / self.scale_of(self.hexes.cell[e]);
            let c = self.hexes.cell[e] as usize;
            let mi = self.hexes.mat[e] as usize;
            let b = &mut best[group(mi)];
            if w > b.0 || (w == b.0 && c < b.1) {
                *b = (w, c, mi);
            }
        }
        let step_of = |b: &(f64, usize, usize)| {
            let (a, bt) = self.damping_of_material(b.2);
            damped_step(b.0, a, bt)
        };
        let best = if best[1].0 > 0.0 && step_of(&best[1]) < step_of(&best[0]) { best[1] } else { best[0] };
        // the mean element step 2/ω of the critical element's block (its material's elements
        // that set a step)
        let (mut sum, mut count) = (0.0, 0usize);
        let mut add = |w: f64| {
            if w > 0.0 {
                sum += 2.0 / w.sqrt();
                count += 1;
            }
        };
        for (e, &w) in tet_omega.iter().enumerate() {
            if self.tets.mat[e] as usize == best.2 {
                add(w);
            }
        }
        for e in 0..self.hexes.nodes.len() {
            if self.hexes.mat[e] as usize == best.2 && !pure_massless(self.hexes.cell[e]) {
                add(shape_omega[self.hexes.shape[e] as usize] / self.scale_of(self.hexes.cell[e]));
            }
        }
        let step_ratio = if best.0 > 0.0 && count > 0 { (2.0 / best.0.sqrt()) / (sum / count as f64) } else { 1.0 };
        let scaled_jacobian = crate::mesh::quality::cell_scaled_jacobian(&self.mesh, best.1).unwrap_or(1.0);
        let mass_factor = self.scale_of(best.1 as u32);
        let (alpha, beta) = self.damping_of_material(best.2);
        CriticalElement { tag: self.mesh.cells[best.1].tag, group: self.materials[best.2].group.clone(), omega2: best.0, alpha, beta, scaled_jacobian, step_ratio, mass_factor }
    }

    /// The inertial density factor of mesh cell `cell` (1 without mass scaling).
    #[inline]
    fn scale_of(&self, cell: u32) -> f64 {
        self.mass_scale.get(cell as usize).copied().unwrap_or(1.0)
    }

    /// Stable time step [s] of the central-difference scheme with Rayleigh damping: the
    /// [`damped_step`] of the critical element with its pair. Infinite when no element has
    /// mass (nothing to integrate explicitly).
    pub fn stable_dt(&self) -> f64 {
        damped_step(self.critical.omega2, self.critical.alpha, self.critical.beta)
    }

    /// Stable step with an extra ω² bound `extra_omega2` [1/s²] added to the critical element's
    /// bound (λ_max(A + B) ≤ λ_max(A) + λ_max(B)), e.g. for penalty springs, with its pair.
    pub fn stable_dt_with(&self, extra_omega2: f64) -> f64 {
        damped_step(self.critical.omega2 + extra_omega2, self.critical.alpha, self.critical.beta)
    }

    /// (α [1/s], β [s]) of material `mi`'s elements: the rock's own pair on the rock's
    /// materials ([`Model::rock_damping`]), else the scene's.
    pub fn damping_of_material(&self, mi: usize) -> (f64, f64) {
        match &self.rock_damping {
            Some(r) if r.material[mi] => (r.alpha, r.beta),
            _ => (self.alpha, self.beta),
        }
    }

    /// Whether the elements' β differ (the rock's own β is not the scene's): the explicit step
    /// then forms βK per pair ([`Model::internal_forces_of_pair_into`]); otherwise one β,
    /// [`Model::beta`], applies everywhere.
    pub fn beta_grouped(&self) -> bool {
        self.rock_damping.as_ref().is_some_and(|r| r.beta != self.beta)
    }

    /// Whether some element carries βK.
    pub fn stiffness_damped(&self) -> bool {
        self.beta > 0.0 || self.rock_damping.as_ref().is_some_and(|r| r.beta > 0.0)
    }

    /// f = K u (f is overwritten). Deterministic whatever the thread count.
    pub fn internal_forces_into(&self, u: &[f64], f: &mut [f64]) {
        self.internal_forces_where_into::<false, 0>(u, f)
    }

    /// f = K u of the elements that carry mass: the elements of massless blocks
    /// ([`Model::massless_cells`]) left out, for a step that applies the condensed foundation's
    /// Schur complement instead (`foundation`). Same order and sums otherwise.
    pub fn internal_forces_of_massive_into(&self, u: &[f64], f: &mut [f64]) {
        self.internal_forces_where_into::<true, 0>(u, f)
    }

    /// f = K_p u of the elements of one Rayleigh pair alone (`rock`: the rock's own,
    /// [`Model::rock_damping`]; else the scene's), the elements of massless blocks left out with
    /// `skip_massless`: the step's βK per pair when the pairs' β differ
    /// ([`Model::beta_grouped`]). Same order and sums as [`Model::internal_forces_into`] on the
    /// pair's elements.
    pub fn internal_forces_of_pair_into(&self, rock: bool, skip_massless: bool, u: &[f64], f: &mut [f64]) {
        match (rock, skip_massless) {
            (false, false) => self.internal_forces_where_into::<false, 1>(u, f),
            (false, true) => self.internal_forces_where_into::<true, 1>(u, f),
            (true, false) => self.internal_forces_where_into::<false, 2>(u, f),
            (true, true) => self.internal_forces_where_into::<true, 2>(u, f),
        }
    }

    /// The element loop: `PAIR` 0 every element, 1 those of the scene's Rayleigh pair, 2 the
    /// rock's own ([`Model::internal_forces_of_pair_into`]).
    fn internal_forces_where_into<const SKIP_MASSLESS: bool, const PAIR: u8>(&self, u: &[f64], f: &mut [f64]) {
        let rock_material: &[bool] = self.rock_damping.as_ref().map_or(&[], |r| &r.material);
        // whether material `mi`'s elements are left out (PAIR 0: never)
        let other_pair = |mi: u16| PAIR != 0 && rock_material.get(mi as usize).copied().unwrap_or(false) != (PAIR == 2);
        if f.len() < 4 * NODAL_BLOCK {
            f.fill(0.0);
        } else {
            crate::par::region();
            f.par_chunks_mut(NODAL_BLOCK).for_each(|b| b.fill(0.0));
        }
        let fp = SharedMut(f.as_mut_ptr());
        // u node by node: one bounds check per node gathered instead of one per component
        let un: &[[f64; 3]] = u.as_chunks::<3>().0;
        // read u and f at the chunk's nodes (the sum only keeps the loads)
        let warm = |nodes: &[u32]| {
            let p = fp;
            let mut s = 0.0;
            for &v in nodes {
                let i = 3 * v as usize;
                // SAFETY: a read of an entry that no other chunk writes while this one runs (below).
                s += u[i] + unsafe { *p.0.add(i) };
            }
            std::hint::black_box(s);
        };
        let tet = |e: usize| {
            if (SKIP_MASSLESS && self.massless_cells[self.tets.cell[e] as usize]) || other_pair(self.tets.mat[e]) {
                return;
            }
            let nd = &self.tets.nodes[e];
            let ue: [[f64; 3]; 4] = std::array::from_fn(|a| un[nd[a] as usize]);
            let g = &self.tets.geom[e];
            let fe = tet4::internal_forces(&g.grad, g.vol, &ue, &self.materials[self.tets.mat[e] as usize].lame);
            let p = fp;
            for a in 0..4 {
                let i = 3 * nd[a] as usize;
                // SAFETY: the chunks assembled concurrently share no node ([`ChunkGraph`]: the
                // chunks that touch a node run one after the other); within a chunk the
                // elements run in order on one thread.
                unsafe {
                    *p.0.add(i) += fe[a][0];
                    *p.0.add(i + 1) += fe[a][1];
                    *p.0.add(i + 2) += fe[a][2];
                }
            }
        };
        let hex = |e: usize| {
            if (SKIP_MASSLESS && self.massless_cells[self.hexes.cell[e] as usize]) || other_pair(self.hexes.mat[e]) {
                return;
            }
            let nd = &self.hexes.nodes[e];
            let ue: [[f64; 3]; 8] = std::array::from_fn(|a| un[nd[a] as usize]);
            let s = &self.hexes.shapes[self.hexes.shape[e] as usize];
            let fe = hex8::internal_forces(s, &ue, &self.materials[self.hexes.mat[e] as usize].lame);
            let p = fp;
            for a in 0..8 {
                let i = 3 * nd[a] as usize;
                // SAFETY: as above.
                unsafe {
                    *p.0.add(i) += fe[a][0];
                    *p.0.add(i + 1) += fe[a][1];
                    *p.0.add(i + 2) += fe[a][2];
                }
            }
        };
        // the chunks in the graph's numbering: the tets', then the hexes'
        let nt = self.tets.schedule.chunks.len();
        let run = |k: usize| {
            if k < nt {
                self.tets.schedule.run_chunk(k, &warm, &tet)
            } else {
                self.hexes.schedule.run_chunk(k - nt, &warm, &hex)
            }
        };
        // one thread: the chunks in order, no pool hand-off (on a 10⁴-element model with
        // contact a hand-off per colour cost about as much as the elements themselves)
        if rayon::current_num_threads() == 1 || self.n_elements() < PAR_MIN {
            (0..self.chunk_graph.len()).for_each(run);
        } else {
            self.chunk_graph.run_all(&run);
        }
    }

    /// Element stresses (xx, yy, zz, xy, yz, zx) [Pa] in model element order (tets, then hexes).
    pub fn element_stress_into(&self, u: &[f64], out: &mut Vec<[f64; 6]>) {
        out.clear();
        let gather = |i: u32| {
            let i = 3 * i as usize;
            [u[i], u[i + 1], u[i + 2]]
        };
        for e in 0..self.tets.nodes.len() {
            let ue = self.tets.nodes[e].map(gather);
            out.push(tet4::stress(&self.tets.geom[e].grad, &ue, &self.materials[self.tets.mat[e] as usize].lame));
        }
        for e in 0..self.hexes.nodes.len() {
            let ue = self.hexes.nodes[e].map(gather);
            let s = &self.hexes.shapes[self.hexes.shape[e] as usize];
            out.push(hex8::stress(s, &ue, &self.materials[self.hexes.mat[e] as usize].lame));
        }
    }

    /// (kind, nodes) of every element in model order, for output grids.
    pub fn element_cells(&self) -> Vec<(CellKind, &[u32])> {
        let mut v: Vec<(CellKind, &[u32])> = Vec::with_capacity(self.n_elements());
        v.extend(self.tets.nodes.iter().map(|n| (CellKind::Tet4, &n[..])));
        v.extend(self.hexes.nodes.iter().map(|n| (CellKind::Hex8, &n[..])));
        v
    }

    /// Material (block) index of every element in model order.
    pub fn element_blocks(&self) -> Vec<i32> {
        self.tets.mat.iter().chain(self.hexes.mat.iter()).map(|&m| m as i32).collect()
    }

    /// Lamé constants of element `e` in model order.
    pub fn element_lame(&self, e: usize) -> &Lame {
        let nt = self.tets.nodes.len();
        let m = if e < nt { self.tets.mat[e] } else { self.hexes.mat[e - nt] };
        &self.materials[m as usize].lame
    }
}

// ---- the steps of `Model::build`, in its order

/// The materials of the scene, in scene order, and the material of every mesh cell
/// (`u32::MAX`: none). A cell in two material groups is an error naming both.
fn material_owners(mesh: &Mesh, scene: &Scene) -> Result<(Vec<Material>, Vec<u32>), crate::Error> {
    let mut materials = Vec::new();
    let mut owner = vec![u32::MAX; mesh.cells.len()];
    for (mi, ms) in scene.materials.iter().enumerate() {
        // rho = 0 without `massless`: nodes without inertia, held (the scene loader refuses it)
        let g = mesh.group_of_dim(&ms.group, 3)?;
        mesh.check_orientation(g)?;
        for &c in &g.cells {
            if owner[c] != u32::MAX {
                return Err(ModelError::Invalid(format!(
                    "element {} is in two material groups, \"{}\" and \"{}\"",
                    mesh.cells[c].tag, scene.materials[owner[c] as usize].group, ms.group
                ))
                .into());
            }
            owner[c] = mi as u32;
        }
        materials.push(Material::new(&ms.group, ms.e, ms.nu, ms.rho));
    }
    Ok((materials, owner))
}

/// The nodes of the joint faces when a material is massless (else none): the elements of a
/// massless block that touch one keep their mass (the thin massive layer along a joint on a
/// massless block, docs/dam_physics.md).
fn joint_face_nodes(mesh: &Mesh, scene: &Scene, massless: &[bool]) -> Result<Vec<bool>, crate::Error> {
    let mut joint_node = vec![false; mesh.nodes.len()];
    if massless.iter().any(|&m| m) {
        for js in &scene.joints {
            for g in [&js.master, &js.slave] {
                for node in mesh.group_nodes(g)? {
                    joint_node[node] = true;
                }
            }
        }
    }
    Ok(joint_node)
}

/// The elements of the material groups in cell order (the order the masses are summed in),
/// before the assembly order, and the nodal masses they lump. Scratch of `Model::build`.
struct ElementScan {
    /// tet4: nodes, material, mesh cell.
    tn: Vec<[u32; 4]>,
    tm: Vec<u16>,
    tc: Vec<u32>,
    /// hex8: nodes, shape id, material, mesh cell.
    hn: Vec<[u32; 8]>,
    hs: Vec<u32>,
    hm: Vec<u16>,
    hc: Vec<u32>,
    /// The congruent hex8 shapes, keyed by (material, edge vectors rounded to 1e-9 of the size).
    shapes: Vec<HexShape>,
    shape_key: HashMap<(usize, [i64; 21]), u32>,
    /// ω² per hex shape, computed once when scaling (NaN: not yet).
    shape_w2: Vec<f64>,
    /// Lumped nodal mass [kg], unscaled (the weight).
    mass: Vec<f64>,
    /// Mass scaling: the scaled (inertial) nodal masses and the factor per mesh cell (empty
    /// without `time.mass_scaling`).
    inertial: Vec<f64>,
    mass_scale: Vec<f64>,
    /// Mass from the elements of massive blocks alone (a node with only layer mass is weightless).
    massive_mass: Vec<f64>,
    /// Mesh cells of massless blocks that are not in the layer along a joint.
    massless_cell: Vec<bool>,
    /// Nodes of at least one element.
    active: Vec<bool>,
}

impl ElementScan {
    fn new(nodes: usize, cells: usize, scaling: bool) -> ElementScan {
        ElementScan {
            tn: Vec::new(),
            tm: Vec::new(),
            tc: Vec::new(),
            hn: Vec::new(),
            hs: Vec::new(),
            hm: Vec::new(),
            hc: Vec::new(),
            shapes: Vec::new(),
            shape_key: HashMap::new(),
            shape_w2: Vec::new(),
            mass: vec![0.0; nodes],
            inertial: if scaling { vec![0.0; nodes] } else { Vec::new() },
            mass_scale: if scaling { vec![1.0; cells] } else { Vec::new() },
            massive_mass: vec![0.0; nodes],
            massless_cell: vec![false; cells],
            active: vec![false; nodes],
        }
    }

    /// Add mesh cell `c` of material `mi`: its density (0 for a massless block's element off
    /// the joint layer), its lumped mass (scaled to `target_w2` when given), its element.
    #[allow(clippy::too_many_arguments)]
    fn add_cell(&mut self, mesh: &Mesh, materials: &[Material], massless: &[bool], joint_node: &[bool], target_w2: Option<f64>, c: usize, mi: usize) -> Result<(), crate::Error> {
        let cell = &mesh.cells[c];
        let layer = massless[mi] && cell.nodes().iter().any(|&v| joint_node[v as usize]);
        if layer && materials[mi].rho == 0.0 {
            return Err(ModelError::Invalid(format!(
                "material \"{}\" is massless with rho = 0, but element {} touches a joint face: a joint on a massless block needs the density of the block's layer along the joint (give `rho`; docs/dam_physics.md)",
                materials[mi].group, cell.tag
            ))
            .into());
        }
        let rho = if massless[mi] && !layer { 0.0 } else { materials[mi].rho };
        self.massless_cell[c] = massless[mi] && !layer;
        match cell.kind {
            CellKind::Tet4 => {
                // geometry recomputed in assembly order (not stored twice)
                let g = tet4::tet_geometry(&tet_x(mesh, cell.nodes())).ok_or_else(|| inverted(mesh, materials, c, mi))?;
                if let Some(t) = target_w2 {
                    // a pure massless element (rho 0 here) has no step and no inertia
                    let s = if rho > 0.0 { mass_scaling::factor(tet4::max_eigenvalue(&g.grad, g.vol, rho, &materials[mi].lame), t) } else { 1.0 };
                    self.mass_scale[c] = s;
                    for a in 0..4 {
                        self.inertial[cell.node(a)] += s * rho * g.vol / 4.0;
                    }
                }
                for a in 0..4 {
                    self.lump(cell.node(a), rho * g.vol / 4.0, massless[mi]);
                }
                self.tn.push(std::array::from_fn(|a| cell.nodes()[a]));
                self.tm.push(mi as u16);
                self.tc.push(c as u32);
            }
            CellKind::Hex8 => self.add_hex(mesh, materials, massless[mi], target_w2, c, mi, rho)?,
            CellKind::Tri3 | CellKind::Quad4 => {
                return Err(ModelError::Invalid(format!("element {} of material group \"{}\" is a face (tri3/quad4): material groups hold volume cells only", cell.tag, materials[mi].group)).into());
            }
        }
        Ok(())
    }

    /// A hex8 cell `c` of material `mi` with density `rho`: its shape (shared by congruent
    /// cells of the same material), lumped mass, element.
    #[allow(clippy::too_many_arguments)]
    fn add_hex(&mut self, mesh: &Mesh, materials: &[Material], massless: bool, target_w2: Option<f64>, c: usize, mi: usize, rho: f64) -> Result<(), crate::Error> {
        let cell = &mesh.cells[c];
        let x: [Vector3<f64>; 8] = std::array::from_fn(|a| mesh.x(cell.node(a)));
        // congruence key: edge vectors from node 0, rounded to 1e-9 of the element size
        let size = (x[6] - x[0]).norm();
        let q = 1e-9 * size;
        let mut key = [0i64; 21];
        for a in 1..8 {
            for i in 0..3 {
                key[3 * (a - 1) + i] = ((x[a][i] - x[0][i]) / q).round() as i64;
            }
        }
        let id = match self.shape_key.get(&(mi, key)) {
            Some(&id) => id,
            None => {
                let s = hex8::hex_shape(&x, &materials[mi].lame).ok_or_else(|| inverted(mesh, materials, c, mi))?;
                self.shapes.push(s);
                let id = (self.shapes.len() - 1) as u32;
                self.shape_key.insert((mi, key), id);
                id
            }
        };
        let (vol, mass_frac) = (self.shapes[id as usize].vol, self.shapes[id as usize].mass_frac);
        if let Some(t) = target_w2 {
            let f = if rho > 0.0 {
                if self.shape_w2.len() <= id as usize {
                    self.shape_w2.resize(id as usize + 1, f64::NAN);
                }
                if self.shape_w2[id as usize].is_nan() {
                    self.shape_w2[id as usize] = hex8::max_eigenvalue(&self.shapes[id as usize], rho, &materials[mi].lame);
                }
                mass_scaling::factor(self.shape_w2[id as usize], t)
            } else {
                1.0
            };
            self.mass_scale[c] = f;
            for a in 0..8 {
                self.inertial[cell.node(a)] += f * rho * vol * mass_frac[a];
            }
        }
        for a in 0..8 {
            self.lump(cell.node(a), rho * vol * mass_frac[a], massless);
        }
        self.hn.push(std::array::from_fn(|a| cell.nodes()[a]));
        self.hs.push(id);
        self.hm.push(mi as u16);
        self.hc.push(c as u32);
        Ok(())
    }

    /// The element sets in assembly order (colours and chunks: [`assembly_order`]), taken out
    /// of the scan (its element lists are left empty; the masses stay).
    fn take_sets(&mut self, mesh: &Mesh) -> Result<(Tet4Set, Hex8Set), ModelError> {
        self.shape_key = HashMap::new();
        let (tn, tm, tc) = (std::mem::take(&mut self.tn), std::mem::take(&mut self.tm), std::mem::take(&mut self.tc));
        let (to, tsched) = assembly_order(&tn, &mesh.nodes)?;
        let tets = {
            let nodes = permute(&tn, &to);
            drop(tn);
            // the same computation as in the scan on the same coordinates: identical values
            let geom = nodes.iter().map(|nd| tet4::tet_geometry(&tet_x(mesh, nd)).expect("checked above")).collect();
            Tet4Set { nodes, geom, mat: permute(&tm, &to), cell: permute(&tc, &to), schedule: tsched }
        };
        drop((to, tm, tc));
        let (hn, hs, hm, hc) = (std::mem::take(&mut self.hn), std::mem::take(&mut self.hs), std::mem::take(&mut self.hm), std::mem::take(&mut self.hc));
        let (ho, hsched) = assembly_order(&hn, &mesh.nodes)?;
        let (shape, shapes) = shapes_in_use_order(&permute(&hs, &ho), std::mem::take(&mut self.shapes));
        let hexes = Hex8Set { nodes: permute(&hn, &ho), shape, mat: permute(&hm, &ho), cell: permute(&hc, &ho), schedule: hsched, shapes };
        Ok((tets, hexes))
    }

    /// Lump `m` [kg] on `node` (and on its massive mass unless the block is massless).
    fn lump(&mut self, node: usize, m: f64, massless: bool) {
        self.mass[node] += m;
        if !massless {
            self.massive_mass[node] += m;
        }
        self.active[node] = true;
    }
}

/// The hex8 shapes renumbered in the order the element loop first uses them (`shape`: each
/// element's shape, in assembly order): the loop then streams the shapes in storage order. On a
/// curved mesh, where every element has its own shape (1.6 kB each), the scan's numbering (mesh
/// cell order) made the loop fetch them out of order. The same values: results unchanged.
fn shapes_in_use_order(shape: &[u32], shapes: Vec<HexShape>) -> (Vec<u32>, Vec<HexShape>) {
    let mut new_id = vec![u32::MAX; shapes.len()];
    let mut order: Vec<u32> = Vec::with_capacity(shapes.len());
    let renumbered = shape
        .iter()
        .map(|&id| {
            if new_id[id as usize] == u32::MAX {
                new_id[id as usize] = order.len() as u32;
                order.push(id);
            }
            new_id[id as usize]
        })
        .collect();
    let mut slots: Vec<Option<HexShape>> = shapes.into_iter().map(Some).collect();
    let reordered = order.iter().filter_map(|&id| slots[id as usize].take()).collect();
    (renumbered, reordered)
}

/// The corner points of a tet4 with mesh nodes `nodes`.
fn tet_x(mesh: &Mesh, nodes: &[u32]) -> [Vector3<f64>; 4] {
    std::array::from_fn(|a| mesh.x(nodes[a] as usize))
}

/// The error of an inverted element (cell `c` of material `mi`), with its smallest corner
/// Jacobian.
fn inverted(mesh: &Mesh, materials: &[Material], c: usize, mi: usize) -> crate::Error {
    MeshError::InvertedElement { path: mesh.source.clone(), group: materials[mi].group.clone(), element: mesh.cells[c].tag, jacobian: mesh.min_corner_jacobian(c) }.into()
}

/// The fixed components of every node (bits x = 1, y = 2, z = 4; a node of no element: all
/// three) and the condensed ones (the nodes of massless elements without mass, less the
/// components the scene's `boundary` fixes).
fn supports(mesh: &Mesh, scene: &Scene, active: &[bool], mass: &[f64], massless_cell: &[bool]) -> Result<(Vec<u8>, Vec<u8>), crate::Error> {
    let mut fixed: Vec<u8> = active.iter().map(|&a| if a { 0 } else { 7 }).collect();
    // nodes of the massless elements (without mass: condensed)
    let mut condensed = vec![0u8; mesh.nodes.len()];
    for (c, &ml) in massless_cell.iter().enumerate() {
        if ml {
            for &v in mesh.cells[c].nodes() {
                if mass[v as usize] == 0.0 {
                    condensed[v as usize] = 7;
                }
            }
        }
    }
    for b in &scene.boundary {
        let bits = b.fix.iter().fold(0u8, |acc, c| acc | match c.as_str() { "x" => 1, "y" => 2, _ => 4 });
        for node in mesh.group_nodes(&b.group)? {
            fixed[node] |= bits;
            condensed[node] &= !bits;
        }
    }
    Ok((fixed, condensed))
}

/// The summary of the scene's mass scaling (`None` without `time.mass_scaling`): the scaled
/// elements, the largest factor and its element, the mass added (the scaled total minus the
/// unscaled one).
fn mass_scaling_summary(mesh: &Mesh, scene: &Scene, mass_scale: &[f64], mass: &[f64], inertial: &[f64]) -> Option<MassScaling> {
    scene.time.mass_scaling.as_ref().map(|ms| {
        let (mut count, mut max_factor, mut max_cell) = (0usize, 1.0, None);
        for (c, &f) in mass_scale.iter().enumerate() {
            if f > 1.0 {
                count += 1;
                if f > max_factor {
                    (max_factor, max_cell) = (f, Some(c));
                }
            }
        }
        // added = Σ (s − 1) ρ V: the scaled total minus the unscaled one
        let total: f64 = mass.iter().sum();
        let added = if count > 0 { inertial.iter().sum::<f64>() - total } else { 0.0 };
        MassScaling {
            target_dt: ms.target_dt,
            element_dt: ms.target_dt / scene.time.courant_or_default(),
            scaled_elements: count,
            added_mass: added,
            total_mass: total,
            max_factor,
            max_factor_element: max_cell.map(|c| mesh.cells[c].tag).unwrap_or(0),
        }
    })
}

/// The central-difference stable step [s] at ω² `w2` [1/s²] with Rayleigh α [1/s], β [s]: the
/// largest dt with ω²dt² + 2(α + βω²) dt − 4 ≤ 0 (undamped: 2/ω); infinite for ω² ≤ 0. The one
/// rule for every element group's step (the model's, the massed rock's note).
pub fn damped_step(w2: f64, alpha: f64, beta: f64) -> f64 {
    if w2 <= 0.0 {
        return f64::INFINITY;
    }
    let c = alpha + beta * w2;
    (-c + (c * c + 4.0 * w2).sqrt()) / w2
}

/// The rock's own Rayleigh pair from the scene's `foundation.damping` (`None` unless it gives
/// one): the pair, and the rock's materials (`foundation.rock`, else those marked `massless`).
/// A rock material still massless (the scene not passed through the massed foundation's
/// `scene_for_model`, or a massless foundation) is an error naming the field.
fn rock_rayleigh(scene: &Scene) -> Result<Option<RockRayleigh>, ModelError> {
    let Some(f) = &scene.foundation else { return Ok(None) };
    let Some((alpha, beta)) = f.damping.own_pair().map_err(ModelError::Invalid)? else { return Ok(None) };
    let rock: Vec<&str> = f.rock_materials(&scene.materials).iter().map(|m| m.group.as_str()).collect();
    if let Some(m) = scene.materials.iter().find(|m| m.massless && rock.contains(&m.group.as_str())) {
        return Err(ModelError::Invalid(format!(
            "foundation.damping: the rock's own Rayleigh pair needs a massed rock, but its material \"{}\" is massless (condensed: no velocity to damp): set foundation.model to \"massed_fixed\" or \"radiating\" (built by Problem::build), or leave foundation.damping out",
            m.group
        )));
    }
    if let Some(g) = scene.damping.mass_groups.iter().flatten().find(|g| rock.contains(&g.as_str())) {
        return Err(ModelError::Invalid(format!("damping.mass_groups names the rock's group \"{g}\", which has its own pair in foundation.damping: leave it out of damping.mass_groups")));
    }
    Ok(Some(RockRayleigh { alpha, beta, material: scene.materials.iter().map(|m| rock.contains(&m.group.as_str())).collect() }))
}

/// α [1/s] of every node's mass-proportional term in the dynamic stage: the scene's `alpha` on
/// the nodes of `damping.mass_groups` (volume groups; default every node, or with the rock's
/// own pair every node of a non-rock material), the rock's own α on the rock's other nodes
/// (where the rock meets the dam the dam's α holds), 0 elsewhere.
fn node_alphas(mesh: &Mesh, scene: &Scene, alpha: f64, rock: Option<&RockRayleigh>) -> Result<Vec<f64>, crate::Error> {
    let n = mesh.nodes.len();
    let mark = |groups: &mut dyn Iterator<Item = &String>| -> Result<Vec<bool>, crate::Error> {
        let mut d = vec![false; n];
        for g in groups {
            mesh.group_of_dim(g, 3)?;
            for node in mesh.group_nodes(g)? {
                d[node] = true;
            }
        }
        Ok(d)
    };
    let (scene_set, rock_set) = match rock {
        None => (if let Some(g) = &scene.damping.mass_groups { mark(&mut g.iter())? } else { vec![true; n] }, vec![false; n]),
        Some(r) => {
            let of = |is_rock: bool| scene.materials.iter().zip(&r.material).filter(move |(_, x)| **x == is_rock).map(|(m, _)| &m.group);
            let scene_set = if let Some(g) = &scene.damping.mass_groups { mark(&mut g.iter())? } else { mark(&mut of(false))? };
            (scene_set, mark(&mut of(true))?)
        }
    };
    let rock_alpha = rock.map_or(0.0, |r| r.alpha);
    Ok(scene_set.iter().zip(&rock_set).map(|(&d, &r)| if d { alpha } else if r { rock_alpha } else { 0.0 }).collect())
}
