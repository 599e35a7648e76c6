//! Target response spectra (5 % damping, Sa in g): the Chinese hydraulic-structures code design
//! spectrum, a user table and a uniform hazard spectrum given as points.
//!
//! **Code spectrum** (DL 5073-2000 *Specifications for seismic design of hydraulic structures*,
//! §4.3 (4.3.3–4.3.6); GB 51247-2018 *Standard for seismic design of hydraulic structures*,
//! §5.3 (5.3.1–5.3.4) keeps the shape, the β_max values and the floor):
//! Sa(T) = a_h β(T) with a_h the design PGA and
//! - β = 1 + (β_max − 1) T / 0.1 for 0 ≤ T ≤ 0.1 s,
//! - β = β_max on the plateau 0.1 s < T ≤ T_g,
//! - β = β_max (T_g / T)^0.6 for T > T_g,
//! - never below the floor β_min = 0.2 β_max.
//!
//! β_max: 2.50 arch dams, 2.00 gravity dams, 1.60 earth-rock dams, 2.25 sluices, intake towers
//! and other concrete structures. T_g by site class: DL 5073-2000 Table 4.3.6 (I 0.20, II 0.30,
//! III 0.40, IV 0.65 s; the code adds 0.05 s for design intensity ≤ 8 when the structure's
//! fundamental period exceeds 1.0 s: give `tg` for that); GB 51247-2018 §5.3.4 takes T_g from the
//! site class and the zonation map's basic characteristic period (0.35, 0.40 or 0.45 s) through
//! the site adjustment table of GB 18306-2015 (§8.2, Table 1; I0, I1, II, III, IV).
//! **Unverified**: the GB 51247 table here ([`tg_gb51247`]) was written from that GB 18306-2015
//! table as recalled by an earlier session; the code texts could not be searched here (only
//! GB 18306-2015 §7 and the GB 51247-2018 contents were found), so check it against your copy.
//! DL 5073-2000 stays the default. The codes draw the spectrum to 3 s; beyond it
//! the same descending branch and floor are used (stated wherever a spectrum is written).
//!
//! **Table**: (T [s], Sa [g]) rows, T strictly increasing, Sa ≥ 0, linear between rows and
//! constant beyond the ends. **UHS**: (T, Sa) points, Sa > 0, interpolated linearly in
//! log T–log Sa (a hazard curve's points are sparse), constant beyond the ends.

use super::MotionError;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// A target spectrum as a scene or the CLI names it (before the PGA is known for the code form).
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize)]
#[serde(tag = "kind", rename_all = "lowercase", deny_unknown_fields)]
pub enum TargetSpec {
    /// The code design spectrum.
    Code {
        /// "DL 5073-2000" (default) or "GB 51247-2018".
        #[serde(default = "default_code")]
        code: String,
        /// "arch", "gravity", "earth-rock", "other" (β_max 2.50, 2.00, 1.60, 2.25).
        structure: String,
        /// DL 5073-2000: "I", "II", "III", "IV"; GB 51247-2018: "I0", "I1", "II", "III", "IV".
        site_class: String,
        /// GB 51247-2018 only: the zonation map's basic characteristic period [s], 0.35, 0.40 or 0.45.
        #[serde(default)]
        basic_tg: Option<f64>,
        /// Override T_g [s] (e.g. the +0.05 s of DL 5073-2000 §4.3.6).
        #[serde(default)]
        tg: Option<f64>,
        /// Override β_max (a site-specific study).
        #[serde(default)]
        beta_max: Option<f64>,
    },
    /// A user table (T [s], Sa [g]), inline `points` or a two-column `file`.
    Table {
        #[serde(default)]
        points: Option<Vec<[f64; 2]>>,
        #[serde(default)]
        file: Option<PathBuf>,
    },
    /// Uniform hazard spectrum points (T [s], Sa [g]), inline or from a file.
    Uhs {
        #[serde(default)]
        points: Option<Vec<[f64; 2]>>,
        #[serde(default)]
        file: Option<PathBuf>,
    },
}

fn default_code() -> String {
    "DL 5073-2000".into()
}

