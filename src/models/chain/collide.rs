//! Simultaneous impacts (docs/physics.md s.4): every shut unit that is closing
//! swaps its two nodes' velocities (unit 1 flips node 1's against the wall),
//! again and again until no shut unit closes. With equal masses each swap
//! puts one pair of a packed block in order, so the result is the sorted
//! velocities whatever the order of the swaps (a Newton's cradle passes the
//! incoming speed through the block).

use std::ops::RangeInclusive;

/// Resolve the impacts among units `first ..= first + shut.len() - 1` at one
/// instant. `shut[i]` says whether unit `first + i` is shut (its gap within
/// round-off of zero); `v` holds the velocities of nodes `first - 1 ..=
/// first + shut.len() - 1` (`v[0]` is the wall's, zero, when `first` is 1).
/// Returns the units whose nodes changed velocity, if any did, and the
/// change of node 1's velocity the wall made (swaps conserve momentum;
/// only wall flips change it).
pub fn cascade(first: usize, shut: &[bool], v: &mut [f64]) -> (Option<RangeInclusive<usize>>, f64) {
    cascade_with(first, shut, v, |_| {})
}

/// One step of a [`cascade`]: node velocities `i` and `i + 1` of its `v`
/// swapped, or (`None`) node 1's flipped against the wall.
pub type Step = Option<usize>;

/// [`cascade`], each step it takes told to `step` as it is taken: what a
/// reset's Jacobian (a signed permutation) is read from.
pub fn cascade_with(
    first: usize,
    shut: &[bool],
    v: &mut [f64],
    mut step: impl FnMut(Step),
) -> (Option<RangeInclusive<usize>>, f64) {
    assert_eq!(v.len(), shut.len() + 1, "one more node than units");
    let mut touched: Option<(usize, usize)> = None;
    let mut wall = 0.0;
    // Each pass fixes at least one closing pair; a block of b units is
    // sorted within b^2 passes (bubble sort), so this bound is never hit.
    for _ in 0..=shut.len() * shut.len() {
        let mut changed = false;
        for (i, _) in shut.iter().enumerate().filter(|(_, shut)| **shut) {
            let unit = first + i;
            if v[i] - v[i + 1] <= 0.0 {
                continue;
            }
            if unit == 1 {
                wall -= 2.0 * v[1];
                v[1] = -v[1];
                step(None);
            } else {
                v.swap(i, i + 1);
                step(Some(i));
            }
            changed = true;
            touched = Some(touched.map_or((unit, unit), |(a, b)| (a.min(unit), b.max(unit))));
        }
        if !changed {
            break;
        }
    }
    (touched.map(|(a, b)| a..=b), wall)
}

/// The impact of `unit` while every other unit in reach is open: its two
/// nodes' velocities `[v_{unit-1}, v_unit]` after it, if it closes (swapped;
/// node 1's flipped against the wall), or `None`. The same as [`cascade`]
/// with this unit the only one shut, without its bookkeeping.
pub fn alone(unit: usize, v: [f64; 2]) -> Option<[f64; 2]> {
    if v[0] - v[1] <= 0.0 {
        return None;
    }
    Some(if unit == 1 {
        [v[0], -v[1]]
    } else {
        [v[1], v[0]]
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_lone_unit_collides_as_in_a_cascade_of_one() {
        let speeds = [-2.5, -1.0, -0.0, 0.0, 1e-300, 0.75, 3.0];
        for unit in [1, 2, 7] {
            for &a in &speeds {
                for &b in &speeds {
                    // Node 0 is the wall, at rest.
                    let a = if unit == 1 { 0.0 } else { a };
                    let mut v = [a, b];
                    let (touched, wall) = cascade(unit, &[true], &mut v);
                    let expected = touched.map(|_| v);
                    let got = alone(unit, [a, b]);
                    let bits = |x: Option<[f64; 2]>| x.map(|v| v.map(f64::to_bits));
                    assert_eq!(bits(got), bits(expected), "unit {unit}: {a} {b}");
                    if let Some([_, right]) = got.filter(|_| unit == 1) {
                        assert_eq!(right - b, wall, "{b}");
                    }
                }
            }
        }
    }

    #[test]
    fn a_node_into_a_packed_block_passes_its_speed_through() {
        // Units 2..4 shut; node 1 arrives at speed 2 on nodes at rest.
        let mut v = [0.0, 2.0, 0.0, 0.0, 0.0];
        let touched = cascade(1, &[false, true, true, true], &mut v);
        assert_eq!(v, [0.0, 0.0, 0.0, 0.0, 2.0]);
        assert_eq!(touched, (Some(2..=4), 0.0));
    }

    #[test]
    fn the_wall_flips_a_closing_first_node_only() {
        let mut v = [0.0, -1.5, 0.0];
        assert_eq!(cascade(1, &[true, false], &mut v), (Some(1..=1), 3.0));
        assert_eq!(v, [0.0, 1.5, 0.0]);
        let mut v = [0.0, 1.5, 0.0];
        assert_eq!(cascade(1, &[true, false], &mut v), (None, 0.0));
    }
}
