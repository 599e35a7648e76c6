//! Axis arithmetic shared by the chart writers, free of plotters: the map to axis space
//! (identity or log10), automatic ranges, clipping of polylines and markers to the plotted
//! window, and tick-label text.
//!
//! Everything here works in *axis space*, where both axis kinds are linear: a log axis is
//! handled as log10 of the value, so margins, clipping and legend placement treat a decade
//! like any other unit length.

use super::table::fmt_sig;

/// Margin added to each side of an automatic range, as a fraction of the data span in axis
/// space. 5 % keeps markers at the extremes clear of the frame without wasting the plot.
pub const AUTO_MARGIN: f64 = 0.05;

/// Half-width of an automatic linear range when all values are equal to `v != 0`, as a
/// fraction of `|v|`: ±10 % shows the value in the middle with round tick labels around it.
pub const FLAT_LINEAR_HALF: f64 = 0.1;

/// Half-width, in decades, of an automatic log range when all values are equal: half a
/// decade each side always brackets at least one power of ten (a labelled tick).
pub const FLAT_LOG_HALF_DECADES: f64 = 0.5;

/// Kind of an axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Axis {
    #[default]
    Linear,
    /// Base-10 logarithmic; every value on it must be > 0.
    Log,
}

/// Value to axis space: identity on a linear axis, log10 on a log axis.
pub fn to_axis(axis: Axis, v: f64) -> f64 {
    match axis {
        Axis::Linear => v,
        Axis::Log => v.log10(),
    }
}

/// Axis space back to value: inverse of [`to_axis`].
pub fn from_axis(axis: Axis, u: f64) -> f64 {
    match axis {
        Axis::Linear => u,
        Axis::Log => 10f64.powf(u),
    }
}

/// Automatic range (in values, not axis space) for data spanning `[lo, hi]` (finite,
/// `lo <= hi`, both positive on a log axis).
///
/// - span > 0: widened by [`AUTO_MARGIN`] of the span on each side (in axis space);
/// - all equal, linear: `v ± FLAT_LINEAR_HALF·|v|`, or `[-1, 1]` for `v = 0`
///   (no scale to take a fraction of; ±1 gives round ticks);
/// - all equal, log: `v ·/÷ 10^FLAT_LOG_HALF_DECADES`.
///
/// A log range that then contains no power of ten is widened outward to whole decades, so
/// the axis always carries at least one labelled tick (plotters labels log axes at powers
/// of ten and their multiples only).
pub fn auto_range(axis: Axis, lo: f64, hi: f64) -> (f64, f64) {
    let (ulo, uhi) = (to_axis(axis, lo), to_axis(axis, hi));
    let span = uhi - ulo;
    let (mut a, mut b) = if span > 0.0 {
        (ulo - AUTO_MARGIN * span, uhi + AUTO_MARGIN * span)
    } else {
        match axis {
            Axis::Linear if ulo == 0.0 => (-1.0, 1.0),
            Axis::Linear => (ulo - FLAT_LINEAR_HALF * ulo.abs(), ulo + FLAT_LINEAR_HALF * ulo.abs()),
            Axis::Log => (ulo - FLAT_LOG_HALF_DECADES, ulo + FLAT_LOG_HALF_DECADES),
        }
    };
    if axis == Axis::Log && b.floor() < a {
        a = a.floor();
        b = b.ceil();
    }
    (from_axis(axis, a), from_axis(axis, b))
}

/// An axis-aligned window in axis space, with a tolerance so that points lying exactly on
/// the boundary (within rounding of the log10 round trip) count as inside.
#[derive(Debug, Clone, Copy)]
pub struct Window {
    pub x: (f64, f64),
    pub y: (f64, f64),
    tol_x: f64,
    tol_y: f64,
}

impl Window {
    /// Window from axis-space bounds (`x.0 < x.1`, `y.0 < y.1`).
    pub fn new(x: (f64, f64), y: (f64, f64)) -> Self {
        // 1e-9 of the span: far below a pixel, far above the log10/powf round-off.
        Window { x, y, tol_x: 1e-9 * (x.1 - x.0), tol_y: 1e-9 * (y.1 - y.0) }
    }

