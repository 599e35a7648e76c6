//! Selective mass scaling (scene `time.mass_scaling`, docs/elements.md "Mass scaling").
//!
//! An element's largest eigenvalue with lumped mass is λ_max = ω²_e ∝ 1/ρ, so raising its
//! density by s = ω²_e / ω²_target lowers its ω² to the target's: the element's own stable step
//! reaches the target. Only the elements above the target are scaled (selective), and only their
//! **inertial** mass: their weight (gravity load ρ g V) stays that of the material, and the
//! reservoir's added mass, added after the model is built, is unchanged. The cost is in the
//! dynamics: the scaled elements respond more slowly than their material; the added mass as a
//! fraction of the total is the measure of how much ([`MassScaling::added_fraction`]).

use serde::{Deserialize, Serialize};

/// Added mass above which the run warns, as a fraction of the model's total (unscaled) mass.
/// Default 0.01 (1 %): the change of a rigid-body or a low mode's response is of the order of the
/// added fraction (the measured error on the bar's wave, docs/elements.md "Mass scaling", was
/// below the fraction), so 1 % keeps the error of the lowest modes, which the earthquake
/// response is made of, below about 1 %; above it the scaling is no longer local to a few bad
/// elements and the mesh should be fixed instead.
pub const ADDED_MASS_WARN_FRACTION: f64 = 0.01;

/// What the mass scaling of a model did (`summary.json` → `mass_scaling`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct MassScaling {
    /// The scene's `time.mass_scaling.target_dt` [s].
    pub target_dt: f64,
    /// The element step the scaled elements were raised to, target_dt / courant [s].
    pub element_dt: f64,
    /// Elements whose density was scaled.
    pub scaled_elements: usize,
    /// Inertial mass added [kg] (Σ (s − 1) ρ V over the scaled elements).
    pub added_mass: f64,
    /// The model's mass before scaling [kg] (Σ ρ V of the elements that carry mass).
    pub total_mass: f64,
    /// The largest density factor s (1 when no element was scaled).
    pub max_factor: f64,
    /// Gmsh tag of the element with the largest factor (0 when none was scaled).
    pub max_factor_element: u64,
}

impl MassScaling {
    /// Added over total mass (0 for a model without mass).
    pub fn added_fraction(&self) -> f64 {
        if self.total_mass > 0.0 { self.added_mass / self.total_mass } else { 0.0 }
    }

    /// One line for the run's notes.
    pub fn note(&self) -> String {
        format!(
            "mass scaling to target dt {:.4e} s (element step {:.4e} s): {} element{} scaled, added mass {:.4e} kg = {:.4} % of the total {:.4e} kg, largest factor {:.4} (element {}); gravity acts on the unscaled mass",
            self.target_dt,
            self.element_dt,
            self.scaled_elements,
            if self.scaled_elements == 1 { "" } else { "s" },
            self.added_mass,
            100.0 * self.added_fraction(),
            self.total_mass,
            self.max_factor,
            self.max_factor_element
        )
    }

    /// The warning when the added mass exceeds [`ADDED_MASS_WARN_FRACTION`] of the total.
    pub fn warning(&self) -> Option<String> {
        (self.added_fraction() > ADDED_MASS_WARN_FRACTION).then(|| {
            format!(
                "mass scaling added {:.4e} kg, {:.2} % of the total mass (above {:.0} %) on {} element{} (largest factor {:.3}, element {}): the scaled model's dynamics differ from the material's by about that fraction; lower time.mass_scaling.target_dt or improve the mesh (docs/elements.md, \"Mass scaling\")",
                self.added_mass,
                100.0 * self.added_fraction(),
                100.0 * ADDED_MASS_WARN_FRACTION,
                self.scaled_elements,
                if self.scaled_elements == 1 { "" } else { "s" },
                self.max_factor,
                self.max_factor_element
            )
        })
    }
}

/// The element ω² [1/s²] whose damped stable step (`Model::stable_dt`'s rule,
/// ω²dt² + 2(α + βω²) dt − 4 = 0) is `element_dt` [s]: (4 − 2α T) / (T² + 2β T) with
/// T = element_dt. `Err` when the mass-proportional damping alone forbids that step
/// (T ≥ 2/α).
pub fn target_omega2(element_dt: f64, alpha: f64, beta: f64) -> Result<f64, String> {
    let t = element_dt;
    if !(t > 0.0 && t.is_finite()) {
        return Err(format!("time.mass_scaling.target_dt: the element step target_dt / courant = {t} must be positive and finite [s]"));
    }
    let num = 4.0 - 2.0 * alpha * t;
    if !(num > 0.0) {
        return Err(format!(
            "time.mass_scaling.target_dt: the element step target_dt / courant = {t:.4e} s is not below 2/α = {:.4e} s, which the mass-proportional damping α = {alpha:.4e} 1/s alone allows: no mass scaling reaches it; lower target_dt or α",
            2.0 / alpha
        ));
    }
    Ok(num / (t * t + 2.0 * beta * t))
}

/// Relative margin above the target ω² within which an element is left unscaled. Default 1e-12:
/// an element whose step equals the target up to round-off (the target is often a regular
/// element's step, shared by many congruent elements) is not counted as scaled by 1 + 1e-16;
/// its step is below the target by at most 5e-13 relative.
pub const ROUND_OFF: f64 = 1e-12;

/// The density factor of an element with ω² `omega2` for the target ω² `target`: ω²/target
/// above it (by more than [`ROUND_OFF`]), 1 (unscaled) otherwise.
pub fn factor(omega2: f64, target: f64) -> f64 {
    if omega2 > target * (1.0 + ROUND_OFF) { omega2 / target } else { 1.0 }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The target ω² inverts the damped stable-step formula: dt_stable(ω²_target) = T to
    /// round-off (1e-14 relative), with and without damping; undamped it is (2/T)².
    #[test]
    fn target_omega2_gives_back_the_element_step() {
        let dt_stable = |w2: f64, a: f64, b: f64| {
            let c = a + b * w2;
            (-c + (c * c + 4.0 * w2).sqrt()) / w2
        };
        for (a, b) in [(0.0, 0.0), (1.2, 0.0), (0.0, 3e-6), (0.8, 2e-7)] {
            let t = 2e-5;
            let w2 = target_omega2(t, a, b).unwrap();
            assert!((dt_stable(w2, a, b) - t).abs() < 1e-14 * t, "α {a}, β {b}");
        }
        assert!((target_omega2(2e-5, 0.0, 0.0).unwrap() - 1e10).abs() < 1e-4);
        assert!(target_omega2(1.0, 2.0, 0.0).unwrap_err().contains("time.mass_scaling.target_dt"));
        assert!(target_omega2(f64::NAN, 0.0, 0.0).unwrap_err().contains("positive and finite"));
        assert_eq!(factor(4.0, 2.0), 2.0);
        assert_eq!(factor(1.0, 2.0), 1.0);
    }
}