/// A resolved target spectrum: Sa(T) [g] for a horizontal component.
#[derive(Clone, Debug)]
pub struct TargetSpectrum {
    /// One line saying what it is (code, clause, parameters), for headers and charts.
    pub label: String,
    shape: Shape,
    /// Multiplier (1 for horizontal; the vertical ratio for a vertical component).
    pub factor: f64,
}

#[derive(Clone, Debug)]
enum Shape {
    Code { pga: f64, beta_max: f64, tg: f64 },
    Table(Vec<[f64; 2]>),
    Uhs(Vec<[f64; 2]>),
}

/// T_g [s] of DL 5073-2000 Table 4.3.6.
fn tg_dl5073(site: &str) -> Option<f64> {
    Some(match site {
        "I" => 0.20,
        "II" => 0.30,
        "III" => 0.40,
        "IV" => 0.65,
        _ => return None,
    })
}

/// T_g [s] of GB 51247-2018 §5.3.4 (GB 18306-2015 §8.2 Table 1) for a basic T_g and a site
/// class. Unverified against the code text (module doc).
fn tg_gb51247(basic: f64, site: &str) -> Option<f64> {
    let row: [f64; 5] = if (basic - 0.35).abs() < 1e-9 {
        [0.20, 0.25, 0.35, 0.45, 0.65]
    } else if (basic - 0.40).abs() < 1e-9 {
        [0.25, 0.30, 0.40, 0.55, 0.75]
    } else if (basic - 0.45).abs() < 1e-9 {
        [0.30, 0.35, 0.45, 0.65, 0.90]
    } else {
        return None;
    };
    let i = ["I0", "I1", "II", "III", "IV"].iter().position(|s| *s == site)?;
    Some(row[i])
}

fn beta_max_of(structure: &str) -> Option<f64> {
    Some(match structure {
        "arch" => 2.50,
        "gravity" => 2.00,
        "earth-rock" => 1.60,
        "other" => 2.25,
        _ => return None,
    })
}

/// Check and return the (T, Sa) rows of a table or UHS; `field` names them in errors.
pub fn check_points(points: &[[f64; 2]], field: &str, positive: bool) -> Result<Vec<[f64; 2]>, MotionError> {
    if points.len() < 2 {
        return Err(MotionError::invalid(field, format!("{} rows: give at least two (T [s], Sa [g]) rows", points.len())));
    }
    for (i, p) in points.iter().enumerate() {
        if !(p[0] > 0.0 && p[0].is_finite()) {
            return Err(MotionError::invalid(format!("{field}[{i}]"), format!("period T = {} s must be positive", p[0])));
        }
        if !p[1].is_finite() || p[1] < 0.0 || (positive && p[1] == 0.0) {
            return Err(MotionError::invalid(
                format!("{field}[{i}]"),
                format!("Sa = {} g at T = {} s must be {} (a spectral acceleration is a magnitude)", p[1], p[0], if positive { "> 0 (log interpolation)" } else { "≥ 0" }),
            ));
        }
        if i > 0 && p[0] <= points[i - 1][0] {
            return Err(MotionError::invalid(format!("{field}[{i}]"), format!("T = {} s does not increase (previous row T = {} s): sort the table by period, without repeats", p[0], points[i - 1][0])));
        }
    }
    Ok(points.to_vec())
}

/// Read two-column (T [s], Sa [g]) rows from a file (`#` comments, spaces or commas).
pub fn read_points(path: &Path) -> Result<Vec<[f64; 2]>, MotionError> {
    let text = std::fs::read_to_string(path).map_err(|source| MotionError::Io { path: path.to_path_buf(), source })?;
    let mut out = Vec::new();
    for (k, raw) in text.lines().enumerate() {
        let l = raw.split('#').next().unwrap_or("").trim();
        if l.is_empty() {
            continue;
        }
        let v: Vec<&str> = l.split(|c: char| c.is_whitespace() || c == ',').filter(|s| !s.is_empty()).collect();
        let field = || format!("{}, line {}", path.display(), k + 1);
        if v.len() < 2 {
            return Err(MotionError::invalid(field(), format!("expected two columns (T [s], Sa [g]), found `{l}`")));
        }
        let t: f64 = v[0].parse().map_err(|_| MotionError::invalid(field(), format!("period `{}` is not a number", v[0])))?;
        let s: f64 = v[1].parse().map_err(|_| MotionError::invalid(field(), format!("Sa `{}` is not a number", v[1])))?;
        out.push([t, s]);
    }
    Ok(out)
}

