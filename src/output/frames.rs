//! Volume frames: one VTU per output step in `frames/`, listed in `<scene>.pvd`.
//!
//! Point data: displacement, velocity, acceleration (relative to the base; central
//! differences at the frame time). Cell data: stress (9-component tensor), principal stresses
//! σ1 ≥ σ2 ≥ σ3, von Mises, block id (index of the material in the scene).

use crate::vtk::pvd::PvdSeries;
use crate::vtk::vtu::{write_vtu, Field, Grid};
use crate::error::OutputError;
use crate::dynamics::Kinematics;
use crate::model::Model;
use std::path::{Path, PathBuf};

pub struct FrameWriter {
    dir: PathBuf,
    name: String,
    pub series: PvdSeries,
    blocks: Vec<i32>,
    stress: Vec<[f64; 6]>,
}

impl FrameWriter {
    pub fn create(out_dir: &Path, name: &str, model: &Model) -> Result<FrameWriter, OutputError> {
        let dir = out_dir.join("frames");
        std::fs::create_dir_all(&dir).map_err(|e| OutputError::write(&dir, e))?;
        let stem = crate::files::file_stem(name);
        Ok(FrameWriter {
            dir,
            series: PvdSeries::new(out_dir.join(format!("{stem}.pvd"))),
            name: stem,
            blocks: model.element_blocks(),
            stress: Vec::new(),
        })
    }

    /// Write a frame and add it to the `.pvd`.
    pub fn write(&mut self, model: &Model, k: &Kinematics) -> Result<PathBuf, OutputError> {
        let idx = self.series.len();
        let path = self.dir.join(format!("{}_{idx:05}.vtu", self.name));
        let v: Vec<f64> = (0..k.u.len()).map(|i| k.velocity(i)).collect();
        let a: Vec<f64> = (0..k.u.len()).map(|i| k.acceleration(i)).collect();
        model.element_stress_into(k.u, &mut self.stress);
        let ne = self.stress.len();
        let mut tensor = Vec::with_capacity(9 * ne);
        let mut principal = Vec::with_capacity(3 * ne);
        let mut vm = Vec::with_capacity(ne);
        for s in &self.stress {
            tensor.extend_from_slice(&[s[0], s[3], s[5], s[3], s[1], s[4], s[5], s[4], s[2]]);
            principal.extend_from_slice(&super::principal_stresses(s));
            vm.push(super::von_mises(s));
        }
        let grid = Grid { points: &model.mesh.nodes, cells: model.element_cells() };
        write_vtu(
            &path,
            &grid,
            &[Field::f64("displacement", 3, k.u), Field::f64("velocity", 3, &v), Field::f64("acceleration", 3, &a)],
            &[
                Field::f64("stress", 9, &tensor),
                Field::f64("principal_stress", 3, &principal),
                Field::f64("von_mises", 1, &vm),
                Field::i32("block_id", 1, &self.blocks),
            ],
        )?;
        self.series.push(k.t, &path)?;
        Ok(path)
    }
}