    pub fn contains(&self, p: (f64, f64)) -> bool {
        p.0 >= self.x.0 - self.tol_x && p.0 <= self.x.1 + self.tol_x && p.1 >= self.y.0 - self.tol_y && p.1 <= self.y.1 + self.tol_y
    }

    /// Position of `p` in the unit square of the window ((0, 0) lower left).
    pub fn unit(&self, p: (f64, f64)) -> (f64, f64) {
        ((p.0 - self.x.0) / (self.x.1 - self.x.0), (p.1 - self.y.0) / (self.y.1 - self.y.0))
    }

    /// Liang–Barsky clip of the segment `p → q`: the parameters `(t0, t1)`, `0 <= t0 <= t1 <= 1`,
    /// of the part inside the window, or `None` if no part is inside.
    pub fn clip_segment(&self, p: (f64, f64), q: (f64, f64)) -> Option<(f64, f64)> {
        let (dx, dy) = (q.0 - p.0, q.1 - p.1);
        let mut t0 = 0.0f64;
        let mut t1 = 1.0f64;
        let edges = [
            (-dx, p.0 - (self.x.0 - self.tol_x)),
            (dx, (self.x.1 + self.tol_x) - p.0),
            (-dy, p.1 - (self.y.0 - self.tol_y)),
            (dy, (self.y.1 + self.tol_y) - p.1),
        ];
        for (den, num) in edges {
            if den == 0.0 {
                if num < 0.0 {
                    return None;
                }
            } else {
                let t = num / den;
                if den < 0.0 {
                    t0 = t0.max(t);
                } else {
                    t1 = t1.min(t);
                }
            }
        }
        (t0 <= t1).then_some((t0, t1))
    }

    /// Clips the polyline `points` (axis space) to the window: the visible pieces, each with
    /// at least two vertices, in order. A polyline that leaves and re-enters the window gives
    /// several pieces, so nothing is drawn along the frame.
    pub fn clip_polyline(&self, points: &[(f64, f64)]) -> Vec<Vec<(f64, f64)>> {
        let lerp = |p: (f64, f64), q: (f64, f64), t: f64| (p.0 + t * (q.0 - p.0), p.1 + t * (q.1 - p.1));
        let mut pieces: Vec<Vec<(f64, f64)>> = Vec::new();
        let mut open = false;
        for w in points.windows(2) {
            let (p, q) = (w[0], w[1]);
            match self.clip_segment(p, q) {
                Some((t0, t1)) => {
                    let b = if t1 >= 1.0 { q } else { lerp(p, q, t1) };
                    if open && t0 <= 0.0 {
                        pieces.last_mut().expect("open piece").push(b);
                    } else {
                        let a = if t0 <= 0.0 { p } else { lerp(p, q, t0) };
                        pieces.push(vec![a, b]);
                    }
                    open = t1 >= 1.0;
                }
                None => open = false,
            }
        }
        pieces
    }
}

/// Tick-label text: six significant digits, trailing zeros dropped ("0.3", "250000",
/// "1e-6"), so labels are short and never show binary round-off like 0.30000000000000004.
/// `|v| <= zero_below` prints as "0": pass 1e-9 × the span of a linear axis, so the tick at
/// zero, computed as a sum of steps, does not read "-2.22045e-16"; pass 0 on a log axis.
pub fn fmt_tick(v: f64, zero_below: f64) -> String {
    if v == 0.0 || v.abs() <= zero_below {
        return "0".to_string();
    }
    let s = fmt_sig(v, 6);
    let (mantissa, exponent) = match s.split_once('e') {
        Some((m, e)) => (m, Some(e)),
        None => (s.as_str(), None),
    };
    let mantissa = if mantissa.contains('.') { mantissa.trim_end_matches('0').trim_end_matches('.') } else { mantissa };
    match exponent {
        Some(e) => format!("{mantissa}e{e}"),
        None => mantissa.to_string(),
    }
}

/// Advance width of a tick-label character, em, for spacing labels: DejaVu Sans's digits are
/// 1303 of 2048 units wide (0.636 em), its widest tick character ('.' and '-' are narrower).
pub const TICK_CHAR_EM: f64 = 0.64;