impl TargetSpec {
    /// Resolve with the design PGA [g] (used by the code form; tables carry their own Sa).
    /// `field` prefixes error messages (e.g. `loads.base[0].synthetic.spectrum`).
    pub fn resolve(&self, pga: f64, field: &str) -> Result<TargetSpectrum, MotionError> {
        match self {
            TargetSpec::Code { code, structure, site_class, basic_tg, tg, beta_max } => {
                let bm = match beta_max {
                    Some(b) if *b >= 1.0 && b.is_finite() => *b,
                    Some(b) => return Err(MotionError::invalid(format!("{field}.beta_max"), format!("{b} must be ≥ 1"))),
                    None => beta_max_of(structure).ok_or_else(|| {
                        MotionError::invalid(format!("{field}.structure"), format!("unknown structure \"{structure}\": use \"arch\" (β_max 2.50), \"gravity\" (2.00), \"earth-rock\" (1.60) or \"other\" (2.25)"))
                    })?,
                };
                let (clause, tg_site) = match code.as_str() {
                    "DL 5073-2000" | "DL5073-2000" => {
                        if basic_tg.is_some() {
                            return Err(MotionError::invalid(format!("{field}.basic_tg"), "only GB 51247-2018 uses a basic characteristic period; DL 5073-2000 takes T_g from the site class alone"));
                        }
                        let t = tg_dl5073(site_class).ok_or_else(|| MotionError::invalid(format!("{field}.site_class"), format!("unknown site class \"{site_class}\" for DL 5073-2000: use I, II, III or IV (Table 4.3.6)")))?;
                        ("DL 5073-2000 §4.3", t)
                    }
                    "GB 51247-2018" | "GB51247-2018" => {
                        let b = basic_tg.ok_or_else(|| MotionError::invalid(format!("{field}.basic_tg"), "GB 51247-2018 needs the zonation map's basic characteristic period: 0.35, 0.40 or 0.45 s"))?;
                        if ![0.35, 0.40, 0.45].iter().any(|x| (x - b).abs() < 1e-9) {
                            return Err(MotionError::invalid(format!("{field}.basic_tg"), format!("{b} s: use 0.35, 0.40 or 0.45 s")));
                        }
                        let t = tg_gb51247(b, site_class).ok_or_else(|| MotionError::invalid(format!("{field}.site_class"), format!("unknown site class \"{site_class}\" for GB 51247-2018: use I0, I1, II, III or IV")))?;
                        ("GB 51247-2018 §5.3 (T_g table unverified, docs/motion.md)", t)
                    }
                    other => return Err(MotionError::invalid(format!("{field}.code"), format!("unknown code \"{other}\": use \"DL 5073-2000\" or \"GB 51247-2018\""))),
                };
                let tgv = match tg {
                    Some(t) if *t > 0.1 && t.is_finite() => *t,
                    Some(t) => return Err(MotionError::invalid(format!("{field}.tg"), format!("{t} s must exceed the plateau start 0.1 s"))),
                    None => tg_site,
                };
                check_pga(pga, "pga")?;
                Ok(TargetSpectrum {
                    label: format!("{clause}: {structure} β_max {bm:.2}, site {site_class}, T_g {tgv:.2} s, floor 0.2 β_max, PGA {pga} g"),
                    shape: Shape::Code { pga, beta_max: bm, tg: tgv },
                    factor: 1.0,
                })
            }
            TargetSpec::Table { points, file } | TargetSpec::Uhs { points, file } => {
                let uhs = matches!(self, TargetSpec::Uhs { .. });
                let raw = match (points, file) {
                    (Some(p), None) => p.clone(),
                    (None, Some(f)) => read_points(f)?,
                    _ => return Err(MotionError::invalid(field, "give `points` or `file`, not both or neither")),
                };
                let pts = check_points(&raw, &format!("{field}.points"), uhs)?;
                let src = file.as_ref().map(|f| f.display().to_string()).unwrap_or_else(|| format!("{} points", pts.len()));
                Ok(TargetSpectrum {
                    label: if uhs { format!("UHS ({src}, log-log interpolation)") } else { format!("table ({src}, linear interpolation)") },
                    shape: if uhs { Shape::Uhs(pts) } else { Shape::Table(pts) },
                    factor: 1.0,
                })
            }
        }
    }
}

