//! Pareto front of two costs, both minimised (e.g. run time and error).

/// Indices of the non-dominated points of `points`, both coordinates minimised, sorted by
/// x, then y, then index (so ties are deterministic).
///
/// Point `a` dominates `b` when `a.x <= b.x` and `a.y <= b.y` with at least one strict.
/// Identical points do not dominate each other, so duplicates on the front are all
/// returned (each is an equally good choice). Points with a non-finite coordinate are never
/// on the front and dominate nothing: they stand for failed runs, not measurements.
/// O(n log n).
pub fn pareto_front(points: &[(f64, f64)]) -> Vec<usize> {
    let mut order: Vec<usize> = (0..points.len()).filter(|&i| points[i].0.is_finite() && points[i].1.is_finite()).collect();
    order.sort_by(|&i, &j| {
        let (a, b) = (points[i], points[j]);
        a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1)).then(i.cmp(&j))
    });
    let mut front: Vec<usize> = Vec::new();
    let mut best_y = f64::INFINITY;
    for i in order {
        let p = points[i];
        // Sorted by x: p is dominated unless its y beats every earlier point's, or it
        // duplicates the last point kept (same x and y).
        let duplicate = front.last().is_some_and(|&k| points[k] == p);
        if p.1 < best_y || duplicate {
            best_y = p.1;
            front.push(i);
        }
    }
    front
}

#[cfg(test)]
mod tests {
    use super::pareto_front;

    #[test]
    fn dominated_points_are_dropped() {
        // (1,5) (2,3) (4,1) are the front; (3,4) is dominated by (2,3), (5,5) by all.
        let p = [(3.0, 4.0), (1.0, 5.0), (5.0, 5.0), (4.0, 1.0), (2.0, 3.0)];
        assert_eq!(pareto_front(&p), vec![1, 4, 3]);
    }

    #[test]
    fn equal_coordinates_dominate_unless_identical() {
        // Same x, larger y: dominated. Same y, larger x: dominated. Identical: both kept, by index.
        let p = [(1.0, 2.0), (1.0, 3.0), (2.0, 1.0), (3.0, 1.0), (2.0, 1.0)];
        assert_eq!(pareto_front(&p), vec![0, 2, 4]);
    }

    #[test]
    fn trivial_inputs() {
        assert_eq!(pareto_front(&[]), Vec::<usize>::new());
        assert_eq!(pareto_front(&[(7.0, -1.0)]), vec![0]);
        assert_eq!(pareto_front(&[(f64::NAN, 0.0), (1.0, 1.0), (0.0, f64::NEG_INFINITY)]), vec![1]);
    }

    #[test]
    fn agrees_with_the_definition() {
        // Deterministic pseudo-random cloud on a coarse grid (many ties), checked against O(n²).
        let mut s = 12345u64;
        let mut next = || {
            s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            ((s >> 33) % 8) as f64
        };
        let p: Vec<(f64, f64)> = (0..200).map(|_| (next(), next())).collect();
        let dominated = |b: (f64, f64)| p.iter().any(|&a| a.0 <= b.0 && a.1 <= b.1 && a != b);
        let mut expected: Vec<usize> = (0..p.len()).filter(|&i| !dominated(p[i])).collect();
        expected.sort_by(|&i, &j| p[i].0.total_cmp(&p[j].0).then(p[i].1.total_cmp(&p[j].1)).then(i.cmp(&j)));
        assert_eq!(pareto_front(&p), expected);
    }
}