/// Smallest free space between neighbouring tick labels, px: half an em of the 15 px tick
/// font, so two labels never read as one number ("700800901000").
pub const TICK_GAP_PX: f64 = 8.0;

/// Fewest pixels per labelled tick on a linear axis: at most one label per 50 px keeps a
/// 600 px axis to about a dozen labels even when short labels would fit more.
pub const TICK_MIN_SPACING_PX: f64 = 50.0;

/// Along which image direction an axis runs: a horizontal axis's labels take their width
/// along it, a vertical axis's labels their height.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Along {
    Horizontal,
    Vertical,
}

/// The ticks of one axis (values, ascending): `labelled` carry a label and a grid line,
/// `light` only a light grid line.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Ticks {
    pub labelled: Vec<f64>,
    pub light: Vec<f64>,
}

/// Ticks for the range `(lo, hi)` (values) drawn over `pixels` px with labels of `font_px`.
///
/// The densest set among round candidates whose labels do not overlap (with [`TICK_GAP_PX`]
/// between them, widths estimated at [`TICK_CHAR_EM`] per character of [`fmt_tick`]'s text):
///
/// - linear: multiples of 1, 2 or 5 × 10^k, at most one per [`TICK_MIN_SPACING_PX`];
/// - log: 1, 2 and 5 × each decade, then every decade, then every 2nd, 5th, 10th … decade;
///   when none of these puts two labels on the axis (a range within a factor of about 2, such
///   as 700–1000), the linear candidates, placed on the log axis.
///
/// At least two labels whenever any candidate gives two; light ticks subdivide the labelled
/// ones (fifths of a linear step; the other integer multiples within a decade on a log axis).
pub fn ticks(axis: Axis, range: (f64, f64), pixels: f64, font_px: f64, along: Along) -> Ticks {
    let (ua, ub) = (to_axis(axis, range.0), to_axis(axis, range.1));
    let zero_below = if axis == Axis::Linear { 1e-9 * (range.1 - range.0) } else { 0.0 };
    let px = |v: f64| (to_axis(axis, v) - ua) / (ub - ua) * pixels;
    let extent = |v: f64| match along {
        Along::Horizontal => TICK_CHAR_EM * font_px * fmt_tick(v, zero_below).chars().count() as f64,
        Along::Vertical => font_px,
    };
    let fits = |t: &[f64]| {
        t.windows(2).all(|w| px(w[1]) - px(w[0]) >= 0.5 * (extent(w[0]) + extent(w[1])) + TICK_GAP_PX)
    };
    let mut candidates: Vec<(Vec<f64>, Vec<f64>)> = Vec::new();
    if axis == Axis::Log {
        candidates.extend(log_candidates(range));
    }
    // linear steps, from about one per TICK_MIN_SPACING_PX up to the whole span
    let span = range.1 - range.0;
    let most = (pixels / TICK_MIN_SPACING_PX).max(1.0);
    let mut k = (span / most).log10().floor() as i32;
    'steps: loop {
        for m in [1.0, 2.0, 5.0] {
            let step = m * 10f64.powi(k);
            if step < span / most {
                continue;
            }
            let labelled = multiples(step, range);
            let light = multiples(step / 5.0, range).into_iter().filter(|v| !labelled.iter().any(|l| close(*l, *v, step))).collect();
            let done = labelled.len() < 2;
            candidates.push((labelled, light));
            if done {
                break 'steps;
            }
        }
        k += 1;
    }
    let pick = candidates.iter().find(|(l, _)| l.len() >= 2 && fits(l)).or_else(|| candidates.iter().find(|(l, _)| !l.is_empty() && fits(l)));
    match pick {
        Some((labelled, light)) => Ticks { labelled: labelled.clone(), light: light.clone() },
        // nothing round fits (a range narrower than its labels): the middle alone
        None => Ticks { labelled: vec![from_axis(axis, 0.5 * (ua + ub))], light: Vec::new() },
    }
}

/// Whether `a` and `b` are the same tick, to round-off of a step `step`.
fn close(a: f64, b: f64, step: f64) -> bool {
    (a - b).abs() <= 1e-9 * step.abs()
}