/// The design PGA must be positive and finite.
pub fn check_pga(pga: f64, field: &str) -> Result<(), MotionError> {
    if !(pga > 0.0 && pga.is_finite()) {
        return Err(MotionError::invalid(field, format!("PGA = {pga} g must be > 0")));
    }
    Ok(())
}

impl TargetSpectrum {
    /// Sa [g] at period `t` [s].
    pub fn sa(&self, t: f64) -> f64 {
        self.factor * match &self.shape {
            Shape::Code { pga, beta_max, tg } => pga * code_beta(t, *beta_max, *tg),
            Shape::Table(p) => interp(p, t, false),
            Shape::Uhs(p) => interp(p, t, true),
        }
    }

    /// The same spectrum times `f` (the vertical at 2/3).
    pub fn scaled(&self, f: f64) -> TargetSpectrum {
        let mut s = self.clone();
        s.factor *= f;
        s
    }

    /// Period range where the spectrum is defined by data (tables) or by the code (to 3 s).
    pub fn defined_range(&self) -> (f64, f64) {
        match &self.shape {
            Shape::Code { .. } => (0.0, 3.0),
            Shape::Table(p) | Shape::Uhs(p) => (p[0][0], p[p.len() - 1][0]),
        }
    }
}

/// β(T) of the code spectrum (see the module doc).
pub fn code_beta(t: f64, beta_max: f64, tg: f64) -> f64 {
    let b = if t <= 0.1 {
        1.0 + (beta_max - 1.0) * t.max(0.0) / 0.1
    } else if t <= tg {
        beta_max
    } else {
        beta_max * (tg / t).powf(0.6)
    };
    b.max(0.2 * beta_max)
}

fn interp(p: &[[f64; 2]], t: f64, log: bool) -> f64 {
    if t <= p[0][0] {
        return p[0][1];
    }
    if t >= p[p.len() - 1][0] {
        return p[p.len() - 1][1];
    }
    let i = p.partition_point(|q| q[0] <= t).max(1);
    let (a, b) = (p[i - 1], p[i]);
    if log {
        let f = (t.ln() - a[0].ln()) / (b[0].ln() - a[0].ln());
        (a[1].ln() + f * (b[1].ln() - a[1].ln())).exp()
    } else {
        let f = (t - a[0]) / (b[0] - a[0]);
        a[1] + f * (b[1] - a[1])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn arch(site: &str) -> TargetSpec {
        TargetSpec::Code { code: default_code(), structure: "arch".into(), site_class: site.into(), basic_tg: None, tg: None, beta_max: None }
    }

    #[test]
    fn code_spectrum_branches() {
        // DL 5073-2000 §4.3: arch β_max 2.5, site I T_g 0.20 s
        let s = arch("I").resolve(0.5575, "t").unwrap();
        assert!((s.sa(0.0) - 0.5575).abs() < 1e-12);
        assert!((s.sa(0.05) - 0.5575 * 1.75).abs() < 1e-12);
        assert!((s.sa(0.15) - 0.5575 * 2.5).abs() < 1e-12);
        assert!((s.sa(1.0) - 0.5575 * 2.5 * (0.2f64).powf(0.6)).abs() < 1e-12);
        // floor 0.2 β_max reached at T_g 0.2^(-1/0.6) = 2.92 s
        assert!((s.sa(5.0) - 0.5575 * 0.5).abs() < 1e-12);
    }

    #[test]
    fn gb51247_tg_table() {
        let s = TargetSpec::Code { code: "GB 51247-2018".into(), structure: "gravity".into(), site_class: "III".into(), basic_tg: Some(0.40), tg: None, beta_max: None };
        let r = s.resolve(0.2, "t").unwrap();
        assert!(r.label.contains("T_g 0.55"), "{}", r.label);
    }

    #[test]
    fn uhs_is_log_log() {
        let s = TargetSpec::Uhs { points: Some(vec![[0.1, 1.0], [1.0, 0.1]]), file: None }.resolve(0.3, "u").unwrap();
        assert!((s.sa(10f64.powf(-0.5)) - 10f64.powf(-0.5)).abs() < 1e-12);
    }
}