/// The multiples of `step` in `range` (inclusive, to round-off), each computed as `i × step`.
fn multiples(step: f64, range: (f64, f64)) -> Vec<f64> {
    let (i0, i1) = ((range.0 / step - 1e-9).ceil(), (range.1 / step + 1e-9).floor());
    if !(i0.is_finite() && i1.is_finite()) || i1 - i0 > 10_000.0 {
        return Vec::new();
    }
    (i0 as i64..=i1 as i64).map(|i| i as f64 * step).collect()
}

/// Log-axis candidates, densest first: 1-2-5 in each decade, then every 1st, 2nd, 5th, 10th …
/// decade; each with its light ticks.
fn log_candidates(range: (f64, f64)) -> Vec<(Vec<f64>, Vec<f64>)> {
    let inside = |v: f64| v >= range.0 * (1.0 - 1e-9) && v <= range.1 * (1.0 + 1e-9);
    let (d0, d1) = (range.0.log10().floor() as i32, range.1.log10().ceil() as i32);
    let per_decade = |ms: &[f64], every: i32| -> Vec<f64> {
        (d0..=d1).filter(|d| d.rem_euclid(every) == 0).flat_map(|d| ms.iter().map(move |m| m * 10f64.powi(d))).filter(|&v| inside(v)).collect()
    };
    let mut out = vec![(per_decade(&[1.0, 2.0, 5.0], 1), per_decade(&[3.0, 4.0, 6.0, 7.0, 8.0, 9.0], 1))];
    out.push((per_decade(&[1.0], 1), per_decade(&[2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0], 1)));
    let mut every = 2;
    while every <= (d1 - d0).max(1) {
        let labelled = per_decade(&[1.0], every);
        let light = per_decade(&[1.0], 1).into_iter().filter(|v| !labelled.contains(v)).collect();
        out.push((labelled, light));
        every = if every.to_string().starts_with('2') { every / 2 * 5 } else { every * 2 };
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn auto_range_linear_adds_margin_and_handles_flat_data() {
        let (a, b) = auto_range(Axis::Linear, 0.0, 10.0);
        assert!((a + 0.5).abs() < 1e-12 && (b - 10.5).abs() < 1e-12, "{a} {b}");
        assert_eq!(auto_range(Axis::Linear, 0.0, 0.0), (-1.0, 1.0));
        let (a, b) = auto_range(Axis::Linear, -2.0, -2.0);
        assert!((a + 2.2).abs() < 1e-12 && (b + 1.8).abs() < 1e-12, "{a} {b}");
    }

    #[test]
    fn auto_range_log_is_symmetric_in_decades_and_holds_a_power_of_ten() {
        // 1e-3 .. 1e1: four decades, 0.2 decade margin each side.
        let (a, b) = auto_range(Axis::Log, 1e-3, 10.0);
        assert!((a.log10() + 3.2).abs() < 1e-12 && (b.log10() - 1.2).abs() < 1e-12, "{a} {b}");
        // Flat: half a decade each side.
        let (a, b) = auto_range(Axis::Log, 3.0, 3.0);
        assert!((a * 10f64.sqrt() - 3.0).abs() < 1e-12 && (b / 10f64.sqrt() - 3.0).abs() < 1e-12);
        // 2..3 brackets no power of ten: widened to the decade 1..10.
        let (a, b) = auto_range(Axis::Log, 2.0, 3.0);
        assert!((a - 1.0).abs() < 1e-12 && (b - 10.0).abs() < 1e-12, "{a} {b}");
    }

    #[test]
    fn clip_polyline_splits_at_the_frame_and_keeps_inner_vertices() {
        let w = Window::new((0.0, 1.0), (0.0, 1.0));
        // Inside, out through the right edge, back in: two pieces.
        let pieces = w.clip_polyline(&[(0.2, 0.5), (0.5, 0.5), (1.5, 0.5), (0.8, 0.2), (0.6, 0.2)]);
        assert_eq!(pieces.len(), 2, "{pieces:?}");
        // Clipped at the frame, within the window's boundary tolerance (1e-9 of the span).
        let close = |a: &[(f64, f64)], b: &[(f64, f64)]| a.len() == b.len() && a.iter().zip(b).all(|(p, q)| (p.0 - q.0).abs() < 1e-6 && (p.1 - q.1).abs() < 1e-6);
        assert!(close(&pieces[0], &[(0.2, 0.5), (0.5, 0.5), (1.0, 0.5)]), "{pieces:?}");
        let first = pieces[1][0];
        assert!((first.0 - 1.0).abs() < 1e-6 && pieces[1].last() == Some(&(0.6, 0.2)), "{pieces:?}");
        // Entirely outside: nothing.
        assert!(w.clip_polyline(&[(2.0, 2.0), (3.0, 2.0)]).is_empty());
        // A segment crossing the window without a vertex inside.
        let pieces = w.clip_polyline(&[(-1.0, 0.5), (2.0, 0.5)]);
        assert_eq!(pieces.len(), 1);
        assert!((pieces[0][0].0 - 0.0).abs() < 1e-6 && (pieces[0][1].0 - 1.0).abs() < 1e-6);
    }

    #[test]
    fn boundary_points_count_as_inside() {
        let (a, b) = (1e-3f64.log10(), 10f64.log10());
        let w = Window::new((a, b), (0.0, 1.0));
        assert!(w.contains((10f64.log10(), 1.0)));
        assert!(w.contains((1e-3f64.log10(), 0.0)));
        assert!(!w.contains((20f64.log10(), 0.5)));
    }

    #[test]
    fn tick_text_is_short() {
        assert_eq!(fmt_tick(0.1 + 0.2, 0.0), "0.3");
        assert_eq!(fmt_tick(250000.0, 0.0), "250000");
        assert_eq!(fmt_tick(1e-6, 0.0), "1e-6");
        assert_eq!(fmt_tick(-2.5e7, 0.0), "-2.5e7");
        assert_eq!(fmt_tick(0.0, 0.0), "0");
        assert_eq!(fmt_tick(1.0, 0.0), "1");
        // Round-off at zero on a linear axis of span 2.
        assert_eq!(fmt_tick(-2.220446049250313e-16, 2e-9), "0");
        assert_eq!(fmt_tick(1e-7, 0.0), "1e-7");
    }

    #[test]
    fn log_ticks_label_a_narrow_range_without_overlap() {
        // the speed-against-accuracy chart of issue 32: wall times 700–1000 s read
        // "700800901000" with plotters' own log ticks
        let t = ticks(Axis::Log, (690.0, 1010.0), 770.0, 15.0, Along::Horizontal);
        assert_eq!(t.labelled, vec![700.0, 750.0, 800.0, 850.0, 900.0, 950.0, 1000.0]);
        // two decades: 1-2-5 (y axis, 15 px labels, 460 px)
        let t = ticks(Axis::Log, (0.008, 0.6), 460.0, 15.0, Along::Vertical);
        assert_eq!(t.labelled, vec![0.01, 0.02, 0.05, 0.1, 0.2, 0.5]);
        assert!(t.light.contains(&0.03) && !t.light.contains(&0.02), "{t:?}");
        // twelve decades on 400 px: every 2nd decade (decades would be 33 px apart, labels 5 chars)
        let t = ticks(Axis::Log, (1e-9, 1e3), 400.0, 15.0, Along::Horizontal);
        assert!(t.labelled.len() >= 3 && t.labelled.iter().all(|v| (v.log10().round() as i32) % 2 == 0), "{t:?}");
    }

    #[test]
    fn linear_ticks_are_round_and_apart() {
        let t = ticks(Axis::Linear, (-0.5, 10.5), 770.0, 15.0, Along::Horizontal);
        assert_eq!(t.labelled, (0..=10).map(f64::from).collect::<Vec<_>>());
        assert!(t.light.contains(&0.4) && !t.light.contains(&2.0));
        // long labels (six digits) on a short axis: a coarser step
        let t = ticks(Axis::Linear, (100000.0, 100100.0), 200.0, 15.0, Along::Horizontal);
        assert!(t.labelled.len() >= 2, "{t:?}");
        for w in t.labelled.windows(2) {
            let gap = (w[1] - w[0]) / 100.0 * 200.0;
            assert!(gap >= TICK_CHAR_EM * 15.0 * 6.0 + TICK_GAP_PX, "{t:?}");
        }
    }
}
